// The track's events (track.h): sensor biases that stepped between windows (a score
// scan over cables and window boundaries, binary segmentation), and per-window groups
// that changed between consecutive windows (Wald tests), each kind at a family-wise
// false-alarm rate over the season (Bonferroni).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "fastcal/internal/number_text.h"
#include "track/track_run.h"

namespace fastcal::internal {
namespace {

struct Candidate {
  int column = -1;  // shared column (index into layout.shared_columns)
  int u = 0;        // the first used window of the new stretch
  double statistic = 0.0;
};

// The per-cable sensor biases among the shared columns.
std::vector<int> BiasColumns(const TrackRun& run) {
  std::vector<int> out;
  for (size_t j = 0; j < run.layout.shared_columns.size(); ++j) {
    const ParameterSpec& s = run.layout.Column(run.layout.shared_columns[j]);
    if (s.kind == ParameterKind::kSensorBias && s.index >= 0) out.push_back(static_cast<int>(j));
  }
  return out;
}

// The score statistic of "bias column j differs from used window u on, within its
// stretch" (track.h), widened by the windows' information-weighted widening.
double StepStatistic(const TrackRun& run, int j, int u) {
  const int column = run.layout.shared_columns[j];
  const std::vector<int> order = LocalOrder(run);
  const int entry = run.entry_of[u][j];
  std::vector<Eigen::VectorXd> local(run.used.size());
  double g = 0.0, h = 0.0, widened = 0.0;
  for (size_t v = u; v < run.used.size() && run.entry_of[v][j] == entry; ++v) {
    const WindowFold& f = run.windows[run.used[v]].fold;
    g += GradientAtSolution(run, static_cast<int>(v))[column];
    const double hv = f.information(column, column);
    h += hv;
    widened += run.widening[v] * hv;
    local[v] = Eigen::VectorXd(order.size());
    for (size_t r = 0; r < order.size(); ++r) local[v][r] = f.information(order[r], column);
  }
  const double a = h - InverseQuadratic(run, local);
  if (!(a > 1e-12 * h) || !(h > 0.0)) return 0.0;
  return g * g / (a * (widened / h));
}

Candidate BestStep(const TrackRun& run, const std::vector<int>& columns) {
  Candidate best;
  for (int j : columns) {
    for (size_t u = 1; u < run.used.size(); ++u) {
      if (run.entry_of[u - 1][j] != run.entry_of[u][j]) continue;  // already split there
      const double t = StepStatistic(run, j, static_cast<int>(u));
      if (t > best.statistic) best = {j, static_cast<int>(u), t};
    }
  }
  return best;
}

std::string WindowText(const TrackRun& run, int u) { return run.windows[run.used[u]].label; }

// The Wald test of a split bias's step (entry e after entry e0), from the final fit.
TrackEvent SensorEvent(const TrackRun& run, int e0, int e, double threshold, int tests) {
  const SharedEntry& entry = run.shared[e];
  const ParameterSpec& s = run.layout.Column(run.layout.shared_columns[entry.column]);
  const double d = run.solver.b()[e] - run.solver.b()[e0];
  const Eigen::MatrixXd p = run.solver.SandwichBB();
  double variance = p(e, e) + p(e0, e0) - 2.0 * p(e, e0);
  for (int c = 0; c < run.consider_sigma.size(); ++c) {
    variance +=
        std::pow((run.consider_x.b(e, c) - run.consider_x.b(e0, c)) * run.consider_sigma[c], 2);
  }
  int u = 0;
  while (u < static_cast<int>(run.used.size()) && run.entry_of[u][entry.column] != e) ++u;
  u = std::max(1, u);
  TrackEvent event =
      EventAt(run, u - 1, u, "sensor", d * d / std::max(variance, 1e-300), 1, threshold, tests);
  event.parameters.push_back(
      {s.name, s.unit, d / s.to_si, std::sqrt(std::max(variance, 0.0)) / s.to_si});
  event.cables.push_back(s.index + 1);
  return event;
}

// The largest of ScanSplits' statistics over window u's block boundaries, judged against
// its misfit alone (a step inside the window is what its block correlation shows).
struct InnerStep {
  double statistic = 0.0;
  int block = -1;
  int splits = 0;
};
InnerStep ScanWithin(const TrackRun& run, int u, const std::vector<int>& rows,
                     const std::vector<int>& columns) {
  InnerStep best;
  const std::vector<SplitScore> scores = ScanSplits(run, u, rows, columns, run.birge[u]);
  best.splits = std::max(0, static_cast<int>(scores.size()) - 1);
  for (size_t j = 1; j < scores.size(); ++j) {
    if (scores[j].valid && scores[j].statistic > best.statistic) {
      best.statistic = scores[j].statistic;
      best.block = static_cast<int>(j);
    }
  }
  return best;
}

// Whether the scan of window u found a step inside it (Bonferroni over its splits).
bool Inside(const TrackRun& run, const InnerStep& step, int dof) {
  return step.block > 0 &&
         step.statistic > ChiSquareQuantile(run.options.false_alarm / step.splits, dof);
}

}  // namespace

namespace {

// The entry of the same column just before entry e (the stretch before its step), or -1.
int PreviousEntry(const TrackRun& run, int e) {
  int previous = -1;
  for (size_t k = 0; k < run.shared.size(); ++k) {
    if (run.shared[k].column != run.shared[e].column ||
        !(run.shared[k].from_s < run.shared[e].from_s)) {
      continue;
    }
    if (previous < 0 || run.shared[k].from_s > run.shared[previous].from_s) {
      previous = static_cast<int>(k);
    }
  }
  return previous;
}

// The entry a step at entry e is measured from: the one before it, or, when that one is
// a window with the step inside (SharedEntry::inside), the one before that (-1: none).
int StepBase(const TrackRun& run, int e) {
  const int previous = PreviousEntry(run, e);
  if (previous < 0 || !run.shared[previous].inside) return previous;
  return PreviousEntry(run, previous);
}

// The Wald statistic of the step from entry e0 to entry e, widened.
double StepWald(const TrackRun& run, int e0, int e) {
  const Eigen::MatrixXd p = run.solver.SandwichBB();
  const double d = run.solver.b()[e] - run.solver.b()[e0];
  const double variance = p(e, e) + p(e0, e0) - 2.0 * p(e, e0);
  return variance > 0.0 ? d * d / variance : 0.0;
}

void EraseEntry(TrackRun& run, int e) {
  run.shared.erase(run.shared.begin() + e);
  run.splits.erase(std::remove(run.splits.begin(), run.splits.end(), e), run.splits.end());
  for (int& s : run.splits) s -= s > e;
}

// The first used window whose column takes entry e (-1: none).
int FirstWindowOf(const TrackRun& run, int e) {
  for (size_t u = 0; u < run.used.size(); ++u) {
    if (run.entry_of[u][run.shared[e].column] == e) return static_cast<int>(u);
  }
  return -1;
}

// Steps the fitted track no longer holds significant (the scan's score test is at the
// fit without them, the Wald test at the fit with them): the weakest is joined back to
// the stretch before it (with the window of its step, when it is inside one), and the
// track refitted, until every step stands.
TrackStatus DropWeakSteps(TrackRun& run, double threshold) {
  for (;;) {
    ComputeWidening(run);
    int weakest = -1;
    double smallest = threshold;
    for (size_t e = 0; e < run.shared.size(); ++e) {
      const int base = StepBase(run, static_cast<int>(e));
      if (base < 0 || run.shared[e].inside) continue;
      const double t = StepWald(run, base, static_cast<int>(e));
      if (t <= smallest) {
        smallest = t;
        weakest = static_cast<int>(e);
      }
    }
    if (weakest < 0) return TrackStatus::kOk;
    run.Progress("sensor step of " +
                 run.layout.Column(run.layout.shared_columns[run.shared[weakest].column]).name +
                 " no longer significant once fitted (Wald " + FormatDouble("%.1f", smallest) +
                 "): joined back");
    const int previous = PreviousEntry(run, weakest);
    const bool inside = run.shared[previous].inside;
    EraseEntry(run, std::max(weakest, inside ? previous : -1));
    if (inside) EraseEntry(run, std::min(weakest, previous));
    const TrackStatus status = Iterate(run, false);
    if (status != TrackStatus::kOk) return status;
  }
}

// Where a sensor step found at the boundary before used window u (the bias `size` higher
// from u on) may be, on one time line: at that boundary, or inside window u - 1 (from a
// cut on already of the new value) or u (before a cut still of the old). Moving it changes
// the chi-square by 2 s delta + S delta^2 (s the score of the part that changes, S its
// information with everything else profiled out, delta the bias change it gets), over the
// noise of s (PlacementNoise): `change`, with the wander's share of the part (what the
// interval and the choice against the boundary are judged by), and `fit`, over the
// window's white and block-scale misfit alone, a scale that is the same for every cut of
// the window (where in the window the step most likely is: a scale growing with the part
// would pull the point towards the short parts). A placement stands for a change between `before_s`
// and `after_s`: a block cut for anywhere in the blocks either side of it, a sample cut for the gap
// between two samples, the boundary for the night.
struct Placement {
  int window = -1;  // used window; -1: the boundary
  int block = 0;    // a block cut: before this block of `window` (-1: a sample cut)
  double change = 0.0;
  double fit = 0.0;
  double before_s = 0.0, after_s = 0.0;
};

// The noise a placement's score s is judged against in window v, Var(s) / S (S its
// information with everything else profiled out), where the tracked model is white at the
// samples' scale but not at the blocks' (issue 53: an attitude-control error with a
// minute's memory, the mass centre wandering inside a day, both move the tensions as a
// sensor step would, for minutes to tens of minutes; judged against the samples' misfit
// alone a dip anywhere in a day outweighed the night where the step was):
//   Var(s) / S = f_w phi + e^T K e / S,
// f_w the window's misfit widening (run.birge); phi the bias's block dispersion, the
// variance of its blocks' scores at the solution, less the wander's expected share of it,
// over their white value (at least 1: the misfit at the blocks' scale); e^T K e per group the
// wander inside the window on the part's score (blocks weighing weight[b]: 1 inside the part, 0
// outside, the share of a block a cut splits), e the part's blocks' cross information with the
// group profiled over the window's local variables (as WanderScoreVariance).
class PlacementNoise {
 public:
  // Bias fold column `column`, block row `row` (BlockRowColumns).
  PlacementNoise(const TrackRun& run, int v, int column, int row)
      : fold_(run.windows[run.used[v]].fold), order_(LocalOrder(run)), column_(column), row_(row) {
    for (size_t gi = 0; gi < run.wander_inside.size(); ++gi) {
      WanderExposure x = ExposureOf(run, v, static_cast<int>(gi));
      if (x.active) exposures_.push_back(std::move(x));
    }
    white_ = run.birge[v] * BlockDispersion(run, v);
  }
  double Scale(const Eigen::VectorXd& weight, double schur) const {
    return white_ + std::max(0.0, WanderVariance(weight)) / schur;
  }
  double white() const { return white_; }
  // The weights of the part from block j on (or, with `head`, before it); `share` of block
  // j - 1 is in the tail too (a cut inside it).
  Eigen::VectorXd Part(int j, bool head, double share = 0.0) const {
    const int blocks = static_cast<int>(fold_.block_samples.size());
    Eigen::VectorXd w(blocks);
    for (int b = 0; b < blocks; ++b) w[b] = b >= j ? 1.0 : (b == j - 1 ? share : 0.0);
    if (head) w = Eigen::VectorXd::Ones(blocks) - w;
    return w;
  }

