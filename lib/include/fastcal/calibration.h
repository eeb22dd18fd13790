// Calibration: estimate model parameters from measured poses and tensions by weighted
// least squares (Ceres), with identifiability analysis and uncertainties.
//
//   minimise  sum_samples sum_i rho(r_i^2) + sum_priors ((theta_k - mean_k)/sigma_k)^2
//   r_i = (gain_i T_i(theta; pose) + bias_i - T_measured_i) / sigma_i
// (internal/calibration_model.h). Derivatives are exact: the statics are differentiated
// with ceres::Jet through the converged inner solves (implicit function theorem).
// Physical limits (mass, density, EA, gain > 0) make an evaluation fail, which Ceres
// treats as an infeasible step and answers by shrinking its trust region. We do not
// use Ceres parameter bounds: with bounds its trust-region minimizer adds a projected
// line search with gradient evaluations, a quarter of the time of a calibration, for
// limits that are never approached.
//
// Identifiability: the whitened Jacobian J (data and prior rows) with its columns scaled
// to unit norm, D, has singular values s_1 >= ... >= s_n. A direction with
// s_k / s_1 < undetermined_ratio is one the data and priors cannot determine: the
// calibration is refused before solving and the direction is named as a combination of
// parameters. Above it but below poorly_determined_ratio it is reported.
//
// Calibrate is a pipeline of stages (calibration.cc), each a function over one run's
// state: validate the inputs; measure the forward model's own error; predict the
// readings at the initial model and screen them for gross errors (gross_errors.h); build
// the problem and check the free set is identifiable; solve and reweight (iteratively
// reweighted least squares: weights from the predicted readings, gross errors re-judged
// after each pass until the set settles); the uncertainty budget (uncertainty.h: formal
// covariance (J^T J)^-1, widened by the misfit and the residuals' time correlation,
// plus consider parameters); diagnostics (score test of every fixed parameter, block
// cross-validation, residual autocorrelation, worst readings); the parameter table and
// the verdict.
#ifndef FASTCAL_CALIBRATION_H_
#define FASTCAL_CALIBRATION_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/change_scan.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/gross_errors.h"
#include "fastcal/sensor_steps.h"
#include "fastcal/sessions.h"
#include "fastcal/slow_error.h"
#include "fastcal/uncertainty.h"

