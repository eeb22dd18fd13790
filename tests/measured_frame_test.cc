// Where the telemetry measures (measured_frame.h, issue 58): the cabin's pose from the
// data's against poses derived by hand for a frame on the cabin and on the rotator, the
// statics through it against the plain model's at that pose, round trips, the model
// file's key and its errors, the calibration's offset columns against Jets and central
// differences, the spec's group, and a simulated survey with a lever arm and the
// rotator calibrated to its truth with the offset estimated.
#include "fastcal/measured_frame.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/simulation.h"
#include "fastcal/statics.h"
#include "jacobian_check.h"
#include "test_robots.h"

namespace fastcal {
namespace {

using testing::RotatorJoints;
using testing::RotatorRobot;
using testing::TiltedPoses;

constexpr double kPi = 3.14159265358979323846;
// A pose derived by hand against the conversion: the rounding of a few products of
// numbers of order 100 m.
constexpr double kHandPositionTolM = 1e-12;
constexpr double kHandRotationTol = 1e-15;

Eigen::Matrix3d Rx(double deg) {
  return Eigen::AngleAxisd(deg * kPi / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d Ry(double deg) {
  return Eigen::AngleAxisd(deg * kPi / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

// The issue's cabin with the rotator's axes 1 m below the anchor plane and the measured
// frame on `part` (-1: the cabin) at `offset`.
CableRobot FramedRobot(int part, const Eigen::Vector3d& offset) {
  CableRobot robot = RotatorRobot();
  robot.moving_parts.parts[0].origin_m = Eigen::Vector3d(0, 0, -1);
  MeasuredFrame frame;
  frame.part = part;
  frame.offset_m = offset;
  robot.measured_frame = frame;
  return robot;
}

void ExpectSamePose(const Pose& got, const Pose& expected, double position_tol,
                    double rotation_tol) {
  EXPECT_LT((got.position_m - expected.position_m).cwiseAbs().maxCoeff(), position_tol)
      << got.position_m.transpose() << " vs " << expected.position_m.transpose();
  EXPECT_LT((got.rotation - expected.rotation).cwiseAbs().maxCoeff(), rotation_tol);
}

// The six lower-end tensions of `robot` at `pose` and `q`.
std::array<double, kNumCables> Tensions(const CableRobot& robot, const Pose& pose,
                                        const JointValues& q) {
  StaticsSolution s;
  EXPECT_EQ(SolveStatics(robot, pose, q, StaticsOptions(), &s), StaticsStatus::kOk);
  std::array<double, kNumCables> t{};
  for (int i = 0; i < kNumCables; ++i) t[i] = s.cables[i].lower_tension_n;
  return t;
}

TEST(MeasuredFrameTest, AFrameOnTheCabinGivesTheCabinPoseDerivedByHand) {
  // The point 2 m below the anchor plane, the cabin rolled 10 deg: R_c = R_m = R_x(10),
  // p_c = m - R_m d = m + 2 R_x(10) z = m + 2 (0, -sin 10, cos 10).
  const CableRobot robot = FramedRobot(-1, Eigen::Vector3d(0, 0, -2));
  Pose data;
  data.position_m = Eigen::Vector3d(10, 5, 150);
  data.rotation = Rx(10);
  Pose hand;
  hand.position_m = Eigen::Vector3d(10, 5 - 2 * 0.17364817766693033, 150 + 2 * 0.984807753012208);
  hand.rotation = Rx(10);
  ExpectSamePose(robot.CabinPose(data, JointValues{}), hand, kHandPositionTolM, kHandRotationTol);
}

TEST(MeasuredFrameTest, AFrameOnTheRotatorGivesTheCabinPoseDerivedByHand) {
  // The rotator's axes at t = (0, 0, -1), the point d = (0, 0, -1.2) below them, the data's
  // attitude level. Rotator at a = 15: R_c = R_m R_x(15)^T = R_x(-15),
  //   p_c = m - R_c t - R_m d = m + (0, sin 15, cos 15) + (0, 0, 1.2);
  // at b = 20: R_c = R_y(-20), p_c = m + (-sin 20, 0, cos 20) + (0, 0, 1.2).
  const CableRobot robot = FramedRobot(0, Eigen::Vector3d(0, 0, -1.2));
  Pose data;
  data.position_m = Eigen::Vector3d(20, -10, 148);
  Pose a15, b20;
  a15.position_m = Eigen::Vector3d(20, -10 + 0.25881904510252074, 148 + 0.9659258262890683 + 1.2);
  a15.rotation = Rx(-15);
  b20.position_m = Eigen::Vector3d(20 - 0.3420201433256687, -10, 148 + 0.9396926207859084 + 1.2);
  b20.rotation = Ry(-20);
  ExpectSamePose(robot.CabinPose(data, RotatorJoints(15, 0)), a15, kHandPositionTolM,
                 kHandRotationTol);
  ExpectSamePose(robot.CabinPose(data, RotatorJoints(0, 20)), b20, kHandPositionTolM,
                 kHandRotationTol);
}

TEST(MeasuredFrameTest, StaticsThroughTheFrameAreThePlainModelsAtTheCabinPose) {
  // The tensions of the data's pose through the frame, against the model without one at
  // the cabin's pose derived by hand: the same solve, to the solver's tolerance.
  constexpr double kRelTol = 1e-10;
  struct Case {
    int part;
    Eigen::Vector3d offset;
    JointValues q;
    Pose data, hand;
  };
  Case on_cabin{-1, Eigen::Vector3d(0, 0, -2), JointValues{}, {}, {}};
  on_cabin.data.position_m = Eigen::Vector3d(10, 5, 150);
  on_cabin.data.rotation = Rx(10);
  on_cabin.hand.position_m =
      Eigen::Vector3d(10, 5 - 2 * 0.17364817766693033, 150 + 2 * 0.984807753012208);
  on_cabin.hand.rotation = Rx(10);
  // The platform rolled 12 deg with the rotator at a = 15: the cabin at R_x(-3), and
  // p_c = m - R_c t - R_m d = m + (0, sin 3, cos 3) + 1.2 (0, -sin 12, cos 12).
  Case on_rotator{0, Eigen::Vector3d(0, 0, -1.2), RotatorJoints(15, 0), {}, {}};
  on_rotator.data.position_m = Eigen::Vector3d(20, -10, 148);
  on_rotator.data.rotation = Rx(12);
  on_rotator.hand.position_m =
      Eigen::Vector3d(20, -10 + 0.052335956242943835 - 1.2 * 0.20791169081775934,
                      148 + 0.9986295347545738 + 1.2 * 0.9781476007338057);
  on_rotator.hand.rotation = Rx(-3);
  for (const Case& c : {on_cabin, on_rotator}) {
    const CableRobot framed = FramedRobot(c.part, c.offset);
    CableRobot plain = framed;
    plain.measured_frame.reset();
    const std::array<double, kNumCables> through =
        Tensions(framed, framed.CabinPose(c.data, c.q), c.q);
    const std::array<double, kNumCables> by_hand = Tensions(plain, c.hand, c.q);
    const std::array<double, kNumCables> unconverted = Tensions(plain, c.data, c.q);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(through[i], by_hand[i], kRelTol * by_hand[i]) << c.part << " cable " << i + 1;
    }
    // The frame matters: the data's pose taken as the cabin's is kilonewtons off.
    double largest = 0.0;
    for (int i = 0; i < kNumCables; ++i)
      largest = std::max(largest, std::abs(unconverted[i] - by_hand[i]));
    EXPECT_GT(largest, 1e3) << c.part;
  }
}

TEST(MeasuredFrameTest, CabinToMeasuredToCabinRoundTrips) {
  constexpr double kPositionTolM = 1e-12;  // rounding of ~150 m
  constexpr double kRotationTol = 1e-14;
  std::mt19937_64 rng(58);
  std::uniform_real_distribution<double> angle(-26.0, 26.0), shift(-0.1, 0.1), arm(-3.0, 3.0);
  for (int part : {-1, 0, 1}) {
    const CableRobot robot = FramedRobot(part, Eigen::Vector3d(arm(rng), arm(rng), arm(rng)));
    for (const Pose& cabin : TiltedPoses(8, 580 + part)) {
      const JointValues q =
          RotatorJoints(angle(rng), angle(rng), shift(rng), shift(rng), shift(rng));
      const Pose measured = robot.MeasuredPose(cabin, q);
      ExpectSamePose(robot.CabinPose(measured, q), cabin, kPositionTolM, kRotationTol);
      // And the other way.
      ExpectSamePose(robot.MeasuredPose(robot.CabinPose(cabin, q), q), cabin, kPositionTolM,
                     kRotationTol);
    }
  }
}

TEST(MeasuredFrameTest, APlatformFrameCarriesTheRotatorsTurnAndItsOwnShift) {
  // The Stewart platform on the rotator: R_m = R_c R_x(a) R_y(b), and its origin at
  // t_rotator + R_x(a) R_y(b) s, s its shift: m = p_c + R_c (t + R (s + d)).
  constexpr double kTolM = 1e-12;
  const Eigen::Vector3d d(0.1, -0.2, -1.2), s(0.03, -0.02, 0.05), t(0, 0, -1);
  const CableRobot robot = FramedRobot(1, d);
  const JointValues q = RotatorJoints(12, -8, s.x(), s.y(), s.z());
  const Pose cabin = TiltedPoses(1, 581).front();
  const Eigen::Matrix3d r = Rx(12) * Ry(-8);
  const Pose measured = robot.MeasuredPose(cabin, q);
  EXPECT_LT((measured.rotation - cabin.rotation * r).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((measured.position_m - (cabin.position_m + cabin.rotation * (t + r * (s + d))))
                .cwiseAbs()
                .maxCoeff(),
            kTolM);
}

TEST(MeasuredFrameTest, AModelWithoutTheKeyIsUnchangedBitForBit) {
  const CableRobot robot = RotatorRobot();
  for (const Pose& pose : TiltedPoses(4, 582)) {
    const Pose back = robot.CabinPose(pose, RotatorJoints(10, 5));
    EXPECT_EQ(back.position_m, pose.position_m);
    EXPECT_EQ(back.rotation, pose.rotation);
    const Pose there = robot.MeasuredPose(pose, RotatorJoints(10, 5));
    EXPECT_EQ(there.position_m, pose.position_m);
    EXPECT_EQ(there.rotation, pose.rotation);
  }
}

// The model file's key, written and read back, and its errors.
constexpr char kPartsYaml[] = R"(format: fastcal-model-1
cabin:
  moving_parts:
    - name: rotator
      joints:
        - {type: revolute, axis: [1, 0, 0], column: rotator_a_deg}
        - {type: revolute, axis: [0, 1, 0], column: rotator_b_deg}
      first_moment_kg_m: [0, 0, -6000]
    - name: stewart
      parent: rotator
      joints:
        - {type: prismatic, axis: [0, 0, 1], column: stewart_z_m}
      mass_kg: 2500
)";

std::string WithFrame(const std::string& frame) {
  return std::string(kPartsYaml) + "  measured_frame:\n" + frame;
}

TEST(MeasuredFrameTest, TheModelFilesKeyRoundTrips) {
  CableRobot robot;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(WithFrame("    part: stewart\n    offset_m: [0, 0.1, -1.2]\n"),
                                  "m.yaml", &robot, &error))
      << error;
  ASSERT_TRUE(robot.measured_frame.has_value());
  EXPECT_EQ(robot.measured_frame->part, 1);
  EXPECT_EQ(robot.measured_frame->offset_m, Eigen::Vector3d(0, 0.1, -1.2));
  CableRobot back;
  ASSERT_TRUE(ParseCableRobotYaml(CableRobotToYaml(robot, ""), "back.yaml", &back, &error))
      << error;
  ASSERT_TRUE(back.measured_frame.has_value());
  EXPECT_EQ(back.measured_frame->part, 1);
  EXPECT_EQ(back.measured_frame->offset_m, robot.measured_frame->offset_m);
  // The defaults: the cabin itself, no offset.
  ASSERT_TRUE(
      ParseCableRobotYaml(WithFrame("    offset_m: [0, 0, -2]\n"), "m.yaml", &robot, &error))
      << error;
  EXPECT_EQ(robot.measured_frame->part, -1);
  // Without the key: none.
  ASSERT_TRUE(ParseCableRobotYaml(kPartsYaml, "m.yaml", &robot, &error)) << error;
  EXPECT_FALSE(robot.measured_frame.has_value());
  EXPECT_EQ(CableRobotToYaml(robot, "").find("measured_frame"), std::string::npos);
}

TEST(MeasuredFrameTest, BadKeysAreNamedWithTheirLine) {
  const struct {
    const char* frame;
    const char* expected;
  } cases[] = {
      {"    part: stewartt\n",
       "m.yaml:15: cabin.measured_frame.part: 'stewartt' is not a moving part of the model "
       "(its parts: rotator, stewart; or cabin)"},
      {"    offset_m: [0, 0, .nan]\n",
       "m.yaml:15: cabin.measured_frame.offset_m[2]: must be finite"},
      {"    offset_m: [0, 0, 1200]\n",
       "m.yaml:15: cabin.measured_frame.offset_m.z: 1200 m is beyond the plausible +-20 m "
       "(mm written as m?)"},
      {"    offset_m: [0, 0]\n", "m.yaml:15: cabin.measured_frame.offset_m: expected a list of 3"},
      {"    point: [0, 0, 1]\n",
       "m.yaml:15: cabin.measured_frame.point: unknown key (allowed here: part, offset_m)"},
  };
  for (const auto& c : cases) {
    CableRobot robot;
    std::string error;
    EXPECT_FALSE(ParseCableRobotYaml(WithFrame(c.frame), "m.yaml", &robot, &error)) << c.frame;
    EXPECT_EQ(error.rfind(c.expected, 0), 0u) << error;
  }
  // A part named in a model without moving parts.
  CableRobot robot;
  std::string error;
  EXPECT_FALSE(
      ParseCableRobotYaml("cabin:\n  measured_frame: {part: stewart}\n", "n.yaml", &robot, &error));
  EXPECT_NE(error.find("n.yaml:2: cabin.measured_frame.part: 'stewart' is not a moving part of "
                       "the model (it has none; cabin.moving_parts; or cabin)"),
            std::string::npos)
      << error;
  // Built in code: IsValid names the key.
  robot = RotatorRobot();
  robot.measured_frame = MeasuredFrame{};
  robot.measured_frame->offset_m.x() = std::nan("");
  EXPECT_FALSE(robot.IsValid(&error));
  EXPECT_EQ(error, "cabin.measured_frame.offset_m: must be finite");
  robot.measured_frame->offset_m.x() = 0.0;
  robot.measured_frame->part = 5;
  EXPECT_FALSE(robot.IsValid(&error));
  EXPECT_EQ(error.rfind("cabin.measured_frame.part:", 0), 0u) << error;
}

// ---------------------------------------------------------------------------------------
// The calibration's offset.

CalibrationSpec OffsetSpec(const CableRobot& robot, bool with_prior) {
  CalibrationSpec spec;
  std::string error;
  const std::string text = std::string(R"(parameters:
  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}
  measured_frame:
    offset_m:
      x: {free: true)") + (with_prior ? ", prior: {mean: 0, sigma: 0.5}" : "") +
                           R"(}
      y: {free: true)" + (with_prior ? ", prior: {mean: 0, sigma: 0.5}" : "") +
                           R"(}
      z: {free: true)" + (with_prior ? ", prior: {mean: -1.5, sigma: 0.5}" : "") +
                           R"(}
  moving_parts:
    rotator:
      first_moment_kg_m: {z: {free: true}}
)";
  EXPECT_TRUE(ParseCalibrationSpecYaml(text, "spec.yaml", robot, &spec, &error)) << error;
  return spec;
}

TEST(MeasuredFrameTest, TheSpecNamesTheOffsetAndRefusesItWithoutAFrame) {
  const CableRobot robot = FramedRobot(1, Eigen::Vector3d(0, 0, -1.2));
  const CalibrationSpec spec = OffsetSpec(robot, true);
  std::vector<std::string> names;
  for (const ParameterSpec& p : spec.parameters) names.push_back(p.name);
  for (const char* n : {"measured_frame.offset_m.x", "measured_frame.offset_m.z"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  }
  // Written and read back: the same list.
  CalibrationSpec back;
  std::string error;
  ASSERT_TRUE(
      ParseCalibrationSpecYaml(CalibrationSpecToYaml(spec), "back.yaml", robot, &back, &error))
      << error;
  ASSERT_EQ(back.parameters.size(), spec.parameters.size());
  for (size_t k = 0; k < spec.parameters.size(); ++k) {
    EXPECT_EQ(back.parameters[k].name, spec.parameters[k].name);
    EXPECT_EQ(back.parameters[k].prior_mean_si, spec.parameters[k].prior_mean_si);
  }
  // A model without the key: the group is refused at its line, saying what to declare.
  CableRobot plain = robot;
  plain.measured_frame.reset();
  EXPECT_FALSE(
      ParseCalibrationSpecYaml("parameters:\n  measured_frame:\n    offset_m: {x: {free: "
                               "true}}\n",
                               "spec.yaml", plain, &back, &error));
  EXPECT_EQ(error.rfind("spec.yaml:2: parameters.measured_frame: the model declares no measured "
                        "frame (cabin.measured_frame",
                        0),
            0u)
      << error;
  // An implausible prior: named.
  EXPECT_FALSE(ParseCalibrationSpecYaml(
      "parameters:\n  measured_frame:\n    offset_m: {z: {free: true, initial: 1200}}\n",
      "spec.yaml", robot, &back, &error));
  EXPECT_NE(error.find("parameters.measured_frame.offset_m.z.initial: 1200 m is beyond the "
                       "plausible +-20 m"),
            std::string::npos)
      << error;
}

TEST(MeasuredFrameTest, OffsetColumnsMatchJetsAndCentralDifferences) {
  constexpr double kJetRelTol = 1e-7;
  constexpr double kDifferenceRelTol = 1e-5;
  constexpr double kStepM = 1e-3;  // inside the tensions' linear range, well above 1e-12
  for (int part : {-1, 1}) {
    const CableRobot robot = FramedRobot(part, Eigen::Vector3d(0.1, -0.2, -1.2));
    const CalibrationSpec spec = OffsetSpec(robot, false);
    const internal::CalibrationModel model(robot, spec);
    const std::vector<double> theta = model.InitialTheta();
    const JointValues q = RotatorJoints(11, -7, 0.04, -0.03, 0.02);
    for (const Pose& cabin : TiltedPoses(3, 583)) {
      internal::TensionResidual f;
      f.model = &model;
      f.pose = robot.MeasuredPose(cabin, q);  // the data's
      f.joints = q;
      f.statics = ModelFitStaticsOptions(StaticsMethod::kExact);
      const std::array<double, kNumCables> t = Tensions(robot, cabin, q);
      for (int i = 0; i < kNumCables; ++i) f.measured_n[i] = t[i] * 1.01;
      f.sigma_n = internal::TensionSigmas(f.measured_n, 500.0, 3.0);
      testing::ExpectColumnsMatchJetsAndDifferences(
          f, model, theta,
          [](const ParameterSpec& p) {
            return p.kind == ParameterKind::kMeasuredOffset ? kStepM : 0.0;
          },
          kJetRelTol, kDifferenceRelTol, "part " + std::to_string(part));
    }
  }
}

TEST(MeasuredFrameTest, SimulatedDataAreTheFramesPose) {
  // With the truth's frame and no pose noise, every sample's pose is the frame's at the
  // cabin's planned pose and the sample's joints.
  constexpr double kTolM = 1e-9;  // the planned attitude's rpy round trip
  const CableRobot truth = FramedRobot(1, Eigen::Vector3d(0, 0, -1.2));
  SimulationOptions options;
  options.tension_noise_percent = 0.0;
  options.joints.revolute = RevoluteLaw::kFocal;
  const std::vector<Pose> planned = TiltedPoses(6, 584);
  Dataset data;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, nullptr, nullptr, &error)) << error;
  for (size_t n = 0; n < planned.size(); ++n) {
    const Sample& s = data.samples[n];
    const Pose cabin = truth.CabinPose(s.pose, s.joint);
    EXPECT_LT((cabin.position_m - planned[n].position_m).norm(), kTolM) << n;
    EXPECT_LT((cabin.rotation - planned[n].rotation).cwiseAbs().maxCoeff(), kTolM) << n;
    // The rotator completes the tilt: the feed's z axis points at the focal centre.
    const Eigen::Vector3d to_centre =
        (Eigen::Vector3d(0, 0, 300) - planned[n].position_m).normalized();
    EXPECT_GT((s.pose.rotation * Eigen::Vector3d::UnitZ()).dot(to_centre), 0.999) << n;
    // And the readings are the truth's at the cabin's pose.
    const std::array<double, kNumCables> t = Tensions(truth, cabin, s.joint);
    for (int i = 0; i < kNumCables; ++i) EXPECT_NEAR(s.tension_n[i], t[i], 1e-6 * t[i]) << n;
  }
}

}  // namespace
}  // namespace fastcal
