// The slow-error process: its Kalman filter against a dense generalised least squares,
// its Prais-Winsten limit and missing readings; its estimator against known truth.
#include "fastcal/slow_error.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "fastcal/internal/slow_error_estimate.h"
#include "fastcal/internal/slow_error_filter.h"

namespace fastcal {
namespace {

using internal::ReadingWhitener;
using internal::SlowErrorEstimateInputs;
using internal::SlowErrorFilter;
using internal::SlowErrorSample;

// The filter is exact: agreement to rounding of a few hundred operations.
constexpr double kExactTolerance = 1e-9;

struct Reading {
  double time_s;
  int session;
};

// Irregular times with a long gap, then a second session whose clock restarts.
std::vector<Reading> IrregularTimes(int count, std::mt19937_64* rng) {
  std::uniform_int_distribution<int> pick(0, 3);
  const double steps[] = {0.5, 1.0, 2.0, 3.0};
  std::vector<Reading> r;
  double t = 100.0;
  for (int k = 0; k < count; ++k) {
    const int session = k >= 2 * count / 3 ? 1 : 0;
    if (k == 2 * count / 3) t = 0.0;  // the new session's clock restarts
    if (k == count / 3) t += 1e5;     // a gap of a day: independent
    r.push_back({t, session});
    t += steps[pick(*rng)];
  }
  return r;
}

// Sigma = I + D C D with C_ts = exp(-|t_t - t_s| / tau) within a series, 0 across.
Eigen::MatrixXd DenseCovariance(const std::vector<Reading>& times, const Eigen::VectorXd& rho,
                                double tau) {
  const int n = static_cast<int>(times.size());
  std::vector<int> series(n, 0);
  for (int k = 1; k < n; ++k) {
    series[k] = series[k - 1] + StartsNewSeries(times[k - 1].time_s, times[k - 1].session,
                                                times[k].time_s, times[k].session);
  }
  Eigen::MatrixXd sigma = Eigen::MatrixXd::Identity(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      if (series[a] != series[b]) continue;
      sigma(a, b) += rho[a] * rho[b] * std::exp(-std::abs(times[a].time_s - times[b].time_s) / tau);
    }
  }
  return sigma;
}

TEST(SlowErrorFilter, WhiteningIsDenseGeneralisedLeastSquares) {
  std::mt19937_64 rng(20261126);
  std::normal_distribution<double> normal;
  constexpr int kReadings = 60, kColumns = 3;  // two regressors and the data
  const std::vector<Reading> times = IrregularTimes(kReadings, &rng);
  SlowErrorProcess process;
  process.sigma_percent = 1.0;  // only IsActive and tau matter to the whitener
  process.time_constant_s = 7.0;
  ReadingWhitener whitener(process, kColumns);
  std::array<Eigen::MatrixXd, kNumCables> raw, whitened;
  std::array<Eigen::VectorXd, kNumCables> rho;
  for (int i = 0; i < kNumCables; ++i) {
    raw[i] = Eigen::MatrixXd(kReadings, kColumns);
    for (int k = 0; k < raw[i].size(); ++k) raw[i].data()[k] = normal(rng);
    whitened[i] = raw[i];
    rho[i] = Eigen::VectorXd(kReadings);
    for (int t = 0; t < kReadings; ++t) rho[i][t] = 0.3 + 0.2 * i + 0.5 * std::sin(0.3 * t + i);
  }
  double log_f = 0.0;
  for (int t = 0; t < kReadings; ++t) {
    double rows[kNumCables * kColumns], r[kNumCables];
    for (int i = 0; i < kNumCables; ++i) {
      r[i] = rho[i][t];
      for (int c = 0; c < kColumns; ++c) rows[i * kColumns + c] = raw[i](t, c);
    }
    log_f += whitener.Whiten(times[t].time_s, times[t].session, r, nullptr, rows);
    for (int i = 0; i < kNumCables; ++i) {
      for (int c = 0; c < kColumns; ++c) whitened[i](t, c) = rows[i * kColumns + c];
    }
  }
  double dense_log_det = 0.0, quadratic = 0.0, whitened_quadratic = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::MatrixXd sigma = DenseCovariance(times, rho[i], process.time_constant_s);
    const Eigen::LLT<Eigen::MatrixXd> llt(sigma);
    const Eigen::MatrixXd x = raw[i].leftCols(2);
    const Eigen::VectorXd y = raw[i].col(2);
    const Eigen::VectorXd gls =
        (x.transpose() * llt.solve(x)).ldlt().solve(x.transpose() * llt.solve(y));
    const Eigen::MatrixXd xw = whitened[i].leftCols(2);
    const Eigen::VectorXd ols =
        (xw.transpose() * xw).ldlt().solve(xw.transpose() * whitened[i].col(2));
    EXPECT_LT((ols - gls).norm(), kExactTolerance * gls.norm()) << "cable " << i;
    // The whitened columns' Gram matrix is X^T Sigma^-1 X (the GLS information).
    EXPECT_LT((xw.transpose() * xw - x.transpose() * llt.solve(x)).norm(),
              kExactTolerance * (xw.transpose() * xw).norm());
    dense_log_det += 2.0 * Eigen::MatrixXd(llt.matrixL()).diagonal().array().log().sum();
    quadratic += y.dot(llt.solve(y));
    whitened_quadratic += whitened[i].col(2).squaredNorm();
  }
  // The prediction-error decomposition: sum log F = log det Sigma, sum x~^2 = y^T Sigma^-1 y.
  EXPECT_NEAR(log_f, dense_log_det, kExactTolerance * std::abs(dense_log_det));
  EXPECT_NEAR(whitened_quadratic, quadratic, kExactTolerance * quadratic);
}

