// Tests of the gross-error screen (gross_errors.h): the threshold in robust sigmas at its
// edge, the floor of 1 (the stated noise), robustness to many gross errors at once, and
// judging with some samples' scales only. Residual patterns are built so that their
// median and MAD are known exactly.
#include "fastcal/gross_errors.h"

#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <vector>

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

}  // namespace
}  // namespace fastcal
