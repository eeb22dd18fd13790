// The uncertainty of a weighted least-squares estimate on real data: a budget in the
// sense of the GUM (JCGM 100:2008), built from the problem linearised at its solution.
// Notation (docs/calibration.md, "Uncertainty budget"): n free parameters, whitened
// residuals r (model minus measured over sigma), their Jacobian J_x, prior information
// Lambda (diag 1/sigma_prior^2 of the free parameters with a prior),
//
//   M = J_x^T J_x + Lambda                            normal matrix
//   P_formal = M^-1                                   formal covariance (stated noise)
//
// Statistical part measured from the data (misfit and time-correlated residuals). With
// s_t = J_t^T r_t the score of sample t (samples in time order, J_t its rows of J_x),
// the long-run covariance of sum_t s_t is estimated by overlapping batch means with
// bandwidth L (Meketon and Schmeiser 1984; the Bartlett-kernel HAC estimator, Newey and
// West 1987; the overlapping form of Kunsch's 1989 delete-a-block jackknife):
//
//   W_j = sum_{t=j}^{j+L-1} s_t,  M_j = sum_{t=j}^{j+L-1} J_t^T J_t,  j = 1 .. N - L + 1
//   Omega_hat = N / ((N - L + 1) L) sum_j W_j W_j^T
//
// The residuals are those of the fit, which has taken out of them whatever part of the
// errors its parameters can absorb: within a batch, the part along M_j M^-1 J^T. For
// errors whose memory is short against L, E[W_j W_j^T] is then tau (M_j - M_j M^-1 M_j)
// instead of tau M_j, so each score component k is corrected by
//
//   c_k = sum_j (M_j)_kk / sum_j (M_j - M_j M^-1 M_j)_kk,   Omega = C^1/2 Omega_hat C^1/2
//
// (C = diag(c)). For one estimated mean this is Meketon and Schmeiser's N / (N - L); for
// p parameters that vary slowly along the data it is about N / (N - p L), and it is near
// 1 for parameters whose Jacobian changes within a batch. Then
//
//   P_data = M^-1 (Omega + Lambda) M^-1
//
// The bandwidth follows the residuals' memory: L = ceil(kBandwidthPerTau * tau), tau the
// largest integrated autocorrelation time 1 + 2 sum_k rho_k (Sokal's window) of the
// parameters' influence series u_t = M^-1 s_t. Only when some tau is significantly above
// 1 (the residuals are correlated) is P_data used at all: on white residuals it would
// add its own sampling noise (a third of the variance at 9 batches) and nothing else,
// and the Birge ratio below already covers the misfit. L is halved while some c_k exceeds
// kMaxBatchCorrection (the fit then absorbs most of a batch's slow error and the residuals
// can no longer measure it: the budget says its widening is a lower bound). From there
// the bandwidth is doubled while the variance keeps growing beyond its own noise
// (DataCovariance in uncertainty.cc). The statistical variance is, per parameter,
//
//   max(P_data, P_floor),  P_floor = M^-1 (f^2 J_x^T J_x + Lambda) M^-1,
//   f^2 = chi2/nu when above its band (misfit_threshold), else 1
//
// (the Birge ratio as a floor, scaling the data's information, not the priors'): never
// narrower than the formal one, never narrower than the misfit calls for.
//
// Systematic part from consider parameters (held fixed, uncertain with sigma_c; Tapley,
// Schutz and Born, "Statistical Orbit Determination", ch. 6), with J_c their whitened
// Jacobian:
//
//   S = -M^-1 J_x^T J_c          sensitivity d(estimate)/d(consider parameter)
//   P_consider = S diag(sigma_c^2) S^T,  per group g: S_g diag(sigma_g^2) S_g^T
//   P_total = P_statistical + P_consider
//
// Score (Lagrange-multiplier) test of a fixed parameter c, at the solution, no refit:
// g = J_c^T r, A = J_c^T J_c - J_c^T J_x M^-1 J_x^T J_c; the chi-square decrease expected
// from freeing c is g^2 / A.
#ifndef FASTCAL_UNCERTAINTY_H_
#define FASTCAL_UNCERTAINTY_H_

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace fastcal {

// Fewer samples than this and the residuals' memory is not measured (no P_data).
inline constexpr int kMinSamplesForCorrelation = 10;

// Per-sample Jacobian rows, one sample per row (row-major, so a sample's rows are contiguous).
using SampleJacobians = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// Per-sample scores s_t (n each), one sample per row, in float (issue 28: 8n bytes a sample
// was 170 MB at 10^6 samples and 21 parameters). Rounding them moves the long-run
// covariance and the autocorrelation times by ~1e-7 relative, far below their own noise;
// every sum over them runs in double.
using SampleScores = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Median and 1.4826 x the median absolute deviation about it: the standard deviation of
// a normal sample, unmoved by a minority of gross errors. Empty input gives {0, 0}.
struct RobustScale {
  double centre = 0.0;
  double scale = 0.0;
};
RobustScale RobustScaleOf(std::vector<double> values);

// Integrated autocorrelation time tau = 1 + 2 sum_{k=1}^{W} rho_k of a series, with
// Sokal's automatic window: the smallest W with W >= window_factor * tau(W). A white
// series gives ~1; n samples then hold about n / tau independent pieces of information.
struct AutocorrelationTime {
  double tau = 1.0;
  int window = 0;
  // False when no window satisfied the condition below a quarter of the series (the
  // memory is too long for the data to measure it; tau is then a lower bound).
  bool reliable = true;
};
AutocorrelationTime IntegratedAutocorrelationTime(const Eigen::Ref<const Eigen::VectorXd>& series,
                                                  double window_factor = 5.0);

// Omega_hat, the overlapping-batch-means estimate of the covariance of sum_t s_t (rows of
// `scores`, N x n, time order) with bandwidth L in [1, N] (formula above, before the
// correction c). Zero when N < 1.
Eigen::MatrixXd LongRunCovarianceOfSum(const Eigen::MatrixXd& scores, int bandwidth);

// The correction c_k (formula above) of each score component for bandwidth L, from each
// sample's Jacobian rows: `jacobians` row t holds J_t (rows_per_sample x n) row after
// row; `inverse_information` is M^-1. Windows are taken with a stride of L / 16 (they
// overlap, and the sums change slowly with j). All 1 when there are no Jacobians.
Eigen::VectorXd BatchCorrection(const SampleJacobians& jacobians, int rows_per_sample,
                                const Eigen::MatrixXd& inverse_information, int bandwidth);

// Each sample's J_t, in time order, without holding them all (issue 28: 0.5 GB at 10^6
// samples and 21 parameters): calls visit(t, J_t) for t = 0, 1, ..., N - 1, J_t as
// rows_per_sample x n floats, row-major (valid during the call). False when the rows
// cannot be had (visit may have been called for some).
using SampleJacobianReplay =
    std::function<bool(const std::function<void(int t, const float* jacobian)>& visit)>;

// The same correction from a replay of N samples' Jacobians (same numbers): the window
// sum's lookback kept in a ring of L samples' rows. All 1 when `replay` fails.
Eigen::VectorXd BatchCorrection(const SampleJacobianReplay& replay, int samples,
                                int rows_per_sample, const Eigen::MatrixXd& inverse_information,
                                int bandwidth);

// Bandwidth per unit of autocorrelation time. The Bartlett kernel's relative bias for a
// series of integrated autocorrelation time tau is about -tau / (2 L): -6% at 8 tau,
// while its relative variance, (4/3) L / N, stays small while N >> tau.
inline constexpr double kBandwidthPerTau = 8.0;
// Largest batch correction c_k accepted before the bandwidth is halved: at 3 the fit has
// absorbed two thirds of a batch's slow error.
inline constexpr double kMaxBatchCorrection = 3.0;
// Largest bandwidth tried, as a fraction of the samples (with fewer than ~4 batches the
// estimate means little).
inline constexpr double kMaxBandwidthFraction = 0.25;
// A wider bandwidth's variance is taken when it exceeds the narrower one's by more than
// this many of its relative standard deviations (one-sided, ~2.3% by chance per step).
inline constexpr double kGrowthSignificance = 2.0;

struct BudgetInputs {
  Eigen::MatrixXd information;        // M (n x n), data and priors
  Eigen::VectorXd prior_information;  // Lambda's diagonal (n); 0 without a prior
  SampleScores scores;                // s_t (N x n) in time order; may be empty
  // J_t of each sample, row after row (N x rows_per_sample * n; float to halve the
  // memory at 1e5 samples); may be empty: then from `jacobian_replay`, or c = 1 without.
  SampleJacobians jacobians;
  // The same rows on demand (only when the residuals are correlated, once per bandwidth
  // tried): the calibration's replay of its linearisation.
  SampleJacobianReplay jacobian_replay;
  int rows_per_sample = 1;
  int num_residuals = 0;    // m: data and prior residuals
  double chi_square = 0.0;  // sum of squared whitened residuals at the solution
  // The reduced chi-square above which the misfit factor applies (the top of its band,
  // calibration.h's ReducedChiSquareBand; 1 when not given).
  double misfit_threshold = 1.0;
  // The fit used a robust loss: scores and M are its psi and H (the rows weighted by
  // sqrt(rho')), and the formal covariance is the M-estimator's sandwich for white
  // residuals (no misfit factor: the sandwich has the residuals' scale).
  bool robust_loss = false;
  // Consider parameters (q of them): J_x^T J_c (n x q), their sigmas in the same units
  // as the Jacobian's columns, and the index of each one's group in `consider_groups`.
  Eigen::MatrixXd consider_cross;
  Eigen::VectorXd consider_sigma;
  std::vector<int> consider_group;
  std::vector<std::string> consider_groups;
  // Threads the parameters' influence series are measured on (the results are the same
  // bits on any number).
  int num_threads = 1;
};

struct ParameterBudget {
  double formal = 0.0;       // sqrt(P_formal)
  double statistical = 0.0;  // sqrt of the statistical variance (formal widened)
  double widening = 1.0;     // statistical / formal
  double tau = 1.0;          // integrated autocorrelation time of its influence series
  double systematic = 0.0;   // sqrt(P_consider)
  double total = 0.0;        // sqrt(statistical^2 + systematic^2)
  std::vector<double> systematic_by_group;  // per consider group, same order
};

struct UncertaintyBudget {
  std::vector<ParameterBudget> parameters;
  Eigen::MatrixXd formal;       // P_formal
  Eigen::MatrixXd statistical;  // widened statistical covariance
  Eigen::MatrixXd systematic;   // P_consider
  Eigen::MatrixXd total;        // P_total
  Eigen::MatrixXd sensitivity;  // S (n x q)
  std::vector<std::string> consider_groups;
  double reduced_chi_square = 0.0;
  double misfit_factor = 1.0;         // sqrt(chi2/nu) when above misfit_threshold, else 1
  int samples = 0;                    // N (rows of scores)
  int bandwidth = 0;                  // L; 0 without scores
  int widest_bandwidth = 0;           // the largest L tried (see P_data above)
  double max_batch_correction = 1.0;  // the largest c_k at L
  double tau = 1.0;                   // largest of the parameters' tau
  double effective_samples = 0.0;     // N / tau
  // The residuals' memory was measured (at least kMinSamplesForCorrelation samples), and
  // they are correlated in time (some tau significantly above 1): P_data used.
  bool correlation_measured = false;
  bool correlated = false;
  bool correlation_reliable = true;  // false: the memory is too long to measure (cap hit)
  bool ok = false;                   // M was invertible
};

// The budget. False (and budget->ok false) when M is not positive definite.
bool ComputeUncertaintyBudget(const BudgetInputs& inputs, UncertaintyBudget* budget);

// Chi-square decrease expected from freeing each candidate (score test), g^T A^-1 g per
// candidate with g_j = J_c,j^T r (plus (c - mean) / sigma^2 when the candidate has a
// prior) and A_j its Schur complement (plus 1 / sigma^2 with a prior). A candidate in
// the span of the free parameters (A_j <= kScoreSpanTolerance * its own J_c^T J_c) gets
// NaN. Inputs: M (n x n), cross = J_x^T J_c (n x q), self = diag(J_c^T J_c) (q) with
// prior information added, gradient g (q).
inline constexpr double kScoreSpanTolerance = 1e-9;
Eigen::VectorXd ScoreTestDecrease(const Eigen::MatrixXd& information, const Eigen::MatrixXd& cross,
                                  const Eigen::VectorXd& self, const Eigen::VectorXd& gradient);

}  // namespace fastcal

#endif  // FASTCAL_UNCERTAINTY_H_
