// Plausibility of a calibration parameter's value: plausibility.h's ranges, by the kind of
// parameter (calibration_spec.h). Beside the calibration spec, above the model's own
// checks (model_plausibility.h), which know no parameter kinds.
#ifndef FASTCAL_PARAMETER_PLAUSIBILITY_H_
#define FASTCAL_PARAMETER_PLAUSIBILITY_H_

#include <string>

#include "fastcal/calibration_spec.h"
#include "fastcal/plausibility.h"

namespace fastcal {

// The plausibility.h quantity of a calibration parameter kind's values; false for a kind
// without one.
bool QuantityOfParameter(ParameterKind kind, ModelQuantity* quantity);
// True when `value_si` is plausible for a parameter of `kind` (or the kind has no range);
// otherwise false and *why as CheckQuantity says it.
bool CheckParameterValue(ParameterKind kind, double value_si, const PlausibilityLimits& limits,
                         std::string* why);

}  // namespace fastcal

#endif  // FASTCAL_PARAMETER_PLAUSIBILITY_H_
