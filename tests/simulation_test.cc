// Tests of the telemetry simulator: exactness without noise, sensor model, noise
// statistics, reproducibility, density mismatch, outliers, errors, CSV round trip.
#include "fastcal/simulation.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fastcal/dataset.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

// Exact statics converge to 1e-12; warm and cold starts agree far better than this.
constexpr double kTensionRelTolerance = 1e-9;
constexpr double kLengthTolerance_m = 1e-9;
// Over N readings the sample RMS of a Gaussian has a standard error of sigma / sqrt(2N)
// and the mean sigma / sqrt(N); these allow about 4.5 standard errors at N = 2160.
constexpr double kNoiseSigma = 0.03;
constexpr double kRmsTolerance = 0.0021;
constexpr double kMeanTolerance = 0.0029;
// Binomial: outlier fraction 0.1 over 2160 readings has a standard error of 0.0065.
constexpr double kOutlierFraction = 0.1;
constexpr double kOutlierFractionTolerance = 0.03;
constexpr double kOutlierScalePercent = 30.0;

// The paper's measured circle, with the focal attitude law.
std::vector<Pose> Circle(int nodes) {
  ArcSpec arc;
  arc.centre_m = Eigen::Vector3d(0.0, 0.0, 156.73);
  arc.radius_m = 71.11;
  arc.start_deg = 0.0;
  arc.end_deg = 360.0;
  arc.nodes = nodes;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  std::string error;
  EXPECT_TRUE(ArcPositions(arc, &positions, &error)) << error;
  EXPECT_TRUE(PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, &error)) << error;
  return poses;
}

SimulationOptions NoNoise() {
  SimulationOptions o;
  o.tension_noise_percent = 0.0;
  return o;
}

StaticsSolution ExactAt(const CableRobot& robot, const Pose& pose) {
  StaticsOptions options;
  options.method = StaticsMethod::kExact;
  StaticsSolution s;
  EXPECT_EQ(SolveStatics(robot, pose, options, &s), StaticsStatus::kOk) << DescribeStatus(s);
  return s;
}

bool SameDataset(const Dataset& a, const Dataset& b) {
  if (a.samples.size() != b.samples.size()) return false;
  for (size_t n = 0; n < a.samples.size(); ++n) {
    const Sample& x = a.samples[n];
    const Sample& y = b.samples[n];
    if (x.time_s != y.time_s || x.pose.position_m != y.pose.position_m ||
        x.pose.rotation != y.pose.rotation || x.planned_rotation != y.planned_rotation ||
        x.tension_n != y.tension_n || x.unstretched_length_m != y.unstretched_length_m) {
      return false;
    }
  }
  return true;
}

TEST(SimulationTest, WithoutNoiseTensionsAreTheExactStaticsAtThePlannedPose) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(36);
  SimulationOptions options = NoNoise();
  options.sample_interval_s = 0.5;
  Dataset data;
  CableRobot used;
  SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, &used, &summary, &error)) << error;
  ASSERT_EQ(data.samples.size(), planned.size());
  EXPECT_TRUE(data.has_planned_attitude);
  EXPECT_TRUE(data.has_unstretched_lengths);
  EXPECT_EQ(summary.samples, 36);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_EQ(used.cables[i].linear_density_kg_per_m, truth.cables[i].linear_density_kg_per_m);
    EXPECT_EQ(summary.tension_noise_rms_n[i], 0.0);
  }
  for (size_t n = 0; n < planned.size(); ++n) {
    const Sample& s = data.samples[n];
    EXPECT_EQ(s.time_s, 0.5 * static_cast<double>(n));
    EXPECT_EQ(s.pose.position_m, planned[n].position_m);
    EXPECT_EQ(s.measured_rpy_deg, s.planned_rpy_deg) << "node " << n;
    EXPECT_EQ(s.pose.rotation, s.planned_rotation) << "node " << n;
    EXPECT_EQ(s.planned_rpy_deg, RpyDegFromRotation(planned[n].rotation));
    const StaticsSolution exact = ExactAt(truth, planned[n]);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(s.tension_n[i], exact.cables[i].lower_tension_n,
                  kTensionRelTolerance * exact.cables[i].lower_tension_n)
          << "node " << n << " cable " << i + 1;
      EXPECT_NEAR(s.unstretched_length_m[i], exact.cables[i].unstretched_length_m,
                  kLengthTolerance_m);
    }
  }
}