 private:
  double BlockDispersion(const TrackRun& run, int v) const {
    const int blocks = static_cast<int>(fold_.block_samples.size());
    const double information = fold_.information(column_, column_);
    if (blocks < 2 || !(information > 0.0)) return 1.0;
    const Eigen::VectorXd d = StepOf(run, v);
    Eigen::VectorXd w(blocks);
    for (int b = 0; b < blocks; ++b) {
      w[b] = fold_.block_scores(b, column_) + fold_.block_information[b].row(row_).dot(d);
    }
    // The wander's expected sum of squares about the mean, tr C - 1^T C 1 / B, with C the
    // blocks' scores' wander covariance.
    double wander = 0.0;
    for (const WanderExposure& x : exposures_) {
      const int p = static_cast<int>(x.rows.cols() / blocks);
      Eigen::MatrixXd r = Eigen::MatrixXd::Zero(blocks * p, blocks);
      for (int b = 0; b < blocks; ++b) {
        for (int c = 0; c < p; ++c) r(b * p + c, b) = x.rows(column_, b * p + c);
      }
      const Eigen::MatrixXd c = r.transpose() * x.k * r;
      wander += c.trace() - c.sum() / blocks;
    }
    const double squares = (w.array() - w.mean()).square().sum() - wander;
    return std::max(1.0, squares * blocks / (blocks - 1.0) / (information * run.birge[v]));
  }
  double WanderVariance(const Eigen::VectorXd& weight) const {
    if (exposures_.empty()) return 0.0;
    Eigen::VectorXd local = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(order_.size()));
    for (int b = 0; b < weight.size(); ++b) {
      if (weight[b] == 0.0) continue;
      for (size_t r = 0; r < order_.size(); ++r) {
        local[r] += weight[b] * fold_.block_information[b](row_, order_[r]);
      }
    }
    double variance = 0.0;
    for (const WanderExposure& x : exposures_) {
      const int p = static_cast<int>(x.rows.cols() / weight.size());
      Eigen::VectorXd e = -x.formal_local_rows.transpose() * local;
      for (int b = 0; b < weight.size(); ++b) {
        for (int c = 0; c < p; ++c) e[b * p + c] += weight[b] * x.rows(column_, b * p + c);
      }
      variance += e.dot(x.k * e);
    }
    return variance;
  }

