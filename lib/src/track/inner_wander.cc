// The wander of a per-window group inside its windows: block-averaged Gauss-Markov
// covariances and the REML estimate (internal/inner_wander.h has the equations).
//
// Per window the contrasts y = L s and their covariance's parts are formed once
// (Prepare): with G = (sum_b I_b)^-1, P's blocks are (LP)_bc = delta_bc 1 - I_b G, so
//   M0 = f L P D P^T L^T,   (M0)_bb' = f (delta_bb' I_b - I_b G I_b')
//   U = L P D,              U_bc = (delta_bc 1 - I_b G) I_c
// and C(q, tau) = M0 + sum_k q_k N_k, N_k = U_k rbar(tau) U_k^T, U_k the columns of U of
// component k (formed once per window and tau). With C = R R^T (Cholesky), Z_k = R^-1 N_k
// R^-T and z = R^-1 y, Fisher scoring in q uses
//   d(-2 l)/dq_k = tr(Z_k) - z^T Z_k z,    E[d2(-2 l)/dq_k dq_l] = tr(Z_k Z_l)
// (Harville 1977, JASA 72, for REML's scores and information). A window of more than
// kMaxBlocks blocks is estimated from runs of adjacent blocks merged (their information and
// scores summed, the run's first and last times): the estimate stays a REML of the same
// process, at a sixteenth of a 32-block window's cost, and its K for the window's own blocks
// follows from (q, tau) whatever blocks it came from.
#include "fastcal/internal/inner_wander.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "fastcal/internal/chi_square.h"
#include "fastcal/internal/sample_chunks.h"