TEST(SimulationTest, SensorGainAndBiasApplyToTheReading) {
  CableRobot truth = CableRobot::NominalFast();
  const double gains[kNumCables] = {1.02, 0.98, 1.0, 1.05, 0.95, 1.01};
  const double biases_n[kNumCables] = {1500.0, -2000.0, 0.0, 500.0, 3000.0, -700.0};
  for (int i = 0; i < kNumCables; ++i) {
    truth.cables[i].sensor_gain = gains[i];
    truth.cables[i].sensor_bias_n = biases_n[i];
  }
  const std::vector<Pose> planned = Circle(8);
  Dataset data;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, NoNoise(), &data, nullptr, nullptr, &error)) << error;
  for (size_t n = 0; n < planned.size(); ++n) {
    const StaticsSolution exact = ExactAt(truth, planned[n]);
    for (int i = 0; i < kNumCables; ++i) {
      const double expected_n = gains[i] * exact.cables[i].lower_tension_n + biases_n[i];
      EXPECT_NEAR(data.samples[n].tension_n[i], expected_n, kTensionRelTolerance * expected_n)
          << "node " << n << " cable " << i + 1;
    }
  }
}

TEST(SimulationTest, RelativeTensionNoiseHasTheRequestedSigma) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(360);
  SimulationOptions options;
  options.tension_noise_percent = 100.0 * kNoiseSigma;
  Dataset data;
  SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, nullptr, &summary, &error)) << error;
  double sum = 0.0, sum_sq = 0.0;
  int count = 0;
  for (size_t n = 0; n < planned.size(); ++n) {
    const StaticsSolution exact = ExactAt(truth, planned[n]);
    for (int i = 0; i < kNumCables; ++i) {
      const double e = data.samples[n].tension_n[i] / exact.cables[i].lower_tension_n - 1.0;
      sum += e;
      sum_sq += e * e;
      ++count;
    }
  }
  ASSERT_EQ(count, 2160);
  EXPECT_NEAR(std::sqrt(sum_sq / count), kNoiseSigma, kRmsTolerance);
  EXPECT_NEAR(sum / count, 0.0, kMeanTolerance);
  EXPECT_EQ(summary.redrawn, 0);
  // The summary reports the same noise, per cable (360 readings each: wider tolerance).
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(summary.tension_noise_rms_relative[i], kNoiseSigma, 2.5 * kRmsTolerance);
  }
}

TEST(SimulationTest, PoseErrorsHaveTheRequestedSigmas) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(360);
  constexpr double kControlSigma_deg = 0.2;
  constexpr double kMeasurementSigma_deg = 0.02;
  constexpr double kPositionSigma_m = 0.01;
  // RMS over 1080 values: standard error sigma / sqrt(2160) ~ 2.2% of sigma.
  constexpr double kRelativeRmsTolerance = 0.1;
  SimulationOptions options;
  options.attitude_control_sigma_deg = kControlSigma_deg;
  options.attitude_measurement_sigma_deg = kMeasurementSigma_deg;
  options.position_measurement_sigma_m = kPositionSigma_m;
  Dataset data;
  SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, nullptr, &summary, &error)) << error;
  double attitude_sq = 0.0, position_sq = 0.0;
  for (size_t n = 0; n < planned.size(); ++n) {
    const Sample& s = data.samples[n];
    attitude_sq += (s.measured_rpy_deg - s.planned_rpy_deg).squaredNorm();
    position_sq += (s.pose.position_m - planned[n].position_m).squaredNorm();
  }
  const double values = 3.0 * static_cast<double>(planned.size());
  const double expected_attitude_deg = std::hypot(kControlSigma_deg, kMeasurementSigma_deg);
  EXPECT_NEAR(std::sqrt(attitude_sq / values), expected_attitude_deg,
              kRelativeRmsTolerance * expected_attitude_deg);
  EXPECT_NEAR(std::sqrt(position_sq / values), kPositionSigma_m,
              kRelativeRmsTolerance * kPositionSigma_m);
  EXPECT_NEAR(summary.attitude_control_rms_deg, kControlSigma_deg,
              kRelativeRmsTolerance * kControlSigma_deg);
  EXPECT_NEAR(summary.attitude_measurement_rms_deg, kMeasurementSigma_deg,
              kRelativeRmsTolerance * kMeasurementSigma_deg);
  EXPECT_NEAR(summary.position_measurement_rms_m, kPositionSigma_m,
              kRelativeRmsTolerance * kPositionSigma_m);
}

TEST(SimulationTest, TensionsComeFromTheActualNotThePlannedAttitude) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(12);
  // No measurement noise: the measured pose is the actual one.
  SimulationOptions options = NoNoise();
  options.attitude_control_sigma_deg = 0.5;
  Dataset data;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, nullptr, nullptr, &error)) << error;
  double largest_change = 0.0;
  for (size_t n = 0; n < planned.size(); ++n) {
    const Sample& s = data.samples[n];
    const StaticsSolution actual = ExactAt(truth, s.pose);
    const StaticsSolution at_plan = ExactAt(truth, planned[n]);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(s.tension_n[i], actual.cables[i].lower_tension_n,
                  kTensionRelTolerance * actual.cables[i].lower_tension_n);
      largest_change = std::max(largest_change,
                                std::abs(s.tension_n[i] / at_plan.cables[i].lower_tension_n - 1.0));
    }
  }
  EXPECT_GT(largest_change, 1e-3);  // a 0.5 deg attitude error moves tensions by ~1%
}

