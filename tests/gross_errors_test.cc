// Tests of the gross-error screen (gross_errors.h): the threshold in robust sigmas at its
// edge, the floor of 1 (the stated noise), robustness to many gross errors at once, and
// judging with some samples' scales only. Residual patterns are built so that their
// median and MAD are known exactly.
#include "fastcal/gross_errors.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "fastcal/evaluation_screen.h"

namespace fastcal {
namespace {

using Rows = std::vector<std::array<double, kNumCables>>;

constexpr double kThreshold = 5.0;  // robust sigmas, the calibration's default
constexpr double kMadToSigma = 1.4826;
constexpr double kEdge = 0.05;  // how far either side of the threshold, whitened
constexpr double kTol = 1e-12;

// 101 samples; cable 1's residuals (t - 50) / 25: median 0, MAD 1, so its scale is
// 1.4826 (above the floor); the other cables' residuals are 0: scale 0, floored to 1.
Rows Pattern() {
  Rows rows(101);
  for (int t = 0; t < 101; ++t) {
    rows[t].fill(0.0);
    rows[t][0] = (t - 50) / 25.0;
  }
  return rows;
}

TEST(GrossErrorScreenTest, FlagsJustBeyondTheThresholdAndNotJustInside) {
  Rows rows = Pattern();
  const double limit = kThreshold * kMadToSigma;
  // Replacing the two extreme readings (-2, +2) keeps the median and the MAD.
  rows[0][0] = limit + kEdge;
  rows[100][0] = -(limit - kEdge);
  // Cable 2 at the floor: 5 stated sigmas is the limit.
  rows[10][1] = kThreshold + kEdge;
  rows[20][1] = -(kThreshold - kEdge);
  const GrossErrorScreen s = ScreenGrossErrors(rows, {}, kThreshold);
  EXPECT_NEAR(s.cables[0].centre, 0.0, kTol);
  EXPECT_NEAR(s.cables[0].scale, kMadToSigma, kTol);
  EXPECT_NEAR(s.cables[1].scale, 1.0, kTol);  // the floor
  EXPECT_TRUE(s.flagged[0][0]);
  EXPECT_FALSE(s.flagged[100][0]);
  EXPECT_TRUE(s.flagged[10][1]);
  EXPECT_FALSE(s.flagged[20][1]);
  EXPECT_EQ(s.count, 2);
  EXPECT_EQ(s.count_all, 2);
  EXPECT_EQ(s.judged, 101 * kNumCables);
}

// Forty readings of one cable 1000 sigmas off cannot widen the scale that judges them.
TEST(GrossErrorScreenTest, ManyGrossErrorsCannotHideEachOther) {
  Rows rows(101);
  for (int t = 0; t < 101; ++t) {
    rows[t].fill(0.0);
    rows[t][3] = t < 40 ? 1000.0 : 0.0;
  }
  const GrossErrorScreen s = ScreenGrossErrors(rows, {}, kThreshold);
  EXPECT_NEAR(s.cables[3].scale, 1.0, kTol);
  EXPECT_EQ(s.count, 40);
  for (int t = 0; t < 101; ++t) EXPECT_EQ(s.flagged[t][3], t < 40) << t;
}

// Samples not judged (held out) do not set the scales but are flagged against them; a
// reading the model cannot predict (NaN) is a gross error.
TEST(GrossErrorScreenTest, UnjudgedSamplesAreFlaggedAgainstTheJudgedScales) {
  Rows rows = Pattern();
  std::vector<bool> judge(101, true);
  rows.push_back({});
  rows.back().fill(0.0);
  rows.back()[0] = 8.0;  // beyond 5 x 1.4826 = 7.41
  rows.back()[5] = std::numeric_limits<double>::quiet_NaN();
  judge.push_back(false);
  const GrossErrorScreen s = ScreenGrossErrors(rows, judge, kThreshold);
  EXPECT_NEAR(s.cables[0].scale, kMadToSigma, kTol);
  EXPECT_TRUE(s.flagged[101][0]);
  EXPECT_TRUE(s.flagged[101][5]);
  EXPECT_EQ(s.count, 0);      // among the judged samples
  EXPECT_EQ(s.count_all, 2);  // among all
  EXPECT_EQ(s.judged, 101 * kNumCables);
}

// The family-wise threshold z_N solves erfc(z_N / sqrt 2) = alpha / N (the definition),
// and the spec's value is the floor: it decides on a short dataset, z_N on a long one.
TEST(GrossErrorThresholdTest, FamilyWiseQuantileAndTheSpecsFloor) {
  constexpr double kQuantileTol = 1e-12;  // relative, of the tail probability
  for (long long n : {6LL, 17443LL, 600000LL, 6000000LL}) {
    const GrossErrorThreshold t = ChooseGrossErrorThreshold(n, kThreshold);
    const double tail = std::erfc(t.family_wise_sigmas / std::sqrt(2.0));
    EXPECT_NEAR(tail / (kGrossErrorFamilyFalseAlarm / n), 1.0, kQuantileTol) << n;
    EXPECT_EQ(t.sigmas, std::max(kThreshold, t.family_wise_sigmas)) << n;
    EXPECT_EQ(t.readings, n);
  }
  // Reference values (Phi^-1(1 - 0.01 / (2 N)), e.g. scipy.stats.norm.isf(0.005 / N)).
  constexpr double kReferenceTol = 1e-6;
  EXPECT_NEAR(ChooseGrossErrorThreshold(6, kThreshold).family_wise_sigmas, 3.1439803,
              kReferenceTol);
  EXPECT_EQ(ChooseGrossErrorThreshold(6, kThreshold).sigmas, kThreshold);
  EXPECT_FALSE(ChooseGrossErrorThreshold(6, kThreshold).family_wise_decides());
  EXPECT_NEAR(ChooseGrossErrorThreshold(600000, kThreshold).sigmas, 5.6434596, kReferenceTol);
  EXPECT_NEAR(ChooseGrossErrorThreshold(6000000, kThreshold).sigmas, 6.0273531, kReferenceTol);
  EXPECT_TRUE(ChooseGrossErrorThreshold(600000, kThreshold).family_wise_decides());
  EXPECT_EQ(ChooseGrossErrorThreshold(600000, 8.0).sigmas, 8.0);  // a stricter spec stands
}

// Pure Gaussian noise of 10^5 samples (6 x 10^5 readings) is accused of nothing at the
// threshold for its length (a 1% chance per seed; this seed is one of the 99%), while a
// planted dropout in the same noise is still named.
TEST(GrossErrorThresholdTest, GaussianNoiseOfAHundredThousandSamplesNamesNothing) {
  constexpr int kSamples = 100000;
  std::mt19937_64 rng(20);
  std::normal_distribution<double> noise(0.0, 1.0);
  Rows rows(kSamples);
  for (auto& row : rows) {
    for (double& r : row) r = noise(rng);
  }
  const GrossErrorThreshold t =
      ChooseGrossErrorThreshold(static_cast<long long>(kNumCables) * kSamples, kThreshold);
  EXPECT_EQ(ScreenGrossErrors(rows, {}, t.sigmas).count, 0);
  rows[kSamples / 2][3] = -1.0 / 0.03;  // a 0 reading, at 3 % noise of the prediction
  const GrossErrorScreen s = ScreenGrossErrors(rows, {}, t.sigmas);
  EXPECT_EQ(s.count, 1);
  EXPECT_TRUE(s.flagged[kSamples / 2][3]);
}

// evaluate's screen: a 0 kN dropout among readings with 1% noise is named by line and
// cable, with its prediction; nothing else is, and the RMS without it is the noise's.
TEST(EvaluationScreenTest, NamesADropoutByLineAndCable) {
  constexpr int kSamples = 2000;
  constexpr double kPredictedN = 500e3;
  constexpr double kNoise = 0.01;  // relative, within the default 3 % noise model
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, kNoise);
  Dataset data;
  VariantEvaluation v;
  v.name = "model, measured attitude";
  for (int t = 0; t < kSamples; ++t) {
    Sample s;
    s.line = t + 2;
    for (int i = 0; i < kNumCables; ++i) s.tension_n[i] = kPredictedN * (1.0 + noise(rng));
    data.samples.push_back(s);
    v.predicted_n.push_back({});
    v.predicted_n.back().fill(kPredictedN);
  }
  data.samples[1234].tension_n[4] = 1e-300;  // the dropout of the issue
  const EvaluationScreen e = ScreenEvaluation(data, v);
  ASSERT_EQ(e.gross_errors.size(), 1u);
  EXPECT_EQ(e.gross_errors[0].line, 1236);
  EXPECT_EQ(e.gross_errors[0].cable, 5);
  EXPECT_EQ(e.gross_errors[0].predicted_n, kPredictedN);
  EXPECT_EQ(e.variant, v.name);
  const std::vector<VariantEvaluation> without = WithoutGrossErrors(data, {v}, e.excluded);
  ASSERT_EQ(without.size(), 1u);
  EXPECT_EQ(without[0].fit.excluded[4], 1);
  constexpr double kRmsTol = 0.1;  // relative, of the noise's RMS over 2000 readings
  EXPECT_NEAR(without[0].fit.rms_n[4] / (kNoise * kPredictedN), 1.0, kRmsTol);
  EXPECT_GT(ErrorStats(data, v.predicted_n, {}, false).rms_n[4], 2.0 * kNoise * kPredictedN);
}

}  // namespace
}  // namespace fastcal
