// Plausibility of a whole model (model_plausibility.h).
#include "fastcal/model_plausibility.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

std::string Num(double value) { return internal::FormatDouble("%.6g", value); }

std::string Vec(const Eigen::Vector3d& v) {
  return "(" + Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z()) + ")";
}

// One value of a model with its key path, quantity and nominal value.
struct ModelValue {
  std::string path;
  ModelQuantity quantity;
  double value_si;
  double nominal_si;
};

// The cabin's principal moments of inertia: the diagonal as given when the tensor is
// diagonal in the cabin frame (the file's usual [Ixx, Iyy, Izz], named by index), else its
// eigenvalues, ascending.
void AddInertiaValues(const Eigen::Matrix3d& inertia, const Eigen::Matrix3d& nominal,
                      std::vector<ModelValue>* values) {
  const std::string key = "cabin.inertia_kg_m2";
  if (inertia.isDiagonal(0.0)) {
    for (int a = 0; a < 3; ++a) {
      values->push_back({key + "[" + std::to_string(a) + "]", ModelQuantity::kCabinInertiaKgM2,
                         inertia(a, a), nominal(a, a)});
    }
    return;
  }
  const Eigen::Vector3d moments =
      inertia.allFinite()
          ? Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia, Eigen::EigenvaluesOnly)
                .eigenvalues()
          : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  for (int a = 0; a < 3; ++a) {
    values->push_back({key + " (principal moment " + std::to_string(a + 1) + ")",
                       ModelQuantity::kCabinInertiaKgM2, moments[a], nominal(a, a)});
  }
}

// Every scalar value of `robot` that has a plausible range, with the nominal FAST
// model's value beside it (components of vectors each on their own).
std::vector<ModelValue> ModelValues(const CableRobot& robot) {
  static const CableRobot nominal = CableRobot::NominalFast();
  static const char kAxes[] = "xyz";
  std::vector<ModelValue> values;
  values.push_back({"gravity_m_per_s2", ModelQuantity::kGravityMPerS2, robot.gravity_m_per_s2,
                    nominal.gravity_m_per_s2});
  if (robot.reflector.has_value()) {
    values.push_back({"reflector.radius_m", ModelQuantity::kReflectorRadiusM,
                      robot.reflector->radius_m, nominal.reflector->radius_m});
    values.push_back({"reflector.aperture_m", ModelQuantity::kReflectorApertureM,
                      robot.reflector->aperture_m, nominal.reflector->aperture_m});
  }
  values.push_back(
      {"cabin.mass_kg", ModelQuantity::kCabinMassKg, robot.cabin_mass_kg, nominal.cabin_mass_kg});
  for (int a = 0; a < 3; ++a) {
    values.push_back({std::string("cabin.mass_centre_m.") + kAxes[a], ModelQuantity::kMassCentreM,
                      robot.mass_centre_cabin_m[a], nominal.mass_centre_cabin_m[a]});
  }
  AddInertiaValues(robot.cabin_inertia_kg_m2, nominal.cabin_inertia_kg_m2, &values);
  for (size_t k = 0; k < robot.moving_parts.parts.size(); ++k) {
    const MovingPart& part = robot.moving_parts.parts[k];
    const std::string key = "cabin.moving_parts[" + std::to_string(k) + "].";
    for (int a = 0; a < 3; ++a) {
      values.push_back({key + "first_moment_kg_m." + kAxes[a], ModelQuantity::kPartFirstMomentKgM,
                        part.first_moment_kg_m[a], 0.0});
    }
    for (int a = 0; a < 3; ++a) {
      values.push_back(
          {key + "origin_m." + kAxes[a], ModelQuantity::kPartOriginM, part.origin_m[a], 0.0});
    }
    values.push_back({key + "mass_kg", ModelQuantity::kPartMassKg, part.mass_kg, 0.0});
  }
  if (robot.measured_frame.has_value()) {
    for (int a = 0; a < 3; ++a) {
      values.push_back({std::string("cabin.measured_frame.offset_m.") + kAxes[a],
                        ModelQuantity::kMeasuredOffsetM, robot.measured_frame->offset_m[a], 0.0});
    }
  }
  for (size_t j = 0; j < robot.anchor_points_cabin_m.size(); ++j) {
    const Eigen::Vector3d nominal_point = j < nominal.anchor_points_cabin_m.size()
                                              ? nominal.anchor_points_cabin_m[j]
                                              : robot.anchor_points_cabin_m[j];
    for (int a = 0; a < 3; ++a) {
      values.push_back({"cabin.anchor_points_m[" + std::to_string(j) + "]." + kAxes[a],
                        ModelQuantity::kAnchorPointM, robot.anchor_points_cabin_m[j][a],
                        nominal_point[a]});
    }
  }
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = robot.cables[i];
    const CableProperties& n = nominal.cables[i];
    const std::string key = "cables[" + std::to_string(i) + "].";
    values.push_back({key + "ea_n", ModelQuantity::kEaN, c.ea_n, n.ea_n});
    values.push_back({key + "linear_density_kg_per_m", ModelQuantity::kLinearDensityKgPerM,
                      c.linear_density_kg_per_m, n.linear_density_kg_per_m});
    values.push_back({key + "sensor_gain", ModelQuantity::kSensorGain, c.sensor_gain, 1.0});
    values.push_back({key + "sensor_bias_kN", ModelQuantity::kSensorBiasN, c.sensor_bias_n, 0.0});
    values.push_back(
        {key + "length_offset_m", ModelQuantity::kLengthOffsetM, c.length_offset_m, 0.0});
    for (size_t j = 0; j < c.attachments.size(); ++j) {
      CableAttachment a = c.attachments[j];
      const std::string at = key + "attachments[" + std::to_string(j) + "].";
      for (const auto& [name, value] : a.Fields()) {
        const std::string field = name;
        const ModelQuantity q = field == "mass_kg" ? ModelQuantity::kAttachmentMassKg
                                : field == "added_density_kg_per_m"
                                    ? ModelQuantity::kAttachmentDensityKgPerM
                                    : ModelQuantity::kAttachmentPositionM;
        values.push_back({at + field, q, *value, *value});  // no nominal: its own value
      }
    }
  }
  return values;
}

