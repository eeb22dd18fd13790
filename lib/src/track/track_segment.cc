// The changes of a per-window group (the mass centre) on one time line (track.h; docs/
// calibration.md, "Tracking over a season", "Events"): a change may happen between two
// windows or inside one, and each candidate is tested with all the data of the stretches
// before and after it.
//
// The time line's units: each used window u's estimate a_u (the joint fit's), and, for a
// cut inside window u before its block j, the window's two parts. From the fold's block
// rows (track_fold.h) the score test of "the group differs from block j on" at the joint
// fit (everything else profiled, ScanSplits) gives the step inside the window, delta =
// -S^-1 s with covariance V = S^-1 f (S the profiled information, s the score, f the
// window's misfit widening); with I the window's information of the group and I+ that of
// its blocks j.. (G = I^-1 I+), the parts are, to first order,
//   head  h- = a_u - G delta,     tail  h+ = a_u + (1 - G) delta
// (a_u is the information-weighted mean of the two; delta is the contrast of the window's
// residuals, uncorrelated with a_u and with the other windows).
//
// A stretch's value is the weighted mean of its units, m = (sum W_i)^-1 sum W_i x_i,
// W_i = (C_i + v 1)^-1: C_i the unit's covariance given the shared parameters (its own
// information's inverse, widened), v the group's wander per component (a random effect of
// each unit). A candidate cut between stretches A and B is tested by the Wald statistic
// T = d^T Var(d)^-1 d of d = m_B - m_A, Var(d) exact to first order: the windows'
// estimates through the joint sandwich covariance P_uv (consecutive windows share b; its
// error cancels in d), the steps inside windows through V, the wander through v sum
// c_i c_i^T. For a Gaussian model T(tau) is, up to a constant, twice the profile
// log-likelihood of a change at tau with the stretches' values free: the best cut is its
// maximum likelihood estimate, and its likelihood interval (Hinkley 1970, Biometrika 57)
// the contiguous cuts with T >= T_max - 7.35 (95%; track_run.h, LocationDrop).
//
// Several changes: binary segmentation (Scott and Knott 1974; Vostrikova 1981: scan every
// stretch between the changes found, add the best significant cut, repeat), with the
// changes re-tested between their neighbours and the weakest below the threshold
// removed, until every one stands. The wander is estimated jointly (as DeCAFS, Romano
// et al. 2022, JASA 117, alternates steps and random walk): from the consecutive windows'
// differences that no change found touches (the median of d^T (C + 2 v 1)^-1 d brought
// to the chi-square median), then the segmentation repeated with it, until the changes
// stand (a step left in would inflate the wander that hides the next one).
//
// Family-wise false-alarm rate alpha over the season: Bonferroni over every candidate cut
// of the first round (between windows and inside each, TimelineCandidates), the
// threshold chi-square(k) at 1 - alpha / candidates; under no change only the first round
// can raise an alarm.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "fastcal/internal/number_text.h"
#include "track/track_run.h"