  const WindowFold& fold_;
  std::vector<int> order_;
  int column_, row_;
  double white_ = 1.0;
  std::vector<WanderExposure> exposures_;
};

// A placement at a cut whose part has score s and information S, for a step of delta:
// its change of chi-square 2 s delta + S delta^2 over the noise of s (quasi-likelihood: s
// and S both divided by Var(s) / S, PlacementNoise), with and without the wander.
Placement PlaceAt(int window, int block, double score, double schur, double delta,
                  const PlacementNoise& noise, const Eigen::VectorXd& part, double before_s,
                  double after_s) {
  const double change = 2.0 * score * delta + schur * delta * delta;
  return {window,   block,  change / noise.Scale(part, schur), change / noise.white(),
          before_s, after_s};
}

// The boundary and every block cut of windows u - 1 and u (ScanSplits).
std::vector<Placement> StepPlacements(const TrackRun& run, int u, const std::vector<int>& rows,
                                      int column, double size) {
  std::vector<Placement> out = {
      {-1, 0, 0.0, 0.0, run.windows[run.used[u - 1]].last_s, run.windows[run.used[u]].first_s}};
  for (const int v : {u - 1, u}) {
    const bool head = v == u;
    const double delta = head ? -size : size;
    const std::vector<SplitScore> scores = ScanSplits(run, v, rows, {column}, run.birge[v], head);
    const WindowFold& f = run.windows[run.used[v]].fold;
    const PlacementNoise noise(run, v, column, rows[0]);
    for (size_t j = kMinPartBlocks; j + kMinPartBlocks <= scores.size(); ++j) {
      if (!scores[j].valid) continue;
      out.push_back(PlaceAt(v, static_cast<int>(j), scores[j].score[0], scores[j].schur(0, 0),
                            delta, noise, noise.Part(static_cast<int>(j), head),
                            f.block_first_time_s[j - 1], f.block_last_time_s[j]));
    }
  }
  return out;
}

// The step placed at the other boundaries of its two stretches (entries e0 before window u,
// e from it on, bias column j): at the boundary before window w < u the windows w..u-1 take
// the new value (a step of `size` each), at the one after window w >= u the windows u..w
// keep the old one (-size); each boundary's change is the sum of its windows' whole-window
// changes (PlaceAt, the scan's j = 0), so that a step the data cannot tell from one a night
// or two away gets an interval over those nights too (issue 53: a re-zeroing reported two
// days early, its interval the one night). A stretch keeps at least one window.
void AddOtherBoundaries(const TrackRun& run, int u, int e0, int e, int j,
                        const std::vector<int>& rows, int column, double size,
                        std::vector<Placement>* placements) {
  const int windows = static_cast<int>(run.used.size());
  const auto whole = [&](int w, double delta) {
    const std::vector<SplitScore> scores = ScanSplits(run, w, rows, {column}, run.birge[w]);
    if (scores.empty() || !scores[0].valid) return Placement();
    const PlacementNoise noise(run, w, column, rows[0]);
    return PlaceAt(w, 0, scores[0].score[0], scores[0].schur(0, 0), delta, noise,
                   noise.Part(0, false), 0.0, 0.0);
  };
  const auto boundary = [&](int before, double change, double fit) {
    return Placement{-1,
                     0,
                     change,
                     fit,
                     run.windows[run.used[before]].last_s,
                     run.windows[run.used[before + 1]].first_s};
  };
  double change = 0.0, fit = 0.0;
  for (int w = u - 1; w >= 1 && run.entry_of[w][j] == e0 && run.entry_of[w - 1][j] == e0; --w) {
    const Placement x = whole(w, size);
    change += x.change;
    fit += x.fit;
    placements->push_back(boundary(w - 1, change, fit));
  }
  change = fit = 0.0;
  for (int w = u; w + 1 < windows && run.entry_of[w][j] == e && run.entry_of[w + 1][j] == e; ++w) {
    const Placement x = whole(w, -size);
    change += x.change;
    fit += x.fit;
    placements->push_back(boundary(w, change, fit));
  }
}

// The block holding a cut between samples at before_s and after_s, +1 (the tail's first
// whole block), and the share of that block after the cut.
std::pair<int, double> CutShare(const WindowFold& f, double before_s, double after_s) {
  const int blocks = static_cast<int>(f.block_samples.size());
  for (int b = 0; b < blocks; ++b) {
    if (after_s > f.block_last_time_s[b]) continue;
    if (after_s <= f.block_first_time_s[b]) return {b, 0.0};
    const double gap = after_s - before_s;
    const double span = f.block_last_time_s[b] - f.block_first_time_s[b] + gap;
    return {b + 1, span > 0.0 ? (f.block_last_time_s[b] - after_s + gap) / span : 0.0};
  }
  return {blocks, 0.0};
}

// Window v's placements at every gap between the samples of its fine fold's scan: the
// exact step columns (internal/step_scan.h) of bias fold column `column` (block row
// `row`), the part from each cut on (or, with `head`, before it: the window's sums minus
// the step's).
std::vector<Placement> SamplePlacements(const TrackRun& run, int v, const WindowFold& f, int column,
                                        int row, double delta, bool head) {
  const std::vector<int> order = LocalOrder(run);
  const ArrowBlock& k = run.problem.blocks[v];
  const int n = static_cast<int>(f.information.cols());
  const WindowFold& coarse = run.windows[run.used[v]].fold;
  const PlacementNoise noise(run, v, column, row);
  std::vector<Placement> out;
  for (size_t c = 0; c < f.fine.cross.size(); ++c) {
    const Eigen::MatrixXd& cross = f.fine.cross[c];
    double score = cross(0, n), self = f.fine.self[c](0, 0);
    Eigen::MatrixXd local(k.p + k.m(), 1);
    for (int r = 0; r < k.p + k.m(); ++r) local(r, 0) = cross(0, order[r]);
    if (head) {
      score = f.gradient[column] - score;
      self = f.information(column, column) - 2.0 * cross(0, column) + self;
      for (int r = 0; r < k.p + k.m(); ++r) {
        local(r, 0) = f.information(order[r], column) - local(r, 0);
      }
    }
    const double schur = self - run.solver.QuadraticFormOfLocal({v}, {local})(0, 0);
    if (!(schur > 0.0)) continue;
    const std::pair<int, double> cut = CutShare(coarse, f.fine.before_s[c], f.fine.after_s[c]);
    out.push_back(PlaceAt(v, -1, score, schur, delta, noise,
                          noise.Part(cut.first, head, cut.second), f.fine.before_s[c],
                          f.fine.after_s[c]));
  }
  return out;
}

// The placements at every gap between samples where the block cuts within the drop of the
// least lie (with a block either side), from fine folds of windows u - 1 and u; the block
// cuts of a window with none there stay. False (run.error) when a fine fold fails.
bool RefinePlacements(TrackRun& run, int u, int column, int row, double size,
                      std::vector<Placement>* placements) {
  double least = 0.0;
  for (const Placement& x : *placements) least = std::min(least, x.change);
  std::vector<Placement> out;
  for (const int v : {u - 1, u}) {
    int lo = std::numeric_limits<int>::max(), hi = -1;
    for (const Placement& x : *placements) {
      if (x.window != v || x.change > least + LocationDrop()) continue;
      lo = std::min(lo, x.block);
      hi = std::max(hi, x.block);
    }
    if (hi < 0) {
      for (const Placement& x : *placements) {
        if (x.window == v) out.push_back(x);
      }
      continue;
    }
    const int blocks = static_cast<int>(run.windows[run.used[v]].fold.block_samples.size());
    WindowFold fine;
    if (!FineFold(run, v, std::max(0, lo - 1), std::min(blocks, hi + 1), {column}, &fine)) {
      return false;
    }
    const bool head = v == u;
    const std::vector<Placement> at =
        SamplePlacements(run, v, fine, column, row, head ? -size : size, head);
    out.insert(out.end(), at.begin(), at.end());
  }
  out.insert(out.begin(), placements->front());  // the boundary
  *placements = std::move(out);
  return true;
}

// The step's likelihood interval over its placements (Hinkley 1970): from the earliest to
// the latest whose change is within LocationDrop() of the least.
std::pair<double, double> PlacementInterval(const std::vector<Placement>& placements) {
  double least = 0.0;
  for (const Placement& x : placements) least = std::min(least, x.change);
  double low = std::numeric_limits<double>::infinity();
  double high = -std::numeric_limits<double>::infinity();
  for (const Placement& x : placements) {
    if (x.change > least + LocationDrop()) continue;
    low = std::min(low, x.before_s);
    high = std::max(high, x.after_s);
  }
  return {low, high};
}

// Where the step most likely is: in a window only when its least change among those
// allowed (a window is moved into only when its stretch keeps another window) is more than
// LocationDrop() below the boundary's (else window -1: it stays there; an overnight
// re-zeroing is not put in an edge block), and then at the least `fit` of the allowed
// placements within LocationDrop() of that least.
Placement MoveStep(const std::vector<Placement>& placements, bool before_ok, bool here_ok, int u) {
  const auto allowed = [&](const Placement& x) {
    return x.window >= 0 && (x.window == u - 1 ? before_ok : here_ok);
  };
  double least = 0.0;
  for (const Placement& x : placements) {
    if (allowed(x)) least = std::min(least, x.change);
  }
  if (!(-least > LocationDrop())) return Placement();
  Placement best;
  best.fit = std::numeric_limits<double>::infinity();
  for (const Placement& x : placements) {
    if (allowed(x) && x.change <= least + LocationDrop() && x.fit < best.fit) best = x;
  }
  return best;
}

// A window the scan already cut out (a step found on either side of it: two halves of one
// step inside it) whose own scan finds the step: one step, inside it.
void JoinHalvesOfOneStep(TrackRun& run, const std::vector<int>& block_columns) {
  const int entries = static_cast<int>(run.shared.size());
  const int windows = static_cast<int>(run.used.size());
  for (int m = 0; m < entries; ++m) {
    const int e0 = PreviousEntry(run, m);
    if (e0 < 0 || run.shared[m].inside || run.shared[e0].inside) continue;
    bool followed = false;
    for (int e = 0; e < entries; ++e) followed = followed || PreviousEntry(run, e) == m;
    const int j = run.shared[m].column;
    const int v = FirstWindowOf(run, m);
    if (!followed || v < 1 || (v + 1 < windows && run.entry_of[v + 1][j] == m)) continue;
    const int column = run.layout.shared_columns[j];
    const auto row = std::find(block_columns.begin(), block_columns.end(), column);
    if (row == block_columns.end()) continue;
    const InnerStep step =
        ScanWithin(run, v, {static_cast<int>(row - block_columns.begin())}, {column});
    if (!Inside(run, step, 1)) continue;
    const WindowFold& f = run.windows[run.used[v]].fold;
    run.shared[m].inside = true;
    run.shared[m].step_time_s = f.block_first_time_s[step.block];
    run.shared[m].step_previous_s = f.block_last_time_s[step.block - 1];
    run.Progress("sensor steps of " + run.layout.Column(column).name + " on both sides of window " +
                 WindowText(run, v) + ": one step inside it (statistic " +
                 FormatDouble("%.1f", step.statistic) + ")");
  }
}

// A sensor re-zeroed inside a window's telemetry: for each step, the windows on either
// side of it are scanned for a step of that bias inside their own telemetry (the score
// test over block boundaries, Bonferroni over them); the window that holds it gets an
// entry of its own (SharedEntry::inside: its readings are of both values), so that the
// stretches before and after it are of one value each and the step between them is the
// whole step, timed at its block.
TrackStatus IsolateInsideSteps(TrackRun& run) {
  const std::vector<FoldRole>& roles = run.layout.roles;
  std::vector<ParameterSpec> columns;
  for (int k = 0; k < run.layout.size(); ++k) columns.push_back(run.layout.Column(k));
  const std::vector<int> block_columns = BlockRowColumns(columns, roles);
  bool isolated = false;
  const int entries = static_cast<int>(run.shared.size());
  const int windows = static_cast<int>(run.used.size());
  JoinHalvesOfOneStep(run, block_columns);
  for (int e = 0; e < entries; ++e) {
    const int e0 = PreviousEntry(run, e);
    if (e0 < 0 || run.shared[e].inside || run.shared[e0].inside) continue;
    const int j = run.shared[e].column;
    const int u = FirstWindowOf(run, e);
    if (u < 1) continue;
    const int column = run.layout.shared_columns[j];
    const auto row = std::find(block_columns.begin(), block_columns.end(), column);
    if (row == block_columns.end()) continue;
    const std::vector<int> rows = {static_cast<int>(row - block_columns.begin())};
    // A window is isolated only when its stretch keeps another window.
    const bool before_ok = u >= 2 && run.entry_of[u - 2][j] == e0;
    const bool here_ok = u + 1 < windows && run.entry_of[u + 1][j] == e;
    const double size = run.shared[e].value_si - run.shared[e0].value_si;
    std::vector<Placement> placements = StepPlacements(run, u, rows, column, size);
    if (!RefinePlacements(run, u, column, rows[0], size, &placements)) return TrackStatus::kFailed;
    AddOtherBoundaries(run, u, e0, e, j, rows, column, size, &placements);
    const std::pair<double, double> interval = PlacementInterval(placements);
    run.shared[e].has_interval = true;
    run.shared[e].interval_low_s = interval.first;
    run.shared[e].interval_high_s = interval.second;
    const Placement step = MoveStep(placements, before_ok, here_ok, u);
    if (step.window < 0) continue;
    const bool use_here = step.window == u;
    const int v = step.window;
    SharedEntry mixed = run.shared[use_here ? e : e0];
    mixed.inside = true;
    mixed.step_time_s = step.after_s;
    mixed.step_previous_s = step.before_s;
    mixed.has_interval = true;
    mixed.interval_low_s = interval.first;
    mixed.interval_high_s = interval.second;
    if (use_here) {
      // Entry e keeps window u alone; the stretch after it gets a new entry.
      SharedEntry after = run.shared[e];
      after.from_s = run.windows[run.used[u + 1]].start_s;
      mixed.from_s = run.shared[e].from_s;
      run.shared[e] = mixed;
      run.shared.push_back(after);
    } else {
      mixed.from_s = run.windows[run.used[u - 1]].start_s;
      run.shared.push_back(mixed);
    }
    run.splits.push_back(static_cast<int>(run.shared.size()) - 1);
    run.Progress("sensor step of " + run.layout.Column(column).name + " inside window " +
                 WindowText(run, v) + " (more likely than at the boundary, by a chi-square of " +
                 FormatDouble("%.1f", -step.change) + "): the window gets a value of its own");
    isolated = true;
  }
  return isolated ? Iterate(run, false) : TrackStatus::kOk;
}

}  // namespace

