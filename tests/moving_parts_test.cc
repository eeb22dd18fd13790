// The cabin's moving parts (moving_parts.h): the mass centre at the joints against the
// closed form of the issue's rotator and platform, the model file's round trip and its
// errors, the statics at the joints, the calibration's analytic columns against Jets and
// central differences, the dataset's joint columns, and the simulation's joint laws.
#include "fastcal/moving_parts.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/joint_plan.h"
#include "fastcal/simulation.h"
#include "fastcal/statics.h"
#include "jacobian_check.h"
#include "temp_path.h"
#include "test_robots.h"

namespace fastcal {
namespace {

using testing::RotatorJoints;
using testing::RotatorRobot;
using testing::TiltedPoses;

constexpr double kPi = 3.14159265358979323846;

TEST(MovingPartsTest, MassCentreIsTheIssuesClosedForm) {
  // c(q) = c0 + ((R - I) Q + R d m_s) / M, R = R_x(a) R_y(b) (issue 35).
  constexpr double kTolM = 1e-14;  // a few ulps of 0.5 m
  const Eigen::Vector3d q(300.0, -200.0, -6000.0);
  const CableRobot robot = RotatorRobot(q, 2500.0);
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> angle(-15.0, 15.0), shift(-0.1, 0.1);
  for (int trial = 0; trial < 20; ++trial) {
    const double a = angle(rng), b = angle(rng);
    const Eigen::Vector3d d(shift(rng), shift(rng), shift(rng));
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(a * kPi / 180.0, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(b * kPi / 180.0, Eigen::Vector3d::UnitY()))
                                  .toRotationMatrix();
    const Eigen::Vector3d expected =
        robot.mass_centre_cabin_m +
        ((r - Eigen::Matrix3d::Identity()) * q + r * d * 2500.0) / robot.cabin_mass_kg;
    const Eigen::Vector3d got = robot.MassCentreAt(RotatorJoints(a, b, d.x(), d.y(), d.z()));
    EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), kTolM) << trial;
  }
}

TEST(MovingPartsTest, ZeroJointsLeaveTheMassCentreBitForBit) {
  const CableRobot robot = RotatorRobot();
  EXPECT_EQ(robot.MassCentreAt(JointValues{}), robot.mass_centre_cabin_m);
}

TEST(MovingPartsTest, AnOffsetChildSwingsWithItsParent) {
  // A child 1 m along x of a rotator's axis, mass 100 kg, no first moment of its own:
  // turning the rotator by 90 deg about z moves it to +y, so c moves by 100 (-1, 1, 0) / M.
  constexpr double kTolM = 1e-15;
  CableRobot robot = CableRobot::NominalFast();
  MovingPart turn;
  turn.name = "turntable";
  Joint j;
  j.axis = Eigen::Vector3d::UnitZ();
  j.column = "turn_deg";
  turn.joints = {j};
  MovingPart child;
  child.name = "box";
  child.parent = 0;
  Joint slide;
  slide.type = JointType::kPrismatic;
  slide.axis = Eigen::Vector3d::UnitZ();
  slide.column = "box_z_m";
  child.joints = {slide};
  child.origin_m = Eigen::Vector3d(1.0, 0.0, 0.0);
  child.mass_kg = 100.0;
  robot.moving_parts.parts = {turn, child};
  ASSERT_TRUE(robot.moving_parts.IsValid(nullptr));
  EXPECT_TRUE(robot.moving_parts.Translates(1));
  EXPECT_FALSE(robot.moving_parts.Translates(0));
  JointValues q{};
  q[0] = 90.0;
  const Eigen::Vector3d shift = robot.MassCentreAt(q) - robot.mass_centre_cabin_m;
  const Eigen::Vector3d expected = 100.0 * Eigen::Vector3d(-1.0, 1.0, 0.0) / robot.cabin_mass_kg;
  EXPECT_LT((shift - expected).cwiseAbs().maxCoeff(), kTolM);
}

TEST(MovingPartsTest, ModelFileRoundTripIsExact) {
  CableRobot robot = RotatorRobot(Eigen::Vector3d(0.1, -1.0 / 3.0, -6000.0), 2500.0);
  robot.moving_parts.parts[1].origin_m = Eigen::Vector3d(0.0, 0.0, 1.0 / 7.0);
  const std::string text = CableRobotToYaml(robot, "moving parts");
  CableRobot back;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(text, "m.yaml", &back, &error)) << error << "\n" << text;
  ASSERT_EQ(back.moving_parts.parts.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    const MovingPart& a = robot.moving_parts.parts[k];
    const MovingPart& b = back.moving_parts.parts[k];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.parent, b.parent);
    EXPECT_EQ(a.origin_m, b.origin_m);
    EXPECT_EQ(a.first_moment_kg_m, b.first_moment_kg_m);
    EXPECT_EQ(a.mass_kg, b.mass_kg);
    ASSERT_EQ(a.joints.size(), b.joints.size());
    for (size_t j = 0; j < a.joints.size(); ++j) {
      EXPECT_EQ(a.joints[j].column, b.joints[j].column);
      EXPECT_EQ(a.joints[j].type, b.joints[j].type);
      EXPECT_EQ(a.joints[j].axis, b.joints[j].axis);
      EXPECT_EQ(a.joints[j].has_range, b.joints[j].has_range);
      EXPECT_EQ(a.joints[j].range_low, b.joints[j].range_low);
    }
  }
  EXPECT_EQ(CableRobotToYaml(back, "moving parts"), text);
}

