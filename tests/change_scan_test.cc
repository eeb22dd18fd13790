// Tests of the change scan (change_scan.h) on linear problems made here: the false-alarm
// rate against the nominal significance, a step of known size and time found, binary
// segmentation of two steps; and through Calibrate on simulated telemetry with a step.
#include "fastcal/change_scan.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/simulation.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

constexpr int kRows = 6;

// A linear survey: N samples of 6 readings, J_t random (smoothly varying poses are not
// needed for the statistics), measured y_t = J_t theta + steps + white unit noise; the
// no-change least-squares fit's residuals r_t = J_t theta_hat - y_t, as a calibration's.
struct LinearSurvey {
  Eigen::MatrixXd residuals;
  SampleJacobians jacobians;
};

LinearSurvey MakeSurvey(int samples, int n,
                        const std::vector<std::pair<int, Eigen::VectorXd>>& steps,
                        const std::vector<int>& scanned, std::uint64_t seed,
                        const Eigen::VectorXd& ramp = Eigen::VectorXd()) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd j(samples * kRows, n);
  Eigen::VectorXd y(samples * kRows);
  for (int t = 0; t < samples; ++t) {
    for (int i = 0; i < kRows; ++i) {
      for (int k = 0; k < n; ++k) j(t * kRows + i, k) = 1.0 + normal(rng);
      double signal = 0.0;
      for (const auto& [at, shift] : steps) {
        if (t < at) continue;
        for (size_t g = 0; g < scanned.size(); ++g)
          signal += j(t * kRows + i, scanned[g]) * shift[g];
      }
      // A steady drift: `ramp` over the whole survey, centred.
      for (int g = 0; g < ramp.size(); ++g) {
        signal += j(t * kRows + i, scanned[g]) * ramp[g] * (t - 0.5 * (samples - 1)) / samples;
      }
      y[t * kRows + i] = signal + normal(rng);
    }
  }
  const Eigen::VectorXd theta = j.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd r = j * theta - y;
  LinearSurvey s;
  s.residuals.resize(samples, kRows);
  s.jacobians.resize(samples, kRows * n);
  for (int t = 0; t < samples; ++t) {
    for (int i = 0; i < kRows; ++i) {
      s.residuals(t, i) = r[t * kRows + i];
      s.jacobians.row(t).segment(i * n, n) = j.row(t * kRows + i).cast<float>();
    }
  }
  return s;
}

ChangeScanInputs Inputs(const LinearSurvey& s, int n, const std::vector<int>& scanned) {
  ChangeScanInputs in;
  in.residuals = &s.residuals;
  in.jacobians = &s.jacobians;
  in.num_free = n;
  in.prior_information = Eigen::VectorXd::Zero(n);
  in.prior_gradient = Eigen::VectorXd::Zero(n);
  in.scanned = scanned;
  in.min_segment = 10;
  in.replicates = 200;
  return in;
}

TEST(ChangeScanTest, FalseAlarmRateIsNearTheNominalLevel) {
  // 300 surveys without a change at a nominal 10%: the count is binomial (300, 0.1),
  // 30 +- 5.2; the window is about 3 of its standard deviations. Without the scan's own
  // null (the maximum judged as a single chi-square with 2 dof at 10%, 4.6) nearly every
  // survey would raise an alarm: the maximum over ~80 splits is not chi-square.
  constexpr int kSurveys = 300;
  constexpr int kMinAlarms = 15, kMaxAlarms = 46;
  const std::vector<int> scanned = {0, 1};
  int alarms = 0, above_naive = 0;
  for (int seed = 1; seed <= kSurveys; ++seed) {
    const LinearSurvey s = MakeSurvey(100, 4, {}, scanned, seed);
    ChangeScanInputs in = Inputs(s, 4, scanned);
    in.significance = 0.1;
    in.max_changes = 1;
    in.seed = 1000 + seed;
    ChangeScanOutput out;
    std::string error;
    ASSERT_TRUE(ScanForChanges(in, &out, &error)) << error;
    alarms += !out.changes.empty();
    above_naive += *std::max_element(out.statistic.begin(), out.statistic.end()) > 4.61;
  }
  EXPECT_GE(alarms, kMinAlarms);
  EXPECT_LE(alarms, kMaxAlarms);
  EXPECT_GT(above_naive, kSurveys / 2);
}

TEST(ChangeScanTest, AStepOfKnownSizeAndTimeIsFound) {
  // A step of (0.6, -0.4) at sample 130 of 200 (its sigma ~0.05): found at 130 within a
  // few samples, its size within 3 of its sigmas; once per seed over 10 seeds.
  constexpr int kFewSamples = 5;
  constexpr double kMaxPull = 3.0;
  const std::vector<int> scanned = {1, 2};
  Eigen::VectorXd shift(2);
  shift << 0.6, -0.4;
  for (int seed = 1; seed <= 10; ++seed) {
    const LinearSurvey s = MakeSurvey(200, 5, {{130, shift}}, scanned, seed);
    ChangeScanInputs in = Inputs(s, 5, scanned);
    in.seed = seed;
    ChangeScanOutput out;
    std::string error;
    ASSERT_TRUE(ScanForChanges(in, &out, &error)) << error;
    ASSERT_EQ(out.changes.size(), 1u) << "seed " << seed;
    const DetectedChange& c = out.changes[0];
    EXPECT_LE(std::abs(c.split - 130), kFewSamples) << "seed " << seed;
    EXPECT_LT(c.p_value, 0.01);
    EXPECT_GT(c.statistic, out.threshold);
    for (int g = 0; g < 2; ++g) {
      EXPECT_LT(std::abs(c.shift[g] - shift[g]) / c.shift_sigma[g], kMaxPull) << "seed " << seed;
    }
  }
}

