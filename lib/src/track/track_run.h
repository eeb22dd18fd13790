// One track's state, passed from stage to stage (track.h): the pipeline is track.cc; the
// data files, the window store and the saved state are track_data.cc; the folds, the
// block-arrow solve, Gauss-Newton and the uncertainties track_solve.cc; the events
// track_events.cc; the outputs track_output.cc and track_html.cc.
#ifndef FASTCAL_SRC_TRACK_TRACK_RUN_H_
#define FASTCAL_SRC_TRACK_TRACK_RUN_H_

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "fastcal/internal/block_arrow.h"
#include "fastcal/internal/chi_square.h"
#include "fastcal/internal/inner_wander.h"
#include "fastcal/internal/units.h"
#include "fastcal/track.h"
#include "fastcal/track_fold.h"

namespace fastcal::internal {

// A change's likelihood interval in time (Hinkley 1970, Biometrika 57): the cuts whose
// statistic (twice the log-likelihood) is within LocationDrop() of the best's, at this
// level (95%). The drop is not chi-square(1)'s 3.84: twice the log-likelihood ratio of
// the true change time against the best is the largest of a two-sided random walk with
// drift, in the limit of small steps max over t of 2 W(t) - |t| (W a standard Brownian
// motion), whose sides exceed x each with probability exp(-x / 2): the drop is
// -2 ln(1 - sqrt(level)), 7.35 at 95% (3.84 left an overnight re-zeroing in the previous
// day's blocks, the maximum over a day's cuts of noise alone).
inline constexpr double kIntervalLevel = 0.95;
// The current model at a stable path (TrackResult::current_model).
inline constexpr char kCurrentModelFile[] = "model_calibrated.yaml";
// A change inside a window leaves at least this many of its blocks on either side: every
// boundary between a window's blocks is a candidate, the first and last minutes of a day
// too (issue 53: with two, a re-zeroing 14 minutes before a day's end was put overnight,
// its interval the night alone). A change on a window's edge and one between the windows
// are then told apart, or not, by their likelihoods: the interval spans both where the
// data cannot tell them apart.
inline constexpr int kMinPartBlocks = 1;
inline double LocationDrop() { return -2.0 * std::log(1.0 - std::sqrt(kIntervalLevel)); }

// The fold's columns: the spec's free parameters and its consider ones, in spec order.
struct TrackLayout {
  std::vector<ParameterSpec> parameters;  // the spec's, consider parameters made free
  std::vector<int> spec_index;            // per column
  std::vector<FoldRole> roles;            // per column
  std::vector<int> window_columns, shared_columns, consider_columns;
  const ParameterSpec& Column(int k) const { return parameters[spec_index[k]]; }
  int size() const { return static_cast<int>(spec_index.size()); }
};

struct TrackFile {
  std::string path;
  long long bytes = 0;
  std::string sha256;
  long long samples = 0;
  // Its readings without their times, digested (ContentWithoutTime in track_data.cc): the
  // same day re-sent with shifted times has the same ("" unknown: an older state's file).
  std::string content;
  // Its first and last sample's time (NaN: not recorded, a state of an older version).
  double first_s = std::numeric_limits<double>::quiet_NaN();
  double last_s = std::numeric_limits<double>::quiet_NaN();
};

struct TrackWindowState {
  long long key = 0;  // floor(time / duration), or the file's index
  std::string label;
  double start_s = 0.0, end_s = 0.0, first_s = 0.0, last_s = 0.0;
  long long samples = 0;
  std::vector<int> files;        // indices into TrackRun::files
  std::string fold_file;         // in folds/ ("" before its first fold)
  bool used = true;              // enough samples to be fitted
  bool dirty = true;             // to fold at its point
  bool folded = false;           // folded in this run
  bool fold_considered = false;  // its fold, of this run, has the consider columns
  bool has_fold = false;
  WindowFold fold;
  std::vector<double> theta;  // its point, per column (SI)
  // As the saved state records them (issue 37): the store's committed length (bytes; -1
  // unknown) and the fold file's SHA-256 ("" unknown).
  long long store_bytes = -1;
  std::string fold_sha256;
  // The committed store's SHA-256 ("" unknown), checked before the store is first read in
  // a run (store_checked): a store copied from another window or track is refused.
  std::string store_sha256;
  bool store_checked = false;
  std::string StoreName() const { return label + ".samples"; }
};

// A value of b: shared column `column` (index into TrackLayout::shared_columns) for the
// windows that start at or after from_s (until the next entry of the same column): a
// bias split by a sensor step has one entry per stretch.
struct SharedEntry {
  int column = 0;
  double from_s = -std::numeric_limits<double>::infinity();
  double value_si = 0.0;
  // A sensor bias's entry for the one window whose telemetry holds its step (the sensor
  // re-zeroed inside the window: its readings are of both values): the event is between
  // the entries before and after it, timed at the step's block (its first sample and the
  // block before's last).
  bool inside = false;
  double step_time_s = 0.0, step_previous_s = 0.0;
  // The likelihood interval of the step into this entry (or, for an entry `inside`, of the
  // step inside its window): over the boundary and both windows' cuts (issue 53: a
  // re-zeroing in a day's last minutes may be indistinguishable from one overnight).
  bool has_interval = false;
  double interval_low_s = 0.0, interval_high_s = 0.0;
};

// A per-window group's wander inside the windows (internal/inner_wander.h): a
// Gauss-Markov process of its components within each window, estimated by REML from the
// windows' block scores, in every covariance of the group once applied (ApplyWanderInside).
struct GroupWanderState {
  std::vector<int> group;  // indices into layout.window_columns
  InnerWander inner;
};

// An event of the track's previous run, as its state recorded it: what tells a new event
// from one reported before (TrackEvent::is_new).
struct KnownEvent {
  std::string kind;
  std::vector<int> cables;
  double time_low_s = 0.0, time_high_s = 0.0;
};

// Marks each of the run's events new unless a known one of its kind and cables has an
// interval that overlaps its own.
void MarkNewEvents(const std::vector<KnownEvent>& known, std::vector<TrackEvent>* events);

struct TrackRun {
  TrackRun(const CableRobot& m, const CalibrationSpec& s, const WindowSpec& w, const std::string& o,
           const TrackOptions& opt, TrackResult* r, std::string* e)
      : model(m), spec(s), window(w), out(o), options(opt), result(r), error(e) {}