TEST(SlowErrorFilter, PraisWinstenIsTheLimitWithoutWhiteNoise) {
  // rho >> 1: the reading is the AR(1) state itself, and the innovations are the
  // Prais-Winsten transformation u_1, (u_t - phi u_{t-1}) / sqrt(1 - phi^2).
  constexpr double kRho = 1e5, kTau = 5.0, kDt = 1.0;
  constexpr double kLimitTolerance = 1e-6;
  const double phi = std::exp(-kDt / kTau);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::vector<double> u(40);
  u[0] = normal(rng);
  for (size_t t = 1; t < u.size(); ++t)
    u[t] = phi * u[t - 1] + std::sqrt(1 - phi * phi) * normal(rng);
  SlowErrorFilter filter(1);
  for (size_t t = 0; t < u.size(); ++t) {
    if (t > 0) filter.Predict(phi);
    double x = kRho * u[t];
    filter.Innovate(kRho, &x, true);
    const double expected = t == 0 ? u[0] : (u[t] - phi * u[t - 1]) / std::sqrt(1 - phi * phi);
    EXPECT_NEAR(x, expected, kLimitTolerance) << "t = " << t;
  }
}

TEST(SlowErrorFilter, LeftOutReadingIsAMissingOne) {
  constexpr double kTau = 4.0;
  const std::vector<double> times = {0.0, 1.0, 2.5, 3.0, 6.0, 6.5};
  const std::vector<double> x = {0.3, -1.2, 2.0, 0.7, -0.4, 1.1};
  constexpr double kRho = 1.3;
  constexpr int kLeftOut = 2;
  // With reading 2 left out (innovated, state not updated) ...
  SlowErrorFilter with(1), without(1);
  std::vector<double> a, b;
  double previous_with = 0.0, previous_without = 0.0;
  for (size_t t = 0; t < times.size(); ++t) {
    if (t > 0) with.Predict(std::exp(-(times[t] - previous_with) / kTau));
    previous_with = times[t];
    double v = x[t];
    with.Innovate(kRho, &v, t != kLeftOut);
    if (t != kLeftOut) a.push_back(v);
    // ... the others are whitened as if it were not there at all.
    if (t == kLeftOut) continue;
    if (!b.empty()) without.Predict(std::exp(-(times[t] - previous_without) / kTau));
    previous_without = times[t];
    double w = x[t];
    without.Innovate(kRho, &w, true);
    b.push_back(w);
  }
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], kExactTolerance);
}