namespace fastcal::internal {
namespace {

// Rounds of the wander/segmentation fixed point at most (the change set settles in two or
// three).
constexpr int kMaxWanderRounds = 8;
// The wander has settled when it moves by less than this fraction of itself.
constexpr double kWanderSettled = 0.01;
// Fewest clean window boundaries from which the wander is estimated (else 0): the median
// of 8 or more holds against a few unexplained ones.
constexpr int kMinWanderBoundaries = 8;

// A cut of the time line: before used window u's data (j = 0: between u - 1 and u), or
// inside it, before its block j.
struct Cut {
  int u = 0;
  int j = 0;
};
bool operator<(const Cut& a, const Cut& b) { return a.u < b.u || (a.u == b.u && a.j < b.j); }
bool operator==(const Cut& a, const Cut& b) { return a.u == b.u && a.j == b.j; }

// A window's two parts at a cut inside it.
struct Split {
  bool valid = false;
  Eigen::VectorXd delta;       // the step inside the window (tail minus head)
  Eigen::MatrixXd v;           // its covariance (the wander inside the window included)
  Eigen::MatrixXd g;           // I^-1 I+
  Eigen::MatrixXd head, tail;  // the parts' covariances given b (their weights)
  // Cov(delta, a_u) through the wander inside the window (zero without one: the step is a
  // contrast of the window's white residuals, uncorrelated with its estimate).
  Eigen::MatrixXd x;
};

// The group's time line at the joint fit.
struct Line {
  int p = 0, windows = 0;
  std::vector<Eigen::VectorXd> a;          // per window
  std::vector<Eigen::MatrixXd> own;        // per window: its covariance given b (widened)
  std::vector<Eigen::MatrixXd> cov;        // P_uv, u * windows + v
  std::vector<std::vector<Split>> splits;  // per window, per block j (0 unused)
  const Eigen::MatrixXd& P(int u, int v) const { return cov[u * windows + v]; }
};

// The prefix sums over the windows at a wander v: weights W_u = (C_u + v 1)^-1.
struct Sums {
  double v = 0.0;
  int n = 0;
  std::vector<Eigen::MatrixXd> w, sw, sww;  // W_u; sum_{<u} W; sum_{<u} W W^T
  std::vector<Eigen::VectorXd> swa;         // sum_{<u} W a
  std::vector<Eigen::MatrixXd> q;           // sum_{u'<a, v'<b} W P W^T, (n+1)^2
  std::vector<Eigen::MatrixXd> r;           // r[u][b] = sum_{v<b} P_uv W_v^T, n (n+1)
  Eigen::MatrixXd Q(int a1, int a2, int b1, int b2) const {
    const auto at = [&](int a, int b) -> const Eigen::MatrixXd& { return q[a * (n + 1) + b]; };
    return at(a2, b2) - at(a1, b2) - at(a2, b1) + at(a1, b1);
  }
  Eigen::MatrixXd R(int u, int b1, int b2) const {
    return r[u * (n + 1) + b2] - r[u * (n + 1) + b1];
  }
};

Eigen::MatrixXd Inverse(const Eigen::MatrixXd& m) {
  return m.ldlt().solve(Eigen::MatrixXd::Identity(m.rows(), m.cols()));
}

bool PositiveDefinite(const Eigen::MatrixXd& m) {
  return Eigen::LLT<Eigen::MatrixXd>(m).info() == Eigen::Success;
}

Eigen::MatrixXd Select(const Eigen::MatrixXd& m, const std::vector<int>& rows,
                       const std::vector<int>& cols) {
  Eigen::MatrixXd out(rows.size(), cols.size());
  for (size_t x = 0; x < rows.size(); ++x) {
    for (size_t y = 0; y < cols.size(); ++y) out(x, y) = m(rows[x], cols[y]);
  }
  return out;
}

// The blocks' information of the group, [I_b 1(lo <= b < hi)] as a p x Bp matrix.
Eigen::MatrixXd BlockInformation(const WindowFold& f, const std::vector<int>& g,
                                 const std::vector<int>& columns, int lo, int hi) {
  const int p = static_cast<int>(g.size());
  const int blocks = static_cast<int>(f.block_samples.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(p, blocks * p);
  for (int b = lo; b < hi; ++b) {
    for (int x = 0; x < p; ++x) {
      for (int y = 0; y < p; ++y) out(x, b * p + y) = f.block_information[b](g[x], columns[y]);
    }
  }
  return out;
}

// Window u's parts at each cut inside it (Split), from the scan of its blocks; with the
// wander inside the window (track_wander.cc) each part's exposure to it: the step's
// efficient score is s = sum_{b >= j} s_b - L^T M_loc^-1 (scores), L the tail's cross
// information with the window's local variables, so delta = -S^-1 s moves by
// E_delta eta, E_delta = -S^-1 ([I_b 1(b >= j)] - L^T M_loc^-1 R^T); a_u by
// E_a eta = -(M_loc^-1 R^T)_g eta; a part's own estimate given b by -I_part^-1 [I_b].
std::vector<Split> WindowSplits(const TrackRun& run, int u, const std::vector<int>& g,
                                const WanderExposure& wander) {
  std::vector<int> columns;
  for (int x : g) columns.push_back(run.layout.window_columns[x]);
  const double scale = run.birge[u];
  const std::vector<SplitScore> scores = ScanSplits(run, u, g, columns, scale);
  const WindowFold& f = run.windows[run.used[u]].fold;
  const Eigen::MatrixXd info = Select(f.information, columns, columns);
  const int p = static_cast<int>(g.size());
  const int blocks = static_cast<int>(scores.size());
  Eigen::MatrixXd e_a;
  if (wander.active) {
    e_a.resize(p, wander.k.cols());
    for (int x = 0; x < p; ++x) e_a.row(x) = -wander.formal_local_rows.row(g[x]);
  }
  std::vector<Split> out(scores.size());
  for (int j = 1; j < blocks; ++j) {
    const SplitScore& s = scores[j];
    const Eigen::MatrixXd after = s.after_information;
    const Eigen::MatrixXd before = info - after;
    if (!s.valid || !PositiveDefinite(s.schur) || !PositiveDefinite(after) ||
        !PositiveDefinite(before)) {
      continue;
    }
    Split& x = out[j];
    const Eigen::MatrixXd s_inverse = Inverse(s.schur);
    const Eigen::MatrixXd before_inverse = Inverse(before), after_inverse = Inverse(after);
    x.delta = -s_inverse * s.score;
    x.v = s_inverse * scale;
    x.g = info.ldlt().solve(after);
    x.head = before_inverse * scale;
    x.tail = after_inverse * scale;
    x.x = Eigen::MatrixXd::Zero(p, p);
    if (wander.active) {
      // The tail's cross information with the local variables, from the blocks' rows.
      Eigen::MatrixXd local = Eigen::MatrixXd::Zero(wander.local_rows.rows(), p);
      for (int b = j; b < blocks; ++b) local += wander.local_rows.middleCols(b * p, p);
      const Eigen::MatrixXd tail_blocks = BlockInformation(f, g, columns, j, blocks);
      const Eigen::MatrixXd e_delta =
          -s_inverse * (tail_blocks - local.transpose() * wander.formal_local_rows);
      const Eigen::MatrixXd e_head = -before_inverse * BlockInformation(f, g, columns, 0, j);
      const Eigen::MatrixXd e_tail = -after_inverse * tail_blocks;
      x.v += e_delta * wander.k * e_delta.transpose();
      x.x = e_delta * wander.k * e_a.transpose();
      x.head += e_head * wander.k * e_head.transpose();
      x.tail += e_tail * wander.k * e_tail.transpose();
    }
    x.valid = true;
  }
  return out;
}

Line BuildLine(const TrackRun& run, const std::vector<int>& g, int gi) {
  Line line;
  line.p = static_cast<int>(g.size());
  line.windows = static_cast<int>(run.used.size());
  const int n = line.windows;
  for (int u = 0; u < n; ++u) {
    const ArrowBlock& k = run.problem.blocks[u];
    Eigen::MatrixXd own = k.h.topLeftCorner(k.p, k.p);
    own.diagonal() += k.prior_information;
    const Eigen::MatrixXd own_inverse = Inverse(own);
    const WanderExposure wander = ExposureOf(run, u, gi);
    Eigen::MatrixXd c = Select(own_inverse, g, g) * run.widening[u];
    if (wander.active) {
      // The window's estimate given b moves by -A^-1 (R^T eta)_a.
      Eigen::MatrixXd e(line.p, wander.k.cols());
      for (int x = 0; x < line.p; ++x) {
        e.row(x) = -own_inverse.row(g[x]) * wander.local_rows.topRows(k.p);
      }
      c += e * wander.k * e.transpose();
    }
    line.own.push_back(c);
    Eigen::VectorXd a(line.p);
    for (int x = 0; x < line.p; ++x) a[x] = run.solver.a(u)[g[x]];
    line.a.push_back(a);
    line.splits.push_back(WindowSplits(run, u, g, wander));
  }
  line.cov.resize(static_cast<size_t>(n) * n);
  for (int u = 0; u < n; ++u) {
    for (int v = u; v < n; ++v) {
      line.cov[u * n + v] = Select(TotalCovariance(run, u, v), g, g);
      // u == v is the same matrix: a transpose onto itself aliases.
      if (v != u) line.cov[v * n + u] = line.cov[u * n + v].transpose();
    }
  }
  return line;
}

Sums BuildSums(const Line& line, double v) {
  Sums s;
  s.v = v;
  s.n = line.windows;
  const int n = s.n, p = line.p;
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(p, p);
  s.sw.assign(n + 1, zero);
  s.sww.assign(n + 1, zero);
  s.swa.assign(n + 1, Eigen::VectorXd::Zero(p));
  for (int u = 0; u < n; ++u) {
    s.w.push_back(Inverse(line.own[u] + v * Eigen::MatrixXd::Identity(p, p)));
    s.sw[u + 1] = s.sw[u] + s.w[u];
    s.sww[u + 1] = s.sww[u] + s.w[u] * s.w[u].transpose();
    s.swa[u + 1] = s.swa[u] + s.w[u] * line.a[u];
  }
  s.r.assign(static_cast<size_t>(n) * (n + 1), zero);
  for (int u = 0; u < n; ++u) {
    for (int b = 0; b < n; ++b) {
      s.r[u * (n + 1) + b + 1] = s.r[u * (n + 1) + b] + line.P(u, b) * s.w[b].transpose();
    }
  }
  s.q.assign(static_cast<size_t>(n + 1) * (n + 1), zero);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      // Row a's sum over v < b + 1, added to the rows above.
      const Eigen::MatrixXd row = s.w[a] * s.r[a * (n + 1) + b + 1];
      s.q[(a + 1) * (n + 1) + b + 1] = s.q[a * (n + 1) + b + 1] + row;
    }
  }
  return s;
}

// One side of a contrast: the whole windows [lo, hi) and a window's part at each end.
struct Part {
  int u = 0, j = 0;
  bool tail = false;
};
struct Side {
  int lo = 0, hi = 0;
  std::vector<Part> parts;
  Eigen::MatrixXd k;  // (sum of its weights)^-1
  Eigen::VectorXd mean;
};

// The units between cuts c1 < c2; false when there are none or both cuts are inside one
// window (a window holds at most one change).
bool MakeSide(const Line& line, const Cut& c1, const Cut& c2, Side* side) {
  if (c1.j > 0 && c2.j > 0 && c1.u == c2.u) return false;
  side->lo = c1.j > 0 ? c1.u + 1 : c1.u;
  side->hi = std::max(side->lo, c2.u);
  side->parts.clear();
  if (c1.j > 0) {
    if (!line.splits[c1.u][c1.j].valid) return false;
    side->parts.push_back({c1.u, c1.j, true});
  }
  if (c2.j > 0) {
    if (!line.splits[c2.u][c2.j].valid) return false;
    side->parts.push_back({c2.u, c2.j, false});
  }
  return side->hi > side->lo || !side->parts.empty();
}

Eigen::MatrixXd PartWeight(const Line& line, const Sums& s, const Part& x) {
  const Split& split = line.splits[x.u][x.j];
  const Eigen::MatrixXd& c = x.tail ? split.tail : split.head;
  return Inverse(c + s.v * Eigen::MatrixXd::Identity(line.p, line.p));
}

// The part's offset from its window's estimate, as a matrix on the split's delta.
Eigen::MatrixXd PartGain(const Line& line, const Part& x) {
  const Split& split = line.splits[x.u][x.j];
  return x.tail ? Eigen::MatrixXd(Eigen::MatrixXd::Identity(line.p, line.p) - split.g)
                : Eigen::MatrixXd(-split.g);
}

void SideMean(const Line& line, const Sums& s, Side* side) {
  Eigen::MatrixXd sw = s.sw[side->hi] - s.sw[side->lo];
  Eigen::VectorXd swa = s.swa[side->hi] - s.swa[side->lo];
  for (const Part& x : side->parts) {
    const Eigen::MatrixXd w = PartWeight(line, s, x);
    sw += w;
    swa += w * (line.a[x.u] + PartGain(line, x) * line.splits[x.u][x.j].delta);
  }
  side->k = Inverse(sw);
  side->mean = side->k * swa;
}

struct Contrast {
  bool valid = false;
  Eigen::VectorXd d;
  Eigen::MatrixXd covariance;
  double statistic = 0.0;
};

// Var(d) for d = sum over the sides (sign -1 before, +1 after) of K (sum W x). A part of
// window u is a_u + gain delta: its a_u through the joint sandwich (P), its delta through
// V, the two through the wander inside the window (Split::x); the day-to-day wander v is
// one effect per window, which the two parts of a window share.
Eigen::MatrixXd ContrastCovariance(const Line& line, const Sums& s, const Side* sides) {
  const int p = line.p;
  struct Single {
    int u, j;
    Eigen::MatrixXd alpha, beta;
  };
  std::vector<Single> singles;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(p, p);
  for (int x = 0; x < 2; ++x) {
    const double sign = x == 0 ? -1.0 : 1.0;
    for (const Part& part : sides[x].parts) {
      const Eigen::MatrixXd alpha = sign * sides[x].k * PartWeight(line, s, part);
      singles.push_back({part.u, part.j, alpha, alpha * PartGain(line, part)});
    }
    out += s.v * sides[x].k * (s.sww[sides[x].hi] - s.sww[sides[x].lo]) * sides[x].k.transpose();
  }
  for (int x = 0; x < 2; ++x) {
    const Eigen::MatrixXd mx = (x == 0 ? -1.0 : 1.0) * sides[x].k;
    for (int y = 0; y < 2; ++y) {
      const Eigen::MatrixXd my = (y == 0 ? -1.0 : 1.0) * sides[y].k;
      out += mx * s.Q(sides[x].lo, sides[x].hi, sides[y].lo, sides[y].hi) * my.transpose();
    }
    for (const Single& i : singles) {
      const Eigen::MatrixXd t = i.alpha * s.R(i.u, sides[x].lo, sides[x].hi) * mx.transpose();
      out += t + t.transpose();
    }
  }
  for (const Single& i : singles) {
    for (const Single& k : singles) {
      out += i.alpha * line.P(i.u, k.u) * k.alpha.transpose();
      if (i.u != k.u) continue;
      // One window's parts: the day's wander once, and delta with a_u through the wander
      // inside the window (the parts of one window are of one split).
      out += s.v * i.alpha * k.alpha.transpose();
      const Eigen::MatrixXd t = i.beta * line.splits[i.u][i.j].x * k.alpha.transpose();
      out += t + t.transpose();
    }
  }
  // The steps inside windows: the two parts of one split share its delta.
  std::vector<bool> done(singles.size(), false);
  for (size_t i = 0; i < singles.size(); ++i) {
    if (done[i]) continue;
    Eigen::MatrixXd beta = singles[i].beta;
    for (size_t k = i + 1; k < singles.size(); ++k) {
      if (singles[k].u != singles[i].u || singles[k].j != singles[i].j) continue;
      beta += singles[k].beta;
      done[k] = true;
    }
    out += beta * line.splits[singles[i].u][singles[i].j].v * beta.transpose();
  }
  return out;
}

// The contrast of the stretch [mid, hi) against [lo, mid).
Contrast ContrastAt(const Line& line, const Sums& s, const Cut& lo, const Cut& mid, const Cut& hi) {
  Contrast c;
  Side sides[2];
  if (!MakeSide(line, lo, mid, &sides[0]) || !MakeSide(line, mid, hi, &sides[1])) return c;
  SideMean(line, s, &sides[0]);
  SideMean(line, s, &sides[1]);
  c.d = sides[1].mean - sides[0].mean;
  c.covariance = ContrastCovariance(line, s, sides);
  if (!PositiveDefinite(c.covariance)) return c;
  c.statistic = c.d.dot(c.covariance.ldlt().solve(c.d));
  c.valid = std::isfinite(c.statistic);
  return c;
}

// Every cut of the line in time order: between windows, and inside each before each of
// its blocks that leaves kMinPartBlocks on either side.
std::vector<Cut> Candidates(const Line& line) {
  std::vector<Cut> out;
  for (int u = 0; u < line.windows; ++u) {
    if (u > 0) out.push_back({u, 0});
    const int blocks = static_cast<int>(line.splits[u].size());
    for (int j = kMinPartBlocks; j <= blocks - kMinPartBlocks; ++j) out.push_back({u, j});
  }
  return out;
}

struct Found {
  Cut cut;
  double statistic = 0.0;
};

// The best cut strictly between lo and hi.
Found BestBetween(const Line& line, const Sums& s, const std::vector<Cut>& candidates,
                  const Cut& lo, const Cut& hi) {
  Found best;
  best.statistic = -1.0;
  for (const Cut& c : candidates) {
    if (!(lo < c) || !(c < hi)) continue;
    const Contrast k = ContrastAt(line, s, lo, c, hi);
    if (k.valid && k.statistic > best.statistic) best = {c, k.statistic};
  }
  return best;
}

// The cuts with the line's ends around them.
std::vector<Cut> Bounded(const Line& line, const std::vector<Cut>& cuts) {
  std::vector<Cut> b = {{0, 0}};
  b.insert(b.end(), cuts.begin(), cuts.end());
  b.push_back({line.windows, 0});
  return b;
}

// Binary segmentation, then each change re-tested between its neighbours (the weakest
// below the threshold removed, until every one stands).
std::vector<Cut> Segment(const Line& line, const Sums& s, double threshold) {
  const std::vector<Cut> candidates = Candidates(line);
  std::vector<Cut> cuts;
  for (;;) {
    const std::vector<Cut> b = Bounded(line, cuts);
    Found best;
    for (size_t k = 0; k + 1 < b.size(); ++k) {
      const Found f = BestBetween(line, s, candidates, b[k], b[k + 1]);
      if (f.statistic > best.statistic) best = f;
    }
    if (!(best.statistic > threshold)) break;
    cuts.push_back(best.cut);
    std::sort(cuts.begin(), cuts.end());
  }
  for (;;) {
    const std::vector<Cut> b = Bounded(line, cuts);
    int weakest = -1;
    double smallest = threshold;
    for (size_t k = 1; k + 1 < b.size(); ++k) {
      const Contrast c = ContrastAt(line, s, b[k - 1], b[k], b[k + 1]);
      const double t = c.valid ? c.statistic : 0.0;
      if (t <= smallest) {
        smallest = t;
        weakest = static_cast<int>(k) - 1;
      }
    }
    if (weakest < 0) return cuts;
    cuts.erase(cuts.begin() + weakest);
  }
}

// The wander (SI variance per component) from the consecutive windows' differences that
// no change touches: the median of d^T (C + 2 v 1)^-1 d brought to the chi-square median.
double CleanWander(const Line& line, const std::vector<Cut>& cuts) {
  const int p = line.p;
  std::vector<Eigen::VectorXd> d;
  std::vector<Eigen::MatrixXd> c;
  for (int u = 1; u < line.windows; ++u) {
    bool touched = false;
    for (const Cut& k : cuts) touched = touched || k.u == u || (k.j > 0 && k.u == u - 1);
    if (touched) continue;
    d.push_back(line.a[u] - line.a[u - 1]);
    c.push_back(line.P(u, u) + line.P(u - 1, u - 1) - line.P(u, u - 1) - line.P(u - 1, u));
  }
  if (static_cast<int>(d.size()) < kMinWanderBoundaries) return 0.0;
  const double target = ChiSquareQuantile(0.5, p);
  const auto median_at = [&](double v) {
    std::vector<double> t;
    for (size_t k = 0; k < d.size(); ++k) {
      const Eigen::MatrixXd m = c[k] + 2.0 * v * Eigen::MatrixXd::Identity(p, p);
      t.push_back(d[k].dot(m.ldlt().solve(d[k])));
    }
    std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
    return t[t.size() / 2];
  };
  if (!(median_at(0.0) > target)) return 0.0;
  double hi = 0.0;  // the differences' own variance: where to start
  for (const Eigen::MatrixXd& m : c) hi = std::max(hi, m.diagonal().maxCoeff());
  hi = std::max(hi, 1e-300);
  for (int k = 0; k < 200 && median_at(hi) > target; ++k) hi *= 4.0;
  double lo = 0.0;
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (lo + hi);
    (median_at(mid) > target ? lo : hi) = mid;
  }
  return hi;
}

