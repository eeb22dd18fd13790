// Tests of the runs in time (dynamics_run.h): the minimum-jerk profile; the lengths
// file's reader and its messages; a move's record, its quasi-static reference, its
// departures and settle time against the samples; a held table staying quasi-static; a
// free decay; refusals.
#include "fastcal/dynamics_run.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "fastcal/statics.h"

namespace fastcal {
namespace {

TEST(MinimumJerk, Profile) {
  EXPECT_EQ(MinimumJerk(-1.0), 0.0);
  EXPECT_EQ(MinimumJerk(0.0), 0.0);
  EXPECT_NEAR(MinimumJerk(0.5), 0.5, 1e-15);
  EXPECT_EQ(MinimumJerk(1.0), 1.0);
  EXPECT_EQ(MinimumJerk(2.0), 1.0);
  // Zero velocity and acceleration at both ends (central differences).
  constexpr double h = 1e-4;
  EXPECT_NEAR((MinimumJerk(h) - MinimumJerk(0.0)) / h, 0.0, 1e-7);
  EXPECT_NEAR((MinimumJerk(1.0) - MinimumJerk(1.0 - h)) / h, 0.0, 1e-7);
  EXPECT_NEAR((MinimumJerk(0.5 + h) - MinimumJerk(0.5 - h)) / (2 * h), 1.875, 1e-6);  // peak
}

TEST(WinchTable, ReadsAndRefusesWithLineAndColumn) {
  WinchTable table;
  std::string error;
  const std::string header = "# a plan\ntime_s,s0_1_m,s0_2_m,s0_3_m,s0_4_m,s0_5_m,s0_6_m,note\n";
  ASSERT_TRUE(
      ParseWinchTable(header + "0,300,301,302,303,304,305,a\n\n2.5,300.1,301,302,303,304,305,b\n",
                      "plan.csv", &table, &error))
      << error;
  ASSERT_EQ(table.time_s.size(), 2u);
  EXPECT_EQ(table.time_s[1], 2.5);
  EXPECT_EQ(table.s0_m[1][0], 300.1);
  EXPECT_EQ(table.s0_m[0][5], 305.0);
  struct Case {
    std::string text, expected;
  };
  for (const Case& c : {
           Case{"time_s,s0_1_m\n0,1\n", "plan.csv:1: no column 's0_2_m'"},
           Case{header + "0,300,x,302,303,304,305,a\n", "plan.csv:3: column 's0_2_m': "},
           Case{header + "0,300,301,302,303,304,nan,a\n", "plan.csv:3: column 's0_6_m': "},
           Case{header + "0,300,301,302,303,304,0,a\n", "plan.csv:3: column 's0_6_m': a length"},
           Case{header + "1,300,301,302,303,304,305,a\n", "plan.csv:3: column 'time_s': the first"},
           Case{header + "0,300,301,302,303,304,305,a\n0,300,301,302,303,304,305,a\n",
                "plan.csv:4: column 'time_s': times must increase"},
           Case{header + "0,300,301,302,303,304,305\n", "plan.csv:3: 7 fields, the header has 8"},
           Case{header, "plan.csv: no data rows"},
           Case{"", "plan.csv: no header line"},
       }) {
    EXPECT_FALSE(ParseWinchTable(c.text, "plan.csv", &table, &error)) << c.text;
    EXPECT_EQ(error.rfind(c.expected, 0), 0u) << error;
  }
}

DynamicsOptions Quick() {
  DynamicsOptions o;
  o.segments = 16;
  return o;
}

// A 10 m move in 30 s at the zenith, held 60 s: the record's times, the winches at the
// end pose's exact lengths, the cabin at the chains' equilibrium there within what
// still vibrates (kEndM), that equilibrium at the end pose within the chains' offset
// (kOffsetM), the summary's figures recomputed from the samples.
TEST(RunDynamics, MoveRecordAndSummary) {
  constexpr double kEndM = 1e-2;     // what vibrates 60 s after: 6.8 mm
  constexpr double kOffsetM = 8e-3;  // the 16-segment chains' offset: 5.2 mm
  DynamicsRunSpec spec;
  spec.start.position_m = Eigen::Vector3d(0.0, 0.0, 140.0);
  spec.end.position_m = Eigen::Vector3d(10.0, 0.0, 140.0);
  spec.move_s = 30.0;
  spec.hold_s = 60.0;
  spec.rate_hz = 5.0;
  DynamicsRunResult r;
  std::string error;
  const CableRobot robot = CableRobot::NominalFast();
  ASSERT_TRUE(RunDynamics(robot, spec, Quick(), &r, &error)) << error;
  ASSERT_EQ(r.samples.size(), 451u);
  EXPECT_DOUBLE_EQ(r.samples.back().time_s, 90.0);
  StaticsSolution end;
  ASSERT_EQ(SolveStatics(robot, spec.end, StaticsOptions(), &end), StaticsStatus::kOk);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(r.samples.back().s0_m[i], end.cables[i].unstretched_length_m, 1e-9);
  }
  const DynamicsSample& last = r.samples.back();
  EXPECT_LT((last.pose.position_m - last.quasi_static_pose.position_m).norm(), kEndM);
  EXPECT_LT((last.quasi_static_pose.position_m - spec.end.position_m).norm(), kOffsetM);
  // At the start, dynamic and quasi-static are one state.
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(r.samples[0].tension_n[i], r.samples[0].quasi_static_tension_n[i], 1e-3);
  }
  double peak_kn = 0.0;
  for (const DynamicsSample& s : r.samples) {
    for (int i = 0; i < kNumCables; ++i) {
      peak_kn = std::max(peak_kn, std::abs(s.tension_n[i] - s.quasi_static_tension_n[i]) / 1e3);
    }
  }
  EXPECT_DOUBLE_EQ(r.departure.max_peak_kn, peak_kn);
  EXPECT_GT(r.departure.max_peak_kn, 0.1);  // the move's accelerations: ~0.6 kN
  EXPECT_LT(r.residual.max_peak_kn, r.departure.max_peak_kn);
  EXPECT_GT(r.departure.peak_position_mm, 1.0);  // the cabin lags the statics' pose
  // The settle time: after it, every sample within the band; before it, one outside.
  ASSERT_TRUE(r.settled);
  for (const DynamicsSample& s : r.samples) {
    if (s.time_s < r.motion_end_s + r.settle_s) continue;
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_LE(std::abs(s.tension_n[i] / s.quasi_static_tension_n[i] - 1.0), spec.settle_fraction);
    }
  }
  const std::string csv = DynamicsCsv(r);
  EXPECT_EQ(csv.rfind("time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,", 0), 0u);
  EXPECT_NE(csv.find(",x_qs_m,y_qs_m,z_qs_m,roll_qs_deg,pitch_qs_deg,yaw_qs_deg,T1_qs_kN,"),
            std::string::npos);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 452);
  const std::string json = DynamicsSummaryJson(r);
  for (const char* key : {"\"departure\"", "\"residual\"", "\"settle_s\"", "\"peak_kN\"",
                          "\"offset_from_exact_statics_mm\"", "\"frequency_hz\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key;
  }
}

