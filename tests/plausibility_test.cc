// Tests of the plausibility limits (fastcal/plausibility.h): the documented defaults, the
// shape of the lowest plausible z (ground, reflector, rim), and the messages.
#include "fastcal/plausibility.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace fastcal {
namespace {

// The reflector formula is evaluated in double: far below a millimetre.
constexpr double kHeightTolM = 1e-9;

TEST(PlausibilityTest, DefaultsAreTheDocumentedOnesAndValid) {
  const PlausibilityLimits limits;
  EXPECT_EQ(limits.max_tension_n, 5e6);
  EXPECT_EQ(limits.max_horizontal_radius_m, 350.0);
  EXPECT_EQ(limits.max_height_m, 300.0);
  EXPECT_EQ(limits.max_abs_angle_deg, 360.0);
  std::string error;
  EXPECT_TRUE(limits.IsValid(&error)) << error;
  PlausibilityLimits bad;
  bad.max_height_m = std::nan("");
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_EQ(error, "max_height_m: must be > 0 and finite (got nan)");
}

TEST(PlausibilityTest, LowestZFollowsTheReflectorLessTheMarginAndNeverBelowGround) {
  const PlausibilityLimits limits;
  EXPECT_EQ(LowestPlausibleZ(0.0, limits), 0.0);  // ground, not -10 m
  const double at_200 = 300.0 - std::sqrt(300.0 * 300.0 - 200.0 * 200.0) - 10.0;
  EXPECT_NEAR(LowestPlausibleZ(200.0, limits), at_200, kHeightTolM);
  // Beyond the 250 m aperture the rim's height holds.
  EXPECT_NEAR(LowestPlausibleZ(340.0, limits), LowestPlausibleZ(250.0, limits), kHeightTolM);
}

TEST(PlausibilityTest, PositionsBelowAboveAndOutsideAreRefusedWithWhy) {
  const PlausibilityLimits limits;
  std::string why;
  EXPECT_TRUE(CheckPosition({0, 0, 140}, limits, &why)) << why;
  EXPECT_TRUE(CheckPosition({330, 0, 150}, limits, &why)) << why;  // near a tower: plausible
  EXPECT_FALSE(CheckPosition({0, 0, -50}, limits, &why));
  EXPECT_EQ(why, "z = -50 m is below the reflector (z >= 0 m at 0 m from the axis)");
  EXPECT_FALSE(CheckPosition({200, 0, 20}, limits, &why));
  EXPECT_NE(why.find("is below the reflector (z >= 66.3932 m at 200 m"), std::string::npos) << why;
  EXPECT_FALSE(CheckPosition({0, 0, 1e308}, limits, &why));
  EXPECT_EQ(why, "z = 1e+308 m is above the tower tops (at most 300 m)");
  EXPECT_FALSE(CheckPosition({300, 300, 150}, limits, &why));
  EXPECT_EQ(why,
            "the position is 424.264 m from the axis, beyond the ring of towers (at most "
            "350 m)");
}

TEST(PlausibilityTest, TensionsAnglesAndLengths) {
  const PlausibilityLimits limits;
  std::string why;
  EXPECT_TRUE(CheckTensionN(0.0, limits, &why));  // a dropout is possible
  EXPECT_TRUE(CheckTensionN(5e6, limits, &why));
  EXPECT_FALSE(CheckTensionN(1e33, limits, &why));
  EXPECT_EQ(why, "1e+30 kN is above the plausible maximum of 5000 kN");
  EXPECT_FALSE(CheckTensionN(-1.0, limits, &why));
  EXPECT_EQ(why, "-0.001 kN is negative: a tension reading is >= 0");
  EXPECT_TRUE(CheckAngleDeg(-359.9, limits, &why));
  EXPECT_FALSE(CheckAngleDeg(1e300, limits, &why));
  EXPECT_EQ(why, "1e+300 deg is beyond the plausible +-360 deg");
  EXPECT_FALSE(CheckRotationVector({0, 0, 7}, limits, &why));
  EXPECT_FALSE(CheckUnstretchedLengthM(0.0, limits, &why));
  EXPECT_FALSE(CheckUnstretchedLengthM(1e6, limits, &why));
  EXPECT_EQ(why, "1e+06 m is above the plausible maximum of 1000 m");
}

// A value just beyond a limit is shown with the digits that make it differ from it.
TEST(PlausibilityTest, ValuesJustBeyondALimitAreShownBeyondIt) {
  const PlausibilityLimits limits;
  std::string why;
  EXPECT_FALSE(CheckPosition({0.0, 0.0, 300.00001}, limits, &why));
  EXPECT_EQ(why, "z = 300.00001 m is above the tower tops (at most 300 m)");
  EXPECT_FALSE(CheckTensionN(5000.0001e3, limits, &why));
  EXPECT_EQ(why, "5000.0001 kN is above the plausible maximum of 5000 kN");
  EXPECT_FALSE(CheckAngleDeg(-360.0000001, limits, &why));
  EXPECT_EQ(why, "-360.0000001 deg is beyond the plausible +-360 deg");
}

}  // namespace
}  // namespace fastcal