TEST(SlowErrorFilter, SeriesBreaks) {
  EXPECT_FALSE(StartsNewSeries(1.0, 0, 2.0, 0));
  EXPECT_FALSE(StartsNewSeries(1.0, 0, 1.0, 0));  // one instant
  EXPECT_TRUE(StartsNewSeries(2.0, 0, 1.0, 0));   // time goes back
  EXPECT_TRUE(StartsNewSeries(1.0, 0, 2.0, 1));   // another session
  EXPECT_TRUE(StartsNewSeries(1.0, 0, NAN, 0));
  EXPECT_DOUBLE_EQ(SlowErrorCorrelation(10.0, 10.0), std::exp(-1.0));
  EXPECT_EQ(SlowErrorCorrelation(1e6, 10.0), 0.0);  // days apart: independent
}

// ---------------------------------------------------------------------------------------
// The estimator.

struct Truth {
  double slow_percent = 1.5;  // sd of the slow error, percent of the reading
  double tau_s = 30.0;
  double white_percent = 3.0;
  int samples = 3000;
  double session_offset_n = 0.0;  // a re-zeroing: every bias steps at the second session
};

// Readings of six cables: a bias per cable (and per session), the slow error, white noise.
SlowErrorEstimateInputs Simulate(const Truth& truth, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  SlowErrorEstimateInputs in;
  in.spec.enabled = true;
  in.spec.estimate_amplitude = in.spec.estimate_time_constant = true;
  std::array<double, kNumCables> u{}, bias{};
  for (int i = 0; i < kNumCables; ++i) {
    u[i] = normal(rng);
    bias[i] = 2000.0 * normal(rng);
  }
  double t = 0.0;
  for (int k = 0; k < truth.samples; ++k) {
    SlowErrorSample s;
    const double dt = 0.5 + std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    t += dt;
    s.time_s = t;
    s.session = k >= truth.samples / 2 && truth.session_offset_n != 0.0 ? 1 : 0;
    const double phi = std::exp(-dt / truth.tau_s);
    for (int i = 0; i < kNumCables; ++i) {
      u[i] = phi * u[i] + std::sqrt(1 - phi * phi) * normal(rng);
      s.reading_n[i] = 2e5 * (1.0 + 0.2 * std::sin(0.01 * k + i));
      s.sigma_n[i] = truth.white_percent / 100.0 * s.reading_n[i];
      const double slow = truth.slow_percent / 100.0 * s.reading_n[i] * u[i];
      const double offset = bias[i] + (s.session == 1 ? truth.session_offset_n : 0.0);
      s.x[i] = (offset + slow) / s.sigma_n[i] + normal(rng);
    }
    in.samples.push_back(s);
  }
  return in;
}

TEST(SlowErrorEstimate, RecoversAmplitudeAndTimeConstant) {
  // The truth within 3 reported sigmas, and the sigmas neither absurdly small nor large.
  constexpr double kSigmas = 3.0;
  for (std::uint64_t seed : {1u, 2u}) {
    const Truth truth;
    const SlowErrorReport r = internal::EstimateSlowError(Simulate(truth, seed));
    EXPECT_TRUE(r.amplitude_estimated && r.time_constant_estimated);
    EXPECT_FALSE(r.amplitude_at_floor);
    EXPECT_NEAR(r.process.sigma_percent, truth.slow_percent, kSigmas * r.amplitude_sigma)
        << "seed " << seed;
    EXPECT_NEAR(r.process.time_constant_s, truth.tau_s, kSigmas * r.time_constant_sigma_s)
        << "seed " << seed;
    EXPECT_GT(r.amplitude_sigma, 0.01 * truth.slow_percent);
    EXPECT_LT(r.amplitude_sigma, 0.3 * truth.slow_percent);
    EXPECT_GT(r.time_constant_sigma_s, 0.01 * truth.tau_s);
    EXPECT_LT(r.time_constant_sigma_s, 0.5 * truth.tau_s);
    EXPECT_GT(r.likelihood_ratio_vs_white, 100.0);  // overwhelming
    EXPECT_EQ(r.series, 1);
  }
}