// The sample times either side of a cut: the last before it and the first after.
std::pair<double, double> CutTimes(const TrackRun& run, const Cut& c) {
  const TrackWindowState& w = run.windows[run.used[c.u]];
  if (c.j == 0) return {run.windows[run.used[c.u - 1]].last_s, w.first_s};
  return {w.fold.block_last_time_s[c.j - 1], w.fold.block_first_time_s[c.j]};
}

// The change's likelihood interval: the candidates between its neighbours lo and hi whose
// T is within LocationDrop() of its own (Hinkley 1970), as their first and last: a set of
// moments that may span a window's last blocks, the night and the next one's first.
struct Span {
  Cut first, last;
};
Span Interval(const Line& line, const Sums& s, const Cut& lo, const Cut& cut, const Cut& hi,
              double t) {
  const double floor = t - LocationDrop();
  Span span{cut, cut};
  for (const Cut& c : Candidates(line)) {
    if (!(lo < c) || !(c < hi)) continue;
    const Contrast k = ContrastAt(line, s, lo, c, hi);
    if (!k.valid || k.statistic < floor) continue;
    if (c < span.first) span.first = c;
    if (span.last < c) span.last = c;
  }
  return span;
}

// A change on a window's edge cannot be told from one between the windows: when a
// change's likelihood interval holds a window boundary, the change is put there (dated
// between the last sample before and the first after, where a maintenance would be), not
// in the edge block whose likelihood is about the same.
void PreferBoundaries(const Line& line, const Sums& s, std::vector<Cut>* cuts) {
  for (size_t k = 0; k < cuts->size(); ++k) {
    const std::vector<Cut> b = Bounded(line, *cuts);
    Cut& cut = (*cuts)[k];
    if (cut.j == 0) continue;
    const Contrast c = ContrastAt(line, s, b[k], cut, b[k + 2]);
    if (!c.valid) continue;
    const Span span = Interval(line, s, b[k], cut, b[k + 2], c.statistic);
    // The boundaries the span may hold: before this window, and before the next.
    const Cut before = {cut.u, 0}, after = {cut.u + 1, 0};
    const bool has_before = cut.u > 0 && !(before < span.first);
    const bool has_after = cut.u + 1 < line.windows && !(span.last < after);
    if (!has_before && !has_after) continue;
    const int blocks = static_cast<int>(line.splits[cut.u].size());
    cut = has_before && (!has_after || cut.j < blocks - cut.j) ? before : after;
  }
}

