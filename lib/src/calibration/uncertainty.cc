// Uncertainty budget of a linearised least-squares estimate (uncertainty.h): robust scale,
// integrated autocorrelation time, overlapping-batch-means long-run covariance, consider
// parameters and the score test.
#include "fastcal/uncertainty.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <unsupported/Eigen/FFT>

#include "fastcal/internal/sample_chunks.h"

namespace fastcal {
namespace {

// 1 / Phi^-1(3/4): the MAD of a standard normal sample is 1 / this.
constexpr double kMadToSigma = 1.4826;
// Sokal's window must end before this fraction of the series, or tau is unreliable.
constexpr double kMaxWindowFraction = 0.25;
// Lags of the autocovariance summed directly before the FFT is used.
constexpr int kDirectLags = 64;
// How many of its standard deviations a tau must exceed 1 by to count as correlated: the
// largest of n parameters' taus is judged, so a 3-sigma rule, not 2.
constexpr double kTauSignificance = 3.0;

double Median(std::vector<double>* v) {
  const size_t n = v->size();
  const auto mid = v->begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(v->begin(), mid, v->end());
  if (n % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(v->begin(), mid));
}

// Omega_hat (LongRunCovarianceOfSum) of double or float scores, its sums in double.
template <typename Scores>
Eigen::MatrixXd LongRunCovarianceOf(const Scores& scores, int bandwidth) {
  const int n_samples = static_cast<int>(scores.rows());
  const int n = static_cast<int>(scores.cols());
  if (n_samples < 1) return Eigen::MatrixXd::Zero(n, n);
  const int l = std::clamp(bandwidth, 1, n_samples);
  const int batches = n_samples - l + 1;
  // The window sums in blocks of rows: memory independent of the number of samples.
  constexpr int kBlock = 4096;
  Eigen::MatrixXd windows(std::min(kBlock, batches), n);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(n, n);
  // The window's sum in double, whatever the scores' type.
  Eigen::RowVectorXd window = scores.topRows(l).template cast<double>().colwise().sum();
  for (int first = 0; first < batches; first += kBlock) {
    const int rows = std::min(kBlock, batches - first);
    for (int k = 0; k < rows; ++k) {
      const int j = first + k;
      if (j > 0) {
        window += scores.row(j + l - 1).template cast<double>() -
                  scores.row(j - 1).template cast<double>();
      }
      windows.row(k) = window;
    }
    sum.selfadjointView<Eigen::Lower>().rankUpdate(windows.topRows(rows).transpose());
  }
  sum = sum.selfadjointView<Eigen::Lower>();
  return static_cast<double>(n_samples) / (static_cast<double>(batches) * l) * sum;
}

// Autocovariances c_0 .. c_{max_lag} of a mean-subtracted series, by FFT of the series
// zero-padded to at least twice its length (so the circular correlation is the linear one).
std::vector<double> Autocovariance(const Eigen::VectorXd& x, int max_lag) {
  const int n = static_cast<int>(x.size());
  int size = 1;
  while (size < 2 * n) size *= 2;
  std::vector<double> padded(size, 0.0);
  for (int t = 0; t < n; ++t) padded[t] = x[t];
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, padded);
  for (std::complex<double>& c : spectrum) c = std::norm(c);
  std::vector<double> correlation;
  fft.inv(correlation, spectrum);
  std::vector<double> c(max_lag + 1);
  for (int k = 0; k <= max_lag; ++k) c[k] = correlation[k] / n;
  return c;
}

// Rows of x scaled to unit diagonal: D M D with D = diag(M)^-1/2 (d returned); then
// inverse as D (D M D)^-1 D. False when M is not positive definite.
bool InverseOfPositiveDefinite(const Eigen::MatrixXd& m, Eigen::MatrixXd* inverse) {
  const int n = static_cast<int>(m.rows());
  Eigen::VectorXd d(n);
  for (int k = 0; k < n; ++k) {
    if (!(m(k, k) > 0.0) || !std::isfinite(m(k, k))) return false;
    d[k] = 1.0 / std::sqrt(m(k, k));
  }
  const Eigen::MatrixXd scaled = d.asDiagonal() * m * d.asDiagonal();
  const Eigen::LLT<Eigen::MatrixXd> llt(scaled);
  if (llt.info() != Eigen::Success) return false;
  *inverse = d.asDiagonal() * llt.solve(Eigen::MatrixXd::Identity(n, n)) * d.asDiagonal();
  return inverse->allFinite();
}

double SqrtNonNegative(double v) { return std::sqrt(std::max(v, 0.0)); }

// The statistical covariance: P_data (or the formal one without scores), each variance
// raised to the floor misfit^2 P_formal, the correlations of P_data kept.
// The misfit floor: the data's information scaled by the Birge ratio, the priors' not
// (a prior is not noisier because the data misfit), M^-1 (f^2 (M - Lambda) + Lambda) M^-1.
Eigen::MatrixXd MisfitFloor(const BudgetInputs& in, const Eigen::MatrixXd& formal, double f) {
  Eigen::MatrixXd meat = f * f * in.information;
  meat.diagonal() -= (f * f - 1.0) * in.prior_information;
  return formal * meat * formal;
}

// Each variance of `data` raised to the floor's, the correlations of `data` kept.
Eigen::MatrixXd StatisticalCovariance(const Eigen::MatrixXd& floor, const Eigen::MatrixXd& data) {
  const int n = static_cast<int>(floor.rows());
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
  for (int k = 0; k < n; ++k) {
    if (!(data(k, k) > 0.0)) return floor;
    if (data(k, k) < floor(k, k)) scale[k] = std::sqrt(floor(k, k) / data(k, k));
  }
  return scale.asDiagonal() * data * scale.asDiagonal();
}

// The influence series' (u_t = M^-1 s_t) largest tau, and the bandwidth it calls for.
// Sets b->correlated when some tau is above 1 by more than kTauSignificance standard
// deviations of tau for a white series, sqrt((4 W + 2) / N) with W the window (Madras
// and Sokal 1988). One series at a time: N doubles, not N x n.
void ChooseBandwidth(const SampleScores& scores, int threads, UncertaintyBudget* b,
                     std::vector<double>* tau) {
  const int n_samples = static_cast<int>(scores.rows());
  const int n = static_cast<int>(scores.cols());
  // Each parameter's series on its own (parameters split among the threads, each thread
  // one series of N doubles at a time); combined afterwards in parameter order.
  std::vector<AutocorrelationTime> times(n);
  const int workers = std::clamp(threads, 1, std::max(n, 1));
  const auto series_of = [&](int worker) {
    Eigen::VectorXd influence(n_samples);
    for (int k = worker; k < n; k += workers) {
      const Eigen::VectorXd p = b->formal.col(k);
      for (int t = 0; t < n_samples; ++t) {
        double u = 0.0;  // in double, from the float scores
        for (int c = 0; c < n; ++c) u += static_cast<double>(scores(t, c)) * p[c];
        influence[t] = u;
      }
      times[k] = IntegratedAutocorrelationTime(influence);
    }
  };
  // The workers the system refused (OnThreads) run here afterwards.
  for (int w = internal::OnThreads(workers, series_of); w < workers; ++w) series_of(w);
  b->tau = 1.0;
  for (int k = 0; k < n; ++k) {
    const AutocorrelationTime& a = times[k];
    (*tau)[k] = a.tau;
    b->tau = std::max(b->tau, a.tau);
    b->correlation_reliable = b->correlation_reliable && a.reliable;
    const double sd = std::sqrt((4.0 * a.window + 2.0) / n_samples);
    b->correlated = b->correlated || a.tau - 1.0 > kTauSignificance * sd;
  }
  const double wanted = std::ceil(kBandwidthPerTau * b->tau);
  b->bandwidth = static_cast<int>(std::clamp(wanted, 1.0, static_cast<double>(n_samples)));
}

// BatchCorrection from the inputs' stored Jacobians, or their replay.
Eigen::VectorXd CorrectionOf(const BudgetInputs& in, const Eigen::MatrixXd& formal, int bandwidth) {
  if (in.jacobians.rows() > 0 || !in.jacobian_replay) {
    return BatchCorrection(in.jacobians, in.rows_per_sample, formal, bandwidth);
  }
  return BatchCorrection(in.jacobian_replay, static_cast<int>(in.scores.rows()), in.rows_per_sample,
                         formal, bandwidth);
}

// The batch correction at the chosen bandwidth, halving it while the correction says the
// fit absorbed most of a batch (then the widening is a lower bound).
Eigen::VectorXd CorrectionWithinLimit(const BudgetInputs& in, UncertaintyBudget* b) {
  Eigen::VectorXd c = CorrectionOf(in, b->formal, b->bandwidth);
  while (b->bandwidth > 1 && !(c.maxCoeff() <= kMaxBatchCorrection)) {
    b->bandwidth = std::max(1, b->bandwidth / 2);
    b->correlation_reliable = false;
    c = CorrectionOf(in, b->formal, b->bandwidth);
  }
  b->max_batch_correction = c.size() > 0 ? c.maxCoeff() : 1.0;
  return c.cwiseMax(1.0);
}

// P_data at bandwidth L (the corrected overlapping batch means, with the priors).
Eigen::MatrixXd DataCovarianceAt(const BudgetInputs& in, const Eigen::MatrixXd& formal,
                                 const Eigen::VectorXd& correction, int bandwidth) {
  const Eigen::VectorXd root_c = correction.cwiseMax(1.0).cwiseSqrt();
  Eigen::MatrixXd meat =
      root_c.asDiagonal() * LongRunCovarianceOf(in.scores, bandwidth) * root_c.asDiagonal();
  meat.diagonal() += in.prior_information;
  return formal * meat * formal;
}

// P_data, robust to a memory longer than the influence series' tau shows (the fit absorbs
// slow errors, which shortens the residuals' apparent memory): the bandwidth is doubled
// from L = 8 tau while the batch correction allows (kMaxBatchCorrection, and at most
// kMaxBandwidthFraction of the samples). A parameter takes a wider bandwidth's variance
// only when it exceeds the one it has by more than kGrowthSignificance of that
// estimate's relative standard deviation, sqrt(4 L / (3 N)) (Bartlett/OBM): a variance
// that keeps growing is a longer memory, not sampling noise. The correlations are those
// of the first bandwidth. When a parameter's variance still grew at the widest
// bandwidth, the memory may be longer than the data can measure: correlation_reliable is
// false.
Eigen::MatrixXd DataCovariance(const BudgetInputs& in, UncertaintyBudget* b) {
  const int n = static_cast<int>(b->formal.rows());
  const Eigen::MatrixXd first =
      DataCovarianceAt(in, b->formal, CorrectionWithinLimit(in, b), b->bandwidth);
  Eigen::VectorXd accepted = first.diagonal();
  std::vector<int> accepted_at(n, b->bandwidth);
  b->widest_bandwidth = b->bandwidth;
  const int cap = static_cast<int>(kMaxBandwidthFraction * b->samples);
  for (int l = 2 * b->bandwidth; l <= cap; l *= 2) {
    const Eigen::VectorXd c = CorrectionOf(in, b->formal, l);
    if (!(c.maxCoeff() <= kMaxBatchCorrection)) break;
    const Eigen::MatrixXd p = DataCovarianceAt(in, b->formal, c, l);
    const double noise = std::sqrt(4.0 * l / (3.0 * b->samples));
    for (int k = 0; k < n; ++k) {
      if (p(k, k) > accepted[k] * (1.0 + kGrowthSignificance * noise)) {
        accepted[k] = p(k, k);
        accepted_at[k] = l;
      }
    }
    b->widest_bandwidth = l;
  }
  for (int k = 0; k < n; ++k) {
    if (accepted_at[k] > b->bandwidth && accepted_at[k] == b->widest_bandwidth) {
      b->correlation_reliable = false;
    }
  }
  Eigen::VectorXd scale(n);
  for (int k = 0; k < n; ++k) {
    scale[k] = first(k, k) > 0.0 ? std::sqrt(accepted[k] / first(k, k)) : 1.0;
  }
  return scale.asDiagonal() * first * scale.asDiagonal();
}

// Sokal's window over autocovariances c_0 .. c_last: true, with tau and the window in
// *a, when some W <= last has W >= window_factor * tau(W); otherwise *a holds tau(last).
bool SokalWindow(const std::vector<double>& c, int last, double window_factor, int n,
                 AutocorrelationTime* a) {
  double tau = 1.0;
  for (int w = 1; w <= last; ++w) {
    tau += 2.0 * c[w] / c[0];
    if (w >= window_factor * tau) {
      a->tau = std::max(tau, 1.0 / n);  // an anticorrelated series: below 1, never 0
      a->window = w;
      return true;
    }
  }
  a->tau = std::max(tau, 1.0 / n);
  a->window = last;
  return false;
}

}  // namespace

