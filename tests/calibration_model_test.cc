// The calibration's rows (internal/calibration_model.h): the analytic Jacobian of exact
// statics (implicit-function theorem and the sensors' own derivatives) against the
// ceres::Jet replay it replaced, for every parameter kind, common groups, sessions and
// readings kept out of the fit; and against central differences of the residuals.
#include "fastcal/internal/calibration_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fastcal/calibration_spec.h"
#include "fastcal/trajectory.h"
#include "test_robots.h"

namespace fastcal {
namespace {

using internal::CalibrationModel;
using internal::TensionCost;
using internal::TensionResidual;
using testing::AsBuiltRobot;
using testing::TiltedPoses;

constexpr int kMaxN = internal::kMaxFreeParameters;

// Every parameter the model has, free; per-cable groups per cable (`common` false) or as
// one common parameter each (true), which Assemble treats as one value for six cables.
CalibrationSpec EverythingFree(const CableRobot& robot, bool common) {
  CalibrationSpec spec;
  for (ParameterSpec p : AllModelParameters(robot)) {
    const bool group = p.kind == ParameterKind::kLinearDensity || p.kind == ParameterKind::kEa ||
                       p.kind == ParameterKind::kSensorGain || p.kind == ParameterKind::kSensorBias;
    if (group && (p.index < 0) != common) continue;
    p.free = true;
    spec.parameters.push_back(p);
  }
  return spec;
}

// theta off the model's values (gains and biases not at 1 and 0, the mass centre moved),
// so that every term of the sensor model is exercised.
std::vector<double> Moved(const CalibrationModel& model, std::uint64_t seed) {
  std::vector<double> theta = model.InitialTheta();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < model.num_free(); ++k) {
    const ParameterSpec& p = model.spec().parameters[model.spec_index(k)];
    switch (p.kind) {
      case ParameterKind::kSensorGain:
        theta[k] += 0.02 * u(rng);
        break;
      case ParameterKind::kSensorBias:
        theta[k] += 2000.0 * u(rng);
        break;
      case ParameterKind::kMassCentre:
      case ParameterKind::kAnchorOffset:
      case ParameterKind::kTowerOffset:
        theta[k] += 0.02 * u(rng);
        break;
      default:
        theta[k] *= 1.0 + 0.01 * u(rng);
    }
  }
  return theta;
}

TensionResidual ResidualAt(const CalibrationModel& model, const Pose& pose, int session) {
  TensionResidual f;
  f.model = &model;
  f.pose = pose;
  f.statics = ModelFitStaticsOptions(StaticsMethod::kExact);
  f.session = session;
  StaticsSolution s;
  std::array<double, kNumCables> reading{};
  EXPECT_EQ(SolveStatics(model.robot(), pose, f.statics, &s), StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) {
    reading[i] = s.cables[i].lower_tension_n * (1.0 + 0.03 * (i - 2.5) / 2.5);
  }
  f.measured_n = reading;
  f.sigma_n = internal::TensionSigmas(reading, 500.0, 3.0);
  f.start = internal::CompactStart::Of(s);
  return f;
}

// The analytic rows against the Jet's: the same residuals to the solves' tolerance (the
// Jet's value is one Newton step on), the same Jacobian to rounding.
void ExpectAnalyticMatchesJets(const CableRobot& robot, const CalibrationSpec& spec, int session) {
  constexpr double kResidualTol = 1e-8;  // whitened: ~1e-12 of a tension over 3% of it
  constexpr double kRelTol = 1e-8;       // of the Jacobian's largest entry in the column
  const CalibrationModel model(robot, spec);
  const int n = model.num_free();
  ASSERT_LE(n, kMaxN);
  const std::vector<double> theta = Moved(model, 5);
  for (const Pose& pose : TiltedPoses(4, 31)) {
    TensionResidual f = ResidualAt(model, pose, session);
    f.excluded[3] = true;
    std::vector<double> analytic(kNumCables * n), jet(kNumCables * n);
    double ra[kNumCables], rj[kNumCables];
    ASSERT_TRUE(f.Evaluate(theta.data(), ra, analytic.data())) << f(theta.data(), ra);
    ASSERT_TRUE(TensionCost::EvaluateJet(f, theta.data(), rj, jet.data()));
    for (int i = 0; i < kNumCables; ++i) EXPECT_NEAR(ra[i], rj[i], kResidualTol) << i;
    for (int k = 0; k < n; ++k) {
      double scale = 0.0;
      for (int i = 0; i < kNumCables; ++i) scale = std::max(scale, std::abs(jet[i * n + k]));
      const std::string name = spec.parameters[model.spec_index(k)].name;
      for (int i = 0; i < kNumCables; ++i) {
        EXPECT_NEAR(analytic[i * n + k], jet[i * n + k], kRelTol * scale)
            << name << " cable " << i + 1;
      }
    }
    for (int k = 0; k < n; ++k) EXPECT_EQ(analytic[3 * n + k], 0.0);  // the excluded reading
  }
}

TEST(CalibrationModelTest, AnalyticJacobianMatchesJetsForEveryParameterKind) {
  const CableRobot robot = AsBuiltRobot();
  ExpectAnalyticMatchesJets(robot, EverythingFree(robot, false), 0);
}

TEST(CalibrationModelTest, AnalyticJacobianMatchesJetsForCommonGroups) {
  const CableRobot robot = CableRobot::NominalFast();
  ExpectAnalyticMatchesJets(robot, EverythingFree(robot, true), 0);
}

TEST(CalibrationModelTest, ParametersOfAnotherSessionHaveZeroColumns) {
  // Two sessions' copies of the mass centre and the gains: a sample of session 1 sees its
  // own copies only (Jets and analytic alike), and zero columns for session 0's.
  const CableRobot robot = CableRobot::NominalFast();
  CalibrationSpec spec;
  for (int session = 0; session < 2; ++session) {
    for (ParameterSpec p : AllModelParameters(robot)) {
      if (p.kind != ParameterKind::kMassCentre &&
          !(p.kind == ParameterKind::kSensorGain && p.index >= 0)) {
        continue;
      }
      p.free = true;
      p.session = session;
      p.name += "@" + std::to_string(session);
      spec.parameters.push_back(p);
    }
  }
  ExpectAnalyticMatchesJets(robot, spec, 1);
  const CalibrationModel model(robot, spec);
  const int n = model.num_free();
  const std::vector<double> theta = model.InitialTheta();
  TensionResidual f = ResidualAt(model, TiltedPoses(1, 32)[0], 1);
  std::vector<double> j(kNumCables * n);
  double r[kNumCables];
  ASSERT_TRUE(f.Evaluate(theta.data(), r, j.data()));
  for (int k = 0; k < n; ++k) {
    const bool own = spec.parameters[model.spec_index(k)].session == 1;
    double largest = 0.0;
    for (int i = 0; i < kNumCables; ++i) largest = std::max(largest, std::abs(j[i * n + k]));
    EXPECT_EQ(largest > 0.0, own) << spec.parameters[model.spec_index(k)].name;
  }
}

// A central-difference step per kind: well above the solves' 1e-12, inside the linear range.
double Step(ParameterKind kind) {
  switch (kind) {
    case ParameterKind::kMassCentre:
    case ParameterKind::kAnchorOffset:
    case ParameterKind::kTowerOffset:
    case ParameterKind::kMeasuredOffset:
      return 1e-3;  // m
    case ParameterKind::kCabinMass:
      return 1.0;  // kg
    case ParameterKind::kLinearDensity:
    case ParameterKind::kAttachmentDensity:
      return 1e-3;  // kg/m
    case ParameterKind::kEa:
      return 1e3;  // N
    case ParameterKind::kSensorGain:
      return 1e-4;
    case ParameterKind::kSensorBias:
      return 1.0;  // N
    case ParameterKind::kAttachmentMass:
      return 1e-2;  // kg
    case ParameterKind::kLengthOffset:
      return 1e-3;  // m
    case ParameterKind::kPartFirstMoment:
      return 10.0;  // kg m
    case ParameterKind::kPartMass:
      return 1.0;  // kg
  }
  return 1e-3;
}

TEST(CalibrationModelTest, AnalyticJacobianMatchesCentralDifferencesOfTheResiduals) {
  // Independent of the Jets: each column against central differences of the residuals in
  // double (gain, bias, density, EA and offsets of the realistic spec's kinds).
  constexpr double kRelTol = 1e-6;
  const CableRobot robot = CableRobot::NominalFast();
  const CalibrationSpec spec = EverythingFree(robot, false);
  const CalibrationModel model(robot, spec);
  const int n = model.num_free();
  const std::vector<double> theta = Moved(model, 6);
  TensionResidual f = ResidualAt(model, TiltedPoses(1, 33)[0], 0);
  std::vector<double> j(kNumCables * n);
  double r[kNumCables];
  ASSERT_TRUE(f.Evaluate(theta.data(), r, j.data()));
  for (int k = 0; k < n; ++k) {
    const double h = Step(spec.parameters[model.spec_index(k)].kind);
    std::vector<double> up = theta, down = theta;
    up[k] += h;
    down[k] -= h;
    double ru[kNumCables], rd[kNumCables];
    ASSERT_TRUE(f.Evaluate(up.data(), ru, nullptr));
    ASSERT_TRUE(f.Evaluate(down.data(), rd, nullptr));
    double scale = 0.0;
    for (int i = 0; i < kNumCables; ++i) scale = std::max(scale, std::abs(ru[i] - rd[i]) / (2 * h));
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(j[i * n + k], (ru[i] - rd[i]) / (2 * h), kRelTol * scale + 1e-9)
          << spec.parameters[model.spec_index(k)].name << " cable " << i + 1;
    }
  }
}

}  // namespace
}  // namespace fastcal
