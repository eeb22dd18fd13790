// The slow-error process estimated from a fit's residuals (internal/slow_error_estimate.h).
#include "fastcal/internal/slow_error_estimate.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>

#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/slow_error_filter.h"

namespace fastcal::internal {
namespace {

// tau's search range, in units of the median sampling interval (below: white at this
// sampling) and of the longest series' span (beyond: a constant the biases absorb).
constexpr double kMinTauPerInterval = 0.2;
constexpr double kMaxTauPerSpan = 10.0;
// The amplitude's search range, as a ratio to the white sigma.
constexpr double kMaxSlowErrorRatio = 20.0;
// Nelder-Mead: at most this many evaluations, stopping when the simplex's values agree
// to this (in -2 l, i.e. a hundredth of a log-likelihood unit).
constexpr int kMaxEvaluations = 120;
constexpr double kValueTolerance = 1e-2;
// Step of the central differences for the curvature, in log units.
constexpr double kCurvatureStep = 0.1;
// A nuisance column whose pivot in the unit-diagonal Gram matrix is below this is the
// others' combination to rounding: the session does not inform it.
constexpr double kCollinearPivot = 1e-9;
// Chi-square(2) 99% quantile: a stated process the likelihood rejects at 1%.
constexpr double kChiSquare2Quantile99 = 9.21034;

// The ratio sigma_e / s of one reading: the stated part plus the estimated one.
struct RatioModel {
  SlowErrorProcess process;
  double Ratio(double reading_n, double sigma_n) const {
    return process.SigmaN(reading_n) / sigma_n;
  }
};

// Per cable and session: X~^T X~ and X~^T x~ of the nuisance columns.
struct NuisanceSums {
  Eigen::Matrix2d gram = Eigen::Matrix2d::Zero();
  Eigen::Vector2d cross = Eigen::Vector2d::Zero();
};

// log det G - b^T G^-1 b of the first `columns` nuisance columns; a column the session
// does not inform (the gain's, when the reading hardly changes) is dropped. Judged on G
// scaled to a unit diagonal: the columns' units differ by a reading's (1 / s against
// r / s: ~10^10 in their squares), and a test on G itself dropped an informed gain.
double RestrictedTerm(const NuisanceSums& sums, int columns) {
  for (int c = columns; c >= 1; --c) {
    const Eigen::MatrixXd g = sums.gram.topLeftCorner(c, c);
    const Eigen::VectorXd scale = g.diagonal().cwiseMax(0.0).cwiseSqrt();
    if (!(scale.minCoeff() > 0.0)) return 0.0;  // no reading of this cable in this session
    const Eigen::VectorXd inverse = scale.cwiseInverse();
    const Eigen::MatrixXd unit = inverse.asDiagonal() * g * inverse.asDiagonal();
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(unit);
    const Eigen::VectorXd d = ldlt.vectorD();
    if (d.minCoeff() <= kCollinearPivot) continue;
    const Eigen::VectorXd b = inverse.cwiseProduct(sums.cross.head(c));
    return d.array().log().sum() + 2.0 * scale.array().log().sum() - b.dot(ldlt.solve(b));
  }
  return 0.0;
}

int CountSessions(const std::vector<SlowErrorSample>& samples) {
  int sessions = 1;
  for (const SlowErrorSample& s : samples) sessions = std::max(sessions, s.session + 1);
  return sessions;
}

}  // namespace

namespace {

// The inputs laid out once for the search's ~100 evaluations: per sample the interval
// from the previous one (kNewSeries where a series starts) and its session; per cable,
// its readings contiguous, x, 1 / s, r / s and whether the reading is kept.
struct LaidOut {
  static constexpr double kNewSeries = -1.0;
  int count = 0, sessions = 1, nuisance = 1;
  std::vector<double> dt_s;
  std::vector<int> session;
  std::array<std::vector<double>, kNumCables> x, inverse_s, reading_over_s;
  std::array<std::vector<unsigned char>, kNumCables> kept;
};

LaidOut LayOut(const SlowErrorEstimateInputs& in) {
  LaidOut out;
  out.count = static_cast<int>(in.samples.size());
  out.sessions = CountSessions(in.samples);
  out.nuisance = in.gain_nuisance ? 2 : 1;
  out.dt_s.resize(out.count);
  out.session.resize(out.count);
  for (int i = 0; i < kNumCables; ++i) {
    out.x[i].resize(out.count);
    out.inverse_s[i].resize(out.count);
    out.reading_over_s[i].resize(out.count);
    out.kept[i].resize(out.count);
  }
  for (int t = 0; t < out.count; ++t) {
    const SlowErrorSample& s = in.samples[t];
    const bool fresh = t == 0 || StartsNewSeries(in.samples[t - 1].time_s,
                                                 in.samples[t - 1].session, s.time_s, s.session);
    out.dt_s[t] = fresh ? LaidOut::kNewSeries : s.time_s - in.samples[t - 1].time_s;
    out.session[t] = s.session;
    for (int i = 0; i < kNumCables; ++i) {
      out.x[i][t] = s.x[i];
      out.inverse_s[i][t] = 1.0 / s.sigma_n[i];
      out.reading_over_s[i][t] = s.reading_n[i] / s.sigma_n[i];
      out.kept[i][t] = !s.excluded[i];
    }
  }
  return out;
}

// One cable's part of -2 l_R: sum log F and sum x~^2 over its kept readings, and its
// nuisance sums per session.
struct CableTerms {
  double log_f = 0.0, square = 0.0;
  std::vector<NuisanceSums> sums;
};

// One cable's filter (slow_error_filter.h) with its sums of -2 l's terms, the current
// session's nuisance sums its own until the session changes. Per reading: rho =
// sqrt((sigma_N / s)^2 + (a r / s)^2) from the laid-out 1 / s and r / s; one division
// (1 / F) and two square roots; a logarithm per kLogBatch readings (log F summed as the
// log of products of up to kLogBatch F's, F >= 1, a product taken early past kLogFlush:
// the same sum to rounding).
template <int kNuisance>
class CableFilter {
 public:
  CableFilter(const LaidOut& in, const SlowErrorProcess& process, int cable, CableTerms* out)
      : x_(in.x[cable].data()),
        inverse_s_(in.inverse_s[cable].data()),
        reading_over_s_(in.reading_over_s[cable].data()),
        kept_(in.kept[cable].data()),
        active_(process.IsActive()),
        sigma_n_(process.sigma_n),
        relative_(process.sigma_percent / 100.0),
        out_(out) {
    out_->sums.assign(in.sessions, NuisanceSums());
  }

