// The calibration problem linearised at its solution, one pass over the fitted samples,
// for the uncertainty budget and the diagnostics (uncertainty.h, calibration.h).
//
// Every parameter a spec can name is a sum of "basis" parameters: mass centre x, y, z,
// cabin mass, and per cable i: density_i, EA_i, gain_i, bias_i, with every anchor and
// tower offset axis (3 + 1 + 4 * 6 + 3 * anchor points + 18 <= 64, one ceres::Jet). A
// common group's parameter (all cables at once) is the sum of its six per-cable columns.
// So one Jet pass through the statics gives, per sample t, the whitened residuals r_t
// and the basis Jacobian B_t (6 x K), and from it the free Jacobian J_x = B_t A_x and
// that of every fixed candidate J_c = B_t A_c (A: 0/1 maps). Accumulated:
//   J_x^T J_x, the scores s_t = J_x^T r_t (kept per sample, time order),
//   J_x^T J_c, diag(J_c^T J_c), J_c^T r             (score test, consider parameters)
//   per cross-validation block k: J_x^T J_x, J_x^T r, and per cable i the sums of
//   (sigma r)^2, sigma^2 r J_x,i and sigma^2 J_x,i^T J_x,i        (tension units, N)
// Readings kept out of the fit (gross errors) have r = 0 and J = 0. With a robust loss,
// each sample's rows are scaled by sqrt(rho'(|r_t|^2)) (its iteratively reweighted
// least-squares weight at the solution).
#ifndef FASTCAL_INTERNAL_CALIBRATION_LINEARISATION_H_
#define FASTCAL_INTERNAL_CALIBRATION_LINEARISATION_H_

#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/statics.h"
#include "fastcal/uncertainty.h"

namespace fastcal::internal {

struct LinearisationInputs {
  CableRobot at_solution;  // the calibrated model
  const Dataset* data = nullptr;
  std::vector<int> fit;  // fitted samples, dataset indices in file order
  // Per fitted sample: the fit's whitening sigmas, and the statics at the solution
  // (warm starts; status other than ok starts cold).
  std::vector<std::array<double, kNumCables>> sigma_n;
  std::vector<StaticsSolution> starts;
  ReadingMask excluded;  // per dataset sample; may be empty
  bool use_planned_attitude = false;
  StaticsOptions statics;
  const ceres::LossFunction* loss = nullptr;  // the fit's robust loss, or null
  std::vector<ParameterSpec> free;            // the free parameters, in theta order
  std::vector<ParameterSpec> candidates;      // fixed parameters to differentiate against
  int cross_validation_blocks = 10;
  int num_threads = 1;
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
  Eigen::MatrixXd information;  // J_x^T J_x over the data (no priors)
  Eigen::MatrixXd scores;       // s_t, one row per fitted sample
  SampleJacobians jacobians;    // J_x,t (6 x n, row after row), one row per fitted sample
  Eigen::MatrixXd cross;        // J_x^T J_c
  Eigen::VectorXd self;         // diag(J_c^T J_c)
  Eigen::VectorXd gradient;     // J_c^T r
  Eigen::MatrixXd residuals;    // r_t (fitted samples x 6); 0 where excluded
  double chi_square = 0.0;      // sum r^2 over the data
  int readings = 0;             // readings not excluded
  std::vector<FoldSums> folds;
};

// The basis columns a parameter (of a spec or a candidate) is the sum of; indices into
// the basis of BasisParameters(num_anchor_points).
std::vector<int> BasisColumns(const ParameterSpec& p, int num_anchor_points);
// The basis parameters, in order (all free, no initial: the model's values).
std::vector<ParameterSpec> BasisParameters(int num_anchor_points);

// One pass. False, with *error naming the sample's line, when the statics fail there.
bool Linearise(const LinearisationInputs& in, Linearisation* out, std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_CALIBRATION_LINEARISATION_H_
