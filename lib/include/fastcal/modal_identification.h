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

// EraOptions' bounds (its IsValid): the Hankel matrices' Grams, (block rows x channels)^2,
// stay within tens of MB and their eigenproblem within seconds.
inline constexpr int kMaxIdentifiedModes = 20;  // FAST's band holds about 20 modes
inline constexpr int kMaxEraExtraOrder = 50;
inline constexpr int kMaxEraBlockRows = 200;
inline constexpr double kMaxEraBandRatio = 10.0;  // max_frequency_hz / min_frequency_hz
inline constexpr int kMaxBootstrapRecords = 1000;

// Which identified poles are modes (IdentifyModesEra): FAST's lowest modes lie 2-20% apart,
// so a frequency uncertain by more than 5% cannot be told from its neighbours; and a
// mode carries at least 1e-3 of the largest one's amplitude (below, a numerical residue
// of the realisation, not a vibration a record shows).
inline constexpr double kMaxRelativeFrequencySigma = 0.05;
inline constexpr double kMinRelativeAmplitude = 1e-3;

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

// The most periods of EraOptions::min_frequency_hz a record may span: a mode damped by
// 0.5% (FAST's least damped) has decayed to 3e-6 of its start after 400 periods; longer
// is no free decay (issue 57: 10^6 rows every 0.1 s took over 600 s and 2.2 GB).
inline constexpr double kMaxRecordPeriods = 400.0;

// Whether `record` can show modes in the options' band, before any work: a sample at
// least every 1 / (4 max_frequency_hz) s (4 a period of the fastest mode sought), a span
// of at most kMaxRecordPeriods periods of min_frequency_hz and of at least four times the
// Hankel matrices' block rows (two periods of min_frequency_hz), at most
// kMaxRecordSamples samples. False with *error saying which, in seconds (issue 57: a
// record re-stamped every 1e-12 s gave modes at 1.5e10 Hz, one every 1000 s modes at
// 1.5e-8 Hz, and a cabin mass change of -280%).
bool CheckRecordSampling(const VibrationRecord& record, const EraOptions& options,
                         std::string* error);

// The record's modes, ascending in frequency. False with *error for a record that
// CheckRecordSampling refuses, samples not finite, options invalid, or when fewer modes
// than asked are found in the band or determined by the record (kMaxRelativeFrequencySigma,
// kMinRelativeAmplitude).
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

// The largest amplitude a simulated free vibration may have: the linearisation about the
// equilibrium holds for small motions (FAST's cabin vibrates by millimetres to
// centimetres); a metre is already far beyond them.
inline constexpr double kMaxVibrationAmplitudeM = 1.0;
// The smallest share of an excited mode's kinetic energy in the cabin: below it the
// cables carry the rest, and scaling the cabin's motion to amplitude_m swings them
// sqrt((1 - share) / share * m_cabin / m_cables) times further (FAST: 37 times at 1e-3).
inline constexpr double kMinExcitedCabinShare = 1e-3;
// The most samples a vibration record may hold (simulated or read: modes --data): a free
// decay of FAST's modes (0.1-0.5 Hz, damped by 0.5-1.5%) is over within an hour, which is
// 3.6e5 samples at 100 Hz. A record holds 96 bytes a sample (12 channels of doubles).
inline constexpr long long kMaxRecordSamples = 1000000;

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
  // Each mode's largest displacement at t = 0 of a point of the cabin: its origin O' or
  // an anchor point (issue 57: scaled by O' alone, a pure yaw mode, which barely moves
  // O', was scaled by 1e11). In (0, kMaxVibrationAmplitudeM].
  double amplitude_m = 0.05;
  double sample_interval_s = 0.1;
  // At most kMaxRecordSamples samples: duration_s / sample_interval_s + 1.
  double duration_s = 400.0;
  double position_noise_m = 0.002;
  double attitude_noise_deg = 0.005;
  double tension_noise_kn = 0.5;
  std::uint64_t seed = 1;
  ModesOptions modes_options;

  // False with *error naming the field: no modes, a damping ratio short, amplitude_m
  // outside (0, kMaxVibrationAmplitudeM], noise < 0, more than kMaxRecordSamples samples,
  // invalid modes_options.
  bool IsValid(std::string* error) const;
};

// False with *error (naming the spec's field) for a spec IsValid refuses, a mode
// with too little of its energy in the cabin to be seen in its motion (under
// kMinExcitedCabinShare), or a motion that leaves what the linearisation and the cables
// can take (a cable's tension below zero, a pose beyond the plausibility limits).
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
  // (identified - predicted) / predicted, and its sigma: the identification's and the
  // prediction's own (prediction_sigma, relative: the lumped chain's discretisation,
  // (f_N - f_N/2) / 3 of N and N/2 segments), in quadrature.
  double difference = 0.0;
  double difference_sigma = 0.0;
  double prediction_sigma = 0.0;
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

// The comparison as CSV (`fastcal modes --data`, docs/cli.md): mode, frequency_hz,
// frequency_sigma_hz, damping_ratio, damping_sigma, predicted_mode, predicted_hz,
// predicted_kind (cabin or cable), difference_percent, difference_sigma_percent, then
// dlnf_dln_<parameter> per ModeParameterName.
std::string ModesComparisonCsv(const ModesComparisonResult& result);

}  // namespace fastcal

#endif  // FASTCAL_MODAL_IDENTIFICATION_H_
