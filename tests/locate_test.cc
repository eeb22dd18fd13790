// Tests of the forward statics (locate.h): round trips through the inverse statics over
// the focal-sphere cap, at the workspace's edge and with cables as built; warm starts along
// a trajectory; the Jacobian and the stiffness against central differences of independently
// computed residuals; physical identities (a symmetric stiffness at an equilibrium, D
// symmetric); an unstable, non-unique equilibrium; bad input and lengths no equilibrium
// holds; the fit of measured lengths, attitude and tensions.
#include "fastcal/locate.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "fastcal/internal/forward_statics.h"
#include "fastcal/trajectory.h"

namespace fastcal {

void PrintTo(StaticsStatus status, std::ostream* os) { *os << StaticsStatusName(status); }

namespace {

using Lengths = std::array<double, kNumCables>;

// The round trip: locate gives back the pose solve was asked for, to this (m, the
// anchors' largest move). Both solve to ~1e-13 m; the floor is rounding.
constexpr double kRoundTripTolM = 1e-9;

Pose FocalPose(const Eigen::Vector3d& position_m) {
  Pose pose;
  pose.position_m = position_m;
  pose.rotation = FocalAttitude(position_m, FocalAttitudeLaw());
  return pose;
}

// The inverse statics' lengths at a pose (exact); false where it has no ok answer.
bool LengthsAt(const CableRobot& robot, const Pose& pose, Lengths* s0,
               StaticsSolution* solution = nullptr) {
  StaticsSolution local;
  StaticsSolution* s = solution != nullptr ? solution : &local;
  if (SolveStatics(robot, pose, StaticsOptions(), s) != StaticsStatus::kOk) return false;
  for (int i = 0; i < kNumCables; ++i) (*s0)[i] = s->cables[i].unstretched_length_m;
  return true;
}

// The anchors' largest move between two poses, computed here.
double AnchorsMoveM(const CableRobot& robot, const Pose& a, const Pose& b) {
  double largest = (a.position_m - b.position_m).norm();
  for (const Eigen::Vector3d& anchor : robot.anchor_points_cabin_m) {
    largest = std::max(
        largest,
        ((a.rotation * anchor + a.position_m) - (b.rotation * anchor + b.position_m)).norm());
  }
  return largest;
}

LocateOptions NoSearch() {
  LocateOptions o;
  o.search_radius_m = 0.0;
  return o;
}

// The focal-sphere cap up to 40 deg off axis every 10 deg x 30 deg, on the sphere and 3 m
// inside and outside it (docs/model.md "Workspace").
std::vector<Pose> CapPoses() {
  std::vector<Pose> poses;
  for (double radius : {160.0, 157.0, 163.0}) {
    for (int theta_deg = 0; theta_deg <= 40; theta_deg += 10) {
      for (int phi_deg = 0; phi_deg < 360; phi_deg += 30) {
        const double t = theta_deg * M_PI / 180, p = phi_deg * M_PI / 180;
        poses.push_back(
            FocalPose(Eigen::Vector3d(0, 0, 300) +
                      radius * Eigen::Vector3d(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p),
                                               -std::cos(t))));
        if (theta_deg == 0) break;
      }
    }
  }
  return poses;
}

// Locate at the inverse statics' lengths of each pose gives the pose back, with the same
// tensions, checked and stable.
void ExpectRoundTrips(const CableRobot& robot, const std::vector<Pose>& poses, int* solved) {
  constexpr double kTensionRelTol = 1e-9;
  *solved = 0;
  for (size_t n = 0; n < poses.size(); ++n) {
    Lengths s0;
    StaticsSolution inverse;
    if (!LengthsAt(robot, poses[n], &s0, &inverse)) continue;
    ++*solved;
    LocateSolution s;
    ASSERT_EQ(Locate(robot, s0, NoSearch(), &s), StaticsStatus::kOk)
        << "pose " << n << ": " << DescribeLocateStatus(s);
    EXPECT_LE(AnchorsMoveM(robot, s.pose, poses[n]), kRoundTripTolM) << "pose " << n;
    EXPECT_EQ(s.stability, Stability::kStable) << "pose " << n;
    EXPECT_LE(s.error_estimate_m, LocateOptions().tolerance_m) << "pose " << n;
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(s.statics.cables[i].lower_tension_n, inverse.cables[i].lower_tension_n,
                  kTensionRelTol * inverse.cables[i].lower_tension_n)
          << "pose " << n << " cable " << i + 1;
      EXPECT_EQ(s.statics.cables[i].unstretched_length_m, s0[i]);
    }
  }
}