// The used windows the wander inside windows is estimated from: not those a change is
// inside (a cut of the group, or a sensor's step inside a window).
std::vector<bool> WanderWindows(const TrackRun& run, const std::vector<Cut>& cuts) {
  std::vector<bool> use(run.used.size(), true);
  for (const Cut& c : cuts) {
    if (c.j > 0) use[c.u] = false;
  }
  for (size_t u = 0; u < run.used.size(); ++u) {
    for (int e : run.entry_of[u]) use[u] = use[u] && !run.shared[e].inside;
  }
  return use;
}

// The changes of the group and its wanders (track_segment.cc's header): the wander inside
// windows and the day-to-day wander from every window and boundary first (a few steps
// leave the median alone; the estimate inside windows leaves out those it cannot explain),
// then without the windows and boundaries the changes found touch, until they stand.
std::vector<Cut> FindCuts(TrackRun& run, const std::vector<int>& g, int gi, double threshold,
                          Line* line, double* wander) {
  *line = BuildLine(run, g, gi);
  double v = CleanWander(*line, {});
  std::vector<Cut> cuts;
  for (int round = 0; round < kMaxWanderRounds; ++round) {
    const Sums s = BuildSums(*line, v);
    std::vector<Cut> found = Segment(*line, s, threshold);
    PreferBoundaries(*line, s, &found);
    const bool same =
        found.size() == cuts.size() && std::equal(found.begin(), found.end(), cuts.begin());
    if (!same) {
      EstimateWanderInside(run, gi, WanderWindows(run, found));
      ApplyWanderInside(run);
      *line = BuildLine(run, g, gi);
    }
    const double next = CleanWander(*line, found);
    cuts = found;
    if (same && std::abs(next - v) <= kWanderSettled * v) break;
    v = next;
  }
  *wander = v;
  return cuts;
}

