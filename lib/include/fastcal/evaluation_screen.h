// Gross errors in a model evaluation (`fastcal evaluate`): the screen calibrate applies
// (gross_errors.h), on the readings of one evaluated variant, so that a 0 kN dropout is
// named (file line and cable) instead of folded into the RMS table.
//
// Whitened residual r_ti = (predicted_ti - measured_ti) / sigma_ti, with the noise model
// of calibration_spec.h, sigma_ti = sqrt(sigma_abs^2 + (percent / 100 * predicted_ti)^2)
// (evaluate has no spec, so the CalibrationSpec defaults: 3 % of the reading), then
// the robust per-cable screen of gross_errors.h at the threshold for 6 N readings.
#ifndef FASTCAL_EVALUATION_SCREEN_H_
#define FASTCAL_EVALUATION_SCREEN_H_

#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/gross_errors.h"

namespace fastcal {

struct EvaluationScreen {
  std::string variant;  // name of the variant whose predictions were judged
  GrossErrorThreshold threshold;
  std::array<RobustScale, kNumCables> cables{};  // per cable centre and scale [sigma]
  ReadingMask excluded;                          // per sample: the gross errors
  std::vector<ReadingResidual> gross_errors;     // in file order (streamed: the first ones)
  // How many readings were flagged, in all and per cable (gross_errors may list fewer:
  // StreamedEvaluation names at most EvaluationStreamOptions::max_named_gross_errors).
  long long count = 0;
  std::array<long long, kNumCables> count_per_cable{};
};

// Screens the readings of `data` against `variant`'s predictions (predicted_n filled),
// with the noise model and threshold floor of `spec` (its other fields unused).
EvaluationScreen ScreenEvaluation(const Dataset& data, const VariantEvaluation& variant,
                                  const CalibrationSpec& spec = CalibrationSpec());

// Each variant's statistics again with the screen's gross errors left out, named
// "<name> - gross errors" (predicted_n left empty: the same predictions).
std::vector<VariantEvaluation> WithoutGrossErrors(const Dataset& data,
                                                  const std::vector<VariantEvaluation>& variants,
                                                  const ReadingMask& excluded);

}  // namespace fastcal

#endif  // FASTCAL_EVALUATION_SCREEN_H_