TrackEvent EventAt(const TrackRun& run, int from, int to, const std::string& kind, double statistic,
                   int dof, double threshold, int tests) {
  TrackEvent e;
  e.kind = kind;
  e.window = to;
  e.previous_window = from;
  e.time_s = run.windows[run.used[to]].first_s;
  e.previous_time_s = run.windows[run.used[from]].last_s;
  e.time_low_s = e.previous_time_s;
  e.time_high_s = e.time_s;
  e.degrees_of_freedom = dof;
  e.statistic = statistic;
  e.threshold = threshold;
  e.p_value = std::min(1.0, tests * ChiSquareTailProbability(statistic, dof));
  return e;
}

std::vector<SplitScore> ScanSplits(const TrackRun& run, int u, const std::vector<int>& rows,
                                   const std::vector<int>& columns, double scale, bool head) {
  const WindowFold& f = run.windows[run.used[u]].fold;
  const int blocks = static_cast<int>(f.block_samples.size());
  const int pg = static_cast<int>(rows.size());
  std::vector<SplitScore> out(std::max(blocks, 1));
  for (int x : rows) {
    if (blocks < 2 || x >= f.block_information[0].rows()) return out;  // a fold without rows
  }
  const std::vector<int> order = LocalOrder(run);
  const ArrowBlock& k = run.problem.blocks[u];
  const Eigen::VectorXd d = StepOf(run, u);
  Eigen::VectorXd score = Eigen::VectorXd::Zero(pg);
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(pg, f.information.cols());
  // The tail's last part is the whole window (j = 0: every caller's cuts start at 1; the
  // step placements at other nights use it).
  for (int n = 1; n < blocks + (head ? 0 : 1); ++n) {
    // The part grows a block at a time: blocks j.. from the end, or ..j-1 from the start.
    const int j = head ? n : blocks - n;
    const int block = head ? n - 1 : j;
    for (int x = 0; x < pg; ++x) {
      score[x] +=
          f.block_scores(block, columns[x]) + f.block_information[block].row(rows[x]).dot(d);
      cross.row(x) += f.block_information[block].row(rows[x]);
    }
    Eigen::MatrixXd self(pg, pg);
    for (int x = 0; x < pg; ++x) {
      for (int y = 0; y < pg; ++y) self(x, y) = cross(x, columns[y]);
    }
    // The right-hand side is window u's alone (QuadraticForm: O(1), not O(windows)).
    Eigen::MatrixXd local(k.p + k.m(), pg);
    for (int x = 0; x < pg; ++x) {
      for (int r = 0; r < k.p + k.m(); ++r) local(r, x) = cross(x, order[r]);
    }
    SplitScore& s = out[j];
    s.score = score;
    s.schur = self - run.solver.QuadraticFormOfLocal({u}, {local});
    s.after_information = self;
    s.statistic = score.dot(Eigen::LDLT<Eigen::MatrixXd>(s.schur).solve(score)) / scale;
    s.valid = std::isfinite(s.statistic);
  }
  return out;
}