TEST(SimulationTest, SameSeedSameDatasetOtherSeedOtherDataset) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(24);
  SimulationOptions options;
  options.attitude_control_sigma_deg = 0.2;
  options.attitude_measurement_sigma_deg = 0.02;
  options.position_measurement_sigma_m = 0.01;
  options.outlier_fraction = 0.05;
  options.density_mismatch_percent = 1.0;
  options.seed = 42;
  Dataset a, b, c;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &a, nullptr, nullptr, &error)) << error;
  ASSERT_TRUE(Simulate(truth, planned, options, &b, nullptr, nullptr, &error)) << error;
  options.seed = 43;
  ASSERT_TRUE(Simulate(truth, planned, options, &c, nullptr, nullptr, &error)) << error;
  EXPECT_TRUE(SameDataset(a, b));
  EXPECT_FALSE(SameDataset(a, c));
  for (size_t n = 0; n < a.samples.size(); ++n) {
    EXPECT_NE(a.samples[n].tension_n[0], c.samples[n].tension_n[0]) << "node " << n;
  }
}

TEST(SimulationTest, EachErrorSourceHasItsOwnStream) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(12);
  SimulationOptions options;  // 3% tension noise
  Dataset quiet, noisy_position;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &quiet, nullptr, nullptr, &error)) << error;
  options.position_measurement_sigma_m = 0.05;
  ASSERT_TRUE(Simulate(truth, planned, options, &noisy_position, nullptr, nullptr, &error))
      << error;
  for (size_t n = 0; n < planned.size(); ++n) {
    EXPECT_EQ(quiet.samples[n].tension_n, noisy_position.samples[n].tension_n) << "node " << n;
    EXPECT_NE(quiet.samples[n].pose.position_m, noisy_position.samples[n].pose.position_m);
  }
}

// Lag-k autocorrelation of a series.
double Autocorrelation(const std::vector<double>& x, int lag) {
  double mean = 0.0;
  for (double v : x) mean += v / x.size();
  double c0 = 0.0, ck = 0.0;
  for (size_t t = 0; t < x.size(); ++t) {
    c0 += (x[t] - mean) * (x[t] - mean);
    if (t + lag < x.size()) ck += (x[t] - mean) * (x[t + lag] - mean);
  }
  return ck / c0;
}

// The slow tension error is an AR(1) per cable: its RMS and its lag-1 correlation
// exp(-dt / tau) are those asked for, and it is the same error the summary reports.
TEST(SimulationTest, TensionDriftIsAnAr1WithTheRequestedSigmaAndTime) {
  constexpr int kNodes = 2000;
  constexpr double kDriftPercent = 2.0, kTime_s = 20.0, kInterval_s = 1.0;
  constexpr double kRmsRelTol = 0.25;  // 2000 samples of tau ~ 39: ~50 independent
  constexpr double kRhoTol = 0.03;
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(kNodes);
  SimulationOptions options = NoNoise();
  options.tension_drift_percent = kDriftPercent;
  options.tension_drift_time_s = kTime_s;
  options.sample_interval_s = kInterval_s;
  Dataset quiet, drifting;
  SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, NoNoise(), &quiet, nullptr, nullptr, &error)) << error;
  ASSERT_TRUE(Simulate(truth, planned, options, &drifting, nullptr, &summary, &error)) << error;
  for (int i = 0; i < kNumCables; ++i) {
    std::vector<double> u;
    double sum2 = 0.0;
    for (int n = 0; n < kNodes; ++n) {
      u.push_back(drifting.samples[n].tension_n[i] / quiet.samples[n].tension_n[i] - 1.0);
      sum2 += u.back() * u.back();
    }
    EXPECT_NEAR(std::sqrt(sum2 / kNodes), summary.tension_drift_rms_relative[i], 1e-12);
    EXPECT_NEAR(summary.tension_drift_rms_relative[i], kDriftPercent / 100.0,
                kRmsRelTol * kDriftPercent / 100.0)
        << "cable " << i + 1;
    EXPECT_NEAR(Autocorrelation(u, 1), std::exp(-kInterval_s / kTime_s), kRhoTol);
  }
  // The poses are untouched: each error source has its own stream.
  for (int n = 0; n < kNodes; ++n) {
    EXPECT_EQ(drifting.samples[n].pose.rotation, quiet.samples[n].pose.rotation);
  }
}