TEST(LocateTest, InvertsSolveOverTheCap) {
  const std::vector<Pose> poses = CapPoses();
  int solved = 0;
  ExpectRoundTrips(CableRobot::NominalFast(), poses, &solved);
  EXPECT_EQ(solved, static_cast<int>(poses.size()));
}

TEST(LocateTest, InvertsSolveAtTheWorkspacesEdge) {
  // Issue 9's sweep: 45 deg off axis, +-5 m off the sphere, extra rotations of 2-5 deg;
  // poses the inverse statics refuses (out of the model's range) have no lengths to try.
  constexpr int kPoses = 300;
  constexpr int kMinSolved = 250;
  std::vector<Pose> poses;
  std::string error;
  ASSERT_TRUE(RandomPosesAroundFocalLaw(EdgeSweepSpec(kPoses, 20260101), &poses, &error)) << error;
  int solved = 0;
  ExpectRoundTrips(CableRobot::NominalFast(), poses, &solved);
  EXPECT_GE(solved, kMinSolved);
}

CableRobot AsBuiltModel() {
  const char* dir = std::getenv("FASTCAL_SOURCE_DIR") != nullptr ? std::getenv("FASTCAL_SOURCE_DIR")
                                                                 : FASTCAL_TEST_SOURCE_DIR;
  CableRobot robot;
  std::string error;
  EXPECT_TRUE(LoadCableRobot(std::string(dir) + "/calibration_data/as_built.yaml", &robot, &error))
      << error;
  return robot;
}

TEST(LocateTest, InvertsSolveWithCablesAsBuilt) {
  const CableRobot robot = AsBuiltModel();
  ASSERT_TRUE(robot.HasAttachments());
  const std::vector<Pose> poses = CapPoses();
  int solved = 0;
  ExpectRoundTrips(robot, poses, &solved);
  EXPECT_EQ(solved, static_cast<int>(poses.size()));
  // The attachments matter: the uniform model puts the cabin elsewhere for these lengths
  // (0.46-0.67 m over the cap's grid, docs/model.md).
  constexpr double kMinShiftM = 0.3;
  Lengths s0;
  ASSERT_TRUE(LengthsAt(robot, poses[5], &s0));
  LocateSolution uniform;
  ASSERT_EQ(Locate(CableRobot::NominalFast(), s0, NoSearch(), &uniform), StaticsStatus::kOk);
  EXPECT_GT(AnchorsMoveM(robot, uniform.pose, poses[5]), kMinShiftM);
}

TEST(LocateTest, WarmAlongAHalfCircleNeedsOneOrTwoSteps) {
  // The paper's half circle of radius 50 m at z = 150 m, 101 nodes: from the previous
  // answer moved along its sensitivity, each node costs at most two Newton steps.
  constexpr int kNodes = 101;
  constexpr int kMaxWarmIterations = 2;
  const CableRobot robot = CableRobot::NominalFast();
  LocateOptions options = NoSearch();
  options.warm_start = true;
  LocateSolution s;
  for (int n = 0; n < kNodes; ++n) {
    const double t = M_PI * n / (kNodes - 1);
    const Pose pose = FocalPose(Eigen::Vector3d(50 * std::cos(t), 50 * std::sin(t), 150));
    Lengths s0;
    ASSERT_TRUE(LengthsAt(robot, pose, &s0));
    ASSERT_EQ(Locate(robot, s0, options, &s), StaticsStatus::kOk) << n;
    EXPECT_LE(AnchorsMoveM(robot, s.pose, pose), kRoundTripTolM) << n;
    EXPECT_EQ(s.continuation, n == 0) << n;
    if (n > 0) {
      EXPECT_LE(s.iterations, kMaxWarmIterations) << n;
    }
  }
}