  // The time between the previous reading and reading t: a new series, or phi.
  void Advance(bool new_series, double phi) {
    if (new_series) {
      fresh_ = true;
    } else if (!fresh_) {
      for (double& v : m_) v *= phi;
      p_ = phi * phi * p_ + (1.0 - phi * phi);
    }
  }

  // Reading t of `session`; one left out leaves the state as it is (a missing one).
  void Take(int t, int session) {
    if (!kept_[t]) return;
    if (fresh_) {
      for (double& v : m_) v = 0.0;
      p_ = 1.0;
      fresh_ = false;
    }
    if (session != session_) {
      FlushSession();
      session_ = session;
    }
    const double a = sigma_n_ * inverse_s_[t], b = relative_ * reading_over_s_[t];
    const double rho = !active_ ? 0.0 : sigma_n_ == 0.0 ? std::abs(b) : std::sqrt(a * a + b * b);
    const double f = rho * rho * p_ + 1.0;
    const double inverse_f = 1.0 / f;
    const double scale = std::sqrt(inverse_f), gain = p_ * rho * inverse_f;
    const double row[3] = {x_[t], inverse_s_[t], reading_over_s_[t]};
    double w[kColumns];
    for (int col = 0; col < kColumns; ++col) {
      const double v = row[col] - rho * m_[col];
      m_[col] += gain * v;
      w[col] = v * scale;
    }
    p_ -= gain * rho * p_;
    product_ *= f;
    if (++in_product_ == kLogBatch || product_ > kLogFlush) {
      log_f_ += std::log(product_);
      product_ = 1.0;
      in_product_ = 0;
    }
    square_ += w[0] * w[0];
    for (int u = 0; u < kNuisance; ++u) {
      n_.cross[u] += w[1 + u] * w[0];
      for (int v = 0; v < kNuisance; ++v) n_.gram(u, v) += w[1 + u] * w[1 + v];
    }
  }

  void Finish() {
    FlushSession();
    if (in_product_ > 0) log_f_ += std::log(product_);
    out_->log_f = log_f_;
    out_->square = square_;
  }

 private:
  static constexpr int kColumns = 1 + kNuisance;
  static constexpr int kLogBatch = 8;
  static constexpr double kLogFlush = 1e200;