  const CableRobot& model;
  const CalibrationSpec& spec;
  const WindowSpec& window;
  std::string out;  // the track's DIR
  const TrackOptions& options;
  TrackResult* result;
  std::string* error;

  std::vector<std::string> data_paths;  // the files given (directories expanded)
  std::string dir;      // where this run writes: a staging directory, or DIR on an update
  bool update = false;  // DIR held a track
  std::vector<KnownEvent> previous_events;  // the previous run's (track_state.json)
  int generation = 0;                       // of this run's fold files
  std::string model_yaml, spec_yaml;
  std::string columns_text;  // the column map the files are read through ("" none)
  TrackLayout layout;
  std::vector<TrackFile> files;
  std::vector<TrackWindowState> windows;  // time order
  std::vector<SharedEntry> shared;        // b, in column order then stretch order
  std::vector<double> consider_si;        // per consider column
  SlowErrorProcess slow;
  double gross_threshold_sigmas = 5.0;
  // Store files appended to in this run, with their size before (rolled back on failure).
  std::vector<std::pair<std::string, long long>> appended;
  // The exclusive lock on DIR for the run's whole life (issue 37): a descriptor of
  // DIR's lock file beside it, named after the resolved track (issue 57). Released with
  // the run, the file removed first (while still locked), so that no run, refused or not,
  // leaves it behind; a run killed meanwhile leaves it, and the next one takes it.
  struct Lock {
    int fd = -1;
    std::string path;
    ~Lock();
  } lock;
  // The solve over the used windows (indices into `windows`).
  std::vector<int> used;
  ArrowProblem problem;
  ArrowSolver solver;
  // Window w's (index into `used`) shared column j -> entry of b.
  std::vector<std::vector<int>> entry_of;
  std::vector<std::string> files_skipped;
  long long unsolvable_skipped = 0;  // samples the initial model cannot solve (skip_invalid_rows)
  // After the solve: per used window its widening f_w, and the consider parameters'
  // M^-1 C (C = J_x^T J_c) and sigmas (SI).
  std::vector<double> widening;
  std::vector<double> birge;  // its misfit part alone
  // The shared entries split by the sensor-step scan in this run (indices into `shared`).
  std::vector<int> splits;
  ArrowVector consider_x;
  Eigen::VectorXd consider_sigma;
  // Each per-window group's wander inside the windows (WindowGroups' order), and whether
  // it is in the problem's sandwich (ApplyWanderInside: each window's scale is then its
  // misfit alone, run.birge, the time correlation being the wander's).
  std::vector<GroupWanderState> wander_inside;
  bool wander_applied = false;

