// Levenberg-Marquardt stopped by the Newton decrement (internal/decrement_stop.h).
#include "fastcal/internal/decrement_stop.h"

#include <Eigen/Cholesky>
#include <utility>

#include "fastcal/internal/number_text.h"

namespace fastcal::internal {

double NewtonDecrement(const Eigen::MatrixXd& r_aug, const std::vector<DecrementPrior>& priors,
                       const double* theta) {
  const int n = static_cast<int>(r_aug.cols()) - 1;
  const Eigen::MatrixXd r = r_aug.topLeftCorner(n, n);
  const Eigen::VectorXd z = r_aug.col(n).head(n);
  Eigen::MatrixXd h = r.transpose() * r;
  Eigen::VectorXd g = r.transpose() * z;
  for (const DecrementPrior& p : priors) {
    h(p.k, p.k) += 1.0 / (p.sigma * p.sigma);
    g[p.k] += (theta[p.k] - p.mean) / (p.sigma * p.sigma);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(h);
  if (llt.info() != Eigen::Success) return -1.0;
  return 0.5 * g.dot(llt.solve(g));
}

DecrementStop::DecrementStop(std::function<bool(const double*, Eigen::MatrixXd*)> linearisation,
                             std::vector<DecrementPrior> priors, const double* theta,
                             double function_tolerance)
    : linearisation_(std::move(linearisation)),
      priors_(std::move(priors)),
      theta_(theta),
      function_tolerance_(function_tolerance) {}

ceres::CallbackReturnType DecrementStop::operator()(const ceres::IterationSummary& summary) {
  // After a rejected step the Jacobian at hand is the rejected point's, not x's.
  if (summary.iteration > 0 && !summary.step_is_successful) return ceres::SOLVER_CONTINUE;
  Eigen::MatrixXd r_aug;
  if (!linearisation_(theta_, &r_aug)) return ceres::SOLVER_CONTINUE;
  const double decrement = NewtonDecrement(r_aug, priors_, theta_);
  if (!(decrement >= 0.0) || decrement > function_tolerance_ * summary.cost) {
    return ceres::SOLVER_CONTINUE;
  }
  stopped_ = true;
  decrement_ = decrement;
  cost_ = summary.cost;
  return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
}

std::string DecrementStop::Reason() const {
  if (!stopped_) return "";
  return "Newton decrement (the next step's predicted decrease) " +
         FormatDouble("%.3e", decrement_) + " <= function_tolerance * cost " +
         FormatDouble("%.3e", function_tolerance_ * cost_);
}

}  // namespace fastcal::internal
