// Tests of the vibrations (modes.h) against closed forms and against the statics: a taut
// string's harmonics; Irvine's first symmetric in-plane mode of a sagging cable; the cabin
// on massless cables against the stiffness of the statics by central differences of the
// equilibrium at fixed unstretched lengths (computed here from the catenary alone);
// convergence in the number of segments; the 3-fold symmetry of the zenith pose's modes.
#include "fastcal/modes.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fastcal/catenary.h"
#include "fastcal/modes_map.h"

namespace fastcal {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// A pose of the focal law `zenith_deg` off axis at azimuth `azimuth_deg` on the focal
// sphere (radius 160 m about (0, 0, 300) m, docs/model.md).
Pose FocalPose(double zenith_deg, double azimuth_deg) {
  const double z = zenith_deg * M_PI / 180.0, a = azimuth_deg * M_PI / 180.0;
  Pose pose;
  pose.position_m =
      Eigen::Vector3d(0.0, 0.0, 300.0) +
      160.0 * Eigen::Vector3d(std::sin(z) * std::cos(a), std::sin(z) * std::sin(a), -std::cos(z));
  pose.rotation = FocalAttitude(pose.position_m, FocalAttitudeLaw());
  return pose;
}

// A level cable, 100 m span, whose horizontal force is `fl_n`: the unstretched length
// that gives it, solved here.
FixedCable LevelCable(double fl_n, double density_kg_per_m, double ea_n) {
  FixedCable cable;
  cable.span_m = 100.0;
  cable.rise_m = 0.0;
  cable.ea_n = ea_n;
  cable.linear_density_kg_per_m = density_kg_per_m;
  CatenaryCurvePoint point;
  int iterations = 0;
  EXPECT_EQ(SolveCatenaryLengthDouble(cable.span_m, 0.0, fl_n, ea_n,
                                      density_kg_per_m * cable.gravity_m_per_s2,
                                      CatenarySolverOptions(), nullptr, &point, &iterations),
            CatenaryStatus::kOk);
  cable.unstretched_length_m = point.s0_m;
  return cable;
}

std::vector<CableMode> CableModes(const FixedCable& cable, int segments, int count) {
  ModesOptions options;
  options.segments = segments;
  options.modes = count;
  std::vector<CableMode> modes;
  std::string error;
  EXPECT_TRUE(ComputeFixedCableModes(cable, options, &modes, &error)) << error;
  return modes;
}

// A taut string (1 kg/m at 1 MN: sag 1.2 cm over 100 m) vibrates out of its plane at
// f_n = (n / 2L) sqrt(T / mu), mu its mass per stretched length. The chain of N segments
// has exactly f_n (2N / n pi) sin(n pi / 2N), whose difference from the continuum is
// (n pi / N)^2 / 24 relative: within kChainTol of it (the sag's and the stretch's
// effect on the tension, ~1e-6); within that bound plus kChainTol of the continuum.
TEST(FixedCableModes, TautStringHarmonics) {
  constexpr double kChainTol = 1e-5;
  constexpr int kSegments = 40;
  const FixedCable cable = LevelCable(1e6, 1.0, 1e10);
  const double mu = cable.linear_density_kg_per_m * cable.unstretched_length_m / cable.span_m;
  const double tension_n = 1e6;
  std::vector<CableMode> out_of_plane;
  for (const CableMode& m : CableModes(cable, kSegments, 12)) {
    if (m.in_plane_share < 1e-3) out_of_plane.push_back(m);
  }
  ASSERT_GE(out_of_plane.size(), 4u);
  for (int n = 1; n <= 4; ++n) {
    const double string_hz = n / (2.0 * cable.span_m) * std::sqrt(tension_n / mu);
    const double x = n * M_PI / (2.0 * kSegments);
    const double chain_hz = string_hz * std::sin(x) / x;
    EXPECT_NEAR(out_of_plane[n - 1].frequency_hz / chain_hz, 1.0, kChainTol) << "n = " << n;
    const double bound = std::pow(n * M_PI / kSegments, 2) / 24.0 + kChainTol;
    EXPECT_NEAR(out_of_plane[n - 1].frequency_hz / string_hz, 1.0, bound) << "n = " << n;
  }
}

// Irvine's sag parameter and his first symmetric in-plane mode of a level cable (Irvine
// and Caughey 1974; "Cable Structures" sect. 3.2): with H the horizontal force, m the
// mass per length, d = m g L^2 / 8H the sag, L_e = L (1 + 8 (d/L)^2) and
//   lambda^2 = (8 d / L)^2 L / (H L_e / EA),
// omega = beta sqrt(H/m) / L where tan(beta/2) = beta/2 - (4 / lambda^2) (beta/2)^3.
double IrvineSymmetricHz(double fl_n, double density_kg_per_m, double ea_n, double span_m) {
  const double m = density_kg_per_m, g = 9.8, l = span_m;
  const double d = m * g * l * l / (8.0 * fl_n);
  const double le = l * (1.0 + 8.0 * (d / l) * (d / l));
  const double lambda2 = std::pow(8.0 * d / l, 2) * l / (fl_n * le / ea_n);
  // The root in (pi, 3 pi) by bisection: the residual changes sign there once.
  auto residual = [&](double b) {
    const double h = 0.5 * b;
    return std::tan(h) - h + 4.0 / lambda2 * h * h * h;
  };
  double lo = M_PI * 1.000001, hi = 3.0 * M_PI * 0.999999;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (residual(lo) * residual(mid) <= 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi) * std::sqrt(fl_n / m) / l / kTwoPi;
}

// A level 100 m cable, 10 kg/m, EA 1e8 N at H = 78 kN: sag 1.56 m (d/L = 1/64) and
// lambda^2 ~ 20, where the first symmetric in-plane mode lies well between the string's
// first (lambda^2 -> 0) and its crossover (lambda^2 = 4 pi^2). Measured: the chain
// (N = 80) within 4e-5 of Irvine's symmetric mode. His first antisymmetric in-plane mode
// is the string's second harmonic, which stretches no cable; the chain is 1.1e-3 below
// it, the shallow-cable theory's terms of a few (d/L)^2 = 2.4e-4 (the tension and the
// mass per span vary along a sagging cable) and the chain's 2.6e-4 at n = 2. kIrvineTol
// covers both with a margin of ~2.
TEST(FixedCableModes, IrvineFirstSymmetricInPlaneMode) {
  constexpr double kIrvineTol = 2e-3;
  const double fl_n = 78e3, density = 10.0, ea_n = 1e8;
  const FixedCable cable = LevelCable(fl_n, density, ea_n);
  std::vector<CableMode> in_plane;
  for (const CableMode& m : CableModes(cable, 80, 8)) {
    if (m.in_plane_share > 0.999) in_plane.push_back(m);
  }
  ASSERT_GE(in_plane.size(), 2u);
  // Its lowest in-plane mode is the symmetric one (mid-span moves), then the antisymmetric.
  EXPECT_GT(std::abs(in_plane[0].midspan_vertical), 0.5);
  EXPECT_LT(std::abs(in_plane[1].midspan_vertical), 1e-6);
  EXPECT_NEAR(in_plane[0].frequency_hz / IrvineSymmetricHz(fl_n, density, ea_n, 100.0), 1.0,
              kIrvineTol);
  const double antisymmetric_hz = 2.0 / (2.0 * 100.0) * std::sqrt(fl_n / density);
  EXPECT_NEAR(in_plane[1].frequency_hz / antisymmetric_hz, 1.0, kIrvineTol);
}

// The net wrench on the cabin (force; moment about O') at `pose` with the cables'
// unstretched lengths held at `s0`, from the catenary alone.
Eigen::Matrix<double, 6, 1> Wrench(const CableRobot& robot, const Pose& pose,
                                   const std::array<double, kNumCables>& s0) {
  Eigen::Matrix<double, 6, 1> q;
  const Eigen::Vector3d weight(0.0, 0.0, robot.cabin_mass_kg * robot.gravity_m_per_s2);
  q.head<3>() = weight;
  q.tail<3>() = (pose.rotation * robot.mass_centre_cabin_m).cross(weight);
  CatenarySolverOptions tight;
  tight.relative_tolerance = 1e-14;
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = robot.cables[i];
    const Eigen::Vector3d r = pose.rotation * robot.AnchorOfCable(i);
    const Eigen::Vector3d chord = c.tower_top_m - (pose.position_m + r);
    const double span = chord.head<2>().norm();
    CatenaryForces f;
    int iterations = 0;
    EXPECT_EQ(SolveCatenaryForcesDouble(span, chord.z(), s0[i], c.ea_n,
                                        c.linear_density_kg_per_m * robot.gravity_m_per_s2, tight,
                                        nullptr, &f, &iterations),
              CatenaryStatus::kOk);
    // The force on the cabin, -F_i: toward the tower, and up.
    const Eigen::Vector3d on_cabin(chord.x() / span * f.fl_n, chord.y() / span * f.fl_n, -f.fz_n);
    q.head<3>() += on_cabin;
    q.tail<3>() += r.cross(on_cabin);
  }
  return q;
}