TEST(ChangeScanTest, ASteadyDriftIsToldFromAStep) {
  // The same size of change, (0.6, -0.4), as a step at mid-survey or as a steady drift over
  // the whole survey: the best step's statistic beats the trend's for the step, the trend's
  // beats the step's for the drift, and the trend's estimate covers the drift.
  constexpr double kMaxPull = 3.0;
  const std::vector<int> scanned = {1, 2};
  Eigen::VectorXd change(2);
  change << 0.6, -0.4;
  for (int seed = 1; seed <= 5; ++seed) {
    ChangeScanOutput step, drift;
    std::string error;
    const LinearSurvey a = MakeSurvey(200, 5, {{100, change}}, scanned, seed);
    ASSERT_TRUE(ScanForChanges(Inputs(a, 5, scanned), &step, &error)) << error;
    EXPECT_GT(step.best_step_statistic, step.trend_statistic) << "seed " << seed;
    const LinearSurvey b = MakeSurvey(200, 5, {}, scanned, seed, change);
    ASSERT_TRUE(ScanForChanges(Inputs(b, 5, scanned), &drift, &error)) << error;
    EXPECT_GT(drift.trend_statistic, drift.best_step_statistic) << "seed " << seed;
    EXPECT_LT(drift.trend_p_value, 1e-6);
    for (int g = 0; g < 2; ++g) {
      EXPECT_LT(std::abs(drift.trend_shift[g] - change[g]) / drift.trend_shift_sigma[g], kMaxPull)
          << "seed " << seed;
    }
  }
  // Without a change the trend's statistic is chi-square with 2 degrees of freedom: its
  // p-value is not small on these seeds.
  const LinearSurvey none = MakeSurvey(200, 5, {}, scanned, 9);
  ChangeScanOutput out;
  std::string error;
  ASSERT_TRUE(ScanForChanges(Inputs(none, 5, scanned), &out, &error)) << error;
  EXPECT_GT(out.trend_p_value, 0.01);
}

TEST(ChangeScanTest, BinarySegmentationFindsTwoStepsInTimeOrder) {
  const std::vector<int> scanned = {0};
  Eigen::VectorXd up(1), down(1);
  up << 0.6;
  down << 0.6;
  const LinearSurvey s = MakeSurvey(300, 3, {{80, up}, {200, down}}, scanned, 7);
  ChangeScanInputs in = Inputs(s, 3, scanned);
  ChangeScanOutput out;
  std::string error;
  ASSERT_TRUE(ScanForChanges(in, &out, &error)) << error;
  ASSERT_EQ(out.changes.size(), 2u);
  EXPECT_NEAR(out.changes[0].split, 80, 3);
  EXPECT_NEAR(out.changes[1].split, 200, 3);
  EXPECT_NEAR(out.changes[0].shift[0], 0.6, 3 * out.changes[0].shift_sigma[0]);
  EXPECT_NEAR(out.changes[1].shift[0], 0.6, 3 * out.changes[1].shift_sigma[0]);
}

TEST(ChangeScanTest, WideningShrinksTheStatisticAndBadInputIsRefused) {
  const std::vector<int> scanned = {0};
  const LinearSurvey s = MakeSurvey(60, 3, {}, scanned, 3);
  ChangeScanInputs in = Inputs(s, 3, scanned);
  ChangeScanOutput plain, wide;
  std::string error;
  in.widening = 1.0;
  ASSERT_TRUE(ScanForChanges(in, &plain, &error)) << error;
  in.widening = 2.0;
  ASSERT_TRUE(ScanForChanges(in, &wide, &error)) << error;
  ASSERT_EQ(plain.statistic.size(), wide.statistic.size());
  for (size_t k = 0; k < plain.statistic.size(); ++k) {
    EXPECT_NEAR(wide.statistic[k], plain.statistic[k] / 4.0, 1e-12 * (1 + plain.statistic[k]));
  }
  EXPECT_EQ(plain.threshold, wide.threshold);  // the null is on the white scale
  // Too short for two segments: an empty scan, not an error.
  in.min_segment = 31;
  ASSERT_TRUE(ScanForChanges(in, &plain, &error)) << error;
  EXPECT_TRUE(plain.statistic.empty());
  in.scanned = {3};
  EXPECT_FALSE(ScanForChanges(in, &plain, &error));
  EXPECT_NE(error.find("out of range"), std::string::npos) << error;
}

