// Tests of the wind (wind.h): each spectrum integrates to sigma^2 = (I U)^2; the
// synthesised gust's variance is the spectrum's over the synthesised band, its mean zero;
// the same seed gives the same gust, another seed another.
#include "fastcal/wind.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <string>
#include <vector>

namespace fastcal {
namespace {

// The integral of S over (f_lo, f_hi) by the trapezoidal rule on a logarithmic grid.
double SpectrumIntegral(const WindOptions& o, double f_lo, double f_hi) {
  constexpr int kPoints = 200000;
  const double a = std::log(f_lo), b = std::log(f_hi);
  double sum = 0.0;
  for (int k = 0; k <= kPoints; ++k) {
    const double f = std::exp(a + (b - a) * k / kPoints);
    const double weight = (k == 0 || k == kPoints) ? 0.5 : 1.0;
    sum += weight * GustSpectralDensity(o, f) * f;  // df = f d(ln f)
  }
  return sum * (b - a) / kPoints;
}

// Kaimal and Davenport each hold sigma^2 over (0, infinity): over 1e-7 to 1e5 Hz within
// kNormalisation (Davenport's tails fall as f^-5/3 above and f above 0, Kaimal's as
// f^-5/3: what the range leaves out).
TEST(Wind, SpectraIntegrateToTheVariance) {
  constexpr double kNormalisation = 2e-3;
  for (GustSpectrum spectrum : {GustSpectrum::kKaimal, GustSpectrum::kDavenport}) {
    WindOptions o;
    o.mean_speed_m_per_s = 6.0;
    o.spectrum = spectrum;
    const double variance = std::pow(o.turbulence_intensity * o.mean_speed_m_per_s, 2);
    EXPECT_NEAR(SpectrumIntegral(o, 1e-7, 1e5) / variance, 1.0, kNormalisation)
        << GustSpectrumName(spectrum);
  }
}

// An hour of gust at 4 m/s (Kaimal): its variance is the spectrum's over the band it
// synthesises (1/P to max_frequency_hz, P the FFT's period) within kVariance (random
// phases make the sample variance exact for a periodic record over its whole period: the
// record is 55% of it), its mean within kMean of 0: three times an hour's mean's sampling
// spread, sigma sqrt(2 (L/U) / T) = 0.13 m/s (L/U = 85 s the gust's integral time).
TEST(Wind, GustHasTheSpectrumsVariance) {
  constexpr double kVariance = 0.05;
  constexpr double kMeanMPerS = 0.4;
  WindOptions o;
  o.mean_speed_m_per_s = 4.0;
  o.seed = 7;
  WindField wind;
  std::string error;
  ASSERT_TRUE(wind.Build(o, 3600.0, &error)) << error;
  const std::vector<double>& gust = wind.gust_m_per_s();
  int size = 1024;
  while (size < static_cast<int>(gust.size())) size *= 2;
  const double period_s = size * kGustIntervalS;
  const double expected = SpectrumIntegral(o, 1.0 / period_s, o.max_frequency_hz);
  const double mean = std::accumulate(gust.begin(), gust.end(), 0.0) / gust.size();
  double variance = 0.0;
  for (double g : gust) variance += (g - mean) * (g - mean);
  variance /= gust.size();
  EXPECT_NEAR(variance / expected, 1.0, kVariance);
  EXPECT_NEAR(mean, 0.0, kMeanMPerS);
  EXPECT_NEAR(wind.Speed(1800.0) - gust[36000], 4.0, 1e-12);  // on the grid, exactly
  EXPECT_NEAR(wind.Velocity(0.0).norm(), wind.Speed(0.0), 1e-12);

  WindField same, other;
  ASSERT_TRUE(same.Build(o, 3600.0, &error));
  o.seed = 8;
  ASSERT_TRUE(other.Build(o, 3600.0, &error));
  EXPECT_EQ(same.gust_m_per_s(), gust);
  EXPECT_NE(other.gust_m_per_s(), gust);
}

TEST(Wind, DirectionAndStillAir) {
  WindOptions o;
  o.mean_speed_m_per_s = 5.0;
  o.direction_deg = 90.0;
  o.turbulence_intensity = 0.0;
  WindField wind;
  std::string error;
  ASSERT_TRUE(wind.Build(o, 10.0, &error));
  EXPECT_NEAR(wind.Velocity(3.0).y(), 5.0, 1e-12);
  EXPECT_NEAR(wind.Velocity(3.0).x(), 0.0, 1e-12);
  o.mean_speed_m_per_s = 0.0;
  ASSERT_TRUE(wind.Build(o, 10.0, &error));
  EXPECT_EQ(wind.Velocity(3.0), Eigen::Vector3d::Zero());
  o.turbulence_intensity = 1.5;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("turbulence_intensity"), std::string::npos);
  GustSpectrum s;
  EXPECT_TRUE(ParseGustSpectrum("davenport", &s));
  EXPECT_EQ(s, GustSpectrum::kDavenport);
  EXPECT_FALSE(ParseGustSpectrum("karman", &s));
}

}  // namespace
}  // namespace fastcal