// K = -d(wrench)/d(u, theta) by central differences, R -> exp(theta) R.
Eigen::Matrix<double, 6, 6> StaticsStiffness(const CableRobot& robot, const Pose& pose,
                                             const std::array<double, kNumCables>& s0) {
  constexpr double kStepM = 1e-3, kStepRad = 1e-4;
  Eigen::Matrix<double, 6, 6> k;
  for (int j = 0; j < 6; ++j) {
    const double h = j < 3 ? kStepM : kStepRad;
    Pose plus = pose, minus = pose;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step[j % 3] = h;
    if (j < 3) {
      plus.position_m += step;
      minus.position_m -= step;
    } else {
      plus.rotation = Eigen::AngleAxisd(h, step / h).toRotationMatrix() * pose.rotation;
      minus.rotation = Eigen::AngleAxisd(-h, step / h).toRotationMatrix() * pose.rotation;
    }
    k.col(j) = -(Wrench(robot, plus, s0) - Wrench(robot, minus, s0)) / (2.0 * h);
  }
  return k;
}

// The cabin's mass matrix at O' built from its definition: kinetic energy
// (1/2) m |v_G|^2 + (1/2) w^T I_G w with v_G = J (u', theta'), J = [I, -[e]x].
Eigen::Matrix<double, 6, 6> CabinMassHere(const CableRobot& robot, const Pose& pose) {
  const Eigen::Vector3d e = pose.rotation * robot.mass_centre_cabin_m;
  Eigen::Matrix<double, 3, 6> j;
  j << Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Zero();
  for (int a = 0; a < 3; ++a) j.col(3 + a) = Eigen::Vector3d::Unit(a).cross(e);
  Eigen::Matrix<double, 6, 6> m = robot.cabin_mass_kg * j.transpose() * j;
  m.bottomRightCorner<3, 3>() +=
      pose.rotation * robot.cabin_inertia_kg_m2 * pose.rotation.transpose();
  return m;
}

