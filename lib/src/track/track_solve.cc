// The track's fit (track.h): folds run locally or by the caller's runner, the block-arrow
// solve over them, Gauss-Newton with the slow error re-estimated, and the uncertainties.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>

#include "fastcal/file_digest.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/calibration_slow_error.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/slow_error_estimate.h"
#include "track/track_run.h"

namespace fastcal::internal {
namespace {

// Step halvings after a step that raised the chi-square or left the model's range.
constexpr int kMaxHalvings = 6;
// Residual samples per window for the slow error's estimate: at least, at most.
constexpr int kMinResidualRun = 100;
constexpr int kMaxResidualRun = 5000;

// Gauss-Newton's next step, in sigmas, was 1e-4 to 1e-3 times the square of the step
// before it where the slow error stayed (10^6 random samples in 10 days: 0.0105 sigma
// after 3.09, 10.4 after 296; 10^7 in 100: 0.0261 after 10.6, 30.1 after 873). A fold
// whose step may be the last (kNextStepPerSquaredStep s^2 <= step_tolerance_sigmas, s the
// step before: 16 sigma at the default 0.05) carries the consider columns too, so that
// the converged track needs no fold of its own for them (FoldConsider): a wrong guess
// costs their share of one fold (about 14% there), a right one a whole fold.
constexpr double kNextStepPerSquaredStep = 2e-4;

// A new track's iterations through subsamples at most (TrackOptions::first_fold_samples;
// the coarser first one below included): from the initial model, 873 sigma away at 10^7
// samples, with the slow error estimated from the second, they take 3.
constexpr int kMaxSubsampleIterations = 4;
// Where the slow error is estimated, the very first fold, at the initial model, reads this
// fraction of the later subsamples' samples of the windows they stride (one in 4k, at
// least min_window_samples) and no run of residuals: its step only brings the point from
// the initial model (hundreds of sigma away) to near the solution, the slow error is
// estimated from the second fold on (the first point's residuals are mostly the model's
// error), and the subsample's rounds go on until it stands, so that the folds of every
// sample start from a subsample of the usual size. At 10^7 samples in 100 windows that
// first fold read 5950 samples a window, 1000 of them the residual run's, for a step the
// next fold takes again. (With a stated slow error the first round may be the last: it
// keeps the usual size; so it does where max_iterations leaves no room for another.)
constexpr long long kFirstFoldFraction = 4;

// How much a Gauss-Newton step may raise the chi-square before it is halved: the weights
// follow the predicted readings (iteratively reweighted least squares), so near the
// solution the chi-square moves by about a part in 10^6 either way.
double ChiSquareSlack(double chi2) { return std::max(1.0, 1e-6 * chi2); }
// A step of at most this many formal sigmas is kept whatever the chi-square does (issue
// 53). Near the solution Gauss-Newton's steps shrink quadratically toward the fixed point
// of the reweighted least squares, which does not minimise the chi-square at the readings'
// own weights: a step of about a sigma moved every predicted reading by ~1e-4 of itself,
// the weights (3 % of it) by twice that, and the chi-square of 86 000 readings by +8.9
// where the quadratic model said -6.3; halving such steps again and again left a month's
// track unconverged after 20 iterations, its steps stuck at 0.1-0.5 sigma. Far from the
// solution (a larger step) the halving guards against a step that overshoots.
constexpr double kKeepStepSigmas = 3.0;

// The windows folded this run and whose points move (the others keep their folds).
bool Moving(const TrackRun& run, const TrackWindowState& w) {
  return !run.update || run.options.refold_all || w.folded || !w.has_fold;
}

// Which samples a round of folds reads: every one, or of the windows of at least twice
// TrackOptions::first_fold_samples one in k (k = samples / first_fold_samples), or one in
// 4k without the run of residuals (the coarser first round, kFirstFoldFraction).
enum class Sampling { kEvery, kSubsample, kCoarse };

// The task of window w: its point over every column, or (without `consider`) over the
// fitted columns alone, the consider parameters then fixed at their values.
FoldTask TaskFor(const TrackRun& run, const TrackWindowState& w, int residual_run, bool consider,
                 Sampling sampling) {
  FoldTask t;
  t.label = w.label;
  // Absolute: a worker of a Dask cluster may run in another directory.
  std::error_code ec;
  t.samples_path = std::filesystem::absolute(run.Path("windows/" + w.StoreName()), ec).string();
  for (int f : w.files) t.files.resize(std::max<size_t>(t.files.size(), f + 1));
  for (int f : w.files) t.files[f] = run.files[f].path;
  t.model_yaml = run.model_yaml;
  t.parameters = run.layout.parameters;
  for (int k = 0; k < run.layout.size(); ++k) {
    if (!consider && run.layout.roles[k] == FoldRole::kConsider) {
      t.parameters[run.layout.spec_index[k]].free = false;
      continue;
    }
    t.roles.push_back(run.layout.roles[k]);
    t.theta_si.push_back(w.theta[k]);
  }
  t.forward_model = run.spec.forward_model;
  t.tension_sigma_n = run.spec.tension_sigma_n;
  t.tension_sigma_percent = run.spec.tension_sigma_percent;
  t.detect_gross_errors = run.spec.detect_gross_errors;
  t.gross_error_threshold_sigmas = run.gross_threshold_sigmas;
  t.slow_error = run.slow;
  t.blocks = run.options.blocks;
  t.residual_samples = residual_run;
  const long long most = run.options.first_fold_samples;
  if (sampling != Sampling::kEvery && most > 0) {
    t.stride = static_cast<int>(std::max(1LL, w.samples / most));
  }
  if (sampling == Sampling::kCoarse && t.stride > 1) {
    // One sample in 4k, at least min_window_samples of them; no run of residuals.
    const long long fewest = std::max(1LL, run.options.min_window_samples);
    t.stride = static_cast<int>(std::max<long long>(
        t.stride, std::min<long long>(kFirstFoldFraction * t.stride, w.samples / fewest)));
    t.residual_samples = 0;
  }
  return t;
}

// Runs the tasks on this machine's threads, a window per thread (a lone window on all).
bool LocalRunner(int threads, const std::vector<std::string>& tasks,
                 std::vector<std::string>* folds, std::string* error) {
  folds->assign(tasks.size(), std::string());
  std::vector<std::string> errors(tasks.size());
  std::atomic<size_t> next{0};
  const int workers = std::max(1, std::min<int>(threads, static_cast<int>(tasks.size())));
  const int inner = std::max(1, threads / workers);
  const auto work = [&] {
    for (size_t k = next++; k < tasks.size(); k = next++) {
      FoldTask task;
      std::string bytes = tasks[k];
      if (inner > 1 && ParseFoldTask(tasks[k], &task, &errors[k])) {
        task.threads = inner;
        bytes = SerializeFoldTask(task);
      }
      if (!RunFoldTask(bytes, &(*folds)[k], &errors[k]) && errors[k].empty()) {
        errors[k] = "fold failed";
      }
    }
  };
  // Windows on `workers` threads, fewer where the system refuses one (internal::OnThreads).
  internal::OnThreads(workers, [&](int) { work(); });
  for (size_t k = 0; k < tasks.size(); ++k) {
    if ((*folds)[k].empty()) {
      *error = errors[k];
      return false;
    }
  }
  return true;
}

int ResidualRun(const TrackRun& run) {
  const int used = std::max<int>(1, static_cast<int>(run.used.size()));
  return std::clamp(run.options.slow_error_samples / used, kMinResidualRun, kMaxResidualRun);
}

// A fold without the consider columns laid out over every column: theirs zero (they are
// used only after the final pass, which folds them). False when the fold is not of the
// layout.
bool ExpandToLayout(const TrackRun& run, WindowFold* f) {
  const int n = run.layout.size();
  const int m = static_cast<int>(f->columns.size());
  if (m == n) return true;
  std::vector<int> from(n, -1);  // layout column -> fold column
  int next = 0;
  for (int k = 0; k < n; ++k) {
    if (run.layout.roles[k] == FoldRole::kConsider) continue;
    if (next >= m || f->columns[next] != run.layout.Column(k).name) return false;
    from[k] = next++;
  }
  if (next != m) return false;
  WindowFold x = *f;
  x.columns.clear();
  x.roles = run.layout.roles;
  x.theta_si.assign(n, 0.0);
  x.information = Eigen::MatrixXd::Zero(n, n);
  x.gradient = Eigen::VectorXd::Zero(n);
  x.block_scores = Eigen::MatrixXd::Zero(f->block_scores.rows(), n);
  for (Eigen::MatrixXd& rows : x.block_information) rows = Eigen::MatrixXd::Zero(rows.rows(), n);
  for (int k = 0, c = 0; k < n; ++k) {
    x.columns.push_back(run.layout.Column(k).name);
    if (from[k] < 0) {
      x.theta_si[k] = run.consider_si[c++];
      continue;
    }
    x.theta_si[k] = f->theta_si[from[k]];
    x.gradient[k] = f->gradient[from[k]];
    x.block_scores.col(k) = f->block_scores.col(from[k]);
    for (size_t b = 0; b < x.block_information.size(); ++b) {
      x.block_information[b].col(k) = f->block_information[b].col(from[k]);
    }
    for (int l = 0; l < n; ++l) {
      if (from[l] >= 0) x.information(k, l) = f->information(from[k], from[l]);
    }
  }
  *f = std::move(x);
  return true;
}

// The window's store holds, up to its committed length, the bytes the state recorded
// (checked once a run, before its first fold): a store copied from another window or
// track, or edited, would otherwise be folded as this window's samples.
bool CheckStoreDigest(TrackRun& run, TrackWindowState* w) {
  if (w->store_checked || w->store_sha256.empty() || w->store_bytes < 0) return true;
  const std::string store = run.Path("windows/" + w->StoreName());
  std::string digest;
  if (!FileSha256Prefix(store, w->store_bytes, &digest, run.error)) return false;
  if (digest != w->store_sha256) {
    *run.error = store +
                 ": not the samples this track stored (its SHA-256 differs from "
                 "track_state.json's); --force rebuilds the track from the data";
    return false;
  }
  w->store_checked = true;
  return true;
}

// The stores of the windows this run folds, each checked against the state's digest.
bool CheckMovingStores(TrackRun& run) {
  for (int w : run.used) {
    if (Moving(run, run.windows[w]) && !CheckStoreDigest(run, &run.windows[w])) return false;
  }
  return true;
}

// Folds every dirty used window at its point (with the consider columns when `consider`),
// reading the samples `sampling` says. *strided (if not null) says whether any window was
// read through a subsample.
bool FoldDirty(TrackRun& run, bool consider = false, Sampling sampling = Sampling::kEvery,
               bool* strided = nullptr) {
  std::vector<int> which;
  std::vector<std::string> tasks;
  const int residual_run = ResidualRun(run);
  int largest_stride = 1;
  for (int w : run.used) {
    if (!run.windows[w].dirty) continue;
    which.push_back(w);
    const FoldTask task = TaskFor(run, run.windows[w], residual_run, consider, sampling);
    largest_stride = std::max(largest_stride, task.stride);
    tasks.push_back(SerializeFoldTask(task));
  }
  if (strided != nullptr) *strided = largest_stride > 1;
  if (tasks.empty()) return true;
  run.Progress(
      "folding " + std::to_string(tasks.size()) + " window" + (tasks.size() == 1 ? "" : "s") +
      (largest_stride > 1
           ? ", a step through one sample in " + std::to_string(largest_stride) + " at most"
           : ""));
  std::vector<std::string> folds;
  const bool ok = run.options.runner ? run.options.runner(tasks, &folds, run.error)
                                     : LocalRunner(run.options.threads, tasks, &folds, run.error);
  if (!ok) return false;
  if (folds.size() != tasks.size()) {
    *run.error = "the fold runner returned " + std::to_string(folds.size()) + " folds for " +
                 std::to_string(tasks.size()) + " windows";
    return false;
  }
  for (size_t k = 0; k < which.size(); ++k) {
    TrackWindowState& w = run.windows[which[k]];
    if (!ParseWindowFold(folds[k], "the fold of window " + w.label, &w.fold, run.error)) {
      return false;
    }
    if (!ExpandToLayout(run, &w.fold) || w.fold.theta_si != w.theta) {
      *run.error = "the fold of window " + w.label + " is not of the task sent";
      return false;
    }
    w.has_fold = true;
    w.dirty = false;
    w.folded = true;
    w.fold_considered = consider && !run.layout.consider_columns.empty();
    ++run.result->folds;
  }
  return true;
}

// The problem over the used windows' folds, with the current entries of b.
void BuildProblem(TrackRun& run) {
  const std::vector<int> order = LocalOrder(run);
  const int p = static_cast<int>(run.layout.window_columns.size());
  const int m = static_cast<int>(run.layout.shared_columns.size());
  ArrowProblem& problem = run.problem;
  problem = ArrowProblem();
  problem.q = static_cast<int>(run.shared.size());
  problem.shared_prior_information = Eigen::VectorXd::Zero(problem.q);
  problem.shared_prior_mean = Eigen::VectorXd::Zero(problem.q);
  for (int e = 0; e < problem.q; ++e) {
    const ParameterSpec& s = run.layout.Column(run.layout.shared_columns[run.shared[e].column]);
    if (!s.has_prior) continue;
    problem.shared_prior_information[e] = 1.0 / (s.prior_sigma_si * s.prior_sigma_si);
    problem.shared_prior_mean[e] = s.prior_mean_si;
  }
  run.entry_of.assign(run.used.size(), {});
  for (size_t u = 0; u < run.used.size(); ++u) {
    const WindowFold& f = run.windows[run.used[u]].fold;
    ArrowBlock k;
    k.p = p;
    k.h.resize(p + m, p + m);
    k.g.resize(p + m);
    k.x0.resize(p + m);
    for (int r = 0; r < p + m; ++r) {
      k.g[r] = f.gradient[order[r]];
      k.x0[r] = f.theta_si[order[r]];
      for (int c = 0; c < p + m; ++c) k.h(r, c) = f.information(order[r], order[c]);
    }
    k.c = f.chi_square;
    k.prior_information = Eigen::VectorXd::Zero(p);
    k.prior_mean = Eigen::VectorXd::Zero(p);
    for (int a = 0; a < p; ++a) {
      const ParameterSpec& s = run.layout.Column(run.layout.window_columns[a]);
      if (!s.has_prior) continue;
      k.prior_information[a] = 1.0 / (s.prior_sigma_si * s.prior_sigma_si);
      k.prior_mean[a] = s.prior_mean_si;
    }
    for (int j = 0; j < m; ++j) {
      k.shared_index.push_back(EntryOf(run, j, run.used[u]));
      run.entry_of[u].push_back(k.shared_index.back());
    }
    problem.blocks.push_back(std::move(k));
  }
}

// The window whose own parameters (or the shared ones) the folds cannot determine.
std::string Undetermined(const TrackRun& run) {
  for (size_t u = 0; u < run.used.size(); ++u) {
    const ArrowBlock& k = run.problem.blocks[u];
    Eigen::MatrixXd a = k.h.topLeftCorner(k.p, k.p);
    a.diagonal() += k.prior_information;
    if (Eigen::LLT<Eigen::MatrixXd>(a).info() != Eigen::Success) {
      return "window " + run.windows[run.used[u]].label + " (" +
             std::to_string(run.windows[run.used[u]].samples) +
             " samples) cannot determine its own parameters: its poses do not separate them; "
             "raise TrackOptions::min_window_samples (--min-window-samples) to leave such "
             "windows out, or give them priors";
    }
  }
  return "the windows together cannot determine the shared parameters: fix some, or give "
         "them priors";
}

// The chi-square of the folds at their points, with the priors there.
double PointChiSquare(const TrackRun& run) {
  double chi2 = 0.0;
  for (int w : run.used) {
    const WindowFold& f = run.windows[w].fold;
    chi2 += f.chi_square;
    for (int k : run.layout.window_columns) {
      const ParameterSpec& s = run.layout.Column(k);
      if (!s.has_prior) continue;
      const double d = (f.theta_si[k] - s.prior_mean_si) / s.prior_sigma_si;
      chi2 += d * d;
    }
  }
  for (const SharedEntry& e : run.shared) {
    const ParameterSpec& s = run.layout.Column(run.layout.shared_columns[e.column]);
    if (!s.has_prior) continue;
    const double d = (e.value_si - s.prior_mean_si) / s.prior_sigma_si;
    chi2 += d * d;
  }
  return chi2;
}

// Sets used window w's point from the solution (its own parameters, b, the consider ones).
void PointFromSolution(TrackRun& run, int u, std::vector<double>* theta) {
  const std::vector<int> order = LocalOrder(run);
  const Eigen::VectorXd x = run.solver.LocalSolution(u);
  for (size_t r = 0; r < order.size(); ++r) (*theta)[order[r]] = x[r];
}

// The largest step of the moving windows and of b over its formal sigma.
double LargestStep(const TrackRun& run) {
  double largest = 0.0;
  const Eigen::VectorXd b_sigma = run.solver.FormalBB().diagonal().cwiseSqrt();
  for (size_t u = 0; u < run.used.size(); ++u) {
    const TrackWindowState& w = run.windows[run.used[u]];
    if (!Moving(run, w)) continue;
    const Eigen::VectorXd a_sigma = run.solver.FormalAA(u, u).diagonal().cwiseSqrt();
    const ArrowBlock& k = run.problem.blocks[u];
    for (int a = 0; a < k.p; ++a) {
      largest = std::max(largest, std::abs(run.solver.a(u)[a] - k.x0[a]) / a_sigma[a]);
    }
    for (int j = 0; j < k.m(); ++j) {
      const int e = k.shared_index[j];
      largest = std::max(largest, std::abs(run.solver.b()[e] - k.x0[k.p + j]) / b_sigma[e]);
    }
  }
  return largest;
}

// The slow error from the folds' residual runs (each window its own series); true when
// the process the folds used stands.
bool ReestimateSlowError(TrackRun& run) {
  SlowErrorEstimateInputs in;
  in.spec = run.spec.slow_error;
  // The cables' filters on the track's threads (the same bits on any number): serial, the
  // estimate was a second or two of every round with one core idle.
  in.num_threads = std::max(1, run.options.threads);
  for (int k : run.layout.shared_columns) {
    in.gain_nuisance = in.gain_nuisance || run.layout.Column(k).kind == ParameterKind::kSensorGain;
  }
  // After the first estimate, each starts at the one before's maximum (a step of the point
  // away), not at a grid over the whole range.
  if (run.result->slow_error.passes > 0) in.start = run.result->slow_error.maximum_likelihood;
  for (size_t u = 0; u < run.used.size(); ++u) {
    for (const FoldResidual& r : run.windows[run.used[u]].fold.residuals) {
      SlowErrorSample s;
      s.time_s = r.time_s;
      s.session = static_cast<int>(u);
      s.x = r.x;
      s.sigma_n = r.sigma_n;
      s.reading_n = r.reading_n;
      s.excluded = r.excluded;
      in.samples.push_back(s);
    }
  }
  const bool settled =
      AdoptSlowErrorEstimate(EstimateSlowError(in), true, &run.slow, &run.result->slow_error);
  run.Progress(DescribeSlowError(run.result->slow_error));
  return settled;
}

void MarkMovingDirty(TrackRun& run) {
  for (int w : run.used) {
    if (Moving(run, run.windows[w])) run.windows[w].dirty = true;
  }
}

}  // namespace

std::vector<int> LocalOrder(const TrackRun& run) {
  std::vector<int> order = run.layout.window_columns;
  order.insert(order.end(), run.layout.shared_columns.begin(), run.layout.shared_columns.end());
  return order;
}

int EntryOf(const TrackRun& run, int j, int w) {
  int best = -1;
  for (size_t e = 0; e < run.shared.size(); ++e) {
    const SharedEntry& s = run.shared[e];
    if (s.column != j || s.from_s > run.windows[w].start_s) continue;
    if (best < 0 || s.from_s > run.shared[best].from_s) best = static_cast<int>(e);
  }
  return best;
}

void InitialPoints(TrackRun& run) {
  CalibrationSpec spec = run.spec;
  spec.parameters = run.layout.parameters;
  const CalibrationModel cm(run.model, spec);
  const std::vector<double> initial = cm.InitialTheta();
  if (run.shared.empty()) {
    for (size_t j = 0; j < run.layout.shared_columns.size(); ++j) {
      SharedEntry e;
      e.column = static_cast<int>(j);
      e.value_si = initial[run.layout.shared_columns[j]];
      run.shared.push_back(e);
    }
  }
  run.consider_si.clear();
  for (int k : run.layout.consider_columns) run.consider_si.push_back(initial[k]);
  run.used.clear();
  const std::vector<double>* previous = nullptr;  // the window before's own values
  for (size_t w = 0; w < run.windows.size(); ++w) {
    TrackWindowState& win = run.windows[w];
    win.used = win.samples >= run.options.min_window_samples;
    if (!win.used) {
      run.result->notes.push_back(
          "window " + win.label + " left out: " + std::to_string(win.samples) +
          " samples, fewer than " + std::to_string(run.options.min_window_samples));
      continue;
    }
    run.used.push_back(static_cast<int>(w));
    if (win.dirty || run.options.refold_all) {
      // A new window starts from the one before it (days follow each other).
      std::vector<double> theta = win.has_fold          ? win.fold.theta_si
                                  : previous != nullptr ? *previous
                                                        : initial;
      for (size_t j = 0; j < run.layout.shared_columns.size(); ++j) {
        theta[run.layout.shared_columns[j]] = run.shared[EntryOf(run, j, w)].value_si;
      }
      for (size_t c = 0; c < run.layout.consider_columns.size(); ++c) {
        theta[run.layout.consider_columns[c]] = run.consider_si[c];
      }
      win.theta = theta;
      win.dirty = true;
    }
    previous = &win.theta;
  }
}

namespace {

// Where Gauss-Newton stands between its iterations (Iterate).
struct GaussNewton {
  // The last full fold's chi-square, infinite when the next fold's is not comparable (a
  // subsample's, or before another slow error).
  double previous_chi2 = std::numeric_limits<double>::infinity();
  std::vector<std::vector<double>> previous_theta;  // per window, the point before the step
  std::vector<double> previous_shared;              // b before the step (SharedEntry::value_si)
  bool has_previous_point = false;                  // previous_theta holds one
  int halvings = 0;
  // The last step in sigmas, infinite when it says nothing of the next (a subsample's).
  double last_step = std::numeric_limits<double>::infinity();
  bool folds_strided = false;  // the windows' folds are a first step's, of a subsample
  int subsample_iterations = 0;
};

// Whether iteration `it`, the `rounds`-th through a subsample, may be followed by another:
// at most kMaxSubsampleIterations of them, and two iterations left after it for the folds
// of every sample.
bool RoomForSubsampleRound(const TrackRun& run, int rounds, int it) {
  return rounds < kMaxSubsampleIterations && it + 2 < run.options.max_iterations;
}

// After an iteration through a subsample: whether the next is too. Until the next step
// would be within the subsample's noise (a sigma of its own: the whole's solution lies
// about that far from the subsample's) with the slow error standing, and with two
// iterations left for the folds of every sample.
bool KeepSubsampling(const TrackRun& run, GaussNewton& gn, int it, bool slow_stands, double step) {
  const bool near = kNextStepPerSquaredStep * step * step <= 1.0;
  return RoomForSubsampleRound(run, ++gn.subsample_iterations, it) && !(near && slow_stands);
}

// The slow error at the start of the iterations (the spec's initial one for a new track;
// an update keeps the track's). Returns whether it is settled (not to be re-estimated).
bool StartSlowError(TrackRun& run, bool estimate_slow_error) {
  bool slow_settled = !estimate_slow_error || !run.spec.slow_error.estimates_any() || run.update;
  if (run.update && run.spec.slow_error.estimates_any() && estimate_slow_error) {
    run.result->slow_error.enabled = true;
    run.result->slow_error.process = run.slow;
    run.result->notes.push_back(
        "an update keeps the slow error the track was built with (--refold re-estimates it)");
    slow_settled = !run.options.refold_all;
    run.result->slow_error.kept_from_track = slow_settled;
  }
  run.result->slow_error.enabled = run.spec.slow_error.enabled;
  if (!run.spec.slow_error.estimates_any()) run.slow = run.spec.slow_error.Initial();
  if (run.result->folds == 0 && !run.update) run.slow = run.spec.slow_error.Initial();
  run.result->slow_error.process = run.slow;
  return slow_settled;
}

// After a fold that failed (the point left the model's range) or raised the chi-square
// over a comparable one: the moving windows back half way to the previous point. True
// when so (the caller folds again).
bool HalveBack(TrackRun& run, GaussNewton& gn, bool folded, double chi2) {
  const bool worse = !folded || (std::isfinite(gn.previous_chi2) &&
                                 chi2 > gn.previous_chi2 + ChiSquareSlack(gn.previous_chi2) &&
                                 !(gn.last_step <= kKeepStepSigmas));
  if (!worse || gn.halvings >= kMaxHalvings || !gn.has_previous_point) return false;
  for (int w : run.used) {
    TrackWindowState& win = run.windows[w];
    if (!Moving(run, win)) continue;
    for (size_t k = 0; k < win.theta.size(); ++k) {
      win.theta[k] = 0.5 * (win.theta[k] + gn.previous_theta[w][k]);
    }
    win.dirty = true;
  }
  // b with them: the chi-square's priors on the shared values are taken at the point the
  // windows are folded at (PointChiSquare).
  for (size_t e = 0; e < run.shared.size() && e < gn.previous_shared.size(); ++e) {
    run.shared[e].value_si = 0.5 * (run.shared[e].value_si + gn.previous_shared[e]);
  }
  ++gn.halvings;
  run.Progress("step halved (chi-square " + FormatDouble("%.6g", chi2) + ")");
  return true;
}

void MarkConverged(TrackRun& run) {
  run.result->converged = true;
  // An earlier pass's "did not converge" no longer holds (issue 37: the summary said
  // "(converged)" beside it).
  std::vector<std::string>& notes = run.result->notes;
  notes.erase(std::remove_if(notes.begin(), notes.end(),
                             [](const std::string& n) {
                               return n.rfind("Gauss-Newton did not converge", 0) == 0;
                             }),
              notes.end());
}

// The moving windows' points to the solve's solution (the old ones kept for a halving).
void StepToSolution(TrackRun& run, GaussNewton& gn) {
  for (size_t u = 0; u < run.used.size(); ++u) {
    TrackWindowState& win = run.windows[run.used[u]];
    if (!Moving(run, win)) continue;
    gn.previous_theta[run.used[u]] = win.theta;
    PointFromSolution(run, static_cast<int>(u), &win.theta);
  }
  gn.has_previous_point = true;
  MarkMovingDirty(run);
}

// Out of iterations: the last solve stands, the windows' points its folds'. Folds of a
// subsample (its rounds' last, where the folds after it failed to the last iteration) are
// folded again in full: the track's folds are each of every sample.
TrackStatus EndUnconverged(TrackRun& run, const GaussNewton& gn) {
  run.result->converged = false;
  run.result->notes.push_back("Gauss-Newton did not converge in " +
                              std::to_string(run.options.max_iterations) +
                              " iterations: the estimates are the last step's");
  for (int w : run.used) {
    TrackWindowState& win = run.windows[w];
    win.dirty = gn.folds_strided && Moving(run, win);
    if (win.dirty) win.theta = win.fold.theta_si;
  }
  if (gn.folds_strided && !FoldDirty(run)) return TrackStatus::kInfeasible;
  BuildProblem(run);
  if (!run.solver.Solve(run.problem))
    return run.Fail(TrackStatus::kUndetermined, Undetermined(run));
  return TrackStatus::kOk;
}

}  // namespace

TrackStatus Iterate(TrackRun& run, bool estimate_slow_error) {
  if (run.used.empty()) {
    return run.Fail(
        TrackStatus::kInvalidInput,
        "no window has " + std::to_string(run.options.min_window_samples) + " samples or more");
  }
  if (!CheckMovingStores(run)) return TrackStatus::kInvalidInput;
  // A new track's first folds are far from the solution: their steps are taken through
  // subsamples (KeepSubsampling; never as the last, the track's folds being each of every
  // sample).
  bool subsample = run.result->folds == 0 && !run.update && run.options.max_iterations > 1;
  const bool initially_settled = StartSlowError(run, estimate_slow_error);
  bool slow_settled = initially_settled;
  GaussNewton gn;
  gn.previous_theta.resize(run.windows.size());
  for (int it = 1; it <= run.options.max_iterations; ++it) {
    if (run.StopRequested()) return run.Cancel();
    ++run.result->iterations;
    const bool may_be_last =
        kNextStepPerSquaredStep * gn.last_step * gn.last_step <= run.options.step_tolerance_sigmas;
    bool strided = false;
    // Never the last round through the subsample: the estimate keeps them going, where the
    // iterations leave room for one more after it.
    const bool coarse =
        subsample && it == 1 && !initially_settled && RoomForSubsampleRound(run, 1, it);
    const Sampling sampling = coarse      ? Sampling::kCoarse
                              : subsample ? Sampling::kSubsample
                                          : Sampling::kEvery;
    const bool folded = FoldDirty(run, may_be_last && !subsample, sampling, &strided);
    if (folded) gn.folds_strided = strided;
    const double chi2 = folded ? PointChiSquare(run) : std::numeric_limits<double>::infinity();
    if (HalveBack(run, gn, folded, chi2)) continue;
    if (!folded) return TrackStatus::kInfeasible;
    gn.halvings = 0;
    bool process_changed = false;
    // The first fold's point is the initial model: its residuals are mostly the model's
    // error, not the sensors' (calibrate likewise estimates after its first fit).
    if (!slow_settled && it > 1) {
      slow_settled = ReestimateSlowError(run);
      process_changed = !slow_settled;
    }
    BuildProblem(run);
    if (!run.solver.Solve(run.problem)) {
      return run.Fail(TrackStatus::kUndetermined, Undetermined(run));
    }
    const double step = LargestStep(run);
    // A subsample's sigmas are sqrt(k) times the whole's: its step says little of the next.
    gn.last_step = strided ? std::numeric_limits<double>::infinity() : step;
    run.Progress("iteration " + std::to_string(run.result->iterations) + ": chi-square " +
                 FormatDouble("%.9g", chi2) + " -> " +
                 FormatDouble("%.9g", run.solver.ChiSquare()) + ", largest step " +
                 FormatDouble("%.3g", step) + " sigma");
    gn.previous_shared.resize(run.shared.size());
    for (size_t e = 0; e < run.shared.size(); ++e) {
      gn.previous_shared[e] = run.shared[e].value_si;
      run.shared[e].value_si = run.solver.b()[e];
    }
    run.result->last_step_sigmas = step;
    run.result->step_tolerance_sigmas = run.options.step_tolerance_sigmas;
    if (step < run.options.step_tolerance_sigmas && slow_settled && !process_changed && !strided) {
      MarkConverged(run);
      return TrackStatus::kOk;
    }
    // A subsample's chi-square is not comparable with the whole's.
    gn.previous_chi2 = process_changed || strided ? std::numeric_limits<double>::infinity() : chi2;
    subsample = strided && KeepSubsampling(run, gn, it, slow_settled && !process_changed, step);
    // The slow error estimated again from the first fold of every sample.
    if (strided && !subsample) slow_settled = initially_settled;
    StepToSolution(run, gn);
  }
  return EndUnconverged(run, gn);
}

// The consider parameters' columns at the solution: a converged track whose last folds
// carry them already keeps those folds (their points within step_tolerance_sigmas of the
// solution; the uncertainties take the step from there, GradientAtSolution); the other
// windows are folded at the solution.
TrackStatus FoldConsider(TrackRun& run) {
  if (run.layout.consider_columns.empty()) return TrackStatus::kOk;
  bool any = false;
  for (size_t u = 0; u < run.used.size(); ++u) {
    TrackWindowState& w = run.windows[run.used[u]];
    if (!Moving(run, w)) continue;
    if (run.result->converged && w.fold_considered && !w.dirty) continue;
    PointFromSolution(run, static_cast<int>(u), &w.theta);
    w.dirty = true;
    any = true;
  }
  if (any) run.Progress("the consider parameters' columns, at the solution:");
  if (!FoldDirty(run, true)) return TrackStatus::kInfeasible;
  BuildProblem(run);
  if (!run.solver.Solve(run.problem))
    return run.Fail(TrackStatus::kUndetermined, Undetermined(run));
  for (size_t e = 0; e < run.shared.size(); ++e) run.shared[e].value_si = run.solver.b()[e];
  return TrackStatus::kOk;
}

bool FineFold(TrackRun& run, int u, int first_block, int end_block, const std::vector<int>& columns,
              WindowFold* out) {
  TrackWindowState& w = run.windows[run.used[u]];
  if (!CheckStoreDigest(run, &w)) return false;
  std::vector<double> theta = w.theta;
  PointFromSolution(run, u, &theta);
  TrackWindowState at = w;
  at.theta = theta;
  // With the consider columns: the fold's columns are the layout's, as the scan's are.
  FoldTask task = TaskFor(run, at, 0, true, Sampling::kEvery);
  task.fine_first_block = first_block;
  task.fine_end_block = end_block;
  task.fine_columns = columns;
  std::vector<std::string> folds;
  const std::vector<std::string> tasks = {SerializeFoldTask(task)};
  const bool ok = run.options.runner ? run.options.runner(tasks, &folds, run.error)
                                     : LocalRunner(run.options.threads, tasks, &folds, run.error);
  if (!ok || folds.size() != 1) return false;
  if (!ParseWindowFold(folds[0], "the fine fold of window " + w.label, out, run.error))
    return false;
  return ExpandToLayout(run, out);
}

Eigen::VectorXd StepOf(const TrackRun& run, int u) {
  const WindowFold& f = run.windows[run.used[u]].fold;
  const std::vector<int> order = LocalOrder(run);
  const Eigen::VectorXd x = run.solver.LocalSolution(u);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(f.theta_si.size()));
  for (size_t r = 0; r < order.size(); ++r) d[order[r]] = x[r] - f.theta_si[order[r]];
  return d;
}

Eigen::VectorXd GradientAtSolution(const TrackRun& run, int u) {
  const WindowFold& f = run.windows[run.used[u]].fold;
  return f.gradient + f.information * StepOf(run, u);
}

double InverseQuadratic(const TrackRun& run, const std::vector<Eigen::VectorXd>& local) {
  // Only the windows `local` names (QuadraticForm: a score test's stretch, not the track).
  std::vector<int> windows;
  std::vector<Eigen::MatrixXd> named;
  for (size_t u = 0; u < run.used.size(); ++u) {
    if (local[u].size() == 0) continue;
    windows.push_back(static_cast<int>(u));
    named.push_back(local[u]);
  }
  if (windows.empty()) return 0.0;
  return run.solver.QuadraticFormOfLocal(windows, named)(0, 0);
}

Eigen::MatrixXd TotalCovariance(const TrackRun& run, int u, int v) {
  Eigen::MatrixXd p = run.solver.SandwichAA(u, v);
  if (run.consider_sigma.size() > 0) {
    const Eigen::MatrixXd s2 = run.consider_sigma.cwiseAbs2().asDiagonal();
    p += run.consider_x.a[u] * s2 * run.consider_x.a[v].transpose();
  }
  return p;
}

}  // namespace fastcal::internal
