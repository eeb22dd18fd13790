// Tests of the statics solvers (statics.h) against the paper's reference values
// (docs/model.md "Reference values"), physical identities computed here from the
// returned forces, the workspace cap, derivatives and failure statuses.
#include "fastcal/statics.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "fastcal/trajectory.h"

namespace fastcal {

// Readable statuses in failure messages.
void PrintTo(StaticsStatus status, std::ostream* os) { *os << StaticsStatusName(status); }

namespace {

constexpr double kKn = 1e3;
// Equilibrium residual tolerances (N, N m) for ~1e5 N forces.
constexpr double kForceResidualTolN = 1e-6;
constexpr double kMomentResidualTolNm = 1e-5;

Pose FocalPose(const Eigen::Vector3d& position_m) {
  Pose pose;
  pose.position_m = position_m;
  pose.rotation = FocalAttitude(position_m, FocalAttitudeLaw());
  return pose;
}

StaticsSolution Solve(const CableRobot& robot, const Pose& pose, StaticsMethod method) {
  StaticsOptions options;
  options.method = method;
  StaticsSolution s;
  SolveStatics(robot, pose, options, &s);
  return s;
}

// Residuals of the cabin's equilibrium in vector form, computed here (not by the solver):
//   sum(-F_i) + W and sum r_i x (-F_i) + e x W.
void EquilibriumResiduals(const CableRobot& robot, const Pose& pose, const StaticsSolution& s,
                          double* force_n, double* moment_nm) {
  const Eigen::Vector3d weight(0, 0, robot.cabin_mass_kg * robot.gravity_m_per_s2);
  Eigen::Vector3d f = weight;
  Eigen::Vector3d m = (pose.rotation * robot.mass_centre_cabin_m).cross(weight);
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d r = pose.rotation * robot.AnchorOfCable(i);
    f -= s.cables[i].force_n;
    m -= r.cross(s.cables[i].force_n);
  }
  *force_n = f.norm();
  *moment_nm = m.norm();
}

// Cable i's chord, from its cabin anchor to its tower top (eq. 1), computed here.
Eigen::Vector3d Chord(const CableRobot& robot, const Pose& pose, int i) {
  return robot.cables[i].tower_top_m - (pose.rotation * robot.AnchorOfCable(i) + pose.position_m);
}

// How far the upper end of cable i, computed from the solution's Fl, Fz and s0 (eqs.
// 14-16), misses its tower top: span and rise (m).
Eigen::Vector2d EndPointMissM(const CableRobot& robot, const Pose& pose, const CableSolution& c,
                              int i) {
  const Eigen::Vector3d chord = Chord(robot, pose, i);
  const CatenaryEnd<double> e = CatenaryEndpoint(
      c.horizontal_force_n, c.force_n.z(), c.unstretched_length_m, robot.cables[i].ea_n,
      robot.cables[i].linear_density_kg_per_m * robot.gravity_m_per_s2);
  return Eigen::Vector2d(e.span_m - chord.head<2>().norm(), e.rise_m - chord.z());
}

// The focal-sphere cap up to 40 deg off axis every 5 deg x 15 deg, plus points 3 m
// inside and outside the sphere along its normal (model.md "Workspace").
std::vector<Eigen::Vector3d> WorkspaceCap() {
  const Eigen::Vector3d centre(0, 0, 300);
  std::vector<Eigen::Vector3d> points;
  for (double radius : {160.0, 157.0, 163.0}) {
    for (int theta_deg = 0; theta_deg <= 40; theta_deg += 5) {
      for (int phi_deg = 0; phi_deg < 360; phi_deg += 15) {
        const double t = theta_deg * M_PI / 180, p = phi_deg * M_PI / 180;
        points.push_back(centre + radius * Eigen::Vector3d(std::sin(t) * std::cos(p),
                                                           std::sin(t) * std::sin(p),
                                                           -std::cos(t)));
        if (theta_deg == 0) break;
      }
    }
  }
  return points;
}

// Exact and AAS at K1 = (0, 0, 140), R = I (paper Table 2).
void SolveK1(const CableRobot& robot, StaticsSolution* exact, StaticsSolution* aas) {
  Pose pose;
  pose.position_m = Eigen::Vector3d(0, 0, 140);
  *exact = Solve(robot, pose, StaticsMethod::kExact);
  *aas = Solve(robot, pose, StaticsMethod::kAas);
}

TEST(StaticsTest, K1MatchesPaperTable2) {
  // Paper Table 2 values and the precision they are printed to.
  constexpr double kExactKn = 159.17, kAasKn = 158.98, kAasErrorPct = -0.117;
  constexpr double kTensionTolKn = 0.005, kErrorTolPct = 0.0005;
  const CableRobot robot = CableRobot::NominalFast();
  StaticsSolution exact, aas;
  SolveK1(robot, &exact, &aas);
  ASSERT_EQ(exact.status, StaticsStatus::kOk);
  ASSERT_EQ(aas.status, StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) {
    const double te = exact.cables[i].lower_tension_n / kKn;
    const double ta = aas.cables[i].lower_tension_n / kKn;
    EXPECT_NEAR(te, kExactKn, kTensionTolKn) << "cable " << i + 1;
    EXPECT_NEAR(ta, kAasKn, kTensionTolKn) << "cable " << i + 1;
    EXPECT_NEAR(100 * (ta - te) / te, kAasErrorPct, kErrorTolPct) << "cable " << i + 1;
  }
}

// The paper's Table 2 lists slightly different tensions for the six cables at K1, where
// the geometry makes them equal. Its layout evaluated with pi truncated to 3.1415 (eqs.
// 1-2) reproduces all twelve printed values: evidence that the solvers agree with the
// paper's to its printed precision, not only to the rounded 159.17 kN.
TEST(StaticsTest, K1PerCableSpreadOfTable2ComesFromPiTruncatedTo3_1415) {
  constexpr double kPaperPi = 3.1415;
  // Table 2, cables 1..6, and half a unit of its last printed digit plus rounding.
  constexpr double kExactKn[kNumCables] = {159.1762, 159.1670, 159.1587,
                                           159.1587, 159.1670, 159.1762};
  constexpr double kAasKn[kNumCables] = {158.9899, 158.9808, 158.9725,
                                         158.9725, 158.9808, 158.9899};
  constexpr double kTensionTolKn = 1.5e-4;
  CableRobot robot = CableRobot::NominalFast();
  const double tower_radius_m = robot.cables[0].tower_top_m.head<2>().norm();
  const double anchor_radius_m = robot.anchor_points_cabin_m[0].head<2>().norm();
  for (int i = 0; i < kNumCables; ++i) {
    const double t = kPaperPi * i / 3;
    robot.cables[i].tower_top_m.head<2>() =
        tower_radius_m * Eigen::Vector2d(std::cos(t), std::sin(t));
  }
  for (int j = 0; j < 3; ++j) {
    const double t = kPaperPi / 6 + 2 * kPaperPi * j / 3;
    robot.anchor_points_cabin_m[j].head<2>() =
        anchor_radius_m * Eigen::Vector2d(std::cos(t), std::sin(t));
  }
  StaticsSolution exact, aas;
  SolveK1(robot, &exact, &aas);
  ASSERT_EQ(exact.status, StaticsStatus::kOk);
  ASSERT_EQ(aas.status, StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(exact.cables[i].lower_tension_n / kKn, kExactKn[i], kTensionTolKn)
        << "cable " << i + 1;
    EXPECT_NEAR(aas.cables[i].lower_tension_n / kKn, kAasKn[i], kTensionTolKn) << "cable " << i + 1;
  }
}

TEST(StaticsTest, K2MatchesPaperTable3) {
  // The paper's "iteration" row of Table 3. Our exact solution with the focal law of
  // model.md differs from it by at most 0.19 kN (0.1%); the issue asked for 0.05 kN,
  // which no variant of the law we tried reaches (see docs/model.md, "K2").
  constexpr double kPaperExactKn[kNumCables] = {181.5009, 190.7462, 200.7024,
                                                119.5531, 119.8599, 191.0149};
  constexpr double kPaperAasErrorPct[kNumCables] = {0.1026, 0.1040, 0.0151, 0.1397, 0.1407, 0.0108};
  constexpr double kTensionTolKn = 0.2;
  constexpr double kErrorTolPct = 0.01;
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(Eigen::Vector3d(42.65, 33.73, 149.52));
  const StaticsSolution exact = Solve(robot, pose, StaticsMethod::kExact);
  const StaticsSolution aas = Solve(robot, pose, StaticsMethod::kAas);
  ASSERT_EQ(exact.status, StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) {
    const double te = exact.cables[i].lower_tension_n / kKn;
    const double ta = aas.cables[i].lower_tension_n / kKn;
    EXPECT_NEAR(te, kPaperExactKn[i], kTensionTolKn) << "cable " << i + 1;
    EXPECT_NEAR(100 * (te - ta) / te, kPaperAasErrorPct[i], kErrorTolPct) << "cable " << i + 1;
  }
  // The four towers the cabin leans toward (1, 2, 3, 6) carry more than 4 and 5.
  for (int i : {0, 1, 2, 5}) {
    EXPECT_GT(exact.cables[i].lower_tension_n, exact.cables[3].lower_tension_n);
  }
}

// Largest |AAS/exact - 1| in percent per cable over a list of positions (focal law).
std::array<double, kNumCables> MaxAasErrorPct(const std::vector<Eigen::Vector3d>& positions) {
  const CableRobot robot = CableRobot::NominalFast();
  std::array<double, kNumCables> worst{};
  for (const Eigen::Vector3d& p : positions) {
    const Pose pose = FocalPose(p);
    const StaticsSolution exact = Solve(robot, pose, StaticsMethod::kExact);
    const StaticsSolution aas = Solve(robot, pose, StaticsMethod::kAas);
    EXPECT_EQ(exact.status, StaticsStatus::kOk);
    EXPECT_EQ(aas.status, StaticsStatus::kOk);
    for (int i = 0; i < kNumCables; ++i) {
      const double e =
          100 * std::abs(aas.cables[i].lower_tension_n / exact.cables[i].lower_tension_n - 1.0);
      worst[i] = std::max(worst[i], e);
    }
  }
  return worst;
}

// Maxima of paper Tables 4 and 5 are printed to 1e-4 percentage points; the issue asks
// for agreement within 0.01 pp.
constexpr double kTableMaxErrorTolPct = 0.01;
constexpr int kPaperNodes = 101;

TEST(StaticsTest, StraightLineMatchesPaperTable4) {
  constexpr double kPaperPct[kNumCables] = {0.1140, 0.1020, 0.1020, 0.1140, 0.1197, 0.1197};
  std::vector<Eigen::Vector3d> line;
  for (int n = 0; n < kPaperNodes; ++n) {
    line.emplace_back(50.0 - 100.0 * n / (kPaperNodes - 1), 0.0, 150.0);
  }
  const auto worst = MaxAasErrorPct(line);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(worst[i], kPaperPct[i], kTableMaxErrorTolPct) << "cable " << i + 1;
  }
}