// A smooth attitude control error: correlated from sample to sample; without a time it
// is white, the same numbers as before this option existed.
TEST(SimulationTest, AttitudeControlErrorCanBeSmooth) {
  constexpr int kNodes = 1000;
  constexpr double kSigmaDeg = 0.2, kTime_s = 30.0;
  constexpr double kRhoTol = 0.05;
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(kNodes);
  SimulationOptions options = NoNoise();
  options.attitude_control_sigma_deg = kSigmaDeg;
  for (double time_s : {0.0, kTime_s}) {
    options.attitude_control_time_s = time_s;
    Dataset data;
    std::string error;
    ASSERT_TRUE(Simulate(truth, planned, options, &data, nullptr, nullptr, &error)) << error;
    std::vector<double> roll;
    for (const Sample& s : data.samples)
      roll.push_back(s.measured_rpy_deg[0] - s.planned_rpy_deg[0]);
    EXPECT_NEAR(Autocorrelation(roll, 1), time_s > 0 ? std::exp(-1.0 / time_s) : 0.0, kRhoTol)
        << "time " << time_s;
  }
}

// The mass centre drifts about the truth model's: the tensions follow it, the truth
// model written out keeps the mean, the summary has the drift's RMS and average.
TEST(SimulationTest, MassCentreDriftsAboutTheTruth) {
  constexpr int kNodes = 600;
  constexpr double kDrift_m = 0.05, kTime_s = 50.0;
  constexpr double kRmsRelTol = 0.35;  // ~12 independent stretches per axis
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(kNodes);
  SimulationOptions options = NoNoise();
  options.mass_centre_drift_m = kDrift_m;
  options.mass_centre_drift_time_s = kTime_s;
  Dataset data, quiet;
  CableRobot used;
  SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, &used, &summary, &error)) << error;
  ASSERT_TRUE(Simulate(truth, planned, NoNoise(), &quiet, nullptr, nullptr, &error)) << error;
  EXPECT_EQ(used.mass_centre_cabin_m, truth.mass_centre_cabin_m);
  EXPECT_NEAR(summary.mass_centre_drift_rms_m, kDrift_m, kRmsRelTol * kDrift_m);
  EXPECT_GT((summary.mass_centre_mean_m - truth.mass_centre_cabin_m).norm(), 0.0);
  int moved = 0;
  for (int n = 0; n < kNodes; ++n) moved += data.samples[n].tension_n != quiet.samples[n].tension_n;
  EXPECT_EQ(moved, kNodes);
}

// Gains and biases drawn once per cable about the truth's: in the truth model written
// out, and the readings are gain * tension + bias with them.
TEST(SimulationTest, SensorGainAndBiasSpreadsAreDrawnOnceAndWrittenOut) {
  constexpr double kGainSpreadPercent = 1.0, kBiasSpreadKn = 2.0;
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(8);
  SimulationOptions options = NoNoise();
  options.sensor_gain_spread_percent = kGainSpreadPercent;
  options.sensor_bias_spread_kn = kBiasSpreadKn;
  Dataset data;
  CableRobot used;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, &used, nullptr, &error)) << error;
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NE(used.cables[i].sensor_gain, 1.0);
    EXPECT_LT(std::abs(used.cables[i].sensor_gain - 1.0), 5 * kGainSpreadPercent / 100.0);
    EXPECT_NE(used.cables[i].sensor_bias_n, 0.0);
    EXPECT_LT(std::abs(used.cables[i].sensor_bias_n), 5 * kBiasSpreadKn * 1e3);
  }
  for (size_t n = 0; n < planned.size(); ++n) {
    const StaticsSolution exact = ExactAt(used, planned[n]);
    for (int i = 0; i < kNumCables; ++i) {
      const double reading = used.cables[i].SensorReadingN(exact.cables[i].lower_tension_n);
      EXPECT_NEAR(data.samples[n].tension_n[i], reading, kTensionRelTolerance * reading);
    }
  }
}

