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
#ifndef FASTCAL_GROSS_ERRORS_H_
#define FASTCAL_GROSS_ERRORS_H_

#include <array>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/uncertainty.h"

namespace fastcal {

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
