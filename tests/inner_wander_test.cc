// The wander inside windows (internal/inner_wander.h): the block averages' correlation
// against a numeric double integral, and the REML estimate on block scores drawn from its
// own model (and from models it does not assume: a step inside a window).
#include "fastcal/internal/inner_wander.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <random>

namespace fastcal::internal {
namespace {

// The midpoint rule's relative error with 2e5 points on a block (h / tau <= 1.5e-3).
constexpr double kIntegralTolerance = 1e-6;

double NumericAverage(double a0, double a1, double b0, double b1, double tau) {
  if (a0 == b0 && a1 == b1) {
    // One block with itself: the kink at s = t spoils the 2-D midpoint rule; over the lag u
    // the average is (2 / L^2) int_0^L (L - u) exp(-u / tau) du.
    constexpr int kFine = 200000;
    const double length = a1 - a0;
    double sum = 0.0;
    for (int i = 0; i < kFine; ++i) {
      const double u = length * (i + 0.5) / kFine;
      sum += (length - u) * std::exp(-u / tau);
    }
    return 2.0 * sum * (length / kFine) / (length * length);
  }
  // Separate blocks (a before b): exp(-(t - s) / tau) = exp((s - a1) / tau) exp(-(t - a1) /
  // tau), the product of two averages over a line each.
  const auto average = [&](double lo, double hi, double sign) {
    constexpr int kFine = 200000;
    double sum = 0.0;
    for (int i = 0; i < kFine; ++i) {
      sum += std::exp(sign * (lo + (hi - lo) * (i + 0.5) / kFine - a1) / tau);
    }
    return sum / kFine;
  };
  return b0 >= a1 ? average(a0, a1, 1.0) * average(b0, b1, -1.0)
                  : NumericAverage(b0, b1, a0, a1, tau);
}

TEST(InnerWanderTest, BlockAveragesAreTheProcessAveragedOverBothBlocks) {
  for (const double tau : {5.0, 60.0, 600.0, 1e5}) {
    const std::vector<double> first = {0.0, 150.0, 200.0};
    const std::vector<double> last = {120.0, 190.0, 500.0};
    const Eigen::MatrixXd r = BlockAverageCorrelation(first, last, tau);
    for (int b = 0; b < 3; ++b) {
      for (int c = 0; c < 3; ++c) {
        const double expected = NumericAverage(first[b], last[b], first[c], last[c], tau);
        EXPECT_NEAR(r(b, c), expected, kIntegralTolerance * std::max(expected, 1e-3))
            << "tau " << tau << " blocks " << b << ", " << c;
      }
    }
  }
  // A single sample's block: the process itself, correlation 1 with itself.
  const Eigen::MatrixXd point = BlockAverageCorrelation({10.0, 20.0}, {10.0, 20.0}, 30.0);
  EXPECT_DOUBLE_EQ(point(0, 0), 1.0);
  EXPECT_NEAR(point(0, 1), std::exp(-10.0 / 30.0), 1e-15);
}

// Seasons of block scores from the model itself: each window's blocks of `block_s`
// seconds (with a 10 s gap between them), information I_b = (1 + U) diag(info) plus a
// random rotation, a Gauss-Markov process of variance q and time constant tau sampled on a
// fine grid and averaged per block, white score noise N(0, f I_b), and the window's own
// value fitted (the scores made to sum to zero).
struct Season {
  std::vector<WanderWindow> windows;
};

Season DrawSeason(int windows, int blocks, int p, const Eigen::VectorXd& q, double tau,
                  double white, unsigned seed, const std::vector<int>& step_windows = {},
                  const Eigen::VectorXd& step = Eigen::VectorXd()) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  constexpr double kBlockS = 200.0, kGapS = 10.0;
  constexpr int kFine = 20;  // process points a block
  Season out;
  for (int w = 0; w < windows; ++w) {
    WanderWindow win;
    win.white = white;
    win.score.resize(blocks, p);
    Eigen::VectorXd x(p);
    for (int k = 0; k < p; ++k) x[k] = std::sqrt(q[k]) * normal(rng);
    double time = 0.0, previous = 0.0;
    for (int b = 0; b < blocks; ++b) {
      win.first_s.push_back(time);
      Eigen::VectorXd mean = Eigen::VectorXd::Zero(p);
      for (int i = 0; i < kFine; ++i) {
        const double t = time + kBlockS * i / (kFine - 1);
        const double phi = std::exp(-(t - previous) / tau);
        for (int k = 0; k < p; ++k) {
          x[k] = phi * x[k] + std::sqrt(q[k] * (1.0 - phi * phi)) * normal(rng);
        }
        previous = t;
        mean += x / kFine;
      }
      win.last_s.push_back(time + kBlockS);
      time += kBlockS + kGapS;
      const bool stepped =
          std::find(step_windows.begin(), step_windows.end(), w) != step_windows.end();
      if (stepped && b >= blocks / 2) mean += step;
      Eigen::MatrixXd a(p, p);
      for (int i = 0; i < p * p; ++i) a.data()[i] = 0.3 * normal(rng);
      Eigen::MatrixXd info = Eigen::MatrixXd::Identity(p, p) + a * a.transpose();
      info *= 1e4 * (1.0 + uniform(rng));
      win.info.push_back(info);
      Eigen::VectorXd e(p);
      for (int k = 0; k < p; ++k) e[k] = normal(rng);
      const Eigen::MatrixXd l = Eigen::LLT<Eigen::MatrixXd>(white * info).matrixL();
      win.score.row(b) = (info * mean + l * e).transpose();
    }
    Eigen::MatrixXd total = Eigen::MatrixXd::Zero(p, p);
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(p);
    for (int b = 0; b < blocks; ++b) {
      total += win.info[b];
      sum += win.score.row(b).transpose();
    }
    const Eigen::VectorXd fitted = total.ldlt().solve(sum);
    for (int b = 0; b < blocks; ++b) win.score.row(b) -= (win.info[b] * fitted).transpose();
    out.windows.push_back(win);
  }
  return out;
}

// With 60 windows of 32 blocks the variances' standard error is ~10 %; these bounds hold
// at about 3 of them.
constexpr double kVarianceTolerance = 0.35;
constexpr double kTauFactor = 2.0;

TEST(InnerWanderTest, RemlFindsTheVarianceAndTimeConstantItWasDrawnWith) {
  const Eigen::Vector2d q(4e-4, 1e-4);  // (2 cm)^2 and (1 cm)^2: the blocks' noise ~1 cm
  const double tau = 900.0;
  const Season season = DrawSeason(60, 32, 2, q, tau, 1.0, 7);
  const InnerWander w = EstimateInnerWander(season.windows);
  ASSERT_TRUE(w.Active());
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(w.variance[k], q[k], kVarianceTolerance * q[k]) << "component " << k;
    EXPECT_GT(w.variance_sigma[k], 0.0);
    EXPECT_LT(std::abs(w.variance[k] - q[k]), 4.0 * w.variance_sigma[k]) << "component " << k;
  }
  EXPECT_GT(w.time_constant_s, tau / kTauFactor);
  EXPECT_LT(w.time_constant_s, tau * kTauFactor);
  EXPECT_EQ(w.windows_used, 60);
  EXPECT_TRUE(w.windows_left_out.empty());
  // The estimate is the deviance's minimum: any of its parameters moved raises it.
  const double at = InnerWanderDeviance(season.windows, w.variance, w.time_constant_s);
  EXPECT_LT(at, InnerWanderDeviance(season.windows, w.variance * 1.2, w.time_constant_s));
  EXPECT_LT(at, InnerWanderDeviance(season.windows, w.variance * 0.8, w.time_constant_s));
  EXPECT_LT(at, InnerWanderDeviance(season.windows, w.variance, w.time_constant_s * 1.3));
  EXPECT_LT(at, InnerWanderDeviance(season.windows, w.variance, w.time_constant_s / 1.3));
}

