// Plausibility limits of input values (plausibility.h).
#include "fastcal/plausibility.h"

#include <algorithm>
#include <cmath>

#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

std::string Num(double value) { return internal::FormatDouble("%.6g", value); }

// `value` beyond `limit`, with as many digits as it takes to look different from it
// ("300.00001 m is above 300 m", not "300 m is above 300 m").
std::string NumBeyond(double value, double limit) {
  for (const char* format : {"%.6g", "%.10g"}) {
    const std::string shown = internal::FormatDouble(format, value);
    if (shown != Num(limit)) return shown;
  }
  return internal::FormatDouble("%.17g", value);
}

bool Fail(std::string* why, const std::string& message) {
  if (why != nullptr) *why = message;
  return false;
}

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
      {"max_unstretched_length_m", max_unstretched_length_m}};
  for (const auto& [name, value] : fields) {
    if (!(std::isfinite(value) && value > 0.0)) {
      return Fail(error, std::string(name) + ": must be > 0 and finite (got " + Num(value) + ")");
    }
  }
  if (reflector_aperture_radius_m > reflector_radius_m) {
    return Fail(error, "reflector_aperture_radius_m: must be <= reflector_radius_m");
  }
  return true;
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
