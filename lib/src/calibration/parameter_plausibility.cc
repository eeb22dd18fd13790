// Plausibility of a calibration parameter's value by its kind (parameter_plausibility.h).
#include "fastcal/parameter_plausibility.h"

namespace fastcal {

bool QuantityOfParameter(ParameterKind kind, ModelQuantity* quantity) {
  switch (kind) {
    case ParameterKind::kMassCentre:
      *quantity = ModelQuantity::kMassCentreM;
      return true;
    case ParameterKind::kCabinMass:
      *quantity = ModelQuantity::kCabinMassKg;
      return true;
    case ParameterKind::kLinearDensity:
      *quantity = ModelQuantity::kLinearDensityKgPerM;
      return true;
    case ParameterKind::kEa:
      *quantity = ModelQuantity::kEaN;
      return true;
    case ParameterKind::kAnchorOffset:
    case ParameterKind::kTowerOffset:
      *quantity = ModelQuantity::kOffsetM;
      return true;
    case ParameterKind::kSensorGain:
      *quantity = ModelQuantity::kSensorGain;
      return true;
    case ParameterKind::kSensorBias:
      *quantity = ModelQuantity::kSensorBiasN;
      return true;
    case ParameterKind::kAttachmentMass:
      *quantity = ModelQuantity::kAttachmentMassKg;
      return true;
    case ParameterKind::kAttachmentDensity:
      *quantity = ModelQuantity::kAttachmentDensityKgPerM;
      return true;
    case ParameterKind::kLengthOffset:
      *quantity = ModelQuantity::kLengthOffsetM;
      return true;
    case ParameterKind::kPartFirstMoment:
      *quantity = ModelQuantity::kPartFirstMomentKgM;
      return true;
    case ParameterKind::kPartMass:
      *quantity = ModelQuantity::kPartMassKg;
      return true;
    case ParameterKind::kMeasuredOffset:
      *quantity = ModelQuantity::kMeasuredOffsetM;
      return true;
    default:
      return false;
  }
}

bool CheckParameterValue(ParameterKind kind, double value_si, const PlausibilityLimits& limits,
                         std::string* why) {
  ModelQuantity quantity;
  return !QuantityOfParameter(kind, &quantity) || CheckQuantity(quantity, value_si, limits, why);
}

}  // namespace fastcal