RobustScale RobustScaleOf(std::vector<double> values) {
  RobustScale s;
  if (values.empty()) return s;
  s.centre = Median(&values);
  for (double& v : values) v = std::abs(v - s.centre);
  s.scale = kMadToSigma * Median(&values);
  return s;
}

AutocorrelationTime IntegratedAutocorrelationTime(const Eigen::Ref<const Eigen::VectorXd>& series,
                                                  double window_factor) {
  AutocorrelationTime a;
  const int n = static_cast<int>(series.size());
  if (n < 2) return a;
  const Eigen::VectorXd x = series.array() - series.mean();
  const int max_window = std::max(1, static_cast<int>(kMaxWindowFraction * n));
  // The first lags summed directly: a series with a short memory (residuals, most
  // influence series) meets the window within them, at ~1/20 of the FFT's cost on 10^6
  // samples. A longer memory takes the FFT over all lags.
  const int direct = std::min(max_window, kDirectLags);
  std::vector<double> c(direct + 1);
  for (int k = 0; k <= direct; ++k) c[k] = x.head(n - k).dot(x.tail(n - k)) / n;
  if (!(c[0] > 0.0)) return a;  // a constant series: no information about its memory
  if (SokalWindow(c, direct, window_factor, n, &a)) return a;
  if (direct < max_window) {
    c = Autocovariance(x, max_window);
    if (SokalWindow(c, max_window, window_factor, n, &a)) return a;
  }
  a.reliable = false;
  return a;
}

