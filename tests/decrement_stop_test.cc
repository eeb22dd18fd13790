// The Newton-decrement stop: the decrement against a linear least-squares problem's exact
// decrease, and a nonlinear Ceres solve stopped by it ending at the same bits as without
// it, one cost evaluation sooner.
#include "fastcal/internal/decrement_stop.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

namespace fastcal::internal {
namespace {

// [R z] of the stacked rows [J r] (QR), as the folded data term keeps them.
Eigen::MatrixXd Folded(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residual) {
  Eigen::MatrixXd augmented(jacobian.rows(), jacobian.cols() + 1);
  augmented << jacobian, residual;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(augmented);
  const int n = static_cast<int>(jacobian.cols());
  return qr.matrixQR().topRows(n + 1).triangularView<Eigen::Upper>();
}

TEST(NewtonDecrement, IsTheExactDecreaseOfALinearProblem) {
  // F = 1/2 |A x - b|^2 + 1/2 sum ((x_k - m_k) / s_k)^2 is quadratic: F(x0) - min F equals
  // the decrement at x0, to rounding.
  constexpr double kRounding = 1e-9;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  const int rows = 30, n = 4;
  Eigen::MatrixXd a(rows, n);
  Eigen::VectorXd b(rows), x0(n);
  for (int k = 0; k < a.size(); ++k) a.data()[k] = normal(rng);
  for (int k = 0; k < rows; ++k) b[k] = normal(rng);
  for (int k = 0; k < n; ++k) x0[k] = 3.0 * normal(rng);
  const std::vector<DecrementPrior> priors = {{1, 0.5, 0.2}, {3, -1.0, 2.0}};
  const auto cost = [&](const Eigen::VectorXd& x) {
    double f = 0.5 * (a * x - b).squaredNorm();
    for (const DecrementPrior& p : priors) f += 0.5 * std::pow((x[p.k] - p.mean) / p.sigma, 2);
    return f;
  };
  Eigen::MatrixXd h = a.transpose() * a;
  Eigen::VectorXd rhs = a.transpose() * b;
  for (const DecrementPrior& p : priors) {
    h(p.k, p.k) += 1.0 / (p.sigma * p.sigma);
    rhs[p.k] += p.mean / (p.sigma * p.sigma);
  }
  const Eigen::VectorXd best = h.ldlt().solve(rhs);
  const double decrease = cost(x0) - cost(best);
  EXPECT_NEAR(NewtonDecrement(Folded(a, a * x0 - b), priors, x0.data()), decrease,
              kRounding * decrease);
}

// y = a exp(b x) + c, fitted to noisy points: a small nonlinear problem.
struct ExpResidual {
  double x, y;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    r[0] = p[0] * exp(p[1] * x) + p[2] - y;
    return true;
  }
};

struct ExpProblem {
  std::vector<double> xs, ys;
  explicit ExpProblem(int points) {
    std::mt19937_64 rng(5);
    std::normal_distribution<double> noise(0.0, 0.05);
    for (int k = 0; k < points; ++k) {
      xs.push_back(0.05 * k);
      ys.push_back(2.0 * std::exp(-1.3 * xs.back()) + 0.4 + noise(rng));
    }
  }
  // [R z] at p, from the analytic Jacobian.
  bool Linearise(const double* p, Eigen::MatrixXd* r_aug) const {
    const int m = static_cast<int>(xs.size());
    Eigen::MatrixXd j(m, 3);
    Eigen::VectorXd r(m);
    for (int k = 0; k < m; ++k) {
      const double e = std::exp(p[1] * xs[k]);
      j.row(k) << e, p[0] * xs[k] * e, 1.0;
      r[k] = p[0] * e + p[2] - ys[k];
    }
    *r_aug = Folded(j, r);
    return true;
  }
  ceres::Solver::Summary Solve(double* p, ceres::IterationCallback* extra) const {
    ceres::Problem problem;
    for (size_t k = 0; k < xs.size(); ++k) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ExpResidual, 1, 3>(new ExpResidual{xs[k], ys[k]}),
          nullptr, p);
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.function_tolerance = 1e-10;
    options.gradient_tolerance = options.parameter_tolerance = 1e-30;
    options.update_state_every_iteration = true;
    if (extra != nullptr) options.callbacks.push_back(extra);
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    return summary;
  }
};

TEST(DecrementStop, StopsWhereCeresWouldOneEvaluationSooner) {
  const ExpProblem problem(40);
  double plain[3] = {1.0, -0.5, 0.0};
  const ceres::Solver::Summary without = problem.Solve(plain, nullptr);
  ASSERT_EQ(without.termination_type, ceres::CONVERGENCE) << without.message;
  double stopped[3] = {1.0, -0.5, 0.0};
  DecrementStop stop(
      [&problem](const double* p, Eigen::MatrixXd* r_aug) { return problem.Linearise(p, r_aug); },
      {}, stopped, 1e-10);
  const ceres::Solver::Summary with = problem.Solve(stopped, &stop);
  EXPECT_TRUE(stop.stopped());
  EXPECT_FALSE(stop.Reason().empty());
  for (int k = 0; k < 3; ++k) EXPECT_EQ(stopped[k], plain[k]) << "parameter " << k;
  EXPECT_EQ(with.num_residual_evaluations + 1, without.num_residual_evaluations);
}

TEST(DecrementStop, ATightToleranceDoesNotStop) {
  // A tolerance no step meets: the solve runs as without the stop.
  const ExpProblem problem(40);
  double p[3] = {1.0, -0.5, 0.0};
  DecrementStop stop(
      [&problem](const double* q, Eigen::MatrixXd* r_aug) { return problem.Linearise(q, r_aug); },
      {}, p, 0.0);
  problem.Solve(p, &stop);
  EXPECT_FALSE(stop.stopped());
  EXPECT_TRUE(stop.Reason().empty());
}

}  // namespace
}  // namespace fastcal::internal