TEST(MovingPartsTest, TheIssuesYamlReads) {
  const std::string text = R"(cabin:
  mass_kg: 30000
  mass_centre_m: [0, 0, 0.5]
  moving_parts:
    - name: rotator
      joints:
        - {type: revolute, axis: [1, 0, 0], column: rotator_a_deg, range: [-40, 40]}
        - {type: revolute, axis: [0, 1, 0], column: rotator_b_deg}
      origin_m: [0, 0, 0]
      first_moment_kg_m: [0, 0, -6000]
    - name: stewart
      parent: rotator
      joints:
        - {type: prismatic, axis: [2, 0, 0], column: stewart_x_m}
      mass_kg: 2500
)";
  CableRobot robot;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(text, "m.yaml", &robot, &error)) << error;
  EXPECT_EQ(robot.moving_parts.JointColumns(),
            (std::vector<std::string>{"rotator_a_deg", "rotator_b_deg", "stewart_x_m"}));
  EXPECT_EQ(robot.moving_parts.parts[1].parent, 0);
  EXPECT_EQ(robot.moving_parts.parts[1].joints[0].axis, Eigen::Vector3d::UnitX());  // normalised
  EXPECT_DOUBLE_EQ(robot.moving_parts.parts[0].joints[0].RangeHighSi(), 40.0 * kPi / 180.0);
}

TEST(MovingPartsTest, BadModelFilesNameTheKey) {
  const std::string head = "cabin:\n  moving_parts:\n    - name: rotator\n";
  const struct {
    std::string body;
    std::string expected;
  } cases[] = {
      {"      joints:\n        - {type: revolute, axis: [1, 0, 0], column: rotator_a}\n",
       "cabin.moving_parts[0].joints[0].column"},
      {"      joints:\n        - {type: hinge, axis: [1, 0, 0], column: a_deg}\n",
       "cabin.moving_parts[0].joints[0].type"},
      {"      joints:\n        - {type: revolute, axis: [0, 0, 0], column: a_deg}\n",
       "cabin.moving_parts[0].joints[0].axis"},
      {"      parent: platform\n      joints:\n        - {type: revolute, axis: [1, 0, 0], "
       "column: a_deg}\n",
       "cabin.moving_parts[0].parent"},
      {"      first_moment_kg_m: [0, 0, 1]\n", "cabin.moving_parts[0].joints"},
      {"      joints:\n        - {type: revolute, axis: [1, 0, 0], column: a_deg, range: [5, "
       "-5]}\n",
       "cabin.moving_parts[0].joints[0].range"},
      {"      joints:\n        - {type: revolute, axis: [1, 0, 0], column: a_deg}\n"
       "      mass_kg: -1\n",
       "cabin.moving_parts[0].mass_kg"},
      // Issue 57: a joint named as a column of the dataset itself (simulate wrote x_m
      // twice, and every reader then refused the file); a part heavier than the cabin, an
      // origin a kilometre off, a range of +-1e9 deg.
      {"      joints:\n        - {type: prismatic, axis: [1, 0, 0], column: x_m}\n",
       "cabin.moving_parts[0].joints[0].column: 'x_m' is a column of the dataset itself"},
      {"      joints:\n        - {type: revolute, axis: [1, 0, 0], column: roll_deg}\n",
       "cabin.moving_parts[0].joints[0].column: 'roll_deg' is a column of the dataset"},
      {"      joints:\n        - {type: prismatic, axis: [1, 0, 0], column: s0_1_m}\n",
       "cabin.moving_parts[0].joints[0].column: 's0_1_m' is a column of the dataset"},
      {"      joints:\n        - {type: revolute, axis: [1, 0, 0], column: planned_roll_deg}\n",
       "cabin.moving_parts[0].joints[0].column: 'planned_roll_deg' is a column of the dataset"},
      {"      joints:\n        - {type: prismatic, axis: [1, 0, 0], column: d_m}\n"
       "      mass_kg: 40000\n",
       "cabin.moving_parts[0].mass_kg: 40000 kg brings the moving parts to 40000 kg, more than "
       "the whole cabin's 30000 kg"},
      {"      origin_m: [1e6, 0, 0]\n      joints:\n        - {type: revolute, axis: [1, 0, 0], "
       "column: a_deg}\n",
       "cabin.moving_parts[0].origin_m.x: 1e+06 m is beyond the plausible +-20 m"},
      {"      joints:\n        - {type: revolute, axis: [1, 0, 0], column: a_deg, range: [-1e9, "
       "1e9]}\n",
       "cabin.moving_parts[0].joints[0].range: [-1e+09, 1e+09]: a joint angle beyond one turn"},
  };
  for (const auto& c : cases) {
    CableRobot robot;
    std::string error;
    EXPECT_FALSE(ParseCableRobotYaml(head + c.body, "m.yaml", &robot, &error)) << c.body;
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
    EXPECT_NE(error.find("m.yaml:"), std::string::npos) << error;
  }
}