Eigen::MatrixXd LongRunCovarianceOfSum(const Eigen::MatrixXd& scores, int bandwidth) {
  return LongRunCovarianceOf(scores, bandwidth);
}

Eigen::VectorXd BatchCorrection(const SampleJacobians& jacobians, int rows_per_sample,
                                const Eigen::MatrixXd& inverse_information, int bandwidth) {
  const int n_samples = static_cast<int>(jacobians.rows());
  const int n = static_cast<int>(inverse_information.rows());
  if (n_samples == 0 || rows_per_sample < 1 || jacobians.cols() != rows_per_sample * n) {
    return Eigen::VectorXd::Ones(n);
  }
  const SampleJacobianReplay replay = [&](const std::function<void(int, const float*)>& visit) {
    for (int t = 0; t < n_samples; ++t) visit(t, jacobians.row(t).data());
    return true;
  };
  return BatchCorrection(replay, n_samples, rows_per_sample, inverse_information, bandwidth);
}

Eigen::VectorXd BatchCorrection(const SampleJacobianReplay& replay, int samples,
                                int rows_per_sample, const Eigen::MatrixXd& inverse_information,
                                int bandwidth) {
  const int n = static_cast<int>(inverse_information.rows());
  if (samples == 0 || rows_per_sample < 1 || !replay) return Eigen::VectorXd::Ones(n);
  const int l = std::clamp(bandwidth, 1, samples);
  const int stride = std::max(1, l / 16);
  const int width = rows_per_sample * n;
  // Per sample J_t^T J_t, added to and removed from the running window sum; the rows of
  // the last l samples in a ring (the one leaving the window is l behind).
  using Rows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<float> ring(static_cast<size_t>(l) * width);
  // Without allocation per sample (10^6 of them).
  Eigen::MatrixXd j(rows_per_sample, n);
  Eigen::MatrixXd window = Eigen::MatrixXd::Zero(n, n);
  auto add = [&](const float* rows, double sign) {
    j = Eigen::Map<const Rows>(rows, rows_per_sample, n).cast<double>();
    window.noalias() += sign * (j.transpose() * j);
  };
  Eigen::VectorXd kept = Eigen::VectorXd::Zero(n), all = Eigen::VectorXd::Zero(n);
  const bool ok = replay([&](int t, const float* rows) {
    float* slot = ring.data() + static_cast<size_t>(t % l) * width;
    add(rows, 1.0);
    if (t >= l) add(slot, -1.0);  // sample t - l leaves the window
    std::copy(rows, rows + width, slot);
    const int b = t - l + 1;  // the window [b, t] is complete
    if (b < 0 || b % stride != 0) return;
    const Eigen::MatrixXd absorbed = window * inverse_information * window;
    all += window.diagonal();
    kept += window.diagonal() - absorbed.diagonal();
  });
  if (!ok) return Eigen::VectorXd::Ones(n);
  Eigen::VectorXd c(n);
  for (int k = 0; k < n; ++k) {
    c[k] = kept[k] > 0.0 ? all[k] / kept[k] : std::numeric_limits<double>::infinity();
  }
  return c;
}