TEST(StaticsTest, HalfCircleMatchesPaperTable5) {
  constexpr double kPaperPct[kNumCables] = {0.1308, 0.1016, 0.1017, 0.1308, 0.1308, 0.1308};
  std::vector<Eigen::Vector3d> arc;
  for (int n = 0; n < kPaperNodes; ++n) {
    const double t = M_PI * n / (kPaperNodes - 1);  // G1 (50,0,150) through +y to G2
    arc.emplace_back(50.0 * std::cos(t), 50.0 * std::sin(t), 150.0);
  }
  const auto worst = MaxAasErrorPct(arc);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(worst[i], kPaperPct[i], kTableMaxErrorTolPct) << "cable " << i + 1;
  }
}

TEST(StaticsTest, WholeWorkspaceCap) {
  // On the cap, AAS within 0.5% of exact (model.md measured up to ~0.33%; we find
  // 0.335%). 3 m inside the sphere the cables are steeper and AAS reaches 0.65%, so the
  // off-sphere points get their own bound. One refinement step is within 1e-6
  // everywhere, and the equilibrium of every solution holds in vector form.
  constexpr double kAasOnSphereRelTol = 5e-3;
  constexpr double kAasOffSphereRelTol = 1e-2;
  constexpr double kRefinedRelTol = 1e-6;
  constexpr double kSphereRadiusM = 160.0;
  const CableRobot robot = CableRobot::NominalFast();
  double worst_on = 0, worst_off = 0, worst_refined = 0;
  for (const Eigen::Vector3d& p : WorkspaceCap()) {
    const Pose pose = FocalPose(p);
    const bool on_sphere =
        std::abs((p - Eigen::Vector3d(0, 0, 300)).norm() - kSphereRadiusM) < 1e-9;
    const StaticsSolution exact = Solve(robot, pose, StaticsMethod::kExact);
    ASSERT_EQ(exact.status, StaticsStatus::kOk) << p.transpose();
    double f, mo;
    EquilibriumResiduals(robot, pose, exact, &f, &mo);
    EXPECT_LT(f, kForceResidualTolN) << p.transpose();
    EXPECT_LT(mo, kMomentResidualTolNm) << p.transpose();
    for (StaticsMethod m : {StaticsMethod::kAas, StaticsMethod::kAasRefined}) {
      const StaticsSolution s = Solve(robot, pose, m);
      ASSERT_EQ(s.status, StaticsStatus::kOk) << p.transpose();
      EquilibriumResiduals(robot, pose, s, &f, &mo);
      EXPECT_LT(f, kForceResidualTolN);
      EXPECT_LT(mo, kMomentResidualTolNm);
      double& worst = m == StaticsMethod::kAasRefined ? worst_refined
                      : on_sphere                     ? worst_on
                                                      : worst_off;
      for (int i = 0; i < kNumCables; ++i) {
        worst = std::max(
            worst, std::abs(s.cables[i].lower_tension_n / exact.cables[i].lower_tension_n - 1.0));
      }
    }
  }
  EXPECT_LT(worst_on, kAasOnSphereRelTol);
  EXPECT_LT(worst_off, kAasOffSphereRelTol);
  EXPECT_LT(worst_refined, kRefinedRelTol);
  // AAS is an approximation: a zero error would mean the comparison compares nothing.
  EXPECT_GT(worst_on, 1e-3);
}

// The statics' inner tolerances are speed settings, not accuracy ones: against solves
// converged to 1e-13 they change no result beyond these bounds (measured over the cap:
// exact 5e-14, aas-refined 7.5e-12, aas 2.9e-7).
TEST(StaticsTest, InnerTolerancesDoNotChangeResults) {
  constexpr double kExactRelTol = 1e-12;
  constexpr double kRefinedRelTol = 1e-9;
  // aas ends its secant solves at aas_secant_tolerance = 1e-6, which bounds the relative
  // error those solves leave in the forces (measured: 2.9e-7 over the cap); its s0
  // solves end at aas_length_tolerance = 1e-8, and s0 moves by ~2e-6 m.
  constexpr double kAasRelTol = 1e-6;
  constexpr double kAasLengthTolM = 1e-5;
  constexpr double kTightCatenaryTol = 1e-13;
  const CableRobot robot = CableRobot::NominalFast();
  for (const Eigen::Vector3d& p : WorkspaceCap()) {
    const Pose pose = FocalPose(p);
    for (StaticsMethod m :
         {StaticsMethod::kAas, StaticsMethod::kAasRefined, StaticsMethod::kExact}) {
      StaticsOptions fast, tight;
      fast.method = tight.method = m;
      tight.catenary.relative_tolerance = kTightCatenaryTol;
      tight.exact_start_catenary_tolerance = kTightCatenaryTol;
      tight.aas_secant_tolerance = kTightCatenaryTol;
      tight.aas_length_tolerance = kTightCatenaryTol;
      StaticsSolution a, b;
      ASSERT_EQ(SolveStatics(robot, pose, fast, &a), StaticsStatus::kOk) << p.transpose();
      ASSERT_EQ(SolveStatics(robot, pose, tight, &b), StaticsStatus::kOk) << p.transpose();
      EXPECT_EQ(a.outer_iterations, b.outer_iterations) << p.transpose();
      const double tol = m == StaticsMethod::kExact ? kExactRelTol
                         : m == StaticsMethod::kAas ? kAasRelTol
                                                    : kRefinedRelTol;
      for (int i = 0; i < kNumCables; ++i) {
        EXPECT_NEAR(a.cables[i].lower_tension_n, b.cables[i].lower_tension_n,
                    tol * b.cables[i].lower_tension_n)
            << StaticsMethodName(m) << " " << p.transpose();
        EXPECT_NEAR(
            a.cables[i].unstretched_length_m, b.cables[i].unstretched_length_m,
            m == StaticsMethod::kAas ? kAasLengthTolM : tol * b.cables[i].unstretched_length_m)
            << StaticsMethodName(m) << " " << p.transpose();
      }
    }
  }
  StaticsOptions bad;
  bad.exact_start_catenary_tolerance = 0.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("exact_start_catenary_tolerance"), std::string::npos) << error;
  bad = StaticsOptions();
  bad.aas_secant_tolerance = -1.0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("aas_secant_tolerance"), std::string::npos) << error;
  bad = StaticsOptions();
  bad.aas_length_tolerance = 0.0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("aas_length_tolerance"), std::string::npos) << error;
}

// Each inner tolerance acts on its own stage only: aas_length_tolerance on the s0 solves
// (so AAS's forces, which do not depend on s0, do not move at all), aas_secant_tolerance
// on the secants of aas and aas-refined (not exact's start: nothing moves).
TEST(StaticsTest, EachInnerToleranceActsOnItsOwnStage) {
  constexpr double kLooseTolerance = 1e-4;
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(Eigen::Vector3d(42.65, 33.73, 149.52));
  StaticsOptions aas;
  aas.method = StaticsMethod::kAas;
  StaticsOptions loose_length = aas;
  loose_length.aas_length_tolerance = kLooseTolerance;
  StaticsOptions exact;
  exact.method = StaticsMethod::kExact;
  StaticsOptions loose_secant = exact;
  loose_secant.aas_secant_tolerance = kLooseTolerance * 100;
  for (const auto& [a, b] : {std::pair{aas, loose_length}, std::pair{exact, loose_secant}}) {
    StaticsSolution sa, sb;
    ASSERT_EQ(SolveStatics(robot, pose, a, &sa), StaticsStatus::kOk);
    ASSERT_EQ(SolveStatics(robot, pose, b, &sb), StaticsStatus::kOk);
    if (a.method == StaticsMethod::kExact) {
      EXPECT_EQ(sa.catenary_iterations, sb.catenary_iterations);
    }
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(sa.cables[i].lower_tension_n, sb.cables[i].lower_tension_n)
          << StaticsMethodName(a.method) << " cable " << i + 1;
    }
  }
}