std::pair<double, double> SplitInterval(const TrackRun& run, int u,
                                        const std::vector<SplitScore>& scores, int j) {
  const WindowFold& f = run.windows[run.used[u]].fold;
  const double floor = scores[j].statistic - LocationDrop();
  int first = j, last = j;
  for (int k = 1; k < static_cast<int>(scores.size()); ++k) {
    if (!scores[k].valid || scores[k].statistic < floor) continue;
    first = std::min(first, k);
    last = std::max(last, k);
  }
  // A block's samples are one unit of the scan: the change may be anywhere in the blocks
  // either side of a cut.
  return {f.block_first_time_s[first - 1], f.block_last_time_s[last]};
}

TrackStatus ScanSensorSteps(TrackRun& run) {
  const std::vector<int> columns = BiasColumns(run);
  const int boundaries = static_cast<int>(run.used.size()) - 1;
  run.result->sensor_tests = static_cast<int>(columns.size()) * std::max(0, boundaries);
  if (run.result->sensor_tests == 0) return TrackStatus::kOk;
  const double threshold = ChiSquareQuantile(run.options.false_alarm / run.result->sensor_tests, 1);
  for (int round = 0; round < run.options.max_sensor_steps; ++round) {
    ComputeWidening(run);
    const Candidate best = BestStep(run, columns);
    if (!(best.statistic > threshold)) break;
    const int e = run.entry_of[best.u][best.column];
    SharedEntry split = run.shared[e];
    split.from_s = run.windows[run.used[best.u]].start_s;
    split.inside = false;
    run.shared.push_back(split);
    run.splits.push_back(static_cast<int>(run.shared.size()) - 1);
    run.Progress("sensor step: " + run.layout.Column(run.layout.shared_columns[best.column]).name +
                 " from window " + WindowText(run, best.u) + " (statistic " +
                 FormatDouble("%.1f", best.statistic) + ", threshold " +
                 FormatDouble("%.1f", threshold) + "): fitted per stretch");
    // The next solve maps the new stretch's windows to the new entry; Gauss-Newton then
    // refolds the windows that move.
    const TrackStatus status = Iterate(run, false);
    if (status != TrackStatus::kOk) return status;
  }
  ComputeWidening(run);
  // Each group's wander inside the windows at the fit so far: the noise a step's placement
  // inside a day is judged against (PartWander). Not applied to the sandwich; Uncertainties
  // estimates it again at the final fit.
  run.wander_inside.clear();
  const std::vector<bool> every(run.used.size(), true);
  for (const std::vector<int>& g : WindowGroups(run)) {
    run.wander_inside.push_back({g, InnerWander()});
    EstimateWanderInside(run, static_cast<int>(run.wander_inside.size()) - 1, every);
  }
  const TrackStatus status = IsolateInsideSteps(run);
  if (status != TrackStatus::kOk) return status;
  return DropWeakSteps(run, threshold);
}