// The length readings are the winches' encoders: each cable's s0 plus an offset drawn
// once (written into the truth model) plus white noise of the requested sigma; turning
// them on changes no other number.
TEST(SimulationTest, LengthReadingsHaveTheirOffsetsAndNoise) {
  constexpr double kOffsetSpreadM = 0.5, kNoiseM = 0.003;
  constexpr int kNodes = 360;  // 2160 readings: the RMS within kRmsTolerance relative
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(kNodes);
  SimulationOptions options;  // 3% tension noise
  Dataset plain, encoded;
  CableRobot used;
  SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &plain, nullptr, nullptr, &error)) << error;
  options.length_offset_spread_m = kOffsetSpreadM;
  options.length_noise_m = kNoiseM;
  ASSERT_TRUE(Simulate(truth, planned, options, &encoded, &used, &summary, &error)) << error;
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NE(used.cables[i].length_offset_m, 0.0) << i;
    EXPECT_LT(std::abs(used.cables[i].length_offset_m), 5 * kOffsetSpreadM) << i;
    EXPECT_EQ(summary.length_offset_m[i], used.cables[i].length_offset_m);
  }
  double sum2 = 0.0;
  for (size_t n = 0; n < planned.size(); ++n) {
    EXPECT_EQ(plain.samples[n].tension_n, encoded.samples[n].tension_n) << n;
    EXPECT_EQ(plain.samples[n].pose.rotation, encoded.samples[n].pose.rotation) << n;
    for (int i = 0; i < kNumCables; ++i) {
      // Without length errors the column is the truth's s0 (ExactAt agrees to 1e-9 m).
      const double s0 = plain.samples[n].unstretched_length_m[i];
      const double noise =
          encoded.samples[n].unstretched_length_m[i] - used.cables[i].EncoderReadingM(s0);
      sum2 += noise * noise;
    }
  }
  const double rms = std::sqrt(sum2 / (kNumCables * planned.size()));
  EXPECT_NEAR(rms / kNoiseM, 1.0, kRmsTolerance / kNoiseSigma);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(summary.length_noise_rms_m[i] / kNoiseM, 1.0, 3 * kRmsTolerance / kNoiseSigma);
  }
  const StaticsSolution exact = ExactAt(truth, planned[0]);
  EXPECT_NEAR(plain.samples[0].unstretched_length_m[0], exact.cables[0].unstretched_length_m,
              kLengthTolerance_m);
  // The offsets are in the truth model written out.
  CableRobot reread;
  ASSERT_TRUE(ParseCableRobotYaml(CableRobotToYaml(used, ""), "truth.yaml", &reread, &error))
      << error;
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_EQ(reread.cables[i].length_offset_m, used.cables[i].length_offset_m);
  }
  options.length_noise_m = -1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("length_noise_m"), std::string::npos) << error;
}

TEST(SimulationTest, DensityMismatchChangesTheTruthReproducibly) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(6);
  SimulationOptions options = NoNoise();
  options.density_mismatch_percent = 5.0;
  options.seed = 7;
  CableRobot used_a, used_b;
  SimulationSummary summary;
  Dataset data;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, &used_a, &summary, &error)) << error;
  ASSERT_TRUE(Simulate(truth, planned, options, nullptr, &used_b, nullptr, &error)) << error;
  for (int i = 0; i < kNumCables; ++i) {
    const double nominal = truth.cables[i].linear_density_kg_per_m;
    EXPECT_NE(used_a.cables[i].linear_density_kg_per_m, nominal) << "cable " << i + 1;
    EXPECT_EQ(used_a.cables[i].linear_density_kg_per_m, used_b.cables[i].linear_density_kg_per_m);
    EXPECT_EQ(used_a.cables[i].linear_density_kg_per_m, nominal * summary.density_factor[i]);
    EXPECT_LT(std::abs(summary.density_factor[i] - 1.0), 0.25);  // 5 sigma at 5%
  }
  // The tensions are those of the model actually used, not of the nominal one.
  for (size_t n = 0; n < planned.size(); ++n) {
    const StaticsSolution exact = ExactAt(used_a, planned[n]);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(data.samples[n].tension_n[i], exact.cables[i].lower_tension_n,
                  kTensionRelTolerance * exact.cables[i].lower_tension_n);
    }
  }
}

TEST(SimulationTest, OutlierFractionAndScaleAreRespected) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(360);
  SimulationOptions options = NoNoise();  // readings are exact unless outliers
  options.outlier_fraction = kOutlierFraction;
  options.outlier_scale_percent = kOutlierScalePercent;
  Dataset data;
  SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(Simulate(truth, planned, options, &data, nullptr, &summary, &error)) << error;
  int changed = 0;
  for (size_t n = 0; n < planned.size(); ++n) {
    const StaticsSolution exact = ExactAt(truth, planned[n]);
    for (int i = 0; i < kNumCables; ++i) {
      const double e = data.samples[n].tension_n[i] / exact.cables[i].lower_tension_n - 1.0;
      EXPECT_LE(std::abs(e), kOutlierScalePercent / 100.0);
      if (std::abs(e) > kTensionRelTolerance) ++changed;
    }
  }
  int reported = 0;
  for (int count : summary.outliers) reported += count;
  EXPECT_EQ(changed, reported);
  EXPECT_NEAR(static_cast<double>(changed) / 2160.0, kOutlierFraction, kOutlierFractionTolerance);
}

