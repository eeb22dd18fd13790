// The change scan (change_scan.h): split units, the linearised step statistic over the
// split times, its null distribution by parametric bootstrap, binary segmentation.
#include "fastcal/change_scan.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/number_text.h"
#include "util/yaml_document.h"

namespace fastcal {
namespace {

// A widening above this is said beside a change found: the residuals have memory, and a
// slow sensor drift (whose false alarms docs/calibration.md states) is a suspect.
constexpr double kMemoryWorthSaying = 1.5;

// An integrated autocorrelation time up to this counts as white (a white series of a
// thousand samples gives 1 +- ~0.2 by Sokal's window).
constexpr double kWhiteTau = 1.5;

// A group of consecutive fitted samples: splits fall between groups.
struct Unit {
  int first = 0;          // first row
  Eigen::MatrixXd info;   // sum J_t^T J_t (n x n)
  Eigen::VectorXd score;  // sum J_t^T r_t (n)
  // F with F F^T = info: the unit's score under white unit noise is F z, z ~ N(0, I).
  // The stacked J_t^T when that is narrower than n, else info's symmetric square root.
  Eigen::MatrixXd noise;
};

Eigen::MatrixXd SquareRoot(const Eigen::MatrixXd& info) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(info);
  const Eigen::VectorXd root = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return eig.eigenvectors() * root.asDiagonal();
}

std::vector<Unit> MakeUnits(const ChangeScanInputs& in, int* unit_samples) {
  const int rows = static_cast<int>(in.residuals->rows());
  const int n = in.num_free, m = in.rows_per_sample;
  const int per_unit = std::max(1, (rows + kMaxScanUnits - 1) / kMaxScanUnits);
  *unit_samples = per_unit;
  std::vector<Unit> units;
  for (int first = 0; first < rows; first += per_unit) {
    const int count = std::min(per_unit, rows - first);
    Unit u;
    u.first = first;
    Eigen::MatrixXd stacked(m * count, n);  // J rows of the unit
    Eigen::VectorXd r(m * count);
    for (int t = 0; t < count; ++t) {
      for (int i = 0; i < m; ++i) {
        stacked.row(t * m + i) = in.jacobians->row(first + t).segment(i * n, n).cast<double>();
        r[t * m + i] = (*in.residuals)(first + t, i);
      }
    }
    u.info = stacked.transpose() * stacked;
    u.score = stacked.transpose() * r;
    u.noise = stacked.rows() <= n ? Eigen::MatrixXd(stacked.transpose()) : SquareRoot(u.info);
    units.push_back(std::move(u));
  }
  return units;
}

// Standard normal draws from the top 53 bits of std::mt19937_64, by Box-Muller: the same
// sequence with every standard library.
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : rng_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = 0.0;
    while (u1 <= 0.0) u1 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
    const double u2 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
    const double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 rng_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

// One round of binary segmentation: the changes found so far (unit indices, sorted) in
// the nuisance, every admissible split of every segment between them.
class Round {
 public:
  Round(const ChangeScanInputs& in, const std::vector<Unit>& units,
        const std::vector<Eigen::MatrixXd>& info_from,
        const std::vector<Eigen::VectorXd>& score_from, const std::vector<int>& changes,
        bool with_splits = true)
      : in_(in), units_(units), info_from_(info_from), changes_(changes) {
    n_ = in.num_free;
    p_ = static_cast<int>(in.scanned.size());
    dim_ = n_ + p_ * static_cast<int>(changes.size());
    BuildNuisance(score_from);
    if (with_splits) BuildSplits(score_from);
  }

  // The linear fit with the changes: beta = -M_X^-1 V (free parameters, then the steps).
  Eigen::VectorXd Fit() const { return -inverse_ * gradient_; }

  // Sets each split's statistic to its raw one over w^2.
  void Widen(double w) {
    for (Split& s : splits_) s.statistic = s.raw / (w * w);
  }

  int num_segments() const { return static_cast<int>(segments_.size()); }
  const Eigen::MatrixXd& nuisance_inverse() const { return inverse_; }
  const Eigen::VectorXd& nuisance_gradient() const { return gradient_; }