// How far a value is from nominal, in units of its plausible range (model_plausibility.h).
double Departure(const ModelValue& v, const PlausibilityLimits& limits) {
  const QuantityRange range = PlausibleRange(v.quantity, limits);
  if (range.min > 0.0 && v.value_si > 0.0 && v.nominal_si > 0.0) {
    return std::abs(std::log(v.value_si / v.nominal_si)) / std::log(range.max / range.nominal);
  }
  return std::abs(v.value_si - v.nominal_si) / std::max(std::abs(range.min), std::abs(range.max));
}

std::string InFileUnit(double value_si, const QuantityRange& range) {
  const std::string unit = range.file_unit;
  return Num(value_si / range.si_per_file_unit) + (unit.empty() ? "" : " " + unit);
}

// The reflector's centre near (0, 0, radius): the global origin is its lowest point.
bool CheckReflectorCentre(const Reflector& reflector, const PlausibilityLimits& limits,
                          std::string* why) {
  const Eigen::Vector3d expected(0.0, 0.0, reflector.radius_m);
  const Eigen::Vector3d off = reflector.centre_m - expected;
  if (off.cwiseAbs().maxCoeff() <= limits.max_reflector_offset_m) return true;
  *why = "reflector.centre_m: " + Vec(reflector.centre_m) + " m is more than " +
         Num(limits.max_reflector_offset_m) + " m from (0, 0, radius_m) = " + Vec(expected) +
         " m (the global origin is the reflector's lowest point; FAST: (0, 0, 300) m)";
  return false;
}

// Tower tops far enough from the axis, high enough, and around it (no gap wider than
// max_tower_gap_deg between neighbours, seen from the axis).
bool CheckTowerLayout(const CableRobot& robot, const PlausibilityLimits& limits, std::string* why) {
  std::vector<std::pair<double, int>> azimuths;
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d& top = robot.cables[i].tower_top_m;
    const std::string key = "cables[" + std::to_string(i) + "].tower_top_m: ";
    const double radius = top.head<2>().norm();
    if (!(radius >= limits.min_tower_radius_m)) {
      *why = key + Num(radius) + " m from the z axis, less than " + Num(limits.min_tower_radius_m) +
             " m (the towers stand around the workspace; FAST: 300 m)";
      return false;
    }
    if (!(top.z() >= limits.min_tower_top_z_m)) {
      *why = key + "z = " + Num(top.z()) + " m is below " + Num(limits.min_tower_top_z_m) +
             " m (the cabin works at 140 to 160 m and hangs from the tower tops; FAST: 270 m)";
      return false;
    }
    azimuths.emplace_back(std::atan2(top.y(), top.x()) * 180.0 / M_PI, i);
  }
  std::sort(azimuths.begin(), azimuths.end());
  for (size_t k = 0; k < azimuths.size(); ++k) {
    const auto& [from, i] = azimuths[k];
    const auto& [to, j] = azimuths[(k + 1) % azimuths.size()];
    const double gap = k + 1 < azimuths.size() ? to - from : to + 360.0 - from;
    if (gap > limits.max_tower_gap_deg) {
      *why = "cables[" + std::to_string(j) + "].tower_top_m: the towers of cables " +
             std::to_string(i + 1) + " and " + std::to_string(j + 1) + " leave a gap of " +
             Num(gap) + " deg seen from the z axis, more than " + Num(limits.max_tower_gap_deg) +
             " deg: the towers must surround the workspace (FAST: 60 deg apart)";
      return false;
    }
  }
  return true;
}

