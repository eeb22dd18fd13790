// Gross errors among the tension readings: readings far from the model, judged robustly
// so that the gross errors cannot hide each other (docs/calibration.md, "Gross errors").
//
// For each cable i, from the whitened residuals r_ti = (predicted - measured) / sigma_ti
// of the samples judged by (the fitted ones, readings not yet excluded or not):
//   centre_i = median_t r_ti,   scale_i = max(1, 1.4826 median_t |r_ti - centre_i|)
// and a reading is a gross error when |r_ti - centre_i| > threshold * scale_i. The median
// and MAD ignore up to half of the readings whatever their size, and the floor of 1 (the
// stated noise) keeps a well-fitting cable from flagging its ordinary noise. A reading is
// judged against the robust scale of the residuals, not the least-squares one, which a
// single 99999 kN reading would inflate past every other error.
//
// The threshold grows with the number N of readings screened, so that pure Gaussian
// noise of any length is accused of nothing with probability 1 - alpha (alpha = 1%):
//   z_N = Phi^-1(1 - alpha / (2 N)),   threshold = max(threshold_sigmas, z_N)
// (Bonferroni over N two-sided tests: P(some |r| > z_N) <= N * alpha / N = alpha). The
// spec's threshold_sigmas is the floor: on a short dataset it alone decides (z_N < 5 up to
// N = 17443 readings, about 2900 samples), on a long one the family-wise rule does (a fixed
// 5-sigma cut expects 0.57 false accusations per million readings; z_N = 5.64 at 10^5
// samples, 6.03 at 10^6). A spec that asks for more than z_N keeps its own.
#ifndef FASTCAL_GROSS_ERRORS_H_
#define FASTCAL_GROSS_ERRORS_H_

#include <array>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/uncertainty.h"

namespace fastcal {

// Chance that pure Gaussian noise has some reading named a gross error, whatever its length.
constexpr double kGrossErrorFamilyFalseAlarm = 0.01;

// The threshold a screen of `readings` readings uses, and why.
struct GrossErrorThreshold {
  double sigmas = 0.0;              // the threshold used: max(floor, family-wise)
  double floor_sigmas = 0.0;        // the spec's threshold_sigmas
  double family_wise_sigmas = 0.0;  // z_N at kGrossErrorFamilyFalseAlarm
  long long readings = 0;           // N, the readings screened
  bool family_wise_decides() const { return family_wise_sigmas > floor_sigmas; }
};

// z with P(|Z| > z) = tail for a standard normal Z, i.e. erfc(z / sqrt 2) = tail, for
// 0 < tail < 1 (by bisection: exact to double precision, cheap, no table).
double TwoSidedNormalQuantile(double tail);

// The threshold for `readings` readings with the spec's floor, at false-alarm rate
// `family_false_alarm` (0 < it < 1) over all of them.
GrossErrorThreshold ChooseGrossErrorThreshold(
    long long readings, double floor_sigmas,
    double family_false_alarm = kGrossErrorFamilyFalseAlarm);

// Which threshold was used and why, one sentence for reports and consoles, e.g. "5.64
// robust sigmas: the family-wise threshold for 600000 readings (a 1% chance that Gaussian
// noise names any), above the floor threshold_sigmas = 5".
std::string DescribeGrossErrorThreshold(const GrossErrorThreshold& threshold);

struct GrossErrorScreen {
  std::array<RobustScale, kNumCables> cables{};  // centre and scale (the floor applied)
  // flagged[t][i]: reading of cable i in sample t is a gross error.
  std::vector<std::array<bool, kNumCables>> flagged;
  int count = 0;      // flagged readings among the judged samples
  int judged = 0;     // readings of the judged samples
  int count_all = 0;  // flagged readings among all samples
};

// Screens `whitened` (one row per sample) with the scales of the samples for which
// judge[t] is true (all when empty); every sample is flagged against those scales.
GrossErrorScreen ScreenGrossErrors(const std::vector<std::array<double, kNumCables>>& whitened,
                                   const std::vector<bool>& judge, double threshold_sigmas);

}  // namespace fastcal

#endif  // FASTCAL_GROSS_ERRORS_H_
