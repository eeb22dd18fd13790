// Wind for the dynamics: a mean speed in a horizontal direction plus gusts along it,
// synthesised from a turbulence spectrum (docs/model.md, "Dynamics").
//
// Spectra of the along-wind speed u (one-sided, f in Hz, sigma = I U, U the mean speed,
// I the turbulence intensity), each integrating to sigma^2 over (0, infinity):
//   Kaimal (IEC 61400-1 ed. 3, annex B):  S(f) = sigma^2 (4 L/U) / (1 + 6 f L/U)^(5/3),
//       L = 8.1 Lambda, Lambda = 42 m above 60 m height: L = 340.2 m;
//   Davenport (1961, Q. J. R. Meteorol. Soc. 87):  S(f) = sigma^2 (2/3) x^2 / (f (1 + x^2)^(4/3)),
//       x = L f / U, L = 1200 m.
// Spectral synthesis (Shinozuka and Deodatis 1991, Appl. Mech. Rev. 44): over a period P
// at least the record's, u'(t) = sum_k sqrt(2 S(f_k) df) cos(2 pi f_k t + phi_k), f_k = k df,
// df = 1/P, up to max_frequency_hz, the phases uniform and seeded; evaluated on a grid of
// kGustIntervalS by one inverse FFT and interpolated linearly between.
//
// Assumptions (said where the results are): the gust is one time series over the whole
// system, fully coherent across the cables' 300 m (an upper bound on how it excites the
// cabin); the mean speed is uniform in height; the across-wind and vertical components
// are left out.
#ifndef FASTCAL_WIND_H_
#define FASTCAL_WIND_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace fastcal {

enum class GustSpectrum { kKaimal, kDavenport };
const char* GustSpectrumName(GustSpectrum spectrum);  // "kaimal", "davenport"
bool ParseGustSpectrum(const std::string& name, GustSpectrum* spectrum);

struct WindOptions {
  // Mean speed (m/s, >= 0; 0: still air, no gusts) and the direction it blows toward,
  // from +x toward +y (deg).
  double mean_speed_m_per_s = 0.0;
  double direction_deg = 0.0;
  GustSpectrum spectrum = GustSpectrum::kKaimal;
  // sigma_u / U, in [0, 1). 0.15: IEC 61400-1 class B's reference intensity at 15 m/s
  // (0.14), rounded up for the karst depression's gustier flow (an assumption).
  double turbulence_intensity = 0.15;
  // The spectrum's length scale L (m; above: Kaimal 340.2, Davenport 1200); <= 0 takes the
  // spectrum's own.
  double length_scale_m = 0.0;
  // Gusts up to this frequency (Hz, > 0): the cabin's and the cables' lowest modes lie at
  // 0.13-0.4 Hz.
  double max_frequency_hz = 2.0;
  std::uint64_t seed = 1;

  bool IsValid(std::string* error) const;
};

// The grid the gust series is evaluated on (s).
inline constexpr double kGustIntervalS = 0.05;

// The one-sided spectrum S(f) of `options` at f (m^2/s^2/Hz); 0 for f <= 0 or U = 0.
double GustSpectralDensity(const WindOptions& options, double frequency_hz);

// The wind over [0, duration_s]: its velocity (global, m/s) at any time in it (beyond it,
// the last value).
class WindField {
 public:
  WindField() = default;
  // False with *error for invalid options or duration.
  bool Build(const WindOptions& options, double duration_s, std::string* error);
  Eigen::Vector3d Velocity(double time_s) const;
  // The along-wind speed U + u'(t).
  double Speed(double time_s) const;
  const std::vector<double>& gust_m_per_s() const { return gust_m_per_s_; }

 private:
  double mean_m_per_s_ = 0.0;
  Eigen::Vector3d direction_ = Eigen::Vector3d::UnitX();
  std::vector<double> gust_m_per_s_;  // u' on the grid
};

}  // namespace fastcal

#endif  // FASTCAL_WIND_H_