// The guess for each cable's curve point at the AAS force (internal::CurveGuess,
// model-corrected) is what lets one catenary evaluation end the s0 solves of aas and
// aas-refined, and makes exact's start. Measured max over the cap +-3 m: 6.7e-5 in s0,
// 1.4e-5 in Fz; the linear guess is ~100 times further off.
TEST(StaticsTest, CurveGuessIsCloseOverTheWorkspace) {
  constexpr double kS0RelTol = 1e-4;
  constexpr double kFzRelTol = 3e-5;  // of the lower-end tension
  const CableRobot robot = CableRobot::NominalFast();
  const StaticsParameters<double> p = MakeStaticsParameters(robot);
  const StaticsOptions options;
  double worst_linear_s0 = 0.0;
  for (const Eigen::Vector3d& position : WorkspaceCap()) {
    const Pose pose = FocalPose(position);
    const StaticsSolution aas = Solve(robot, pose, StaticsMethod::kAas);
    ASSERT_EQ(aas.status, StaticsStatus::kOk);
    internal::PoseGeometry<double> g;
    int cable = -1;
    ASSERT_EQ(internal::ComputeGeometry(p, pose, 1e-9, &g, &cable), StaticsStatus::kOk);
    for (int i = 0; i < kNumCables; ++i) {
      const CableSolution& c = aas.cables[i];
      CatenaryCurvePoint truth;
      int iterations = 0;
      ASSERT_EQ(
          SolveCatenaryLengthDouble(g.span[i], g.rise[i], c.horizontal_force_n, p.ea_n[i], g.w[i],
                                    CatenarySolverOptions(), nullptr, &truth, &iterations),
          CatenaryStatus::kOk);
      const CatenaryCurvePoint guess =
          internal::CurveGuess(c.horizontal_force_n, g, i, p.ea_n[i], c.secant_low, c.secant_high,
                               options, /*model_corrected=*/true);
      EXPECT_NEAR(guess.s0_m, truth.s0_m, kS0RelTol * truth.s0_m) << position.transpose();
      EXPECT_NEAR(guess.fz_n, truth.fz_n, kFzRelTol * c.lower_tension_n) << position.transpose();
      const CatenaryCurvePoint linear =
          internal::CurveGuess(c.horizontal_force_n, g, i, p.ea_n[i], c.secant_low, c.secant_high,
                               options, /*model_corrected=*/false);
      worst_linear_s0 = std::max(worst_linear_s0, std::abs(linear.s0_m / truth.s0_m - 1.0));
    }
  }
  EXPECT_GT(worst_linear_s0, 10 * kS0RelTol);
}

TEST(StaticsTest, ExactSolutionSatisfiesEveryCatenary) {
  constexpr double kEndPointTolM = 1e-8;
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(Eigen::Vector3d(-60, 45, 155));
  const StaticsSolution s = Solve(robot, pose, StaticsMethod::kExact);
  ASSERT_EQ(s.status, StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d chord = Chord(robot, pose, i);
    const CableSolution& c = s.cables[i];
    const Eigen::Vector2d miss_m = EndPointMissM(robot, pose, c, i);
    EXPECT_NEAR(miss_m.x(), 0.0, kEndPointTolM);
    EXPECT_NEAR(miss_m.y(), 0.0, kEndPointTolM);
    // The horizontal force points from the tower back toward the cabin (eqs. 17-18).
    EXPECT_NEAR(c.force_n.head<2>().normalized().dot(-chord.head<2>().normalized()), 1.0, 1e-12);
    EXPECT_GT(c.upper_tension_n, c.lower_tension_n);  // the cable's weight hangs on the tower
  }
}

TEST(StaticsTest, MassCentreShiftLoadsTheCablesOnThatSide) {
  // With the mass centre moved toward +x (toward tower 1), the cables tied to the anchor
  // at 30 deg (cables 1 and 2) and 270 deg... carry the extra moment; check sign against
  // the moment balance about the y axis computed here from the vector form.
  const CableRobot nominal = CableRobot::NominalFast();
  CableRobot shifted = nominal;
  shifted.mass_centre_cabin_m = Eigen::Vector3d(0.22, 0.11, 0.5);
  const Pose pose = FocalPose(Eigen::Vector3d(0, 71.11, 156.73));
  const StaticsSolution a = Solve(nominal, pose, StaticsMethod::kExact);
  const StaticsSolution b = Solve(shifted, pose, StaticsMethod::kExact);
  ASSERT_EQ(b.status, StaticsStatus::kOk);
  double f, m;
  EquilibriumResiduals(shifted, pose, b, &f, &m);
  EXPECT_LT(m, kMomentResidualTolNm);
  EquilibriumResiduals(nominal, pose, b, &f, &m);
  EXPECT_GT(m, 1e3);  // the nominal model's moment balance is violated by ~m g 0.25 m
  // Vertical force sum unchanged; the anchor nearest the shift (30 deg: cables 1, 2)
  // takes more of the load.
  const double fz_a = a.cables[0].force_n.z() + a.cables[1].force_n.z();
  const double fz_b = b.cables[0].force_n.z() + b.cables[1].force_n.z();
  EXPECT_LT(fz_b, fz_a);  // Fz is negative: more pull down at the cabin side
}

// aas-refined steps until its error estimate meets refined_relative_tolerance: at a taut
// pose one step for 1e-6, two for 1e-12, each squaring the error (a Newton step).
TEST(StaticsTest, RefinementConvergesQuadratically) {
  // Tolerances that one and two steps meet here (AAS's own error is ~1e-3).
  constexpr double kOneStepTolerance = 1e-6, kTwoStepTolerance = 1e-12;
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(Eigen::Vector3d(80, -50, 170));
  const StaticsSolution exact = Solve(robot, pose, StaticsMethod::kExact);
  double previous = 1.0;
  for (int steps = 0; steps <= 2; ++steps) {
    StaticsOptions options;
    options.method = steps == 0 ? StaticsMethod::kAas : StaticsMethod::kAasRefined;
    options.refined_relative_tolerance = steps == 1 ? kOneStepTolerance : kTwoStepTolerance;
    StaticsSolution s;
    ASSERT_EQ(SolveStatics(robot, pose, options, &s), StaticsStatus::kOk);
    EXPECT_EQ(s.outer_iterations, steps);
    double err = 0;
    for (int i = 0; i < kNumCables; ++i) {
      err = std::max(err,
                     std::abs(s.cables[i].lower_tension_n / exact.cables[i].lower_tension_n - 1));
    }
    if (steps > 0) {
      EXPECT_LT(err, std::max(10 * previous * previous, 1e-13)) << steps;
    }
    previous = err;
  }
}

TEST(StaticsTest, WarmStartGivesTheColdSolution) {
  // aas: its secant solves stop at StaticsOptions::aas_secant_tolerance (1e-6), so warm
  // and cold may end on different points within it. The others converge further.
  constexpr double kAasRelTol = 1e-6;
  constexpr double kConvergedRelTol = 1e-9;
  const CableRobot robot = CableRobot::NominalFast();
  for (StaticsMethod m : {StaticsMethod::kAas, StaticsMethod::kAasRefined, StaticsMethod::kExact}) {
    const double kRelTol = m == StaticsMethod::kAas ? kAasRelTol : kConvergedRelTol;
    StaticsOptions warm;
    warm.method = m;
    warm.warm_start = true;
    StaticsSolution w;
    for (int n = 0; n <= 20; ++n) {
      const Pose pose = FocalPose(Eigen::Vector3d(50 - 5.0 * n, 2.0 * n, 150));
      ASSERT_EQ(SolveStatics(robot, pose, warm, &w), StaticsStatus::kOk);
      const StaticsSolution c = Solve(robot, pose, m);
      for (int i = 0; i < kNumCables; ++i) {
        EXPECT_NEAR(w.cables[i].lower_tension_n, c.cables[i].lower_tension_n,
                    kRelTol * c.cables[i].lower_tension_n);
      }
    }
  }
}

// Along the paper's line (nodes 1 m apart) exact starts each node from the last two
// solutions extrapolated: two Newton steps from the third node on (three from the last
// one alone, as at the second). A pose off the path's line, or back at its start, is
// started from the last solution alone, and still gives the cold solution.
TEST(StaticsTest, WarmStartExtrapolatesAlongThePath) {
  constexpr double kConvergedRelTol = 1e-9;
  const CableRobot robot = CableRobot::NominalFast();
  StaticsOptions warm;
  warm.warm_start = true;
  StaticsSolution w;
  for (int n = 0; n <= 20; ++n) {
    ASSERT_EQ(SolveStatics(robot, FocalPose(Eigen::Vector3d(50 - n, 0, 150)), warm, &w),
              StaticsStatus::kOk);
    EXPECT_EQ(w.has_previous, n >= 1);
    if (n >= 2) {
      EXPECT_EQ(w.outer_iterations, 2) << n;
    }
  }
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(20, 20, 150), Eigen::Vector3d(50, 0, 150)}) {
    ASSERT_EQ(SolveStatics(robot, FocalPose(p), warm, &w), StaticsStatus::kOk);
    const StaticsSolution c = Solve(robot, FocalPose(p), StaticsMethod::kExact);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(w.cables[i].lower_tension_n, c.cables[i].lower_tension_n,
                  kConvergedRelTol * c.cables[i].lower_tension_n);
    }
  }
}