// Winches held at the start's lengths by a table: nothing moves, dynamic is
// quasi-static to rounding.
// The quasi-static reference does not depend on the sampling: a move of 40 m in 16 s
// sampled once a second (the winches' lengths change by metres between samples) gives the
// same reference as at 4 Hz at the common times. It failed before the reference went in
// pieces from the last sample's ("the chains' stiffness is singular"), found by design's
// waits after its moves (issue 55).
TEST(RunDynamics, QuasiStaticReferenceDoesNotDependOnTheSampling) {
  constexpr double kSameN = 1e-3;  // Newton's tolerance on the chains, in N
  DynamicsRunSpec spec;
  spec.start.position_m = Eigen::Vector3d(0.0, 0.0, 140.0);
  spec.end.position_m = Eigen::Vector3d(40.0, 0.0, 145.0);
  spec.move_s = 16.0;
  spec.hold_s = 2.0;
  DynamicsOptions options = Quick();
  options.segments = 8;
  const CableRobot robot = CableRobot::NominalFast();
  DynamicsRunResult coarse, fine;
  std::string error;
  spec.rate_hz = 1.0;
  ASSERT_TRUE(RunDynamics(robot, spec, options, &coarse, &error)) << error;
  spec.rate_hz = 4.0;
  ASSERT_TRUE(RunDynamics(robot, spec, options, &fine, &error)) << error;
  ASSERT_EQ(fine.samples.size(), 4 * (coarse.samples.size() - 1) + 1);
  for (size_t k = 0; k < coarse.samples.size(); ++k) {
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(coarse.samples[k].quasi_static_tension_n[i],
                  fine.samples[4 * k].quasi_static_tension_n[i], kSameN)
          << "t = " << coarse.samples[k].time_s << " s, cable " << i + 1;
    }
  }
}