TEST(MovingPartsTest, StaticsAtTheJointsAreTheStaticsOfTheMovedMassCentre) {
  const CableRobot robot = RotatorRobot();
  const StaticsOptions options;
  for (const Pose& pose : TiltedPoses(5, 351)) {
    const JointValues q = RotatorJoints(12.0, -9.0, 0.05, -0.02, 0.01);
    CableRobot moved = CableRobot::NominalFast();
    moved.mass_centre_cabin_m = robot.MassCentreAt(q);
    StaticsSolution a, b, zero, rigid;
    ASSERT_EQ(SolveStatics(robot, pose, q, options, &a), StaticsStatus::kOk);
    ASSERT_EQ(SolveStatics(moved, pose, options, &b), StaticsStatus::kOk);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(a.cables[i].lower_tension_n, b.cables[i].lower_tension_n);
    }
    // Joints at zero: the rigid model's bits; and the rotator's turn is not nothing.
    ASSERT_EQ(SolveStatics(robot, pose, JointValues{}, options, &zero), StaticsStatus::kOk);
    ASSERT_EQ(SolveStatics(CableRobot::NominalFast(), pose, options, &rigid), StaticsStatus::kOk);
    double largest = 0.0;
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(zero.cables[i].lower_tension_n, rigid.cables[i].lower_tension_n);
      largest = std::max(largest,
                         std::abs(a.cables[i].lower_tension_n - rigid.cables[i].lower_tension_n));
    }
    constexpr double kVisibleN = 100.0;  // 12 deg of a 6000 kg m rotator: kN, not noise
    EXPECT_GT(largest, kVisibleN);
  }
}

// The parts' parameters free, with the mass centre and the cabin's mass.
CalibrationSpec PartsFree(const CableRobot& robot) {
  CalibrationSpec spec;
  for (ParameterSpec p : AllModelParameters(robot)) {
    if (p.kind != ParameterKind::kMassCentre && p.kind != ParameterKind::kCabinMass &&
        p.kind != ParameterKind::kPartFirstMoment && p.kind != ParameterKind::kPartMass) {
      continue;
    }
    p.free = true;
    spec.parameters.push_back(p);
  }
  return spec;
}

internal::TensionResidual ResidualAt(const internal::CalibrationModel& model, const Pose& pose,
                                     const JointValues& q) {
  internal::TensionResidual f;
  f.model = &model;
  f.pose = pose;
  f.joints = q;
  f.statics = ModelFitStaticsOptions(StaticsMethod::kExact);
  StaticsSolution s;
  EXPECT_EQ(SolveStatics(model.robot(), pose, q, f.statics, &s), StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) f.measured_n[i] = s.cables[i].lower_tension_n * 1.01;
  f.sigma_n = internal::TensionSigmas(f.measured_n, 500.0, 3.0);
  return f;
}

