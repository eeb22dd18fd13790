// Identified modes: the dominant frequencies and damping ratios of a record of the cabin's
// free vibration (after a disturbance), by the eigensystem realisation algorithm (ERA:
// Juang and Pappa 1985, "An eigensystem realization algorithm for modal parameter
// identification and model reduction", J. Guid. Control Dyn. 8(5)), with bootstrap
// uncertainties; and the synthetic records the tests (and the docs) identify.
//
// ERA on a free decay y_k (p channels, k = 0..n-1, evenly spaced by dt): the block Hankel
// matrices H0 = [y_{i+j}] and H1 = [y_{i+j+1}] (r block rows); H0 = U S V^T truncated to
// the model order m; A = S^-1/2 U^T H1 V S^-1/2, C = the first p rows of U S^1/2,
// x0 = the first column of S^1/2 V^T. Each eigenvalue z of A is a pole s = ln(z)/dt:
// f = |s| / 2 pi, zeta = -Re(s) / |s|; its amplitude in the record |C psi| |q0| (psi the
// eigenvector, q0 = Psi^-1 x0). The order is over-specified (noise takes the extra
// poles) and the modes with the largest amplitudes kept.
//
// Uncertainty: the record's residual after the identified modes is resampled in blocks
// (a moving-block bootstrap; Kuensch 1989, Ann. Statist. 17) onto the identified modes'
// reconstruction and identified again; each mode's sigma is the spread of its frequency
// and damping over those records.
#ifndef FASTCAL_MODAL_IDENTIFICATION_H_
#define FASTCAL_MODAL_IDENTIFICATION_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/modes.h"
#include "fastcal/pose.h"

namespace fastcal {

// An evenly sampled record: one row per channel (e.g. x, y, z, roll, pitch, yaw, tensions,
// each in its own unit: ERA scales each channel by its standard deviation first).
struct VibrationRecord {
  double sample_interval_s = 0.1;
  Eigen::MatrixXd channels;  // channels x samples
};

struct EraOptions {
  // Physical modes sought: the record's `modes` largest are returned.
  int modes = 3;
  // Poles beyond 2 * modes in the realisation, for the noise (over-specification).
  int extra_order = 8;
  // The band of the modes sought (Hz). The record is averaged over blocks of D samples,
  // D the largest that keeps 4 samples a period of max_frequency_hz (an FIR filter and a
  // decimation: a damped sinusoid stays one, with its frequency and damping), and the
  // Hankel matrices span two periods of min_frequency_hz: a span much shorter than the
  // modes' periods left the damping biased high by 30-85% at FAST's 0.4-1.5%.
  double min_frequency_hz = 0.1;
  double max_frequency_hz = 0.5;
  // Block rows of the Hankel matrices; 0: from min_frequency_hz as above (at least what
  // the order needs).
  int block_rows = 0;
  // Poles with a damping ratio outside (0, max_damping_ratio) are not modes of a barely
  // damped structure.
  double max_damping_ratio = 0.2;
  // Bootstrap records for the sigmas (>= 2), and their generator's seed.
  int bootstrap_records = 20;
  std::uint64_t seed = 1;
  // Block length of the residual's resampling (samples).
  int bootstrap_block = 50;

