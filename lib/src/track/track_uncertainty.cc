// The track's uncertainties (track.h): each window's widening, the sandwich covariance
// with the consider parameters' part, the estimates per window and shared, and what each
// sensor reads per window.
#include <algorithm>
#include <cmath>

#include "track/track_run.h"

namespace fastcal::internal {
namespace {

// Fewest blocks with which a window's time correlation is judged at all.
constexpr int kMinBlocks = 8;
// One-sided level of each window's test of time-correlated residuals.
constexpr double kCorrelationLevel = 0.01;

// The variance of the window's block scores of its own parameters at the solution over
// their white value, the largest where significant (chi-square with B - 1 degrees of
// freedom under white residuals), else 1.
double BlockWidening(const TrackRun& run, const WindowFold& f, const Eigen::VectorXd& d) {
  const int blocks = static_cast<int>(f.block_samples.size());
  if (blocks < kMinBlocks) return 1.0;
  const double limit = ChiSquareQuantile(kCorrelationLevel, blocks - 1) / (blocks - 1);
  double widening = 1.0;
  const std::vector<int>& columns = run.layout.window_columns;
  for (size_t k = 0; k < columns.size(); ++k) {
    Eigen::VectorXd w(blocks);
    for (int j = 0; j < blocks; ++j) {
      w[j] = f.block_scores(j, columns[k]) + f.block_information[j].row(k).dot(d);
    }
    const double variance = (w.array() - w.mean()).square().sum() * blocks / (blocks - 1.0);
    const double ratio = variance / f.information(columns[k], columns[k]);
    if (ratio > limit) widening = std::max(widening, ratio);
  }
  return widening;
}

// The consider parameters' M^-1 C, C their cross information with the track's.
void ConsiderSensitivity(TrackRun& run) {
  const std::vector<int>& consider = run.layout.consider_columns;
  const int nc = static_cast<int>(consider.size());
  run.consider_sigma = Eigen::VectorXd(nc);
  for (int c = 0; c < nc; ++c)
    run.consider_sigma[c] = run.layout.Column(consider[c]).prior_sigma_si;
  if (nc == 0) return;
  const std::vector<int> order = LocalOrder(run);
  ArrowVector cross;
  cross.b = Eigen::MatrixXd::Zero(run.problem.q, nc);
  for (size_t u = 0; u < run.used.size(); ++u) {
    const ArrowBlock& k = run.problem.blocks[u];
    const Eigen::MatrixXd& h = run.windows[run.used[u]].fold.information;
    Eigen::MatrixXd a(k.p, nc);
    for (int r = 0; r < k.p; ++r) {
      for (int c = 0; c < nc; ++c) a(r, c) = h(order[r], consider[c]);
    }
    for (int j = 0; j < k.m(); ++j) {
      for (int c = 0; c < nc; ++c) cross.b(k.shared_index[j], c) += h(order[k.p + j], consider[c]);
    }
    cross.a.push_back(a);
  }
  run.consider_x = run.solver.SolveFor(cross);
}

// The wander variance (every group's, inside window u) of the score of fold column
// `column` profiled over the window's local variables (`local`: its cross information with
// them): e = R_c - R^T M_loc^-1 local, var = e^T K e per group.
double WanderScoreVariance(const TrackRun& run, int u, int column, const Eigen::VectorXd& local) {
  double variance = 0.0;
  for (size_t gi = 0; gi < run.wander_inside.size(); ++gi) {
    const WanderExposure x = ExposureOf(run, u, static_cast<int>(gi));
    if (!x.active) continue;
    const Eigen::VectorXd e =
        x.rows.row(column).transpose() - x.formal_local_rows.transpose() * local;
    variance += e.dot(x.k * e);
  }
  return variance;
}

// Variance of entry e of b: sandwich plus consider.
double SharedVariance(const TrackRun& run, int e) {
  double v = run.solver.SandwichBB()(e, e);
  for (int c = 0; c < run.consider_sigma.size(); ++c) {
    v += std::pow(run.consider_x.b(e, c) * run.consider_sigma[c], 2);
  }
  return v;
}

// What each shared per-cable bias reads in used window u (track.h, TrackWindow::offset_kn).
void SensorOffsets(const TrackRun& run, int u, TrackWindow* out) {
  const std::vector<int> order = LocalOrder(run);
  const ArrowBlock& k = run.problem.blocks[u];
  const WindowFold& f = run.windows[run.used[u]].fold;
  const Eigen::VectorXd gradient = GradientAtSolution(run, u);
  for (int j = 0; j < k.m(); ++j) {
    const int column = order[k.p + j];
    const ParameterSpec& s = run.layout.Column(column);
    if (s.kind != ParameterKind::kSensorBias || s.index < 0) continue;
    std::vector<Eigen::VectorXd> local(run.used.size());
    local[u] = Eigen::VectorXd(k.p + k.m());
    for (int r = 0; r < k.p + k.m(); ++r) local[u][r] = f.information(order[r], column);
    const double a = f.information(column, column) - InverseQuadratic(run, local);
    if (!(a > 0.0)) continue;
    const int e = k.shared_index[j];
    TrackEstimate& o = out->offset_kn[s.index];
    o.value = (run.solver.b()[e] - gradient[column] / a) / s.to_si;
    o.sigma_formal = std::sqrt(1.0 / a + run.solver.FormalBB()(e, e)) / s.to_si;
    const double wander = WanderScoreVariance(run, u, column, local[u]) / (a * a);
    o.sigma_total = std::sqrt(run.widening[u] / a + wander + SharedVariance(run, e)) / s.to_si;
    out->has_offsets = true;
  }
}

TrackWindow WindowResult(const TrackRun& run, int u) {
  const TrackWindowState& w = run.windows[run.used[u]];
  const WindowFold& f = w.fold;
  TrackWindow out;
  out.label = w.label;
  out.start_s = w.start_s;
  out.end_s = w.end_s;
  out.first_time_s = w.first_s;
  out.last_time_s = w.last_s;
  out.samples = w.samples;
  out.readings = f.readings;
  out.gross_errors = f.gross_error_count;
  out.folded = w.folded;
  const Eigen::VectorXd d = StepOf(run, u);
  out.chi_square = f.chi_square + 2.0 * f.gradient.dot(d) + d.dot(f.information * d);
  const long long nu = f.readings - static_cast<long long>(run.layout.window_columns.size());
  out.reduced_chi_square = nu > 0 ? out.chi_square / nu : 0.0;
  out.widening = run.widening[u];
  const Eigen::MatrixXd total = TotalCovariance(run, u, u);
  const Eigen::MatrixXd formal = run.solver.FormalAA(u, u);
  for (size_t a = 0; a < run.layout.window_columns.size(); ++a) {
    const ParameterSpec& s = run.layout.Column(run.layout.window_columns[a]);
    TrackEstimate e;
    e.value = run.solver.a(u)[a] / s.to_si;
    e.sigma_total = std::sqrt(std::max(0.0, total(a, a))) / s.to_si;
    e.sigma_formal = std::sqrt(std::max(0.0, formal(a, a))) / s.to_si;
    out.estimates.push_back(e);
  }
  for (int i = 0; i < kNumCables; ++i) {
    out.rms_n[i] = f.count[i] > 0 ? std::sqrt(f.sum_sq_n2[i] / f.count[i]) : 0.0;
  }
  SensorOffsets(run, u, &out);
  return out;
}

}  // namespace

void ComputeWidening(TrackRun& run) {
  run.widening.assign(run.used.size(), 1.0);
  run.birge.assign(run.used.size(), 1.0);
  for (size_t u = 0; u < run.used.size(); ++u) {
    const WindowFold& f = run.windows[run.used[u]].fold;
    const Eigen::VectorXd d = StepOf(run, static_cast<int>(u));
    const double chi2 = f.chi_square + 2.0 * f.gradient.dot(d) + d.dot(f.information * d);
    const double nu = static_cast<double>(f.readings) - run.layout.window_columns.size();
    // The Birge ratio where the misfit is beyond the band, as the calibration's budget.
    double birge = 1.0;
    if (nu > 0.0 && chi2 / nu > 1.0 + 3.0 * std::sqrt(2.0 / nu)) birge = chi2 / nu;
    run.birge[u] = birge;
    // With the groups' wander inside the windows in the sandwich, the scores' correlation
    // in time is its (ApplyWanderInside); before, the blocks' spread stands for it.
    run.widening[u] = run.wander_applied ? birge : std::max(birge, BlockWidening(run, f, d));
    run.problem.blocks[u].scale = run.widening[u];
  }
}

TrackStatus Uncertainties(TrackRun& run) {
  ComputeWidening(run);
  ConsiderSensitivity(run);
  // Each group's wander inside the windows, from every window (those the model cannot
  // explain, a change inside them, left out by the estimate itself); the events' stage
  // estimates it again without the windows its changes are in.
  run.wander_inside.clear();
  run.wander_applied = false;
  const std::vector<bool> every(run.used.size(), true);
  for (const std::vector<int>& g : WindowGroups(run)) {
    run.wander_inside.push_back({g, InnerWander()});
    EstimateWanderInside(run, static_cast<int>(run.wander_inside.size()) - 1, every);
  }
  ApplyWanderInside(run);
  return Results(run);
}

TrackStatus Results(TrackRun& run) {
  TrackResult& r = *run.result;
  r.windows.clear();
  r.samples = r.readings = r.gross_errors = 0;
  r.chi_square = 0.0;
  r.files.clear();
  for (const TrackFile& f : run.files) r.files.push_back(f.path);
  r.updated = run.update;
  long long parameters = static_cast<long long>(run.shared.size());
  for (size_t u = 0; u < run.used.size(); ++u) {
    r.windows.push_back(WindowResult(run, static_cast<int>(u)));
    const TrackWindow& w = r.windows.back();
    r.samples += w.samples;
    r.readings += w.readings;
    r.gross_errors += w.gross_errors;
    r.chi_square += w.chi_square;
    parameters += static_cast<long long>(run.layout.window_columns.size());
  }
  r.reduced_chi_square = r.readings > parameters ? r.chi_square / (r.readings - parameters) : 0.0;
  r.shared.clear();
  for (size_t e = 0; e < run.shared.size(); ++e) {
    const ParameterSpec& s = run.layout.Column(run.layout.shared_columns[run.shared[e].column]);
    TrackShared out;
    out.name = s.name;
    out.unit = s.unit;
    out.estimate.value = run.solver.b()[e] / s.to_si;
    out.estimate.sigma_total =
        std::sqrt(std::max(0.0, SharedVariance(run, static_cast<int>(e)))) / s.to_si;
    out.estimate.sigma_formal = std::sqrt(std::max(0.0, run.solver.FormalBB()(e, e))) / s.to_si;
    out.from_window = -1;
    for (size_t u = 0; u < run.used.size(); ++u) {
      const auto& entries = run.entry_of[u];
      if (std::find(entries.begin(), entries.end(), static_cast<int>(e)) == entries.end()) continue;
      if (out.from_window < 0) out.from_window = static_cast<int>(u);
      out.to_window = static_cast<int>(u);
    }
    r.shared.push_back(out);
  }
  return TrackStatus::kOk;
}

}  // namespace fastcal::internal
