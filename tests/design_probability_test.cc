// Tests of the design's two uses of probability (design.h): poses held with a stated
// probability over the priors' joint distribution (internal/design_range.h: first-order
// reliability, solved exactly at the design point), checked by Monte Carlo draws of the
// truth at every designed stop; and the slow sensor error in the predictions
// (WhitenInTimeOrder) against a dense generalised-least-squares information.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/design.h"
#include "fastcal/internal/design_information.h"
#include "fastcal/statics.h"

namespace fastcal {
namespace {

constexpr double kMassCentreSigmaM = 0.05;
constexpr double kDensitySigmaKgPerM = 0.18;

// The mass centre and the common density under priors (their means the model's), a gain
// that does not move the forces.
CalibrationSpec Spec(const CableRobot& robot) {
  const Eigen::Vector3d& c = robot.mass_centre_cabin_m;
  char text[512];
  std::snprintf(text, sizeof text,
                "parameters:\n"
                "  mass_centre_m:\n"
                "    x: {free: true, prior: {mean: %.17g, sigma: %g}}\n"
                "    y: {free: true, prior: {mean: %.17g, sigma: %g}}\n"
                "    z: {free: true, prior: {mean: %.17g, sigma: %g}}\n"
                "  linear_density_kg_per_m: {free: true, prior: {mean: %.17g, sigma: %g}}\n"
                "  sensor_gain: {free: true, prior: {mean: 1, sigma: 0.01}}\n",
                c.x(), kMassCentreSigmaM, c.y(), kMassCentreSigmaM, c.z(), kMassCentreSigmaM,
                robot.cables[0].linear_density_kg_per_m, kDensitySigmaKgPerM);
  CalibrationSpec spec;
  std::string error;
  EXPECT_TRUE(ParseCalibrationSpecYaml(text, "spec", robot, &spec, &error)) << error;
  return spec;
}

DesignOptions TiltedCap(double hold_probability) {
  DesignOptions o;
  o.workspace.grid.off_axis_step_deg = 5.0;
  o.workspace.grid.azimuth_step_deg = 30.0;
  o.max_extra_tilt_deg = 5.0;
  o.samples = 60;
  o.hold_probability = hold_probability;
  o.wanted = {"mass_centre_m.x", "mass_centre_m.y", "mass_centre_m.z"};
  return o;
}

TEST(DesignHoldProbabilityTest, MonteCarloTruthsBreakADesignedStopNoMoreOftenThanStated) {
  const CableRobot robot = CableRobot::NominalFast();
  const CalibrationSpec spec = Spec(robot);
  // A probability large enough for draws to resolve it.
  constexpr double kHoldProbability = 0.02;
  const DesignOptions o = TiltedCap(kHoldProbability);
  Design d;
  std::string error;
  ASSERT_TRUE(DesignSurvey(robot, spec, o, &d, &error)) << error;
  EXPECT_GT(d.rejected_off_nominal, 0) << "the rule left no candidate out: it tests nothing";
  constexpr int kDraws = 400;
  std::mt19937_64 engine(20261128);
  std::normal_distribution<double> normal;
  int breaks = 0, draws = 0;
  for (const DesignStop& stop : d.stops) {
    const Pose& pose = d.candidates[stop.candidate].pose;
    int here = 0;
    for (int k = 0; k < kDraws; ++k) {
      CableRobot truth = robot;
      for (int axis = 0; axis < 3; ++axis) {
        truth.mass_centre_cabin_m[axis] += kMassCentreSigmaM * normal(engine);
      }
      const double density = kDensitySigmaKgPerM * normal(engine);
      for (CableProperties& c : truth.cables) c.linear_density_kg_per_m += density;
      StaticsSolution s;
      bool broken = SolveStatics(truth, pose, o.workspace.statics, &s) != StaticsStatus::kOk;
      for (int i = 0; i < kNumCables && !broken; ++i) {
        broken = s.cables[i].lower_tension_n < o.workspace.min_tension_n;
      }
      here += broken;
    }
    // Each stop: at most the stated probability, within 4 binomial sigmas of the draws.
    const double allowed =
        kHoldProbability + 4.0 * std::sqrt(kHoldProbability * (1 - kHoldProbability) / kDraws);
    EXPECT_LE(static_cast<double>(here) / kDraws, allowed)
        << "stop at " << pose.position_m.transpose();
    breaks += here;
    draws += kDraws;
  }
  const double pooled =
      kHoldProbability + 3.0 * std::sqrt(kHoldProbability * (1 - kHoldProbability) / draws);
  EXPECT_LE(static_cast<double>(breaks) / draws, pooled);
}

TEST(DesignHoldProbabilityTest, ASmallerProbabilityHoldsFewerCandidatesAndIsChecked) {
  const CableRobot robot = CableRobot::NominalFast();
  const CalibrationSpec spec = Spec(robot);
  Design loose, strict;
  std::string error;
  ASSERT_TRUE(DesignSurvey(robot, spec, TiltedCap(0.02), &loose, &error)) << error;
  ASSERT_TRUE(DesignSurvey(robot, spec, TiltedCap(1e-6), &strict, &error)) << error;
  EXPECT_LT(strict.candidates.size(), loose.candidates.size());
  DesignOptions o;
  for (double bad : {-1e-3, 0.5, std::nan("")}) {
    o.hold_probability = bad;
    EXPECT_FALSE(o.IsValid(&error));
    EXPECT_NE(error.find("hold_probability"), std::string::npos) << error;
  }
}

// The whitened rows' information equals J^T Sigma^-1 J per cable, Sigma = I + R K R with
// K_ts = exp(-|t - s| / tau) and R = diag(sigma_e(t) / s_t): the calibration's GLS.
TEST(DesignSlowErrorTest, WhitenedInformationEqualsDenseGls) {
  constexpr int kSamples = 7, kColumns = 3;
  const std::vector<double> times = {0.0, 1.0, 2.0, 2.5, 10.0, 11.0, 40.0};  // irregular
  SlowErrorProcess process;
  process.sigma_percent = 2.0;
  process.time_constant_s = 3.0;
  internal::DesignProblem pr;
  pr.n = 2;
  pr.q = 1;
  pr.rows = kNumCables;
  std::mt19937_64 engine(7);
  std::normal_distribution<double> normal;
  const int rows = kNumCables * kSamples;
  pr.x_rows.resize(rows, pr.n);
  pr.z_rows.resize(rows, pr.q);
  pr.reading.resize(rows);
  pr.white_sigma.resize(rows);
  for (int r = 0; r < rows; ++r) {
    for (int k = 0; k < pr.n; ++k) pr.x_rows(r, k) = normal(engine);
    pr.z_rows(r, 0) = normal(engine);
    pr.reading[r] = 1e6 * (1.0 + 0.2 * normal(engine));  // N
    pr.white_sigma[r] = 3e4;
  }
  const internal::DesignProblem white = pr;
  internal::WhitenInTimeOrder(process, times, &pr);
  Eigen::MatrixXd whitened(rows, kColumns), dense = Eigen::MatrixXd::Zero(kColumns, kColumns);
  whitened << pr.x_rows, pr.z_rows;
  for (int i = 0; i < kNumCables; ++i) {
    Eigen::MatrixXd j(kSamples, kColumns);
    Eigen::MatrixXd sigma = Eigen::MatrixXd::Identity(kSamples, kSamples);
    for (int t = 0; t < kSamples; ++t) {
      const int r = t * kNumCables + i;
      j.row(t) << white.x_rows.row(r), white.z_rows.row(r);
      for (int s = 0; s < kSamples; ++s) {
        const int q = s * kNumCables + i;
        const double rho_t = process.SigmaN(white.reading[r]) / white.white_sigma[r];
        const double rho_s = process.SigmaN(white.reading[q]) / white.white_sigma[q];
        sigma(t, s) += rho_t * rho_s * std::exp(-std::abs(times[t] - times[s]) / 3.0);
      }
    }
    dense += j.transpose() * sigma.llt().solve(j);
  }
  const Eigen::MatrixXd filtered = whitened.transpose() * whitened;
  constexpr double kRelative = 1e-10;
  EXPECT_LT((filtered - dense).norm(), kRelative * dense.norm());
  // And an inactive process leaves the rows alone.
  internal::DesignProblem same = white;
  internal::WhitenInTimeOrder(SlowErrorProcess(), times, &same);
  EXPECT_EQ(same.x_rows, white.x_rows);
}

TEST(DesignSlowErrorTest, PredictionsUseTheSpecsSlowErrorAndTheOptionsWhereItIsEstimated) {
  const CableRobot robot = CableRobot::NominalFast();
  CalibrationSpec spec = Spec(robot);
  DesignOptions o = TiltedCap(1e-4);
  EXPECT_FALSE(PredictionSlowError(spec, o).IsActive());  // the spec has none: white
  spec.slow_error.enabled = true;
  spec.slow_error.estimate_amplitude = true;
  spec.slow_error.estimate_time_constant = true;
  const SlowErrorProcess p = PredictionSlowError(spec, o);
  EXPECT_EQ(p.sigma_percent, o.slow_error_percent);
  EXPECT_EQ(p.time_constant_s, o.slow_error_time_s);
  // Correlated errors carry less information: every wanted sigma grows.
  Design slow, white;
  std::string error;
  ASSERT_TRUE(DesignSurvey(robot, spec, o, &slow, &error)) << error;
  spec.slow_error = SlowErrorSpec();
  ASSERT_TRUE(DesignSurvey(robot, spec, o, &white, &error)) << error;
  for (int k : slow.wanted) {
    EXPECT_GT(slow.design.budget.parameters[k].total, white.design.budget.parameters[k].total)
        << slow.free_names[k];
  }
}

}  // namespace
}  // namespace fastcal