TEST(RunDynamics, HeldTableStaysQuasiStatic) {
  DynamicsRunSpec spec;
  spec.kind = DynamicsRunSpec::Kind::kLengths;
  spec.start.position_m = Eigen::Vector3d(20.0, -10.0, 142.0);
  StaticsSolution start;
  ASSERT_EQ(SolveStatics(CableRobot::NominalFast(), spec.start, StaticsOptions(), &start),
            StaticsStatus::kOk);
  std::array<double, kNumCables> s0{};
  for (int i = 0; i < kNumCables; ++i) s0[i] = start.cables[i].unstretched_length_m;
  spec.lengths.time_s = {0.0, 10.0};
  spec.lengths.s0_m = {s0, s0};
  spec.hold_s = 20.0;
  DynamicsRunResult r;
  std::string error;
  ASSERT_TRUE(RunDynamics(CableRobot::NominalFast(), spec, Quick(), &r, &error)) << error;
  EXPECT_LT(r.departure.max_peak_kn, 1e-6);
  EXPECT_LT(r.departure.peak_position_mm, 1e-6);
  EXPECT_TRUE(r.settled);
  EXPECT_EQ(r.settle_s, 0.0);
}

// A free decay from 0.1 m: it has not settled to 0.1% in 30 s (the lowest mode's time
// constant is 4 minutes), it has to 5%.
TEST(RunDynamics, FreeDecaySettles) {
  DynamicsRunSpec spec;
  spec.kind = DynamicsRunSpec::Kind::kFreeDecay;
  spec.start.position_m = Eigen::Vector3d(0.0, 0.0, 140.0);
  spec.offset_m = Eigen::Vector3d(0.1, 0.0, 0.0);
  spec.hold_s = 30.0;
  spec.settle_fraction = 0.001;
  DynamicsRunResult r;
  std::string error;
  ASSERT_TRUE(RunDynamics(CableRobot::NominalFast(), spec, Quick(), &r, &error)) << error;
  EXPECT_FALSE(r.settled);
  EXPECT_TRUE(std::isnan(r.settle_s));
  EXPECT_NEAR(r.samples[0].pose.position_m.x() - r.samples[0].quasi_static_pose.position_m.x(), 0.1,
              1e-9);
  spec.settle_fraction = 0.05;
  ASSERT_TRUE(RunDynamics(CableRobot::NominalFast(), spec, Quick(), &r, &error)) << error;
  EXPECT_TRUE(r.settled);
}

TEST(RunDynamics, Refusals) {
  DynamicsRunSpec spec;
  spec.start.position_m = Eigen::Vector3d(0.0, 0.0, 140.0);
  spec.end.position_m = Eigen::Vector3d(0.0, 0.0, 290.0);
  spec.hold_s = 1.0;
  DynamicsRunResult r;
  std::string error;
  EXPECT_FALSE(RunDynamics(CableRobot::NominalFast(), spec, Quick(), &r, &error));
  EXPECT_NE(error.find("end pose"), std::string::npos) << error;
  spec.end.position_m = Eigen::Vector3d(1.0, 0.0, 140.0);
  spec.move_s = -1.0;
  EXPECT_FALSE(RunDynamics(CableRobot::NominalFast(), spec, Quick(), &r, &error));
  EXPECT_NE(error.find("move_s"), std::string::npos) << error;
  spec.move_s = 10.0;
  spec.rate_hz = std::nan("");
  EXPECT_FALSE(spec.IsValid(&error));
  EXPECT_NE(error.find("rate_hz"), std::string::npos) << error;
}

}  // namespace
}  // namespace fastcal
