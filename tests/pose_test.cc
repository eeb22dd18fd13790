// Tests of the attitude conversions and the focal attitude law (pose.h): the RPY
// convention against elementary matrices written out by hand, round trips between the
// parametrisations on seeded random attitudes, quaternion validation, and the geometry
// of the focal law (tilt angle, plane and direction).
#include "fastcal/pose.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace fastcal {
namespace {

constexpr uint64_t kSeed = 20240918;
constexpr int kRandomSamples = 1000;
constexpr double kDeg = M_PI / 180.0;
// Products of a few rotations in double: entries agree to a few ulps.
constexpr double kMatrixTol = 1e-14;
// RPY recovered from a rotation matrix: a few ulps of the angle, in degrees.
constexpr double kAngleTolDeg = 1e-11;
// The focal law's tilt, plane and direction, computed through acos/asin.
constexpr double kFocalAngleTolDeg = 1e-9;
constexpr double kFocalPlaneTol = 1e-12;

Eigen::Matrix3d Rx(double a_deg) {
  const double c = std::cos(a_deg * kDeg), s = std::sin(a_deg * kDeg);
  Eigen::Matrix3d r;
  r << 1, 0, 0,  //
      0, c, -s,  //
      0, s, c;
  return r;
}
Eigen::Matrix3d Ry(double a_deg) {
  const double c = std::cos(a_deg * kDeg), s = std::sin(a_deg * kDeg);
  Eigen::Matrix3d r;
  r << c, 0, s,  //
      0, 1, 0,   //
      -s, 0, c;
  return r;
}
Eigen::Matrix3d Rz(double a_deg) {
  const double c = std::cos(a_deg * kDeg), s = std::sin(a_deg * kDeg);
  Eigen::Matrix3d r;
  r << c, -s, 0,  //
      s, c, 0,    //
      0, 0, 1;
  return r;
}

double MaxAbsDiff(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

void ExpectProperRotation(const Eigen::Matrix3d& r) {
  EXPECT_LT(MaxAbsDiff(r.transpose() * r, Eigen::Matrix3d::Identity()), kMatrixTol);
  EXPECT_NEAR(r.determinant(), 1.0, kMatrixTol);
}

// Uniformly distributed unit quaternion (w, x, y, z), w >= 0.
Eigen::Vector4d RandomUnitQuaternion(std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector4d q(normal(*rng), normal(*rng), normal(*rng), normal(*rng));
  q.normalize();
  if (q[0] < 0) q = -q;
  return q;
}

TEST(RotationFromRpyDeg, IsRzTimesRyTimesRxOfElementaryMatrices) {
  constexpr double kRollDeg = 10.0, kPitchDeg = -20.0, kYawDeg = 35.0;
  const Eigen::Matrix3d r = RotationFromRpyDeg(kRollDeg, kPitchDeg, kYawDeg);
  EXPECT_LT(MaxAbsDiff(r, Rz(kYawDeg) * Ry(kPitchDeg) * Rx(kRollDeg)), kMatrixTol) << r;
  // The other order is a different matrix, so the check above pins the order.
  EXPECT_GT(MaxAbsDiff(r, Rx(kRollDeg) * Ry(kPitchDeg) * Rz(kYawDeg)), 1e-3);
}

TEST(RotationFromRpyDeg, EachAngleRotatesAboutItsAxisPositively) {
  // roll 90: y -> z; pitch 90: z -> x; yaw 90: x -> y (right-handed, counter-clockwise).
  EXPECT_LT(
      (RotationFromRpyDeg(90, 0, 0) * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(),
      kMatrixTol);
  EXPECT_LT(
      (RotationFromRpyDeg(0, 90, 0) * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(),
      kMatrixTol);
  EXPECT_LT(
      (RotationFromRpyDeg(0, 0, 90) * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
      kMatrixTol);
  EXPECT_EQ(RotationFromRpyDeg(0, 0, 0), Eigen::Matrix3d::Identity());
}

TEST(RpyDegFromRotation, RoundTripOnRandomAngles) {
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> roll_yaw(-179.0, 179.0), pitch(-89.0, 89.0);
  for (int n = 0; n < kRandomSamples; ++n) {
    const Eigen::Vector3d rpy(roll_yaw(rng), pitch(rng), roll_yaw(rng));
    const Eigen::Matrix3d r = RotationFromRpyDeg(rpy[0], rpy[1], rpy[2]);
    ExpectProperRotation(r);
    const Eigen::Vector3d back = RpyDegFromRotation(r);
    for (int k = 0; k < 3; ++k) {
      ASSERT_NEAR(back[k], rpy[k], kAngleTolDeg) << "sample " << n << " angle " << k;
    }
  }
}

TEST(RpyDegFromRotation, AtAndNearGimbalLockReproducesRotation) {
  // At exactly +-90 deg pitch only yaw -+ roll is defined: all of it goes into yaw.
  for (const double pitch_deg : {90.0, -90.0}) {
    const Eigen::Matrix3d r = RotationFromRpyDeg(25.0, pitch_deg, -40.0);
    const Eigen::Vector3d back = RpyDegFromRotation(r);
    EXPECT_EQ(back[0], 0.0);
    EXPECT_NEAR(back[1], pitch_deg, kAngleTolDeg);
    EXPECT_LT(MaxAbsDiff(RotationFromRpyDeg(back[0], back[1], back[2]), r), kMatrixTol)
        << back.transpose();
  }
  // Just off the lock the pitch is still recovered to full precision (asin would not).
  for (const double pitch_deg : {90.0 - 1e-7, -90.0 + 1e-5, 89.999}) {
    const Eigen::Matrix3d r = RotationFromRpyDeg(25.0, pitch_deg, -40.0);
    const Eigen::Vector3d back = RpyDegFromRotation(r);
    EXPECT_NEAR(back[1], pitch_deg, kAngleTolDeg) << pitch_deg;
    EXPECT_LT(MaxAbsDiff(RotationFromRpyDeg(back[0], back[1], back[2]), r), kMatrixTol)
        << pitch_deg << ": " << back.transpose();
  }
}

TEST(RotationFromQuaternion, IdentityAnd90DegreesAboutZ) {
  Eigen::Matrix3d r;
  std::string error;
  ASSERT_TRUE(RotationFromQuaternion(1, 0, 0, 0, &r, &error)) << error;
  EXPECT_EQ(r, Eigen::Matrix3d::Identity());

  const double h = std::sqrt(0.5);  // cos 45 = sin 45
  ASSERT_TRUE(RotationFromQuaternion(h, 0, 0, h, &r, &error)) << error;
  Eigen::Matrix3d expected;
  expected << 0, -1, 0,  //
      1, 0, 0,           //
      0, 0, 1;
  EXPECT_LT(MaxAbsDiff(r, expected), kMatrixTol) << r;
}

TEST(RotationFromQuaternion, NonUnitBeyondToleranceIsRejected) {
  constexpr double kScale = 1.0 + 2.0 * kQuaternionUnitTolerance;
  Eigen::Matrix3d r = Eigen::Matrix3d::Constant(7.0);
  std::string error;
  EXPECT_FALSE(
      RotationFromQuaternion(kScale * 0.5, kScale * 0.5, kScale * 0.5, kScale * 0.5, &r, &error));
  EXPECT_NE(error.find("unit"), std::string::npos) << error;
  EXPECT_EQ(r, Eigen::Matrix3d::Constant(7.0));  // untouched
  error.clear();
  EXPECT_FALSE(RotationFromQuaternion(0, 0, 0, 0, &r, &error));
  EXPECT_FALSE(error.empty());
}

TEST(RotationFromQuaternion, SlightlyNonUnitIsAcceptedAndNormalised) {
  // Well inside the tolerance, as a quaternion typed with a few digits would be.
  constexpr double kScale = 1.0 + 0.5 * kQuaternionUnitTolerance;
  std::mt19937_64 rng(kSeed);
  const Eigen::Vector4d q = RandomUnitQuaternion(&rng);
  Eigen::Matrix3d unit, scaled;
  std::string error;
  ASSERT_TRUE(RotationFromQuaternion(q[0], q[1], q[2], q[3], &unit, &error)) << error;
  ASSERT_TRUE(RotationFromQuaternion(kScale * q[0], kScale * q[1], kScale * q[2], kScale * q[3],
                                     &scaled, &error))
      << error;
  ExpectProperRotation(scaled);
  EXPECT_LT(MaxAbsDiff(scaled, unit), kMatrixTol);
}

TEST(RotationFromQuaternion, NonFiniteIsRejected) {
  Eigen::Matrix3d r;
  std::string error;
  EXPECT_FALSE(RotationFromQuaternion(std::nan(""), 0, 0, 0, &r, &error));
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
  error.clear();
  EXPECT_FALSE(
      RotationFromQuaternion(1, 0, std::numeric_limits<double>::infinity(), 0, &r, &error));
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
}

TEST(QuaternionFromRotation, RoundTripOnRandomAttitudes) {
  std::mt19937_64 rng(kSeed);
  for (int n = 0; n < kRandomSamples; ++n) {
    const Eigen::Vector4d q = RandomUnitQuaternion(&rng);
    Eigen::Matrix3d r;
    std::string error;
    ASSERT_TRUE(RotationFromQuaternion(q[0], q[1], q[2], q[3], &r, &error)) << error;
    const Eigen::Vector4d back = QuaternionFromRotation(r);
    EXPECT_GE(back[0], 0.0);
    ASSERT_LT((back - q).cwiseAbs().maxCoeff(), kMatrixTol) << "sample " << n;
    Eigen::Matrix3d r2;
    ASSERT_TRUE(RotationFromQuaternion(back[0], back[1], back[2], back[3], &r2, &error));
    ASSERT_LT(MaxAbsDiff(r2, r), kMatrixTol) << "sample " << n;
  }
}

TEST(QuaternionFromRotation, NegativeHemisphereIsFlippedToWNonNegative) {
  // 270 deg about z is q = (cos 135, 0, 0, sin 135) = -(cos(-45), 0, 0, sin(-45)).
  const Eigen::Vector4d q = QuaternionFromRotation(Rz(270.0));
  const double h = std::sqrt(0.5);
  EXPECT_LT((q - Eigen::Vector4d(h, 0, 0, -h)).cwiseAbs().maxCoeff(), kMatrixTol) << q;
}

TEST(RotationFromRotationVector, ZeroIsIdentityAndQuarterTurnAboutX) {
  EXPECT_EQ(RotationFromRotationVector(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d r = RotationFromRotationVector(Eigen::Vector3d(M_PI / 2.0, 0.0, 0.0));
  EXPECT_LT(MaxAbsDiff(r, Rx(90.0)), kMatrixTol) << r;
  EXPECT_LT((r * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), kMatrixTol);
}

TEST(RotationFromRotationVector, AgreesWithQuaternionOfSameAxisAngle) {
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> component(-2.0, 2.0);  // |v| up to ~3.5 rad
  for (int n = 0; n < kRandomSamples; ++n) {
    const Eigen::Vector3d v(component(rng), component(rng), component(rng));
    const double angle = v.norm();
    const Eigen::Vector3d axis_sin = std::sin(angle / 2.0) * v / angle;
    Eigen::Matrix3d from_quaternion;
    std::string error;
    ASSERT_TRUE(RotationFromQuaternion(std::cos(angle / 2.0), axis_sin.x(), axis_sin.y(),
                                       axis_sin.z(), &from_quaternion, &error))
        << error;
    const Eigen::Matrix3d r = RotationFromRotationVector(v);
    ExpectProperRotation(r);
    ASSERT_LT(MaxAbsDiff(r, from_quaternion), kMatrixTol) << "sample " << n;
    // The axis is fixed by the rotation.
    ASSERT_LT((r * v - v).norm(), kMatrixTol * 10.0) << "sample " << n;
  }
}

TEST(FocalAttitude, OnAxisIsIdentity) {
  const FocalAttitudeLaw law;
  EXPECT_EQ(FocalAttitude(Eigen::Vector3d(0.0, 0.0, 140.0), law), Eigen::Matrix3d::Identity());
  EXPECT_EQ(FocalAttitude(Eigen::Vector3d(0.0, 0.0, 0.0), law), Eigen::Matrix3d::Identity());
}

TEST(FocalAttitude, TiltsZTowardAxisByFractionOfOffAxisAngle) {
  constexpr double kSphereRadiusM = 160.0, kOffAxisDeg = 40.0, kTiltFraction = 0.41;
  const FocalAttitudeLaw law;  // defaults: f = 0.41, C = (0, 0, 300) m
  ASSERT_EQ(law.tilt_fraction, kTiltFraction);
  const Eigen::Vector3d centre(0.0, 0.0, 300.0);
  ASSERT_EQ(law.focal_centre_m, centre);
  for (const double azimuth_deg : {0.0, 75.0, 200.0, -120.0}) {
    const double a = azimuth_deg * kDeg, t = kOffAxisDeg * kDeg;
    // On the sphere below C, 40 deg off the vertical axis through C.
    const Eigen::Vector3d position =
        centre + kSphereRadiusM * Eigen::Vector3d(std::sin(t) * std::cos(a),
                                                  std::sin(t) * std::sin(a), -std::cos(t));
    const Eigen::Matrix3d r = FocalAttitude(position, law);
    ExpectProperRotation(r);
    const Eigen::Vector3d z_rotated = r * Eigen::Vector3d::UnitZ();
    // Tilt of z' from z.
    EXPECT_NEAR(std::acos(std::clamp(z_rotated.z(), -1.0, 1.0)) / kDeg, kTiltFraction * kOffAxisDeg,
                kFocalAngleTolDeg)
        << "azimuth " << azimuth_deg;
    // z' lies in the vertical plane through the point and the axis (normal: z x radial).
    const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0.0);
    const Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ().cross(radial);
    EXPECT_NEAR(z_rotated.dot(plane_normal), 0.0, kFocalPlaneTol) << "azimuth " << azimuth_deg;
    // Its horizontal part points from the point toward the axis.
    EXPECT_LT(z_rotated.dot(radial), 0.0) << "azimuth " << azimuth_deg;
    EXPECT_NEAR(z_rotated.dot(radial), -std::sin(kTiltFraction * t), kFocalPlaneTol);
  }
}

TEST(FocalAttitude, ZeroTiltFractionIsIdentity) {
  FocalAttitudeLaw law;
  law.tilt_fraction = 0.0;
  const Eigen::Matrix3d r = FocalAttitude(Eigen::Vector3d(60.0, -80.0, 160.0), law);
  EXPECT_LT(MaxAbsDiff(r, Eigen::Matrix3d::Identity()), kMatrixTol) << r;
}

TEST(IsFinite, DetectsNonFiniteEntries) {
  Pose pose;
  EXPECT_TRUE(IsFinite(pose));
  pose.position_m = Eigen::Vector3d(1.0, 2.0, 150.0);
  EXPECT_TRUE(IsFinite(pose));
  pose.position_m.y() = std::nan("");
  EXPECT_FALSE(IsFinite(pose));
  pose.position_m.y() = 2.0;
  pose.rotation(2, 1) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(IsFinite(pose));
}

}  // namespace
}  // namespace fastcal