// The moving parts within the cabin they belong to (issue 57: a part of 40 t in a 30 t
// cabin and a joint range of +-1e9 deg were accepted): their masses together at most the
// whole cabin's (cabin.mass_kg includes them), and each joint's stated range within what a
// joint value may be (PlausibleJointValue: one turn, or 100 m).
bool CheckMovingPartsPlausible(const CableRobot& robot, std::string* why) {
  double parts_kg = 0.0;
  for (size_t k = 0; k < robot.moving_parts.parts.size(); ++k) {
    const MovingPart& part = robot.moving_parts.parts[k];
    const std::string key = "cabin.moving_parts[" + std::to_string(k) + "]";
    parts_kg += part.mass_kg;
    if (parts_kg > robot.cabin_mass_kg) {
      *why = key + ".mass_kg: " + Num(part.mass_kg) + " kg brings the moving parts to " +
             Num(parts_kg) + " kg, more than the whole cabin's " + Num(robot.cabin_mass_kg) +
             " kg (cabin.mass_kg includes its moving parts)";
      return false;
    }
    for (size_t j = 0; j < part.joints.size(); ++j) {
      const Joint& joint = part.joints[j];
      std::string what;
      if (joint.has_range && (!PlausibleJointValue(joint.column, joint.range_low, &what) ||
                              !PlausibleJointValue(joint.column, joint.range_high, &what))) {
        *why = key + ".joints[" + std::to_string(j) + "].range: [" + Num(joint.range_low) + ", " +
               Num(joint.range_high) + "]: " + what;
        return false;
      }
    }
  }
  return true;
}

}  // namespace

bool CheckModelPlausible(const CableRobot& robot, const PlausibilityLimits& limits,
                         std::string* why) {
  std::string what;
  for (const ModelValue& v : ModelValues(robot)) {
    if (!CheckQuantity(v.quantity, v.value_si, limits, &what)) {
      if (why != nullptr) *why = v.path + ": " + what;
      return false;
    }
  }
  if (robot.reflector.has_value() && !CheckReflectorCentre(*robot.reflector, limits, &what)) {
    if (why != nullptr) *why = what;
    return false;
  }
  for (int i = 0; i < kNumCables; ++i) {
    if (!CheckPosition(robot.cables[i].tower_top_m, limits, &what)) {
      if (why != nullptr) *why = "cables[" + std::to_string(i) + "].tower_top_m: " + what;
      return false;
    }
  }
  if (!CheckTowerLayout(robot, limits, &what)) {
    if (why != nullptr) *why = what;
    return false;
  }
  if (!CheckMovingPartsPlausible(robot, &what)) {
    if (why != nullptr) *why = what;
    return false;
  }
  return true;
}

bool CheckModel(const CableRobot& robot, std::string* why) {
  return robot.IsValid(why) && CheckModelPlausible(robot, PlausibilityLimits(), why);
}

std::vector<std::string> FurthestFromNominal(const CableRobot& robot,
                                             const PlausibilityLimits& limits, size_t count) {
  // Below this share of its plausible range a departure is a calibration, not a slip.
  constexpr double kNegligibleDeparture = 0.01;
  // Tower tops: a metre is far (they are surveyed to a centimetre).
  constexpr double kTowerTopScaleM = 1.0;
  static const CableRobot nominal = CableRobot::NominalFast();
  std::vector<std::pair<double, std::string>> found;
  for (const ModelValue& v : ModelValues(robot)) {
    const double d = Departure(v, limits);
    if (!(d > kNegligibleDeparture)) continue;
    const QuantityRange range = PlausibleRange(v.quantity, limits);
    found.emplace_back(d, v.path + " = " + InFileUnit(v.value_si, range) + " (nominal " +
                              InFileUnit(v.nominal_si, range) + ")");
  }
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d& top = robot.cables[i].tower_top_m;
    const Eigen::Vector3d& nominal_top = nominal.cables[i].tower_top_m;
    const double d = (top - nominal_top).norm() / kTowerTopScaleM;
    if (!(d > kNegligibleDeparture)) continue;
    found.emplace_back(d, "cables[" + std::to_string(i) + "].tower_top_m = " + Vec(top) +
                              " m (nominal " + Vec(nominal_top) + " m)");
  }
  std::stable_sort(found.begin(), found.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::string> names;
  for (size_t k = 0; k < std::min(count, found.size()); ++k) names.push_back(found[k].second);
  return names;
}

}  // namespace fastcal
