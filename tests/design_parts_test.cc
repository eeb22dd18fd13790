// Tests of the survey design with the cabin's moving parts (design.h, "Moving parts"):
// the rotator's angles as design variables separate its first moment from the fixed mass
// centre, which a survey with the rotator held at zero cannot; the designed poses file
// carries the joint columns and reads back exactly (trajectory.h); the pose reader's
// errors for joint columns.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/design.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

constexpr char kModel[] = R"(cabin:
  mass_kg: 30000
  mass_centre_m: [0, 0, 0.5]
  moving_parts:
    - name: rotator
      joints:
        - {type: revolute, axis: [1, 0, 0], column: rotator_a_deg, range: [-40, 40]}
        - {type: revolute, axis: [0, 1, 0], column: rotator_b_deg, range: [-40, 40]}
      first_moment_kg_m: [0, 0, -6000]
    - name: stewart
      parent: rotator
      joints:
        - {type: prismatic, axis: [0, 0, 1], column: stewart_z_m, range: [-0.5, 0.5]}
      mass_kg: 2500
)";

// The issue's priors: N(0, 3000 kg m) per first-moment component, N(2500, 300) kg.
constexpr char kSpec[] = R"(
parameters:
  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}
  sensor_gain: {free: true, prior: {mean: 1, sigma: 0.01}}
  moving_parts:
    rotator:
      first_moment_kg_m:
        x: {free: true, prior: {mean: 0, sigma: 3000}}
        y: {free: true, prior: {mean: 0, sigma: 3000}}
        z: {free: true, prior: {mean: 0, sigma: 3000}}
    stewart:
      mass_kg: {free: true, prior: {mean: 2500, sigma: 300}}
)";
constexpr double kPriorSigmaKgM = 3000.0;

CableRobot Model() {
  CableRobot robot;
  std::string error;
  EXPECT_TRUE(ParseCableRobotYaml(kModel, "model.yaml", &robot, &error)) << error;
  return robot;
}

CalibrationSpec Spec(const CableRobot& robot) {
  CalibrationSpec spec;
  std::string error;
  EXPECT_TRUE(ParseCalibrationSpecYaml(kSpec, "spec.yaml", robot, &spec, &error)) << error;
  return spec;
}

// A coarse cap (9 positions), 60 samples, Q_z and the mass centre's z wanted.
DesignOptions Options() {
  DesignOptions o;
  o.workspace.grid.off_axis_step_deg = 20.0;
  o.workspace.grid.azimuth_step_deg = 90.0;
  o.samples = 60;
  o.wanted = {"moving_parts.rotator.first_moment_kg_m.z", "mass_centre_m.z"};
  return o;
}

double SigmaOf(const Design& d, const std::string& name) {
  for (size_t k = 0; k < d.free_names.size(); ++k) {
    if (d.free_names[k] == name) return d.design.budget.parameters[k].total;
  }
  ADD_FAILURE() << name << " is not free";
  return NAN;
}