// A cabin whose mass centre sits 12 m above its anchors' plane: at K1's lengths it hangs
// level only in an unstable equilibrium (its tilts have negative stiffness), and tilted
// equilibria of the same lengths lie nearby. The nominal cabin is stable and alone.
TEST(LocateTest, TopHeavyCabinIsReportedUnstableAndNotUnique) {
  CableRobot robot = CableRobot::NominalFast();
  robot.mass_centre_cabin_m = Eigen::Vector3d(0, 0, 12);
  Pose k1;
  k1.position_m = Eigen::Vector3d(0, 0, 140);
  Lengths s0;
  ASSERT_TRUE(LengthsAt(robot, k1, &s0));
  LocateSolution s;
  ASSERT_EQ(Locate(robot, s0, LocateOptions(), &s), StaticsStatus::kOk) << DescribeLocateStatus(s);
  EXPECT_LE(AnchorsMoveM(robot, s.pose, k1), kRoundTripTolM);
  EXPECT_EQ(s.stability, Stability::kUnstable);
  EXPECT_EQ(s.unstable_modes, 2);  // the two tilts
  EXPECT_LT(s.min_stiffness_n_per_m, 0.0);
  EXPECT_GT(s.other_equilibria, 0);
  EXPECT_GT(s.nearest_other.distance_m, LocateOptions().distinct_m);
  const std::string text = DescribeLocateStatus(s);
  EXPECT_NE(text.find("unstable"), std::string::npos) << text;
  EXPECT_NE(text.find("not unique"), std::string::npos) << text;
  // The other equilibrium is one: its lengths are these.
  Lengths other;
  ASSERT_TRUE(LengthsAt(robot, s.nearest_other.pose, &other));
  constexpr double kLengthTolM = 1e-9;
  for (int i = 0; i < kNumCables; ++i) EXPECT_NEAR(other[i], s0[i], kLengthTolM) << i;

  const CableRobot nominal = CableRobot::NominalFast();
  ASSERT_TRUE(LengthsAt(nominal, k1, &s0));
  ASSERT_EQ(Locate(nominal, s0, LocateOptions(), &s), StaticsStatus::kOk);
  EXPECT_EQ(s.stability, Stability::kStable);
  EXPECT_TRUE(s.searched);
  EXPECT_EQ(s.other_equilibria, 0);
  EXPECT_EQ(DescribeLocateStatus(s), "ok, stable");
}

// A state near an equilibrium: a pose of the cap, each cable closed there (uniform
// catenary), the forces then moved by up to 1% at random.
internal::ForwardState RandomState(const StaticsParameters<double>& p, std::mt19937_64* rng,
                                   Lengths* s0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double theta = 0.6 * std::abs(u(*rng)), phi = M_PI * u(*rng);
  internal::ForwardState x;
  x.pose = FocalPose(Eigen::Vector3d(0, 0, 300) +
                     160 * Eigen::Vector3d(std::sin(theta) * std::cos(phi),
                                           std::sin(theta) * std::sin(phi), -std::cos(theta)));
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d chord =
        p.tower_top_m[i] - x.pose.position_m - x.pose.rotation * p.anchor_cabin_m[i];
    (*s0)[i] = chord.norm() * (1.0 + 0.005 * u(*rng));
  }
  EXPECT_TRUE(internal::ClosedForcesAt(p, *s0, x.pose, &x.force_n));
  for (Eigen::Vector3d& f : x.force_n) {
    f += 0.01 * f.norm() * Eigen::Vector3d(u(*rng), u(*rng), u(*rng));
  }
  return x;
}

TEST(LocateTest, ForwardJacobianMatchesCentralDifferences) {
  constexpr int kStates = 20;
  constexpr double kForceStepN = 1.0;  // forces ~1e5 N
  constexpr double kPoseStep = 1e-5;   // m and rad
  constexpr double kRelTol = 1e-6;     // of the column's largest entry
  const StaticsParameters<double> p = MakeStaticsParameters(CableRobot::NominalFast());
  const internal::ForwardScales scales = internal::MakeForwardScales(p);
  std::mt19937_64 rng(31);
  for (int n = 0; n < kStates; ++n) {
    Lengths s0;
    const internal::ForwardState x = RandomState(p, &rng, &s0);
    internal::ForwardLinearisation lin;
    ASSERT_TRUE(internal::LineariseForward(p, scales, s0, x, &lin));
    const Eigen::Matrix<double, 24, 24> j = internal::ForwardJacobian(p, x, lin);
    for (int c = 0; c < 24; ++c) {
      auto residuals_at = [&](double h) {
        internal::ForwardState y = x;
        if (c < 18) {
          y.force_n[c / 3][c % 3] += h * kForceStepN;
        } else {
          internal::Vector6d dx = internal::Vector6d::Zero();
          dx[c - 18] = h * kPoseStep;
          y = internal::MoveState(x, dx, internal::ZeroForces(), 1.0);
        }
        internal::ForwardLinearisation l;
        EXPECT_TRUE(internal::LineariseForward(p, scales, s0, y, &l));
        return internal::ForwardResiduals(l);
      };
      const double step = c < 18 ? kForceStepN : kPoseStep;
      const Eigen::Matrix<double, 24, 1> numeric =
          (residuals_at(1) - residuals_at(-1)) / (2 * step);
      const double scale = std::max(numeric.cwiseAbs().maxCoeff(), j.col(c).cwiseAbs().maxCoeff());
      EXPECT_LE((numeric - j.col(c)).cwiseAbs().maxCoeff(), kRelTol * scale)
          << "state " << n << " column " << c;
    }
    // Each cable's D is symmetric (dZ/dFl = -dL/dFz) and D^-1 its inverse.
    constexpr double kIdentityTol = 1e-10;
    for (int i = 0; i < kNumCables; ++i) {
      const Eigen::Matrix3d& d = lin.ends[i].d;
      EXPECT_LE((d - d.transpose()).norm(), kIdentityTol * d.norm()) << i;
      EXPECT_LE((d * lin.ends[i].d_inverse - Eigen::Matrix3d::Identity()).norm(), kIdentityTol)
          << i;
    }
  }
}

