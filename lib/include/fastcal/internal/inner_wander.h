// The wander of a per-window group inside its windows (a track's mass centre moving about
// within an observing day; docs/calibration.md, "Tracking over a season", "The wander
// inside a day"): a first-order Gauss-Markov process per component, its variances and time
// constant estimated by restricted maximum likelihood (REML) from the windows' block
// scores, as the slow sensor error's from the residuals (slow_error_estimate.h).
//
// The model. Window w's blocks b = 1..B (contiguous runs of its samples in time order,
// track_fold.h) each see the group's value plus the process averaged over the block,
// eta_b. At the joint fit a block's score of the group's columns is, to first order,
//   s_b = I_b eta_b + e_b,      Cov(e_b, e_c) = f delta_bc I_b
// (I_b the block's information of the group, f the window's white misfit: its Birge
// ratio), and the process's block averages have
//   Cov(eta_b, eta_c) = diag(q) rbar_bc(tau)
// with, for blocks [t0_b, t1_b] of lengths L_b and the Gauss-Markov correlation
// exp(-|t - t'| / tau) averaged over both blocks (the exact averages of a continuous
// process; Gelb 1974, ch. 3, for the process):
//   rbar_bb = 2 (tau / L)^2 (L / tau - 1 + exp(-L / tau))
//   rbar_bc = F_b F_c exp(-(t0_c - t1_b) / tau),  F_b = (tau / L_b)(1 - exp(-L_b / tau)),
// b before c. Windows are independent (the process forgets overnight: a wander of a
// longer memory shows as the day-to-day wander, TrackWander).
//
// The window's own value is fitted, so its scores sum to zero: sum_b s_b = 0. REML (the
// likelihood of the contrasts free of the fitted mean; Patterson and Thompson 1971,
// Biometrika 58) uses the scores of the first B - 1 blocks, y = L s, s = P u with
// P = 1 - D X (X^T D X)^-1 X^T (D = diag(I_b), X = 1_B x I_p):
//   y ~ N(0, C),   C = L P (f D + D K D) P^T L^T,   K = sum_k q_k (rbar x e_k e_k^T)
//   -2 l(q, tau) = sum_w (log det C_w + y_w^T C_w^-1 y_w) + const.
// For each tau the q_k >= 0 follow by Fisher scoring (C is linear in q); tau by a grid
// and golden-section search over log tau. A step inside a window is not read as wander: a
// window whose scores the model cannot explain (y^T C^-1 y beyond the chi-square(m)
// quantile at 1 - 0.01 / windows) is left out of the estimate. The white model (q = 0)
// judges first, unless it leaves out most windows (a wander everywhere: then the estimate
// over all of them, which a few steps move little); the estimate over the rest then judges
// every window again, until the set left out stands.
#ifndef FASTCAL_INTERNAL_INNER_WANDER_H_
#define FASTCAL_INTERNAL_INNER_WANDER_H_

#include <Eigen/Core>
#include <vector>

namespace fastcal::internal {

// One window's blocks for the group (p components), at the joint fit.
struct WanderWindow {
  std::vector<double> first_s, last_s;  // per block: its first and last sample's time
  std::vector<Eigen::MatrixXd> info;    // per block: I_b (p x p)
  Eigen::MatrixXd score;                // B x p: s_b
  double white = 1.0;                   // f: the window's white misfit (>= 1)
  bool use = true;                      // in the estimate (false: a change inside it)
};

struct InnerWander {
  Eigen::VectorXd variance;        // q_k per component (SI^2); empty or all 0: none
  double time_constant_s = 0.0;    // tau
  Eigen::VectorXd variance_sigma;  // the q_k's standard errors (Fisher information)
  // The standard error of ln tau (the profile's curvature; 0 where not determined).
  double log_time_constant_sigma = 0.0;
  int windows_used = 0;
  std::vector<int> windows_left_out;  // indices into the estimate's windows
  double log_likelihood_gain = 0.0;   // l(q, tau) - l(0): the wander's support
  bool Active() const { return variance.size() > 0 && variance.maxCoeff() > 0.0; }
};

// rbar (B x B) for blocks [first_s[b], last_s[b]] at time constant tau (> 0).
Eigen::MatrixXd BlockAverageCorrelation(const std::vector<double>& first_s,
                                        const std::vector<double>& last_s, double tau_s);

// K (Bp x Bp, block-major: row b * p + k): Cov(eta_b[k], eta_c[l]) of the wander's block
// averages. Zero when the wander is not active.
Eigen::MatrixXd WanderBlockCovariance(const InnerWander& wander, const std::vector<double>& first_s,
                                      const std::vector<double>& last_s);

struct InnerWanderOptions {
  // Per-window level at which a window's scores are judged beyond the model (a step
  // inside it): 1 - level / windows.
  double outlier_level = 0.01;
  // Rounds of judging the windows and estimating again, at most.
  int max_rounds = 4;
  // Threads over the windows (each window's terms are independent).
  int threads = 1;
};

// The REML estimate over the windows with `use` set (at least two blocks each). None
// (variance all 0) when no window has two blocks or the data hold no wander.
InnerWander EstimateInnerWander(const std::vector<WanderWindow>& windows,
                                const InnerWanderOptions& options = InnerWanderOptions());

// -2 l(q, tau) over the windows with `use` set, without the constant: for tests and for
// the profile's report.
double InnerWanderDeviance(const std::vector<WanderWindow>& windows, const Eigen::VectorXd& q,
                           double tau_s);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_INNER_WANDER_H_