// Window u's two parts at a cut j inside it (track.h, TrackEvent::parts): each part's
// estimate a_u + gain delta (PartGain), its covariance the part's own given b plus b's
// share of the window's (P_uu less its own), in the group's units.
std::vector<TrackWindowPart> WindowParts(const TrackRun& run, const Line& line,
                                         const std::vector<int>& g, const Cut& cut,
                                         double change_s) {
  const Split& split = line.splits[cut.u][cut.j];
  const TrackWindowState& w = run.windows[run.used[cut.u]];
  long long before = 0;
  for (int b = 0; b < cut.j; ++b) before += w.fold.block_samples[b];
  const Eigen::MatrixXd shared = line.P(cut.u, cut.u) - line.own[cut.u];
  std::vector<TrackWindowPart> parts;
  for (const bool tail : {false, true}) {
    const Part x{cut.u, cut.j, tail};
    const Eigen::VectorXd value = line.a[cut.u] + PartGain(line, x) * split.delta;
    const Eigen::MatrixXd& own = tail ? split.tail : split.head;
    TrackWindowPart part;
    part.start_s = tail ? change_s : w.start_s;
    part.end_s = tail ? w.end_s : change_s;
    part.samples = tail ? w.samples - before : before;
    for (size_t k = 0; k < g.size(); ++k) {
      const double to_si = run.layout.Column(run.layout.window_columns[g[k]]).to_si;
      const int x = static_cast<int>(k);
      part.estimates.push_back({value[x] / to_si,
                                std::sqrt(std::max(0.0, own(x, x) + shared(x, x))) / to_si,
                                std::sqrt(std::max(0.0, own(x, x))) / to_si});
    }
    parts.push_back(part);
  }
  return parts;
}

}  // namespace