// K against the wrench of cables closed anew at displaced poses (each cable's catenary
// solved by catenary.h at its chord, not through D^-1), and symmetric at the equilibrium:
// the Hessian of a potential.
TEST(LocateTest, StiffnessIsTheWrenchDerivativeAndSymmetricAtTheEquilibrium) {
  constexpr double kPoseStep = 1e-4;  // m and rad
  constexpr double kRelTol = 1e-5;    // of K's largest entry in the row
  constexpr double kSymmetryTol = 1e-9;
  const CableRobot robot = CableRobot::NominalFast();
  const StaticsParameters<double> p = MakeStaticsParameters(robot);
  const internal::ForwardScales scales = internal::MakeForwardScales(p);
  Lengths s0;
  ASSERT_TRUE(LengthsAt(robot, FocalPose(Eigen::Vector3d(42.65, 33.73, 149.52)), &s0));
  LocateSolution s;
  ASSERT_EQ(Locate(robot, s0, NoSearch(), &s), StaticsStatus::kOk);
  internal::ForwardState x{s.pose, s.force_n};
  internal::ForwardLinearisation lin;
  ASSERT_TRUE(internal::LineariseForward(p, scales, s0, x, &lin));
  const internal::Matrix6d& k = lin.stiffness;
  for (int c = 0; c < 6; ++c) {
    auto wrench_at = [&](double h) {
      internal::Vector6d dx = internal::Vector6d::Zero();
      dx[c] = h * kPoseStep;
      internal::ForwardState y = internal::MoveState(x, dx, internal::ZeroForces(), 1.0);
      EXPECT_TRUE(internal::ClosedForcesAt(p, s0, y.pose, &y.force_n));
      internal::ForwardLinearisation l;
      EXPECT_TRUE(internal::LineariseForward(p, scales, s0, y, &l));
      return internal::Vector6d(l.wrench);
    };
    const internal::Vector6d numeric = (wrench_at(1) - wrench_at(-1)) / (2 * kPoseStep);
    for (int r = 0; r < 6; ++r) {
      EXPECT_NEAR(numeric[r], k(r, c), kRelTol * k.row(r).cwiseAbs().maxCoeff())
          << "row " << r << " column " << c;
    }
  }
  EXPECT_LE((k - k.transpose()).norm(), kSymmetryTol * k.norm());
  // And the scaled, symmetrised Hessian Locate reports is positive definite here.
  EXPECT_GT(s.min_stiffness_n_per_m, 0.0);
}

