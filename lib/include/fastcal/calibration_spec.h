// What a calibration estimates and how: the calibration spec (YAML, docs/calibration.md).
//
// The model's parameters are laid out as scalar "parameters", each free or fixed, with an
// initial value and an optional Gaussian prior:
//   mass_centre_m.{x,y,z}           m     cabin-frame mass centre (initial: the model's)
//   cabin_mass_kg                   kg    (initial: the model's)
//   linear_density_kg_per_m         kg/m  one value for all cables ("common") or
//   linear_density_kg_per_m[i]            one per cable i = 1..6 ("per_cable")
//   ea_n / ea_n[i]                  N     axial stiffness, common or per cable
//   anchor_offset_m[j].{x,y,z}      m     added to cabin anchor point j = 1..n (cabin frame)
//   tower_offset_m[i].{x,y,z}       m     added to tower top i = 1..6 (global frame)
//   sensor_gain / sensor_gain[i]    1     measured = gain * model + bias
//   sensor_bias_kN / sensor_bias_kN[i]  kN
//   attachment_mass_kg[i][j]        kg    point mass j of cable i (cable_attachment.h;
//   attachment_density_kg_per_m[i][j] kg/m  added density j of cable i; j = 1.. counts
//                                         the cable's attachments in the model file)
//   length_offset_m / length_offset_m[i]  m  a winch encoder's zero: measured length =
//                                         unstretched length + offset (needs the lengths
//                                         in the fit: noise.length_sigma_m)
//   moving_parts.NAME.first_moment_kg_m.{x,y,z}  kg m, moving_parts.NAME.mass_kg  kg
//   measured_frame.offset_m.{x,y,z}  m    the measured point in its part's frame
//                                         (measured_frame.h; the model must declare
//                                         cabin.measured_frame)
// Values in the file are in the unit the name carries (kN for the bias); inside
// everything is SI (ParameterSpec::to_si converts).
#ifndef FASTCAL_CALIBRATION_SPEC_H_
#define FASTCAL_CALIBRATION_SPEC_H_

#include <string>
#include <vector>

#include "fastcal/parameter_table.h"
#include "fastcal/slow_error.h"
#include "fastcal/statics.h"

namespace fastcal {

struct ParameterSpec {
  ParameterKind kind = ParameterKind::kMassCentre;
  int index = -1;      // cable, anchor point or tower (0-based); -1 = common to all cables
  int component = -1;  // axis 0..2 for vector quantities, else -1
  std::string name;    // as in the spec and the report, e.g. "mass_centre_m.x"
  std::string unit;    // unit of values in files and reports: m, kg, kg/m, N, 1, kN
  double to_si = 1.0;  // SI value = file value * to_si
  bool free = false;
  bool has_initial = false;  // else the model's value (offsets 0, gain 1, bias 0)
  double initial_si = 0.0;
  // A Gaussian prior. On a free parameter it is added to the fit; on a fixed one it makes
  // it a consider parameter: held at its value, its sigma propagated into the estimates'
  // uncertainty (calibration.h, uncertainty.h).
  bool has_prior = false;
  double prior_mean_si = 0.0;
  double prior_sigma_si = 0.0;
  // The session this parameter belongs to (an index into Dataset::session_labels), or -1:
  // one value shared by every session. Only a joint fit's expanded spec has sessions
  // (sessions.h: SeparateSessionParameters); its name then ends in "@LABEL".
  int session = -1;

  bool IsConsider() const { return !free && has_prior; }
};

// The slow sensor error of the spec (noise.slow_error; slow_error.h): off by default.
// Each part is stated (a number) or estimated from the fit's residuals ("estimate"); at
// most one amplitude part (sigma_percent or sigma_kN) is estimated.
struct SlowErrorSpec {
  bool enabled = false;
  SlowErrorProcess stated;  // the stated parts (SI); an estimated part's entry is unused
  bool estimate_amplitude = false;
  bool amplitude_in_percent = true;  // the estimated part: sigma_percent, else sigma_kN
  bool estimate_time_constant = false;

