// Tests of the dynamics in time (dynamics.h): the static equilibrium a fixed point; the
// energy conserved without damping; a free decay's frequencies against the modes' and its
// damping against the stated ratio; second-order convergence in the step and 1/N^2 in the
// segments; a taut cable's transverse and axial waves against the string's and the bar's
// formulas; a slack segment carrying no force. Every tolerance is named with why.
#include "fastcal/dynamics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fastcal/catenary.h"
#include "fastcal/modal_identification.h"
#include "fastcal/modes.h"
#include "test_robots.h"

namespace fastcal {
namespace {

using testing::FocalSpherePose;

// A measured figure on stdout, for docs/model.md ("Dynamics", the checks).
void Figure(const std::string& text) { std::cout << "[ figure   ] " << text << std::endl; }
std::string Num(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

std::unique_ptr<CableDynamics> Make(const Pose& pose, const DynamicsOptions& options,
                                    double duration_s = 400.0) {
  std::string error;
  std::unique_ptr<CableDynamics> d =
      CableDynamics::Create(CableRobot::NominalFast(), pose, options, duration_s, &error);
  EXPECT_TRUE(d) << error;
  return d;
}

// Advances `d` in steps of `interval_s` to `end_s`, the winches held, calling `sample`
// after each.
template <typename Sample>
void Hold(CableDynamics* d, double interval_s, double end_s, Sample sample) {
  const std::array<double, kNumCables> s0 = d->UnstretchedLengthsM();
  std::string error;
  const int steps = static_cast<int>(std::lround(end_s / interval_s));
  for (int k = 1; k <= steps; ++k) {
    ASSERT_TRUE(d->Advance(k * interval_s, s0, &error)) << error;
    sample();
  }
}

// The mean period of an oscillation about 0 from its upward zero crossings (linear
// interpolation between samples), skipping the first `skip` crossings.
double MeanFrequencyHz(const std::vector<double>& x, double interval_s, int skip = 1) {
  std::vector<double> crossings;
  for (size_t k = 1; k < x.size(); ++k) {
    if (x[k - 1] < 0.0 && x[k] >= 0.0) {
      crossings.push_back((k - 1 + x[k - 1] / (x[k - 1] - x[k])) * interval_s);
    }
  }
  if (static_cast<int>(crossings.size()) < skip + 2) return 0.0;
  return (crossings.size() - 1 - skip) / (crossings.back() - crossings[skip]);
}

// The exact statics' equilibrium, held by the chains: at rest it stays where it is.
// The chains' equilibrium lies kStartOffsetM from the statics' pose (the polygon against
// the curve, 0.81 mm at N = 40 and falling as 1/N^2), its tensions kStartTension apart
// (3.4e-6 at the zenith, 1.7e-5 at 40 deg); over 300 s neither position nor tensions move more than
// rounding: kDriftM is the bound.
TEST(CableDynamics, StaticEquilibriumIsAFixedPoint) {
  constexpr double kStartOffsetM = 2e-3;
  constexpr double kStartTension = 5e-5;
  constexpr double kDriftM = 1e-6;
  constexpr double kTensionDrift = 1e-9;
  for (const Pose& pose : {FocalSpherePose(0.0, 0.0), FocalSpherePose(40.0, 30.0)}) {
    DynamicsOptions options;
    std::unique_ptr<CableDynamics> d = Make(pose, options);
    ASSERT_TRUE(d);
    EXPECT_LT(d->start().position_offset_m, kStartOffsetM);
    EXPECT_LT(d->start().tension_offset, kStartTension);
    const Pose start = d->CabinPose();
    const std::array<double, kNumCables> tension = d->LowerTensionsN();
    double drift = 0.0, tension_drift = 0.0;
    Hold(d.get(), 1.0, 300.0, [&]() {
      drift = std::max(drift, (d->CabinPose().position_m - start.position_m).norm());
      for (int i = 0; i < kNumCables; ++i) {
        tension_drift =
            std::max(tension_drift, std::abs(d->LowerTensionsN()[i] / tension[i] - 1.0));
      }
    });
    EXPECT_LT(drift, kDriftM) << pose.position_m.transpose();
    Figure("fixed point at z = " + Num(pose.position_m.z()) + " m: drift " + Num(drift) +
           " m, tensions " + Num(tension_drift) + ", start offset " +
           Num(d->start().position_offset_m) + " m, " + Num(d->start().tension_offset));
    EXPECT_LT(tension_drift, kTensionDrift);
    EXPECT_EQ(d->stats().halvings, 0);
  }
}

// Undamped (no structural damping, no drag, the trapezoidal rule), the energy of a free
// vibration stays what the displacement gave it: within kEnergy of it over 300 s (the
// issue's 1e-4; the trapezoidal rule conserves a linear system's energy exactly, and
// the geometry's nonlinearity at 0.1 m leaves ~6e-6). With damping it falls.
TEST(CableDynamics, EnergyConservedWithoutDamping) {
  constexpr double kEnergy = 1e-4;
  DynamicsOptions options;
  options.damping_ratio = 0.0;
  options.spectral_radius = 1.0;
  options.cabin_drag_area_m2 = 0.0;
  options.cable_drag_diameter_m = 0.0;
  std::unique_ptr<CableDynamics> d = Make(FocalSpherePose(20.0, 45.0), options);
  ASSERT_TRUE(d);
  std::string error;
  ASSERT_TRUE(
      d->Displace(Eigen::Vector3d(0.1, -0.05, 0.03), Eigen::Vector3d(0.0, 0.0, 2e-3), &error))
      << error;
  const double start = d->Energy().Total();
  ASSERT_GT(start, 100.0);  // J: the displacement's work against the cables and gravity
  double worst = 0.0, largest_kinetic = 0.0;
  Hold(d.get(), 0.5, 300.0, [&]() {
    worst = std::max(worst, std::abs(d->Energy().Total() / start - 1.0));
    largest_kinetic = std::max(largest_kinetic, d->Energy().kinetic_j);
  });
  EXPECT_LT(worst, kEnergy);
  Figure("energy: " + Num(start) + " J given, largest relative change " + Num(worst));
  EXPECT_GT(largest_kinetic, 0.5 * start);  // it did move

  options = DynamicsOptions();  // damped: 0.004 on the lowest mode, drag
  d = Make(FocalSpherePose(20.0, 45.0), options);
  ASSERT_TRUE(d->Displace(Eigen::Vector3d(0.1, -0.05, 0.03), Eigen::Vector3d::Zero(), &error));
  const double damped_start = d->Energy().Total();
  Hold(d.get(), 1.0, 300.0, []() {});
  EXPECT_LT(d->Energy().Total(), 0.5 * damped_start);
}

// One mode's free decay: the chains and the cabin moved along the mode's shape (5 cm at
// O'), released at rest, recorded at 20 Hz; the channel that moves most (pose or
// tension) from the equilibrium. No drag: the air adds ~5% to the lowest mode's damping
// at these amplitudes (quadratic drag: more as they grow).
struct Decay {
  std::vector<double> x;
  double frequency_hz = 0.0, damping_ratio = 0.0;
  int channel = 0;
};
constexpr double kDecayIntervalS = 0.05;

Decay ModeDecay(const Pose& pose, int mode, const DynamicsOptions& options, double duration_s,
                const CableDynamics** made = nullptr) {
  static std::unique_ptr<CableDynamics> d;
  d = Make(pose, options);
  Decay out;
  if (!d) return out;
  if (made != nullptr) *made = d.get();
  std::string error;
  QuasiStaticState rest;
  EXPECT_TRUE(d->QuasiStatic(d->UnstretchedLengthsM(), &rest, &error)) << error;
  EXPECT_TRUE(d->DisplaceAlongMode(mode, 0.05, &error)) << error;
  std::vector<Eigen::Matrix<double, 12, 1>> rows;
  auto sample = [&]() {
    Eigen::Matrix<double, 12, 1> row;
    row.head<3>() = d->CabinPose().position_m - rest.pose.position_m;
    const Eigen::AngleAxisd turn(d->CabinPose().rotation * rest.pose.rotation.transpose());
    row.segment<3>(3) = 10.0 * turn.angle() * turn.axis();  // a rotation at 10 m
    for (int i = 0; i < kNumCables; ++i) {
      row[6 + i] = (d->LowerTensionsN()[i] - rest.lower_tension_n[i]) / 1e5;  // 1e5 N a metre
    }
    rows.push_back(row);
  };
  sample();
  Hold(d.get(), kDecayIntervalS, duration_s, sample);
  double largest = 0.0;
  for (int k = 0; k < 12; ++k) {
    double sum = 0.0;
    for (const auto& row : rows) sum += row[k] * row[k];
    if (sum > largest) largest = sum, out.channel = k;
  }
  for (const auto& row : rows) out.x.push_back(row[out.channel]);
  out.frequency_hz = MeanFrequencyHz(out.x, kDecayIntervalS);
  // The damping from the peaks of |x| (two a period): their logarithms' slope.
  double st = 0, sy = 0, stt = 0, sty = 0, n = 0;
  for (size_t k = 1; k + 1 < out.x.size(); ++k) {
    const double a = std::abs(out.x[k]);
    if (a >= std::abs(out.x[k - 1]) && a > std::abs(out.x[k + 1])) {
      const double t = k * kDecayIntervalS, y = std::log(a);
      st += t, sy += y, stt += t * t, sty += t * y, n += 1;
    }
  }
  const double slope = (n * sty - st * sy) / (n * stt - st * st);
  out.damping_ratio = -slope / (2.0 * M_PI * out.frequency_hz);
  return out;
}

struct ModeCase {
  double zenith_deg, azimuth_deg;
  int mode;
};
const ModeCase kModeCases[] = {
    {0.0, 0.0, 1}, {0.0, 0.0, 4}, {0.0, 0.0, 10}, {40.0, 30.0, 1}, {40.0, 30.0, 2}};

// Undamped, each mode's free decay keeps the frequency `modes` predicts at the same
// segments: within kFrequency (the 0.3%). Measured: 2e-5 to 4e-5, and 3.3e-4 for the
// 40 deg mode 2, whose neighbour 0.6% away leaks into the zero crossings.
TEST(CableDynamics, FreeDecayFrequenciesAgreeWithModes) {
  constexpr double kFrequency = 3e-3;
  DynamicsOptions options;
  options.damping_ratio = 0.0;
  options.cabin_drag_area_m2 = 0.0;
  options.cable_drag_diameter_m = 0.0;
  for (const ModeCase& c : kModeCases) {
    const Pose pose = FocalSpherePose(c.zenith_deg, c.azimuth_deg);
    const Decay decay = ModeDecay(pose, c.mode, options, 200.0);
    ModesOptions modes_options;
    modes_options.segments = options.segments;
    ModesResult predicted;
    std::string error;
    ASSERT_TRUE(ComputeModes(CableRobot::NominalFast(), pose, modes_options, &predicted, &error));
    Figure(std::to_string(c.zenith_deg) + " deg mode " + std::to_string(c.mode) + ": " +
           Num(decay.frequency_hz) + " Hz, modes " + Num(predicted.modes[c.mode - 1].frequency_hz) +
           ", relative " +
           Num(decay.frequency_hz / predicted.modes[c.mode - 1].frequency_hz - 1.0));
    EXPECT_NEAR(decay.frequency_hz / predicted.modes[c.mode - 1].frequency_hz, 1.0, kFrequency)
        << c.zenith_deg << " deg, mode " << c.mode << ", channel " << decay.channel;
  }
}

// Damped as stated: the lowest mode's decay has the damping ratio 0.004 within kLowest
// (measured 0.00395 at the zenith, 0.00393 at 40 deg: the first-order estimate that set
// it is 1.3-1.7% high); each mode's is what the strain-rate damping gives it to first order
// (DynamicsStart) within kEach (measured 0.6-5%, and 11% for the 40 deg mode 2, coupled by
// the damping to its neighbour 0.6% away). The damping also moves the frequencies: up by
// 0.05% (the lowest) to 0.29% (the zenith's bounce, 2% from three undamped cable modes):
// non-proportional damping couples close modes.
TEST(CableDynamics, FreeDecayDampingAsStated) {
  constexpr double kLowest = 0.03;
  constexpr double kEach = 0.15;
  DynamicsOptions options;
  options.cabin_drag_area_m2 = 0.0;
  options.cable_drag_diameter_m = 0.0;
  for (const ModeCase& c : kModeCases) {
    const CableDynamics* d = nullptr;
    const Decay decay =
        ModeDecay(FocalSpherePose(c.zenith_deg, c.azimuth_deg), c.mode, options, 300.0, &d);
    ASSERT_TRUE(d);
    const std::string where = std::to_string(c.zenith_deg) + " deg, mode " + std::to_string(c.mode);
    EXPECT_NEAR(decay.damping_ratio / d->start().damping_ratio[c.mode - 1], 1.0, kEach) << where;
    Figure(where + ": zeta " + Num(decay.damping_ratio) + " against " +
           Num(d->start().damping_ratio[c.mode - 1]) + " (first order); f " +
           Num(decay.frequency_hz) + " Hz, undamped " + Num(d->start().frequency_hz[c.mode - 1]));
    if (c.mode == 1) {
      EXPECT_NEAR(decay.damping_ratio / options.damping_ratio, 1.0, kLowest) << where;
    }
  }
}

// Second order in the step: the cabin's x 30 s into a free decay moves by 4x less each
// time the step halves (measured ratios 4.1, 4.0, 4.0 from 80 ms); and as 1/N^2 in the
// segments, the lowest frequency of the chains (ratios 4.0, 4.0). kOrder bounds the
// ratios about 4.
TEST(CableDynamics, ConvergesInStepAndSegments) {
  constexpr double kOrder = 0.6;
  std::string error;
  auto x_at_30 = [&](double step_s) {
    DynamicsOptions options;
    options.segments = 20;
    options.max_step_s = step_s;
    std::unique_ptr<CableDynamics> d = Make(FocalSpherePose(0.0, 0.0), options, 40.0);
    EXPECT_TRUE(d->Displace(Eigen::Vector3d(0.1, 0.0, 0.05), Eigen::Vector3d::Zero(), &error));
    EXPECT_TRUE(d->Advance(30.0, d->UnstretchedLengthsM(), &error)) << error;
    return d->CabinPose().position_m.x();
  };
  std::vector<double> x;
  for (double h : {0.04, 0.02, 0.01}) x.push_back(x_at_30(h));
  EXPECT_NEAR((x[0] - x[1]) / (x[1] - x[2]), 4.0, kOrder);
  Figure("step ratio " + Num((x[0] - x[1]) / (x[1] - x[2])) + ", x(30 s) change at 20 ms " +
         Num(x[1] - x[2]) + " m");
  std::vector<double> f;
  for (int n : {10, 20, 40}) {
    DynamicsOptions options;
    options.segments = n;
    f.push_back(Make(FocalSpherePose(0.0, 0.0), options, 1.0)->start().frequency_hz[0]);
  }
  EXPECT_NEAR((f[1] - f[0]) / (f[2] - f[1]), 4.0, kOrder);
  Figure("segments ratio " + Num((f[1] - f[0]) / (f[2] - f[1])));
}

// A taut cable between fixed points (gravity 1e-3 of the Earth's: straight to 1e-7),
// 100 m, 1 kg/m, EA 1 MN, stretched 1%: the string's transverse waves
// f_n = (n / 2L) sqrt(T / mu) (T = 10 kN: 0.5 Hz) and the bar's axial ones
// f_n = (n / 2 s0) sqrt(EA / rho) (5 Hz). The chain of N segments has each times
// sin(x)/x, x = n pi / 2N (modes_test.cc); the generalised-alpha step lengthens the period
// by ~(omega h)^2 / 12: within kChain of the chain's value, and within the chain's own
// bound plus kChain of the continuum's.
TEST(FixedCableDynamics, TautStringAndBarWaves) {
  constexpr double kChain = 5e-4;
  constexpr int kSegments = 40;
  FixedCable cable;
  cable.span_m = 100.0;
  cable.ea_n = 1e6;
  cable.linear_density_kg_per_m = 1.0;
  cable.gravity_m_per_s2 = -9.8e-3;
  cable.unstretched_length_m = cable.span_m / 1.01;
  const double tension_n = cable.ea_n * 0.01;
  const double mu = cable.linear_density_kg_per_m * cable.unstretched_length_m / cable.span_m;
  DynamicsOptions options;
  options.segments = kSegments;
  options.damping_ratio = 0.0;
  options.cable_drag_diameter_m = 0.0;
  struct Case {
    FixedCableRelease::Kind kind;
    int harmonic;
    double step_s, duration_s, continuum_hz;
  };
  const double string_hz = std::sqrt(tension_n / mu) / (2.0 * cable.span_m);
  const double bar_hz =
      std::sqrt(cable.ea_n / cable.linear_density_kg_per_m) / (2.0 * cable.unstretched_length_m);
  for (const Case& c : {Case{FixedCableRelease::Kind::kTransverse, 1, 2e-3, 20.0, string_hz},
                        Case{FixedCableRelease::Kind::kTransverse, 3, 1e-3, 8.0, 3 * string_hz},
                        Case{FixedCableRelease::Kind::kAxial, 1, 2e-4, 2.0, bar_hz}}) {
    options.max_step_s = c.step_s;
    FixedCableRelease release;
    release.kind = c.kind;
    release.harmonic = c.harmonic;
    release.amplitude_m = c.kind == FixedCableRelease::Kind::kAxial ? 1e-3 : 0.05;
    FixedCableRecord record;
    std::string error;
    ASSERT_TRUE(
        SimulateFixedCable(cable, options, release, c.duration_s, c.step_s, &record, &error))
        << error;
    const double measured = MeanFrequencyHz(record.displacement_m, record.sample_interval_s);
    const double x = c.harmonic * M_PI / (2.0 * kSegments);
    const double chain_hz = c.continuum_hz * std::sin(x) / x;
    EXPECT_NEAR(measured / chain_hz, 1.0, kChain) << c.harmonic;
    Figure(std::string(c.kind == FixedCableRelease::Kind::kAxial ? "axial" : "transverse") +
           " n = " + std::to_string(c.harmonic) + ": " + Num(measured) + " Hz, chain " +
           Num(measured / chain_hz - 1.0) + ", continuum " + Num(measured / c.continuum_hz - 1.0));
    EXPECT_NEAR(measured / c.continuum_hz, 1.0, x * x / 6.0 + kChain) << c.harmonic;
  }
}

// A cable cannot push: released with an axial displacement larger than its stretch
// (1 m against 0.99 m), segments go slack; the lower end's tension falls to its half
// node's weight, never below, and the motion goes on (taut again, and beyond the static
// tension).
TEST(FixedCableDynamics, SlackSegmentsCarryNoForce) {
  FixedCable cable;
  cable.span_m = 100.0;
  cable.ea_n = 1e6;
  cable.linear_density_kg_per_m = 1.0;
  cable.gravity_m_per_s2 = -9.8e-3;
  cable.unstretched_length_m = cable.span_m / 1.01;
  DynamicsOptions options;
  options.segments = 20;
  options.max_step_s = 5e-4;
  FixedCableRelease release;
  release.kind = FixedCableRelease::Kind::kAxial;
  release.amplitude_m = 1.0;
  FixedCableRecord record;
  std::string error;
  ASSERT_TRUE(SimulateFixedCable(cable, options, release, 0.5, 5e-4, &record, &error)) << error;
  const auto [low, high] =
      std::minmax_element(record.lower_tension_n.begin(), record.lower_tension_n.end());
  EXPECT_GE(*low, 0.0);
  // Slack: the lowest segment pulls nothing, leaving the half node's weight (0.024 N).
  const double half_node_weight_n = 0.5 * 1.0 * cable.unstretched_length_m / 20 * 9.8e-3;
  EXPECT_LT(*low, 1.001 * half_node_weight_n);
  EXPECT_GT(*high, 1.5e4);  // and taut again, beyond the static 10 kN
}

TEST(DynamicsOptions, RefusesNonsense) {
  std::string error;
  DynamicsOptions o;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.segments = 1;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("segments"), std::string::npos);
  o = DynamicsOptions();
  o.damping_ratio = std::nan("");
  EXPECT_FALSE(o.IsValid(&error));
  o = DynamicsOptions();
  o.cable_damping_ratio = {0.01, 0.01};
  EXPECT_FALSE(o.IsValid(&error));
  o = DynamicsOptions();
  o.max_step_s = 0.0;
  EXPECT_FALSE(o.IsValid(&error));
  o = DynamicsOptions();
  o.wind.mean_speed_m_per_s = -1.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("wind"), std::string::npos);
  o = DynamicsOptions();
  o.statics.method = StaticsMethod::kAas;
  EXPECT_FALSE(o.IsValid(&error));
}

// A pose the statics cannot hold is refused with their account.
TEST(CableDynamics, RefusesAPoseTheStaticsCannotHold) {
  Pose pose;
  pose.position_m = Eigen::Vector3d(0.0, 0.0, 290.0);
  std::string error;
  EXPECT_FALSE(
      CableDynamics::Create(CableRobot::NominalFast(), pose, DynamicsOptions(), 10.0, &error));
  EXPECT_NE(error.find("statics cannot hold"), std::string::npos) << error;
}

// The modes' model checks (issue 57's plausibility) hold for the dynamics too: one check of
// what the chains describe (it took only IsValid before, which passes 1e300 kg m^2).
TEST(CableDynamics, RefusesAnImplausibleModelAsTheModesDo) {
  CableRobot robot = CableRobot::NominalFast();
  robot.cabin_inertia_kg_m2 = Eigen::Vector3d::Constant(1e300).asDiagonal();
  Pose pose;
  pose.position_m = Eigen::Vector3d(0.0, 0.0, 140.0);
  std::string error;
  EXPECT_FALSE(CableDynamics::Create(robot, pose, DynamicsOptions(), 10.0, &error));
  EXPECT_NE(error.find("model: cabin.inertia_kg_m2[0]: 1e+300 kg m^2"), std::string::npos) << error;
}

// Per-cable damping: each cable's tau from its own first axial mode's ratio.
TEST(CableDynamics, PerCableDamping) {
  DynamicsOptions options;
  options.cable_damping_ratio = {0.01, 0.01, 0.01, 0.01, 0.01, 0.02};
  std::unique_ptr<CableDynamics> d = Make(FocalSpherePose(0.0, 0.0), options, 1.0);
  ASSERT_TRUE(d);
  const std::array<double, kNumCables>& tau = d->start().damping_time_s;
  EXPECT_NEAR(tau[5] / tau[0], 2.0, 1e-9);  // the same lengths at the zenith
  const CableProperties c = CableRobot::NominalFast().cables[0];
  const double s0 = d->UnstretchedLengthsM()[0];
  const double omega = M_PI / s0 * std::sqrt(c.ea_n / c.linear_density_kg_per_m);
  EXPECT_NEAR(tau[0], 2.0 * 0.01 / omega, 1e-12);
}

}  // namespace
}  // namespace fastcal