TEST(LocateTest, SensitivityToTheLengthsMatchesCentralDifferences) {
  constexpr double kLengthStepM = 1e-4;
  constexpr double kRelTol = 1e-6;  // of the column's largest entry
  const CableRobot robot = CableRobot::NominalFast();
  Lengths s0;
  ASSERT_TRUE(LengthsAt(robot, FocalPose(Eigen::Vector3d(-60, 25, 160)), &s0));
  LocateSolution s;
  ASSERT_EQ(Locate(robot, s0, NoSearch(), &s), StaticsStatus::kOk);
  for (int j = 0; j < kNumCables; ++j) {
    LocateSolution plus, minus;
    Lengths a = s0, b = s0;
    a[j] += kLengthStepM;
    b[j] -= kLengthStepM;
    ASSERT_EQ(Locate(robot, a, NoSearch(), &plus), StaticsStatus::kOk);
    ASSERT_EQ(Locate(robot, b, NoSearch(), &minus), StaticsStatus::kOk);
    internal::Vector6d numeric;
    numeric.head<3>() = (plus.pose.position_m - minus.pose.position_m) / (2 * kLengthStepM);
    numeric.tail<3>() =
        internal::RotationDifference(plus.pose.rotation, minus.pose.rotation) / (2 * kLengthStepM);
    const double scale = s.pose_per_length.col(j).cwiseAbs().maxCoeff();
    EXPECT_LE((numeric - s.pose_per_length.col(j)).cwiseAbs().maxCoeff(), kRelTol * scale) << j;
  }
  // Paying out every cable lowers the cabin.
  EXPECT_GT(s.pose_per_length.row(2).sum() * -1.0, 0.0);
}

TEST(LocateTest, BadInputIsAStatusWithNoNumbers) {
  const CableRobot robot = CableRobot::NominalFast();
  Lengths s0;
  ASSERT_TRUE(LengthsAt(robot, FocalPose(Eigen::Vector3d(0, 0, 140)), &s0));
  for (double bad : {std::nan(""), 0.0, -300.0, HUGE_VAL}) {
    Lengths l = s0;
    l[3] = bad;
    LocateSolution s;
    EXPECT_EQ(Locate(robot, l, LocateOptions(), &s), StaticsStatus::kInvalidInput) << bad;
    EXPECT_EQ(s.pose.position_m, Eigen::Vector3d::Zero());
    EXPECT_EQ(s.statics.cables[0].lower_tension_n, 0.0);
    EXPECT_EQ(s.stability, Stability::kUnknown);
    EXPECT_NE(DescribeLocateStatus(s).find("invalid input"), std::string::npos);
  }
  LocateOptions bad;
  bad.tolerance_m = 0.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("tolerance_m"), std::string::npos) << error;
  LocateSolution s;
  EXPECT_EQ(Locate(robot, s0, bad, &s), StaticsStatus::kInvalidInput);
  bad = LocateOptions();
  bad.statics.max_strain = -1.0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("statics: max_strain"), std::string::npos) << error;
  bad = LocateOptions();
  bad.search_radius_m = -1.0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("search_radius_m"), std::string::npos) << error;
  EXPECT_EQ(Locate(CableRobot(), s0, LocateOptions(), &s), StaticsStatus::kInvalidInput);
}

// Lengths no FAST pose has: every cable 250 m long holds the cabin only by stretching
// them 17%; 400 m lets it sink into the reflector; 200 and 400 m alternately stretch
// three cables by tens of percent. Each says why, with no numbers.
TEST(LocateTest, LengthsOutsideTheModelsRangeSayWhy) {
  const CableRobot robot = CableRobot::NominalFast();
  LocateSolution s;
  Lengths l;
  l.fill(250.0);
  EXPECT_EQ(Locate(robot, l, LocateOptions(), &s), StaticsStatus::kOverstretchedCable);
  EXPECT_NE(DescribeLocateStatus(s).find("stretched beyond the model's elastic range"),
            std::string::npos)
      << DescribeLocateStatus(s);
  EXPECT_EQ(s.pose.position_m, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.statics.cables[2].lower_tension_n, 0.0);
  l.fill(400.0);
  EXPECT_EQ(Locate(robot, l, LocateOptions(), &s), StaticsStatus::kReflectorContact);
  EXPECT_NE(DescribeLocateStatus(s).find("through the reflector"), std::string::npos)
      << DescribeLocateStatus(s);
  // Alternately 200 and 400 m: cables stretched by tens of percent, where rounding alone
  // lifts the check's error estimate above 1e-12; the range is the reason given.
  l = {200.0, 400.0, 200.0, 400.0, 200.0, 400.0};
  EXPECT_EQ(Locate(robot, l, LocateOptions(), &s), StaticsStatus::kOverstretchedCable)
      << DescribeLocateStatus(s);
  EXPECT_EQ(s.pose.position_m, Eigen::Vector3d::Zero());
}