  TrackStatus Fail(TrackStatus status, const std::string& why) const {
    *error = why;
    return status;
  }
  // TrackOptions::should_stop asked between pieces of work; true: the caller returns
  // Cancel().
  bool StopRequested() const { return options.should_stop && options.should_stop(); }
  TrackStatus Cancel() const {
    return Fail(TrackStatus::kCancelled, "stopped on request (TrackOptions::should_stop)");
  }
  void Progress(const std::string& line) const {
    if (options.progress) options.progress(line);
  }
  std::string Path(const std::string& name) const { return dir + "/" + name; }
};

// "2024-05-01T12:00:00Z" for a Unix time (the fraction when there is one) in the zone
// offset_s east of UTC ("2024-05-01T20:00:00+08:00"), else the seconds as a number.
std::string TrackTimeText(double time_s, int offset_s);
// The window's label from its key (track.h, TrackWindow::label).
std::string WindowLabel(const WindowSpec& window, double start_s);

// Stages of track_data.cc.
TrackStatus ExpandDataPaths(const std::vector<std::string>& given, std::vector<std::string>* out,
                            std::string* error);
TrackStatus PrepareDirectory(TrackRun& run);
TrackStatus ReadNewFiles(TrackRun& run);
TrackStatus SaveState(TrackRun& run);
TrackStatus FinishDirectory(TrackRun& run);
void RollBack(TrackRun& run);
bool LoadFold(const TrackRun& run, TrackWindowState* w, std::string* error);

// Stages of track_solve.cc.
void InitialPoints(TrackRun& run);
TrackStatus Iterate(TrackRun& run, bool estimate_slow_error);
// A last fold of the moving windows at the solution with the consider parameters'
// columns too (the iterations fold without them: narrower derivatives, the same fit),
// and the solve over it.
TrackStatus FoldConsider(TrackRun& run);
TrackStatus Uncertainties(TrackRun& run);
// The windows' and the shared parameters' estimates with sigma_total (TrackResult), from
// the solution and the sandwich as they stand.
TrackStatus Results(TrackRun& run);
// Used window u folded at the solution with a fine scan (FoldTask::fine_columns) of its
// blocks [first_block, end_block) and fold columns `columns` (laid out over the track's
// columns); false with run.error.
bool FineFold(TrackRun& run, int u, int first_block, int end_block, const std::vector<int>& columns,
              WindowFold* out);
// Used window u's solution minus its fold's point, per column (fold order).
Eigen::VectorXd StepOf(const TrackRun& run, int u);
// Its fold's gradient at the solution, g + H d (fold order).
Eigen::VectorXd GradientAtSolution(const TrackRun& run, int u);
// The local order [a; s] of the block-arrow problem: fold columns of the window's own
// parameters, then of the shared ones.
std::vector<int> LocalOrder(const TrackRun& run);
// c^T M^-1 c for a new parameter's cross information with the track's: per used window
// its column over the window's local order (empty: none).
double InverseQuadratic(const TrackRun& run, const std::vector<Eigen::VectorXd>& local);
// The entry of b that shared column j takes in run.windows[w].
int EntryOf(const TrackRun& run, int j, int w);
// The total covariance (sandwich and consider) of the window parameters of used windows
// u and v.
Eigen::MatrixXd TotalCovariance(const TrackRun& run, int u, int v);

// Stage helper of track_uncertainty.cc: each used window's widening f_w (run.widening,
// and the problem's block scales).
void ComputeWidening(TrackRun& run);

// Stages of track_wander.cc: the wander of the per-window groups inside the windows.
// The groups tested together: a vector quantity's axes, or one parameter (indices into
// layout.window_columns).
std::vector<std::vector<int>> WindowGroups(const TrackRun& run);
// Group g's blocks in used window u at the joint fit (scores at the solution).
WanderWindow WanderWindowOf(const TrackRun& run, int u, const std::vector<int>& g);
// Estimates run.wander_inside[gi] over the used windows with use[u] (a change inside a
// window leaves it out).
void EstimateWanderInside(TrackRun& run, int gi, const std::vector<bool>& use);
// Puts every group's wander into the problem's sandwich (ArrowBlock::extra; the scale each
// window's misfit alone) and sets run.widening to it.
void ApplyWanderInside(TrackRun& run);
// What a covariance over used window u's scores needs of group gi's wander: K (Bp x Bp,
// the blocks' averages; zero without a wander) and the blocks' rows of the group's
// columns as columns (n x Bp over the fold's columns: column b p + x is block b's row of
// component x). A linear function e^T (scores) then has wander variance (R^T e)^T K (R^T e).
struct WanderExposure {
  bool active = false;
  Eigen::MatrixXd k;
  Eigen::MatrixXd rows;
  // The same rows in the window's local order [a; s] (LocalOrder), and M^-1 over those
  // local variables times them (the joint fit's response to the window's scores).
  Eigen::MatrixXd local_rows, formal_local_rows;
};
WanderExposure ExposureOf(const TrackRun& run, int u, int gi);
// Group gi's wander inside windows as the result states it (TrackWander's inside_ fields).
void DescribeWanderInside(const TrackRun& run, int gi, TrackWander* out);
// The formal covariance M^-1 of used window u's local variables [a; s].
Eigen::MatrixXd LocalFormal(const TrackRun& run, int u);

// Stages of track_events.cc.
TrackStatus ScanSensorSteps(TrackRun& run);
TrackStatus FindParameterEvents(TrackRun& run);
// An event between used windows `from` (the last with the old value) and `to` (the first
// with the new one), timed between them (the last sample of one, the first of the other).
TrackEvent EventAt(const TrackRun& run, int from, int to, const std::string& kind, double statistic,
                   int dof, double threshold, int tests);
// The score test of a step inside used window u's telemetry before block j, at the joint
// fit: per block j (0 unused) the score s of "these parameters differ from block j on"
// (or, with `head`, "differ before block j"; the fold's block scores and information rows
// moved to the solution: the gradient of chi-square / 2 in the fold's convention), its
// information S with everything else profiled out, the statistic s^T S^-1 s / scale, and
// the information of the part's blocks of the scanned columns. `rows` index the fold's
// block information rows (BlockRowColumns), `columns` the fold columns they are of.
struct SplitScore {
  bool valid = false;
  double statistic = 0.0;
  Eigen::VectorXd score;
  Eigen::MatrixXd schur;
  Eigen::MatrixXd after_information;  // of the part scanned
};
std::vector<SplitScore> ScanSplits(const TrackRun& run, int u, const std::vector<int>& rows,
                                   const std::vector<int>& columns, double scale,
                                   bool head = false);
// The likelihood interval of a step inside a window from its scan (the cuts whose statistic
// is within LocationDrop() of cut j's), widened to the blocks either side of them: the first
// sample of the block before the first such cut and the last of the block after the last.
std::pair<double, double> SplitInterval(const TrackRun& run, int u,
                                        const std::vector<SplitScore>& scores, int j);

// Stages of track_segment.cc: a per-window group's changes on one time line.
struct GroupTest {
  std::string kind;  // "parameter", or "sensor" for a per-window sensor group
  int tests = 1;     // Bonferroni's count
};
// Candidate cuts of the time line: every window boundary, and every block boundary
// inside a window that leaves kMinPartBlocks on either side.
int TimelineCandidates(const TrackRun& run);
// Appends group g's events (indices into layout.window_columns; run.wander_inside[gi] its
// wander inside windows, estimated again without the windows its changes are inside) and
// sets its day-to-day wander (SI variance per component).
void SegmentGroup(TrackRun& run, const std::vector<int>& g, int gi, const GroupTest& test,
                  std::vector<TrackEvent>* out, double* wander);

// Stages of track_output.cc.
TrackStatus BuildModels(TrackRun& run);
TrackStatus WriteOutputs(TrackRun& run);
std::string TrackHtml(const TrackResult& result);

// A row of track.csv and track.html's windows: a window, or one part of a window a
// parameter change is inside (TrackEvent::parts: before, then after), with the event's
// parameters from the part and everything else the window's.
struct TrackRow {
  const TrackWindow* window = nullptr;
  std::string label;  // the window's, or LABEL_before / LABEL_after
  double start_s = 0.0, end_s = 0.0, first_time_s = 0.0, last_time_s = 0.0;
  long long samples = 0;
  std::vector<TrackEstimate> estimates;  // per TrackResult::window_parameters
};
std::vector<TrackRow> TrackRows(const TrackResult& result);

}  // namespace fastcal::internal

#endif  // FASTCAL_SRC_TRACK_TRACK_RUN_H_