  void FlushSession() {
    if (session_ < 0) return;
    out_->sums[session_].gram += n_.gram;
    out_->sums[session_].cross += n_.cross;
    n_ = NuisanceSums();
  }

  const double *x_, *inverse_s_, *reading_over_s_;
  const unsigned char* kept_;
  bool active_;
  double sigma_n_, relative_;
  CableTerms* out_;
  double m_[kColumns] = {};
  double p_ = 1.0, product_ = 1.0, log_f_ = 0.0, square_ = 0.0;
  bool fresh_ = true;
  int in_product_ = 0, session_ = -1;
  NuisanceSums n_;  // the current session's
};

// Cables first .. first + kCables - 1, sample by sample: the cables' independent chains
// interleave (a single cable's is bound by the latency of its division and roots), each
// filter's state its own (a fixed number of cables: no indexing through a cable's
// memory); exp(-dt / tau) only where dt changes.
template <int kNuisance, int kCables>
void FilterCables(const LaidOut& in, const SlowErrorProcess& process, int first,
                  CableTerms* terms) {
  std::array<std::optional<CableFilter<kNuisance>>, kCables> cable;
  for (int k = 0; k < kCables; ++k) cable[k].emplace(in, process, first + k, &terms[first + k]);
  const bool active = process.IsActive();
  double last_dt = LaidOut::kNewSeries, phi = 0.0;
  for (int t = 0; t < in.count; ++t) {
    const double dt = in.dt_s[t];
    const bool new_series = dt == LaidOut::kNewSeries;
    if (!new_series && dt != last_dt) {
      phi = active ? SlowErrorCorrelation(dt, process.time_constant_s) : 0.0;
      last_dt = dt;
    }
    for (int k = 0; k < kCables; ++k) {
      cable[k]->Advance(new_series, phi);
      cable[k]->Take(t, in.session[t]);
    }
  }
  for (int k = 0; k < kCables; ++k) cable[k]->Finish();
}

// Cables [first, end) in runs the filter interleaves (at most three at a time).
template <int kNuisance>
void FilterCableRange(const LaidOut& in, const SlowErrorProcess& process, int first, int end,
                      CableTerms* terms) {
  while (first < end) {
    const int count = std::min(end - first, 3);
    if (count == 3) {
      FilterCables<kNuisance, 3>(in, process, first, terms);
    } else if (count == 2) {
      FilterCables<kNuisance, 2>(in, process, first, terms);
    } else {
      FilterCables<kNuisance, 1>(in, process, first, terms);
    }
    first += count;
  }
}

// -2 l_R: each cable's filter on its own (cables split among the threads), its terms
// summed per cable and the cables' sums added in cable order, so that the total has the
// same bits on any number of threads.
double MinusTwoLogLikelihood(const LaidOut& in, const SlowErrorProcess& process, int threads) {
  CableTerms terms[kNumCables];
  const int groups = std::clamp(threads, 1, kNumCables);
  const auto filter_group = [&](int group) {
    const int first = kNumCables * group / groups, end = kNumCables * (group + 1) / groups;
    if (in.nuisance == 2) {
      FilterCableRange<2>(in, process, first, end, terms);
    } else {
      FilterCableRange<1>(in, process, first, end, terms);
    }
  };
  // The groups of threads the system refused (OnThreads) are filtered here afterwards.
  for (int g = OnThreads(groups, filter_group); g < groups; ++g) filter_group(g);
  double total = 0.0;
  for (const CableTerms& c : terms) total += c.log_f + c.square;
  for (const CableTerms& c : terms) {
    for (const NuisanceSums& n : c.sums) total += RestrictedTerm(n, in.nuisance);
  }
  return total;
}

}  // namespace

double SlowErrorMinusTwoLogLikelihood(const SlowErrorEstimateInputs& in,
                                      const SlowErrorProcess& process) {
  return MinusTwoLogLikelihood(LayOut(in), process, in.num_threads);
}

namespace {

// The search: y = (log a, log tau), a the estimated amplitude part (percent or N), with
// the stated coordinates held.
struct Search {
  const SlowErrorEstimateInputs* in = nullptr;
  bool free[2] = {false, false};
  double lower[2] = {0.0, 0.0}, upper[2] = {0.0, 0.0};
  double a_ref = 1.0;  // the amplitude equal to the white sigma at a median reading
  LaidOut laid_out;    // in's readings, laid out for the evaluations