// The fit: measurements made by the inverse statics at a pose give the pose back with no
// misfit, whatever is measured.
TEST(LocateTest, FitOfConsistentMeasurementsIsThePose) {
  constexpr double kPoseTolM = 1e-7;
  constexpr double kMaxChi2 = 1e-10;
  CableRobot robot = CableRobot::NominalFast();
  robot.cables[2].sensor_gain = 1.02;
  robot.cables[4].sensor_bias_n = -1500.0;
  robot.cables[1].length_offset_m = 0.35;  // the encoders read s0 + offset
  robot.cables[5].length_offset_m = -1.2;
  const Pose pose = FocalPose(Eigen::Vector3d(42.65, 33.73, 149.52));
  StaticsSolution inverse;
  LocateMeasurement m;
  ASSERT_TRUE(LengthsAt(robot, pose, &m.length_m, &inverse));
  for (int i = 0; i < kNumCables; ++i)
    m.length_m[i] = robot.cables[i].EncoderReadingM(m.length_m[i]);
  m.has_attitude = true;
  m.rotation = pose.rotation;
  m.has_tensions = true;
  for (int i = 0; i < kNumCables; ++i) {
    m.tension_n[i] = robot.cables[i].SensorReadingN(inverse.cables[i].lower_tension_n);
  }
  LocateSolution s;
  ASSERT_EQ(LocateFromMeasurements(robot, m, LocateNoise(), LocateOptions(), &s),
            StaticsStatus::kOk)
      << DescribeLocateStatus(s);
  EXPECT_TRUE(s.fit.fitted);
  EXPECT_EQ(s.fit.readings, 15);
  EXPECT_LE(s.fit.chi2, kMaxChi2);
  EXPECT_LE(AnchorsMoveM(robot, s.pose, pose), kPoseTolM);
  EXPECT_EQ(s.stability, Stability::kStable);
  // Lengths alone: the covariance is sigma_L^2 P P^T.
  m.has_attitude = m.has_tensions = false;
  LocateNoise noise;
  noise.length_sigma_m = 0.002;
  ASSERT_EQ(LocateFromMeasurements(robot, m, noise, LocateOptions(), &s), StaticsStatus::kOk);
  EXPECT_FALSE(s.fit.fitted);
  const Eigen::Matrix<double, 6, 6> expected = noise.length_sigma_m * noise.length_sigma_m *
                                               s.pose_per_length * s.pose_per_length.transpose();
  EXPECT_LE((s.fit.covariance - expected).norm(), 1e-12 * expected.norm());
}

// The model's readings at a pose (the inverse statics), whitened as docs/model.md says,
// computed here: the fit's cost, independently of its Jacobian. The tensions' sigmas are
// given (the fit's, from its predicted readings: frozen, as in each of its steps).
double CostAt(const CableRobot& robot, const Pose& pose, const LocateMeasurement& m,
              const LocateNoise& noise, const Lengths& tension_sigma_n) {
  StaticsSolution s;
  EXPECT_EQ(SolveStatics(robot, pose, StaticsOptions(), &s), StaticsStatus::kOk);
  double cost = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    const double dl = (s.cables[i].unstretched_length_m - m.length_m[i]) / noise.length_sigma_m;
    const double reading = robot.cables[i].SensorReadingN(s.cables[i].lower_tension_n);
    const double dt = (reading - m.tension_n[i]) / tension_sigma_n[i];
    cost += dl * dl + dt * dt;
  }
  const Eigen::AngleAxisd turn(pose.rotation * m.rotation.transpose());
  const double da = turn.angle() / (noise.attitude_sigma_deg * M_PI / 180);
  return cost + da * da;
}

