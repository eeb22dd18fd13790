// Plausibility limits of input values (plausibility.h).
#include "fastcal/plausibility.h"

#include <algorithm>
#include <cmath>

#include "fastcal/internal/fail.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

std::string Num(double value) { return internal::FormatDouble("%.6g", value); }

// `value` beyond `limit`, with as many digits as it takes to look different from it
// ("300.00001 m is above 300 m", not "300 m is above 300 m").
std::string NumBeyond(double value, double limit) { return internal::FormatBeyond(value, limit); }

using internal::Fail;

}  // namespace

bool PlausibilityLimits::IsValid(std::string* error) const {
  const std::pair<const char*, double> fields[] = {
      {"max_tension_n", max_tension_n},
      {"max_horizontal_radius_m", max_horizontal_radius_m},
      {"max_height_m", max_height_m},
      {"reflector_radius_m", reflector_radius_m},
      {"reflector_aperture_radius_m", reflector_aperture_radius_m},
      {"below_reflector_margin_m", below_reflector_margin_m},
      {"max_abs_angle_deg", max_abs_angle_deg},
      {"max_rotation_vector_rad", max_rotation_vector_rad},
      {"max_unstretched_length_m", max_unstretched_length_m},
      {"min_cabin_mass_kg", min_cabin_mass_kg},
      {"max_cabin_mass_kg", max_cabin_mass_kg},
      {"max_abs_mass_centre_m", max_abs_mass_centre_m},
      {"max_abs_anchor_point_m", max_abs_anchor_point_m},
      {"min_linear_density_kg_per_m", min_linear_density_kg_per_m},
      {"max_linear_density_kg_per_m", max_linear_density_kg_per_m},
      {"min_ea_n", min_ea_n},
      {"max_ea_n", max_ea_n},
      {"max_abs_offset_m", max_abs_offset_m},
      {"min_sensor_gain", min_sensor_gain},
      {"max_sensor_gain", max_sensor_gain},
      {"max_abs_sensor_bias_n", max_abs_sensor_bias_n},
      {"max_abs_length_offset_m", max_abs_length_offset_m},
      {"max_length_sigma_m", max_length_sigma_m},
      {"max_tension_sigma_n", max_tension_sigma_n},
      {"max_tension_sigma_percent", max_tension_sigma_percent},
      {"max_attachment_mass_kg", max_attachment_mass_kg},
      {"max_attachment_density_kg_per_m", max_attachment_density_kg_per_m},
      {"max_attachment_position_m", max_attachment_position_m},
      {"min_tension_sigma_n", min_tension_sigma_n},
      {"min_tension_sigma_percent", min_tension_sigma_percent},
      {"min_abs_gravity_m_per_s2", min_abs_gravity_m_per_s2},
      {"max_abs_gravity_m_per_s2", max_abs_gravity_m_per_s2},
      {"min_reflector_radius_m", min_reflector_radius_m},
      {"max_reflector_radius_m", max_reflector_radius_m},
      {"min_reflector_aperture_m", min_reflector_aperture_m},
      {"max_reflector_offset_m", max_reflector_offset_m},
      {"min_tower_radius_m", min_tower_radius_m},
      {"min_tower_top_z_m", min_tower_top_z_m},
      {"max_tower_gap_deg", max_tower_gap_deg},
      {"min_cabin_inertia_kg_m2", min_cabin_inertia_kg_m2},
      {"max_cabin_inertia_kg_m2", max_cabin_inertia_kg_m2}};
  for (const auto& [name, value] : fields) {
    if (!(std::isfinite(value) && value > 0.0)) {
      return Fail(error, std::string(name) + ": must be > 0 and finite (got " + Num(value) + ")");
    }
  }
  if (reflector_aperture_radius_m > reflector_radius_m) {
    return Fail(error, "reflector_aperture_radius_m: must be <= reflector_radius_m");
  }
  const std::pair<const char*, std::pair<double, double>> ranges[] = {
      {"cabin_mass_kg", {min_cabin_mass_kg, max_cabin_mass_kg}},
      {"linear_density_kg_per_m", {min_linear_density_kg_per_m, max_linear_density_kg_per_m}},
      {"ea_n", {min_ea_n, max_ea_n}},
      {"sensor_gain", {min_sensor_gain, max_sensor_gain}},
      {"abs_gravity_m_per_s2", {min_abs_gravity_m_per_s2, max_abs_gravity_m_per_s2}},
      {"reflector_radius_m", {min_reflector_radius_m, max_reflector_radius_m}},
      {"cabin_inertia_kg_m2", {min_cabin_inertia_kg_m2, max_cabin_inertia_kg_m2}}};
  for (const auto& [name, range] : ranges) {
    if (range.first > range.second) {
      return Fail(error, std::string("min_") + name + ": must be <= max_" + name);
    }
  }
  return true;
}

