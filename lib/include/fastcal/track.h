// Tracking over months (docs/calibration.md, "Tracking"): the mass centre and the sensors
// through a season of telemetry, as one joint fit whose sessions are windows (days, by
// default), at a scale where one dense problem is wrong.
//
// The telemetry (many files in any order, or one long file; absolute times) is cut into
// windows: calendar days in UTC ("1d"), another duration aligned to 1970-01-01T00:00Z
// ("6h", "7d"), or one per file. The spec's sessions.separate groups (sessions.h) are the
// per-window parameters a_w (the mass centre, in calibration_data/spec_track.yaml); every
// other free parameter b is shared by all windows (densities, gains, biases), and each
// consider parameter is held at its value with its sigma propagated. Each window is folded
// at a linearisation point into its information over (a_w, b) (track_fold.h: whitened by
// the slow sensor error, gross errors screened), and the block-arrow normal equations are
// solved by the Schur complement on b and back-substitution (internal/block_arrow.h);
// Gauss-Newton iterates folds and solves, re-estimating the slow error's amplitude and
// time constant from the windows' residuals, until every step is below
// TrackOptions::step_tolerance_sigmas of its sigma.
//
// sigma_total per window: the sandwich covariance of the joint fit (uncertainty.h's
// P = M^-1 (Omega + Lambda) M^-1) with each window's information scaled by its widening
// f_w = max(its Birge ratio chi2/nu when above the band 1 + 3 sqrt(2/nu), the variance of
// its block scores over their white value when significant at 1%: residuals correlated in
// time that the slow-error model left), plus the consider parameters' part.
//
// Events, each kind at family-wise false-alarm rate TrackOptions::false_alarm over the
// whole season (Bonferroni over every test of the kind), on one time line: a change may
// happen between two windows or inside one (before any block of its fold).
//   sensor     a shared sensor bias that stepped (re-zeroed): the score test of "the bias
//              differs from window w on" (as sensor_steps.h, with the per-window
//              parameters profiled out, over the whole stretch), over every cable and
//              window boundary; the largest significant one is fitted (the bias gets a
//              value per stretch) and the scan repeated (binary segmentation); then each
//              step is moved to its most likely cut (into the window before or after,
//              unless the boundary is within the likelihood interval). A re-zeroed sensor
//              is then a sensor event, not a mass-centre move.
//   parameter  a per-window group (the mass centre's three axes together) that changed:
//              each candidate cut tested with the whole stretches before and after it
//              (their windows' estimates, the window's two parts from its block rows:
//              track_segment.cc), several by binary segmentation with re-testing, the
//              group's wander estimated with the steps found taken out.
// An event between windows is dated between the last sample before it and the first
// after; one inside a window at the block of largest likelihood, with its likelihood
// interval (TrackEvent::time_low_s, time_high_s).
//
// Outputs in DIR (WriteTrack; formats in docs/calibration.md, "Tracking: files"):
// track.csv, events.json, model_calibrated@WINDOW.yaml (the latest window, and one per
// event-free stretch), track.html; and the track's state for an update: track_state.json,
// folds/ (each window's fold at its last point), windows/ (each window's samples).
// A later run with more files updates the track: only the windows that gained samples are
// folded; the others keep their folds (their quadratic models at their own points, exact
// for a linear model, to first order otherwise: TrackOptions::refold_all refolds them).
#ifndef FASTCAL_TRACK_H_
#define FASTCAL_TRACK_H_

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/slow_error.h"
#include "fastcal/track_fold.h"