  SlowErrorProcess At(const Eigen::Vector2d& y) const {
    SlowErrorProcess p = in->spec.stated;
    if (free[0]) {
      (in->spec.amplitude_in_percent ? p.sigma_percent : p.sigma_n) = std::exp(y[0]);
    }
    if (free[1]) p.time_constant_s = std::exp(y[1]);
    return p;
  }
  Eigen::Vector2d Clamp(Eigen::Vector2d y) const {
    for (int k = 0; k < 2; ++k) y[k] = std::clamp(y[k], lower[k], upper[k]);
    return y;
  }
  double Value(const Eigen::Vector2d& y) const { return ValueOf(At(Clamp(y))); }
  double ValueOf(const SlowErrorProcess& process) const {
    ++evaluations;
    return MinusTwoLogLikelihood(laid_out, process, in->num_threads);
  }
  mutable int evaluations = 0;  // of the likelihood, each a filter over every sample
};

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Bounds from the data: the amplitude's around the white sigma, tau's between a fraction
// of the sampling interval and many times the longest series.
Search MakeSearch(const SlowErrorEstimateInputs& in) {
  Search s;
  s.in = &in;
  s.laid_out = LayOut(in);
  s.free[0] = in.spec.estimate_amplitude;
  s.free[1] = in.spec.estimate_time_constant;
  std::vector<double> ratio, dt;
  double span = 0.0, series_start = 0.0;
  for (size_t t = 0; t < in.samples.size(); ++t) {
    const SlowErrorSample& x = in.samples[t];
    const bool fresh = t == 0 || StartsNewSeries(in.samples[t - 1].time_s,
                                                 in.samples[t - 1].session, x.time_s, x.session);
    if (fresh) {
      series_start = x.time_s;
    } else if (x.time_s > in.samples[t - 1].time_s) {
      dt.push_back(x.time_s - in.samples[t - 1].time_s);
    }
    span = std::max(span, x.time_s - series_start);
    if (t % 16 == 0) {  // a median needs no more
      for (int i = 0; i < kNumCables; ++i) {
        ratio.push_back(in.spec.amplitude_in_percent ? 100.0 * x.sigma_n[i] / x.reading_n[i]
                                                     : x.sigma_n[i]);
      }
    }
  }
  s.a_ref = std::max(Median(ratio), 1e-12);
  const double interval = dt.empty() ? 1.0 : Median(dt);
  s.lower[0] = std::log(kMinSlowErrorRatio * s.a_ref);
  s.upper[0] = std::log(kMaxSlowErrorRatio * s.a_ref);
  s.lower[1] = std::log(kMinTauPerInterval * interval);
  s.upper[1] = std::log(std::max(kMaxTauPerSpan * span, 10.0 * interval));
  return s;
}

// The best point of a coarse grid over the free coordinates (the likelihood can have a
// ridge along which Nelder-Mead alone would stall far from the maximum).
Eigen::Vector2d GridStart(const Search& s, const Eigen::Vector2d& fixed) {
  constexpr int kAmplitudeNodes = 6, kTauNodes = 8;
  Eigen::Vector2d best = fixed;
  double best_value = std::numeric_limits<double>::infinity();
  const int na = s.free[0] ? kAmplitudeNodes : 1, nt = s.free[1] ? kTauNodes : 1;
  for (int a = 0; a < na; ++a) {
    for (int t = 0; t < nt; ++t) {
      Eigen::Vector2d y = fixed;
      // The amplitude's grid spans 0.05 to 3 white sigmas; tau's its whole range.
      if (s.free[0]) y[0] = std::log(s.a_ref * 0.05 * std::pow(60.0, a / (na - 1.0)));
      if (s.free[1]) y[1] = s.lower[1] + (s.upper[1] - s.lower[1]) * (t + 0.5) / nt;
      const double v = s.Value(y);
      if (v < best_value) {
        best_value = v;
        best = y;
      }
    }
  }
  return s.Clamp(best);
}

// Nelder-Mead over the free coordinates (Nelder and Mead 1965; standard coefficients).
Eigen::Vector2d NelderMead(const Search& s, Eigen::Vector2d start) {
  std::vector<int> dims;
  for (int k = 0; k < 2; ++k) {
    if (s.free[k]) dims.push_back(k);
  }
  const int d = static_cast<int>(dims.size());
  std::vector<Eigen::Vector2d> x(d + 1, start);
  for (int k = 0; k < d; ++k) x[k + 1][dims[k]] += 0.5;
  std::vector<double> f(d + 1);
  for (int k = 0; k <= d; ++k) {
    x[k] = s.Clamp(x[k]);
    f[k] = s.Value(x[k]);
  }
  int evaluations = d + 1;
  while (evaluations < kMaxEvaluations) {
    std::vector<int> order(d + 1);
    for (int k = 0; k <= d; ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return f[a] < f[b]; });
    const int best = order.front(), worst = order.back();
    if (f[worst] - f[best] < kValueTolerance) break;
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (int k = 0; k < d; ++k) centroid += x[order[k]] / d;
    const auto probe = [&](double c) {
      const Eigen::Vector2d y = s.Clamp(centroid + c * (x[worst] - centroid));
      ++evaluations;
      return std::make_pair(y, s.Value(y));
    };
    auto [reflected, fr] = probe(-1.0);
    if (fr < f[best]) {
      auto [expanded, fe] = probe(-2.0);
      if (fe < fr) std::tie(reflected, fr) = std::tie(expanded, fe);
      x[worst] = reflected;
      f[worst] = fr;
      continue;
    }
    if (fr < f[order[d - 1]]) {  // better than the second worst
      x[worst] = reflected;
      f[worst] = fr;
      continue;
    }
    auto [contracted, fc] = probe(fr < f[worst] ? -0.5 : 0.5);
    if (fc < std::min(fr, f[worst])) {
      x[worst] = contracted;
      f[worst] = fc;
      continue;
    }
    for (int k = 0; k <= d; ++k) {  // shrink toward the best
      if (k == best) continue;
      x[k] = s.Clamp(x[best] + 0.5 * (x[k] - x[best]));
      f[k] = s.Value(x[k]);
      ++evaluations;
    }
  }
  int best = 0;
  for (int k = 1; k <= d; ++k) {
    if (f[k] < f[best]) best = k;
  }
  return x[best];
}

bool AtBound(const Search& s, const Eigen::Vector2d& y, int k) {
  const double margin = 0.05 * (s.upper[k] - s.lower[k]);
  return s.free[k] && (y[k] <= s.lower[k] + margin || y[k] >= s.upper[k] - margin);
}

// 1-sigma of the free coordinates in log units, from the curvature of -2 l / 2 at y
// (0 for a coordinate at a bound or without curvature).
Eigen::Vector2d LogSigmas(const Search& s, const Eigen::Vector2d& y, double value) {
  const double h = kCurvatureStep;
  Eigen::Matrix2d hessian = Eigen::Matrix2d::Identity();
  std::vector<int> dims;
  for (int k = 0; k < 2; ++k) {
    if (s.free[k] && !AtBound(s, y, k)) dims.push_back(k);
  }
  for (int a : dims) {
    Eigen::Vector2d e = Eigen::Vector2d::Zero();
    e[a] = h;
    hessian(a, a) = (s.Value(y + e) - 2.0 * value + s.Value(y - e)) / (h * h) / 2.0;
  }
  if (dims.size() == 2) {
    const Eigen::Vector2d e0(h, 0.0), e1(0.0, h);
    hessian(0, 1) = hessian(1, 0) = (s.Value(y + e0 + e1) - s.Value(y + e0 - e1) -
                                     s.Value(y - e0 + e1) + s.Value(y - e0 - e1)) /
                                    (4.0 * h * h) / 2.0;
  }
  Eigen::Vector2d sigma = Eigen::Vector2d::Zero();
  if (dims.empty()) return sigma;
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(hessian);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return sigma;
  const Eigen::Matrix2d covariance = ldlt.solve(Eigen::Matrix2d::Identity());
  for (int k : dims) sigma[k] = std::sqrt(std::max(covariance(k, k), 0.0));
  return sigma;
}

int CountSeries(const std::vector<SlowErrorSample>& samples) {
  int series = 0;
  for (size_t t = 0; t < samples.size(); ++t) {
    series += t == 0 || StartsNewSeries(samples[t - 1].time_s, samples[t - 1].session,
                                        samples[t].time_s, samples[t].session);
  }
  return series;
}

// A process's amplitude in the spec's units (percent of the reading, or N).
double AmplitudeOf(const SlowErrorEstimateInputs& in, const SlowErrorProcess& p) {
  return in.spec.amplitude_in_percent ? p.sigma_percent : p.sigma_n;
}

// (log a, log tau) of a process, a in the spec's units of the amplitude.
Eigen::Vector2d LogCoordinates(const SlowErrorEstimateInputs& in, const SlowErrorProcess& p) {
  const double a = AmplitudeOf(in, p);
  return Eigen::Vector2d(std::log(std::max(a, 1e-300)),
                         std::log(std::max(p.time_constant_s, 1e-300)));
}

// The maximum over the free coordinates of `search`, from the stated values: the search
// starts at the inputs' start where it has one inside the search's range, else at the
// grid's best node. A start at a bound is not taken: the simplex's first steps (+0.5 in
// each free coordinate) would be clamped back onto it, and the search could not leave
// the bound.
Eigen::Vector2d Maximise(const Search& search) {
  const SlowErrorEstimateInputs& in = *search.in;
  const Eigen::Vector2d fixed = LogCoordinates(in, in.spec.stated);
  if (in.start.has_value()) {
    const double a = AmplitudeOf(in, *in.start);
    if (a > 0.0 && std::isfinite(a) && in.start->time_constant_s > 0.0 &&
        std::isfinite(in.start->time_constant_s)) {
      Eigen::Vector2d y = LogCoordinates(in, *in.start);
      for (int k = 0; k < 2; ++k) {
        if (!search.free[k]) y[k] = fixed[k];
      }
      if (!AtBound(search, y, 0) && !AtBound(search, y, 1)) return NelderMead(search, y);
    }
  }
  return NelderMead(search, GridStart(search, fixed));
}

}  // namespace

