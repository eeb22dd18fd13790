// Nominal FAST model and physical validation (layout: cable_robot.h, paper eqs. 1-2 and
// Table 1).
#include "fastcal/cable_robot.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>

namespace fastcal {
namespace {
// Two tower tops or two anchor points closer than this are "coincident".
constexpr double kCoincidentDistanceM = 1e-6;
// A rigid body's inertia about its mass centre: finite, symmetric (to rounding), positive
// definite, and its principal moments obey the triangle inequality (I1 + I2 >= I3), which
// every real mass distribution does.
bool IsCabinInertiaValid(const Eigen::Matrix3d& inertia, std::string* why) {
  if (!inertia.allFinite()) return *why = "must be finite", false;
  const double scale = inertia.cwiseAbs().maxCoeff();
  if (!((inertia - inertia.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale)) {
    return *why = "must be symmetric", false;
  }
  const Eigen::Vector3d moments =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(moments[0] > 0.0)) return *why = "must be positive definite (kg m^2)", false;
  if (moments[0] + moments[1] < moments[2] * (1.0 - 1e-12)) {
    return *why = "principal moments must obey I1 + I2 >= I3 (no rigid body has these)", false;
  }
  return true;
}
}  // namespace

CableRobot CableRobot::NominalFast() {
  constexpr double kAnchorRadiusM = 7.5, kTowerRadiusM = 300.0, kTowerHeightM = 270.0;
  CableRobot robot;
  robot.anchor_points_cabin_m.clear();
  for (int j = 0; j < 3; ++j) {
    const double angle = M_PI / 6.0 + 2.0 * M_PI * j / 3.0;
    robot.anchor_points_cabin_m.emplace_back(kAnchorRadiusM * std::cos(angle),
                                             kAnchorRadiusM * std::sin(angle), 0.0);
  }
  for (int i = 0; i < kNumCables; ++i) {
    const double angle = M_PI * i / 3.0;
    CableProperties& c = robot.cables[i];
    c.tower_top_m = Eigen::Vector3d(kTowerRadiusM * std::cos(angle),
                                    kTowerRadiusM * std::sin(angle), kTowerHeightM);
    c.anchor_index = i / 2;
    c.ea_n = 1.6e11 * 1.541e-4;
    c.linear_density_kg_per_m = 11.718;
  }
  robot.cabin_mass_kg = 30000.0;
  robot.mass_centre_cabin_m = Eigen::Vector3d(0.0, 0.0, 0.5);
  robot.gravity_m_per_s2 = -9.8;
  robot.reflector = Reflector();
  return robot;
}

bool CableRobot::IsValid(std::string* error) const {
  std::ostringstream e;
  auto fail = [&](const std::string& key, const std::string& why) {
    if (error != nullptr) *error = key + ": " + why;
    return false;
  };
  if (anchor_points_cabin_m.empty()) return fail("anchor_points_cabin_m", "at least one is needed");
  for (size_t j = 0; j < anchor_points_cabin_m.size(); ++j) {
    const std::string key = "anchor_points_cabin_m[" + std::to_string(j) + "]";
    if (!anchor_points_cabin_m[j].allFinite()) return fail(key, "must be finite");
    for (size_t k = 0; k < j; ++k) {
      if ((anchor_points_cabin_m[j] - anchor_points_cabin_m[k]).norm() < kCoincidentDistanceM) {
        return fail(key, "coincides with anchor_points_cabin_m[" + std::to_string(k) + "]");
      }
    }
  }
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = cables[i];
    const std::string key = "cables[" + std::to_string(i) + "]";
    if (!c.tower_top_m.allFinite()) return fail(key + ".tower_top_m", "must be finite");
    for (int k = 0; k < i; ++k) {
      if ((c.tower_top_m - cables[k].tower_top_m).norm() < kCoincidentDistanceM) {
        return fail(key + ".tower_top_m", "coincides with cables[" + std::to_string(k) + "]");
      }
    }
    if (c.anchor_index < 0 || c.anchor_index >= static_cast<int>(anchor_points_cabin_m.size())) {
      return fail(key + ".anchor", "index " + std::to_string(c.anchor_index) +
                                       " is not an anchor point (0.." +
                                       std::to_string(anchor_points_cabin_m.size() - 1) + ")");
    }
    if (!(c.ea_n > 0.0) || !std::isfinite(c.ea_n)) return fail(key + ".ea_n", "must be > 0");
    if (!(c.linear_density_kg_per_m > 0.0) || !std::isfinite(c.linear_density_kg_per_m)) {
      return fail(key + ".linear_density_kg_per_m", "must be > 0");
    }
    if (!(c.sensor_gain > 0.0) || !std::isfinite(c.sensor_gain)) {
      return fail(key + ".sensor_gain", "must be > 0");
    }
    if (!std::isfinite(c.sensor_bias_n)) return fail(key + ".sensor_bias_kN", "must be finite");
    if (!std::isfinite(c.length_offset_m)) return fail(key + ".length_offset_m", "must be finite");
    if (c.attachments.size() > static_cast<size_t>(kMaxAttachmentsPerCable)) {
      return fail(key + ".attachments",
                  "has " + std::to_string(c.attachments.size()) + " entries; at most " +
                      std::to_string(kMaxAttachmentsPerCable) + " per cable are supported");
    }
    for (size_t j = 0; j < c.attachments.size(); ++j) {
      std::string why;
      if (!c.attachments[j].IsValid(&why)) {
        return fail(key + ".attachments[" + std::to_string(j) + "]." + why.substr(0, why.find(':')),
                    why.substr(why.find(": ") + 2));
      }
    }
  }
  if (!(cabin_mass_kg > 0.0) || !std::isfinite(cabin_mass_kg)) {
    return fail("cabin_mass_kg", "must be > 0");
  }
  if (!mass_centre_cabin_m.allFinite()) return fail("mass_centre_cabin_m", "must be finite");
  if (!moving_parts.IsValid(error)) return false;
  if (measured_frame.has_value() && !measured_frame->IsValid(moving_parts, error)) return false;
  if (std::string why; !IsCabinInertiaValid(cabin_inertia_kg_m2, &why)) {
    return fail("cabin_inertia_kg_m2", why);
  }
  if (reflector.has_value()) {
    if (!reflector->centre_m.allFinite()) return fail("reflector.centre_m", "must be finite");
    if (!(reflector->radius_m > 0.0) || !std::isfinite(reflector->radius_m)) {
      return fail("reflector.radius_m", "must be > 0");
    }
    if (!(reflector->aperture_m > 0.0) || !(reflector->aperture_m <= 2.0 * reflector->radius_m)) {
      return fail("reflector.aperture_m", "must be > 0 and at most 2 radius_m");
    }
  }
  if (!(gravity_m_per_s2 < 0.0) || !std::isfinite(gravity_m_per_s2)) {
    return fail("gravity_m_per_s2", "must be < 0 (z is up)");
  }
  return true;
}

