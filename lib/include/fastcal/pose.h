// Cabin pose: position of the cabin-frame origin O' in the global frame and the attitude
// R, the rotation taking cabin-frame vectors to the global frame (docs/model.md).
//
// Attitude parametrisations:
//   roll/pitch/yaw in degrees:  R = Rz(yaw) Ry(pitch) Rx(roll)  (extrinsic x, then y, then z)
//   unit quaternion (w, x, y, z), Hamilton convention, R = R(q)
//   rotation vector v (rad):     R = exp([v]x), angle |v| about v/|v|
// Focal attitude law (model.md, "Reference values"): tilt z' toward the centre C of the
// focal sphere by f times the off-axis angle, about the horizontal axis z x u, where u is
// the unit vector from the position to C:  R = AngleAxis(f * asin(|z x u|), z x u / |z x u|).
// With f = 0.41 and C = (0, 0, 300) m it reproduces the paper's Tables 3-5.
#ifndef FASTCAL_POSE_H_
#define FASTCAL_POSE_H_

#include <Eigen/Core>
#include <string>

namespace fastcal {

struct Pose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // cabin frame -> global frame
};

// True when every entry of position and rotation is finite.
bool IsFinite(const Pose& pose);

Eigen::Matrix3d RotationFromRpyDeg(double roll_deg, double pitch_deg, double yaw_deg);
// Inverse of RotationFromRpyDeg; pitch in [-90, 90] deg.
Eigen::Vector3d RpyDegFromRotation(const Eigen::Matrix3d& rotation);

// Tolerance on | |q| - 1 | for a quaternion given as "unit": values typed or exported
// with a few digits are accepted and normalised; anything further off is an error.
inline constexpr double kQuaternionUnitTolerance = 1e-3;
// Returns false (with *error) for a non-finite or non-unit quaternion.
bool RotationFromQuaternion(double w, double x, double y, double z, Eigen::Matrix3d* rotation,
                            std::string* error);
Eigen::Vector4d QuaternionFromRotation(const Eigen::Matrix3d& rotation);  // (w, x, y, z), w >= 0

Eigen::Matrix3d RotationFromRotationVector(const Eigen::Vector3d& rotation_vector_rad);

struct FocalAttitudeLaw {
  // Fraction of the off-axis angle by which z' is tilted toward the focal-sphere centre,
  // in [0, 1]: 0 keeps the cabin level, 1 points z' at the centre.
  double tilt_fraction = 0.41;
  // Centre of the focal sphere, global frame.
  Eigen::Vector3d focal_centre_m = Eigen::Vector3d(0.0, 0.0, 300.0);
};
// Attitude the law prescribes at `position_m`. At the axis (|z x u| = 0) it is identity.
Eigen::Matrix3d FocalAttitude(const Eigen::Vector3d& position_m, const FocalAttitudeLaw& law);

}  // namespace fastcal

#endif  // FASTCAL_POSE_H_
