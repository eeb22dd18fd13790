// A scan for a step in some parameters within one survey (docs/calibration.md, "Change
// scan"): is there a time at which, say, the mass centre moved?
//
// At the fit's solution the problem is linearised (calibration_linearisation.h): per
// fitted sample t, in time order, the whitened residuals r_t and their Jacobian J_t
// (6 x n). A step of the p scanned parameters at split k (the first sample after it) is
// the column block Z_t = J_t,G [t >= k]. With the nuisance X_t = [J_t, the steps found
// so far] and M_X = sum X_t^T X_t + priors, its score and information, the free and
// found parameters profiled out (one Gauss-Newton step; exact for a linear model):
//
//   h_k = sum_{t>=k} J_t,G^T r_t - B_k^T M_X^-1 V,    V = sum_t X_t^T r_t + prior gradient
//   S_k = sum_{t>=k} J_t,G^T J_t,G - B_k^T M_X^-1 B_k,  B_k = sum_{t>=k} X_t^T J_t,G
//   W_k = h_k^T S_k^-1 h_k / w^2,   step estimate d_k = -S_k^-1 h_k
//
// W_k is the Wald (= score = likelihood-ratio, for a linear model) statistic of a step at
// k. w widens it as the uncertainty budget widens sigma (uncertainty.h), so that the
// statistic is judged against the noise the residuals actually have: per scanned
// parameter, the long-run variance of its score J_t,G^T r'_t (overlapping batch means at
// the budget's bandwidth) over its white value, the largest, at least 1. The residuals
// r' are those with the round's best step fitted: the fit's own residuals contain the
// step, which would count as misfit and memory and hide itself (the power loss of
// change tests with a long-run variance from the null model, Vogelsang 1999).
//
// The maximum of W_k over the split times is not chi-square (Andrews 1993: its null
// distribution depends on the trimming and, with poses that change along the survey, on
// the design). Its null distribution is drawn here for this very design: white unit
// noise e_t ~ N(0, I) through the same J_t (a parametric bootstrap of the linearised
// model), `replicates` times, each giving max_k W*_k; the p-value is
// (1 + #{max W* >= max W}) / (1 + replicates). Samples are grouped into at most
// kMaxScanUnits consecutive units (splits only between units; sums per unit, and the
// noise of a unit's sum drawn from its information's square root), so the scan costs
// O(units n^2) per replicate whatever the survey's length.
//
// A step or a drift? Beside the steps, the scanned parameters' linear trend over the whole
// survey is tested the same way (Z_t = J_t,G s_t, s_t = (t - mid) / N over the fitted
// samples: s spans one unit, so its estimate is the change over the survey). A single test,
// chi-square with p degrees of freedom without a trend; its statistic against the best
// step's tells the two apart: for a true step the best step explains more (a trend
// captures 3/4 of a mid-survey step's chi-square), for a steady drift the trend does
// (a step captures 3/4 of a trend's). A mass centre that wanders, rather than steps, is
// said to wander (ChangeScanVerdict) when the trend explains at least as much as the best
// step, when binary segmentation needs more than one step, or when the change's time is
// not determined (ChangeScanResult::change_time_*: its interval spans more than
// kMaxStepTimeFraction of the survey).
//
// Several changes: binary segmentation (Vostrikova 1981). Each round scans every segment
// between the changes found so far, with those changes in the nuisance; the segment
// whose maximum is most significant, if below `significance`, adds its change. At most
// max_changes; each side of a split at least min_segment samples.
#ifndef FASTCAL_CHANGE_SCAN_H_
#define FASTCAL_CHANGE_SCAN_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fastcal/time_text.h"
#include "fastcal/uncertainty.h"

