// Robots and poses several tests share.
#ifndef FASTCAL_TESTS_TEST_ROBOTS_H_
#define FASTCAL_TESTS_TEST_ROBOTS_H_

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/pose.h"
#include "fastcal/trajectory.h"

namespace fastcal::testing {

// Issue 18's telemetry: each cable a 250-650 kg assembly 2-6 m above the cabin and
// 0.6-1.6 kg/m of hung lines over the lowest 120-200 m.
inline CableRobot AsBuiltRobot() {
  CableRobot robot = CableRobot::NominalFast();
  for (int i = 0; i < kNumCables; ++i) {
    robot.cables[i].attachments = {
        CableAttachment::PointMass(2.0 + 0.8 * i, 250.0 + 80.0 * i),
        CableAttachment::AddedDensity(0.0, 120.0 + 16.0 * i, 0.6 + 0.2 * i)};
  }
  return robot;
}

// Issue 35's cabin: an A-B rotator (first moment `rotator_q` about its axes, joints at
// zero: e.g. 10 t centred 0.6 m below them is (0, 0, -6000) kg m) carrying a Stewart
// platform of `platform_kg` that translates along x, y, z (columns rotator_a_deg,
// rotator_b_deg, stewart_x_m, stewart_y_m, stewart_z_m).
inline CableRobot RotatorRobot(const Eigen::Vector3d& rotator_q = Eigen::Vector3d(0, 0, -6000),
                               double platform_kg = 2500.0) {
  CableRobot robot = CableRobot::NominalFast();
  MovingPart rotator;
  rotator.name = "rotator";
  Joint a, b;
  a.axis = Eigen::Vector3d::UnitX();
  a.column = "rotator_a_deg";
  b.axis = Eigen::Vector3d::UnitY();
  b.column = "rotator_b_deg";
  a.has_range = b.has_range = true;
  a.range_low = b.range_low = -40.0;
  a.range_high = b.range_high = 40.0;
  rotator.joints = {a, b};
  rotator.first_moment_kg_m = rotator_q;
  MovingPart stewart;
  stewart.name = "stewart";
  stewart.parent = 0;
  const char* columns[] = {"stewart_x_m", "stewart_y_m", "stewart_z_m"};
  for (int c = 0; c < 3; ++c) {
    Joint j;
    j.type = JointType::kPrismatic;
    j.axis = Eigen::Vector3d::Unit(c);
    j.column = columns[c];
    stewart.joints.push_back(j);
  }
  stewart.mass_kg = platform_kg;
  robot.moving_parts.parts = {rotator, stewart};
  return robot;
}

// Joint values of RotatorRobot: the rotator's angles (deg) and the platform's shift (m).
inline JointValues RotatorJoints(double a_deg, double b_deg, double x_m = 0.0, double y_m = 0.0,
                                 double z_m = 0.0) {
  JointValues q{};
  q[0] = a_deg;
  q[1] = b_deg;
  q[2] = x_m;
  q[3] = y_m;
  q[4] = z_m;
  return q;
}

// `count` random poses up to 35 deg off axis (with the focal law's 2-5 deg extra tilts,
// inside the model's range), `spread_m` off the focal sphere.
inline std::vector<Pose> TiltedPoses(int count, std::uint64_t seed, double spread_m = 0.0) {
  RandomPoseSpec spec;
  spec.positions.samples = count;
  spec.positions.seed = seed;
  spec.positions.max_off_axis_deg = 35.0;
  spec.positions.radial_spread_m = spread_m;
  std::vector<Pose> poses;
  std::string error;
  EXPECT_TRUE(RandomPosesAroundFocalLaw(spec, &poses, &error)) << error;
  return poses;
}

// The focal law's pose `zenith_deg` off axis at azimuth `azimuth_deg` on the focal sphere
// (radius 160 m about (0, 0, 300) m, docs/model.md).
inline Pose FocalSpherePose(double zenith_deg, double azimuth_deg) {
  const double z = zenith_deg * M_PI / 180.0, a = azimuth_deg * M_PI / 180.0;
  Pose pose;
  pose.position_m =
      Eigen::Vector3d(0.0, 0.0, 300.0) +
      160.0 * Eigen::Vector3d(std::sin(z) * std::cos(a), std::sin(z) * std::sin(a), -std::cos(z));
  pose.rotation = FocalAttitude(pose.position_m, FocalAttitudeLaw());
  return pose;
}

}  // namespace fastcal::testing

#endif  // FASTCAL_TESTS_TEST_ROBOTS_H_