TEST(SlowErrorEstimate, WhiteNoiseShowsNoSlowError) {
  Truth truth;
  truth.slow_percent = 0.0;
  const SlowErrorReport r = internal::EstimateSlowError(Simulate(truth, 3));
  // Chi-square(2) at 99%: white noise is preferred or nearly so.
  constexpr double kChiSquare2Quantile99 = 9.21;
  EXPECT_LT(r.likelihood_ratio_vs_white, kChiSquare2Quantile99);
  EXPECT_LT(r.process.sigma_percent, 0.3 * truth.white_percent);
}

TEST(SlowErrorEstimate, ReZeroedSensorsAreNotSlowError) {
  // Biases stepping by 3 white sigmas between two sessions: profiled out per session.
  constexpr double kRelativeChange = 0.05;
  Truth truth;
  const SlowErrorReport steady = internal::EstimateSlowError(Simulate(truth, 4));
  truth.session_offset_n = 18000.0;  // 3 x 3% of 200 kN
  const SlowErrorReport stepped = internal::EstimateSlowError(Simulate(truth, 4));
  EXPECT_EQ(stepped.series, 2);
  EXPECT_NEAR(stepped.process.sigma_percent, steady.process.sigma_percent,
              kRelativeChange * steady.process.sigma_percent);
}

TEST(SlowErrorEstimate, StatedProcessIsChecked) {
  const Truth truth;
  SlowErrorEstimateInputs in = Simulate(truth, 5);
  in.spec.estimate_amplitude = in.spec.estimate_time_constant = false;
  in.spec.stated.sigma_percent = truth.slow_percent;
  in.spec.stated.time_constant_s = truth.tau_s;
  const SlowErrorReport right = internal::EstimateSlowError(in);
  EXPECT_FALSE(right.stated_contradicted) << right.stated_likelihood_ratio;
  EXPECT_DOUBLE_EQ(right.process.time_constant_s, truth.tau_s);  // stated: used as is
  in.spec.stated.time_constant_s = 10.0 * truth.tau_s;
  const SlowErrorReport wrong = internal::EstimateSlowError(in);
  EXPECT_TRUE(wrong.stated_contradicted);
  EXPECT_NEAR(wrong.maximum_likelihood.time_constant_s, truth.tau_s, 0.5 * truth.tau_s);
}

TEST(SlowErrorEstimate, StatedTimeConstantEstimatedAmplitude) {
  const Truth truth;
  SlowErrorEstimateInputs in = Simulate(truth, 6);
  in.spec.estimate_time_constant = false;
  in.spec.stated.time_constant_s = truth.tau_s;
  const SlowErrorReport r = internal::EstimateSlowError(in);
  EXPECT_DOUBLE_EQ(r.process.time_constant_s, truth.tau_s);
  EXPECT_EQ(r.time_constant_sigma_s, 0.0);
  EXPECT_NEAR(r.process.sigma_percent, truth.slow_percent, 3.0 * r.amplitude_sigma);
}