  bool IsValid(std::string* error) const;
};

struct IdentifiedMode {
  double frequency_hz = 0.0;
  double frequency_sigma_hz = 0.0;
  double damping_ratio = 0.0;
  double damping_sigma = 0.0;
  double amplitude = 0.0;  // in the record's scaled units: the mode's share of the motion
};

// The record's modes, ascending in frequency. False with *error for a record too short or
// options invalid, or when fewer modes than asked are found.
bool IdentifyModesEra(const VibrationRecord& record, const EraOptions& options,
                      std::vector<IdentifiedMode>* modes, std::string* error);

// Whether a record is a free decay (ERA) or ambient (SSI, subspace_identification.h): a
// free decay's envelope falls, an ambient record's is stationary. The ratio
//     rho = (mean square of the first quarter) / (mean square of the last quarter)
// of the channels, each centred and scaled by its spread and summed, is about
// exp(1.5 zeta omega T) for a free decay of length T (the quarters' centres 3T/4 apart:
// 9.6 for zeta 0.004 at 0.15 Hz over 400 s, 290 for 0.01) and about 1 for a stationary
// record. 1 for a record of fewer than 4 samples or a flat last quarter.
double EnvelopeDecayRatio(const VibrationRecord& record);
// A record whose rho reaches this is taken for a free decay (`fastcal modes --data
// --identification=auto`): its amplitude halves from the first quarter to the last.
inline constexpr double kFreeDecayRatio = 4.0;

// A free decay by modal superposition: channel c at time t = k dt is
//   sum_j shape(c, j) exp(-zeta_j w_j t) cos(w_d,j t + phase_j) + noise_c,
// w_j = 2 pi f_j, w_d = w_j sqrt(1 - zeta^2), noise white Gaussian with sigma noise_sigma[c].
struct FreeDecaySpec {
  std::vector<double> frequency_hz;
  std::vector<double> damping_ratio;
  std::vector<double> phase_rad;  // per mode; empty: all 0
  Eigen::MatrixXd shape;          // channels x modes: each mode's amplitude per channel
  Eigen::VectorXd noise_sigma;    // per channel
  double sample_interval_s = 0.1;
  double duration_s = 400.0;
  std::uint64_t seed = 1;
};
bool SimulateFreeDecay(const FreeDecaySpec& spec, VibrationRecord* record, std::string* error);

// A record of the cabin's free vibration at a pose from the linearised model (modal
// superposition of predicted modes): channels x, y, z (m), roll, pitch, yaw (deg) and the
// six lower-end tensions (kN), absolute (the equilibrium plus the motion plus noise). The
// pose channels follow the modes' cabin shapes; the tensions follow the cabin's motion
// quasi-statically (their change with the pose at fixed unstretched lengths, by central
// differences of the catenary): a record for the tests and the docs, not a simulation of
// the cables' own tension waves.
struct VibrationRecordSpec {
  std::vector<int> modes = {1, 2, 3};                        // 1-based predicted modes excited
  std::vector<double> damping_ratio = {0.005, 0.01, 0.015};  // one per mode
  double amplitude_m = 0.05;  // each mode's largest displacement of O' at t = 0
  double sample_interval_s = 0.1;
  double duration_s = 400.0;
  double position_noise_m = 0.002;
  double attitude_noise_deg = 0.005;
  double tension_noise_kn = 0.5;
  std::uint64_t seed = 1;
  ModesOptions modes_options;
};
bool SimulateVibrationRecord(const CableRobot& robot, const Pose& pose,
                             const VibrationRecordSpec& spec, VibrationRecord* record,
                             std::string* error);

// The model's parameters whose change the comparison measures: the cables' linear
// density (all six together), the cabin's mass and its inertia (scaled as a whole).
inline constexpr int kModeParameters = 3;
const char* ModeParameterName(int parameter);  // "linear_density", "cabin_mass", "cabin_inertia"

// One identified mode against the prediction at the record's pose.
struct ModeComparison {
  IdentifiedMode identified;
  int predicted_mode = 0;  // 1-based, the nearest predicted in frequency
  double predicted_hz = 0.0;
  double predicted_cabin_share = 0.0;
  // (identified - predicted) / predicted, and its sigma from the identification's.
  double difference = 0.0;
  double difference_sigma = 0.0;
  // d ln f / d ln p of the predicted mode for each parameter (by a 1% step).
  std::array<double, kModeParameters> sensitivity{};
};

// What the differences point to: for each parameter alone, the relative change that best
// explains them (weighted least squares over the modes, weights 1/sigma^2), its sigma and
// the fit's chi-square (degrees of freedom: modes - 1). The smallest chi-square is the
// best single explanation; none is when every chi-square is large.
struct ParameterFit {
  double relative_change = 0.0;
  double sigma = 0.0;
  double chi2 = 0.0;
};

struct ModesComparisonResult {
  std::vector<ModeComparison> modes;
  std::array<ParameterFit, kModeParameters> fits{};
  int best = 0;  // the parameter with the smallest chi-square
  // sum (difference / sigma)^2 with no parameter changed (degrees of freedom: modes), and
  // whether it lies within what noise gives (below modes + 3 sqrt(2 modes)): then the
  // record agrees with the model and the fits point to nothing.
  double chi2_model = 0.0;
  bool agrees = false;
};

// Compares `identified` with the predicted modes at `pose` (ComputeModes with `options`;
// its `modes` lowest are searched for the nearest). False with *error when the prediction
// fails.
bool CompareWithPrediction(const CableRobot& robot, const Pose& pose,
                           const std::vector<IdentifiedMode>& identified,
                           const ModesOptions& options, ModesComparisonResult* result,
                           std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_MODAL_IDENTIFICATION_H_