// aas and aas-refined start their secant solves from the last two solutions' secants
// extrapolated the same way: along the paper's line, from the third node on, each of the
// 12 secant and 6 curve-point solves ends after at most one evaluation (cold: exactly one;
// from the last secants alone 23 a node), and the forces are the cold ones to within the
// secants' tolerance. An extrapolated start can meet that tolerance (1e-6 of the chord)
// as it is and end without a Newton step, so on this line the forces differ by up to
// ~1.5e-6 relative (statics.h: aas_secant_tolerance), where a cold solve, which always
// takes its step, ends within 3e-7 of converged secants.
TEST(StaticsTest, WarmAasExtrapolatesItsSecantsAlongThePath) {
  constexpr int kColdEvaluations = 2 * kNumCables + kNumCables;
  constexpr double kAasRelTol = 2e-6;
  const CableRobot robot = CableRobot::NominalFast();
  for (StaticsMethod m : {StaticsMethod::kAas, StaticsMethod::kAasRefined}) {
    StaticsOptions warm;
    warm.method = m;
    warm.warm_start = true;
    StaticsSolution w;
    for (int n = 0; n <= 20; ++n) {
      const Pose pose = FocalPose(Eigen::Vector3d(50 - n, 0, 150));
      ASSERT_EQ(SolveStatics(robot, pose, warm, &w), StaticsStatus::kOk);
      if (n >= 2) {
        EXPECT_LE(w.catenary_iterations, kColdEvaluations) << StaticsMethodName(m) << " " << n;
      }
      const StaticsSolution c = Solve(robot, pose, m);
      for (int i = 0; i < kNumCables; ++i) {
        EXPECT_NEAR(w.cables[i].lower_tension_n, c.cables[i].lower_tension_n,
                    kAasRelTol * c.cables[i].lower_tension_n);
      }
    }
  }
  // After exact (whose solutions carry no secants of their own pose) the first aas solve
  // starts from old secants and the second from its predecessor's alone: no
  // extrapolation from old ones (that took 77 evaluations), and back to one evaluation
  // per solve from the third.
  {
    constexpr int kFromLastSecants = 24;  // 23 measured along the line
    StaticsOptions switching;
    switching.warm_start = true;
    StaticsSolution s;
    for (int n = 0; n <= 15; ++n) {
      switching.method = n < 10 ? StaticsMethod::kExact : StaticsMethod::kAas;
      ASSERT_EQ(SolveStatics(robot, FocalPose(Eigen::Vector3d(50 - n, 0, 150)), switching, &s),
                StaticsStatus::kOk);
      if (n == 11) {
        EXPECT_LE(s.catenary_iterations, kFromLastSecants);
      }
      if (n >= 12) {
        EXPECT_LE(s.catenary_iterations, kColdEvaluations) << n;
      }
    }
  }
  // Off the path's line: the last secants alone, and still the cold forces.
  StaticsOptions warm;
  warm.method = StaticsMethod::kAas;
  warm.warm_start = true;
  StaticsSolution w;
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(40, 0, 150), Eigen::Vector3d(39, 0, 150), Eigen::Vector3d(20, 20, 150)}) {
    ASSERT_EQ(SolveStatics(robot, FocalPose(p), warm, &w), StaticsStatus::kOk);
    const StaticsSolution c = Solve(robot, FocalPose(p), StaticsMethod::kAas);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(w.cables[i].lower_tension_n, c.cables[i].lower_tension_n,
                  kAasRelTol * c.cables[i].lower_tension_n);
    }
  }
}

// Solutions of the equations that describe no cable are refused (StaticsOptions'
// max_strain, max_length_ratio), for every method and also after a warm start.
TEST(StaticsTest, SolutionsOutsideTheModelsRangeAreRefused) {
  const CableRobot robot = CableRobot::NominalFast();
  // 10 m below the tower tops the cables are nearly horizontal: exact needs 1898 kN per
  // cable, 7.7% strain.
  Pose high;
  high.position_m = Eigen::Vector3d(0, 0, 260);
  EXPECT_EQ(Solve(robot, high, StaticsMethod::kExact).status, StaticsStatus::kOverstretchedCable);
  // 1 cm below them aas-refined's Newton step overshoots to s0 < 0, so it cannot go on;
  // exact finds the equilibrium, at a strain of 59.
  Pose top;
  top.position_m = Eigen::Vector3d(0, 0, 269.99);
  EXPECT_EQ(Solve(robot, top, StaticsMethod::kAasRefined).status, StaticsStatus::kNotConverged);
  EXPECT_EQ(Solve(robot, top, StaticsMethod::kExact).status, StaticsStatus::kOverstretchedCable);
  // 43 deg off axis cable 3 nearly goes slack: AAS's secant, extrapolated, gives it
  // s0 = 6.5e6 m; its error estimate says so (exact: 474 m, 1.33 chords, inside the limit).
  const Pose edge = FocalPose(Eigen::Vector3d(109.2820323, 29.2820323, 186.862915));
  const StaticsSolution aas = Solve(robot, edge, StaticsMethod::kAas);
  EXPECT_EQ(aas.status, StaticsStatus::kInaccurate);
  EXPECT_GT(aas.limit_value, 1.0);
  EXPECT_EQ(Solve(robot, edge, StaticsMethod::kExact).status, StaticsStatus::kOk);
  // Warm-started from K2, exact's Newton reaches a root with s0 = 4.9 m and 1.45e6 kN:
  // refused, then retried cold, which finds the overstretched equilibrium.
  StaticsOptions warm;
  warm.method = StaticsMethod::kExact;
  warm.warm_start = true;
  StaticsSolution s;
  ASSERT_EQ(SolveStatics(robot, FocalPose(Eigen::Vector3d(42.65, 33.73, 149.52)), warm, &s),
            StaticsStatus::kOk);
  EXPECT_NE(SolveStatics(robot, top, warm, &s), StaticsStatus::kOk);
  for (const CableSolution& c : s.cables) EXPECT_EQ(c.lower_tension_n, 0.0);
  // The limits are options: allow 10% strain and the 260 m pose solves.
  StaticsOptions lenient;
  lenient.method = StaticsMethod::kExact;
  lenient.max_strain = 0.1;
  ASSERT_EQ(SolveStatics(robot, high, lenient, &s), StaticsStatus::kOk);
  EXPECT_NEAR(s.cables[0].lower_tension_n / kKn, 1898.49, 0.01);
  StaticsOptions bad;
  bad.max_strain = 0.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("max_strain"), std::string::npos) << error;
}

TEST(StaticsTest, InfeasibleAndInvalidPosesReportStatusNotNan) {
  const CableRobot robot = CableRobot::NominalFast();
  Pose outside;  // beyond the tower circle: the far cables cannot pull it back
  outside.position_m = Eigen::Vector3d(330, 0, 150);
  for (StaticsMethod m : {StaticsMethod::kAas, StaticsMethod::kAasRefined, StaticsMethod::kExact}) {
    const StaticsSolution s = Solve(robot, outside, m);
    EXPECT_NE(s.status, StaticsStatus::kOk) << StaticsMethodName(m);
    for (const CableSolution& c : s.cables) EXPECT_EQ(c.lower_tension_n, 0.0);
    EXPECT_FALSE(DescribeStatus(s).empty());
  }
  Pose above;  // above the tower tops: nothing holds it up
  above.position_m = Eigen::Vector3d(0, 0, 290);
  EXPECT_EQ(Solve(robot, above, StaticsMethod::kExact).status, StaticsStatus::kNoEquilibrium);
  Pose nan_pose;
  nan_pose.position_m = Eigen::Vector3d(0, NAN, 150);
  EXPECT_EQ(Solve(robot, nan_pose, StaticsMethod::kAas).status, StaticsStatus::kInvalidInput);
  Pose inf_pose;
  inf_pose.rotation(0, 0) = INFINITY;
  EXPECT_EQ(Solve(robot, inf_pose, StaticsMethod::kExact).status, StaticsStatus::kInvalidInput);
  CableRobot bad = robot;
  bad.cables[3].ea_n = -1;
  Pose ok;
  ok.position_m = Eigen::Vector3d(0, 0, 140);
  EXPECT_EQ(Solve(bad, ok, StaticsMethod::kAas).status, StaticsStatus::kInvalidInput);
  StaticsOptions options;
  options.secant_low_fraction = 1.02;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("secant"), std::string::npos);
  // SolveStatics checks the options itself: swapped secants, no refinement step.
  StaticsSolution s;
  EXPECT_EQ(SolveStatics(robot, ok, options, &s), StaticsStatus::kInvalidInput);
  StaticsOptions no_steps;
  no_steps.max_refinement_steps = 0;
  EXPECT_EQ(SolveStatics(robot, ok, no_steps, &s), StaticsStatus::kInvalidInput);
  for (const CableSolution& c : s.cables) EXPECT_EQ(c.lower_tension_n, 0.0);
  // A default-constructed robot has no anchor points: invalid input, not a crash.
  EXPECT_EQ(SolveStatics(CableRobot(), ok, StaticsOptions(), &s), StaticsStatus::kInvalidInput);
}

