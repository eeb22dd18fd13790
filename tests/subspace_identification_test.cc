// Tests of the ambient identification (subspace_identification.h): SSI-cov on synthetic
// ambient records of known poles (white-noise-driven modes, seeded) recovers frequencies to
// 1% and damping to 30% with jackknife sigmas that cover the errors; a free decay and an
// ambient record are told apart by their envelopes; bad records and options are refused.
#include "fastcal/subspace_identification.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace fastcal {
namespace {

// Six channels (a pose's), each mode spread over them by a seeded random shape, white
// measurement noise at kNoiseFraction of the channel's motion; three hours at 2 Hz (an
// hour's damping ratios scatter by ~20%: 1 / sqrt(zeta omega T) of them).
AmbientRecordSpec Ambient(std::uint64_t seed, const std::vector<double>& hz,
                          const std::vector<double>& zeta) {
  constexpr double kNoiseFraction = 0.2;
  AmbientRecordSpec spec;
  spec.frequency_hz = hz;
  spec.damping_ratio = zeta;
  spec.sample_interval_s = 0.5;
  spec.duration_s = 10800.0;
  spec.seed = seed;
  std::mt19937_64 rng(seed + 1000);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int modes = static_cast<int>(hz.size());
  spec.shape.resize(6, modes);
  for (int c = 0; c < 6; ++c) {
    for (int j = 0; j < modes; ++j) spec.shape(c, j) = unit(rng);
  }
  spec.noise_sigma = kNoiseFraction * spec.shape.rowwise().norm();
  return spec;
}

// Frequencies to kFrequencyTol (1%), damping to kDampingTol (30%), the bounds, on
// independent records of modes near FAST's (one a test); each error within kSigmas of its
// jackknife sigma.
class SsiKnownPoles : public ::testing::TestWithParam<int> {};

TEST_P(SsiKnownPoles, RecoversFrequenciesAndDampingWithinTheirSigmas) {
  constexpr double kFrequencyTol = 0.01, kDampingTol = 0.3, kSigmas = 4.0;
  const std::vector<std::vector<double>> frequencies = {
      {0.155, 0.182, 0.316}, {0.138, 0.201, 0.345}, {0.143, 0.185, 0.262}};
  const std::vector<double> zeta = {0.01, 0.015, 0.02};
  const int r = GetParam();
  VibrationRecord record;
  std::string error;
  ASSERT_TRUE(SimulateAmbientRecord(Ambient(11 + r, frequencies[r], zeta), &record, &error))
      << error;
  std::vector<IdentifiedMode> modes;
  ASSERT_TRUE(IdentifyModesSsi(record, SsiOptions(), &modes, &error)) << error;
  ASSERT_EQ(modes.size(), 3u);
  for (int j = 0; j < 3; ++j) {
    const IdentifiedMode& m = modes[j];
    const double df = m.frequency_hz - frequencies[r][j], dz = m.damping_ratio - zeta[j];
    std::printf("[ figure ] record %d mode %d: %.5f +- %.5f Hz (%.5f), zeta %.4f +- %.4f (%.4f)\n",
                r, j + 1, m.frequency_hz, m.frequency_sigma_hz, frequencies[r][j], m.damping_ratio,
                m.damping_sigma, zeta[j]);
    EXPECT_LT(std::abs(df), kFrequencyTol * frequencies[r][j]) << "mode " << j + 1;
    EXPECT_LT(std::abs(dz), kDampingTol * zeta[j]) << "mode " << j + 1;
    EXPECT_LT(std::abs(df), kSigmas * m.frequency_sigma_hz) << "mode " << j + 1;
    EXPECT_LT(std::abs(dz), kSigmas * m.damping_sigma) << "mode " << j + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(ThreeRecords, SsiKnownPoles, ::testing::Values(0, 1, 2));

// Six more channels that are mostly white noise (a mode's motion under noise kNoiseRatio
// times its spread, as tension sensors' 3% under an ambient sway) do not spoil the modes:
// they are no references (their lag-1 autocorrelation is near 0), which also halves the
// block Toeplitz matrix.
TEST(IdentifyModesSsi, NoisyChannelsAreNoReferences) {
  constexpr double kFrequencyTol = 0.01, kDampingTol = 0.3, kNoiseRatio = 10.0;
  const std::vector<double> hz = {0.155, 0.182, 0.316}, zeta = {0.01, 0.015, 0.02};
  AmbientRecordSpec spec = Ambient(11, hz, zeta);
  spec.shape.conservativeResize(12, 3);
  spec.noise_sigma.conservativeResize(12);
  for (int c = 6; c < 12; ++c) {
    spec.shape.row(c) = 0.3 * spec.shape.row(c - 6);
    spec.noise_sigma[c] = kNoiseRatio * spec.shape.row(c).norm();
  }
  VibrationRecord record;
  std::string error;
  ASSERT_TRUE(SimulateAmbientRecord(spec, &record, &error)) << error;
  std::vector<IdentifiedMode> modes;
  ASSERT_TRUE(IdentifyModesSsi(record, SsiOptions(), &modes, &error)) << error;
  ASSERT_EQ(modes.size(), 3u);
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(modes[j].frequency_hz / hz[j], 1.0, kFrequencyTol) << "mode " << j + 1;
    EXPECT_NEAR(modes[j].damping_ratio / zeta[j], 1.0, kDampingTol) << "mode " << j + 1;
  }
}

// A free decay's envelope falls (rho far above kFreeDecayRatio), an ambient record's does
// not (rho near 1), so `--identification=auto` picks ERA for one and SSI for the other.
TEST(EnvelopeDecayRatio, TellsAFreeDecayFromAnAmbientRecord) {
  VibrationRecord ambient, decay;
  std::string error;
  ASSERT_TRUE(SimulateAmbientRecord(Ambient(3, {0.155, 0.182}, {0.004, 0.01}), &ambient, &error))
      << error;
  FreeDecaySpec free;
  free.frequency_hz = {0.155, 0.182};
  free.damping_ratio = {0.004, 0.01};
  free.shape = Eigen::MatrixXd::Ones(3, 2);
  free.noise_sigma = Eigen::VectorXd::Constant(3, 0.01);
  free.duration_s = 400.0;
  ASSERT_TRUE(SimulateFreeDecay(free, &decay, &error)) << error;
  const double rho_ambient = EnvelopeDecayRatio(ambient), rho_decay = EnvelopeDecayRatio(decay);
  std::printf("[ figure ] rho: ambient %.3f, free decay %.3f\n", rho_ambient, rho_decay);
  EXPECT_LT(rho_ambient, 0.5 * kFreeDecayRatio);
  EXPECT_GT(rho_decay, 2.0 * kFreeDecayRatio);
  EXPECT_EQ(EnvelopeDecayRatio(VibrationRecord()), 1.0);
}

TEST(IdentifyModesSsi, RefusesBadOptionsAndShortRecords) {
  std::string error;
  SsiOptions o;
  o.max_order = 5;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("max_order"), std::string::npos) << error;
  o = SsiOptions();
  o.min_frequency_hz = 0.6;
  EXPECT_FALSE(o.IsValid(&error));
  o = SsiOptions();
  o.blocks = 2;
  EXPECT_FALSE(o.IsValid(&error));

  VibrationRecord record;
  ASSERT_TRUE(SimulateAmbientRecord(Ambient(5, {0.155}, {0.01}), &record, &error)) << error;
  std::vector<IdentifiedMode> modes;
  VibrationRecord short_record = record;
  short_record.channels = record.channels.leftCols(400);  // 200 s: blocks of 25 s
  EXPECT_FALSE(IdentifyModesSsi(short_record, SsiOptions(), &modes, &error));
  EXPECT_NE(error.find("too short"), std::string::npos) << error;
  VibrationRecord coarse = record;
  coarse.sample_interval_s = 2.0;  // Nyquist 0.25 Hz, below max_frequency_hz
  EXPECT_FALSE(IdentifyModesSsi(coarse, SsiOptions(), &modes, &error));
  VibrationRecord broken = record;
  broken.channels(2, 7) = std::nan("");
  EXPECT_FALSE(IdentifyModesSsi(broken, SsiOptions(), &modes, &error));
  SsiOptions many;
  many.modes = 6;  // one mode in the record
  EXPECT_FALSE(IdentifyModesSsi(record, many, &modes, &error));
  EXPECT_NE(error.find("fewer than"), std::string::npos) << error;

  AmbientRecordSpec bad = Ambient(5, {0.155}, {0.01});
  bad.frequency_hz = {1.5};  // above the Nyquist of 0.5 s
  EXPECT_FALSE(SimulateAmbientRecord(bad, &record, &error));
}

}  // namespace
}  // namespace fastcal
