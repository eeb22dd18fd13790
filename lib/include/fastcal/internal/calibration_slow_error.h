// The calibration's slow-error stages (calibration.cc; slow_error.h): each reading's
// slow-to-white sigma ratio, the prediction's residuals whitened into innovations (for the
// gross-error screen and the worst readings), and the estimate's inputs.
#ifndef FASTCAL_INTERNAL_CALIBRATION_SLOW_ERROR_H_
#define FASTCAL_INTERNAL_CALIBRATION_SLOW_ERROR_H_

#include <array>
#include <vector>

#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/internal/slow_error_estimate.h"
#include "fastcal/slow_error.h"

namespace fastcal::internal {

using ReadingArrays = std::vector<std::array<double, kNumCables>>;

// The fit's predicted readings at some parameters, per dataset sample.
struct PredictionView {
  const Dataset* data = nullptr;
  const ReadingArrays* reading_n = nullptr;  // gain T + bias
  const ReadingArrays* sigma_n = nullptr;    // the white sigma
  const std::vector<int>* fit = nullptr;     // fitted samples (dataset indices, file order)
  const ReadingMask* excluded = nullptr;     // per dataset sample (may be empty)
};

// Per fitted sample j: rho_ji = process.SigmaN(reading) / sigma_white (empty when inactive).
ReadingArrays SlowErrorRatios(const SlowErrorProcess& process, const PredictionView& at);

// The prediction's residuals over their white sigma (`x`, per dataset sample) whitened
// in place: the fitted samples' in time order by the process's filters (readings kept
// out innovated without updating them); the others standardised by their marginal sigma,
// x / sqrt(1 + rho^2). Nothing changes for an inactive process.
void WhitenPrediction(const SlowErrorProcess& process, const PredictionView& at, ReadingArrays* x);

// The estimate's inputs: the prediction's residuals over their white sigma,
// (reading - measured) / sigma, of the fitted samples, or of contiguous runs of at most
// `budget` of them.
SlowErrorEstimateInputs SlowErrorInputs(const CalibrationSpec& spec, const PredictionView& at,
                                        int budget);

// Relative change of the slow error's amplitude and time constant within which a new
// estimate leaves the process a fit used as it is (calibrate's passes, the track's
// Gauss-Newton iterations stop).
inline constexpr double kSlowErrorSettled = 0.05;

// A new estimate of the process taken in: *report becomes `estimate` (its pass count one
// more than before) and, unless the process *used stands (active, and each part within
// kSlowErrorSettled of the estimate's, or both at the amplitude floor) or `may_change` is
// false, *used becomes the estimate's. Returns whether it stood.
bool AdoptSlowErrorEstimate(const SlowErrorReport& estimate, bool may_change,
                            SlowErrorProcess* used, SlowErrorReport* report);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_CALIBRATION_SLOW_ERROR_H_
