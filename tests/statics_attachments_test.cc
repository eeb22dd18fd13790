// Tests of the statics of cables as built (statics.h with cable_attachment.h): the two
// identities of docs/model.md "Cables as built" solved through the whole cabin's
// equilibrium, the reduction to uniform cables, the statuses that refuse what the methods
// cannot answer, a workspace sweep, the model file's round trip, and the derivatives the
// calibration takes through the chain (Jets against central differences).
#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "fastcal/cable_robot.h"
#include "fastcal/statics.h"
#include "test_robots.h"

namespace fastcal {

void PrintTo(StaticsStatus status, std::ostream* os) { *os << StaticsStatusName(status); }

namespace {

using testing::AsBuiltRobot;

// Relative agreement of two exact solves of one equilibrium (each to 1e-12).
constexpr double kSolveTol = 1e-9;

CableAttachment Point(double at_m, double mass_kg) {
  return CableAttachment::PointMass(at_m, mass_kg);
}

CableAttachment Range(double from_m, double to_m, double density) {
  return CableAttachment::AddedDensity(from_m, to_m, density);
}

Pose FocalPose(const Eigen::Vector3d& position_m) {
  Pose pose;
  pose.position_m = position_m;
  pose.rotation = FocalAttitude(position_m, FocalAttitudeLaw());
  return pose;
}

StaticsSolution Solve(const CableRobot& robot, const Pose& pose,
                      StaticsMethod method = StaticsMethod::kExact) {
  StaticsOptions options;
  options.method = method;
  StaticsSolution s;
  SolveStatics(robot, pose, options, &s);
  return s;
}

const Eigen::Vector3d kK2(42.65, 33.73, 149.52);

TEST(StaticsAttachmentsTest, AddedDensityOverEveryCableIsTheHeavierUniformModel) {
  CableRobot with = CableRobot::NominalFast(), heavier = CableRobot::NominalFast();
  for (int i = 0; i < kNumCables; ++i) {
    const double added = 0.4 + 0.2 * i;
    with.cables[i].attachments = {Range(0.0, 1e4, added)};
    heavier.cables[i].linear_density_kg_per_m += added;
  }
  for (const Eigen::Vector3d& position : {Eigen::Vector3d(0, 0, 140), kK2}) {
    const StaticsSolution a = Solve(with, FocalPose(position));
    const StaticsSolution b = Solve(heavier, FocalPose(position));
    ASSERT_EQ(a.status, StaticsStatus::kOk);
    ASSERT_EQ(b.status, StaticsStatus::kOk);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(a.cables[i].lower_tension_n, b.cables[i].lower_tension_n,
                  kSolveTol * b.cables[i].lower_tension_n);
      EXPECT_NEAR(a.cables[i].upper_tension_n, b.cables[i].upper_tension_n,
                  kSolveTol * b.cables[i].upper_tension_n);
      EXPECT_NEAR(a.cables[i].unstretched_length_m, b.cables[i].unstretched_length_m,
                  kSolveTol * b.cables[i].unstretched_length_m);
    }
  }
}

// A point mass at at_m: 0 is that mass moved onto the cabin at the cable's anchor: same
// pose, same cable above it; the sensor below the mass reads the tension without it.
TEST(StaticsAttachmentsTest, PointMassAtTheLowerEndIsCabinMassAtTheAnchor) {
  for (int cable = 0; cable < kNumCables; cable += 3) {
    const double mass_kg = 520.0;
    CableRobot with = CableRobot::NominalFast(), moved = CableRobot::NominalFast();
    with.cables[cable].attachments = {Point(0.0, mass_kg)};
    const double m0 = moved.cabin_mass_kg;
    moved.mass_centre_cabin_m =
        (m0 * moved.mass_centre_cabin_m + mass_kg * moved.AnchorOfCable(cable)) / (m0 + mass_kg);
    moved.cabin_mass_kg = m0 + mass_kg;
    const Pose pose = FocalPose(kK2);
    const StaticsSolution a = Solve(with, pose), b = Solve(moved, pose);
    ASSERT_EQ(a.status, StaticsStatus::kOk);
    ASSERT_EQ(b.status, StaticsStatus::kOk);
    const double weight_n = mass_kg * with.gravity_m_per_s2;
    for (int i = 0; i < kNumCables; ++i) {
      const CableSolution &x = a.cables[i], &y = b.cables[i];
      EXPECT_NEAR(x.unstretched_length_m, y.unstretched_length_m,
                  kSolveTol * y.unstretched_length_m);
      EXPECT_NEAR(x.upper_tension_n, y.upper_tension_n, kSolveTol * y.upper_tension_n);
      // The cable above the mass sees the force below it plus the mass's weight.
      Eigen::Vector3d above = x.force_n;
      if (i == cable) above.z() += weight_n;
      EXPECT_NEAR((above - y.force_n).norm(), 0.0, kSolveTol * y.lower_tension_n) << i;
      EXPECT_NEAR(x.lower_tension_n, x.force_n.norm(), kSolveTol * y.lower_tension_n);
    }
    // The sensor under the mass reads less than the uniform cable's lower end.
    EXPECT_LT(a.cables[cable].lower_tension_n, b.cables[cable].lower_tension_n);
  }
}

TEST(StaticsAttachmentsTest, MasslessAttachmentsChangeNothing) {
  CableRobot robot = CableRobot::NominalFast(), cut = robot;
  for (CableProperties& c : cut.cables) c.attachments = {Point(3.0, 0.0), Range(0, 150, 0.0)};
  const StaticsSolution a = Solve(robot, FocalPose(kK2)), b = Solve(cut, FocalPose(kK2));
  ASSERT_EQ(b.status, StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(a.cables[i].lower_tension_n, b.cables[i].lower_tension_n,
                kSolveTol * a.cables[i].lower_tension_n);
  }
}

TEST(StaticsAttachmentsTest, ExactSolvesTheWorkspaceCapWithEquilibriumAndChecks) {
  const CableRobot robot = AsBuiltRobot();
  std::mt19937_64 rng(181);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  StaticsOptions options;
  StaticsSolution s;
  int ok = 0;
  constexpr int kPoses = 200;
  for (int k = 0; k < kPoses; ++k) {
    // Uniform over the focal sphere's cap up to 40 deg off-axis.
    const double theta = std::acos(1.0 - u01(rng) * (1.0 - std::cos(40.0 * M_PI / 180.0)));
    const double phi = 2.0 * M_PI * u01(rng);
    const Eigen::Vector3d p(160.0 * std::sin(theta) * std::cos(phi),
                            160.0 * std::sin(theta) * std::sin(phi),
                            300.0 - 160.0 * std::cos(theta));
    ASSERT_EQ(SolveStatics(robot, FocalPose(p), options, &s), StaticsStatus::kOk)
        << DescribeStatus(s) << " at " << p.transpose();
    EXPECT_LE(s.error_estimate, options.exact_relative_tolerance);
    EXPECT_LT(s.force_residual_n, 1e-6);
    EXPECT_LT(s.end_residual_m, 1e-9);
    EXPECT_FALSE(s.continuation) << "the uniform start should suffice at " << p.transpose();
    ++ok;
  }
  EXPECT_EQ(ok, kPoses);
}

TEST(StaticsAttachmentsTest, AasMethodsRefuseCablesWithAttachments) {
  for (StaticsMethod method : {StaticsMethod::kAas, StaticsMethod::kAasRefined}) {
    const StaticsSolution s = Solve(AsBuiltRobot(), FocalPose(kK2), method);
    EXPECT_EQ(s.status, StaticsStatus::kUnsupportedModel);
    EXPECT_EQ(s.cable, 0);
    EXPECT_EQ(s.cables[0].lower_tension_n, 0.0);
    EXPECT_NE(DescribeStatus(s).find("use exact"), std::string::npos);
  }
}

TEST(StaticsAttachmentsTest, AnAttachmentBeyondTheCableIsAStatusNotANumber) {
  CableRobot robot = CableRobot::NominalFast();
  robot.cables[3].attachments = {Point(4.0, 400.0), Point(900.0, 10.0)};
  const StaticsSolution s = Solve(robot, FocalPose(kK2));
  EXPECT_EQ(s.status, StaticsStatus::kAttachmentBeyondCable);
  EXPECT_EQ(s.cable, 3);
  EXPECT_EQ(s.limit_value, 900.0);
  EXPECT_GT(s.limit, 250.0);
  EXPECT_LT(s.limit, 400.0);
  for (const CableSolution& c : s.cables) EXPECT_EQ(c.lower_tension_n, 0.0);
  EXPECT_NE(DescribeStatus(s).find("cables[3].attachments"), std::string::npos)
      << DescribeStatus(s);
  // A range that starts on the cable may reach beyond it: the lines cover the rest.
  robot.cables[3].attachments = {Range(100.0, 900.0, 1.0)};
  EXPECT_EQ(Solve(robot, FocalPose(kK2)).status, StaticsStatus::kOk);
}

TEST(StaticsAttachmentsTest, ModelFileRoundTripIsBitExact) {
  CableRobot robot = AsBuiltRobot();
  robot.cables[5].attachments.push_back(Point(0.1 + 0.2, 1.0 / 3.0));
  const std::string yaml = CableRobotToYaml(robot, "test");
  CableRobot back;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(yaml, "round.yaml", &back, &error)) << error;
  for (int i = 0; i < kNumCables; ++i) {
    ASSERT_EQ(back.cables[i].attachments.size(), robot.cables[i].attachments.size());
    for (size_t j = 0; j < robot.cables[i].attachments.size(); ++j) {
      const CableAttachment &a = robot.cables[i].attachments[j], &b = back.cables[i].attachments[j];
      EXPECT_EQ(a.kind, b.kind);
      EXPECT_EQ(a.at_m, b.at_m);
      EXPECT_EQ(a.mass_kg, b.mass_kg);
      EXPECT_EQ(a.from_m, b.from_m);
      EXPECT_EQ(a.to_m, b.to_m);
      EXPECT_EQ(a.added_density_kg_per_m, b.added_density_kg_per_m);
    }
  }
  EXPECT_EQ(CableRobotToYaml(back, "test"), yaml);
}