  bool estimates_any() const { return enabled && (estimate_amplitude || estimate_time_constant); }
  // The process to whiten with before anything is estimated: the stated one, or (for an
  // estimated part) white noise only.
  SlowErrorProcess Initial() const;
};

enum class RobustLoss { kNone, kHuber, kCauchy };
const char* RobustLossName(RobustLoss loss);  // "none", "huber", "cauchy"

struct CalibrationSpec {
  // Every parameter the spec names, free or fixed, in a canonical order (the order of
  // the list in the file header above). Parameters the spec does not name are fixed at
  // the model's values and not listed.
  std::vector<ParameterSpec> parameters;
  // Statics model inside the residuals. exact by default: as fast as aas-refined and
  // right wherever it answers; plain AAS's own 0.1-0.3% error is a bias, not noise, and
  // would shift the estimates (docs/calibration.md).
  StaticsMethod forward_model = StaticsMethod::kExact;
  // Tension noise: sigma_i^2 = sigma_abs^2 + (percent/100 * predicted_i)^2, predicted_i
  // the model's reading (docs/calibration.md: why not the measured one).
  double tension_sigma_n = 0.0;
  double tension_sigma_percent = 3.0;
  // The winches' lengths (the dataset's s0_<i>_m columns) as measurements, each with this
  // sigma (m): rows beside each sample's six tensions, residual (s0_model + offset -
  // measured) / sigma (docs/calibration.md, "Lengths"). 0 (the default): lengths are not
  // used. Needs forward_model exact.
  double length_sigma_m = 0.0;
  bool UsesLengths() const { return length_sigma_m > 0.0; }
  // Slow error of each tension reading, on top of the white noise above (slow_error.h).
  SlowErrorSpec slow_error;
  RobustLoss robust_loss = RobustLoss::kNone;
  double robust_loss_scale = 1.0;  // in units of sigma (whitened residual)
  // Fraction of the samples held out of the fit and used only to evaluate: whole
  // contiguous blocks (the samples cut into `holdout_blocks` blocks in file order, the
  // held ones chosen with `holdout_seed`), since a single sample of a slow trajectory is
  // predicted by its neighbours.
  double holdout_fraction = 0.0;
  unsigned long long holdout_seed = 1;
  int holdout_blocks = 10;
  // Block cross-validation: the fitted samples cut into this many contiguous blocks, each
  // predicted by the fit without it (linearised: one Gauss-Newton step). >= 2.
  int cross_validation_blocks = 10;
  // Gross errors: a reading whose whitened residual is more than
  // `gross_error_threshold_sigmas` robust sigmas (1.4826 MAD of its cable's residuals,
  // at least 1) from its cable's median is kept out of the fit and named. More than
  // `max_gross_error_fraction` of the readings flagged refuses the dataset.
  bool detect_gross_errors = true;
  double gross_error_threshold_sigmas = 5.0;
  double max_gross_error_fraction = 0.25;
  // Attitude used in the fit: the measured one (default) or the planned one.
  bool use_planned_attitude = false;
  // Ceres options. Pass 1 (weights from the initial model) stops at a relative cost
  // decrease of 1e-4 or function_tolerance, whichever is larger; later passes at these.
  int max_iterations = 100;
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  // Threads of every pass over the samples (the fit, the linearisation, the RMS table):
  // the results are the same bits on any number (docs/speed.md, "At 10^5 and 10^6
  // samples"). 1 to kMaxCalibrationThreads.
  int num_threads = 2;
  // Joint fit of several sessions (`sessions: {separate: [...]}`, sessions.h): the free
  // parameters of these groups ("mass_centre_m", ParameterGroupName) get one value per
  // session of the data; every other parameter is shared by all sessions. Empty: the
  // sessions are fitted as one survey.
  std::vector<std::string> separate_groups;
  // The change scan (`change_scan: {...}`, change_scan.h): is there a time at which the
  // free parameters of these groups stepped? Empty: no scan.
  std::vector<std::string> change_scan_groups;
  // Shortest segment on either side of a change, in fitted samples (>= 2 x the free
  // parameters is needed to refit a side; the scan's null distribution depends on it
  // through the trimming fraction).
  int change_scan_min_segment = 50;
  // Family-wise false-alarm probability of each test of binary segmentation.
  double change_scan_significance = 0.01;
  // At most this many changes are reported.
  int change_scan_max_changes = 3;

  bool IsValid(std::string* error) const;
};

// Largest spec file LoadCalibrationSpec reads: a spec is a few KiB.
inline constexpr long long kMaxSpecFileBytes = 16LL << 20;  // 16 MiB
// Most threads a spec may ask for (solver.threads): a pass over the samples uses one per
// 1024 samples at most, and a thread costs memory; 100000 is a slip.
inline constexpr int kMaxCalibrationThreads = 256;

// Parses a spec for `model`. Errors name the file, the line and the key; unknown keys and
// unknown parameter names are errors. The model's anchor points bound anchor_offset_m[j],
// its cables' attachments the attachment groups. Only a regular file of at most
// kMaxSpecFileBytes is read (others are refused before reading).
bool LoadCalibrationSpec(const std::string& path, const CableRobot& model, CalibrationSpec* spec,
                         std::string* error);
bool ParseCalibrationSpecYaml(const std::string& text, const std::string& source_name,
                              const CableRobot& model, CalibrationSpec* spec, std::string* error);
// The same for a model of `num_anchor_points` anchor points whose cables carry no
// attachments.
bool LoadCalibrationSpec(const std::string& path, int num_anchor_points, CalibrationSpec* spec,
                         std::string* error);
bool ParseCalibrationSpecYaml(const std::string& text, const std::string& source_name,
                              int num_anchor_points, CalibrationSpec* spec, std::string* error);
// The spec as YAML (same format), for provenance in summary.json and the report.
std::string CalibrationSpecToYaml(const CalibrationSpec& spec);

// Every parameter a spec can name for a model with `num_anchor_points` anchor points, in
// canonical order: each per-cable group both common and per cable, every offset axis.
// Names, units and to_si as the reader gives them; all fixed, without initial or prior.
// (The candidates of the calibration's misfit ranking.)
std::vector<ParameterSpec> AllModelParameters(int num_anchor_points);
// The same for `model`, its attachments' masses and densities included.
std::vector<ParameterSpec> AllModelParameters(const CableRobot& model);

// Whether `p` names something `model` has: an anchor point it has, and for an attachment
// parameter an attachment of that kind at that position. On failure says why in *error.
bool ParameterFitsModel(const ParameterSpec& p, const CableRobot& model, std::string* error);

// Whether two specs name the same parameter: same kind, and the same axis, cable, anchor
// point or tower where the kind has one (a per-cable group's common parameter, index -1,
// is not any one cable's).
bool SameParameter(const ParameterSpec& a, const ParameterSpec& b);

// The spec's group key of a parameter kind ("sensor_gain", "mass_centre_m", ...).
const char* ParameterGroupName(ParameterKind kind);

}  // namespace fastcal

#endif  // FASTCAL_CALIBRATION_SPEC_H_