SlowErrorReport EstimateSlowError(const SlowErrorEstimateInputs& in) {
  SlowErrorReport report;
  report.enabled = true;
  report.amplitude_estimated = in.spec.estimate_amplitude;
  report.amplitude_in_percent = in.spec.amplitude_in_percent;
  report.time_constant_estimated = in.spec.estimate_time_constant;
  report.series = CountSeries(in.samples);
  report.samples_used = static_cast<int>(in.samples.size());
  // Both parts free: the maximum-likelihood process (the estimate itself, or the check of
  // a stated one).
  SlowErrorEstimateInputs both = in;
  both.spec.estimate_amplitude = both.spec.estimate_time_constant = true;
  const Search full = MakeSearch(both);
  const double white = full.ValueOf(SlowErrorProcess());
  const Eigen::Vector2d ml = Maximise(full);
  const double ml_value = full.Value(ml);
  report.maximum_likelihood = full.At(ml);
  Eigen::Vector2d y = ml;
  double value = ml_value;
  const Search search = MakeSearch(in);
  if (!in.spec.estimate_amplitude || !in.spec.estimate_time_constant) {
    y = in.spec.estimates_any() ? Maximise(search) : Eigen::Vector2d::Zero();
    value = search.ValueOf(search.At(y));
  }
  report.process = search.At(y);
  report.likelihood_ratio_vs_white = white - value;
  if (!in.spec.estimates_any()) {
    report.stated_likelihood_ratio = std::max(0.0, value - ml_value);
    report.stated_p_value = std::exp(-report.stated_likelihood_ratio / 2.0);  // chi-square(2)
    report.stated_contradicted = report.stated_likelihood_ratio > kChiSquare2Quantile99;
    report.likelihood_evaluations = full.evaluations + search.evaluations;
    return report;
  }
  report.amplitude_at_floor = in.spec.estimate_amplitude && y[0] <= search.lower[0] + 0.05;
  report.time_constant_at_bound = AtBound(search, y, 1);
  const Eigen::Vector2d log_sigma = LogSigmas(search, y, value);
  if (in.spec.estimate_amplitude)
    report.amplitude_sigma = AmplitudeOf(in, report.process) * log_sigma[0];
  if (in.spec.estimate_time_constant) {
    report.time_constant_sigma_s = report.process.time_constant_s * log_sigma[1];
  }
  report.likelihood_evaluations = full.evaluations + search.evaluations;
  return report;
}

std::vector<int> SlowErrorEstimateSamples(int count, int budget) {
  std::vector<int> indices;
  if (count <= budget) {
    for (int t = 0; t < count; ++t) indices.push_back(t);
    return indices;
  }
  constexpr int kRuns = 10;
  const int run = budget / kRuns;
  for (int k = 0; k < kRuns; ++k) {
    const long long start = static_cast<long long>(k) * (count - run) / (kRuns - 1);
    for (int t = 0; t < run; ++t) indices.push_back(static_cast<int>(start + t));
  }
  return indices;
}

}  // namespace fastcal::internal