bool ComputeUncertaintyBudget(const BudgetInputs& in, UncertaintyBudget* b) {
  *b = UncertaintyBudget();
  const int n = static_cast<int>(in.information.rows());
  b->consider_groups = in.consider_groups;
  if (n == 0 || !InverseOfPositiveDefinite(in.information, &b->formal)) return false;
  const int dof = in.num_residuals - n;
  b->reduced_chi_square = dof > 0 ? in.chi_square / dof : std::numeric_limits<double>::quiet_NaN();
  b->samples = static_cast<int>(in.scores.rows());
  if (in.robust_loss && b->samples > 0) {
    // An M-estimator's covariance for white residuals: the sandwich
    // H^-1 (sum_t psi_t psi_t^T + Lambda) H^-1 (the scores are psi, M is H); it carries
    // the residuals' scale itself, so no misfit factor on top.
    Eigen::MatrixXd meat = LongRunCovarianceOf(in.scores, 1);
    meat.diagonal() += in.prior_information;
    b->formal = b->formal * meat * b->formal;
  } else if (std::isfinite(b->reduced_chi_square) && b->reduced_chi_square > in.misfit_threshold) {
    b->misfit_factor = std::sqrt(std::max(1.0, b->reduced_chi_square));
  }
  std::vector<double> tau(n, 1.0);
  Eigen::MatrixXd data = b->formal;
  b->correlation_measured =
      b->samples >= kMinSamplesForCorrelation && in.scores.cols() == n && dof > 0;
  if (b->correlation_measured) ChooseBandwidth(in.scores, in.num_threads, b, &tau);
  if (b->correlated) data = DataCovariance(in, b);
  b->effective_samples = b->samples / b->tau;
  b->statistical = StatisticalCovariance(MisfitFloor(in, b->formal, b->misfit_factor), data);

  const int q = static_cast<int>(in.consider_sigma.size());
  const int groups = static_cast<int>(in.consider_groups.size());
  b->systematic = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> by_group(groups, Eigen::MatrixXd::Zero(n, n));
  if (q > 0) {
    b->sensitivity = -b->formal * in.consider_cross;
    for (int j = 0; j < q; ++j) {
      const Eigen::VectorXd s = b->sensitivity.col(j);
      const Eigen::MatrixXd part = in.consider_sigma[j] * in.consider_sigma[j] * s * s.transpose();
      b->systematic += part;
      by_group[in.consider_group[j]] += part;
    }
  }
  b->total = b->statistical + b->systematic;
  for (int k = 0; k < n; ++k) {
    ParameterBudget p;
    p.formal = SqrtNonNegative(b->formal(k, k));
    p.statistical = SqrtNonNegative(b->statistical(k, k));
    p.widening = p.formal > 0.0 ? p.statistical / p.formal : 1.0;
    p.tau = tau[k];
    p.systematic = SqrtNonNegative(b->systematic(k, k));
    p.total = SqrtNonNegative(b->total(k, k));
    for (int g = 0; g < groups; ++g)
      p.systematic_by_group.push_back(SqrtNonNegative(by_group[g](k, k)));
    b->parameters.push_back(p);
  }
  b->ok = true;
  return true;
}

Eigen::VectorXd ScoreTestDecrease(const Eigen::MatrixXd& information, const Eigen::MatrixXd& cross,
                                  const Eigen::VectorXd& self, const Eigen::VectorXd& gradient) {
  const int q = static_cast<int>(self.size());
  Eigen::VectorXd decrease = Eigen::VectorXd::Constant(q, std::numeric_limits<double>::quiet_NaN());
  Eigen::MatrixXd inverse;
  if (information.rows() > 0 && !InverseOfPositiveDefinite(information, &inverse)) return decrease;
  for (int j = 0; j < q; ++j) {
    double a = self[j];
    if (information.rows() > 0) a -= cross.col(j).dot(inverse * cross.col(j));
    if (!(self[j] > 0.0) || !(a > kScoreSpanTolerance * self[j])) continue;
    decrease[j] = gradient[j] * gradient[j] / a;
  }
  return decrease;
}

}  // namespace fastcal