// With noisy readings the fitted pose is the cost's minimum: its numerical gradient there
// vanishes against its curvature. A wrong Jacobian would stop Gauss-Newton elsewhere.
TEST(LocateTest, FitStopsAtTheMinimumOfTheWhitenedCost) {
  constexpr double kPoseStep = 1e-4;     // m, rad
  constexpr double kGradientTol = 1e-3;  // of the curvature times the step
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(Eigen::Vector3d(-35, -60, 155));
  StaticsSolution inverse;
  LocateMeasurement m;
  ASSERT_TRUE(LengthsAt(robot, pose, &m.length_m, &inverse));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  LocateNoise noise;
  noise.length_sigma_m = 0.005;
  noise.attitude_sigma_deg = 0.02;
  for (int i = 0; i < kNumCables; ++i) {
    m.length_m[i] += noise.length_sigma_m * gauss(rng);
    m.tension_n[i] = inverse.cables[i].lower_tension_n * (1 + 0.03 * gauss(rng));
  }
  m.has_tensions = m.has_attitude = true;
  const Eigen::Vector3d tilt(gauss(rng), gauss(rng), gauss(rng));
  m.rotation =
      Eigen::AngleAxisd(noise.attitude_sigma_deg * M_PI / 180 * tilt.norm(), tilt.normalized()) *
      pose.rotation;
  LocateSolution s;
  ASSERT_EQ(LocateFromMeasurements(robot, m, noise, LocateOptions(), &s), StaticsStatus::kOk)
      << DescribeLocateStatus(s);
  Lengths sigma_n;
  for (int i = 0; i < kNumCables; ++i) {
    sigma_n[i] = noise.tension_sigma_percent / 100 *
                 robot.cables[i].SensorReadingN(s.statics.cables[i].lower_tension_n);
  }
  EXPECT_NEAR(CostAt(robot, s.pose, m, noise, sigma_n), s.fit.chi2, 1e-6 * s.fit.chi2);
  for (int c = 0; c < 6; ++c) {
    double cost[3];
    for (int h = -1; h <= 1; ++h) {
      internal::Vector6d dx = internal::Vector6d::Zero();
      dx[c] = h * kPoseStep;
      internal::ForwardState x{s.pose, internal::ZeroForces()};
      cost[h + 1] =
          CostAt(robot, internal::MoveState(x, dx, x.force_n, 1.0).pose, m, noise, sigma_n);
    }
    const double slope = (cost[2] - cost[0]) / 2, curvature = cost[2] - 2 * cost[1] + cost[0];
    EXPECT_GT(curvature, 0.0) << c;
    EXPECT_LE(std::abs(slope), kGradientTol * curvature) << "axis " << c;
  }
  // The measured tensions and attitude narrow the pose: the fit's sigmas are below the
  // lengths' alone.
  LocateMeasurement lengths_only = m;
  lengths_only.has_tensions = lengths_only.has_attitude = false;
  LocateSolution alone;
  ASSERT_EQ(LocateFromMeasurements(robot, lengths_only, noise, LocateOptions(), &alone),
            StaticsStatus::kOk);
  for (int k = 0; k < 6; ++k) EXPECT_LT(s.fit.covariance(k, k), alone.fit.covariance(k, k)) << k;
}

TEST(LocateTest, RotationDifferenceDerivativeMatchesCentralDifferences) {
  constexpr double kStep = 1e-6;  // rad
  constexpr double kTol = 1e-8;
  const Eigen::Matrix3d from = RotationFromRpyDeg(10.0, 20.0, -30.0);
  for (double angle_deg : {1e-6, 3.0, 40.0, 150.0}) {
    const Eigen::Matrix3d to =
        Eigen::AngleAxisd(angle_deg * M_PI / 180, Eigen::Vector3d(1, -2, 0.5).normalized()) * from;
    const Eigen::Matrix3d j = internal::InverseLeftJacobian(internal::RotationDifference(to, from));
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(c);
      const Eigen::Vector3d numeric =
          (internal::RotationDifference(Eigen::AngleAxisd(kStep, axis) * to, from) -
           internal::RotationDifference(Eigen::AngleAxisd(-kStep, axis) * to, from)) /
          (2 * kStep);
      EXPECT_LE((numeric - j.col(c)).cwiseAbs().maxCoeff(), kTol) << angle_deg << " deg, " << c;
    }
  }
}

TEST(LocateTest, RpyDerivativeMatchesCentralDifferences) {
  constexpr double kStep = 1e-6;  // rad
  constexpr double kTol = 1e-6;   // deg/rad
  const Eigen::Matrix3d r = RotationFromRpyDeg(3.0, -7.0, 40.0);
  const Eigen::Matrix3d d = RpyDegPerRotationVector(r);
  for (int c = 0; c < 3; ++c) {
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(c);
    const Eigen::Vector3d plus =
        RpyDegFromRotation(Eigen::AngleAxisd(kStep, axis).toRotationMatrix() * r);
    const Eigen::Vector3d minus =
        RpyDegFromRotation(Eigen::AngleAxisd(-kStep, axis).toRotationMatrix() * r);
    EXPECT_LE(((plus - minus) / (2 * kStep) - d.col(c)).cwiseAbs().maxCoeff(), kTol) << c;
  }
}

}  // namespace
}  // namespace fastcal