int TimelineCandidates(const TrackRun& run) {
  int count = std::max(0, static_cast<int>(run.used.size()) - 1);
  for (int w : run.used) {
    const int blocks = static_cast<int>(run.windows[w].fold.block_samples.size());
    count += std::max(0, blocks - 2 * kMinPartBlocks + 1);
  }
  return count;
}

void SegmentGroup(TrackRun& run, const std::vector<int>& g, int gi, const GroupTest& test,
                  std::vector<TrackEvent>* out, double* wander) {
  const int p = static_cast<int>(g.size());
  const double threshold = ChiSquareQuantile(run.options.false_alarm / test.tests, p);
  Line line;
  double v = 0.0;
  const std::vector<Cut> cuts = FindCuts(run, g, gi, threshold, &line, &v);
  *wander = v;
  const Sums s = BuildSums(line, v);
  const std::vector<Cut> b = Bounded(line, cuts);
  for (size_t k = 1; k + 1 < b.size(); ++k) {
    const Contrast c = ContrastAt(line, s, b[k - 1], b[k], b[k + 1]);
    if (!c.valid) continue;
    const Cut& cut = b[k];
    TrackEvent e = EventAt(run, std::max(0, cut.u - 1), cut.u, test.kind, c.statistic, p, threshold,
                           test.tests);
    const std::pair<double, double> times = CutTimes(run, cut);
    e.previous_time_s = times.first;
    e.time_s = times.second;
    e.within_window = cut.j > 0;
    if (e.within_window) e.parts = WindowParts(run, line, g, cut, e.time_s);
    const Span span = Interval(line, s, b[k - 1], cut, b[k + 1], c.statistic);
    // A cut inside a window stands for a change anywhere in the blocks either side of it
    // (a block's samples are one unit of the scan): the interval spans them.
    const WindowFold& lo = run.windows[run.used[span.first.u]].fold;
    const WindowFold& hi = run.windows[run.used[span.last.u]].fold;
    e.time_low_s = span.first.j > 0 ? lo.block_first_time_s[span.first.j - 1]
                                    : CutTimes(run, span.first).first;
    e.time_high_s =
        span.last.j > 0 ? hi.block_last_time_s[span.last.j] : CutTimes(run, span.last).second;
    for (int x = 0; x < p; ++x) {
      const ParameterSpec& spec = run.layout.Column(run.layout.window_columns[g[x]]);
      e.parameters.push_back(
          {spec.name, spec.unit, c.d[x] / spec.to_si, std::sqrt(c.covariance(x, x)) / spec.to_si});
      if (test.kind == "sensor" && spec.index >= 0) e.cables.push_back(spec.index + 1);
    }
    run.Progress(
        run.layout.Column(run.layout.window_columns[g[0]]).name + (p > 1 ? " (group)" : "") +
        ": change " + (e.within_window ? "inside window " : "before window ") +
        run.windows[run.used[cut.u]].label + " at " +
        TrackTimeText(e.time_s, run.result->time_offset_s) + " (statistic " +
        FormatDouble("%.1f", c.statistic) + ", threshold " + FormatDouble("%.1f", threshold) + ")");
    out->push_back(e);
  }
}

}  // namespace fastcal::internal