// Each bad attachment: the file, the line and the key path in the message.
TEST(StaticsAttachmentsTest, BadAttachmentsAreNamedByFileLineAndKey) {
  const std::string head = CableRobotToYaml(CableRobot::NominalFast(), "");
  struct Case {
    std::string entry, expect;
  };
  const Case cases[] = {
      {"{at_m: -1, mass_kg: 10}", "cables[0].attachments[0].at_m: must be >= 0"},
      {"{at_m: 1, mass_kg: -10}", "cables[0].attachments[0].mass_kg: must be >= 0"},
      {"{from_m: 5, to_m: 5, added_density_kg_per_m: 1}", "attachments[0].to_m: must be > from_m"},
      {"{from_m: 0, to_m: 5, added_density_kg_per_m: -1}", "added_density_kg_per_m: must be >= 0"},
      {"{at_m: 1}", "a point mass has exactly the keys at_m and mass_kg"},
      {"{at_m: 1, mass_kg: 2, to_m: 3}", "a point mass has exactly"},
      {"{from_m: 1, to_m: 2}", "added weight has exactly"},
      {"{at_m: 1, mass: 2}", "unknown key"},
      {"{at_m: x, mass_kg: 2}", "expected a number"},
  };
  for (const Case& c : cases) {
    std::string yaml = head;
    const std::string anchor = "    linear_density_kg_per_m: 11.718\n";
    const size_t at = yaml.find(anchor) + anchor.size();
    yaml.insert(at, "    attachments:\n      - " + c.entry + "\n");
    CableRobot robot;
    std::string error;
    EXPECT_FALSE(ParseCableRobotYaml(yaml, "m.yaml", &robot, &error)) << c.entry;
    EXPECT_NE(error.find(c.expect), std::string::npos) << error;
    EXPECT_EQ(error.rfind("m.yaml:", 0), 0u) << error;
  }
  std::string yaml = head;
  const std::string anchor = "    linear_density_kg_per_m: 11.718\n";
  std::string many = "    attachments:\n";
  for (int j = 0; j <= kMaxAttachmentsPerCable; ++j) many += "      - {at_m: 1, mass_kg: 1}\n";
  yaml.insert(yaml.find(anchor) + anchor.size(), many);
  CableRobot robot;
  std::string error;
  EXPECT_FALSE(ParseCableRobotYaml(yaml, "m.yaml", &robot, &error));
  EXPECT_NE(error.find("at most 8 per cable"), std::string::npos) << error;
}

