// Random poses over the focal-sphere cap with the focal attitude law, seeded: the planned
// poses of the simulated surveys the calibration, sessions and track tests fit.
#ifndef FASTCAL_TESTS_RANDOM_CAP_POSES_H_
#define FASTCAL_TESTS_RANDOM_CAP_POSES_H_

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "fastcal/pose.h"
#include "fastcal/trajectory.h"

namespace fastcal {

inline std::vector<Pose> RandomCapPoses(int samples, std::uint64_t seed) {
  RandomWorkspaceSpec spec;
  spec.samples = samples;
  spec.seed = seed;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  std::string error;
  EXPECT_TRUE(RandomWorkspacePositions(spec, &positions, &error)) << error;
  EXPECT_TRUE(PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, &error)) << error;
  return poses;
}

}  // namespace fastcal

#endif  // FASTCAL_TESTS_RANDOM_CAP_POSES_H_