Eigen::Vector3d CableRobot::MassCentreAt(const JointValues& joints) const {
  if (moving_parts.empty()) return mass_centre_cabin_m;
  PartShifts shifts;
  moving_parts.ShiftsAt(joints, &shifts);
  return mass_centre_cabin_m + moving_parts.MassCentreShift(shifts, cabin_mass_kg);
}

Pose CableRobot::CabinPose(const Pose& measured, const JointValues& joints) const {
  if (!measured_frame.has_value()) return measured;
  return CabinPoseFromMeasured(*measured_frame, moving_parts, measured, joints);
}

Pose CableRobot::MeasuredPose(const Pose& cabin, const JointValues& joints) const {
  if (!measured_frame.has_value()) return cabin;
  return MeasuredPoseFromCabin(*measured_frame, moving_parts, cabin, joints);
}

bool CableAttachment::IsValid(std::string* error) const {
  auto fail = [&](const char* key, const std::string& why) {
    if (error != nullptr) *error = std::string(key) + ": " + why;
    return false;
  };
  if (kind == AttachmentKind::kPointMass) {
    if (!(at_m >= 0.0) || !std::isfinite(at_m))
      return fail("at_m", "must be >= 0 (m from the lower end)");
    if (!(mass_kg >= 0.0) || !std::isfinite(mass_kg)) return fail("mass_kg", "must be >= 0");
    return true;
  }
  if (!(from_m >= 0.0) || !std::isfinite(from_m)) {
    return fail("from_m", "must be >= 0 (m from the lower end)");
  }
  if (!(to_m > from_m) || !std::isfinite(to_m)) return fail("to_m", "must be > from_m");
  if (!(added_density_kg_per_m >= 0.0) || !std::isfinite(added_density_kg_per_m)) {
    return fail("added_density_kg_per_m", "must be >= 0");
  }
  return true;
}

}  // namespace fastcal