TEST(SlowErrorEstimate, AStartReachesTheGridsMaximum) {
  // A re-estimate starts at the previous maximum (a track's next step): from the grid's
  // own maximum moved by a fifth in amplitude and by half in tau (a step of the fit), it
  // ends at the grid's maximum, to the search's tolerance in -2 l and to a tenth of the
  // estimate's sigma.
  constexpr double kValueTolerance = 2e-2;  // twice Nelder-Mead's stop, in -2 l
  constexpr double kSigmaFraction = 0.1;
  const Truth truth;
  SlowErrorEstimateInputs in = Simulate(truth, 8);
  const SlowErrorReport grid = internal::EstimateSlowError(in);
  SlowErrorProcess moved = grid.maximum_likelihood;
  moved.sigma_percent *= 1.2;
  moved.time_constant_s *= 0.5;
  in.start = moved;
  const SlowErrorReport started = internal::EstimateSlowError(in);
  const double grid_value = internal::SlowErrorMinusTwoLogLikelihood(in, grid.process);
  const double started_value = internal::SlowErrorMinusTwoLogLikelihood(in, started.process);
  EXPECT_LT(std::abs(started_value - grid_value), kValueTolerance);
  EXPECT_NEAR(started.process.sigma_percent, grid.process.sigma_percent,
              kSigmaFraction * grid.amplitude_sigma);
  EXPECT_NEAR(started.process.time_constant_s, grid.process.time_constant_s,
              kSigmaFraction * grid.time_constant_sigma_s);
  // And the start is where the search began: without the grid's 6 x 8 nodes.
  constexpr int kGridNodes = 48;
  EXPECT_LT(started.likelihood_evaluations, grid.likelihood_evaluations - kGridNodes / 2)
      << started.likelihood_evaluations << " against " << grid.likelihood_evaluations;
  // A start without amplitude, or at a bound of the search (a time constant beyond the
  // data's span: the simplex's first step would be clamped back onto it and the search
  // could not leave the bound), falls back to the grid: the same result, bit for bit.
  SlowErrorProcess at_bound = grid.maximum_likelihood;
  at_bound.time_constant_s = 1e12;
  for (const SlowErrorProcess& start : {SlowErrorProcess(), at_bound}) {
    in.start = start;
    const SlowErrorReport fallback = internal::EstimateSlowError(in);
    EXPECT_EQ(fallback.process.sigma_percent, grid.process.sigma_percent);
    EXPECT_EQ(fallback.process.time_constant_s, grid.process.time_constant_s);
  }
}

TEST(SlowErrorEstimate, ThreadsDoNotChangeTheLikelihood) {
  // The cables' filters split among threads: the same bits on any number, with readings
  // left out, two sessions and the gain profiled out too.
  Truth truth;
  truth.samples = 500;
  truth.session_offset_n = 18000.0;
  SlowErrorEstimateInputs in = Simulate(truth, 7);
  in.gain_nuisance = true;
  for (size_t t = 0; t < in.samples.size(); t += 7) in.samples[t].excluded[t % kNumCables] = true;
  SlowErrorProcess process;
  process.sigma_percent = truth.slow_percent;
  process.time_constant_s = truth.tau_s;
  ASSERT_TRUE(process.IsActive());
  for (const SlowErrorProcess& p : {process, SlowErrorProcess()}) {
    in.num_threads = 1;
    const double one = internal::SlowErrorMinusTwoLogLikelihood(in, p);
    EXPECT_TRUE(std::isfinite(one));
    for (int threads : {2, 3, 4, 6, 8}) {
      in.num_threads = threads;
      EXPECT_EQ(internal::SlowErrorMinusTwoLogLikelihood(in, p), one) << threads << " threads";
    }
  }
}

