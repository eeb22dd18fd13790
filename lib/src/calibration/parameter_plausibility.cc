// Plausibility of a calibration parameter's value by its kind (parameter_plausibility.h).
#include "fastcal/parameter_plausibility.h"

namespace fastcal {

bool QuantityOfParameter(ParameterKind kind, ModelQuantity* quantity) {
  const ParameterKindInfo* row = FindParameterKind(kind);
  if (row == nullptr) return false;
  *quantity = row->quantity;
  return true;
}

bool CheckParameterValue(ParameterKind kind, double value_si, const PlausibilityLimits& limits,
                         std::string* why) {
  ModelQuantity quantity;
  return !QuantityOfParameter(kind, &quantity) || CheckQuantity(quantity, value_si, limits, why);
}

}  // namespace fastcal