TEST(StaticsTest, JetTensionsMatchCentralDifferences) {
  // d tension / d(mass centre x, z, density of cable 3, EA of cable 1, tower 5 y, mass)
  // through each method, against central differences of the double solve.
  using Jet = ceres::Jet<double, 6>;
  constexpr double kRelTol = 2e-5;
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(Eigen::Vector3d(42.65, 33.73, 149.52));
  const StaticsParameters<double> p0 = MakeStaticsParameters(robot);
  auto perturb = [](auto& p, int k, const auto& d) {
    switch (k) {
      case 0:
        p.mass_centre_cabin_m[0] += d;
        break;
      case 1:
        p.mass_centre_cabin_m[2] += d;
        break;
      case 2:
        p.linear_density_kg_per_m[2] += d;
        break;
      case 3:
        p.ea_n[0] += d;
        break;
      case 4:
        p.tower_top_m[4][1] += d;
        break;
      case 5:
        p.cabin_mass_kg += d;
        break;
    }
  };
  const double steps[6] = {1e-4, 1e-4, 1e-5, 1e2, 1e-4, 1e-2};
  for (StaticsMethod m : {StaticsMethod::kAas, StaticsMethod::kAasRefined, StaticsMethod::kExact}) {
    StaticsOptions options;
    options.method = m;
    StaticsParameters<Jet> pj;
    CastParametersInto(p0, &pj);
    for (int k = 0; k < 6; ++k) {
      Jet unit(0.0, k);
      perturb(pj, k, unit);
    }
    std::array<Jet, kNumCables> tj;
    ASSERT_EQ(ModelLowerTensions(pj, pose, options, &tj), StaticsStatus::kOk);
    for (int k = 0; k < 6; ++k) {
      StaticsParameters<double> up = p0, dn = p0;
      perturb(up, k, steps[k]);
      perturb(dn, k, -steps[k]);
      std::array<double, kNumCables> tu, td;
      ASSERT_EQ(ModelLowerTensions(up, pose, options, &tu), StaticsStatus::kOk);
      ASSERT_EQ(ModelLowerTensions(dn, pose, options, &td), StaticsStatus::kOk);
      for (int i = 0; i < kNumCables; ++i) {
        const double numeric = (tu[i] - td[i]) / (2 * steps[k]);
        EXPECT_NEAR(tj[i].v[k], numeric, kRelTol * (std::abs(numeric) + 1.0))
            << StaticsMethodName(m) << " parameter " << k << " cable " << i + 1;
      }
    }
  }
}

// ---- Issue 9: no ok without proof, no false refusal, honest statuses ----------------

// The issue's two example poses. At the first, aas-refined returned T5 = 28.95 kN as ok;
// the equilibrium has 31.98 kN, with cable 5 at s0/k = 1.487 hanging in a loop that passes
// 2.4 m through the reflector (found by this work: the issue quoted it as holdable), so it
// is refused as reflector contact, and solves without the reflector in the model. Every
// method refused the second as "slack", though it has an equilibrium within the model's
// range (its smallest tension 29.85 kN).
TEST(StaticsTest, Issue9ExamplePosesAreRightOrRefused) {
  constexpr double kTensionTolKn = 0.01;   // the issue quotes 0.01 kN
  constexpr double kClearanceTolM = 0.01;  // measured -2.388 m, sampled independently
  CableRobot robot = CableRobot::NominalFast();
  Pose sagging;
  sagging.position_m = Eigen::Vector3d(52.483144870, 85.317743916, 179.260329188);
  sagging.rotation = RotationFromRpyDeg(14.724046077086, -5.261549746844, 2.681403711399);
  const StaticsSolution touching = Solve(robot, sagging, StaticsMethod::kExact);
  EXPECT_EQ(touching.status, StaticsStatus::kReflectorContact) << DescribeStatus(touching);
  EXPECT_EQ(touching.cable, 4);
  EXPECT_NEAR(touching.limit_value, -2.39, kClearanceTolM);
  EXPECT_NE(DescribeStatus(touching).find("cable 5 would pass through the reflector"),
            std::string::npos);
  for (const CableSolution& c : touching.cables) EXPECT_EQ(c.lower_tension_n, 0.0);
  const CableRobot with_reflector = robot;
  robot.reflector.reset();
  const StaticsSolution exact = Solve(robot, sagging, StaticsMethod::kExact);
  ASSERT_EQ(exact.status, StaticsStatus::kOk) << DescribeStatus(exact);
  EXPECT_NEAR(exact.cables[4].lower_tension_n / kKn, 31.98, kTensionTolKn);
  const StaticsSolution refined = Solve(robot, sagging, StaticsMethod::kAasRefined);
  ASSERT_EQ(refined.status, StaticsStatus::kOk) << DescribeStatus(refined);
  EXPECT_GT(refined.outer_iterations, 1);  // one step left it 9% off
  EXPECT_NEAR(refined.cables[4].lower_tension_n / kKn, 31.98, kTensionTolKn);
  const StaticsSolution aas = Solve(robot, sagging, StaticsMethod::kAas);
  EXPECT_EQ(aas.status, StaticsStatus::kInaccurate);
  EXPECT_GT(aas.limit_value, aas.limit);
  robot = with_reflector;

  // The second: exact finds the equilibrium the old start missed; cable 2 hangs 1.64 m
  // through the reflector there too, and without the reflector it is ok.
  Pose held;
  held.position_m = Eigen::Vector3d(-96.519, -24.789, 178.667);
  held.rotation = RotationFromRpyDeg(-0.809, 15.021, -2.162);
  const StaticsSolution through = Solve(robot, held, StaticsMethod::kExact);
  EXPECT_EQ(through.status, StaticsStatus::kReflectorContact) << DescribeStatus(through);
  EXPECT_EQ(through.cable, 1);
  EXPECT_NEAR(through.limit_value, -1.64, kClearanceTolM);
  robot.reflector.reset();
  const StaticsSolution s = Solve(robot, held, StaticsMethod::kExact);
  ASSERT_EQ(s.status, StaticsStatus::kOk) << DescribeStatus(s);
  double smallest_kn = HUGE_VAL;
  for (const CableSolution& c : s.cables)
    smallest_kn = std::min(smallest_kn, c.lower_tension_n / kKn);
  EXPECT_NEAR(smallest_kn, 29.85, kTensionTolKn);
  // The approximate methods cannot say whether such a pose can be held: they say so.
  EXPECT_EQ(Solve(robot, held, StaticsMethod::kAas).status, StaticsStatus::kInaccurate);
  EXPECT_EQ(Solve(robot, held, StaticsMethod::kAasRefined).status, StaticsStatus::kNotConverged);
}

// In a fit (ModelFitStaticsOptions) aas answers whatever its error estimate: a trial mass
// centre 0.5 m off takes its error over 1% at the cap's edge, and refusing those samples
// made a calibration with the aas forward model fail. Its estimate is still reported.
TEST(StaticsTest, ModelFitAcceptsAasBeyondItsUsualLimit) {
  constexpr double kUsualLimit = 0.01;  // StaticsOptions().aas_max_relative_error
  CableRobot robot = CableRobot::NominalFast();
  robot.mass_centre_cabin_m = Eigen::Vector3d(0.5, 0.3, 1.0);
  const Pose pose = FocalPose(Eigen::Vector3d(97.4, -29.0, 175.9));
  StaticsOptions plain;
  plain.method = StaticsMethod::kAas;
  StaticsSolution s;
  EXPECT_EQ(SolveStatics(robot, pose, plain, &s), StaticsStatus::kInaccurate);
  EXPECT_GT(s.limit_value, kUsualLimit);
  ASSERT_EQ(SolveStatics(robot, pose, ModelFitStaticsOptions(StaticsMethod::kAas), &s),
            StaticsStatus::kOk);
  EXPECT_GT(s.error_estimate, kUsualLimit);
}

// Forces only (compute_unstretched_lengths off, a fit's aas): the same forces as with the
// curve points solved, without their solves, and a check from the model-corrected guesses
// of the points instead. Over the cap +-3 m measured: s0 within 6.7e-5, the estimate 0.76
// to 1.10 times the solved one, the pose's end residual 1.06 to 1.71 times (aas's Fz
// miss is a few N, the guess's error ~2 N). Bounds a little wider than measured.
TEST(StaticsTest, AasForcesOnlyChecksFromTheGuessedCurvePoints) {
  constexpr double kS0RelTol = 1e-4;  // the guess's 6.7e-5 (statics_core.h)
  constexpr double kMinEstimateRatio = 0.7, kMaxEstimateRatio = 1.2;
  constexpr double kMinEndResidualRatio = 0.95, kMaxEndResidualRatio = 1.85;
  const CableRobot robot = CableRobot::NominalFast();
  for (const Eigen::Vector3d& p : WorkspaceCap()) {
    const Pose pose = FocalPose(p);
    StaticsOptions options;
    options.method = StaticsMethod::kAas;
    StaticsSolution solved, guessed;
    ASSERT_EQ(SolveStatics(robot, pose, options, &solved), StaticsStatus::kOk);
    options.compute_unstretched_lengths = false;
    ASSERT_EQ(SolveStatics(robot, pose, options, &guessed), StaticsStatus::kOk);
    EXPECT_LT(guessed.catenary_iterations, solved.catenary_iterations);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(guessed.cables[i].lower_tension_n, solved.cables[i].lower_tension_n);
      EXPECT_NEAR(guessed.cables[i].unstretched_length_m / solved.cables[i].unstretched_length_m,
                  1.0, kS0RelTol);
    }
    const double estimate_ratio = guessed.error_estimate / solved.error_estimate;
    EXPECT_GE(estimate_ratio, kMinEstimateRatio) << p.transpose();
    EXPECT_LE(estimate_ratio, kMaxEstimateRatio) << p.transpose();
    const double residual_ratio = guessed.end_residual_m / solved.end_residual_m;
    EXPECT_GE(residual_ratio, kMinEndResidualRatio) << p.transpose();
    EXPECT_LE(residual_ratio, kMaxEndResidualRatio) << p.transpose();
  }
}

