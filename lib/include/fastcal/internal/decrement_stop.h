// Stopping Levenberg-Marquardt one cost evaluation early, where it would stop anyway.
//
// Ceres stops on its function tolerance only after evaluating a trial step: it computes
// the step, evaluates the cost at x + delta, and when |F(x) - F(x + delta)| <=
// function_tolerance * F(x) it stops at x, leaving the step untaken. On the folded data
// term every evaluation solves the statics of every sample (1.2 s at 10^6 samples), so
// that last evaluation is the most expensive line of a converged pass. Near the optimum
// the Gauss-Newton model predicts the decrease of the next step, the Newton decrement
//   lambda = 1/2 g^T H^-1 g,   H = J^T J,  g = J^T r,
// (Boyd and Vandenberghe 2004, sec. 9.5.1), from the Jacobian Ceres has already
// evaluated at x: when lambda <= function_tolerance * F(x) the trial would show no more
// decrease than the tolerance and Ceres would stop at the same x. This callback stops
// there instead (after a taken step, or at the start), and says why.
//
// Ceres's step is damped (H + D / mu), so its model decrease is at most lambda: the
// test never stops where Ceres's next step is predicted to decrease the cost by more.
#ifndef FASTCAL_INTERNAL_DECREMENT_STOP_H_
#define FASTCAL_INTERNAL_DECREMENT_STOP_H_

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace fastcal::internal {

// A Gaussian prior on one parameter: residual (theta_k - mean) / sigma.
struct DecrementPrior {
  int k = 0;
  double mean = 0.0, sigma = 1.0;
};

// The Newton decrement 1/2 g^T H^-1 g of the data term's folded rows r_aug = [R z]
// ((n + 1) x (n + 1) or n x (n + 1): H = R^T R, g = R^T z) plus the priors at theta.
// Returns -1 when H is not positive definite.
double NewtonDecrement(const Eigen::MatrixXd& r_aug, const std::vector<DecrementPrior>& priors,
                       const double* theta);

class DecrementStop : public ceres::IterationCallback {
 public:
  // linearisation(theta, &r_aug): the data term's folded rows at theta when they are at
  // hand (no new evaluation), else false. `theta` is the parameter block Ceres updates
  // every iteration (Solver::Options::update_state_every_iteration must be true).
  DecrementStop(std::function<bool(const double*, Eigen::MatrixXd*)> linearisation,
                std::vector<DecrementPrior> priors, const double* theta, double function_tolerance);
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override;

  bool stopped() const { return stopped_; }
  // Why it stopped (empty when it did not).
  std::string Reason() const;

 private:
  std::function<bool(const double*, Eigen::MatrixXd*)> linearisation_;
  std::vector<DecrementPrior> priors_;
  const double* theta_;
  double function_tolerance_;
  bool stopped_ = false;
  double decrement_ = 0.0, cost_ = 0.0;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_DECREMENT_STOP_H_