TEST(ChangeScanTest, CalibrateFindsAMassCentreStepInSimulatedTelemetry) {
  // 300 random poses of the cap, 3% noise, gains 1% (free with their prior); the mass
  // centre steps by (6, 0, 4) cm at sample 180: one change, near sample 180, its size
  // within 3 sigma; the verdict says so and tells to fit per session.
  RandomWorkspaceSpec positions;
  positions.samples = 300;
  positions.seed = 21;
  std::vector<Eigen::Vector3d> points;
  std::vector<Pose> poses;
  std::string error;
  ASSERT_TRUE(RandomWorkspacePositions(positions, &points, &error)) << error;
  ASSERT_TRUE(PosesWithAttitudeLaw(points, FocalAttitudeLaw(), &poses, &error)) << error;
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = Eigen::Vector3d(0.2, 0.0, 0.5);
  SimulationOptions o;
  o.sensor_gain_spread_percent = 1.0;
  o.mass_centre_steps.push_back({180.0, Eigen::Vector3d(0.06, 0.0, 0.04)});
  o.seed = 21;
  Dataset data;
  ASSERT_TRUE(Simulate(truth, poses, o, &data, nullptr, nullptr, &error)) << error;
  CalibrationSpec spec;
  ASSERT_TRUE(ParseCalibrationSpecYaml(
      "parameters:\n  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}\n"
      "  sensor_gain: {mode: per_cable, free: true, prior: {mean: 1, sigma: 0.01}}\n"
      "change_scan: {parameters: [mass_centre_m], min_segment_samples: 30}\n",
      "spec", 6, &spec, &error))
      << error;
  CalibrationOptions options;
  options.change_scan_replicates = 300;
  CalibrationResult r;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &r, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_TRUE(r.change_scan.enabled);
  ASSERT_EQ(r.change_scan.changes.size(), 1u) << r.verdict_text;
  const FoundChange& c = r.change_scan.changes[0];
  EXPECT_NEAR(c.time_s, 180.0, 10.0);
  const double truth_shift[3] = {0.06, 0.0, 0.04};
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::abs(c.shift[k] - truth_shift[k]) / c.shift_sigma[k], 3.0)
        << r.change_scan.parameters[k];
  }
  EXPECT_NE(r.verdict_text.find("sessions: {separate: [mass_centre_m]}"), std::string::npos)
      << r.verdict_text;
  // Rows out of time order: the scan says so.
  std::swap(data.samples[10].time_s, data.samples[11].time_s);
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &r, &error),
            CalibrationStatus::kOk)
      << error;
  bool noted = false;
  for (const std::string& note : r.notes)
    noted |= note.find("time_s decreases at") != std::string::npos;
  EXPECT_TRUE(noted);
  // Scanning a group the fit separates per session is refused.
  spec.separate_groups = {"mass_centre_m"};
  data.session_labels = {"a", "b"};
  for (size_t t = 150; t < data.samples.size(); ++t) data.samples[t].session = 1;
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &r, &error),
            CalibrationStatus::kInvalidInput);
  EXPECT_NE(error.find("change_scan and sessions.separate"), std::string::npos) << error;
}

}  // namespace
}  // namespace fastcal

namespace fastcal {
namespace {

// The change time's interval and the wandering rule (SetChangeTimeAndWandering): a sharp
// peak of the scan's statistic is a step at a determined time; a plateau over half the
// survey is a change whose time is not determined: a wandering.
TEST(ChangeTimeTest, APlateauIsAWanderingAndAPeakAStep) {
  constexpr int kScanned = 3;  // the mass centre's axes: chi-square(3) 95% point 7.815
  ChangeScanResult scan;
  for (int k = 0; k < 100; ++k) scan.time_s.push_back(10.0 * k);
  scan.changes.resize(1);
  scan.best_step_statistic = 60.0;
  scan.trend_statistic = 20.0;
  // A peak: 60 at t = 500 s, at least 10 below it elsewhere.
  for (int k = 0; k < 100; ++k) scan.statistic.push_back(k == 50 ? 60.0 : 40.0);
  SetChangeTimeAndWandering(kScanned, &scan);
  EXPECT_EQ(scan.change_time_low_s, 500.0);
  EXPECT_EQ(scan.change_time_high_s, 500.0);
  EXPECT_FALSE(scan.wanders);
  // A plateau: within 7.8 of the best from t = 200 to 700 s (half the survey).
  for (int k = 0; k < 100; ++k) scan.statistic[k] = k >= 20 && k <= 70 ? 55.0 : 40.0;
  scan.statistic[50] = 60.0;
  SetChangeTimeAndWandering(kScanned, &scan);
  EXPECT_EQ(scan.change_time_low_s, 200.0);
  EXPECT_EQ(scan.change_time_high_s, 700.0);
  EXPECT_TRUE(scan.wanders);
  // No change found: never a wandering, whatever the statistic's shape.
  scan.changes.clear();
  SetChangeTimeAndWandering(kScanned, &scan);
  EXPECT_FALSE(scan.wanders);
}

}  // namespace
}  // namespace fastcal