namespace {

// The likelihood interval of a sensor step inside used window u (bias column j of the
// shared ones), from the scan of its blocks at the final fit.
void TimeSensorStep(const TrackRun& run, int u, int j, TrackEvent* e) {
  std::vector<ParameterSpec> columns;
  for (int k = 0; k < run.layout.size(); ++k) columns.push_back(run.layout.Column(k));
  const std::vector<int> block_columns = BlockRowColumns(columns, run.layout.roles);
  const int column = run.layout.shared_columns[j];
  const auto row = std::find(block_columns.begin(), block_columns.end(), column);
  if (row == block_columns.end()) return;
  const std::vector<SplitScore> scores =
      ScanSplits(run, u, {static_cast<int>(row - block_columns.begin())}, {column}, run.birge[u]);
  const WindowFold& f = run.windows[run.used[u]].fold;
  for (size_t k = 1; k < scores.size(); ++k) {
    if (f.block_first_time_s[k] != e->time_s) continue;
    if (!scores[k].valid) return;
    const std::pair<double, double> interval = SplitInterval(run, u, scores, static_cast<int>(k));
    e->time_low_s = interval.first;
    e->time_high_s = interval.second;
  }
}

}  // namespace

void MarkNewEvents(const std::vector<KnownEvent>& known, std::vector<TrackEvent>* events) {
  for (TrackEvent& e : *events) {
    e.is_new = std::none_of(known.begin(), known.end(), [&e](const KnownEvent& k) {
      return k.kind == e.kind && k.cables == e.cables && k.time_low_s <= e.time_high_s &&
             e.time_low_s <= k.time_high_s;
    });
  }
}