namespace fastcal {

// The longest window: a year (366 d). A window is a part of a season (a day, a week);
// one longer than the season holds it all and tracks nothing (issue 57: --window=1e9d,
// 2.7 million years, was accepted).
inline constexpr double kMaxWindowS = 366.0 * 86400.0;

struct WindowSpec {
  enum class Kind { kDuration, kFile };
  Kind kind = Kind::kDuration;
  // kDuration: windows [k d, (k + 1) d) of time_s, k an integer: for Unix times (time_s
  // >= 1e8) aligned to 1970-01-01T00:00:00Z, so "1d" is a calendar day in UTC. A whole
  // number of seconds, from 1 to kMaxWindowS.
  double duration_s = 86400.0;
  // The windows' boundaries moved from the epoch's alignment by origin_s (s, in [0,
  // duration_s)): with "@12:00+08:00" they fall at local noon in UTC+8 (04:00 UTC), so
  // that a night's observing in Beijing is one day's window (issue 59). The labels are
  // then the window start's date (and time) on that clock, label_offset_s east of UTC.
  double origin_s = 0.0;
  int label_offset_s = 0;
  bool has_origin = false;
  bool IsValid(std::string* error) const;
};

// "1d" (the default), "12h", "30m", "3600s", "7d", each optionally "@HH:MM" with a zone
// ("@12:00+08:00", "@00:00Z"; none: UTC) where its boundaries fall; "file": one window per
// file.
bool ParseWindowSpec(const std::string& text, WindowSpec* window, std::string* error);
std::string WindowSpecText(const WindowSpec& window);

// Runs folds: each task's bytes (SerializeFoldTask) to the fold's bytes
// (SerializeWindowFold), in the same order. The track's own runner folds on threads;
// Python's sends them to Dask workers (fastcal.track).
using FoldRunner = std::function<bool(const std::vector<std::string>& tasks,
                                      std::vector<std::string>* folds, std::string* error)>;

// Largest data file a track reads (TrackOptions::read).
inline constexpr long long kTrackMaxFileBytes = 1LL << 40;

struct TrackOptions {
  // One line per stage and iteration; the library never prints.
  std::function<void(const std::string&)> progress;
  // Asked between pieces of work (before each stage, each data file read, each
  // iteration's folds), on the calling thread: true stops the run, which returns
  // kCancelled and leaves the track as it was (a Python caller's Ctrl-C). Null: never.
  std::function<bool()> should_stop;
  // Folds run at once on this machine (one window each; a lone window uses them all).
  // 1 to kMaxCalibrationThreads (256).
  int threads = 2;
  // Null: fold on this machine's threads.
  FoldRunner runner;
  // How the data files are read (DatasetReadOptions: skip_invalid_rows, limits, a
  // column map). skip_invalid_rows also leaves out the samples the initial model cannot
  // solve (as calibrate's), named in the notes; without it such a sample stops the run
  // naming its file, line and why. Each file is streamed a chunk at a time into the window store,
  // so that a season in one long file is read with bounded memory: files up to 1 TiB (not
  // ReadDataset's 1 GiB).
  DatasetReadOptions read = [] {
    DatasetReadOptions r;
    r.max_file_bytes = kTrackMaxFileBytes;
    return r;
  }();
  // Gauss-Newton iterations (each a fold of the windows that moved) at most.
  int max_iterations = 20;
  // A new track's first folds, from the initial model, read every k-th sample of a window
  // of at least twice this many (k = samples / this, rounded down), and every sample of
  // the run the slow error is estimated from (FoldTask::stride): their steps only bring
  // the point to within the subsample's noise of the solution and settle the slow error
  // (at most 4 of them), and the folds of every sample after them reach the solution in
  // two (issue 41: at 10^7 samples, 3 folds of every sample and one of a fifth became
  // 2 and 3 of a twentieth). Where the slow error is estimated (and max_iterations > 3),
  // the very first of them reads one sample in 4k of the windows the others stride (at
  // least min_window_samples) and no residual run: its step only brings the point near,
  // and the estimate starts from the second. 0: every sample; otherwise at least
  // min_window_samples. Not with max_iterations = 1.
  long long first_fold_samples = 5000;
  // Converged when every parameter's step is below this fraction of its formal sigma.
  // The consider parameters' columns are folded with an iteration whose step may be the
  // last (the step before it below about sqrt(5000 x this) sigma); where the converged
  // iteration's fold lacks them, one more fold at the solution adds them (the estimates'
  // change over it is of the order of the step squared).
  double step_tolerance_sigmas = 0.05;
  // Each kind of event: the chance that noise alone reports any over the whole season.
  double false_alarm = 0.01;
  // Sensor steps fitted at most (binary segmentation).
  int max_sensor_steps = 10;
  // Windows with fewer samples are left out (listed in the notes): a window must
  // determine its own parameters.
  long long min_window_samples = 100;
  // Blocks of each window's fold (track_fold.h) and the slow-error estimate's budget.
  int blocks = 32;
  int slow_error_samples = 100000;
  // An update (DIR holds a track): refold every window at the new point, not only those
  // that gained samples.
  bool refold_all = false;
  // Build the track afresh from the data whatever DIR holds (else a track of another
  // model, spec or windowing, of files that changed, or a damaged one is refused; a
  // matching one is updated).
  bool force = false;
  // Files whose time spans overlap are refused (the same instants given twice, e.g. a day
  // re-sent with another name, would be folded twice); true folds them all, for files
  // that really are of one time (two exports split by channel would not be: one sample
  // per instant is what a dataset holds).
  bool keep_overlapping = false;
  bool IsValid(std::string* error) const;
};

struct TrackEstimate {
  double value = 0.0;        // in the parameter's unit
  double sigma_total = 0.0;  // sandwich (widened) + consider
  double sigma_formal = 0.0;
};

struct TrackWindow {
  std::string label;  // "2024-05-01", "2024-05-01T0600Z", "t86400", or the file's stem
  double start_s = 0.0, end_s = 0.0;  // bounds (per file: its first and last sample)
  double first_time_s = 0.0, last_time_s = 0.0;
  long long samples = 0, readings = 0, gross_errors = 0;
  double chi_square = 0.0, reduced_chi_square = 0.0;
  double widening = 1.0;                   // f_w (variance factor)
  std::vector<TrackEstimate> estimates;    // per TrackResult::window_parameters
  std::array<double, kNumCables> rms_n{};  // model minus measured, fitted readings
  // What each shared per-cable bias reads in this window (the shared value of its
  // stretch plus the window's own departure, one Gauss-Newton step; slow errors included
  // in its sigma): the sensors' offsets over time. has_offsets false without such biases.
  bool has_offsets = false;
  std::array<TrackEstimate, kNumCables> offset_kn{};
  bool folded = false;  // folded in this run (an update keeps the others' folds)
};

struct TrackShared {
  std::string name, unit;  // the spec's
  TrackEstimate estimate;
  // A bias split by sensor steps: the windows [from, to] this value holds for.
  int from_window = 0, to_window = 0;
};

struct TrackEventParameter {
  std::string name, unit;
  double shift = 0.0;  // later minus earlier, in `unit`
  double sigma_total = 0.0;
};

// A window's per-window parameters in one part of it, before or after a change inside its
// telemetry (TrackEvent::before, ::after).
struct TrackWindowPart {
  double start_s = 0.0, end_s = 0.0;  // the part's bounds: the window's and the change's
  long long samples = 0;
  // The event's parameters in this part (value in their unit, sigma_total): to first
  // order the window's estimate less (before) or plus (after) its share of the step, with
  // the part's own covariance in place of the window's.
  std::vector<TrackEstimate> estimates;
};

struct TrackEvent {
  std::string kind;  // "parameter" or "sensor"
  // The first sample of the later window, and the last of the earlier one; or, when the
  // step is inside a window's telemetry (within_window), the first sample of the block
  // where it is and the last of the block before.
  double time_s = 0.0;
  double previous_time_s = 0.0;
  bool within_window = false;
  // The change's likelihood interval (Hinkley 1970): between windows, the last sample
  // before and the first after (previous_time_s, time_s); inside a window, the cuts
  // between its blocks whose likelihood is within the 95% drop (7.35) of the
  // best's.
  double time_low_s = 0.0, time_high_s = 0.0;
  int window = 0;           // index of the window the new value is first seen in
  int previous_window = 0;  // index of the last window before the change
  std::vector<TrackEventParameter> parameters;
  std::vector<int> cables;  // 1-based, for a sensor event
  int degrees_of_freedom = 1;
  double statistic = 0.0;
  double threshold = 0.0;
  // Family-wise: min(1, tests x P(chi-square > statistic)); the event's is below
  // TrackOptions::false_alarm.
  double p_value = 1.0;
  // Not among the events the track's previous run reported (track_state.json): none of
  // them of its kind and cables has an interval that overlaps this one's. Every event of
  // a track built afresh (a new DIR, --force) is new.
  bool is_new = true;
  // A parameter change inside a window's telemetry (within_window): the window in its two
  // parts, reported in track.csv and as two models instead of the window's average, a
  // value the cabin never had. Empty otherwise.
  std::vector<TrackWindowPart> parts;
};

// A per-window group's wander, in two parts: between windows (day to day) beyond its
// estimates' errors, and inside the windows. The events are steps beyond both.
//   rms     between windows: the variance per component that, added to each window's,
//           brings the median of the consecutive windows' difference statistics to the
//           chi-square median (a wander of the days' levels);
//   inside  a first-order Gauss-Markov process per component within each window (the mass
//           centre moving about within an observing day), its variances and time constant
//           estimated by REML from the windows' block scores (internal/inner_wander.h); in
//           every window's, shift's and shared parameter's sigma_total.
struct TrackWander {
  std::string group;  // "mass_centre_m", or the parameter's name
  std::string unit;
  double rms = 0.0;  // between windows: sqrt of the variance per component, in `unit`
  std::vector<std::string> components;  // the group's parameters
  // Inside the windows, per component: the process's standard deviation and its
  // standard error (in `unit`; 0 where none is seen), and the time constant with the
  // standard error of its logarithm (0 when there is no wander).
  std::vector<double> inside_rms, inside_rms_sigma;
  double inside_time_constant_s = 0.0;
  double inside_log_time_constant_sigma = 0.0;
  int inside_windows = 0;                    // the windows it was estimated from
  std::vector<std::string> inside_left_out;  // windows the model could not explain
  // Twice the log-likelihood gain of the wander over none (its likelihood-ratio statistic,
  // p + 1 parameters), and whether it is beyond chance at 5 % (chi-square(p + 1)): a
  // wander not beyond chance is still in the sigmas (the data cannot rule it out).
  double inside_likelihood_ratio = 0.0;
  bool inside_significant = false;
};

struct TrackResult {
  std::vector<std::string> files;  // every data file of the track
  WindowSpec window;
  std::vector<std::string> window_parameters, window_units;  // a_w, in spec order
  std::vector<TrackWindow> windows;                          // time order
  std::vector<TrackShared> shared;
  std::vector<TrackEvent> events;  // time order
  double false_alarm = 0.01;
  int parameter_tests = 0, sensor_tests = 0;
  std::vector<TrackWander> wander;  // per group tested for parameter events
  // The zone times are shown in (events.json, track.csv, the console), seconds east of
  // UTC: the column map's (ColumnMapTime::offset_s), as calibrate and import show them;
  // 0 (UTC) without a map. The windows are cut in UTC all the same.
  int time_offset_s = 0;
  SlowErrorReport slow_error;
  long long samples = 0, readings = 0, gross_errors = 0;
  double chi_square = 0.0, reduced_chi_square = 0.0;
  int iterations = 0;
  bool converged = false;
  // The last Gauss-Newton step's largest change of a parameter over its formal sigma, and
  // the tolerance it was held to (TrackOptions::step_tolerance_sigmas): why the iterations
  // stopped (DescribeGaussNewton).
  double last_step_sigmas = 0.0;
  double step_tolerance_sigmas = 0.0;
  int folds = 0;         // folds computed in this run
  bool updated = false;  // an update of an existing track
  std::vector<std::string> notes;
  // The models: the latest window's, and each event-free stretch's (its windows'
  // per-window parameters averaged by their information), labelled as in the file names
  // model_calibrated@LABEL.yaml.
  std::vector<std::pair<std::string, CableRobot>> models;
  std::vector<std::string> model_comments;  // parallel: each model's estimates
  // The current model, written also as model_calibrated.yaml (a stable path): the one of
  // the stretch that holds the latest window (an index into `models`; -1 without one).
  int current_model = -1;
  int NewEvents() const {
    int n = 0;
    for (const TrackEvent& e : events) n += e.is_new ? 1 : 0;
    return n;
  }
};

// "Gauss-Newton converged in N iterations (the last step S sigma, below T)" or "Gauss-Newton
// did not converge in N iterations (the last step S sigma, above T)".
std::string DescribeGaussNewton(const TrackResult& result);

// One sentence on a group's wander inside and between windows, for the console and
// track.html ("" when neither is seen).
std::string DescribeWander(const TrackWander& wander);
// When an event happened, for the console and track.html: "between A and B" (an event
// between windows) or "inside the window, at T", then its likelihood interval when it is
// not just that night ("95% interval LOW to HIGH"), and, where the interval spans a night
// and a window's telemetry, that the data cannot tell them apart. Times as TrackTimeText.
std::string DescribeEventTime(const TrackResult& result, const TrackEvent& event);

enum class TrackStatus {
  kOk = 0,
  kInvalidInput,  // spec, data, DIR, options
  kInfeasible,    // a pose the model cannot solve at the track's point
  kUndetermined,  // a window's or the shared parameters cannot be determined
  kFailed,        // a fold runner failed, or the files could not be written
  kCancelled,     // TrackOptions::should_stop said so (the track is left as it was)
};

// Builds (or updates) the track in `out_dir` from the data files (a directory stands for
// its *.csv files, in name order) and writes its outputs. On failure nothing of a new
// track is left, and an existing one is as it was.
TrackStatus RunTrack(const CableRobot& model, const CalibrationSpec& spec,
                     const std::vector<std::string>& data, const WindowSpec& window,
                     const std::string& out_dir, const TrackOptions& options, TrackResult* result,
                     std::string* error);

// The files a track's DIR holds (names and folders relative to DIR): what --force may
// replace.
bool IsTrackOutput(const std::string& name);

}  // namespace fastcal

#endif  // FASTCAL_TRACK_H_
