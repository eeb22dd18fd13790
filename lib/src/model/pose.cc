// Attitude conversions and the focal attitude law (equations: pose.h).
#include "fastcal/pose.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace fastcal {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
// Below this |z x u| the position is on the focal axis and the law gives identity.
constexpr double kOnAxisSine = 1e-12;
// Below this cos(pitch) roll and yaw are indistinguishable (rounding level of R's entries).
constexpr double kGimbalLockCos = 1e-12;
}  // namespace

bool IsFinite(const Pose& pose) { return pose.position_m.allFinite() && pose.rotation.allFinite(); }

Eigen::Matrix3d RotationFromRpyDeg(double roll_deg, double pitch_deg, double yaw_deg) {
  return (Eigen::AngleAxisd(yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * kDegToRad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d RpyDegFromRotation(const Eigen::Matrix3d& r) {
  // R = Rz(y) Ry(p) Rx(r): row 2 is (-sin p, cos p sin r, cos p cos r). Pitch from atan2, not
  // asin(-R(2,0)), which loses half the digits near +-90 deg. Yaw from M = R Rx(roll)^T =
  // Rz(y) Ry(p), whose M(0,1) = -sin y and M(1,1) = cos y are not scaled by cos p, so R is
  // reproduced to rounding even at (and near) gimbal lock.
  const double cos_pitch = std::hypot(r(2, 1), r(2, 2));
  const double pitch = std::atan2(-r(2, 0), cos_pitch);
  // Gimbal lock: put all of the rotation about z into yaw.
  const double roll = cos_pitch < kGimbalLockCos ? 0.0 : std::atan2(r(2, 1), r(2, 2));
  const double s = std::sin(roll), c = std::cos(roll);
  const double yaw = std::atan2(s * r(0, 2) - c * r(0, 1), c * r(1, 1) - s * r(1, 2));
  return Eigen::Vector3d(roll, pitch, yaw) / kDegToRad;
}

bool RotationFromQuaternion(double w, double x, double y, double z, Eigen::Matrix3d* rotation,
                            std::string* error) {
  const Eigen::Vector4d q(w, x, y, z);
  if (!q.allFinite()) {
    if (error != nullptr) *error = "quaternion has a non-finite component";
    return false;
  }
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > kQuaternionUnitTolerance) {
    if (error != nullptr) {
      std::ostringstream s;
      s << "quaternion (w,x,y,z) must be unit: |q| = " << norm << " (tolerance "
        << kQuaternionUnitTolerance << ")";
      *error = s.str();
    }
    return false;
  }
  *rotation = Eigen::Quaterniond(w / norm, x / norm, y / norm, z / norm).toRotationMatrix();
  return true;
}

Eigen::Vector4d QuaternionFromRotation(const Eigen::Matrix3d& rotation) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;
  return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
}

Eigen::Matrix3d RotationFromRotationVector(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

Eigen::Matrix3d FocalAttitude(const Eigen::Vector3d& position_m, const FocalAttitudeLaw& law) {
  const Eigen::Vector3d u = (law.focal_centre_m - position_m).normalized();
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(u);
  const double sine = axis.norm();
  if (sine < kOnAxisSine) return Eigen::Matrix3d::Identity();
  // asin(|z x u|) is the off-axis angle for u in the upper half space (the workspace).
  const double angle = law.tilt_fraction * std::asin(std::min(sine, 1.0));
  return Eigen::AngleAxisd(angle, axis / sine).toRotationMatrix();
}

}  // namespace fastcal