// -2 l_R of readings whose per-reading ratio rho is the process's SigmaN over s, computed
// densely: per cable log det Sigma + y^T Sigma^-1 y over the readings kept, and per cable
// and session log det G - b^T G^-1 b, G = X^T Sigma^-1 X, b = X^T Sigma^-1 y.
double DenseRestrictedMinusTwoLogLikelihood(const SlowErrorEstimateInputs& in,
                                            const SlowErrorProcess& process) {
  double total = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    std::vector<Reading> times;
    std::vector<int> session;
    std::vector<double> y, rho, inv_s, q;
    for (const SlowErrorSample& s : in.samples) {
      if (s.excluded[i]) continue;  // a left-out reading is a missing one
      times.push_back({s.time_s, s.session});
      session.push_back(s.session);
      y.push_back(s.x[i]);
      rho.push_back(process.SigmaN(s.reading_n[i]) / s.sigma_n[i]);
      inv_s.push_back(1.0 / s.sigma_n[i]);
      q.push_back(s.reading_n[i] / s.sigma_n[i]);
    }
    const int n = static_cast<int>(y.size());
    const Eigen::MatrixXd sigma = DenseCovariance(
        times, Eigen::Map<const Eigen::VectorXd>(rho.data(), n), process.time_constant_s);
    const Eigen::LLT<Eigen::MatrixXd> llt(sigma);
    const Eigen::VectorXd yv = Eigen::Map<const Eigen::VectorXd>(y.data(), n);
    total += 2.0 * Eigen::MatrixXd(llt.matrixL()).diagonal().array().log().sum();
    total += yv.dot(llt.solve(yv));
    for (int k = 0; k <= session.back(); ++k) {
      Eigen::MatrixXd x = Eigen::MatrixXd::Zero(n, in.gain_nuisance ? 2 : 1);
      for (int t = 0; t < n; ++t) {
        if (session[t] != k) continue;
        x(t, 0) = inv_s[t];
        if (in.gain_nuisance) x(t, 1) = q[t];
      }
      const Eigen::MatrixXd g = x.transpose() * llt.solve(x);
      const Eigen::VectorXd b = x.transpose() * llt.solve(yv);
      total += std::log(g.determinant()) - b.dot(g.ldlt().solve(b));
    }
  }
  return total;
}

TEST(SlowErrorEstimate, LikelihoodIsTheDenseRestrictedOne) {
  // Irregular times, a day's gap, two sessions, readings left out, the bias and gain
  // profiled out; the amplitude relative, absolute, and both.
  std::mt19937_64 rng(4242);
  std::normal_distribution<double> normal;
  constexpr int kReadings = 48;
  const std::vector<Reading> times = IrregularTimes(kReadings, &rng);
  SlowErrorEstimateInputs in;
  in.gain_nuisance = true;
  for (int t = 0; t < kReadings; ++t) {
    SlowErrorSample s;
    s.time_s = times[t].time_s;
    s.session = times[t].session;
    for (int i = 0; i < kNumCables; ++i) {
      s.reading_n[i] = 2e5 * (1.0 + 0.3 * std::sin(0.2 * t + i));
      s.sigma_n[i] = 500.0 + 0.02 * s.reading_n[i];
      s.x[i] = normal(rng);
      s.excluded[i] = (t * 7 + i) % 11 == 0;
    }
    in.samples.push_back(s);
  }
  SlowErrorProcess relative, absolute, both;
  relative.sigma_percent = 1.5;
  absolute.sigma_n = 3000.0;
  both.sigma_percent = 0.7;
  both.sigma_n = 1500.0;
  for (SlowErrorProcess p : {relative, absolute, both}) {
    for (double tau : {0.8, 6.0}) {
      p.time_constant_s = tau;
      const double dense = DenseRestrictedMinusTwoLogLikelihood(in, p);
      EXPECT_NEAR(internal::SlowErrorMinusTwoLogLikelihood(in, p), dense,
                  kExactTolerance * std::abs(dense))
          << p.sigma_percent << " %, " << p.sigma_n << " N, tau " << tau;
    }
  }
}

TEST(SlowErrorEstimate, SamplesForALongDataset) {
  EXPECT_EQ(internal::SlowErrorEstimateSamples(50, 100).size(), 50u);
  const std::vector<int> runs = internal::SlowErrorEstimateSamples(100000, 1000);
  ASSERT_EQ(runs.size(), 1000u);
  EXPECT_EQ(runs.front(), 0);
  EXPECT_EQ(runs.back(), 99999);  // the runs reach the end
  for (size_t k = 1; k < runs.size(); ++k) EXPECT_GT(runs[k], runs[k - 1]);
}

}  // namespace
}  // namespace fastcal