  // The observed statistic at each admissible split, by segment.
  struct Split {
    int unit = 0, segment = 0;
    Eigen::MatrixXd cross;      // B_k (dim x p)
    Eigen::MatrixXd s_inverse;  // S_k^-1 (p x p)
    double raw = 0.0;           // h^T S^-1 h on the white scale
    double statistic = 0.0;     // raw / w^2
  };
  const std::vector<Split>& splits() const { return splits_; }

  // Per segment, the largest null statistic of `replicates` draws.
  std::vector<std::vector<double>> NullMaxima(int replicates, std::uint64_t seed) const {
    std::vector<std::vector<double>> maxima(segments_.size());
    Normal normal(seed);
    const int num_units = static_cast<int>(units_.size());
    std::vector<Eigen::VectorXd> from(num_units + 1, Eigen::VectorXd::Zero(n_));
    Eigen::VectorXd v(dim_);
    for (int rep = 0; rep < replicates; ++rep) {
      for (int u = num_units - 1; u >= 0; --u) {
        const Eigen::MatrixXd& f = units_[u].noise;
        Eigen::VectorXd z(f.cols());
        for (int k = 0; k < z.size(); ++k) z[k] = normal();
        from[u] = from[u + 1] + f * z;
      }
      v.head(n_) = from[0];
      for (int k = 0; k < n_; ++k) v[k] += std::sqrt(in_.prior_information[k]) * normal();
      for (size_t c = 0; c < changes_.size(); ++c)
        v.segment(n_ + c * p_, p_) = Scanned(from[changes_[c]]);
      const Eigen::VectorXd projected = inverse_ * v;
      std::vector<double> best(segments_.size(), 0.0);
      for (const Split& s : splits_) {
        const Eigen::VectorXd h = Scanned(from[s.unit]) - s.cross.transpose() * projected;
        best[s.segment] = std::max(best[s.segment], h.dot(s.s_inverse * h));
      }
      for (size_t g = 0; g < segments_.size(); ++g) maxima[g].push_back(best[g]);
    }
    return maxima;
  }

 private:
  Eigen::VectorXd Scanned(const Eigen::VectorXd& v) const {
    Eigen::VectorXd out(p_);
    for (int j = 0; j < p_; ++j) out[j] = v[in_.scanned[j]];
    return out;
  }
  // Columns G of rows `rows` of info_from[unit]: sum over units >= unit of J^T J_G.
  Eigen::MatrixXd CrossFrom(int unit) const {
    Eigen::MatrixXd out(n_, p_);
    for (int j = 0; j < p_; ++j) out.col(j) = info_from_[unit].col(in_.scanned[j]);
    return out;
  }
  Eigen::MatrixXd ScannedBlock(int unit) const {
    Eigen::MatrixXd out(p_, p_);
    for (int a = 0; a < p_; ++a) {
      for (int b = 0; b < p_; ++b) out(a, b) = info_from_[unit](in_.scanned[a], in_.scanned[b]);
    }
    return out;
  }
  // B for a step starting at `unit`: its cross with the free parameters and each change.
  Eigen::MatrixXd Cross(int unit) const {
    Eigen::MatrixXd b(dim_, p_);
    b.topRows(n_) = CrossFrom(unit);
    for (size_t c = 0; c < changes_.size(); ++c) {
      b.middleRows(n_ + c * p_, p_) = ScannedBlock(std::max(unit, changes_[c]));
    }
    return b;
  }

  void BuildNuisance(const std::vector<Eigen::VectorXd>& score_from) {
    Eigen::MatrixXd m(dim_, dim_);
    m.topLeftCorner(n_, n_) = info_from_[0];
    m.topLeftCorner(n_, n_).diagonal() += in_.prior_information;
    gradient_.resize(dim_);
    gradient_.head(n_) = score_from[0] + in_.prior_gradient;
    for (size_t c = 0; c < changes_.size(); ++c) {
      const Eigen::MatrixXd b = Cross(changes_[c]);
      m.middleCols(n_ + c * p_, p_) = b;
      m.middleRows(n_ + c * p_, p_) = b.transpose();
      gradient_.segment(n_ + c * p_, p_) = Scanned(score_from[changes_[c]]);
    }
    inverse_ = m.ldlt().solve(Eigen::MatrixXd::Identity(dim_, dim_));
  }

