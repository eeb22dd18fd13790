// The table of calibration parameter kinds (parameter_table.h): one row per kind.
#include "fastcal/parameter_table.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "fastcal/calibration.h"
#include "fastcal/internal/units.h"

namespace fastcal {
namespace {

using K = ParameterKind;
using S = ParameterShape;
using Q = ModelQuantity;
using D = DeterminedScale;
using M = DesignMargin;
using O = CalibrationOptions;

// A prior's sigma this much wider than the option still counts as determined (the fit
// cannot narrow a parameter below its prior's sigma by rounding alone).
constexpr double kPriorSigmaSlack = 1.01;

// kind, key, unit, to_si, shape, quantity, positive, non_negative, moves_forces,
// moves_geometry, max_sigma, determined_scale, design_margin.
constexpr std::array<ParameterKindInfo, kNumParameterKinds> kRows = {{
    {K::kMassCentre, "mass_centre_m", "m", 1.0, S::kAxes, Q::kMassCentreM, nullptr, false, true,
     false, &O::max_sigma_mass_centre_m, D::kAbsolute, M::kMassCentre},
    {K::kCabinMass, "cabin_mass_kg", "kg", 1.0, S::kOne, Q::kCabinMassKg, "a mass", false, true,
     false, &O::max_sigma_cabin_mass_fraction, D::kOfValue, M::kRelative},
    {K::kLinearDensity, "linear_density_kg_per_m", "kg/m", 1.0, S::kPerCable,
     Q::kLinearDensityKgPerM, "a linear density", false, true, false,
     &O::max_sigma_density_fraction, D::kOfValue, M::kRelative},
    {K::kEa, "ea_n", "N", 1.0, S::kPerCable, Q::kEaN, "an axial stiffness EA", false, true, false,
     &O::max_sigma_ea_fraction, D::kOfValue, M::kRelative},
    {K::kAnchorOffset, "anchor_offset_m", "m", 1.0, S::kPointAxes, Q::kOffsetM, nullptr, false,
     true, true, &O::max_sigma_anchor_offset_m, D::kAbsolute, M::kOffset},
    {K::kTowerOffset, "tower_offset_m", "m", 1.0, S::kPointAxes, Q::kOffsetM, nullptr, false, true,
     true, &O::max_sigma_tower_offset_m, D::kAbsolute, M::kOffset},
    {K::kSensorGain, "sensor_gain", "1", 1.0, S::kPerCable, Q::kSensorGain, "a sensor gain", false,
     false, false, &O::max_sigma_sensor_gain, D::kAbsolute, M::kNone},
    {K::kSensorBias, "sensor_bias_kN", "kN", internal::kNPerKn, S::kPerCable, Q::kSensorBiasN,
     nullptr, false, false, false, &O::max_sigma_sensor_bias_n, D::kAbsolute, M::kNone},
    {K::kAttachmentMass, "attachment_mass_kg", "kg", 1.0, S::kAttachment, Q::kAttachmentMassKg,
     nullptr, true, true, false, &O::max_sigma_attachment_mass_kg, D::kAbsolute, M::kRelative},
    {K::kAttachmentDensity, "attachment_density_kg_per_m", "kg/m", 1.0, S::kAttachment,
     Q::kAttachmentDensityKgPerM, nullptr, true, true, false,
     &O::max_sigma_attachment_density_kg_per_m, D::kAbsolute, M::kRelative},
    {K::kLengthOffset, "length_offset_m", "m", 1.0, S::kPerCable, Q::kLengthOffsetM, nullptr, false,
     false, false, &O::max_sigma_length_offset_m, D::kAbsolute, M::kNone},
    // Both under one key, `moving_parts: {NAME: {first_moment_kg_m: {x, y, z}, mass_kg}}`.
    {K::kPartFirstMoment, "moving_parts", "kg m", 1.0, S::kPartAxes, Q::kPartFirstMomentKgM,
     nullptr, false, true, false, &O::max_sigma_part_first_moment_kg_m, D::kAbsoluteOrPrior,
     M::kRelative},
    {K::kPartMass, "moving_parts", "kg", 1.0, S::kPart, Q::kPartMassKg, nullptr, false, true, false,
     &O::max_sigma_part_mass_kg, D::kAbsoluteOrPrior, M::kRelative},
    // `measured_frame: {offset_m: {x, y, z}}`: it moves the cabin, so every cable's ends.
    {K::kMeasuredOffset, "measured_frame", "m", 1.0, S::kAxes, Q::kMeasuredOffsetM, nullptr, false,
     true, true, &O::max_sigma_measured_offset_m, D::kAbsoluteOrPrior, M::kOffset},
}};

// The rows are in the enum's order: a row out of place is a compile error.
constexpr bool InEnumOrder() {
  for (int k = 0; k < kNumParameterKinds; ++k) {
    if (static_cast<int>(kRows[k].kind) != k) return false;
  }
  return true;
}
static_assert(InEnumOrder(), "parameter_table.cc: rows out of ParameterKind's order");

}  // namespace

const std::array<ParameterKindInfo, kNumParameterKinds>& ParameterKinds() { return kRows; }

const ParameterKindInfo* FindParameterKind(ParameterKind kind) {
  const int k = static_cast<int>(kind);
  return k >= 0 && k < kNumParameterKinds ? &kRows[k] : nullptr;
}

const ParameterKindInfo& KindInfo(ParameterKind kind) {
  const ParameterKindInfo* row = FindParameterKind(kind);
  if (row == nullptr) std::abort();  // a programming error: a kind cast from a bad number
  return *row;
}

bool IsPerCableCapable(ParameterKind kind) {
  const ParameterKindInfo* row = FindParameterKind(kind);
  return row != nullptr && row->shape == ParameterShape::kPerCable;
}

bool IsVector(ParameterKind kind) {
  const ParameterKindInfo* row = FindParameterKind(kind);
  return row != nullptr &&
         (row->shape == ParameterShape::kAxes || row->shape == ParameterShape::kPointAxes ||
          row->shape == ParameterShape::kPartAxes);
}

bool IsAttachment(ParameterKind kind) {
  const ParameterKindInfo* row = FindParameterKind(kind);
  return row != nullptr && row->shape == ParameterShape::kAttachment;
}

bool IsPart(ParameterKind kind) {
  const ParameterKindInfo* row = FindParameterKind(kind);
  return row != nullptr &&
         (row->shape == ParameterShape::kPartAxes || row->shape == ParameterShape::kPart);
}

double MaxSigmaOf(ParameterKind kind, double initial, double prior_sigma,
                  const CalibrationOptions& options) {
  const ParameterKindInfo& row = KindInfo(kind);
  const double option = options.*row.max_sigma;
  switch (row.determined_scale) {
    case DeterminedScale::kAbsolute:
      return option;
    case DeterminedScale::kOfValue:
      return option * std::abs(initial);
    case DeterminedScale::kAbsoluteOrPrior:
      return std::max(option, kPriorSigmaSlack * prior_sigma);
  }
  return option;
}

}  // namespace fastcal
