// Tests of the identified modes (modal_identification.h): the issue's records (free decays
// of three modes sampled at 10 Hz for 400 s, damping 0.4-1.5%, noise on the pose and the
// tensions) identified by ERA to 1% in frequency and 25% in damping, with sigmas that
// cover the errors; bad records and options refused.
#include "fastcal/modal_identification.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace fastcal {
namespace {

// Twelve channels as telemetry has them: x, y, z (m), roll, pitch, yaw (deg) and six
// tensions (kN); each mode moves them all, the cabin by centimetres and the tensions by
// kN; noise 2 mm, 0.005 deg and 0.5 kN (the tension sensors' 3% of a fluctuation).
FreeDecaySpec IssueRecord(std::uint64_t seed, const std::vector<double>& hz,
                          const std::vector<double>& zeta) {
  FreeDecaySpec spec;
  spec.frequency_hz = hz;
  spec.damping_ratio = zeta;
  spec.sample_interval_s = 0.1;
  spec.duration_s = 400.0;
  spec.seed = seed;
  std::mt19937_64 rng(seed + 1000);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), phase(0.0, 2.0 * M_PI);
  spec.shape.resize(12, 3);
  for (int c = 0; c < 12; ++c) {
    const double scale = c < 3 ? 0.05 : c < 6 ? 0.05 : 8.0;
    for (int j = 0; j < 3; ++j) spec.shape(c, j) = scale * unit(rng);
  }
  for (int j = 0; j < 3; ++j) spec.phase_rad.push_back(phase(rng));
  spec.noise_sigma.resize(12);
  for (int c = 0; c < 12; ++c) spec.noise_sigma[c] = c < 3 ? 0.002 : c < 6 ? 0.005 : 0.5;
  return spec;
}

// The issue's acceptance: frequencies to kFrequencyTol (1%), damping to kDampingTol (25%),
// on five independent records of modes near FAST's (0.15-0.37 Hz); and each error within
// kSigmas of its bootstrap sigma (the sigmas are not decoration).
TEST(IdentifyModesEra, RecoversTheIssuesFreeDecays) {
  constexpr double kFrequencyTol = 0.01, kDampingTol = 0.25, kSigmas = 5.0;
  const std::vector<std::vector<double>> frequencies = {{0.155, 0.182, 0.316},
                                                        {0.138, 0.201, 0.345},
                                                        {0.150, 0.160, 0.250},
                                                        {0.130, 0.190, 0.370},
                                                        {0.143, 0.185, 0.262}};
  const std::vector<double> zeta = {0.004, 0.008, 0.015};
  // Two of the five records (the first, and the one with the closest pair, 0.150 and
  // 0.160 Hz): each costs seconds of bootstrap, and all five were the suite's slowest test.
  for (int r : {0, 2}) {
    VibrationRecord record;
    std::string error;
    ASSERT_TRUE(SimulateFreeDecay(IssueRecord(7 + r, frequencies[r], zeta), &record, &error))
        << error;
    ASSERT_EQ(record.channels.cols(), 4001);
    std::vector<IdentifiedMode> modes;
    ASSERT_TRUE(IdentifyModesEra(record, EraOptions(), &modes, &error)) << error;
    ASSERT_EQ(modes.size(), 3u);
    for (int j = 0; j < 3; ++j) {
      const IdentifiedMode& m = modes[j];
      SCOPED_TRACE("record " + std::to_string(r) + " mode " + std::to_string(j));
      EXPECT_NEAR(m.frequency_hz / frequencies[r][j], 1.0, kFrequencyTol);
      EXPECT_NEAR(m.damping_ratio / zeta[j], 1.0, kDampingTol);
      EXPECT_GT(m.frequency_sigma_hz, 0.0);
      EXPECT_GT(m.damping_sigma, 0.0);
      EXPECT_LT(std::abs(m.frequency_hz - frequencies[r][j]), kSigmas * m.frequency_sigma_hz);
      EXPECT_LT(std::abs(m.damping_ratio - zeta[j]), kSigmas * m.damping_sigma);
    }
  }
}

TEST(IdentifyModesEra, RefusesWhatItCannotIdentify) {
  VibrationRecord record;
  record.channels = Eigen::MatrixXd::Random(6, 30);
  std::vector<IdentifiedMode> modes;
  std::string error;
  EXPECT_FALSE(IdentifyModesEra(record, EraOptions(), &modes, &error));
  EXPECT_NE(error.find("too short"), std::string::npos) << error;
  EraOptions options;
  options.bootstrap_records = 1;
  EXPECT_FALSE(IdentifyModesEra(record, options, &modes, &error));
  EXPECT_NE(error.find("bootstrap_records"), std::string::npos) << error;
  FreeDecaySpec spec;
  EXPECT_FALSE(SimulateFreeDecay(spec, &record, &error));
}