TrackStatus FindParameterEvents(TrackRun& run) {
  TrackResult& r = *run.result;
  r.events.clear();
  r.wander.clear();
  // Sensor events: every split bias, tested on the final fit.
  if (r.sensor_tests > 0) {
    const double threshold = ChiSquareQuantile(run.options.false_alarm / r.sensor_tests, 1);
    for (size_t e = 0; e < run.shared.size(); ++e) {
      const int base = StepBase(run, static_cast<int>(e));
      if (base < 0 || run.shared[e].inside) continue;
      TrackEvent event = SensorEvent(run, base, static_cast<int>(e), threshold, r.sensor_tests);
      const int previous = PreviousEntry(run, static_cast<int>(e));
      const SharedEntry& timed = run.shared[previous].inside ? run.shared[previous] : run.shared[e];
      if (run.shared[previous].inside) {
        // The step inside the window of entry `previous`: timed at its block.
        const SharedEntry& mixed = run.shared[previous];
        event.window = std::max(0, FirstWindowOf(run, previous));
        event.previous_window = std::max(0, event.window - 1);
        event.time_s = mixed.step_time_s;
        event.previous_time_s = mixed.step_previous_s;
        event.within_window = true;
        if (!timed.has_interval) TimeSensorStep(run, event.window, timed.column, &event);
      }
      if (timed.has_interval) {
        event.time_low_s = timed.interval_low_s;
        event.time_high_s = timed.interval_high_s;
      }
      r.events.push_back(event);
    }
  }
  // Parameter events: each per-window group's changes on one time line.
  const std::vector<std::vector<int>> groups = WindowGroups(run);
  const int candidates = TimelineCandidates(run);
  r.parameter_tests = static_cast<int>(groups.size()) * candidates;
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    if (candidates == 0) break;
    const std::vector<int>& g = groups[gi];
    const ParameterSpec& s = run.layout.Column(run.layout.window_columns[g[0]]);
    const bool sensor =
        s.kind == ParameterKind::kSensorBias || s.kind == ParameterKind::kSensorGain;
    double wander = 0.0;
    SegmentGroup(run, g, static_cast<int>(gi), {sensor ? "sensor" : "parameter", r.parameter_tests},
                 &r.events, &wander);
    TrackWander w;
    w.group = g.size() > 1 ? std::string(ParameterGroupName(s.kind)) : s.name;
    w.unit = s.unit;
    w.rms = std::sqrt(wander) / s.to_si;
    DescribeWanderInside(run, static_cast<int>(gi), &w);
    r.wander.push_back(w);
  }
  std::stable_sort(r.events.begin(), r.events.end(),
                   [](const TrackEvent& a, const TrackEvent& b) { return a.time_s < b.time_s; });
  MarkNewEvents(run.previous_events, &r.events);
  // The windows' and shared estimates again: the wander inside windows in their sandwich
  // is now the one estimated without the windows the changes are inside.
  return Results(run);
}

}  // namespace fastcal::internal
