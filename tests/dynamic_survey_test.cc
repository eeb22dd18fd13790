// Tests of the survey flown in time (dynamic_survey.h) through the simulation's actual
// source (simulation.h): the samples' times follow the moves and waits; after a long
// wait the noise-free tensions and poses are the statics' at the planned poses (within
// the chains' offset from the catenary and what still vibrates); a repeated pose is
// sampled at the interval; options the source excludes are refused.
#include "fastcal/dynamic_survey.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fastcal/simulation.h"
#include "fastcal/statics.h"

namespace fastcal {
namespace {

std::vector<Pose> Stops() {
  std::vector<Pose> poses(4);
  poses[0].position_m = Eigen::Vector3d(0.0, 0.0, 140.0);
  poses[1].position_m = Eigen::Vector3d(4.0, 0.0, 140.0);
  poses[2] = poses[1];
  poses[3].position_m = Eigen::Vector3d(4.0, 3.0, 141.0);
  return poses;
}

SimulationOptions NoiseFree() {
  SimulationOptions o;
  o.tension_noise_percent = 0.0;
  return o;
}

// Moves of 4 m and 3.2 m lasting 40 s (the shortest move: a move of ~10 s, near the lowest
// modes' periods, leaves 0.7% ringing after a minute), 60 s waits, 2 s between the samples
// at one stop: the times; the noise-free readings within kTension of the statics' (the
// chains' offset at 16 segments, 2e-5, and what the move leaves) and the cabin within
// kPositionM of the planned pose.
TEST(SurveyFlight, SamplesFollowTheFlight) {
  constexpr double kTension = 5e-4;    // measured: 1.4e-4 at most
  constexpr double kPositionM = 0.01;  // measured: 5.2 mm, the chains' own offset
  const std::vector<Pose> poses = Stops();
  SurveyFlightOptions flight;
  flight.dynamics.segments = 16;
  flight.min_move_s = 40.0;
  flight.wait_s = 60.0;
  flight.sample_interval_s = 2.0;
  SimulationOptions options = NoiseFree();
  double duration_s = 0.0;
  std::string error;
  ASSERT_TRUE(MakeSurveyFlight(poses, flight, &options.actual_source, &duration_s, &error))
      << error;
  EXPECT_DOUBLE_EQ(duration_s, 40.0 + 60.0 + 2.0 + 40.0 + 60.0);
  Dataset data;
  const CableRobot robot = CableRobot::NominalFast();
  ASSERT_TRUE(Simulate(robot, poses, options, &data, nullptr, nullptr, &error)) << error;
  ASSERT_EQ(data.samples.size(), 4u);
  EXPECT_DOUBLE_EQ(data.samples[1].time_s, 100.0);
  EXPECT_DOUBLE_EQ(data.samples[2].time_s, 102.0);
  EXPECT_DOUBLE_EQ(data.samples[3].time_s, duration_s);
  for (size_t n = 0; n < poses.size(); ++n) {
    StaticsSolution statics;
    ASSERT_EQ(SolveStatics(robot, poses[n], StaticsOptions(), &statics), StaticsStatus::kOk);
    const Sample& s = data.samples[n];
    EXPECT_LT((s.pose.position_m - poses[n].position_m).norm(), kPositionM) << n;
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(s.tension_n[i] / statics.cables[i].lower_tension_n, 1.0, kTension) << n;
      EXPECT_NEAR(s.unstretched_length_m[i], statics.cables[i].unstretched_length_m, 1e-6) << n;
    }
  }
  // Readings differ from the static simulation's only by the dynamics: not bit for bit.
  Dataset statics_data;
  ASSERT_TRUE(Simulate(robot, poses, NoiseFree(), &statics_data, nullptr, nullptr, &error));
  EXPECT_NE(statics_data.samples[1].tension_n[0], data.samples[1].tension_n[0]);
}

TEST(SurveyFlight, Refusals) {
  const std::vector<Pose> poses = Stops();
  SurveyFlightOptions flight;
  flight.dynamics.segments = 12;
  SimulationOptions options = NoiseFree();
  double duration_s = 0.0;
  std::string error;
  ASSERT_TRUE(MakeSurveyFlight(poses, flight, &options.actual_source, &duration_s, &error));
  options.mass_centre_drift_m = 0.01;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("actual_source"), std::string::npos) << error;
  flight.speed_m_per_s = 0.0;
  EXPECT_FALSE(MakeSurveyFlight(poses, flight, &options.actual_source, &duration_s, &error));
  EXPECT_NE(error.find("speed_m_per_s"), std::string::npos) << error;
  flight = SurveyFlightOptions();
  EXPECT_FALSE(MakeSurveyFlight({}, flight, &options.actual_source, &duration_s, &error));
  // A source planned for other poses says so.
  options = NoiseFree();
  ASSERT_TRUE(MakeSurveyFlight(poses, flight, &options.actual_source, &duration_s, &error));
  std::vector<Pose> other = poses;
  other[1].position_m.x() += 1.0;
  Dataset data;
  EXPECT_FALSE(
      Simulate(CableRobot::NominalFast(), other, options, &data, nullptr, nullptr, &error));
  EXPECT_NE(error.find("planned for other poses"), std::string::npos) << error;
}

}  // namespace
}  // namespace fastcal
