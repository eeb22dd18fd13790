// The calibration problem linearised at its solution, for the uncertainty budget and the
// diagnostics (uncertainty.h, calibration.h). Two passes over the fitted samples:
//
// Free parameters (every fitted sample): the fit's own rows (FittedSamples::Rows) give the
// whitened residuals r_t and J_t (6 x n). Accumulated:
//   J_x^T J_x and its R factor (row_fold.h, as the identifiability check wants it),
//   the scores s_t = J_t^T r_t and r_t (kept per sample, time order: the long-run
//   covariance, the residuals' memory), and per cross-validation block k: J_x^T J_x,
//   J_x^T r, and per cable i the sums of (sigma r)^2, sigma^2 r J_x,i and
//   sigma^2 J_x,i^T J_x,i (tension units).
// J_t itself is kept only on request (the change scan's); otherwise ReplayFreeJacobians
// computes the rows again, in time order, for the budget's batch correction (issue 28:
// 6n floats a sample, 0.5 GB at 10^6 samples and 21 parameters, for a correction only
// correlated residuals need).
//
// Candidates (every fixed parameter the model has): every parameter a spec can name is a
// sum of "basis" parameters (mass centre x, y, z, cabin mass, per cable i density_i,
// EA_i, gain_i, bias_i, every anchor and tower offset axis, every attachment's mass or
// density: 3 + 1 + 24 + 3 * anchor points + 18 + attachments <= kMaxFreeParameters, one
// Jet); a common group's parameter is the sum of its six per-cable
// columns. One basis pass gives B_t (6 x K), so J_x = B_t A_x and J_c = B_t A_c (A: 0/1
// maps), accumulated as J_x^T J_c, diag(J_c^T J_c) and J_c^T r. This pass costs ~25 us a
// sample (a 64-wide Jet through the statics; twice that with attachments, 128 wide), so on long
// datasets it runs on at most LinearisationInputs::max_candidate_samples evenly spaced samples and
// its sums are scaled by N / N_used: J_x^T J_c and diag(J_c^T J_c) involve no noise and are smooth
// along the poses (a quadrature), while J_c^T r then carries N / N_used times its noise (the misfit
// ranking's threshold is raised by that factor).
//
// Readings kept out of the fit (gross errors) have r = 0 and J = 0. With a robust loss,
// each sample's rows are scaled by sqrt(rho'(|r_t|^2)) (its iteratively reweighted
// least-squares weight at the solution).
#ifndef FASTCAL_INTERNAL_CALIBRATION_LINEARISATION_H_
#define FASTCAL_INTERNAL_CALIBRATION_LINEARISATION_H_

#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/row_fold.h"
#include "fastcal/statics.h"
#include "fastcal/uncertainty.h"

namespace fastcal::internal {

struct LinearisationInputs {
  // The fitted samples with the fit's whitening sigmas, exclusions and warm starts (the
  // statics at the solution), through the fit's model (its free set).
  FittedSamples samples;
  const double* theta = nullptr;              // the solution
  const ceres::LossFunction* loss = nullptr;  // the fit's robust loss, or null
  std::vector<ParameterSpec> candidates;      // fixed parameters to differentiate against
  int cross_validation_blocks = 10;
  // Threads of both passes: the results do not depend on it (sample_chunks.h).
  int num_threads = 1;
  int max_candidate_samples = 20000;  // the candidate pass's sample budget (see above)
  // Keep every sample's J_t in Linearisation::jacobians (the change scan needs them).
  bool keep_jacobians = false;
};

struct FoldSums {
  int samples = 0;
  Eigen::MatrixXd information;  // J_x^T J_x (whitened)
  Eigen::VectorXd gradient;     // J_x^T r
  std::array<int, kNumCables> readings{};
  std::array<double, kNumCables> sse_n2{};            // sum (sigma r)^2
  std::array<Eigen::VectorXd, kNumCables> cross_n2;   // sum sigma^2 r J_x,i^T
  std::array<Eigen::MatrixXd, kNumCables> normal_n2;  // sum sigma^2 J_x,i^T J_x,i
};

struct Linearisation {
  Eigen::MatrixXd information;  // J_x^T J_x over the data (no priors; rows weighted)
  // With a robust loss, sum 2 rho'' (J^T r)(J^T r)^T: added to `information` it makes
  // the loss's exact Hessian (Triggs et al. 2000), which Gauss-Newton leaves out and
  // which the M-estimator's sandwich needs. 0 without a loss.
  Eigen::MatrixXd loss_curvature;
  Eigen::MatrixXd r_factor;     // upper triangular R, R^T R = J_x^T J_x
  SampleScores scores;          // s_t, one row per fitted sample (float: uncertainty.h)
  // J_t (6 x n, row after row), one row per fitted sample: with keep_jacobians only.
  SampleJacobians jacobians;
  Eigen::MatrixXd residuals;    // r_t (fitted samples x 6); 0 where excluded
  double chi_square = 0.0;      // sum (w r)^2 over the data, w the robust loss's weight
  double raw_chi_square = 0.0;  // sum r^2 over the data
  int readings = 0;             // readings not excluded
  std::vector<FoldSums> folds;
  // With two or more sessions, per session: J_x^T J_x and J_x^T r over its samples (rows
  // weighted as above), for the test of sensors re-zeroed between sessions
  // (sensor_steps.h). Empty with one session.
  std::vector<Eigen::MatrixXd> session_information;
  std::vector<Eigen::VectorXd> session_gradient;
  // Candidates (scaled to all fitted samples).
  Eigen::MatrixXd cross;         // J_x^T J_c
  Eigen::VectorXd self;          // diag(J_c^T J_c)
  Eigen::VectorXd gradient;      // J_c^T r
  int candidate_samples = 0;     // N_used
  double candidate_scale = 1.0;  // N / N_used, by which the sums above were scaled
  // J_x^T J_x over the candidate pass's samples, scaled like the sums above: the score
  // test's Schur complement is a small difference of large numbers for a candidate near
  // the free parameters' span, so its two terms must come from the same samples.
  Eigen::MatrixXd candidate_information;
  // Per sample of the candidate pass (in time order): J_c,t^T r_t (unscaled), the
  // sample's row in `scores` and its score s_t in double (the score test projects the
  // candidates' scores on these, a difference of nearly equal numbers).
  Eigen::MatrixXd candidate_scores;
  std::vector<int> candidate_rows;
  Eigen::MatrixXd candidate_free_scores;
};

// The basis parameters, in order (all free, no initial: the model's values).
std::vector<ParameterSpec> BasisParameters(const CableRobot& model);
// The basis columns a parameter (of a spec or a candidate) is the sum of.
std::vector<int> BasisColumns(const ParameterSpec& p, const CableRobot& model);

// Both passes. False, with *error naming the sample's line, when the statics fail there.
bool Linearise(const LinearisationInputs& in, Linearisation* out, std::string* error);

// The free pass's J_t again, as Linearisation::jacobians would hold them (the same
// floats), visited in time order (uncertainty.h, SampleJacobianReplay). False when the
// statics fail (they did not in Linearise with the same inputs).
bool ReplayFreeJacobians(const LinearisationInputs& in,
                         const std::function<void(int t, const float* jacobian)>& visit);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_CALIBRATION_LINEARISATION_H_
