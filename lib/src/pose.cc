// Attitude conversions and the focal attitude law (equations: pose.h).
#include "fastcal/pose.h"

#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

namespace fastcal {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
// Below this |z x u| the position is on the focal axis and the law gives identity.
constexpr double kOnAxisSine = 1e-12;
}  // namespace

bool IsFinite(const Pose& pose) {
  return pose.position_m.allFinite() && pose.rotation.allFinite();
}

Eigen::Matrix3d RotationFromRpyDeg(double roll_deg, double pitch_deg, double yaw_deg) {
  return (Eigen::AngleAxisd(yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * kDegToRad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d RpyDegFromRotation(const Eigen::Matrix3d& r) {
  // R = Rz(y) Ry(p) Rx(r): R(2,0) = -sin p, R(2,1) = cos p sin r, R(1,0) = sin y cos p.
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  double roll, yaw;
  if (std::abs(r(2, 0)) < 1.0 - 1e-12) {
    roll = std::atan2(r(2, 1), r(2, 2));
    yaw = std::atan2(r(1, 0), r(0, 0));
  } else {  // gimbal lock: put all of the rotation about z into yaw
    roll = 0.0;
    yaw = std::atan2(-r(0, 1), r(1, 1));
  }
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