// The calibration differentiates the tensions through the chain (the exact method's
// Newton step in Jet arithmetic, statics_core.h): against central differences in each
// attachment's value, and in the cabin's mass-centre z.
TEST(StaticsAttachmentsTest, JetTensionsMatchCentralDifferencesThroughTheChain) {
  using Jet = ceres::Jet<double, 3>;
  const CableRobot robot = AsBuiltRobot();
  const StaticsParameters<double> p0 = MakeStaticsParameters(robot);
  const Pose pose = FocalPose(kK2);
  const StaticsOptions options = ModelFitStaticsOptions(StaticsMethod::kExact);
  // Steps and tolerance: relative 1e-5 of the tensions' derivatives, well above the
  // solves' 1e-12 over steps of ~1e-3 relative.
  const double steps[3] = {1.0, 1e-2, 1e-3};  // kg, kg/m, m
  constexpr double kTol = 1e-5;
  StaticsParameters<Jet> pj;
  CastParametersInto(p0, &pj);
  // Parameters: cable 2's point mass, cable 5's added density, the mass centre's z.
  pj.chain[1].value[0].v[0] = 1.0;
  pj.chain[4].value[1].v[1] = 1.0;
  pj.mass_centre_cabin_m[2].v[2] = 1.0;
  std::array<Jet, kNumCables> tj;
  ASSERT_EQ(ModelLowerTensions(pj, pose, options, &tj), StaticsStatus::kOk);
  for (int k = 0; k < 3; ++k) {
    StaticsParameters<double> up = p0, dn = p0;
    double* u = k == 0   ? &up.chain[1].value[0]
                : k == 1 ? &up.chain[4].value[1]
                         : &up.mass_centre_cabin_m[2];
    double* d = k == 0   ? &dn.chain[1].value[0]
                : k == 1 ? &dn.chain[4].value[1]
                         : &dn.mass_centre_cabin_m[2];
    *u += steps[k];
    *d -= steps[k];
    std::array<double, kNumCables> tu, td;
    ASSERT_EQ(ModelLowerTensions(up, pose, options, &tu), StaticsStatus::kOk);
    ASSERT_EQ(ModelLowerTensions(dn, pose, options, &td), StaticsStatus::kOk);
    double largest = 0.0;
    for (int i = 0; i < kNumCables; ++i) largest = std::max(largest, std::abs(tj[i].v[k]));
    ASSERT_GT(largest, 0.0) << "parameter " << k << " moves no tension";
    for (int i = 0; i < kNumCables; ++i) {
      const double numeric = (tu[i] - td[i]) / (2.0 * steps[k]);
      EXPECT_NEAR(tj[i].v[k], numeric, kTol * largest) << "parameter " << k << " cable " << i;
    }
  }
}

}  // namespace
}  // namespace fastcal