// Issue 57, 3: whether a record can show the band is decided before any work, in seconds
// (a record re-stamped every 1e-12 s overflowed an int cast and gave modes at 1.5e10 Hz;
// one every 1000 s gave modes at 1.5e-8 Hz).
TEST(IdentifyModesEra, RefusesARecordThatCannotShowTheBand) {
  VibrationRecord record;
  record.channels = Eigen::MatrixXd::Random(12, 4001);
  std::string error;
  record.sample_interval_s = 1e-12;
  EXPECT_FALSE(CheckRecordSampling(record, EraOptions(), &error));
  EXPECT_NE(error.find("spans 4e-09 s, too short for the band searched, 0.1 to 0.5 Hz: at least "
                       "80 s are needed"),
            std::string::npos)
      << error;
  record.sample_interval_s = 1e3;
  EXPECT_FALSE(CheckRecordSampling(record, EraOptions(), &error));
  EXPECT_NE(error.find("is sampled too slowly for the band searched, 0.1 to 0.5 Hz: 4 samples a "
                       "period of its top, one every 0.5 s or faster"),
            std::string::npos)
      << error;
  VibrationRecord days;  // 8102 samples every 0.5 s, 4050 s: over 400 periods of 0.1 Hz
  days.channels = Eigen::MatrixXd::Random(12, 8102);
  days.sample_interval_s = 0.5;
  EXPECT_FALSE(CheckRecordSampling(days, EraOptions(), &error));
  EXPECT_NE(error.find("longer than any free decay"), std::string::npos) << error;
  record.sample_interval_s = 0.1;
  EXPECT_TRUE(CheckRecordSampling(record, EraOptions(), &error)) << error;
  EraOptions options;
  options.modes = kMaxIdentifiedModes + 1;
  EXPECT_FALSE(CheckRecordSampling(record, options, &error));
}

// Issue 57, 13: asked for more modes than the record holds, ERA's extra poles fit the
// noise and were matched to predicted modes at +113%. A free decay of three modes asked
// for six: refused, saying how many it determines; asked for three: the three.
TEST(IdentifyModesEra, ModesTheRecordDoesNotDetermineAreNotReported) {
  VibrationRecord record;
  std::string error;
  const std::vector<double> hz = {0.155, 0.182, 0.316}, zeta = {0.004, 0.008, 0.015};
  ASSERT_TRUE(SimulateFreeDecay(IssueRecord(7, hz, zeta), &record, &error)) << error;
  EraOptions options;
  options.modes = 6;
  std::vector<IdentifiedMode> modes;
  EXPECT_FALSE(IdentifyModesEra(record, options, &modes, &error));
  EXPECT_NE(error.find("the record determines 3 of the 6 modes asked for"), std::string::npos)
      << error;
  options.modes = 3;
  ASSERT_TRUE(IdentifyModesEra(record, options, &modes, &error)) << error;
  ASSERT_EQ(modes.size(), 3u);
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(modes[j].frequency_hz / hz[j], 1.0, 0.01);
}

// Issue 57, 1: each excited mode is scaled so that the largest motion of a point of the
// cabin (O' or an anchor point) is the amplitude: mode 3 at the zenith turns the cabin
// about z and barely moves O' (scaled by O' alone its yaw was 4.7e10 deg). Noise-free, the
// record's first sample is the equilibrium plus that motion.
TEST(SimulateVibrationRecord, TheAmplitudeIsTheCabinsLargestMotion) {
  constexpr double kAmplitudeM = 0.05;
  constexpr double kRoundingM = 1e-9;  // the record's sums of the equilibrium and the motion
  const CableRobot robot = CableRobot::NominalFast();
  Pose pose;
  pose.position_m = Eigen::Vector3d(0.0, 0.0, 140.0);
  VibrationRecordSpec spec;
  spec.modes = {3};
  spec.damping_ratio = {0.01};
  spec.amplitude_m = kAmplitudeM;
  spec.position_noise_m = spec.attitude_noise_deg = spec.tension_noise_kn = 0.0;
  VibrationRecord record;
  std::string error;
  ASSERT_TRUE(SimulateVibrationRecord(robot, pose, spec, &record, &error)) << error;
  const Eigen::Vector3d u = record.channels.col(0).head<3>() - pose.position_m;
  const Eigen::Matrix3d rotation =
      RotationFromRpyDeg(record.channels(3, 0), record.channels(4, 0), record.channels(5, 0));
  double largest = u.norm();
  for (const Eigen::Vector3d& a : robot.anchor_points_cabin_m) {
    largest = std::max(largest, (u + rotation * a - a).norm());
  }
  EXPECT_NEAR(largest, kAmplitudeM, 1e-3 * kAmplitudeM + kRoundingM);
  EXPECT_LT(std::abs(record.channels(5, 0)), 1.0);  // yaw within a degree
  spec.amplitude_m = 1e6;
  EXPECT_FALSE(SimulateVibrationRecord(robot, pose, spec, &record, &error));
  EXPECT_NE(error.find("amplitude_m = 1e+06 m: must be in (0, 1] m"), std::string::npos) << error;
  spec.amplitude_m = kAmplitudeM;
  spec.sample_interval_s = 1e-300;
  EXPECT_FALSE(SimulateVibrationRecord(robot, pose, spec, &record, &error));
  EXPECT_NE(error.find("more than the 1000000 a record may hold"), std::string::npos) << error;
}

}  // namespace
}  // namespace fastcal