TEST(SimulationTest, InfeasiblePoseIsAnErrorNamingTheNode) {
  const CableRobot truth = CableRobot::NominalFast();
  std::vector<Pose> planned = Circle(4);
  planned[2].position_m = Eigen::Vector3d(330.0, 0.0, 150.0);  // beyond the towers
  planned[2].rotation.setIdentity();
  Dataset data;
  data.path = "untouched";
  std::string error;
  EXPECT_FALSE(Simulate(truth, planned, SimulationOptions(), &data, nullptr, nullptr, &error));
  EXPECT_NE(error.find("node 2 "), std::string::npos) << error;
  EXPECT_NE(error.find("330"), std::string::npos) << error;
  EXPECT_NE(error.find("cable"), std::string::npos) << error;  // DescribeStatus names the cable
  EXPECT_EQ(data.path, "untouched");
}

TEST(SimulationTest, InvalidOptionsAndInputsAreRejected) {
  const CableRobot truth = CableRobot::NominalFast();
  const std::vector<Pose> planned = Circle(4);
  std::string error;
  auto rejects = [&](SimulationOptions o, const std::string& field) {
    error.clear();
    EXPECT_FALSE(o.IsValid(&error)) << field;
    EXPECT_NE(error.find(field), std::string::npos) << error;
    EXPECT_FALSE(Simulate(truth, planned, o, nullptr, nullptr, nullptr, &error)) << field;
  };
  SimulationOptions o;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.attitude_control_sigma_deg = -0.1;
  rejects(o, "attitude_control_sigma_deg");
  o = SimulationOptions();
  o.tension_noise_percent = NAN;
  rejects(o, "tension_noise_percent");
  o = SimulationOptions();
  o.outlier_fraction = 1.5;
  rejects(o, "outlier_fraction");
  o = SimulationOptions();
  o.outlier_scale_percent = 100.0;
  rejects(o, "outlier_scale_percent");
  o = SimulationOptions();
  o.sample_interval_s = 0.0;
  rejects(o, "sample_interval_s");
  const std::pair<const char*, double SimulationOptions::*> kNonNegative[] = {
      {"attitude_control_time_s", &SimulationOptions::attitude_control_time_s},
      {"tension_drift_percent", &SimulationOptions::tension_drift_percent},
      {"tension_drift_time_s", &SimulationOptions::tension_drift_time_s},
      {"mass_centre_drift_m", &SimulationOptions::mass_centre_drift_m},
      {"mass_centre_drift_time_s", &SimulationOptions::mass_centre_drift_time_s},
      {"sensor_gain_spread_percent", &SimulationOptions::sensor_gain_spread_percent},
      {"sensor_bias_spread_kn", &SimulationOptions::sensor_bias_spread_kn}};
  for (const auto& [name, field] : kNonNegative) {
    o = SimulationOptions();
    o.*field = -1.0;
    rejects(o, name);
    o.*field = INFINITY;
    rejects(o, name);
  }

  EXPECT_FALSE(Simulate(truth, {}, SimulationOptions(), nullptr, nullptr, nullptr, &error));
  std::vector<Pose> bad = planned;
  bad[1].position_m.x() = NAN;
  EXPECT_FALSE(Simulate(truth, bad, SimulationOptions(), nullptr, nullptr, nullptr, &error));
  EXPECT_NE(error.find("node 1"), std::string::npos) << error;
  CableRobot negative_bias = truth;
  negative_bias.cables[3].sensor_bias_n = -1e7;
  EXPECT_FALSE(
      Simulate(negative_bias, planned, SimulationOptions(), nullptr, nullptr, nullptr, &error));
  EXPECT_NE(error.find("cable 4"), std::string::npos) << error;
}

TEST(SimulationTest, DatasetSurvivesWriteAndRead) {
  std::string pattern = ::testing::TempDir() + "simulation_test_XXXXXX";
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const fs::path dir = pattern;
  const std::string path = (dir / "sim.csv").string();

  SimulationOptions options;
  options.attitude_control_sigma_deg = 0.2;
  options.attitude_measurement_sigma_deg = 0.02;
  options.position_measurement_sigma_m = 0.01;
  options.outlier_fraction = 0.05;
  options.sample_interval_s = 0.1;
  Dataset written, read;
  std::string error;
  ASSERT_TRUE(
      Simulate(CableRobot::NominalFast(), Circle(36), options, &written, nullptr, nullptr, &error))
      << error;
  ASSERT_TRUE(WriteDataset(path, written, "simulated", &error)) << error;
  ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &read, &error)) << error;
  EXPECT_TRUE(read.has_planned_attitude);
  EXPECT_TRUE(read.has_unstretched_lengths);
  EXPECT_FALSE(read.attitude_as_quaternion);
  EXPECT_TRUE(SameDataset(written, read));
  for (size_t n = 0; n < read.samples.size(); ++n) {
    EXPECT_EQ(read.samples[n].measured_rpy_deg, written.samples[n].measured_rpy_deg);
    EXPECT_EQ(read.samples[n].planned_rpy_deg, written.samples[n].planned_rpy_deg);
  }
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}