TEST(MovingPartsTest, AllModelParametersNameTheParts) {
  std::vector<std::string> names;
  for (const ParameterSpec& p : PartsFree(RotatorRobot()).parameters) names.push_back(p.name);
  for (const char* expected :
       {"moving_parts.rotator.first_moment_kg_m.x", "moving_parts.rotator.first_moment_kg_m.z",
        "moving_parts.stewart.first_moment_kg_m.y", "moving_parts.stewart.mass_kg"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  }
  // The rotator turns about its own origin: its mass moves nothing, and is not a parameter.
  EXPECT_EQ(std::find(names.begin(), names.end(), "moving_parts.rotator.mass_kg"), names.end());
}

TEST(MovingPartsTest, AnalyticColumnsMatchJetsAndCentralDifferences) {
  constexpr double kRelTol = 1e-7;
  constexpr double kDifferenceRelTol = 1e-5;
  const CableRobot robot = RotatorRobot(Eigen::Vector3d(400.0, -300.0, -6000.0), 2500.0);
  const CalibrationSpec spec = PartsFree(robot);
  const internal::CalibrationModel model(robot, spec);
  const std::vector<double> theta = model.InitialTheta();
  const JointValues q = RotatorJoints(11.0, -7.0, 0.04, -0.03, 0.02);
  for (const Pose& pose : TiltedPoses(3, 352)) {
    const internal::TensionResidual f = ResidualAt(model, pose, q);
    // Central differences in double: steps inside the linear range, well above 1e-12.
    testing::ExpectColumnsMatchJetsAndDifferences(
        f, model, theta,
        [](const ParameterSpec& p) {
          return p.kind == ParameterKind::kMassCentre  ? 1e-3
                 : p.kind == ParameterKind::kCabinMass ? 1.0
                                                       : 10.0;  // kg m, kg
        },
        kRelTol, kDifferenceRelTol, "");
  }
}

TEST(MovingPartsTest, DatasetJointColumnsRoundTripAndAreRequired) {
  const CableRobot robot = RotatorRobot();
  SimulationOptions options;
  options.tension_noise_percent = 0.0;
  options.joints.revolute = RevoluteLaw::kGrid;
  options.joints.grid_deg = {-15.0, 0.0, 15.0};
  options.joints.prismatic_sigma_m = 0.05;
  Dataset data;
  std::string error;
  ASSERT_TRUE(Simulate(robot, TiltedPoses(12, 353), options, &data, nullptr, nullptr, &error))
      << error;
  ASSERT_EQ(data.joint_columns, robot.moving_parts.JointColumns());
  EXPECT_EQ(data.samples[4].joint[0], 0.0);  // grid point 4: (0, 0)
  EXPECT_EQ(data.samples[5].joint[1], 15.0);
  EXPECT_NE(data.samples[5].joint[2], 0.0);  // the platform's spread
  const std::string path = test::TempPath("joints", ".csv");
  ASSERT_TRUE(WriteDataset(path, data, "", &error)) << error;
  DatasetReadOptions read;
  read.joint_columns = robot.moving_parts.JointColumns();
  Dataset back;
  ASSERT_TRUE(ReadDataset(path, read, &back, &error)) << error;
  ASSERT_EQ(back.samples.size(), data.samples.size());
  for (size_t n = 0; n < data.samples.size(); ++n) {
    EXPECT_EQ(back.samples[n].joint, data.samples[n].joint) << n;
  }
  EXPECT_TRUE(CheckJointColumns(back, robot.moving_parts, &error)) << error;
  // Read without the model's columns: an unknown column, with the hint.
  EXPECT_FALSE(ReadDataset(path, DatasetReadOptions(), &back, &error));
  EXPECT_NE(error.find("unknown column 'rotator_a_deg'"), std::string::npos) << error;
  EXPECT_NE(error.find("moving part"), std::string::npos) << error;
  // A model asking for columns the file lacks: every missing one named.
  read.joint_columns.push_back("tilt_deg");
  read.joint_columns.push_back("lift_m");
  EXPECT_FALSE(ReadDataset(path, read, &back, &error));
  EXPECT_NE(error.find("'tilt_deg', 'lift_m'"), std::string::npos) << error;
  std::remove(path.c_str());
}

TEST(MovingPartsTest, FocalLawPutsTheFeedAxisAlongTheRadius) {
  constexpr double kTolRad = 1e-12;
  const CableRobot robot = RotatorRobot();
  JointPlanOptions options;
  options.revolute = RevoluteLaw::kFocal;
  JointPlan plan;
  std::string error;
  ASSERT_TRUE(JointPlan::Make(robot.moving_parts, options, &plan, &error)) << error;
  for (const Pose& pose : TiltedPoses(6, 354)) {
    JointValues q;
    ASSERT_TRUE(plan.Next(0, pose, &q, &error)) << error;
    const Eigen::Matrix3d rotator =
        (Eigen::AngleAxisd(q[0] * kPi / 180.0, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(q[1] * kPi / 180.0, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
    const Eigen::Vector3d feed = pose.rotation * rotator * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d radius = (options.focal_centre_m - pose.position_m).normalized();
    // The angle between them by its sine (acos near 1 resolves only 1e-8 rad).
    EXPECT_LT(feed.cross(radius).norm(), kTolRad);
    EXPECT_GT(feed.dot(radius), 0.0);
  }
  // A model without a rotator cannot follow the focal law.
  EXPECT_FALSE(JointPlan::Make(MovingParts(), options, &plan, &error));
  EXPECT_NE(error.find("rotator"), std::string::npos) << error;
}

}  // namespace
}  // namespace fastcal