namespace fastcal {

// Most split units; a survey with more fitted samples groups them (splits then fall
// between groups of ceil(N / kMaxScanUnits) samples).
inline constexpr int kMaxScanUnits = 2000;

struct ChangeScanInputs {
  // Per fitted sample in time order: whitened residuals (N x rows_per_sample) and their
  // Jacobian (N x rows_per_sample * n, the rows one after the other), as the budget's.
  const Eigen::MatrixXd* residuals = nullptr;
  const SampleJacobians* jacobians = nullptr;
  int rows_per_sample = 6;
  int num_free = 0;
  // Prior information (diag 1/sigma^2, 0 without a prior) and the priors' gradient
  // (theta - mean) / sigma^2 at the solution, per free parameter.
  Eigen::VectorXd prior_information;
  Eigen::VectorXd prior_gradient;
  std::vector<int> scanned;  // free-parameter indices of the scanned parameters
  double widening = 0.0;     // > 0: w fixed at this; 0: measured, as above
  int bandwidth = 1;         // of the batch means: the budget's when correlated, else 1
  int min_segment = 50;      // samples on each side of a split, >= 1
  double significance = 0.01;
  int max_changes = 3;
  int replicates = 1000;  // null draws per round
  std::uint64_t seed = 1;
};

struct DetectedChange {
  int split = 0;  // first fitted sample (row) after the change
  double statistic = 0.0;
  double p_value = 1.0;
  // The scanned parameters' step (later minus earlier, SI, in `scanned` order) and its
  // sigma (widened), from the linear fit with every change found.
  Eigen::VectorXd shift;
  Eigen::VectorXd shift_sigma;
};

struct ChangeScanOutput {
  // The first round (no change yet): W at each admissible split (row of its first
  // sample), the largest, and the statistic the maximum exceeds with probability
  // `significance` under no change.
  std::vector<int> splits;
  std::vector<double> statistic;
  double threshold = 0.0;
  double widening = 1.0;                // the first round's w
  int unit_samples = 1;                 // samples per split unit
  std::vector<DetectedChange> changes;  // in time order
  // The linear trend over the survey (above): its statistic (widened by the first
  // round's w), p-value (chi-square, p degrees of freedom), and the scanned parameters'
  // change over the survey with its sigma; the first round's best step statistic.
  double trend_statistic = 0.0;
  double trend_p_value = 1.0;
  Eigen::VectorXd trend_shift;
  Eigen::VectorXd trend_shift_sigma;
  double best_step_statistic = 0.0;
};

// False, with *error, for inputs that do not fit together (sizes, no scanned
// parameter). Too short a survey for two segments gives an empty scan, not an error.
bool ScanForChanges(const ChangeScanInputs& in, ChangeScanOutput* out, std::string* error);

// A change found by a calibration's scan, in the dataset's terms.
struct FoundChange {
  double time_s = 0.0;  // of the first sample after the change
  int line = 0;         // its line in the file
  int sample = 0;       // its index in the dataset
  double statistic = 0.0;
  double p_value = 1.0;
  // Per scanned parameter (ChangeScanResult::parameters): the step, later minus
  // earlier, and its sigma, in the parameter's unit.
  std::vector<double> shift;
  std::vector<double> shift_sigma;
};

// The change scan of a calibration (CalibrationResult::change_scan).
struct ChangeScanResult {
  bool enabled = false;                 // the spec asked for a scan
  std::vector<std::string> groups;      // as the spec names them
  std::vector<std::string> parameters;  // the scanned free parameters
  std::vector<std::string> units;       // their units
  // The first round's statistic over the split times (time of the first sample after
  // the split), and the threshold its maximum exceeds with probability `significance`
  // when nothing changed.
  std::vector<double> time_s;
  std::vector<double> statistic;
  double threshold = 0.0;
  double significance = 0.0;
  int min_segment = 0;
  int unit_samples = 1;
  int replicates = 0;
  double widening = 1.0;
  std::vector<FoundChange> changes;  // in time order; empty when none was found
  // The linear trend over the survey (ChangeScanOutput's), in the parameters' units, and
  // whether the data show a wandering rather than a step: a change was found and the trend
  // explains at least as much as the best step, or more than one step was needed.
  double trend_statistic = 0.0;
  double trend_p_value = 1.0;
  std::vector<double> trend_shift;
  std::vector<double> trend_shift_sigma;
  double best_step_statistic = 0.0;
  // The first round's change time, as a likelihood-ratio interval: the split times whose
  // statistic is within the chi-square(p) 95% point of the largest (Siegmund 1988's
  // confidence region for a change point, in its simplest form). A sharp step gives a few
  // samples; a gradual change, or a weak one, a wide span.
  double change_time_low_s = 0.0;
  double change_time_high_s = 0.0;
  bool wanders = false;
  // How the data's times read (time_text.h): dates and times in the data's zone when
  // they are Unix times, seconds otherwise; the verdict and the report use it.
  TimeDisplay time_display;
};

// The fraction of the scanned span the change time's interval may cover for a change to
// count as a step: wider, its time is not determined, and the change is reported as
// gradual (a wandering).
inline constexpr double kMaxStepTimeFraction = 0.2;

// From the first round's statistic and times (`scan->statistic`, `time_s`) and its
// changes and trend: the change time's likelihood-ratio interval (change_time_low_s,
// change_time_high_s; `scanned` parameters, the chi-square's degrees of freedom) and
// whether the data show a wandering rather than a step (`wanders`: more than one change,
// a trend that explains at least as much as the best step, or a change time not
// determined, its interval wider than kMaxStepTimeFraction of the scanned times).
void SetChangeTimeAndWandering(int scanned, ChangeScanResult* scan);

// One sentence for the verdict: the changes found (when, how much, p), or that none was;
// with changes, the --sessions-at value that cuts the survey there.
std::string ChangeScanVerdict(const ChangeScanResult& scan);

// The value of --sessions-at that cuts the survey at the changes found ("" for none):
// each change's time (of its first sample), ISO 8601 with the data's zone for Unix times
// (to the microsecond: a cut takes samples within 1 us of it as after it).
std::string SessionsAtText(const ChangeScanResult& scan);

// The times of the changes a previous calibration found, from its summary.json (its
// "changes", each "time_s" written to 17 digits), for fastcal calibrate
// --sessions-at=DIR/summary.json. False, with *error naming the file, when it cannot be
// read, is not a calibration's summary.json, had no change scan, or found no change.
bool ReadSummaryChangeTimes(const std::string& path, std::vector<double>* times_s,
                            std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_CHANGE_SCAN_H_