namespace fastcal {

struct CalibrationOptions {
  // Called once per solver iteration with a one-line summary; the library never prints.
  std::function<void(const std::string&)> progress;
  // Asked between pieces of work (before each stage, after each solver iteration), on the
  // calling thread: true stops the calibration, which returns kCancelled with nothing
  // more computed (a Python caller's Ctrl-C). Null: never stops.
  std::function<bool()> should_stop;
  // Singular-value ratio below which a direction counts as undetermined (refused).
  double undetermined_ratio = 1e-8;
  // Ratio below which a direction counts as poorly determined (reported).
  double poorly_determined_ratio = 1e-3;
  // |correlation| above which a pair of estimates is reported.
  double strong_correlation = 0.9;
  // A parameter with a prior whose posterior sigma exceeds this fraction of its prior
  // sigma is reported as set mostly by the prior.
  double prior_dominated_fraction = 0.5;
  // Largest standard deviation (predicted before solving from the stated noise, the
  // data's poses and the priors) with which a free parameter still counts as determined.
  // A free set with any parameter above its limit is refused. Relative limits are
  // fractions of the parameter's initial value. Our judgement of "useful", for FAST:
  double max_sigma_mass_centre_m = 0.05;
  double max_sigma_cabin_mass_fraction = 0.05;
  double max_sigma_density_fraction = 0.05;
  double max_sigma_ea_fraction = 0.2;
  double max_sigma_anchor_offset_m = 0.05;
  double max_sigma_tower_offset_m = 0.2;
  double max_sigma_sensor_gain = 0.05;
  double max_sigma_sensor_bias_n = 5e3;
  // Attachments (cable_attachment.h): FAST's sensor assemblies weigh 250-650 kg, its
  // hung lines 0.6-1.6 kg/m; an estimate this uncertain says little about either.
  double max_sigma_attachment_mass_kg = 100.0;
  double max_sigma_attachment_density_kg_per_m = 0.5;
  // A winch encoder's zero (length_offset_m): a decimetre says little about a length.
  double max_sigma_length_offset_m = 0.1;
  // A moving part's first moment: 1500 kg m moves a 30 t cabin's mass centre by 5 cm, the
  // mass centre's own limit. A component with a prior is held to its prior's sigma instead
  // (one along the part's own rotation axis is seen only at second order in the angles:
  // moving_parts.h); a part's mass to 500 kg.
  double max_sigma_part_first_moment_kg_m = 1500.0;
  double max_sigma_part_mass_kg = 500.0;
  // The measured frame's point (measured_frame.h): the tensions see it only through the
  // cables' geometry, so a survey of the cap determines it to about a decimetre
  // (docs/calibration.md, "The measured frame"); a component with a prior is held to the
  // prior's sigma instead, as a first moment's.
  double max_sigma_measured_offset_m = 0.1;
  // A reduced chi-square above this is a fit that failed (the typical residual 5 times
  // the stated noise): the model does not describe the data, and the linearised
  // uncertainties no longer mean anything. Between the band and this the misfit is
  // scaled into the uncertainties (the paper's own fit, 10-20 kN RMS against ~5 kN of
  // sensor noise, is a chi^2/nu of about 4-16: usable, with wider sigmas).
  double failed_fit_reduced_chi_square = 25.0;
  // The verdict is kModelIncomplete when a significant candidate of the misfit ranking
  // (a fixed parameter the data point at beyond noise, CalibrationResult::misfit_ranking)
  // would move a free estimate by more than this many times the uncertainty it would
  // have with the candidate freed (sigma_total widened by the move's own uncertainty):
  // sigma_total cannot contain that error, so neither "ok" nor "misfit scaled" would be
  // honest (docs/calibration.md, "Model incomplete").
  double incomplete_model_sigmas = 3.0;
  // Least-squares passes at most: 2 when nothing changes (weights from the initial
  // model, then from the first fit), more while the set of gross errors still changes.
  int max_passes = 4;
  // A joint fit of sessions whose sensor-step test (sensor_steps.h) accuses a shared bias
  // is fitted again with that bias per session. Off: the accusation is reported only.
  bool separate_stepped_sensors = true;
  // Readings listed as the worst fitted ones (largest |residual| / sigma).
  int worst_readings = 10;
  // The misfit ranking and the consider parameters' sensitivities come from at most this
  // many evenly spaced fitted samples, their sums scaled up (a 64-wide Jet through the
  // statics costs ~25 us a sample): docs/calibration.md, "What would explain the misfit".
  int max_candidate_samples = 20000;
  // The change scan's null draws per round (change_scan.h) and their seed: 1000 place
  // a 1% threshold to about +-0.3% in probability.
  int change_scan_replicates = 1000;
  std::uint64_t change_scan_seed = 1;
  // Evaluate the model before and after (CalibrationResult::variants), the paper's
  // Table 6. Off, Calibrate skips those exact statics passes.
  bool evaluate = true;
};

// A direction in parameter space: weights on parameter names (unit vector in the
// column-scaled parameters; entries below 0.1 in magnitude omitted).
struct ParameterDirection {
  double singular_value_ratio = 0.0;
  std::vector<std::pair<std::string, double>> weights;
  std::string Describe() const;  // "cabin_mass_kg (+0.71) ~ sensor_gain (-0.71)"
};

struct Identifiability {
  std::vector<double> singular_value_ratios;  // s_k / s_1, descending
  // Standard deviation of each free parameter (SI) from (J^T J)^-1; infinite along an
  // undetermined direction.
  std::vector<double> sigma_si;
  std::vector<ParameterDirection> undetermined;  // ratio < undetermined_ratio
  std::vector<ParameterDirection> poorly_determined;
  // For each free parameter, the one its estimate is most correlated with (index into
  // the free parameters; -1 with a single free parameter or an undetermined direction)
  // and that correlation: what the data cannot separate it from.
  std::vector<int> partner;
  std::vector<double> partner_correlation;
};

struct ParameterEstimate {
  std::string name;
  std::string unit;  // of the values below (the spec's unit: kN for biases)
  bool free = false;
  bool consider = false;  // fixed with a prior: its sigma enters the others' budget
  double initial = 0.0;
  double estimate = 0.0;
  // Formal sigma: (J^T J)^-1 for the stated noise and independent samples. 0 if fixed.
  double sigma = 0.0;
  // The uncertainty to quote (uncertainty.h), and its parts: statistical (the formal
  // one widened by what the data show: misfit and time-correlated residuals),
  // systematic (the consider parameters), sigma_total^2 = statistical^2 + systematic^2.
  double sigma_total = 0.0;
  double sigma_statistical = 0.0;
  double sigma_systematic = 0.0;
  double widening = 1.0;  // sigma_statistical / sigma
  double tau = 1.0;       // integrated autocorrelation time of its influence series
  // Systematic part per consider group (CalibrationResult::budget.consider_groups).
  std::vector<double> systematic_by_group;
  bool has_prior = false;
  double prior_mean = 0.0;
  double prior_sigma = 0.0;
  std::string note;  // e.g. "set mostly by its prior"
  // Free estimates only: the misfit ranking's significant candidate that would move this
  // estimate most, when by more than CalibrationOptions::incomplete_model_sigmas, and by
  // how much (in `unit`, and in sigma_total); empty otherwise. Such an estimate is not
  // sound as it stands (FitVerdict::kModelIncomplete).
  std::string moved_by;
  double moved_by_shift = 0.0;
  double moved_by_sigmas = 0.0;
};

// One reading, a tension or (with lengths in the fit) a length: a gross error, or one of
// the worst fitted readings.
struct ReadingResidual {
  int sample = -1;  // index into Dataset::samples
  int line = 0;     // line in the file
  int cable = 0;    // 1 .. 6
  double measured_n = 0.0;
  double predicted_n = 0.0;     // the model's reading at the solution
  double residual_sigma = 0.0;  // (predicted - measured) / sigma at the solution
  bool held_out = false;
  // A length reading (s0_<cable>_m): measured and predicted (s0 + offset) in metres, and
  // measured_n, predicted_n 0. A slipped encoder is a gross error of a length.
  bool length = false;
  double measured_m = 0.0;
  double predicted_m = 0.0;
};

struct GrossErrorSummary {
  bool enabled = false;
  // The threshold used (robust sigmas), the larger of the spec's threshold_sigmas (the
  // floor) and the family-wise one for the readings screened (gross_errors.h).
  double threshold_sigmas = 0.0;
  GrossErrorThreshold threshold;  // how it was chosen; N: every sample's readings
  // Per cable, of the fitted readings' whitened residuals at the solution: median and
  // robust scale (1.4826 MAD, at least 1), and readings flagged (fitted and held out).
  std::array<double, kNumCables> centre{};
  std::array<double, kNumCables> scale{};
  std::array<int, kNumCables> count{};
  int fitted_readings = 0;  // readings of the fitted samples
  int fitted_flagged = 0;
  bool settled = true;  // the flagged set stopped changing before max_passes
  // With lengths in the fit, the same per cable for the length readings (screened on
  // their own: another sensor, another scale).
  std::array<double, kNumCables> length_centre{};
  std::array<double, kNumCables> length_scale{};
  std::array<int, kNumCables> length_count{};
};

// Model minus measured length per cable (m): s0 of the model at the sample's pose plus
// the encoder's offset, against the s0_<i>_m column.
struct LengthResidualStats {
  int samples = 0;
  std::array<int, kNumCables> excluded{};  // gross errors left out, per cable
  std::array<double, kNumCables> mean_m{};
  std::array<double, kNumCables> rms_m{};
  std::array<double, kNumCables> max_abs_m{};
};

// The lengths in a calibration (spec noise.length_sigma_m): their residuals per cable at
// the initial and at the calibrated parameters, over the fitted samples and the held-out
// ones, gross errors left out.
struct LengthEvaluation {
  bool used = false;
  double sigma_m = 0.0;
  LengthResidualStats initial, calibrated;
  LengthResidualStats initial_holdout, calibrated_holdout;  // samples 0: nothing held out
};

// The chi-square decrease expected from freeing a fixed parameter (score test), with
// what freeing it would do (one Gauss-Newton step: exact for a linear model).
struct MisfitCandidate {
  std::string name;
  std::string unit;
  double expected_decrease = 0.0;
  // The score statistic against the noise the residuals actually have (their long-run
  // variance, so time-correlated or misfitting residuals do not inflate it):
  // chi-square with 1 degree of freedom when the parameter explains nothing.
  double statistic = 0.0;
  // statistic above CalibrationResult::misfit_threshold: more than noise alone would
  // give the largest of all the candidates.
  bool significant = false;
  double change = 0.0;  // of the parameter itself, in `unit`
  // value + change is outside the parameter's plausible range (plausibility.h: a negative
  // or tenfold EA, a tower a metre off): the one-step linear extrapolation behind change
  // and shifts is far beyond where it holds. Reports show "beyond the linear range".
  bool beyond_linear_range = false;
  std::vector<double> shifts;  // of each free parameter, in its unit, free order
};

// Block cross-validation (linearised: each block predicted by one Gauss-Newton step
// from the full fit without it; exact for a linear model).
struct CrossValidation {
  int blocks = 0;  // 0: not computed
  int folds_used = 0;
  std::array<double, kNumCables> rms_n{};      // predicted-by-the-rest minus measured
  std::array<double, kNumCables> fit_rms_n{};  // the fit's own, same readings
};

enum class FitVerdict {
  kOk,               // reduced chi-square within its band
  kNoiseOverstated,  // below the band: the sigmas are pessimistic
  kMisfit,           // above the band: the misfit is scaled into sigma_total
  kFailed,           // not converged, or chi^2/nu above failed_fit_reduced_chi_square
  // A fixed parameter the data point at would move a free estimate by more than
  // CalibrationOptions::incomplete_model_sigmas sigma_total (ParameterEstimate::moved_by):
  // the model lacks what the data show, whatever the chi-square says.
  kModelIncomplete,
};
// "ok", "noise overstated", "misfit scaled", "failed", "model incomplete".
const char* FitVerdictName(FitVerdict verdict);

struct CalibrationResult {
  std::vector<ParameterEstimate> parameters;  // every parameter the spec names
  std::vector<std::string> free_names;
  // Correlation of the estimates from the total covariance; free parameters, spec order.
  Eigen::MatrixXd correlation;
  bool covariance_ok = false;
  // The budget of the free parameters (SI units, free order).
  UncertaintyBudget budget;
  // Gross errors among the readings, in file order, and the screen's numbers.
  std::vector<ReadingResidual> gross_errors;
  GrossErrorSummary gross_error_summary;
  ReadingMask excluded;         // per dataset sample: readings kept out (the gross errors)
  ReadingMask length_excluded;  // the same for the lengths (empty without them)
  // The fitted readings with the largest |residual| / sigma, largest first.
  std::vector<ReadingResidual> worst_readings;
  // Every fixed parameter the model has, by the chi-square decrease expected from
  // freeing it, largest first (candidates already spanned by the free set left out).
  std::vector<MisfitCandidate> misfit_ranking;
  // The statistic that the best of q candidates reaches from noise alone with
  // probability 1% (chi-square with 1 degree of freedom at 1 - 0.01 / q).
  double misfit_threshold = 0.0;
  CrossValidation cross_validation;
  // The model against the measurements (exact statics, gross errors left out): the
  // initial model at each attitude the data has, then the calibrated one at the fit's
  // attitude (the last). Empty with CalibrationOptions::evaluate off.
  std::vector<VariantEvaluation> variants;
  // The lengths' residuals before and after (used false without lengths in the fit).
  LengthEvaluation lengths;
  // The slow sensor error the fit whitened by, and what the residuals say of it
  // (spec noise.slow_error; slow_error.h). enabled false: white noise only.
  SlowErrorReport slow_error;
  // Integrated autocorrelation time of each cable's whitened residuals (file order).
  std::array<double, kNumCables> residual_tau{};
  FitVerdict verdict = FitVerdict::kOk;
  std::string verdict_text;                      // one paragraph: what the verdict means here
  std::vector<std::string> notes;                // further facts the report and console show
  std::vector<std::string> strong_correlations;  // "a ~ b: +0.97"
  // With priors, before and after solving; and from the data alone after solving.
  Identifiability before, after, data_only;
  CableRobot calibrated;
  // A joint fit of several sessions (spec sessions.separate, data with two or more
  // sessions: sessions.h); else all empty. The labels (Dataset::session_labels), the
  // calibrated model of each session (`calibrated` is the first's), and each separate
  // parameter's difference between consecutive sessions.
  std::vector<std::string> session_labels;
  std::vector<CableRobot> session_models;
  std::vector<SessionDifference> session_differences;
  // The scan for a change within the survey (spec change_scan; change_scan.h).
  ChangeScanResult change_scan;
  // A joint fit of sessions: the test of sensors re-zeroed between them (sensor_steps.h),
  // from the fit with the spec's shared biases; when it accuses some, the result is that
  // of the fit again with their biases per session (`separated`).
  SensorStepTest sensor_steps;
  std::vector<bool> held_out;  // per dataset sample
  int num_fit_samples = 0;
  int num_residuals = 0;
  int num_free = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double reduced_chi_square = 0.0;
  int iterations = 0;
  bool converged = false;
  std::string termination;
  std::string ceres_brief_report;
  std::string ceres_full_report;
  // The forward model's |T - T_exact| / T_exact over the dataset poses (up to 2000,
  // evenly spaced) at the initial parameters: the model error, next to the noise level.
  double forward_model_max_rel_error = 0.0;
  double forward_model_rms_rel_error = 0.0;
  double seconds = 0.0;
  // Each stage of the pipeline, in order: its wall time, the process's CPU time over it
  // (all threads: cpu_seconds / seconds is how many cores were busy) and the process's
  // peak resident memory at its end (getrusage; 0 where unavailable): where a long
  // dataset's time and memory go (printed by `fastcal calibrate --timings`).
  struct Stage {
    std::string name;
    double seconds = 0.0;
    double cpu_seconds = 0.0;
    double peak_resident_mb = 0.0;
  };
  std::vector<Stage> stages;
};

// Whether the reduced chi-square agrees with the stated noise. For a correct noise model
// chi^2/nu is 1 with a standard deviation of sqrt(2 / nu), nu = residuals - free
// parameters; farther from 1 than kChiSquareBandSigmas of those, the fit is off: model
// error the free parameters cannot absorb, or noise misstated. The report's verdict and
// `fastcal calibrate` use this band.
inline constexpr double kChiSquareBandSigmas = 3.0;
struct ChiSquareBand {
  int degrees_of_freedom = 0;  // nu; <= 0: no band
  double half_width = 0.0;     // kChiSquareBandSigmas sqrt(2 / nu); 0 without a band
  // |chi^2/nu - 1| <= half_width; false without a band or a finite chi^2/nu.
  bool within = false;
};
ChiSquareBand ReducedChiSquareBand(const CalibrationResult& result);

enum class CalibrationStatus {
  kOk = 0,
  kInvalidInput,       // bad spec, dataset, or fewer residuals than free parameters
  kUndetermined,       // the data and priors cannot determine the free set (refused)
  kInfeasible,         // the initial model cannot hold a sample's pose
  kSolverFailed,       // Ceres failed
  kMostlyGrossErrors,  // more than max_gross_error_fraction of the readings flagged
  kCancelled,          // CalibrationOptions::should_stop said so
};

// The model the calibration starts from: `model` with the spec's initial values applied
// (the "initial model" of Calibrate's messages).
CableRobot InitialCalibrationModel(const CableRobot& model, const CalibrationSpec& spec);

// Runs the calibration. On a status other than kOk, *error explains it (for kUndetermined:
// the undetermined combinations and what to fix); `result` then holds what was computed
// (for kUndetermined, `before`).
CalibrationStatus Calibrate(const CableRobot& model, const CalibrationSpec& spec,
                            const Dataset& data, const CalibrationOptions& options,
                            CalibrationResult* result, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_CALIBRATION_H_