  void BuildSplits(const std::vector<Eigen::VectorXd>& score_from) {
    const int num_units = static_cast<int>(units_.size());
    const int rows = static_cast<int>(in_.residuals->rows());
    std::vector<int> bounds{0};
    bounds.insert(bounds.end(), changes_.begin(), changes_.end());
    bounds.push_back(num_units);
    const auto first_row = [&](int unit) { return unit < num_units ? units_[unit].first : rows; };
    const Eigen::VectorXd projected = inverse_ * gradient_;
    for (size_t g = 0; g + 1 < bounds.size(); ++g) {
      segments_.push_back({bounds[g], bounds[g + 1]});
      for (int k = bounds[g] + 1; k < bounds[g + 1]; ++k) {
        if (first_row(k) - first_row(bounds[g]) < in_.min_segment ||
            first_row(bounds[g + 1]) - first_row(k) < in_.min_segment) {
          continue;
        }
        Split s;
        s.unit = k;
        s.segment = static_cast<int>(g);
        s.cross = Cross(k);
        const Eigen::MatrixXd schur = ScannedBlock(k) - s.cross.transpose() * inverse_ * s.cross;
        const Eigen::LDLT<Eigen::MatrixXd> ldlt(schur);
        if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
            !(ldlt.vectorD().minCoeff() > 0.0)) {
          continue;  // the scanned parameters do not act on one side
        }
        s.s_inverse = ldlt.solve(Eigen::MatrixXd::Identity(p_, p_));
        const Eigen::VectorXd h = Scanned(score_from[k]) - s.cross.transpose() * projected;
        s.raw = s.statistic = h.dot(s.s_inverse * h);
        splits_.push_back(std::move(s));
      }
    }
  }

  const ChangeScanInputs& in_;
  const std::vector<Unit>& units_;
  const std::vector<Eigen::MatrixXd>& info_from_;
  std::vector<int> changes_;
  int n_ = 0, p_ = 0, dim_ = 0;
  Eigen::MatrixXd inverse_;   // M_X^-1
  Eigen::VectorXd gradient_;  // V
  std::vector<std::pair<int, int>> segments_;
  std::vector<Split> splits_;
};

// w from the residuals with the free parameters and `steps` (units, sorted) fitted
// linearly: per scanned parameter, the long-run variance of its score J_t,G^T r'_t
// (overlapping batch means of `bandwidth` samples, uncertainty.h) over its value for
// white unit noise, sum J_t,G^T J_t,G; the largest, never below 1. With the step in the
// fit, the step itself does not count as misfit or memory of the residuals.
double MeasuredWidening(const ChangeScanInputs& in, const std::vector<Unit>& units,
                        const std::vector<int>& steps, const Eigen::VectorXd& beta) {
  const int rows = static_cast<int>(in.residuals->rows());
  const int n = in.num_free, m = in.rows_per_sample, p = static_cast<int>(in.scanned.size());
  const int bandwidth = std::max(1, in.bandwidth);
  Eigen::MatrixXd scores(rows, p);
  Eigen::VectorXd white = Eigen::VectorXd::Zero(p);
  Eigen::MatrixXd j(m, n);
  for (int t = 0; t < rows; ++t) {
    for (int i = 0; i < m; ++i) j.row(i) = in.jacobians->row(t).segment(i * n, n).cast<double>();
    Eigen::VectorXd shift = beta.head(n);
    for (size_t c = 0; c < steps.size(); ++c) {
      if (t < units[steps[c]].first) continue;
      for (int g = 0; g < p; ++g) shift[in.scanned[g]] += beta[n + c * p + g];
    }
    const Eigen::VectorXd r = in.residuals->row(t).transpose() + j * shift;
    for (int g = 0; g < p; ++g) {
      scores(t, g) = j.col(in.scanned[g]).dot(r);
      white[g] += j.col(in.scanned[g]).squaredNorm();
    }
  }
  double ratio = 1.0;
  for (int g = 0; g < p; ++g) {
    // The batch length: the budget's, or longer for this score's own memory (the budget
    // judges its influence series, in which a slow error may not stand out while it
    // still moves the scan's partial sums).
    const double tau =
        rows >= kMinSamplesForCorrelation ? IntegratedAutocorrelationTime(scores.col(g)).tau : 1.0;
    const int own = static_cast<int>(std::ceil(kBandwidthPerTau * std::max(1.0, tau)));
    const int length = std::clamp(std::max(bandwidth, tau > kWhiteTau ? own : 1), 1,
                                  std::max(1, static_cast<int>(kMaxBandwidthFraction * rows)));
    const double omega = LongRunCovarianceOfSum(scores.col(g), length)(0, 0);
    if (white[g] > 0.0) ratio = std::max(ratio, omega / white[g]);
  }
  return std::sqrt(ratio);
}