// Without a wander the estimate is at most a little of one: over 20 seasons the largest
// variance stays within 3 of its standard errors (the white noise's misfit is f, known).
TEST(InnerWanderTest, WhiteScoresShowLittleWander) {
  int beyond = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Season season = DrawSeason(30, 32, 3, Eigen::Vector3d::Zero(), 600.0, 1.3, seed);
    const InnerWander w = EstimateInnerWander(season.windows);
    for (int k = 0; k < 3; ++k) {
      if (w.variance_sigma.size() > 0 && w.variance[k] > 3.0 * w.variance_sigma[k]) ++beyond;
    }
  }
  // 60 components: at 3 sigma (one-sided, 0.13 %) more than one is beyond chance.
  EXPECT_LE(beyond, 1);
}

TEST(InnerWanderTest, AWindowWithAStepInsideIsLeftOut) {
  const Eigen::Vector2d q(4e-4, 1e-4);
  const Eigen::Vector2d step(0.3, -0.2);  // 15 and 20 sigma of the process
  const Season season = DrawSeason(40, 32, 2, q, 900.0, 1.0, 11, {17}, step);
  const InnerWander w = EstimateInnerWander(season.windows);
  ASSERT_EQ(w.windows_left_out.size(), 1u);
  EXPECT_EQ(w.windows_left_out[0], 17);
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(w.variance[k], q[k], kVarianceTolerance * q[k]);
  // Marked out by hand instead: the same estimate.
  Season marked = season;
  marked.windows[17].use = false;
  const InnerWander m = EstimateInnerWander(marked.windows);
  EXPECT_TRUE(m.windows_left_out.empty());
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(m.variance[k], w.variance[k], 1e-6 * q[k]);
}