// Without the cables' inertia the modes are the cabin's on the statics' stiffness (the
// Guyan limit). The chain's condensed stiffness differs from the continuum's by O(1/N^2)
// (measured at N = 40: 8e-5 of its largest entry, frequencies within 1.0e-4), the
// differences' error is O(h^2) ~1e-7: kStiffnessTol of the largest entry and
// kFrequencyTol relative on each frequency leave a margin of ~2.5. Poses at
// the zenith and 40 deg off axis (the focal law tilts the cabin ~16 deg there), with a
// mass centre off the axis so that every coupling term counts.
TEST(ComputeModes, MasslessCablesGiveTheStaticsStiffness) {
  constexpr double kStiffnessTol = 2e-4, kFrequencyTol = 2.5e-4;
  CableRobot robot = CableRobot::NominalFast();
  robot.mass_centre_cabin_m = Eigen::Vector3d(0.3, -0.2, 0.8);
  robot.cabin_inertia_kg_m2 << 3.6e5, 1e4, -2e4, 1e4, 3.4e5, 5e3, -2e4, 5e3, 5.1e5;
  for (const Pose& pose : {FocalPose(0.0, 0.0), FocalPose(40.0, 70.0)}) {
    ModesOptions options;
    options.segments = 40;
    options.cable_inertia = false;
    ModesResult result;
    std::string error;
    ASSERT_TRUE(ComputeModes(robot, pose, options, &result, &error)) << error;
    EXPECT_LT(result.stiffness_asymmetry, 1e-10);
    std::array<double, kNumCables> s0;
    for (int i = 0; i < kNumCables; ++i) s0[i] = result.statics.cables[i].unstretched_length_m;
    Eigen::Matrix<double, 6, 6> k = StaticsStiffness(robot, pose, s0);
    EXPECT_LT((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-6 * k.cwiseAbs().maxCoeff());
    k = 0.5 * (k + k.transpose()).eval();
    EXPECT_LT((result.cabin_stiffness - k).cwiseAbs().maxCoeff(),
              kStiffnessTol * k.cwiseAbs().maxCoeff())
        << "modes:\n"
        << result.cabin_stiffness << "\nstatics:\n"
        << k;
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> reference(
        k, CabinMassHere(robot, pose));
    ASSERT_EQ(result.modes.size(), 6u);
    for (int i = 0; i < 6; ++i) {
      const double hz = std::sqrt(reference.eigenvalues()[i]) / kTwoPi;
      EXPECT_NEAR(result.modes[i].frequency_hz / hz, 1.0, kFrequencyTol) << "mode " << i + 1;
      EXPECT_NEAR(result.modes[i].CabinShare(), 1.0, 1e-12);
    }
  }
}

std::vector<double> Frequencies(const CableRobot& robot, const Pose& pose, int segments,
                                int count) {
  ModesOptions options;
  options.segments = segments;
  options.modes = count;
  ModesResult result;
  std::string error;
  EXPECT_TRUE(ComputeModes(robot, pose, options, &result, &error)) << error;
  std::vector<double> hz;
  for (const Mode& m : result.modes) hz.push_back(m.frequency_hz);
  return hz;
}

// The chain's error falls as 1/N^2: doubling N from 16 to 32 to 64 shrinks each of the
// 20 lowest frequencies' change by kMinRatio at least (4 for a pure 1/N^2 error; measured
// 3.9 to 4.03), and the default N's 20 lowest lie within 0.1% of the converged values
// (Richardson's extrapolation from N = 64 and 128), ModesOptions::segments's claim.
TEST(ComputeModes, ConvergesAsOneOverNSquared) {
  constexpr double kMinRatio = 3.5, kDefaultTol = 1e-3;
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(40.0, 0.0);
  const std::vector<double> f16 = Frequencies(robot, pose, 16, 20);
  const std::vector<double> f32 = Frequencies(robot, pose, 32, 20);
  const std::vector<double> f64 = Frequencies(robot, pose, 64, 20);
  const std::vector<double> f128 = Frequencies(robot, pose, 128, 20);
  const std::vector<double> f_default = Frequencies(robot, pose, ModesOptions().segments, 20);
  ASSERT_EQ(f128.size(), 20u);
  for (int i = 0; i < 20; ++i) {
    EXPECT_GT(f32[i] - f16[i], kMinRatio * (f64[i] - f32[i])) << "mode " << i;
    EXPECT_GT(f64[i] - f32[i], kMinRatio * (f128[i] - f64[i])) << "mode " << i;
    const double converged = f128[i] + (f128[i] - f64[i]) / 3.0;
    EXPECT_NEAR(f_default[i] / converged, 1.0, kDefaultTol) << "mode " << i;
  }
}

// The shift-invert Lanczos (the default) and the dense solver give the same frequencies
// (to kSolverTol: both are converged to ~1e-12). At a tilted pose, where no two
// frequencies are equal, the same energy shares too; at the zenith, whose pairs and a
// triple of equal frequencies a single-vector Krylov method could miss, every one of them.
TEST(ComputeModes, LanczosAgreesWithTheDenseSolver) {
  constexpr double kSolverTol = 1e-8;
  for (const Pose& pose : {FocalPose(30.0, 200.0), FocalPose(0.0, 0.0)}) {
    ModesOptions options;
    options.segments = 12;
    ModesResult lanczos, dense;
    std::string error;
    ASSERT_TRUE(ComputeModes(CableRobot::NominalFast(), pose, options, &lanczos, &error)) << error;
    options.solver = ModesOptions::Solver::kDense;
    ASSERT_TRUE(ComputeModes(CableRobot::NominalFast(), pose, options, &dense, &error)) << error;
    ASSERT_EQ(lanczos.modes.size(), 20u);
    ASSERT_EQ(dense.modes.size(), 20u);
    const bool tilted = pose.position_m.x() != 0.0;
    for (int i = 0; i < 20; ++i) {
      EXPECT_NEAR(lanczos.modes[i].frequency_hz / dense.modes[i].frequency_hz, 1.0, kSolverTol)
          << "mode " << i + 1;
      if (!tilted) continue;
      EXPECT_NEAR(lanczos.modes[i].cables_share, dense.modes[i].cables_share, 1e-6) << i;
      EXPECT_EQ(lanczos.modes[i].dominant_cable, dense.modes[i].dominant_cable) << i;
    }
  }
}

// At the zenith the robot has 3-fold symmetry (and mirror planes): a mode whose cabin
// moves differently along x and y (or about them) belongs to a pair of equal
// frequencies; within kPairTol, rounding on the eigenproblem's ~1e-14. Every mode's
// energy shares sum to 1.
TEST(ComputeModes, ZenithModesComeInSymmetricPairs) {
  constexpr double kPairTol = 1e-8;
  ModesOptions options;
  options.segments = 16;
  ModesResult result;
  std::string error;
  ASSERT_TRUE(
      ComputeModes(CableRobot::NominalFast(), FocalPose(0.0, 0.0), options, &result, &error))
      << error;
  ASSERT_EQ(result.modes.size(), 20u);
  int paired = 0;
  for (size_t i = 0; i < result.modes.size(); ++i) {
    const Mode& m = result.modes[i];
    double sum = m.cables_share + m.CabinShare();
    EXPECT_NEAR(sum, 1.0, 1e-12);
    const double xy = std::abs(m.cabin_translation_share.x() - m.cabin_translation_share.y()) +
                      std::abs(m.cabin_rotation_share.x() - m.cabin_rotation_share.y());
    if (xy < 1e-6) continue;
    bool partner = false;
    for (size_t j = 0; j < result.modes.size(); ++j) {
      partner = partner || (j != i && std::abs(result.modes[j].frequency_hz - m.frequency_hz) <
                                          kPairTol * m.frequency_hz);
    }
    EXPECT_TRUE(partner) << "mode " << i + 1 << " at " << m.frequency_hz << " Hz";
    paired += partner;
  }
  EXPECT_GE(paired, 4);  // at least the cabin's two sways and two tilts
}

// The map of the cap: one node per grid point in the grid's order, each node's figures
// those of its own modes (the axis node's against ComputeModes at the zenith), a node
// without equilibrium recorded with its reason, and a CSV row per node.
TEST(ComputeModesMap, SummarisesEachNodesModes) {
  ModesMapOptions options;
  options.grid.max_off_axis_deg = 10.0;
  options.grid.off_axis_step_deg = 10.0;
  options.grid.azimuth_step_deg = 120.0;
  options.modes.segments = 12;
  ModesMap map;
  std::string error;
  ASSERT_TRUE(ComputeModesMap(CableRobot::NominalFast(), options, &map, &error)) << error;
  ASSERT_EQ(map.nodes.size(), 4u);
  ModesResult zenith;
  ASSERT_TRUE(
      ComputeModes(CableRobot::NominalFast(), FocalPose(0.0, 0.0), options.modes, &zenith, &error));
  const ModesMapNode& axis = map.nodes[0];
  ASSERT_TRUE(axis.ok) << axis.reason;
  EXPECT_EQ(axis.lowest_hz, zenith.modes[0].frequency_hz);
  ASSERT_GT(axis.first_cabin_mode, 0);
  const Mode& first = zenith.modes[axis.first_cabin_mode - 1];
  EXPECT_EQ(axis.first_cabin_hz, first.frequency_hz);
  EXPECT_GT(first.CabinShare(), 0.5);
  for (int i = 0; i + 1 < axis.first_cabin_mode; ++i) EXPECT_LE(zenith.modes[i].CabinShare(), 0.5);
  // The vertical bounce at the zenith is the first cabin-dominated mode (docs/model.md).
  EXPECT_EQ(axis.motion_hz[2], axis.first_cabin_hz);
  EXPECT_NEAR(map.nodes[2].azimuth_deg, 120.0, 1e-9);
  EXPECT_NEAR(map.nodes[2].off_axis_deg, 10.0, 1e-9);
  const std::string csv = ModesMapCsv(map);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  // The axis node at z = 400 m, above the towers: no equilibrium.
  options.grid.focal_centre_m.z() = 560.0;
  options.attitude_law.focal_centre_m = options.grid.focal_centre_m;
  ASSERT_TRUE(ComputeModesMap(CableRobot::NominalFast(), options, &map, &error)) << error;
  EXPECT_FALSE(map.nodes[0].ok);
  EXPECT_NE(map.nodes[0].reason.find("no equilibrium"), std::string::npos) << map.nodes[0].reason;
  EXPECT_NE(ModesMapCsv(map).find(",no_modes,"), std::string::npos);
  options.grid.off_axis_step_deg = 0.0;
  EXPECT_FALSE(ComputeModesMap(CableRobot::NominalFast(), options, &map, &error));
  EXPECT_NE(error.find("off_axis_step_deg"), std::string::npos) << error;
}

TEST(ComputeModes, RefusesWhatItCannotLineariseAbout) {
  ModesResult result;
  std::string error;
  ModesOptions options;
  options.segments = 1;
  EXPECT_FALSE(
      ComputeModes(CableRobot::NominalFast(), FocalPose(0.0, 0.0), options, &result, &error));
  EXPECT_NE(error.find("segments"), std::string::npos) << error;
  options = ModesOptions();
  options.statics.method = StaticsMethod::kAas;
  EXPECT_FALSE(
      ComputeModes(CableRobot::NominalFast(), FocalPose(0.0, 0.0), options, &result, &error));
  EXPECT_NE(error.find("exact"), std::string::npos) << error;
  Pose far = FocalPose(0.0, 0.0);
  far.position_m.x() = 400.0;  // beyond the towers
  EXPECT_FALSE(ComputeModes(CableRobot::NominalFast(), far, ModesOptions(), &result, &error));
  EXPECT_NE(error.find("no equilibrium"), std::string::npos) << error;
  CableRobot robot = CableRobot::NominalFast();
  robot.cabin_inertia_kg_m2(0, 0) = -1.0;
  EXPECT_FALSE(ComputeModes(robot, FocalPose(0.0, 0.0), ModesOptions(), &result, &error));
  EXPECT_NE(error.find("cabin_inertia_kg_m2"), std::string::npos) << error;
  // Issue 57: 1e300 kg m^2 (finite, positive definite) threw from Spectra's eigensolver;
  // now the model's plausible range refuses it, whoever built the model.
  robot.cabin_inertia_kg_m2 = Eigen::Vector3d::Constant(1e300).asDiagonal();
  EXPECT_FALSE(ComputeModes(robot, FocalPose(0.0, 0.0), ModesOptions(), &result, &error));
  EXPECT_NE(error.find("cabin.inertia_kg_m2[0]: 1e+300 kg m^2"), std::string::npos) << error;
  options = ModesOptions();
  options.modes = kMaxModes + 1;
  EXPECT_FALSE(
      ComputeModes(CableRobot::NominalFast(), FocalPose(0.0, 0.0), options, &result, &error));
  EXPECT_NE(error.find("modes: must be in [1, 200]"), std::string::npos) << error;
}

// Issue 57, 7: K and M are sparse (each cable a chain: its rows couple its neighbouring
// nodes and, at the anchor, the cabin's six dofs), so memory grows with the segments, not
// their square: 1000 segments (17 988 dofs) solve as 48 do, the lowest frequency within
// the chain's 1/N^2 convergence of the default's. Dense, they took 5 GB.
TEST(ComputeModes, AThousandSegmentsSolveAsFortyEightDo) {
  // The 48-segment chain's lowest frequency is within 0.021% of the converged one
  // (modes.h, ModesOptions::segments); a thousand segments are converged far closer.
  constexpr double kConvergenceTol = 3e-4;
  ModesOptions options;
  ModesResult fine, coarse;
  std::string error;
  ASSERT_TRUE(
      ComputeModes(CableRobot::NominalFast(), FocalPose(0.0, 0.0), options, &coarse, &error))
      << error;
  options.segments = 1000;
  ASSERT_TRUE(ComputeModes(CableRobot::NominalFast(), FocalPose(0.0, 0.0), options, &fine, &error))
      << error;
  EXPECT_EQ(fine.degrees_of_freedom, 6 + 6 * 3 * 999);
  ASSERT_EQ(fine.modes.size(), 20u);
  EXPECT_NEAR(fine.modes[0].frequency_hz / coarse.modes[0].frequency_hz, 1.0, kConvergenceTol);
  EXPECT_GE(fine.modes[0].frequency_hz, coarse.modes[0].frequency_hz);  // converges from below
}

}  // namespace
}  // namespace fastcal