// Each method's error estimate (the Newton step that the end-condition residuals imply,
// moved through the equilibrium) against its actual error, over the workspace cap +-3 m:
// measured within 3% for aas and within 5% for one aas-refined step (its error, ~1e-8,
// is second order and the estimate first) wherever that error is above the rounding of
// the reference (1e-11).
TEST(StaticsTest, ErrorEstimateMatchesTheActualError) {
  constexpr double kAasRatioTol = 0.05, kRefinedRatioTol = 0.1;
  constexpr double kResolvableError = 1e-11;
  const CableRobot robot = CableRobot::NominalFast();
  for (const Eigen::Vector3d& p : WorkspaceCap()) {
    const Pose pose = FocalPose(p);
    const StaticsSolution exact = Solve(robot, pose, StaticsMethod::kExact);
    ASSERT_EQ(exact.status, StaticsStatus::kOk);
    EXPECT_LT(exact.error_estimate, StaticsOptions().exact_relative_tolerance);
    for (StaticsMethod m : {StaticsMethod::kAas, StaticsMethod::kAasRefined}) {
      StaticsOptions options;
      options.method = m;
      options.refined_relative_tolerance = 1.0;  // one step, whatever its estimate
      StaticsSolution s;
      ASSERT_EQ(SolveStatics(robot, pose, options, &s), StaticsStatus::kOk) << p.transpose();
      double error = 0.0;
      for (int i = 0; i < kNumCables; ++i) {
        error = std::max(
            error, std::abs(s.cables[i].lower_tension_n / exact.cables[i].lower_tension_n - 1));
      }
      if (error < kResolvableError) continue;
      EXPECT_NEAR(error / s.error_estimate, 1.0,
                  m == StaticsMethod::kAas ? kAasRatioTol : kRefinedRatioTol)
          << StaticsMethodName(m) << " " << p.transpose();
    }
  }
}

// Poses of the kind the issue's sweep drew: off-axis angle 0-45 deg (uniform over the
// cap's area), +-5 m off the focal sphere, the focal law times an extra rotation whose
// amplitude per axis is drawn in [2, 5] deg (trajectory.h, RandomPosesAroundFocalLaw).
std::vector<Pose> Issue9SweepPoses(int count, std::uint64_t seed) {
  std::vector<Pose> poses;
  std::string error;
  EXPECT_TRUE(RandomPosesAroundFocalLaw(EdgeSweepSpec(count, seed), &poses, &error)) << error;
  return poses;
}

// aas-refined accepts an estimate only while its steps are seen to converge: at these
// poses of the sweep, without the reflector, its first step lands near a fold of the
// equations, 27% from the equilibrium (a cable at s0/k 0.93-0.97 instead of 1.34-1.44)
// with an estimate of 0.2-0.6%, and its next steps diverge. With a loose tolerance that
// estimate alone passed it as ok.
TEST(StaticsTest, AasRefinedDoesNotAcceptAStall) {
  constexpr double kLooseTolerance = 1e-2;
  CableRobot robot = CableRobot::NominalFast();
  robot.reflector.reset();
  const std::vector<Pose> poses = Issue9SweepPoses(10000, 20260101);
  StaticsOptions loose;
  loose.method = StaticsMethod::kAasRefined;
  loose.refined_relative_tolerance = kLooseTolerance;
  for (int n : {962, 1969, 9218}) {
    const StaticsSolution exact = Solve(robot, poses[n], StaticsMethod::kExact);
    ASSERT_EQ(exact.status, StaticsStatus::kOk) << n;
    StaticsSolution s;
    if (SolveStatics(robot, poses[n], loose, &s) != StaticsStatus::kOk) continue;
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(s.cables[i].lower_tension_n, exact.cables[i].lower_tension_n,
                  kLooseTolerance * exact.cables[i].lower_tension_n)
          << "pose " << n << " cable " << i + 1;
    }
  }
}

using State = std::array<internal::CableState<double>, kNumCables>;

State StateOf(const StaticsSolution& s) {
  State st;
  for (int i = 0; i < kNumCables; ++i) {
    st[i] = {s.cables[i].horizontal_force_n, s.cables[i].force_n.z(),
             s.cables[i].unstretched_length_m};
  }
  return st;
}

// The test's own reference solver: full Newton steps on the equations (ReducedNewtonStep),
// followed along a straight path from a solved neighbour, the step halved on failure.
// Independent of SolveStatics's starts and checks; its results are checked below by
// their end conditions and equilibrium, computed here.
bool ReferenceNewton(const StaticsParameters<double>& p, const Pose& pose, State* st) {
  constexpr int kMaxSteps = 12;
  constexpr double kConvergedStep = 1e-8;  // relative |dFl|: the error left is ~1e-16
  internal::PoseGeometry<double> g;
  int cable = -1;
  if (internal::ComputeGeometry(p, pose, 1e-9, &g, &cable) != StaticsStatus::kOk) return false;
  for (int it = 0; it < kMaxSteps; ++it) {
    double step = 0.0, residual = 0.0;
    if (internal::ReducedNewtonStep(p, g, st, &cable, &step, &residual) != StaticsStatus::kOk) {
      return false;
    }
    if (step < kConvergedStep) return true;
  }
  return false;
}

bool ReferenceFollow(const StaticsParameters<double>& p, const Pose& from, State from_state,
                     const Pose& to, State* out) {
  constexpr double kMinStep = 1e-4;  // of the path; the library stops at 1e-3
  double t = 0.0, dt = 1.0;
  State st = from_state;
  while (t < 1.0) {
    const double next = std::min(1.0, t + dt);
    Pose pose;
    pose.position_m = (1.0 - next) * from.position_m + next * to.position_m;
    pose.rotation = Eigen::Quaterniond(from.rotation)
                        .slerp(next, Eigen::Quaterniond(to.rotation))
                        .toRotationMatrix();
    State trial = st;
    if (ReferenceNewton(p, pose, &trial)) {
      st = trial;
      t = next;
      dt *= 2.0;
    } else if ((dt *= 0.5) < kMinStep) {
      return false;
    }
  }
  *out = st;
  return true;
}

// What the reference equilibrium is, by the model's limits (StaticsOptions' defaults),
// computed here: s0 <= 0 or strain over max_strain, then s0/k over max_length_ratio,
// then a sampled point of a cable below the reflector's sphere, over its aperture.
StaticsStatus ClassifyReference(const CableRobot& robot, const Pose& pose, const State& st) {
  constexpr int kShapePoints = 400;
  const StaticsOptions limits;
  StaticsStatus status = StaticsStatus::kOk;
  for (int i = 0; i < kNumCables && status == StaticsStatus::kOk; ++i) {
    const double w = robot.cables[i].linear_density_kg_per_m * robot.gravity_m_per_s2;
    const double upper_n = CatenaryTension(st[i].fl, st[i].fz, st[i].s0, w);
    const double strain = std::max(std::hypot(st[i].fl, st[i].fz), upper_n) / robot.cables[i].ea_n;
    if (!(st[i].s0 > 0.0) || strain > limits.max_strain)
      status = StaticsStatus::kOverstretchedCable;
  }
  for (int i = 0; i < kNumCables && status == StaticsStatus::kOk; ++i) {
    if (st[i].s0 > limits.max_length_ratio * Chord(robot, pose, i).norm()) {
      status = StaticsStatus::kSaggingCable;
    }
  }
  for (int i = 0; i < kNumCables && status == StaticsStatus::kOk; ++i) {
    const Eigen::Vector3d anchor = pose.rotation * robot.AnchorOfCable(i) + pose.position_m;
    const Eigen::Vector3d chord = robot.cables[i].tower_top_m - anchor;
    const Eigen::Vector2d u = chord.head<2>().normalized();
    const Reflector& r = *robot.reflector;
    for (const CatenaryPoint& q : CatenaryShape(
             st[i].fl, st[i].fz, st[i].s0, robot.cables[i].ea_n,
             robot.cables[i].linear_density_kg_per_m * robot.gravity_m_per_s2, kShapePoints)) {
      const Eigen::Vector3d d =
          anchor + Eigen::Vector3d(u.x() * q.span_m, u.y() * q.span_m, q.rise_m) - r.centre_m;
      if (d.z() < 0.0 && d.head<2>().norm() < 0.5 * r.aperture_m && d.norm() > r.radius_m) {
        status = StaticsStatus::kReflectorContact;
      }
    }
  }
  return status;
}