TEST(DesignPartsTest, TheRotatorsAnglesSeparateItsFirstMomentFromTheMassCentre) {
  const CableRobot robot = Model();
  const CalibrationSpec spec = Spec(robot);
  Design d;
  std::string error;
  ASSERT_TRUE(DesignSurvey(robot, spec, Options(), &d, &error)) << error;
  ASSERT_TRUE(d.design.ok) << d.design.note;
  EXPECT_EQ(d.joint_columns,
            (std::vector<std::string>{"rotator_a_deg", "rotator_b_deg", "stewart_z_m"}));
  ASSERT_EQ(d.joints.size(), d.poses.size());
  // Every stop at a point of the grid, the platform at zero; some pose visited at more
  // than one pair of angles (that is what separates Q_z from c0_z).
  const std::set<double> grid = {-15.0, 0.0, 15.0};
  int revisits = 0;
  for (size_t k = 0; k < d.stops.size(); ++k) {
    const DesignCandidate& c = d.candidates[d.stops[k].candidate];
    EXPECT_TRUE(grid.count(c.joints[0]) && grid.count(c.joints[1]));
    EXPECT_EQ(c.joints[2], 0.0);
    EXPECT_GE(c.joint_point, 0);
    if (k > 0 && c.pose.position_m == d.candidates[d.stops[k - 1].candidate].pose.position_m) {
      ++revisits;
    }
  }
  EXPECT_GT(revisits, 0) << "no pose is visited at two pairs of angles";
  // The first moment's z known far better than its prior, which the circle (the rotator
  // by the focal law, tied to the cabin's tilt) hardly improves on.
  constexpr double kWellDetermined = 0.2;  // of the prior's sigma
  const double q_z = SigmaOf(d, "moving_parts.rotator.first_moment_kg_m.z");
  EXPECT_LT(q_z, kWellDetermined * kPriorSigmaKgM);
  // The rotator held at zero: Q_z and c0_z are the same column; the prior alone holds Q_z.
  DesignOptions zero = Options();
  zero.joint_grid_deg = {0.0};
  Design held;
  ASSERT_TRUE(DesignSurvey(robot, spec, zero, &held, &error)) << error;
  constexpr double kPriorBound = 0.95;  // of the prior's sigma
  EXPECT_GT(SigmaOf(held, "moving_parts.rotator.first_moment_kg_m.z"),
            kPriorBound * kPriorSigmaKgM);
  // The design's poses file carries the joints and reads back exactly.
  std::vector<Pose> poses;
  std::vector<JointValues> joints;
  ASSERT_TRUE(ParsePosesCsv(DesignPosesCsv(d, "test"), "poses.csv", d.joint_columns, &poses,
                            &joints, nullptr, &error))
      << error;
  ASSERT_EQ(joints.size(), d.joints.size());
  for (size_t n = 0; n < joints.size(); ++n) {
    for (size_t j = 0; j < d.joint_columns.size(); ++j) EXPECT_EQ(joints[n][j], d.joints[n][j]);
  }
  // The prediction for any survey takes the joints: the design's own samples predict the
  // design's sigma (its rows are the same).
  DesignPrediction again;
  ASSERT_TRUE(PredictSurvey(robot, spec, Options(), d.poses, d.joints, &again, &error)) << error;
  const int k = 6;  // moving_parts.rotator.first_moment_kg_m.z in the spec's order
  ASSERT_EQ(d.free_names[k], "moving_parts.rotator.first_moment_kg_m.z");
  constexpr double kSame = 1e-9;
  EXPECT_NEAR(again.budget.parameters[k].total, q_z, kSame * q_z);
}

TEST(DesignPartsTest, AGridOutsideTheJointsRangesIsRefusedAndBadGridsNamed) {
  const CableRobot robot = Model();
  DesignOptions o = Options();
  o.joint_grid_deg = {50.0, 60.0};  // beyond +-40
  Design d;
  std::string error;
  EXPECT_FALSE(DesignSurvey(robot, Spec(robot), o, &d, &error));
  EXPECT_NE(error.find("joint grid"), std::string::npos) << error;
  o.joint_grid_deg = {NAN};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("joint_grid_deg"), std::string::npos) << error;
  o.joint_grid_deg = std::vector<double>(10, 0.0);
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("joint_grid_deg"), std::string::npos) << error;
}

TEST(PoseFileJointsTest, AllOrNoneAndEachValueChecked) {
  const std::vector<std::string> columns = {"rotator_a_deg", "rotator_b_deg"};
  std::vector<Pose> poses;
  std::vector<JointValues> joints;
  std::string error;
  // None: the poses, and no joints (the command's law sets them).
  ASSERT_TRUE(
      ParsePosesCsv("x_m,y_m,z_m\n0,0,150\n", "p.csv", columns, &poses, &joints, nullptr, &error))
      << error;
  EXPECT_TRUE(joints.empty());
  // All, in any order among the pose's columns.
  ASSERT_TRUE(ParsePosesCsv("rotator_b_deg,x_m,y_m,z_m,rotator_a_deg\n-5,0,0,150,7.5\n", "p.csv",
                            columns, &poses, &joints, nullptr, &error))
      << error;
  ASSERT_EQ(joints.size(), 1u);
  EXPECT_EQ(joints[0][0], 7.5);
  EXPECT_EQ(joints[0][1], -5.0);
  // Some but not all: the missing one named.
  EXPECT_FALSE(ParsePosesCsv("x_m,y_m,z_m,rotator_a_deg\n0,0,150,1\n", "p.csv", columns, &poses,
                             &joints, nullptr, &error));
  EXPECT_NE(error.find("'rotator_b_deg'"), std::string::npos) << error;
  // A value out of one turn, named by file, line and column.
  EXPECT_FALSE(ParsePosesCsv("x_m,y_m,z_m,rotator_a_deg,rotator_b_deg\n0,0,150,1,900\n", "p.csv",
                             columns, &poses, &joints, nullptr, &error));
  EXPECT_NE(error.find("p.csv:2:"), std::string::npos) << error;
  EXPECT_NE(error.find("rotator_b_deg"), std::string::npos) << error;
  // A joint column without a model that names it: unknown, with the reason.
  EXPECT_FALSE(
      ParsePosesCsv("x_m,y_m,z_m,rotator_a_deg\n0,0,150,1\n", "p.csv", &poses, nullptr, &error));
  EXPECT_NE(error.find("cabin.moving_parts"), std::string::npos) << error;
}

}  // namespace
}  // namespace fastcal