QuantityRange PlausibleRange(ModelQuantity quantity, const PlausibilityLimits& limits) {
  // Nominal FAST values: docs/model.md, Table 1 (CableRobot::NominalFast()).
  constexpr double kNominalMassKg = 30000.0, kNominalDensity = 11.718, kNominalEaN = 2.4656e7;
  constexpr double kNominalInertiaKgM2 = 3.5e5;  // CableRobot's assumed default (x, y)
  switch (quantity) {
    case ModelQuantity::kCabinMassKg:
      return {limits.min_cabin_mass_kg, limits.max_cabin_mass_kg, kNominalMassKg, "kg", 1.0};
    case ModelQuantity::kMassCentreM:
      return {-limits.max_abs_mass_centre_m, limits.max_abs_mass_centre_m, 0.0, "m", 1.0};
    case ModelQuantity::kAnchorPointM:
      return {-limits.max_abs_anchor_point_m, limits.max_abs_anchor_point_m, 0.0, "m", 1.0};
    case ModelQuantity::kLinearDensityKgPerM:
      return {limits.min_linear_density_kg_per_m, limits.max_linear_density_kg_per_m,
              kNominalDensity, "kg/m", 1.0};
    case ModelQuantity::kEaN:
      return {limits.min_ea_n, limits.max_ea_n, kNominalEaN, "N", 1.0};
    case ModelQuantity::kOffsetM:
      return {-limits.max_abs_offset_m, limits.max_abs_offset_m, 0.0, "m", 1.0};
    case ModelQuantity::kSensorGain:
      return {limits.min_sensor_gain, limits.max_sensor_gain, 1.0, "", 1.0};
    case ModelQuantity::kSensorBiasN:
      return {-limits.max_abs_sensor_bias_n, limits.max_abs_sensor_bias_n, 0.0, "kN", 1e3};
    case ModelQuantity::kLengthOffsetM:
      return {-limits.max_abs_length_offset_m, limits.max_abs_length_offset_m, 0.0, "m", 1.0};
    case ModelQuantity::kLengthSigmaM:
      return {0.0, limits.max_length_sigma_m, 0.0, "m", 1.0};
    case ModelQuantity::kTensionSigmaN:
      return {0.0, limits.max_tension_sigma_n, 0.0, "kN", 1e3};
    case ModelQuantity::kTensionSigmaPercent:
      return {0.0, limits.max_tension_sigma_percent, 3.0, "%", 1.0};
    case ModelQuantity::kAttachmentMassKg:
      return {0.0, limits.max_attachment_mass_kg, 0.0, "kg", 1.0};
    case ModelQuantity::kAttachmentDensityKgPerM:
      return {0.0, limits.max_attachment_density_kg_per_m, 0.0, "kg/m", 1.0};
    case ModelQuantity::kAttachmentPositionM:
      return {0.0, limits.max_attachment_position_m, 0.0, "m", 1.0};
    case ModelQuantity::kGravityMPerS2:
      return {-limits.max_abs_gravity_m_per_s2, -limits.min_abs_gravity_m_per_s2, -9.8, "m/s^2",
              1.0};
    case ModelQuantity::kReflectorRadiusM:
      return {limits.min_reflector_radius_m, limits.max_reflector_radius_m, 300.0, "m", 1.0};
    case ModelQuantity::kReflectorApertureM:
      return {limits.min_reflector_aperture_m, 2.0 * limits.max_reflector_radius_m, 500.0, "m",
              1.0};
    case ModelQuantity::kPartFirstMomentKgM: {
      const double max = limits.max_cabin_mass_kg * limits.max_abs_mass_centre_m;
      return {-max, max, 0.0, "kg m", 1.0};
    }
    case ModelQuantity::kPartMassKg:
      return {0.0, limits.max_cabin_mass_kg, 0.0, "kg", 1.0};
    case ModelQuantity::kMeasuredOffsetM:
      return {-limits.max_abs_anchor_point_m, limits.max_abs_anchor_point_m, 0.0, "m", 1.0};
    case ModelQuantity::kPartOriginM:
      return {-limits.max_abs_anchor_point_m, limits.max_abs_anchor_point_m, 0.0, "m", 1.0};
    case ModelQuantity::kCabinInertiaKgM2:
      return {limits.min_cabin_inertia_kg_m2, limits.max_cabin_inertia_kg_m2, kNominalInertiaKgM2,
              "kg m^2", 1.0};
  }
  return {};
}

