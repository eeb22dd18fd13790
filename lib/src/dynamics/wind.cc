// Wind: spectra and spectral synthesis (wind.h has the equations and their sources).
#include "fastcal/wind.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <unsupported/Eigen/FFT>

namespace fastcal {
namespace {

constexpr double kKaimalLengthM = 340.2;      // 8.1 x 42 m (IEC 61400-1)
constexpr double kDavenportLengthM = 1200.0;  // Davenport 1961
// The longest record a wind is synthesised for: 10 days at kGustIntervalS is 1.7e7
// samples (137 MB): beyond, a caller is asking for something else.
constexpr double kMaxDurationS = 10 * 86400.0;

double LengthScale(const WindOptions& o) {
  if (o.length_scale_m > 0.0) return o.length_scale_m;
  return o.spectrum == GustSpectrum::kKaimal ? kKaimalLengthM : kDavenportLengthM;
}

}  // namespace

const char* GustSpectrumName(GustSpectrum spectrum) {
  return spectrum == GustSpectrum::kKaimal ? "kaimal" : "davenport";
}

bool ParseGustSpectrum(const std::string& name, GustSpectrum* spectrum) {
  if (name == "kaimal") {
    *spectrum = GustSpectrum::kKaimal;
  } else if (name == "davenport") {
    *spectrum = GustSpectrum::kDavenport;
  } else {
    return false;
  }
  return true;
}

bool WindOptions::IsValid(std::string* error) const {
  if (!(mean_speed_m_per_s >= 0.0) || !std::isfinite(mean_speed_m_per_s) ||
      mean_speed_m_per_s > 100.0) {
    *error = "wind.mean_speed_m_per_s: must be in [0, 100] m/s";
    return false;
  }
  if (!std::isfinite(direction_deg)) {
    *error = "wind.direction_deg: must be finite";
    return false;
  }
  if (!(turbulence_intensity >= 0.0 && turbulence_intensity < 1.0)) {
    *error = "wind.turbulence_intensity: must be in [0, 1)";
    return false;
  }
  if (!std::isfinite(length_scale_m)) {
    *error = "wind.length_scale_m: must be finite";
    return false;
  }
  if (!(max_frequency_hz > 0.0 && max_frequency_hz <= 0.5 / kGustIntervalS)) {
    *error = "wind.max_frequency_hz: must be in (0, 10] Hz";
    return false;
  }
  return true;
}

double GustSpectralDensity(const WindOptions& o, double f) {
  const double u = o.mean_speed_m_per_s;
  if (!(f > 0.0) || !(u > 0.0)) return 0.0;
  const double variance = std::pow(o.turbulence_intensity * u, 2);
  const double length = LengthScale(o);
  if (o.spectrum == GustSpectrum::kKaimal) {
    return variance * (4.0 * length / u) / std::pow(1.0 + 6.0 * f * length / u, 5.0 / 3.0);
  }
  const double x = length * f / u;
  return variance * (2.0 / 3.0) * x * x / (f * std::pow(1.0 + x * x, 4.0 / 3.0));
}

bool WindField::Build(const WindOptions& o, double duration_s, std::string* error) {
  if (!o.IsValid(error)) return false;
  if (!(duration_s >= 0.0) || !(duration_s <= kMaxDurationS)) {
    *error = "wind: the duration must be in [0, 10 days]";
    return false;
  }
  const double angle = o.direction_deg * M_PI / 180.0;
  direction_ = Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
  mean_m_per_s_ = o.mean_speed_m_per_s;
  const int samples = static_cast<int>(std::ceil(duration_s / kGustIntervalS)) + 2;
  gust_m_per_s_.assign(samples, 0.0);
  if (!(o.mean_speed_m_per_s > 0.0) || !(o.turbulence_intensity > 0.0)) return true;
  // The period: a power of two of grid steps covering the record (at least 1024).
  int size = 1024;
  while (size < samples) size *= 2;
  const double df = 1.0 / (size * kGustIntervalS);
  const int highest = std::min(size / 2 - 1, static_cast<int>(o.max_frequency_hz / df));
  std::mt19937_64 generator(o.seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  std::vector<std::complex<double>> spectrum(size, 0.0);
  for (int k = 1; k <= highest; ++k) {
    const double amplitude = std::sqrt(2.0 * GustSpectralDensity(o, k * df) * df);
    // x_m = (1/size) sum_k X_k e^{2 pi i k m / size}: X_k = size A_k e^{i phi_k}.
    spectrum[k] = std::polar(size * amplitude, phase(generator));
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> series;
  fft.inv(series, spectrum);
  for (int m = 0; m < samples; ++m) gust_m_per_s_[m] = series[m].real();
  return true;
}

double WindField::Speed(double time_s) const {
  if (gust_m_per_s_.empty()) return mean_m_per_s_;
  const double position = std::max(0.0, time_s / kGustIntervalS);
  const size_t i = static_cast<size_t>(position);
  if (i + 1 >= gust_m_per_s_.size()) return mean_m_per_s_ + gust_m_per_s_.back();
  const double w = position - static_cast<double>(i);
  return mean_m_per_s_ + (1.0 - w) * gust_m_per_s_[i] + w * gust_m_per_s_[i + 1];
}

Eigen::Vector3d WindField::Velocity(double time_s) const {
  if (mean_m_per_s_ == 0.0) return Eigen::Vector3d::Zero();
  return Speed(time_s) * direction_;
}

}  // namespace fastcal
