// The wander of a track's per-window groups inside the windows (track_run.h;
// internal/inner_wander.h has the model and its REML estimate; docs/calibration.md,
// "Tracking over a season", "The wander inside a day").
//
// Window w's scores over its local variables x = [a; s] gain, from group g's wander eta,
// the term R^T eta with R^T = [R_1^T ... R_B^T], R_b the rows of block b's information of
// the group's columns (track_fold.h: WindowFold::block_information). Its covariance
//   X_w = R^T K R,   K = Cov(eta_b, eta_c) (the blocks' averages)
// is added to the window's white part in the joint sandwich (internal/block_arrow.h:
// Omega_w = f_w H_w + X_w, f_w then the misfit's Birge ratio alone), so that every window's
// sigma_total, every shared one's and every event's carries the wander. A statistic linear
// in the window's scores, e^T (scores), has the wander variance (R e)^T K (R e); the joint
// fit's response to the window's scores is -M^-1 over its local variables (LocalFormal),
// so an estimate of the fit moves by -M_loc^-1 R^T eta.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>

#include "track/track_run.h"

namespace fastcal::internal {

std::vector<std::vector<int>> WindowGroups(const TrackRun& run) {
  std::map<std::string, std::vector<int>> by_key;
  std::vector<std::string> keys;
  for (size_t a = 0; a < run.layout.window_columns.size(); ++a) {
    const ParameterSpec& s = run.layout.Column(run.layout.window_columns[a]);
    // A point's axes are one group (a moving part's are named apart: by name).
    const ParameterShape shape = KindInfo(s.kind).shape;
    const bool vector = shape == ParameterShape::kAxes || shape == ParameterShape::kPointAxes;
    const std::string key =
        vector ? std::string(ParameterGroupName(s.kind)) + "/" + std::to_string(s.index) : s.name;
    if (!by_key.count(key)) keys.push_back(key);
    by_key[key].push_back(static_cast<int>(a));
  }
  std::vector<std::vector<int>> groups;
  for (const std::string& k : keys) groups.push_back(by_key[k]);
  return groups;
}

namespace {

// The level at which the wander inside windows is said to be beyond chance.
constexpr double kWanderSignificance = 0.05;

// Whether window u's fold has the block rows of group g (a fold of an older version may
// have none).
bool HasBlockRows(const WindowFold& f, const std::vector<int>& g) {
  if (f.block_samples.size() < 2 || f.block_information.size() != f.block_samples.size()) {
    return false;
  }
  for (int x : g) {
    if (x >= f.block_information[0].rows()) return false;
  }
  return true;
}

}  // namespace

WanderWindow WanderWindowOf(const TrackRun& run, int u, const std::vector<int>& g) {
  WanderWindow w;
  const WindowFold& f = run.windows[run.used[u]].fold;
  if (!HasBlockRows(f, g)) {
    w.use = false;
    return w;
  }
  const int blocks = static_cast<int>(f.block_samples.size());
  const int p = static_cast<int>(g.size());
  const Eigen::VectorXd d = StepOf(run, u);
  w.first_s = f.block_first_time_s;
  w.last_s = f.block_last_time_s;
  w.score.resize(blocks, p);
  for (int b = 0; b < blocks; ++b) {
    Eigen::MatrixXd info(p, p);
    for (int x = 0; x < p; ++x) {
      const int column = run.layout.window_columns[g[x]];
      w.score(b, x) = f.block_scores(b, column) + f.block_information[b].row(g[x]).dot(d);
      for (int y = 0; y < p; ++y) {
        info(x, y) = f.block_information[b](g[x], run.layout.window_columns[g[y]]);
      }
    }
    w.info.push_back(0.5 * (info + info.transpose()));
  }
  w.white = u < static_cast<int>(run.birge.size()) ? run.birge[u] : 1.0;
  return w;
}

void EstimateWanderInside(TrackRun& run, int gi, const std::vector<bool>& use) {
  GroupWanderState& state = run.wander_inside[gi];
  std::vector<WanderWindow> windows;
  for (size_t u = 0; u < run.used.size(); ++u) {
    windows.push_back(WanderWindowOf(run, static_cast<int>(u), state.group));
    windows.back().use = windows.back().use && use[u];
  }
  InnerWanderOptions options;
  options.threads = run.options.threads;
  state.inner = EstimateInnerWander(windows, options);
}

Eigen::MatrixXd LocalFormal(const TrackRun& run, int u) {
  const ArrowBlock& k = run.problem.blocks[u];
  const int p = k.p, m = k.m();
  Eigen::MatrixXd out(p + m, p + m);
  out.topLeftCorner(p, p) = run.solver.FormalAA(u, u);
  const Eigen::MatrixXd ab = run.solver.FormalAB(u);
  const Eigen::MatrixXd& bb = run.solver.FormalBB();
  for (int j = 0; j < m; ++j) {
    out.block(0, p + j, p, 1) = ab.col(k.shared_index[j]);
    out.block(p + j, 0, 1, p) = ab.col(k.shared_index[j]).transpose();
    for (int l = 0; l < m; ++l) out(p + j, p + l) = bb(k.shared_index[j], k.shared_index[l]);
  }
  return out;
}

WanderExposure ExposureOf(const TrackRun& run, int u, int gi) {
  WanderExposure e;
  const GroupWanderState& state = run.wander_inside[gi];
  const WindowFold& f = run.windows[run.used[u]].fold;
  if (!state.inner.Active() || !HasBlockRows(f, state.group)) return e;
  const std::vector<int>& g = state.group;
  const int blocks = static_cast<int>(f.block_samples.size());
  const int p = static_cast<int>(g.size());
  const int n = static_cast<int>(f.information.cols());
  e.rows.resize(n, blocks * p);
  for (int b = 0; b < blocks; ++b) {
    for (int x = 0; x < p; ++x)
      e.rows.col(b * p + x) = f.block_information[b].row(g[x]).transpose();
  }
  e.k = WanderBlockCovariance(state.inner, f.block_first_time_s, f.block_last_time_s);
  const std::vector<int> order = LocalOrder(run);
  e.local_rows.resize(static_cast<Eigen::Index>(order.size()), blocks * p);
  for (size_t r = 0; r < order.size(); ++r) e.local_rows.row(r) = e.rows.row(order[r]);
  e.formal_local_rows = LocalFormal(run, u) * e.local_rows;
  e.active = true;
  return e;
}

void DescribeWanderInside(const TrackRun& run, int gi, TrackWander* out) {
  const GroupWanderState& state = run.wander_inside[gi];
  const InnerWander& inner = state.inner;
  out->components.clear();
  out->inside_rms.clear();
  out->inside_rms_sigma.clear();
  for (size_t x = 0; x < state.group.size(); ++x) {
    const ParameterSpec& s = run.layout.Column(run.layout.window_columns[state.group[x]]);
    out->components.push_back(s.name);
    const double q = x < static_cast<size_t>(inner.variance.size()) ? inner.variance[x] : 0.0;
    const double sq =
        x < static_cast<size_t>(inner.variance_sigma.size()) ? inner.variance_sigma[x] : 0.0;
    const double sd = std::sqrt(std::max(0.0, q));
    out->inside_rms.push_back(sd / s.to_si);
    // The delta method: sd(sqrt q) = sd(q) / (2 sqrt q); at q = 0, sqrt(sd(q)).
    out->inside_rms_sigma.push_back((sd > 0.0 ? sq / (2.0 * sd) : std::sqrt(sq)) / s.to_si);
  }
  out->inside_time_constant_s = inner.Active() ? inner.time_constant_s : 0.0;
  out->inside_log_time_constant_sigma = inner.Active() ? inner.log_time_constant_sigma : 0.0;
  out->inside_windows = inner.windows_used;
  out->inside_likelihood_ratio = 2.0 * inner.log_likelihood_gain;
  out->inside_significant =
      inner.Active() &&
      out->inside_likelihood_ratio >
          ChiSquareQuantile(kWanderSignificance, static_cast<int>(state.group.size()) + 1);
  out->inside_left_out.clear();
  for (int u : inner.windows_left_out) {
    out->inside_left_out.push_back(run.windows[run.used[u]].label);
  }
}

void ApplyWanderInside(TrackRun& run) {
  for (size_t u = 0; u < run.used.size(); ++u) {
    ArrowBlock& k = run.problem.blocks[u];
    Eigen::MatrixXd extra = Eigen::MatrixXd::Zero(k.p + k.m(), k.p + k.m());
    bool any = false;
    for (size_t gi = 0; gi < run.wander_inside.size(); ++gi) {
      const WanderExposure e = ExposureOf(run, static_cast<int>(u), static_cast<int>(gi));
      if (!e.active) continue;
      extra += e.local_rows * e.k * e.local_rows.transpose();
      any = true;
    }
    k.extra = any ? Eigen::MatrixXd(0.5 * (extra + extra.transpose())) : Eigen::MatrixXd();
    k.scale = run.birge[u];
    run.widening[u] = run.birge[u];
  }
  run.solver.ResetSandwich();
  run.wander_applied = true;
}

}  // namespace fastcal::internal