namespace fastcal::internal {
namespace {

// Below this L / tau the block averages' closed forms lose digits to cancellation: their
// series are used instead (error below 1e-12).
constexpr double kSeriesBelow = 1e-4;
// The time constant's search: from a quarter of the typical block (shorter is white noise
// at the blocks' scale, which the misfit already holds) to the longest window, on a grid
// of this many points in log tau, then golden-section steps between the best's
// neighbours. A longer time constant the window's own data cannot tell from a drift across
// the day on top of an offset of the day, and the offset is the wander between windows'
// (estimated from the days' scatter): searched up to ten windows, a smooth drift inside
// the days (with moving parts, the rotator's first moment known to +-900 kg m moves the
// apparent mass centre with the pointing) read as a wander of 2 cm over 20 hours, which
// every day's and every shift's sigma_total then carried, and moves of 3.6 cm went unseen
// (issue 53's study).
constexpr double kShortestTauBlocks = 0.25;
constexpr double kLongestTauWindows = 1.0;
constexpr int kTauGrid = 9;
constexpr int kGoldenSteps = 10;
// Fisher scoring in q: at most, and settled when every q_k moves by less than this
// fraction of its standard error.
constexpr int kMaxScoring = 40;
constexpr double kScoringSettled = 1e-2;
// C's diagonal is lifted by this fraction of its mean: a block whose information is
// singular in some direction (a single pose) gives M0 a null direction without data.
constexpr double kRidge = 1e-10;
// Step in ln tau of the profile's curvature (the standard error of ln tau).
constexpr double kCurvatureStep = 0.1;

double SelfAverage(double length_s, double tau_s) {
  const double x = length_s / tau_s;
  if (x < kSeriesBelow) return 1.0 - x / 3.0 + x * x / 12.0;
  return 2.0 * (x - 1.0 + std::exp(-x)) / (x * x);
}

double EdgeFactor(double length_s, double tau_s) {
  const double x = length_s / tau_s;
  if (x < kSeriesBelow) return 1.0 - x / 2.0 + x * x / 6.0;
  return -std::expm1(-x) / x;
}

// Blocks at most in a window's REML terms (adjacent blocks merged beyond: the file header).
constexpr int kMaxBlocks = 16;

// The window with runs of adjacent blocks merged to at most kMaxBlocks.
WanderWindow Coarsened(const WanderWindow& w) {
  const int blocks = static_cast<int>(w.info.size());
  if (blocks <= kMaxBlocks) return w;
  WanderWindow out;
  out.white = w.white;
  out.use = w.use;
  const int p = static_cast<int>(w.score.cols());
  out.score = Eigen::MatrixXd::Zero(kMaxBlocks, p);
  for (int c = 0; c < kMaxBlocks; ++c) {
    const int lo = c * blocks / kMaxBlocks, hi = (c + 1) * blocks / kMaxBlocks;
    Eigen::MatrixXd info = Eigen::MatrixXd::Zero(p, p);
    for (int b = lo; b < hi; ++b) {
      info += w.info[b];
      out.score.row(c) += w.score.row(b);
    }
    out.info.push_back(info);
    out.first_s.push_back(w.first_s[lo]);
    out.last_s.push_back(w.last_s[hi - 1]);
  }
  return out;
}

// One window's REML terms, formed once; N_k kept for the last tau asked.
struct Prepared {
  bool ok = false;
  int m = 0;            // (B - 1) p
  WanderWindow window;  // coarsened
  Eigen::VectorXd y;
  Eigen::MatrixXd m0;
  std::vector<Eigen::MatrixXd> u;  // per component: m x B
  double tau = -1.0;
  std::vector<Eigen::MatrixXd> n;  // per component at tau: U_k rbar U_k^T
  const std::vector<Eigen::MatrixXd>& NAt(double tau_s) {
    if (tau_s != tau) {
      const Eigen::MatrixXd r = BlockAverageCorrelation(window.first_s, window.last_s, tau_s);
      n.resize(u.size());
      for (size_t k = 0; k < u.size(); ++k) n[k].noalias() = u[k] * r * u[k].transpose();
      tau = tau_s;
    }
    return n;
  }
};

Prepared Prepare(const WanderWindow& given, int p) {
  Prepared out;
  out.window = Coarsened(given);
  const WanderWindow& w = out.window;
  const int blocks = static_cast<int>(w.info.size());
  if (blocks < 2 || w.score.rows() != blocks || w.score.cols() != p) return out;
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(p, p);
  for (const Eigen::MatrixXd& i : w.info) total += i;
  Eigen::LLT<Eigen::MatrixXd> llt(total);
  if (llt.info() != Eigen::Success) return out;
  const Eigen::MatrixXd g = llt.solve(Eigen::MatrixXd::Identity(p, p));
  const int m = (blocks - 1) * p;
  out.m = m;
  out.y.resize(m);
  out.m0 = Eigen::MatrixXd::Zero(m, m);
  out.u.assign(p, Eigen::MatrixXd::Zero(m, blocks));
  std::vector<Eigen::MatrixXd> ig(blocks);  // I_b G
  for (int b = 0; b < blocks; ++b) ig[b] = w.info[b] * g;
  for (int b = 0; b + 1 < blocks; ++b) {
    out.y.segment(b * p, p) = w.score.row(b).transpose();
    for (int c = 0; c + 1 < blocks; ++c) {
      Eigen::MatrixXd block = -ig[b] * w.info[c];
      if (b == c) block += w.info[b];
      out.m0.block(b * p, c * p, p, p) = w.white * block;
    }
    for (int c = 0; c < blocks; ++c) {
      Eigen::MatrixXd ub = -ig[b] * w.info[c];
      if (b == c) ub += w.info[c];
      for (int k = 0; k < p; ++k) out.u[k].block(b * p, c, p, 1) = ub.col(k);
    }
  }
  const double mean = out.m0.diagonal().mean();
  if (!(mean > 0.0) || !std::isfinite(mean)) return out;
  out.m0.diagonal().array() += kRidge * mean;
  out.ok = true;
  return out;
}

// One window's deviance and, when asked, its Fisher scoring terms at (q, tau).
struct Terms {
  bool ok = false;
  double deviance = 0.0;
  double quadratic = 0.0;  // y^T C^-1 y
  Eigen::VectorXd gradient;
  Eigen::MatrixXd fisher;
};

Terms WindowTerms(Prepared& w, const Eigen::VectorXd& q, double tau, bool scoring) {
  Terms t;
  const int p = static_cast<int>(q.size());
  const std::vector<Eigen::MatrixXd>& n = w.NAt(tau);
  Eigen::MatrixXd c = w.m0;
  for (int k = 0; k < p; ++k) {
    if (q[k] > 0.0) c += q[k] * n[k];
  }
  Eigen::LLT<Eigen::MatrixXd> llt(c);
  if (llt.info() != Eigen::Success) return t;
  const auto l = llt.matrixL();
  const Eigen::VectorXd z = l.solve(w.y);
  t.quadratic = z.squaredNorm();
  t.deviance = 2.0 * llt.matrixLLT().diagonal().array().log().sum() + t.quadratic;
  t.ok = std::isfinite(t.deviance);
  if (!scoring || !t.ok) return t;
  std::vector<Eigen::MatrixXd> zk(p);
  t.gradient.resize(p);
  t.fisher.resize(p, p);
  for (int k = 0; k < p; ++k) {
    Eigen::MatrixXd half = l.solve(n[k]);  // R^-1 N_k
    zk[k] = l.solve(half.transpose());     // R^-1 N_k R^-T
    t.gradient[k] = zk[k].trace() - z.dot(zk[k] * z);
  }
  for (int k = 0; k < p; ++k) {
    for (int j = k; j < p; ++j) {
      t.fisher(k, j) = t.fisher(j, k) = (zk[k].array() * zk[j].transpose().array()).sum();
    }
  }
  return t;
}

// The sums over the windows in use, on the options' threads.
struct Sums {
  bool ok = true;
  double deviance = 0.0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd fisher;
  std::vector<double> quadratic;  // per prepared window (NaN: not used)
};

Sums SumTerms(std::vector<Prepared>& prepared, const std::vector<bool>& use,
              const Eigen::VectorXd& q, double tau, bool scoring, int threads) {
  const int p = static_cast<int>(q.size());
  Sums s;
  s.gradient = Eigen::VectorXd::Zero(p);
  s.fisher = Eigen::MatrixXd::Zero(p, p);
  s.quadratic.assign(prepared.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<Terms> terms(prepared.size());
  std::mutex next_mutex;
  size_t next = 0;
  // Each window on one thread at a time (its N_k cache is its own).
  OnThreads(std::max(1, threads), [&](int) {
    for (;;) {
      size_t k;
      {
        std::lock_guard<std::mutex> lock(next_mutex);
        k = next++;
      }
      if (k >= prepared.size()) return;
      if (use[k]) terms[k] = WindowTerms(prepared[k], q, tau, scoring);
    }
  });
  for (size_t k = 0; k < prepared.size(); ++k) {
    if (!use[k]) continue;
    if (!terms[k].ok) {
      s.ok = false;
      continue;
    }
    s.deviance += terms[k].deviance;
    s.quadratic[k] = terms[k].quadratic;
    if (scoring) {
      s.gradient += terms[k].gradient;
      s.fisher += terms[k].fisher;
    }
  }
  return s;
}

struct Profile {
  double deviance = std::numeric_limits<double>::infinity();
  Eigen::VectorXd q;
  Eigen::MatrixXd fisher;
};

// The q >= 0 that minimise the deviance at tau (Fisher scoring from `start`, projected on
// q >= 0, halved where the deviance would rise).
Profile ProfileAt(std::vector<Prepared>& prepared, const std::vector<bool>& use, double tau,
                  const Eigen::VectorXd& start, int threads) {
  Profile best;
  Eigen::VectorXd q = start;
  Sums s = SumTerms(prepared, use, q, tau, true, threads);
  if (!s.ok) return best;
  for (int it = 0; it < kMaxScoring; ++it) {
    const int p = static_cast<int>(q.size());
    Eigen::VectorXd step = Eigen::VectorXd::Zero(p);
    // Components without information keep their value; the others take the step, those
    // at zero whose gradient points below zero stay there.
    std::vector<int> free;
    for (int k = 0; k < p; ++k) {
      if (s.fisher(k, k) > 0.0 && !(q[k] <= 0.0 && s.gradient[k] > 0.0)) free.push_back(k);
    }
    if (free.empty()) break;
    Eigen::MatrixXd f(free.size(), free.size());
    Eigen::VectorXd g(free.size());
    for (size_t a = 0; a < free.size(); ++a) {
      g[a] = s.gradient[free[a]];
      for (size_t b = 0; b < free.size(); ++b) f(a, b) = s.fisher(free[a], free[b]);
    }
    const Eigen::VectorXd d = -f.ldlt().solve(g);
    for (size_t a = 0; a < free.size(); ++a) step[free[a]] = d[a];
    Sums next;
    Eigen::VectorXd candidate = q;
    double factor = 1.0;
    for (int halving = 0; halving < 20; ++halving, factor *= 0.5) {
      candidate = (q + factor * step).cwiseMax(0.0);
      next = SumTerms(prepared, use, candidate, tau, false, threads);
      if (next.ok && next.deviance <= s.deviance + 1e-9 * std::abs(s.deviance)) break;
    }
    if (!next.ok) break;
    next = SumTerms(prepared, use, candidate, tau, true, threads);
    if (!next.ok) break;
    bool settled = true;
    for (int k : free) {
      const double se = 1.0 / std::sqrt(std::max(s.fisher(k, k), 1e-300));
      settled = settled && std::abs(candidate[k] - q[k]) < kScoringSettled * se;
    }
    q = candidate;
    s = next;
    if (settled) break;
  }
  best.deviance = s.deviance;
  best.q = q;
  best.fisher = s.fisher;
  return best;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The search's range of ln tau over the windows in `use` (file header).
std::pair<double, double> TauRange(const std::vector<Prepared>& prepared,
                                   const std::vector<bool>& use) {
  std::vector<double> lengths;
  double longest = 0.0;
  for (size_t k = 0; k < prepared.size(); ++k) {
    if (!use[k]) continue;
    const WanderWindow& w = prepared[k].window;
    for (size_t b = 0; b < w.first_s.size(); ++b) lengths.push_back(w.last_s[b] - w.first_s[b]);
    longest = std::max(longest, w.last_s.back() - w.first_s.front());
  }
  const double lo = std::log(std::max(1.0, kShortestTauBlocks * Median(lengths)));
  const double hi = std::log(std::max(std::exp(lo) * 2.0, kLongestTauWindows * longest));
  return {lo, hi};
}

// The estimate over the windows in `use`.
InnerWander EstimateOver(std::vector<Prepared>& prepared, const std::vector<bool>& use, int p,
                         int threads, Eigen::VectorXd* quadratic_at_best) {
  InnerWander out;
  out.variance = Eigen::VectorXd::Zero(p);
  out.variance_sigma = Eigen::VectorXd::Zero(p);
  double longest = 0.0;
  for (size_t k = 0; k < prepared.size(); ++k) {
    if (!use[k]) continue;
    const WanderWindow& w = prepared[k].window;
    longest = std::max(longest, w.last_s.back() - w.first_s.front());
    ++out.windows_used;
  }
  if (out.windows_used == 0 || !(longest > 0.0)) return out;
  const auto [lo, hi] = TauRange(prepared, use);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(p);
  const Sums none = SumTerms(prepared, use, zero, std::exp(lo), false, threads);
  if (!none.ok) return out;
  // The grid, each point's scoring from zero; then golden-section steps.
  std::vector<double> x(kTauGrid);
  std::vector<Profile> at(kTauGrid);
  int best = 0;
  for (int i = 0; i < kTauGrid; ++i) {
    x[i] = lo + (hi - lo) * i / (kTauGrid - 1);
    // Each point starts where the one before ended (the q change little between them).
    at[i] = ProfileAt(prepared, use, std::exp(x[i]),
                      i > 0 && at[i - 1].q.size() == p ? at[i - 1].q : zero, threads);
    if (at[i].deviance < at[best].deviance) best = i;
  }
  double a = x[std::max(0, best - 1)], b = x[std::min(kTauGrid - 1, best + 1)];
  Profile top = at[best];
  double top_x = x[best];
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - ratio * (b - a), d = a + ratio * (b - a);
  Profile pc = ProfileAt(prepared, use, std::exp(c), top.q, threads);
  Profile pd = ProfileAt(prepared, use, std::exp(d), top.q, threads);
  for (int step = 0; step < kGoldenSteps; ++step) {
    if (pc.deviance < pd.deviance) {
      b = d;
      d = c;
      pd = pc;
      c = b - ratio * (b - a);
      pc = ProfileAt(prepared, use, std::exp(c), pd.q, threads);
    } else {
      a = c;
      c = d;
      pc = pd;
      d = a + ratio * (b - a);
      pd = ProfileAt(prepared, use, std::exp(d), pc.q, threads);
    }
  }
  for (const auto& [px, pp] : {std::pair<double, const Profile*>{c, &pc}, {d, &pd}}) {
    if (pp->deviance < top.deviance) {
      top = *pp;
      top_x = px;
    }
  }
  out.log_likelihood_gain = 0.5 * (none.deviance - top.deviance);
  if (!(top.q.maxCoeff() > 0.0)) return out;
  out.variance = top.q;
  out.time_constant_s = std::exp(top_x);
  for (int k = 0; k < p; ++k) {
    out.variance_sigma[k] =
        top.fisher(k, k) > 0.0
            ? std::sqrt(2.0 * top.fisher.ldlt().solve(Eigen::MatrixXd::Identity(p, p))(k, k))
            : 0.0;
  }
  const double minus =
      ProfileAt(prepared, use, std::exp(top_x - kCurvatureStep), top.q, threads).deviance;
  const double plus =
      ProfileAt(prepared, use, std::exp(top_x + kCurvatureStep), top.q, threads).deviance;
  const double curvature = (plus - 2.0 * top.deviance + minus) / (kCurvatureStep * kCurvatureStep);
  out.log_time_constant_sigma = curvature > 0.0 ? std::sqrt(2.0 / curvature) : 0.0;
  if (quadratic_at_best != nullptr) {
    const Sums s = SumTerms(prepared, use, top.q, out.time_constant_s, false, threads);
    *quadratic_at_best = Eigen::Map<const Eigen::VectorXd>(s.quadratic.data(), s.quadratic.size());
  }
  return out;
}

}  // namespace

Eigen::MatrixXd BlockAverageCorrelation(const std::vector<double>& first_s,
                                        const std::vector<double>& last_s, double tau_s) {
  const int blocks = static_cast<int>(first_s.size());
  Eigen::MatrixXd r(blocks, blocks);
  std::vector<double> edge(blocks);
  for (int b = 0; b < blocks; ++b) {
    const double length = std::max(0.0, last_s[b] - first_s[b]);
    edge[b] = EdgeFactor(length, tau_s);
    r(b, b) = SelfAverage(length, tau_s);
  }
  for (int b = 0; b < blocks; ++b) {
    for (int c = b + 1; c < blocks; ++c) {
      const double gap = std::max(0.0, first_s[c] - last_s[b]);
      r(b, c) = r(c, b) = edge[b] * edge[c] * std::exp(-gap / tau_s);
    }
  }
  return r;
}

Eigen::MatrixXd WanderBlockCovariance(const InnerWander& wander, const std::vector<double>& first_s,
                                      const std::vector<double>& last_s) {
  const int blocks = static_cast<int>(first_s.size());
  const int p = static_cast<int>(wander.variance.size());
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(blocks * p, blocks * p);
  if (!wander.Active() || !(wander.time_constant_s > 0.0)) return k;
  const Eigen::MatrixXd r = BlockAverageCorrelation(first_s, last_s, wander.time_constant_s);
  for (int b = 0; b < blocks; ++b) {
    for (int c = 0; c < blocks; ++c) {
      for (int x = 0; x < p; ++x) k(b * p + x, c * p + x) = wander.variance[x] * r(b, c);
    }
  }
  return k;
}

double InnerWanderDeviance(const std::vector<WanderWindow>& windows, const Eigen::VectorXd& q,
                           double tau_s) {
  const int p = static_cast<int>(q.size());
  std::vector<Prepared> prepared;
  std::vector<bool> use;
  for (const WanderWindow& w : windows) {
    prepared.push_back(Prepare(w, p));
    use.push_back(w.use && prepared.back().ok);
  }
  const Sums s = SumTerms(prepared, use, q, tau_s, false, 1);
  return s.ok ? s.deviance : std::numeric_limits<double>::quiet_NaN();
}

namespace {

// The windows of `candidates` whose scores a model (q, tau) cannot explain: y^T C^-1 y
// beyond the chi-square(m) quantile at 1 - level / candidates.
std::vector<int> Beyond(std::vector<Prepared>& prepared, const std::vector<int>& candidates,
                        const Eigen::VectorXd& q, double tau, const InnerWanderOptions& options,
                        std::vector<double>* excess = nullptr) {
  std::vector<bool> use(prepared.size(), false);
  for (int k : candidates) use[k] = true;
  const Sums s = SumTerms(prepared, use, q, tau, false, options.threads);
  std::vector<int> out;
  if (excess) excess->clear();
  for (int k : candidates) {
    const double m = prepared[k].m;
    const double limit = ChiSquareQuantile(options.outlier_level / candidates.size(), m);
    if (!std::isfinite(s.quadratic[k]) || s.quadratic[k] > limit) out.push_back(k);
    // How far beyond its mean, in its standard deviations (NaN sorts as the worst).
    const double z = (s.quadratic[k] - m) / std::sqrt(2.0 * std::max(m, 1.0));
    if (excess) excess->push_back(std::isfinite(z) ? z : std::numeric_limits<double>::max());
  }
  return out;
}

// The worse explained half of `candidates` by `excess` (Beyond's, in candidates' order).
std::vector<int> WorseHalf(const std::vector<int>& candidates, const std::vector<double>& excess) {
  std::vector<int> order(candidates.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return excess[a] < excess[b]; });
  std::vector<int> out;
  for (size_t i = (order.size() + 1) / 2; i < order.size(); ++i)
    out.push_back(candidates[order[i]]);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

InnerWander EstimateInnerWander(const std::vector<WanderWindow>& windows,
                                const InnerWanderOptions& options) {
  int p = 0;
  for (const WanderWindow& w : windows) {
    if (!w.info.empty()) p = static_cast<int>(w.info.front().rows());
  }
  std::vector<Prepared> prepared;
  std::vector<int> candidates;
  for (const WanderWindow& w : windows) {
    prepared.push_back(Prepare(w, p));
    if (w.use && prepared.back().ok) candidates.push_back(static_cast<int>(prepared.size()) - 1);
  }
  // A step inside a window is not read as wander: the windows the white model cannot
  // explain are left out, unless they are most of them (a wander everywhere: then the
  // estimate over the half the white model explains best judges them, a trimmed start: an
  // estimate over all let four moves of 1.5-3.6 cm in 15 windows read as a wander of 2 cm
  // over 20 hours, and hide in it; issue 53's study with moving parts); the estimate over
  // the rest then judges every window again, until the set left out stands.
  const auto estimate = [&](const std::vector<int>& left_out) {
    std::vector<bool> use(prepared.size(), false);
    for (int k : candidates) use[k] = true;
    for (int k : left_out) use[k] = false;
    Eigen::VectorXd unused;
    InnerWander w = EstimateOver(prepared, use, p, options.threads, &unused);
    w.windows_left_out = left_out;
    return w;
  };
  std::vector<double> white_excess;
  std::vector<int> left_out =
      Beyond(prepared, candidates, Eigen::VectorXd::Zero(p), 1.0, options, &white_excess);
  InnerWander out;
  if (2 * left_out.size() > candidates.size()) {
    const std::vector<int> half = WorseHalf(candidates, white_excess);
    out = estimate(half);
    left_out =
        Beyond(prepared, candidates, out.variance, std::max(out.time_constant_s, 1.0), options);
    if (2 * left_out.size() > candidates.size()) left_out = half;
  }
  for (int round = 0; round < std::max(1, options.max_rounds); ++round) {
    out = estimate(left_out);
    const std::vector<int> again =
        Beyond(prepared, candidates, out.variance, std::max(out.time_constant_s, 1.0), options);
    if (again == left_out || 2 * again.size() > candidates.size()) break;
    left_out = again;
  }
  return out;
}

}  // namespace fastcal::internal
