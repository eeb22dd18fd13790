// Tests of the model plausibility checks and the unsolvable-rows diagnosis
// (fastcal/model_plausibility.h, fastcal/unsolvable_rows.h): the nominal model passes, each slip is
// named at its key, the furthest-from-nominal list ranks by the plausible range, and a model that
// cannot solve what the nominal model solves is blamed while rows outside the workspace are not.
#include "fastcal/model_plausibility.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fastcal/unsolvable_rows.h"

namespace fastcal {
namespace {

TEST(ModelPlausibilityTest, NominalModelIsPlausibleAndEachSlipIsNamedAtItsKey) {
  const PlausibilityLimits limits;
  std::string why;
  EXPECT_TRUE(CheckModelPlausible(CableRobot::NominalFast(), limits, &why)) << why;
  CableRobot robot = CableRobot::NominalFast();
  robot.cables[4].sensor_bias_n = 2e6;  // 2000 "kN": N written as kN
  EXPECT_FALSE(CheckModelPlausible(robot, limits, &why));
  EXPECT_EQ(why,
            "cables[4].sensor_bias_kN: 2000 kN is beyond the plausible +-100 kN (N written as "
            "kN?)");
  robot = CableRobot::NominalFast();
  robot.cables[1].tower_top_m.z() = 270e3;  // mm written as m
  EXPECT_FALSE(CheckModelPlausible(robot, limits, &why));
  EXPECT_EQ(why.rfind("cables[1].tower_top_m: z = 270000 m is above the tower tops", 0), 0u) << why;
}

// Issue 29: gravity, a point-sized reflector and degenerate tower layouts were accepted,
// then blamed on the solver; each is now refused at its key.
TEST(ModelPlausibilityTest, TheModelsWorldIsCheckedAtItsKey) {
  const PlausibilityLimits limits;
  std::string why;
  const auto refused = [&](const CableRobot& robot) {
    EXPECT_FALSE(CheckModelPlausible(robot, limits, &why));
    return why;
  };
  CableRobot robot = CableRobot::NominalFast();
  robot.gravity_m_per_s2 = -1.0;
  EXPECT_EQ(refused(robot),
            "gravity_m_per_s2: -1 m/s^2 is above the plausible maximum of -9.7 m/s^2 (nominal "
            "FAST: -9.8 m/s^2)");
  robot = CableRobot::NominalFast();
  robot.reflector->radius_m = 1e-9;
  robot.reflector->aperture_m = 1e-9;
  EXPECT_EQ(refused(robot).rfind("reflector.radius_m: 1e-09 m is below the plausible minimum", 0),
            0u)
      << why;
  robot = CableRobot::NominalFast();
  robot.reflector->centre_m = Eigen::Vector3d(0.0, 0.0, 1000.0);
  EXPECT_EQ(refused(robot).rfind("reflector.centre_m: (0, 0, 1000) m is more than 50 m", 0), 0u)
      << why;
  // Every tower on one side of the axis: a side the cables cannot pull toward.
  robot = CableRobot::NominalFast();
  for (int i = 0; i < kNumCables; ++i) {
    const double angle = (10.0 + 20.0 * i) * M_PI / 180.0;
    robot.cables[i].tower_top_m =
        Eigen::Vector3d(300.0 * std::cos(angle), 300.0 * std::sin(angle), 270.0);
  }
  EXPECT_NE(refused(robot).find("leave a gap of 260 deg"), std::string::npos) << why;
  robot = CableRobot::NominalFast();
  robot.cables[2].tower_top_m = Eigen::Vector3d(1.0, 1.0, 270.0);
  EXPECT_EQ(refused(robot).rfind("cables[2].tower_top_m: 1.41421 m from the z axis", 0), 0u) << why;
  robot = CableRobot::NominalFast();
  robot.cables[5].tower_top_m.z() = 130.0;  // above the reflector's rim, below the cabin
  EXPECT_EQ(refused(robot).rfind("cables[5].tower_top_m: z = 130 m is below 150 m", 0), 0u) << why;
}

// Issue 57: the cabin's inertia had no range; 1e300 kg m^2 aborted `modes` (Spectra's
// exception, exit 134), 1e100 gave a mode of 0 Hz, 1e-300 and 3.5e12 were accepted. Each
// principal moment is refused at its key, given as a diagonal or as a full tensor.
TEST(ModelPlausibilityTest, TheCabinsInertiaHasAPlausibleRange) {
  std::string why;
  for (const double moment : {1e300, 1e100, 3.5e12, 1e-300, 350.0}) {
    CableRobot robot = CableRobot::NominalFast();
    robot.cabin_inertia_kg_m2 = Eigen::Vector3d::Constant(moment).asDiagonal();
    EXPECT_FALSE(CheckModel(robot, &why)) << moment;
    EXPECT_EQ(why.rfind("cabin.inertia_kg_m2[", 0), 0u) << why;
    EXPECT_NE(why.find("kg m^2 is " + std::string(moment > 1e8 ? "above" : "below")),
              std::string::npos)
        << why;
  }
  CableRobot robot = CableRobot::NominalFast();
  robot.cabin_inertia_kg_m2 << 3.5e5, 1e5, 0.0, 1e5, 3.5e5, 0.0, 0.0, 0.0, 2e8;
  EXPECT_FALSE(CheckModel(robot, &why));  // the triangle inequality first: no rigid body
  robot.cabin_inertia_kg_m2 << 2e8, 1e5, 0.0, 1e5, 2e8, 0.0, 0.0, 0.0, 3e8;
  EXPECT_FALSE(CheckModel(robot, &why));
  EXPECT_EQ(why.rfind("cabin.inertia_kg_m2 (principal moment", 0), 0u) << why;
  robot.cabin_inertia_kg_m2 << 4e5, 1e4, 0.0, 1e4, 4e5, 0.0, 0.0, 0.0, 6e5;
  EXPECT_TRUE(CheckModel(robot, &why)) << why;
  EXPECT_TRUE(CheckModel(CableRobot::NominalFast(), &why)) << why;
}

TEST(ModelPlausibilityTest, QuantityMessagesGiveTheNominalValueAndTheLikelySlip) {
  const PlausibilityLimits limits;
  std::string why;
  EXPECT_TRUE(CheckQuantity(ModelQuantity::kEaN, 2.4656e7, limits, &why));
  EXPECT_FALSE(CheckQuantity(ModelQuantity::kEaN, 2.4656e10, limits, &why));
  EXPECT_EQ(why,
            "2.4656e+10 N is above the plausible maximum of 1.25e+08 N (nominal FAST: "
            "2.4656e+07 N)");
  EXPECT_FALSE(CheckQuantity(ModelQuantity::kSensorGain, 100.0, limits, &why));
  EXPECT_EQ(why, "100 is above the plausible maximum of 2 (nominal FAST: 1)");
  EXPECT_FALSE(CheckQuantity(ModelQuantity::kTensionSigmaPercent, -1.0, limits, &why));
  EXPECT_EQ(why, "-1% is below the plausible minimum of 0% (nominal FAST: 3%)");
  // Not finite: no hint.
  EXPECT_FALSE(CheckQuantity(ModelQuantity::kCabinMassKg, std::nan(""), limits, &why));
  EXPECT_EQ(why, "must be finite");
}

TEST(ModelPlausibilityTest, FurthestFromNominalRanksByThePlausibleRange) {
  CableRobot robot = CableRobot::NominalFast();
  robot.cabin_mass_kg = 45000.0;                   // log(1.5)/log(3.33) = 0.34 of its range
  robot.mass_centre_cabin_m.x() = 4.0;             // 0.8 of its range
  robot.cables[2].linear_density_kg_per_m = 11.8;  // 0.004: negligible, not listed
  const std::vector<std::string> names = FurthestFromNominal(robot, PlausibilityLimits(), 3);
  ASSERT_EQ(names.size(), 2u);
  EXPECT_EQ(names[0], "cabin.mass_centre_m.x = 4 m (nominal 0 m)");
  EXPECT_EQ(names[1], "cabin.mass_kg = 45000 kg (nominal 30000 kg)");
  EXPECT_TRUE(FurthestFromNominal(CableRobot::NominalFast(), PlausibilityLimits(), 3).empty());
}

// 24 poses on a circle of 50 m radius at z = 140 m, level: the nominal model holds them
// all (tensions are not needed to tell whether a pose can be solved).
Dataset Circle() {
  Dataset data;
  data.path = "circle.csv";
  for (int k = 0; k < 24; ++k) {
    Sample s;
    s.line = k + 2;
    const double angle = 2.0 * M_PI * k / 24;
    s.pose.position_m = Eigen::Vector3d(50.0 * std::cos(angle), 50.0 * std::sin(angle), 140.0);
    data.samples.push_back(s);
  }
  return data;
}

TEST(ModelPlausibilityTest, AModelThatCannotSolveWhatTheNominalSolvesIsBlamed) {
  const Dataset data = Circle();
  CableRobot robot = CableRobot::NominalFast();
  robot.mass_centre_cabin_m.x() = 4.0;
  const UnsolvableRows d = DiagnoseUnsolvableRows(
      robot, "the model", data, {AttitudeSource::kMeasured}, {StaticsMethod::kExact});
  EXPECT_EQ(d.rows, 24);
  // A mass centre 4 m off the axis tilts the level cabin's equilibrium out of reach on most
  // of the circle (18 of the 24 poses); the nominal model holds every one of them.
  EXPECT_GE(d.failed, 12);
  EXPECT_EQ(d.solved_by_nominal, d.failed);
  EXPECT_TRUE(d.model_likely);
  const std::string text = DescribeUnsolvableRows(d, "the model");
  const std::string n = std::to_string(d.failed);
  EXPECT_EQ(
      text.rfind("the model cannot solve " + n + " of 24 rows (the nominal FAST model solves " + n +
                     " of them): the model or the spec is the likely cause, not the data; "
                     "furthest from nominal: cabin.mass_centre_m.x = 4 m (nominal 0 m). "
                     "First: circle.csv:",
                 0),
      0u)
      << text;
}

TEST(ModelPlausibilityTest, RowsTheNominalModelCannotHoldEitherAreNotBlamedOnTheModel) {
  Dataset data = Circle();
  // Two rows near tower 4, where no model of FAST holds the cabin (a slack cable).
  for (int k : {3, 9}) data.samples[k].pose.position_m = Eigen::Vector3d(330.0, 0.0, 150.0);
  const UnsolvableRows d =
      DiagnoseUnsolvableRows(CableRobot::NominalFast(), "the model", data,
                             {AttitudeSource::kMeasured}, {StaticsMethod::kExact});
  EXPECT_EQ(d.failed, 2);
  EXPECT_EQ(d.solved_by_nominal, 0);
  EXPECT_FALSE(d.model_likely);
}

}  // namespace
}  // namespace fastcal