// The test's own check of a returned solution: its end conditions (CatenaryEndpoint at
// the returned Fl, Fz, s0, against the chords computed here) and its equilibrium in vector
// form. Returns the largest end residual (m).
double CheckedEndResidualM(const CableRobot& robot, const Pose& pose, const StaticsSolution& s) {
  double largest_m = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    largest_m = std::max(largest_m, EndPointMissM(robot, pose, s.cables[i], i).norm());
  }
  double force_n, moment_nm;
  EquilibriumResiduals(robot, pose, s, &force_n, &moment_nm);
  EXPECT_LT(force_n, kForceResidualTolN);
  EXPECT_LT(moment_nm, kMomentResidualTolNm);
  return largest_m;
}

// The seeded sweep of issue 9, 10,000 poses: every ok of every method passes the test's
// own end-condition and equilibrium check and is within its method's promise of the
// reference; exact solves every pose where the reference (continuation from the nearest
// solved neighbour, in the order of the off-axis angle) finds an equilibrium within the
// model's range, and classifies the others as the reference does; the counts per status
// are those measured when this test was written (any change must be explained).
TEST(StaticsTest, Issue9SweepEveryOkIsProvedAndExactFindsEveryEquilibrium) {
  constexpr int kPoses = 10000;
  constexpr std::uint64_t kSeed = 20260101;
  constexpr double kExactRelTol = 1e-9;  // exact vs the reference (both ~1e-12)
  constexpr double kExactEndResidualM = 1e-6;
  // The reported end residual is the test's own, to rounding of the end point (~1e-13 m)
  // and, for aas, of its linearisation (0.5% of itself).
  constexpr double kEndResidualAgreement = 5e-3;
  constexpr double kEndResidualFloorM = 1e-9;
  // aas-refined is ok once its first-order estimate is below 1e-6; measured error up to
  // 1.0e-6 over this sweep.
  constexpr double kRefinedRelTol = 2e-6;
  const CableRobot robot = CableRobot::NominalFast();
  const StaticsParameters<double> p = MakeStaticsParameters(robot);
  const std::vector<Pose> poses = Issue9SweepPoses(kPoses, kSeed);

  // Reference equilibria, nearest the axis first, each from its nearest solved neighbour
  // within the model's range (K1 for the first).
  std::vector<int> order(kPoses);
  for (int n = 0; n < kPoses; ++n) order[n] = n;
  auto off_axis = [&](int n) { return poses[n].position_m.head<2>().norm(); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return off_axis(a) < off_axis(b); });
  Pose k1;
  k1.position_m = Eigen::Vector3d(0, 0, 140);
  std::vector<Pose> seeds = {k1};
  std::vector<Eigen::Quaterniond> seed_attitudes = {Eigen::Quaterniond(k1.rotation)};
  std::vector<State> seed_states = {StateOf(Solve(robot, k1, StaticsMethod::kExact))};
  // Distance between poses: of the positions, plus the rotation angle between the
  // attitudes times the anchors' radius (7.5 m): how far an anchor moves.
  constexpr double kAnchorRadiusM = 7.5;
  std::vector<bool> found(kPoses, false);
  std::vector<State> reference(kPoses);
  std::vector<StaticsStatus> expected(kPoses, StaticsStatus::kNoEquilibrium);
  for (int n : order) {
    double nearest = HUGE_VAL;
    size_t from = 0;
    const Eigen::Quaterniond attitude(poses[n].rotation);
    for (size_t k = 0; k < seeds.size(); ++k) {
      const double d = (seeds[k].position_m - poses[n].position_m).norm() +
                       kAnchorRadiusM * 2.0 *
                           std::acos(std::min(1.0, std::abs(seed_attitudes[k].dot(attitude))));
      if (d < nearest) {
        nearest = d;
        from = k;
      }
    }
    found[n] = ReferenceFollow(p, seeds[from], seed_states[from], poses[n], &reference[n]);
    if (!found[n]) continue;
    expected[n] = ClassifyReference(robot, poses[n], reference[n]);
    if (expected[n] == StaticsStatus::kOk) {
      seeds.push_back(poses[n]);
      seed_attitudes.push_back(attitude);
      seed_states.push_back(reference[n]);
    }
  }

  std::map<std::string, int> counts;
  for (int n = 0; n < kPoses; ++n) {
    ++counts[std::string("reference ") +
             (found[n] ? StaticsStatusName(expected[n]) : "none found")];
    const Pose& pose = poses[n];
    for (StaticsMethod m :
         {StaticsMethod::kExact, StaticsMethod::kAasRefined, StaticsMethod::kAas}) {
      const StaticsSolution s = Solve(robot, pose, m);
      ++counts[std::string(StaticsMethodName(m)) + " " + StaticsStatusName(s.status)];
      if (m == StaticsMethod::kExact && found[n]) {
        EXPECT_EQ(s.status, expected[n]) << "pose " << n << ": " << DescribeStatus(s);
      } else if (m == StaticsMethod::kExact) {
        // Where the reference path ends, exact's path from the home pose may still find an
        // equilibrium beyond the model's range; never one within it.
        EXPECT_NE(s.status, StaticsStatus::kOk) << "pose " << n;
      }
      if (s.status != StaticsStatus::kOk) continue;
      const double end_m = CheckedEndResidualM(robot, pose, s);
      EXPECT_NEAR(s.end_residual_m, end_m, kEndResidualAgreement * end_m + kEndResidualFloorM);
      if (m == StaticsMethod::kExact) {
        EXPECT_LT(end_m, kExactEndResidualM) << "pose " << n;
      }
      ASSERT_TRUE(found[n]) << StaticsMethodName(m) << " ok at pose " << n
                            << " where the reference found no equilibrium";
      const double promise = m == StaticsMethod::kExact ? kExactRelTol
                             : m == StaticsMethod::kAasRefined
                                 ? kRefinedRelTol
                                 : StaticsOptions().aas_max_relative_error;
      for (int i = 0; i < kNumCables; ++i) {
        const double t = std::hypot(reference[n][i].fl, reference[n][i].fz);
        EXPECT_NEAR(s.cables[i].lower_tension_n, t, promise * t)
            << StaticsMethodName(m) << " pose " << n << " cable " << i + 1;
      }
    }
  }
  // Measured when the test was written (seed 20260101). The reference's own verdicts
  // first (exact agrees with each, pose by pose, checked above); where its path finds
  // none, exact's from the home pose may find an equilibrium beyond the range (with
  // another seed, 2 of 109 poses), never one within it.
  const std::map<std::string, int> kExpectedCounts = {
      {"reference ok", 8920},
      {"reference reflector_contact", 5},
      {"reference sagging_cable", 947},
      {"reference overstretched_cable", 13},
      {"reference none found", 115},
      {"exact ok", 8920},
      {"exact reflector_contact", 5},
      {"exact sagging_cable", 947},
      {"exact overstretched_cable", 13},
      {"exact no_equilibrium", 115},
      {"aas-refined ok", 8892},
      {"aas-refined reflector_contact", 3},
      {"aas-refined sagging_cable", 20},
      {"aas-refined not_converged", 1085},
      {"aas ok", 7959},
      {"aas inaccurate", 2041},
  };
  EXPECT_EQ(counts, kExpectedCounts);
}

// Issue 29, item 7: where cables sag several equilibria can hold one pose. These models
// make them common on the cap: cables of 60 kg/m (five times FAST's, the plausible
// maximum; docs/data-format.md), with the nominal or a 10 t cabin.
CableRobot HeavyCableRobot(double cabin_mass_kg) {
  CableRobot robot = CableRobot::NominalFast();
  for (CableProperties& c : robot.cables) c.linear_density_kg_per_m = 60.0;
  robot.cabin_mass_kg = cabin_mass_kg;
  return robot;
}

Pose RpyPose(const Eigen::Vector3d& position_m, double roll_deg, double pitch_deg, double yaw_deg) {
  Pose pose;
  pose.position_m = position_m;
  pose.rotation = RotationFromRpyDeg(roll_deg, pitch_deg, yaw_deg);
  return pose;
}

// The test's own equilibrium connected to the home pose K1 = (0, 0, 140): the straight
// path from there (position, attitude by slerp) in kSteps equal steps, each point solved
// by ReferenceNewton from the one before, with no extrapolation: steps of ~0.3 m, far
// shorter than the continuation's, so that none can jump a fold. False where a point
// fails (the path's equilibrium ends).
bool FollowFromK1(const CableRobot& robot, const Pose& to, State* out) {
  constexpr int kSteps = 400;
  const StaticsParameters<double> p = MakeStaticsParameters(robot);
  Pose k1;
  k1.position_m = Eigen::Vector3d(0, 0, 140);
  State st = StateOf(Solve(robot, k1, StaticsMethod::kExact));
  for (int n = 1; n <= kSteps; ++n) {
    const double t = static_cast<double>(n) / kSteps;
    Pose pose;
    pose.position_m = (1.0 - t) * k1.position_m + t * to.position_m;
    pose.rotation = Eigen::Quaterniond(k1.rotation)
                        .slerp(t, Eigen::Quaterniond(to.rotation))
                        .toRotationMatrix();
    if (!ReferenceNewton(p, pose, &st)) return false;
  }
  *out = st;
  return true;
}