namespace {

// The unit slip that makes a value 1000 times too small (`smaller`) or too large.
struct SlipHints {
  const char* smaller;
  const char* larger;
};
SlipHints SlipHintsOf(ModelQuantity quantity) {
  switch (quantity) {
    case ModelQuantity::kCabinMassKg:
      return {"tonnes written as kg?", "grams written as kg?"};
    case ModelQuantity::kMassCentreM:
    case ModelQuantity::kAnchorPointM:
    case ModelQuantity::kOffsetM:
    case ModelQuantity::kMeasuredOffsetM:
      return {nullptr, "mm written as m?"};
    case ModelQuantity::kLinearDensityKgPerM:
    case ModelQuantity::kAttachmentDensityKgPerM:
      return {nullptr, "g/m written as kg/m?"};
    case ModelQuantity::kAttachmentMassKg:
      return {nullptr, "grams written as kg?"};
    case ModelQuantity::kAttachmentPositionM:
    case ModelQuantity::kPartOriginM:
    case ModelQuantity::kLengthOffsetM:
    case ModelQuantity::kLengthSigmaM:
      return {nullptr, "mm written as m?"};
    case ModelQuantity::kEaN:
      return {"kN written as N?", nullptr};
    case ModelQuantity::kCabinInertiaKgM2:
      return {"t m^2 written as kg m^2?", nullptr};
    case ModelQuantity::kSensorBiasN:
    case ModelQuantity::kTensionSigmaN:
      return {nullptr, "N written as kN?"};
    default:
      return {nullptr, nullptr};
  }
}

std::string WithFileUnit(double value, const char* unit) {
  return *unit == '\0' ? Num(value) : Num(value) + (std::string(unit) == "%" ? "" : " ") + unit;
}

}  // namespace

bool CheckQuantity(ModelQuantity quantity, double value_si, const PlausibilityLimits& limits,
                   std::string* why) {
  const QuantityRange range = PlausibleRange(quantity, limits);
  if (value_si >= range.min && value_si <= range.max) return true;
  const double k = range.si_per_file_unit;
  std::string message;
  if (!std::isfinite(value_si)) {
    message = "must be finite";
  } else if (range.min == -range.max) {
    message = WithFileUnit(value_si / k, range.file_unit) + " is beyond the plausible +-" +
              WithFileUnit(range.max / k, range.file_unit);
  } else if (value_si < range.min) {
    message = WithFileUnit(value_si / k, range.file_unit) + " is below the plausible minimum of " +
              WithFileUnit(range.min / k, range.file_unit);
  } else {
    message = WithFileUnit(value_si / k, range.file_unit) + " is above the plausible maximum of " +
              WithFileUnit(range.max / k, range.file_unit);
  }
  std::string context;
  if (range.nominal != 0.0) {
    context = "nominal FAST: " + WithFileUnit(range.nominal / k, range.file_unit);
  }
  const SlipHints hints = SlipHintsOf(quantity);
  auto plausible = [&](double v) { return v >= range.min && v <= range.max; };
  const char* hint = nullptr;
  if (hints.smaller != nullptr && plausible(value_si * 1e3)) hint = hints.smaller;
  if (hints.larger != nullptr && plausible(value_si / 1e3)) hint = hints.larger;
  if (hint != nullptr) context += (context.empty() ? "" : "; ") + std::string(hint);
  if (std::isfinite(value_si) && !context.empty()) message += " (" + context + ")";
  return Fail(why, message);
}