// When the wander is everywhere (most windows beyond the white model), steps inside
// several windows are still left out and the wander is the rest's. (The estimate that
// judges them is made over the half the white model explains best, issue 53; on these
// draws one over all the windows judges the same, it is the study's seasons with moving
// parts that told them apart.)
TEST(InnerWanderTest, StepsInsideAFewWindowsDoNotSetAWanderThatIsEverywhere) {
  const Eigen::Vector2d q(4e-4, 1e-4);     // the blocks' scores 4x their white variance
  const Eigen::Vector2d step(0.15, -0.1);  // 7.5 and 10 sigma of the process
  const std::vector<int> stepped = {2, 5, 8, 11, 14, 17};
  const Season season = DrawSeason(20, 32, 2, q, 900.0, 1.0, 5, stepped, step);
  const InnerWander w = EstimateInnerWander(season.windows);
  EXPECT_EQ(w.windows_left_out, stepped);
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(w.variance[k], q[k], 2.0 * kVarianceTolerance * q[k]);
}

// A time constant beyond the windows' span is not searched: inside a window it cannot be
// told from a drift across it on top of an offset of the window, and the offset is the
// wander between windows' (issue 53: with moving parts, a smooth drift of the apparent
// mass centre inside each day read as a wander of 2 cm over 20 hours). Here each window
// drifts linearly by 2 cm across it (a random direction), on white scores.
TEST(InnerWanderTest, ADriftAcrossEachWindowIsNotAWanderOfDays) {
  Season season = DrawSeason(30, 32, 2, Eigen::Vector2d::Zero(), 600.0, 1.0, 3);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> normal(0.0, 1.0);
  double span_s = 0.0;
  for (WanderWindow& w : season.windows) {
    const double t0 = w.first_s.front(), t1 = w.last_s.back();
    span_s = std::max(span_s, t1 - t0);
    const Eigen::Vector2d drift = 0.02 * Eigen::Vector2d(normal(rng), normal(rng)).normalized();
    Eigen::MatrixXd total = Eigen::MatrixXd::Zero(2, 2);
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(2);
    for (size_t b = 0; b < w.info.size(); ++b) {
      const double mid = 0.5 * (w.first_s[b] + w.last_s[b]);
      const Eigen::Vector2d at = drift * ((mid - t0) / (t1 - t0) - 0.5);
      w.score.row(b) += (w.info[b] * at).transpose();
      total += w.info[b];
      sum += w.score.row(b).transpose();
    }
    const Eigen::VectorXd fitted = total.ldlt().solve(sum);
    for (size_t b = 0; b < w.info.size(); ++b) w.score.row(b) -= (w.info[b] * fitted).transpose();
  }
  const InnerWander w = EstimateInnerWander(season.windows);
  ASSERT_TRUE(w.Active());
  EXPECT_LE(w.time_constant_s, span_s * (1.0 + 1e-9));
  // The drift's own size, not a wander of days: a process of tau <= the window whose
  // changes across it are the drift's 2 cm (its rms per axis ~1.4 cm) is of that order.
  for (int k = 0; k < 2; ++k) EXPECT_LT(std::sqrt(w.variance[k]), 0.02) << "component " << k;
}

// The trimmed start (issue 53): with steps of ~3.5 sigma of the process in 8 of 20
// windows, an estimate over all windows takes the steps for a wander 3-7 times the true
// one and then leaves out 0 to 2 of them (it did so on these two draws before the start
// was trimmed); the estimate over the half the white model explains best leaves out
// exactly the stepped windows and finds the wander they were drawn with.
TEST(InnerWanderTest, StepsInNearlyHalfTheWindowsAreJudgedByTheBetterHalf) {
  const Eigen::Vector2d q(4e-4, 1e-4);
  const Eigen::Vector2d step(0.07, -0.049);
  const std::vector<int> stepped = {1, 3, 5, 7, 9, 11, 13, 15};
  for (unsigned seed : {1u, 2u}) {
    const Season season = DrawSeason(20, 32, 2, q, 900.0, 1.0, seed, stepped, step);
    const InnerWander w = EstimateInnerWander(season.windows);
    EXPECT_EQ(w.windows_left_out, stepped) << "seed " << seed;
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(w.variance[k], q[k], 2.0 * kVarianceTolerance * q[k])
          << "seed " << seed << " component " << k;
    }
  }
}

TEST(InnerWanderTest, NoBlocksNoWander) {
  EXPECT_FALSE(EstimateInnerWander({}).Active());
  WanderWindow one;
  one.first_s = {0.0};
  one.last_s = {10.0};
  one.info = {Eigen::MatrixXd::Identity(2, 2)};
  one.score = Eigen::MatrixXd::Zero(1, 2);
  EXPECT_FALSE(EstimateInnerWander({one}).Active());
}

}  // namespace
}  // namespace fastcal::internal