// The pose of the issue: solved alone, or after one 2 m away (warm start), exact gave two
// different equilibria, both ok (T1 515.2 kN alone, 405.5 kN after the other). Now both
// give the one connected to the home pose, and say that several hold the pose.
TEST(StaticsTest, AnswerDoesNotDependOnThePoseSolvedBefore) {
  constexpr double kSameRelTol = 1e-9;
  constexpr double kReferenceRelTol = 1e-7;  // the reference's Newton stops at 1e-8 steps
  const CableRobot robot = HeavyCableRobot(30000.0);
  const Pose before = RpyPose(Eigen::Vector3d(-111, -31, 182), -8, 23, 10);
  const Pose pose = RpyPose(Eigen::Vector3d(-111, -33, 182), -8, 23, 10);
  const StaticsSolution alone = Solve(robot, pose, StaticsMethod::kExact);
  StaticsOptions warm;
  warm.warm_start = true;
  StaticsSolution after;
  ASSERT_EQ(SolveStatics(robot, before, warm, &after), StaticsStatus::kOk);
  ASSERT_EQ(SolveStatics(robot, pose, warm, &after), StaticsStatus::kOk);
  ASSERT_EQ(alone.status, StaticsStatus::kOk) << DescribeStatus(alone);
  State reference;
  ASSERT_TRUE(FollowFromK1(robot, pose, &reference));
  for (int i = 0; i < kNumCables; ++i) {
    const double t = alone.cables[i].lower_tension_n;
    EXPECT_NEAR(after.cables[i].lower_tension_n, t, kSameRelTol * t) << "cable " << i + 1;
    EXPECT_NEAR(t, std::hypot(reference[i].fl, reference[i].fz), kReferenceRelTol * t)
        << "cable " << i + 1;
  }
  for (const StaticsSolution* s : {&alone, static_cast<const StaticsSolution*>(&after)}) {
    EXPECT_TRUE(s->other_equilibrium);
    EXPECT_EQ(s->branch, EquilibriumBranch::kFromHome);
    EXPECT_GE(s->taut_certificate, 0.5);
    EXPECT_STREQ(EquilibriumCode(*s), "several");
    EXPECT_NE(DescribeStatus(*s).find("several equilibria"), std::string::npos);
  }
}

// Where the home pose's branch ends at a fold before the pose, yet AAS's start finds an
// equilibrium there (cable 3 in a deep loop, once reported as sagging_cable), the answer
// is no_equilibrium, and the account says that another equilibrium exists.
TEST(StaticsTest, AnEquilibriumBeyondAFoldIsNotTheAnswerButIsNamed) {
  const CableRobot robot = HeavyCableRobot(30000.0);
  const StaticsSolution s =
      Solve(robot, RpyPose(Eigen::Vector3d(111, 0, 188), -9, -26, 4), StaticsMethod::kExact);
  EXPECT_EQ(s.status, StaticsStatus::kNoEquilibrium);
  EXPECT_TRUE(s.other_equilibrium);
  EXPECT_EQ(s.branch, EquilibriumBranch::kNone);
  EXPECT_STREQ(EquilibriumCode(s), "unreachable");
  const std::string text = DescribeStatus(s);
  EXPECT_NE(text.find("no equilibrium with positive cable forces reached from the home pose"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("another equilibrium holds this pose"), std::string::npos) << text;
  for (const CableSolution& c : s.cables) EXPECT_EQ(c.lower_tension_n, 0.0);
}

// exact's continuation from the home pose used to jump a fold on the way to this pose
// (60 kg/m, 10 t cabin): it reached an equilibrium with cable 3 in a loop (s0/k 5.7, the
// reflector pierced), on the far side of the fold, and reported reflector_contact. Each
// point of its path must now keep the home pose's side (det J of the reduced equilibrium
// against the straight cables'), and it finds the equilibrium the fine path finds.
TEST(StaticsTest, TheContinuationKeepsTheHomePosesSideOfEveryFold) {
  constexpr double kReferenceRelTol = 1e-7;
  const CableRobot robot = HeavyCableRobot(10000.0);
  const Pose pose = RpyPose(Eigen::Vector3d(-26, -111, 192), -19, -1, 11);
  const StaticsSolution s = Solve(robot, pose, StaticsMethod::kExact);
  ASSERT_EQ(s.status, StaticsStatus::kOk) << DescribeStatus(s);
  EXPECT_TRUE(s.continuation);
  EXPECT_EQ(s.branch, EquilibriumBranch::kFromHome);
  State reference;
  ASSERT_TRUE(FollowFromK1(robot, pose, &reference));
  for (int i = 0; i < kNumCables; ++i) {
    const double t = s.cables[i].lower_tension_n;
    EXPECT_NEAR(t, std::hypot(reference[i].fl, reference[i].fz), kReferenceRelTol * t)
        << "cable " << i + 1;
  }
}

// Seeded pairs over the cap with the heavy models: a pose solved warm after a neighbour a
// few metres and degrees away gives the cold solve's status and forces, and the same
// account of the equilibria (EquilibriumCode); the sweep meets every kind.
TEST(StaticsTest, WarmAndColdGiveTheSameEquilibriumWithSaggingCables) {
  constexpr int kPairs = 600;
  constexpr double kSameRelTol = 1e-9;
  constexpr double kNeighbourM = 3.0, kNeighbourDeg = 2.0;
  for (double cabin_kg : {30000.0, 10000.0}) {
    const CableRobot robot = HeavyCableRobot(cabin_kg);
    RandomPoseSpec spec = EdgeSweepSpec(kPairs, /*seed=*/29);
    spec.positions.max_off_axis_deg = 50.0;  // wider than the edge sweep: more sagging
    spec.positions.radial_spread_m = 10.0;
    spec.min_extra_rotation_deg = 5.0;
    spec.max_extra_rotation_deg = 12.0;
    std::vector<Pose> poses;
    std::string error;
    ASSERT_TRUE(RandomPosesAroundFocalLaw(spec, &poses, &error)) << error;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> metres(0.0, kNeighbourM), degrees(0.0, kNeighbourDeg);
    std::map<std::string, int> codes;
    for (const Pose& pose : poses) {
      Pose neighbour;
      neighbour.position_m =
          pose.position_m + Eigen::Vector3d(metres(rng), metres(rng), metres(rng));
      neighbour.rotation =
          pose.rotation * RotationFromRpyDeg(degrees(rng), degrees(rng), degrees(rng));
      StaticsOptions warm;
      warm.warm_start = true;
      StaticsSolution w;
      SolveStatics(robot, neighbour, warm, &w);
      SolveStatics(robot, pose, warm, &w);
      const StaticsSolution c = Solve(robot, pose, StaticsMethod::kExact);
      ++codes[std::string(StaticsStatusName(c.status)) + " " + EquilibriumCode(c)];
      ASSERT_EQ(w.status, c.status);
      EXPECT_STREQ(EquilibriumCode(w), EquilibriumCode(c));
      for (int i = 0; i < kNumCables; ++i) {
        const double t = c.cables[i].lower_tension_n;
        ASSERT_NEAR(w.cables[i].lower_tension_n, t, kSameRelTol * t) << "cable " << i + 1;
      }
    }
    // Measured: 219 taut, 47 home of 600 (157, 94 with the 10 t cabin); poses where the
    // cold solve meets several are rarer (1 in 400 over 4000 such poses; the tests above).
    for (const char* kind : {"ok taut", "ok home"}) {
      EXPECT_GT(codes[kind], 0) << kind << " (cabin " << cabin_kg << " kg)";
    }
  }
}

// On FAST's workspace cap, with its cables, every equilibrium is certified taut: no other
// equilibrium is that taut, and the solve needs no continuation to say so.
TEST(StaticsTest, EveryEquilibriumOfTheCapIsCertifiedTaut) {
  constexpr double kLargestCertificate = 0.05;  // measured 0.0024-0.0056 on the sphere
  const CableRobot robot = CableRobot::NominalFast();
  FocalGridSpec grid;
  grid.max_off_axis_deg = 40.0;
  grid.off_axis_step_deg = 5.0;
  grid.azimuth_step_deg = 15.0;
  std::vector<Eigen::Vector3d> positions;
  std::string error;
  ASSERT_TRUE(FocalSpherePositions(grid, &positions, &error)) << error;
  StaticsOptions warm;
  warm.warm_start = true;
  StaticsSolution w;
  for (const Eigen::Vector3d& position : positions) {
    const Pose pose = FocalPose(position);
    const StaticsSolution c = Solve(robot, pose, StaticsMethod::kExact);
    ASSERT_EQ(SolveStatics(robot, pose, warm, &w), StaticsStatus::kOk);
    for (const StaticsSolution* s : {&c, static_cast<const StaticsSolution*>(&w)}) {
      ASSERT_EQ(s->status, StaticsStatus::kOk);
      EXPECT_EQ(s->branch, EquilibriumBranch::kTaut);
      EXPECT_FALSE(s->other_equilibrium);
      EXPECT_FALSE(s->continuation);
      EXPECT_LT(s->taut_certificate, kLargestCertificate);
      EXPECT_STREQ(EquilibriumCode(*s), "taut");
    }
  }
  // aas and aas-refined say nothing about which equilibrium.
  EXPECT_STREQ(EquilibriumCode(Solve(robot, FocalPose(positions[0]), StaticsMethod::kAas)), "");
}

}  // namespace
}  // namespace fastcal