// The changes plus the best remaining split by the raw statistic: the alternative the
// round tests, whose residuals measure w. Not every split the scan may still report:
// on a survey with slow sensor drift those steps absorb the drift's low frequencies,
// which then no longer widen the scan (74% false alarms against 18% with one step, on
// the realistic simulation of docs/calibration.md); the price is that a second step of
// opposite sign counts as memory while the first is tested.
std::vector<int> StepsForWidening(const Round& r, std::vector<int> steps) {
  const auto best = std::max_element(r.splits().begin(), r.splits().end(),
                                     [](const auto& a, const auto& b) { return a.raw < b.raw; });
  steps.push_back(best->unit);
  std::sort(steps.begin(), steps.end());
  return steps;
}

// P(chi-square with `dof` degrees of freedom > x), for dof 1..3 (the scanned parameters
// of a mass centre): closed forms.
double ChiSquareTail(double x, int dof) {
  if (!(x > 0.0)) return 1.0;
  if (dof == 1) return std::erfc(std::sqrt(x / 2.0));
  if (dof == 2) return std::exp(-x / 2.0);
  if (dof == 3) {
    return std::erfc(std::sqrt(x / 2.0)) + std::sqrt(2.0 * x / M_PI) * std::exp(-x / 2.0);
  }
  // More parameters: the Wilson-Hilferty normal approximation.
  const double k = dof,
               z = (std::cbrt(x / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

// The scanned parameters' linear trend over the survey (change_scan.h), widened by w.
void TestTrend(const ChangeScanInputs& in, double w, ChangeScanOutput* out) {
  const int rows = static_cast<int>(in.residuals->rows());
  const int n = in.num_free, m = in.rows_per_sample, p = static_cast<int>(in.scanned.size());
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(n, n), cross = Eigen::MatrixXd::Zero(n, p);
  Eigen::MatrixXd self = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(n), score = Eigen::VectorXd::Zero(p);
  Eigen::MatrixXd j(m, n), z(m, p);
  for (int t = 0; t < rows; ++t) {
    const double s = (t - 0.5 * (rows - 1)) / rows;
    for (int i = 0; i < m; ++i) j.row(i) = in.jacobians->row(t).segment(i * n, n).cast<double>();
    for (int g = 0; g < p; ++g) z.col(g) = s * j.col(in.scanned[g]);
    const Eigen::VectorXd r = in.residuals->row(t).transpose();
    info.noalias() += j.transpose() * j;
    cross.noalias() += j.transpose() * z;
    self.noalias() += z.transpose() * z;
    gradient.noalias() += j.transpose() * r;
    score.noalias() += z.transpose() * r;
  }
  info.diagonal() += in.prior_information;
  gradient += in.prior_gradient;
  const Eigen::LDLT<Eigen::MatrixXd> nuisance(info);
  const Eigen::MatrixXd schur = self - cross.transpose() * nuisance.solve(cross);
  const Eigen::VectorXd h = score - cross.transpose() * nuisance.solve(gradient);
  const Eigen::LDLT<Eigen::MatrixXd> s(schur);
  if (s.info() != Eigen::Success || !(s.vectorD().minCoeff() > 0.0)) return;
  const Eigen::MatrixXd s_inverse = s.solve(Eigen::MatrixXd::Identity(p, p));
  out->trend_statistic = h.dot(s_inverse * h) / (w * w);
  out->trend_p_value = ChiSquareTail(out->trend_statistic, p);
  out->trend_shift = -s_inverse * h;
  out->trend_shift_sigma = w * s_inverse.diagonal().cwiseMax(0.0).cwiseSqrt();
}

double PValue(const std::vector<double>& null_maxima, double observed) {
  const auto above = std::count_if(null_maxima.begin(), null_maxima.end(),
                                   [observed](double w) { return w >= observed; });
  return (1.0 + static_cast<double>(above)) / (1.0 + static_cast<double>(null_maxima.size()));
}

// The (1 - alpha) quantile of the null maxima.
double Quantile(std::vector<double> values, double alpha) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t k = std::min(values.size() - 1,
                            static_cast<size_t>(std::ceil((1.0 - alpha) * values.size())) - 1);
  return values[k];
}

bool CheckInputs(const ChangeScanInputs& in, std::string* error) {
  const auto fail = [error](const std::string& what) {
    *error = "change scan: " + what;
    return false;
  };
  if (in.residuals == nullptr || in.jacobians == nullptr) return fail("no linearisation");
  const int n = in.num_free;
  if (in.jacobians->rows() != in.residuals->rows() || in.residuals->cols() != in.rows_per_sample ||
      in.jacobians->cols() != in.rows_per_sample * n || in.prior_information.size() != n ||
      in.prior_gradient.size() != n) {
    return fail("inputs of different sizes");
  }
  if (in.scanned.empty()) return fail("no scanned parameter");
  for (int k : in.scanned) {
    if (k < 0 || k >= n) return fail("scanned parameter out of range");
  }
  if (in.min_segment < 1 || in.replicates < 1 || in.max_changes < 1 ||
      !(in.significance > 0.0 && in.significance < 1.0) || !(in.widening >= 0.0) ||
      in.bandwidth < 1) {
    return fail("bad options");
  }
  return true;
}

}  // namespace

bool ScanForChanges(const ChangeScanInputs& in, ChangeScanOutput* out, std::string* error) {
  if (!CheckInputs(in, error)) return false;
  *out = ChangeScanOutput();
  const std::vector<Unit> units = MakeUnits(in, &out->unit_samples);
  const int num_units = static_cast<int>(units.size());
  const int n = in.num_free;
  // Sums over the units from u on.
  std::vector<Eigen::MatrixXd> info_from(num_units + 1, Eigen::MatrixXd::Zero(n, n));
  std::vector<Eigen::VectorXd> score_from(num_units + 1, Eigen::VectorXd::Zero(n));
  for (int u = num_units - 1; u >= 0; --u) {
    info_from[u] = info_from[u + 1] + units[u].info;
    score_from[u] = score_from[u + 1] + units[u].score;
  }
  std::vector<int> changes;  // unit indices, sorted
  std::vector<DetectedChange> found;
  for (int round = 0; round <= in.max_changes; ++round) {
    Round r(in, units, info_from, score_from, changes);
    if (r.splits().empty()) break;
    // w: fixed, or measured with the round's best step fitted.
    double w = in.widening;
    if (!(w > 0.0)) {
      const std::vector<int> steps = StepsForWidening(r, changes);
      w = MeasuredWidening(in, units, steps,
                           Round(in, units, info_from, score_from, steps, false).Fit());
    }
    r.Widen(w);
    const std::vector<std::vector<double>> maxima =
        r.NullMaxima(in.replicates, in.seed + static_cast<std::uint64_t>(round));
    if (round == 0) {
      for (const Round::Split& s : r.splits()) {
        out->splits.push_back(units[s.unit].first);
        out->statistic.push_back(s.statistic);
      }
      out->threshold = Quantile(maxima[0], in.significance);
      out->widening = w;
      for (const Round::Split& s : r.splits()) {
        out->best_step_statistic = std::max(out->best_step_statistic, s.statistic);
      }
      TestTrend(in, w, out);
    }
    if (round == in.max_changes) break;
    // The most significant segment maximum.
    const Round::Split* best = nullptr;
    double best_p = 2.0;
    std::vector<const Round::Split*> top(r.num_segments(), nullptr);
    for (const Round::Split& s : r.splits()) {
      if (top[s.segment] == nullptr || s.statistic > top[s.segment]->statistic) top[s.segment] = &s;
    }
    for (int g = 0; g < r.num_segments(); ++g) {
      if (top[g] == nullptr) continue;
      const double p = PValue(maxima[g], top[g]->statistic);
      if (p < best_p || (p == best_p && top[g]->statistic > best->statistic)) {
        best = top[g];
        best_p = p;
      }
    }
    if (best == nullptr || !(best_p <= in.significance)) break;
    DetectedChange c;
    c.split = units[best->unit].first;
    c.statistic = best->statistic;
    c.p_value = best_p;
    found.push_back(c);
    changes.push_back(best->unit);
    std::sort(changes.begin(), changes.end());
  }
  if (found.empty()) return true;
  // The steps from the linear fit with every change: beta = -M_X^-1 V.
  const Round all(in, units, info_from, score_from, changes, false);
  const Eigen::VectorXd beta = all.Fit();
  const double w = in.widening > 0.0 ? in.widening : MeasuredWidening(in, units, changes, beta);
  const int p = static_cast<int>(in.scanned.size());
  std::sort(found.begin(), found.end(),
            [](const auto& a, const auto& b) { return a.split < b.split; });
  for (size_t c = 0; c < found.size(); ++c) {
    const int at = n + static_cast<int>(c) * p;
    found[c].shift = beta.segment(at, p);
    found[c].shift_sigma =
        w * all.nuisance_inverse().diagonal().segment(at, p).cwiseMax(0.0).cwiseSqrt();
  }
  out->changes = std::move(found);
  return true;
}

namespace {

// "2024-05-01 12:00:03 +08:00" for a Unix time, "t = 800 s" for seconds.
std::string Instant(double time_s, const TimeDisplay& display) {
  return display.absolute ? TimeText(time_s, display) : "t = " + TimeText(time_s, display);
}

}  // namespace

std::string ChangeScanVerdict(const ChangeScanResult& scan) {
  using internal::FormatDouble;
  std::string groups;
  for (const std::string& g : scan.groups) groups += (groups.empty() ? "" : ", ") + g;
  if (scan.time_s.empty()) {
    return "the survey is too short to scan " + groups + " for a change (" +
           std::to_string(scan.min_segment) + " samples needed on each side)";
  }
  if (scan.changes.empty()) {
    const double largest = *std::max_element(scan.statistic.begin(), scan.statistic.end());
    return "no change of " + groups + " found within the survey (largest scan statistic " +
           FormatDouble("%.3g", largest) + " against " + FormatDouble("%.3g", scan.threshold) +
           ", the " + FormatDouble("%g", 100.0 * scan.significance) + "% threshold)";
  }
  std::string out;
  for (const FoundChange& c : scan.changes) {
    std::string shifts;
    for (size_t k = 0; k < c.shift.size(); ++k) {
      shifts += (k ? ", " : "") + scan.parameters[k] + " " + FormatDouble("%+.3g", c.shift[k]) +
                " +- " + FormatDouble("%.2g", c.shift_sigma[k]) + " " + scan.units[k];
    }
    out += (out.empty() ? "" : "; ") + std::string("a change at ") +
           Instant(c.time_s, scan.time_display) + " (line " + std::to_string(c.line) + ", p " +
           FormatDouble("%.2g", c.p_value) + "): " + shifts;
  }
  if (scan.wanders) {
    std::string trend;
    for (size_t k = 0; k < scan.trend_shift.size(); ++k) {
      trend += (k ? ", " : "") + scan.parameters[k] + " " +
               FormatDouble("%+.3g", scan.trend_shift[k]) + " +- " +
               FormatDouble("%.2g", scan.trend_shift_sigma[k]) + " " + scan.units[k];
    }
    out += "; but the data show a gradual change (a wandering) rather than a step: " +
           std::string(scan.changes.size() > 1 ? "several steps were needed; " : "") +
           "its time is between " + Instant(scan.change_time_low_s, scan.time_display) + " and " +
           Instant(scan.change_time_high_s, scan.time_display) +
           " (95%); a steady trend explains " +
           (scan.trend_statistic >= scan.best_step_statistic ? "at least as much as"
                                                             : "some of what") +
           " the best step (statistic " + FormatDouble("%.3g", scan.trend_statistic) + " against " +
           FormatDouble("%.3g", scan.best_step_statistic) + "; over the survey " + trend + ")";
  }
  if (scan.widening > kMemoryWorthSaying) {
    out += " (the residuals' memory widens the scan by " + FormatDouble("%.2g", scan.widening) +
           ": an error the noise model leaves out (a slow drift it does not model) can also "
           "look like a step; docs/calibration.md, \"Change scan\")";
  }
  return out + ". The estimates are an average over " + (scan.changes.size() == 1 ? "it" : "them") +
         ": cut the survey there, --sessions-at=" + SessionsAtText(scan) +
         ", and fit with sessions: {separate: [" + groups + "]}";
}

std::string SessionsAtText(const ChangeScanResult& scan) {
  std::string text;
  for (const FoundChange& c : scan.changes) {
    text += (text.empty() ? "" : ",") + TimeValueText(c.time_s, scan.time_display);
  }
  return text;
}

bool ReadSummaryChangeTimes(const std::string& path, std::vector<double>* times_s,
                            std::string* error) {
  constexpr long long kMaxSummaryBytes = 256LL << 20;
  std::string text;
  if (!internal::ReadRegularFile(path, kMaxSummaryBytes, "summary.json", &text, error)) {
    return false;
  }
  const std::string what = path + ": ";
  try {
    const internal::YamlDocuments documents = internal::LoadYamlDocuments(text);
    const YAML::Node& root = documents.first;
    if (!root.IsMap() || !root["changes"] || !root["change_scan"]) {
      *error = what + "not the summary.json of fastcal calibrate (no \"changes\")";
      return false;
    }
    if (root["change_scan"].IsNull()) {
      *error = what +
               "that calibration had no change scan (a spec with change_scan: {...}, "
               "docs/calibration.md, \"Change scan\")";
      return false;
    }
    const YAML::Node changes = root["changes"];
    if (!changes.IsSequence() || changes.size() == 0) {
      *error = what + "its change scan found no change: nothing to cut at";
      return false;
    }
    std::vector<double> times;
    for (const YAML::Node& change : changes) {
      double t = 0.0;
      if (!change.IsMap() || !change["time_s"] ||
          !internal::ParseDouble(change["time_s"].Scalar(), &t) || !std::isfinite(t)) {
        *error = what + "a change without a finite time_s";
        return false;
      }
      times.push_back(t);
    }
    *times_s = std::move(times);
    return true;
  } catch (const std::exception& e) {
    *error = what + "cannot read it as JSON: " + e.what();
    return false;
  }
}

void SetChangeTimeAndWandering(int scanned, ChangeScanResult* scan) {
  scan->wanders = false;
  if (scan->statistic.empty()) return;
  // Chi-square 95% points for 1, 2, 3 degrees of freedom (the mass centre's axes), and
  // the Wilson-Hilferty approximation beyond.
  const double kChiSquare95[] = {3.841, 5.991, 7.815};
  const double c =
      scanned <= 3
          ? kChiSquare95[std::max(scanned, 1) - 1]
          : scanned *
                std::pow(1.0 - 2.0 / (9.0 * scanned) + 1.645 * std::sqrt(2.0 / (9.0 * scanned)), 3);
  const double best = *std::max_element(scan->statistic.begin(), scan->statistic.end());
  scan->change_time_low_s = std::numeric_limits<double>::infinity();
  scan->change_time_high_s = -std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < scan->statistic.size(); ++k) {
    if (scan->statistic[k] < best - c) continue;
    scan->change_time_low_s = std::min(scan->change_time_low_s, scan->time_s[k]);
    scan->change_time_high_s = std::max(scan->change_time_high_s, scan->time_s[k]);
  }
  const auto [first, last] = std::minmax_element(scan->time_s.begin(), scan->time_s.end());
  const double span = *last - *first;
  const bool undetermined = span > 0.0 && scan->change_time_high_s - scan->change_time_low_s >
                                              kMaxStepTimeFraction * span;
  scan->wanders = !scan->changes.empty() &&
                  (scan->changes.size() > 1 || scan->trend_statistic >= scan->best_step_statistic ||
                   undetermined);
}

}  // namespace fastcal