TEST(SimulationTest, MassCentreStepsAndSessions) {
  // Noise-free: before the step the tensions are the truth's, from the step's time on
  // those of the truth with the mass centre moved; the sessions cut the samples in
  // equal consecutive parts, labelled 1..N.
  const std::vector<Pose> poses = Circle(10);
  ASSERT_EQ(poses.size(), 10u);
  const CableRobot truth = CableRobot::NominalFast();
  SimulationOptions o = NoNoise();
  o.sample_interval_s = 2.0;
  o.mass_centre_steps.push_back({8.0, Eigen::Vector3d(0.3, -0.2, 0.1)});
  o.sessions = 3;
  Dataset d;
  CableRobot used;
  std::string error;
  ASSERT_TRUE(Simulate(truth, poses, o, &d, &used, nullptr, &error)) << error;
  EXPECT_EQ(used.mass_centre_cabin_m, truth.mass_centre_cabin_m);  // before the step
  CableRobot moved = truth;
  moved.mass_centre_cabin_m += Eigen::Vector3d(0.3, -0.2, 0.1);
  for (size_t n = 0; n < poses.size(); ++n) {
    const StaticsSolution expected = ExactAt(d.samples[n].time_s >= 8.0 ? moved : truth, poses[n]);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(d.samples[n].tension_n[i] / expected.cables[i].lower_tension_n, 1.0,
                  kTensionRelTolerance)
          << "sample " << n << " cable " << i + 1;
    }
  }
  EXPECT_EQ(d.session_labels, (std::vector<std::string>{"1", "2", "3"}));
  const int expected_session[10] = {0, 0, 0, 0, 1, 1, 1, 2, 2, 2};
  for (size_t n = 0; n < poses.size(); ++n) EXPECT_EQ(d.samples[n].session, expected_session[n]);
  // More sessions than poses, and a non-finite step, are refused.
  o.sessions = 11;
  EXPECT_FALSE(Simulate(truth, poses, o, &d, nullptr, nullptr, &error));
  EXPECT_NE(error.find("11 sessions for 10 poses"), std::string::npos) << error;
  o.sessions = 1;
  o.mass_centre_steps[0].time_s = std::nan("");
  EXPECT_FALSE(Simulate(truth, poses, o, &d, nullptr, nullptr, &error));
  EXPECT_NE(error.find("mass_centre_steps"), std::string::npos) << error;
}

// The wander inside days about a level that stays (mass_centre_drift_centred): each
// session's drift has zero mean, so the samples' average mass centre is the truth's; drawn
// as the plain process it is not.
TEST(SimulationTest, CentredDriftKeepsEachSessionsMeanMassCentre) {
  const std::vector<Pose> poses = Circle(60);
  const CableRobot truth = CableRobot::NominalFast();
  SimulationOptions o = NoNoise();
  o.sample_interval_s = 10.0;
  o.sessions = 3;
  o.session_gap_s = 80000.0;
  o.mass_centre_drift_m = 0.01;
  o.mass_centre_drift_time_s = 300.0;
  for (const bool centred : {true, false}) {
    o.mass_centre_drift_centred = centred;
    Dataset d;
    SimulationSummary summary;
    std::string error;
    ASSERT_TRUE(Simulate(truth, poses, o, &d, nullptr, &summary, &error)) << error;
    const double off = (summary.mass_centre_mean_m - truth.mass_centre_cabin_m).norm();
    EXPECT_GT(summary.mass_centre_drift_rms_m, 0.004) << "centred " << centred;
    if (centred) {
      EXPECT_LT(off, 1e-12);
    } else {
      EXPECT_GT(off, 1e-4);  // three sessions of 200 s, tau 300 s: their means wander
    }
  }
}