double LowestPlausibleZ(double horizontal_radius_m, const PlausibilityLimits& limits) {
  const double r = limits.reflector_radius_m;
  const double rho = std::min(horizontal_radius_m, limits.reflector_aperture_radius_m);
  const double surface_z = r - std::sqrt(std::max(0.0, r * r - rho * rho));
  return std::max(0.0, surface_z - limits.below_reflector_margin_m);
}

bool CheckTensionN(double tension_n, const PlausibilityLimits& limits, std::string* why) {
  if (tension_n < 0.0) {
    return Fail(why, Num(tension_n / 1e3) + " kN is negative: a tension reading is >= 0");
  }
  if (!(tension_n <= limits.max_tension_n)) {
    return Fail(why, NumBeyond(tension_n / 1e3, limits.max_tension_n / 1e3) +
                         " kN is above the plausible maximum of " +
                         Num(limits.max_tension_n / 1e3) + " kN");
  }
  return true;
}

bool CheckPosition(const Eigen::Vector3d& position_m, const PlausibilityLimits& limits,
                   std::string* why) {
  if (!position_m.allFinite()) return Fail(why, "the position is not finite");
  const double rho = std::hypot(position_m.x(), position_m.y());
  if (!(rho <= limits.max_horizontal_radius_m)) {
    return Fail(why, "the position is " + NumBeyond(rho, limits.max_horizontal_radius_m) +
                         " m from the axis, beyond the ring of towers (at most " +
                         Num(limits.max_horizontal_radius_m) + " m)");
  }
  const double z = position_m.z();
  if (!(z <= limits.max_height_m)) {
    return Fail(why, "z = " + NumBeyond(z, limits.max_height_m) +
                         " m is above the tower tops (at most " + Num(limits.max_height_m) + " m)");
  }
  const double lowest = LowestPlausibleZ(rho, limits);
  if (!(z >= lowest)) {
    return Fail(why, "z = " + NumBeyond(z, lowest) + " m is below the reflector (z >= " +
                         Num(lowest) + " m at " + Num(rho) + " m from the axis)");
  }
  return true;
}

bool CheckAngleDeg(double angle_deg, const PlausibilityLimits& limits, std::string* why) {
  if (!(std::abs(angle_deg) <= limits.max_abs_angle_deg)) {
    const std::string shown =
        (angle_deg < 0.0 ? "-" : "") + NumBeyond(std::abs(angle_deg), limits.max_abs_angle_deg);
    return Fail(why,
                shown + " deg is beyond the plausible +-" + Num(limits.max_abs_angle_deg) + " deg");
  }
  return true;
}

bool CheckRotationVector(const Eigen::Vector3d& rotation_vector_rad,
                         const PlausibilityLimits& limits, std::string* why) {
  const double angle = rotation_vector_rad.norm();
  if (!(angle <= limits.max_rotation_vector_rad)) {
    return Fail(why, "a rotation of " + NumBeyond(angle, limits.max_rotation_vector_rad) +
                         " rad is beyond the plausible " + Num(limits.max_rotation_vector_rad) +
                         " rad (one turn)");
  }
  return true;
}

bool CheckUnstretchedLengthM(double length_m, const PlausibilityLimits& limits, std::string* why) {
  if (!(length_m > 0.0)) return Fail(why, "unstretched length must be > 0");
  if (!(length_m <= limits.max_unstretched_length_m)) {
    return Fail(why, NumBeyond(length_m, limits.max_unstretched_length_m) +
                         " m is above the plausible maximum of " +
                         Num(limits.max_unstretched_length_m) + " m");
  }
  return true;
}

}  // namespace fastcal
