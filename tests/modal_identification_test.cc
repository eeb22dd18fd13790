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
  EXPECT_NE(error.find("too few"), std::string::npos) << error;
  EraOptions options;
  options.bootstrap_records = 1;
  EXPECT_FALSE(IdentifyModesEra(record, options, &modes, &error));
  EXPECT_NE(error.find("bootstrap_records"), std::string::npos) << error;
  FreeDecaySpec spec;
  EXPECT_FALSE(SimulateFreeDecay(spec, &record, &error));
}

}  // namespace
}  // namespace fastcal