std::string FileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// fastcal simulate streams (issue 20): SimulateStream into a DatasetWriter writes the
// same bytes as Simulate then WriteDataset, with the same truth model and summary; the
// writer refuses an existing file, a file of no rows and a row the reader would refuse.
TEST(SimulationTest, StreamedSimulationWritesTheSameFile) {
  std::string pattern = ::testing::TempDir() + "simulation_stream_XXXXXX";
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const fs::path dir = pattern;
  const std::string whole = (dir / "whole.csv").string();
  const std::string streamed = (dir / "streamed.csv").string();
  SimulationOptions options;
  options.attitude_control_sigma_deg = 0.2;
  options.tension_drift_percent = 1.0;
  options.mass_centre_drift_m = 0.05;
  options.outlier_fraction = 0.05;
  const std::vector<Pose> planned = Circle(72);
  Dataset data;
  CableRobot used_whole, used_streamed;
  SimulationSummary summary_whole, summary_streamed;
  std::string error;
  ASSERT_TRUE(Simulate(CableRobot::NominalFast(), planned, options, &data, &used_whole,
                       &summary_whole, &error))
      << error;
  ASSERT_TRUE(WriteDataset(whole, data, "simulated\ntwo lines", &error)) << error;

  DatasetWriter writer;
  ASSERT_TRUE(writer.Open(streamed, SimulatedDatasetLayout(), "simulated\ntwo lines", &error))
      << error;
  const SampleSink sink = [&](const Sample& s, std::string* why) { return writer.Write(s, why); };
  ASSERT_TRUE(SimulateStream(CableRobot::NominalFast(), planned, options, sink, &used_streamed,
                             &summary_streamed, &error))
      << error;
  ASSERT_TRUE(writer.Close(&error)) << error;
  EXPECT_EQ(FileText(streamed), FileText(whole));
  EXPECT_EQ(used_streamed.mass_centre_cabin_m, used_whole.mass_centre_cabin_m);
  EXPECT_EQ(summary_streamed.tension_noise_rms_n, summary_whole.tension_noise_rms_n);
  EXPECT_EQ(summary_streamed.samples, summary_whole.samples);

  DatasetWriter again;
  EXPECT_FALSE(again.Open(streamed, SimulatedDatasetLayout(), "", &error));
  EXPECT_NE(error.find("streamed.csv: cannot create"), std::string::npos) << error;
  DatasetWriter empty;
  ASSERT_TRUE(empty.Open((dir / "empty.csv").string(), SimulatedDatasetLayout(), "", &error));
  EXPECT_FALSE(empty.Close(&error));
  EXPECT_NE(error.find("no samples to write"), std::string::npos) << error;
  DatasetWriter bad;
  ASSERT_TRUE(bad.Open((dir / "bad.csv").string(), SimulatedDatasetLayout(), "", &error));
  Sample nan = data.samples.front();
  nan.tension_n[2] = std::nan("");
  EXPECT_FALSE(bad.Write(nan, &error));
  EXPECT_NE(error.find("samples[0]"), std::string::npos) << error;
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}

// fastcal simulate draws its planned poses as it goes (issue 20: memory independent of
// the number of samples): a PoseStream gives the samples the pose vector gives, and the
// caller's stream is not advanced (SimulateStream works on a copy).
TEST(SimulationTest, PoseStreamSimulatesTheSameSamplesAsThePoseVector) {
  SimulationOptions options;
  options.attitude_control_sigma_deg = 0.2;
  options.outlier_fraction = 0.05;
  options.sessions = 2;
  const std::vector<Pose> planned = Circle(40);
  Dataset whole;
  ASSERT_TRUE(
      Simulate(CableRobot::NominalFast(), planned, options, &whole, nullptr, nullptr, nullptr));
  PoseStream stream;
  stream.count = static_cast<long long>(planned.size());
  stream.next = [&planned, n = size_t{0}]() mutable { return planned[n++]; };
  std::vector<Sample> streamed;
  const SampleSink keep = [&streamed](const Sample& s, std::string*) {
    streamed.push_back(s);
    return true;
  };
  std::string error;
  ASSERT_TRUE(
      SimulateStream(CableRobot::NominalFast(), stream, options, keep, nullptr, nullptr, &error))
      << error;
  ASSERT_EQ(streamed.size(), whole.samples.size());
  for (size_t n = 0; n < streamed.size(); ++n) {
    EXPECT_EQ(streamed[n].tension_n, whole.samples[n].tension_n) << n;
    EXPECT_EQ(streamed[n].pose.position_m, whole.samples[n].pose.position_m) << n;
    EXPECT_EQ(streamed[n].session, whole.samples[n].session) << n;
  }
  EXPECT_EQ(stream.next().position_m, planned[0].position_m);  // not advanced by the run

  // A non-finite pose is named when drawn, as the vector's check names it.
  Pose bad = planned[5];
  bad.position_m.x() = std::nan("");
  PoseStream broken;
  broken.count = 10;
  broken.next = [&planned, bad, n = 0]() mutable { return n == 5 ? (++n, bad) : planned[n++]; };
  EXPECT_FALSE(SimulateStream(CableRobot::NominalFast(), broken, SimulationOptions(), keep, nullptr,
                              nullptr, &error));
  EXPECT_EQ(error, "planned pose of node 5 is not finite");
}

}  // namespace
}  // namespace fastcal
