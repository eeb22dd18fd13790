// Tests of the closed loop (closed_loop.h): with the truth as the controller's model the
// cabin stays at the command within the chains' own discretisation offset, and the PID
// removes that; a controller's model with its mass centre 5 cm off leaves the cabin where
// the truth hangs at the controller's lengths (the forward statics' answer); bad options.
#include "fastcal/closed_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fastcal/locate.h"
#include "test_robots.h"

namespace fastcal {
namespace {

using testing::FocalSpherePose;

// 20 segments a cable: the chains' equilibrium lies a few mm from the exact statics'
// pose (O(1/N^2), DynamicsStart), which these tests measure and allow for.
DynamicsOptions Plant() {
  DynamicsOptions o;
  o.segments = 20;
  return o;
}

LoopSpec Hold(double hold_s) {
  LoopSpec spec;
  spec.start = FocalSpherePose(20.0, 30.0);
  spec.hold_s = hold_s;
  return spec;
}

// The error's RMS over the record's last `window_s` (what is left once the PID has
// taken a static error away: the vibration its corrections excite, 0.004 damped).
double TailRms(const LoopResult& r, double window_s) {
  double sum = 0.0;
  int n = 0;
  for (const LoopSample& s : r.samples) {
    if (s.time_s < r.samples.back().time_s - window_s) continue;
    sum += s.error_m * s.error_m;
    ++n;
  }
  return n > 0 ? std::sqrt(sum / n) : 0.0;
}

LoopResult Loop(const CableRobot& controller, const LoopSpec& spec, const LoopOptions& o) {
  LoopResult r;
  std::string error;
  EXPECT_TRUE(RunLoop(CableRobot::NominalFast(), controller, spec, o, Plant(), &r, &error))
      << error;
  return r;
}

// The plant at rest where its chains hang; the offset from the command is the chains'
// own (a few mm at 20 segments), and the PID takes it away.
TEST(ClosedLoop, TheTruthAsTheControllersModelHoldsThePose) {
  const CableRobot truth = CableRobot::NominalFast();
  LoopOptions feed_forward;
  feed_forward.kp = feed_forward.ki_per_s = 0.0;
  const LoopResult alone = Loop(truth, Hold(20.0), feed_forward);
  ASSERT_FALSE(alone.samples.empty());
  // The chains' offset, as DynamicsStart states it, is the whole error.
  constexpr double kChainOffsetAgreementM = 1e-4;
  EXPECT_NEAR(alone.summary.error_rms_m, alone.start.position_offset_m, kChainOffsetAgreementM);
  EXPECT_LT(alone.summary.error_peak_m, 0.01);
  const LoopResult pid = Loop(truth, Hold(180.0), LoopOptions());
  // After two minutes of the default PID (its integral's time constant ~25 s) the offset
  // (~4 mm) is gone; what remains is the vibration its corrections excite, ~0.2 mm.
  constexpr double kSettledRmsM = 5e-4;
  EXPECT_LT(TailRms(pid, 60.0), kSettledRmsM) << TailRms(pid, 60.0);
  EXPECT_LT(TailRms(pid, 60.0), 0.25 * alone.summary.error_rms_m);
  EXPECT_EQ(pid.summary.limit_cycles, 0);
}

// A controller's model with the mass centre 5 cm off in x: the feed-forward alone leaves
// the cabin where the truth hangs at the controller's lengths (Locate), to within the
// chains' offset; the PID brings it back.
TEST(ClosedLoop, AMassCentreOffGivesTheErrorTheStaticsPredict) {
  const CableRobot truth = CableRobot::NominalFast();
  CableRobot controller = truth;
  controller.mass_centre_cabin_m.x() += 0.05;
  LoopOptions feed_forward;
  feed_forward.kp = feed_forward.ki_per_s = 0.0;
  const LoopSpec spec = Hold(20.0);
  const LoopResult off = Loop(controller, spec, feed_forward);
  const LoopResult right = Loop(truth, spec, feed_forward);
  ASSERT_FALSE(off.samples.empty());
  ASSERT_FALSE(right.samples.empty());
  // The statics' answer: the controller's lengths at the command, the truth's pose there.
  StaticsSolution planned;
  ASSERT_EQ(SolveStatics(controller, spec.start, StaticsOptions(), &planned), StaticsStatus::kOk);
  std::array<double, kNumCables> s0{};
  for (int i = 0; i < kNumCables; ++i) s0[i] = planned.cables[i].unstretched_length_m;
  LocateSolution located;
  ASSERT_EQ(Locate(truth, s0, LocateOptions(), &located), StaticsStatus::kOk);
  const Eigen::Vector3d predicted = located.pose.position_m - spec.start.position_m;
  // The loop's, less the chains' own offset at the truth's lengths.
  const Eigen::Vector3d chains =
      right.samples.back().pose.position_m - right.samples.back().command.position_m;
  const Eigen::Vector3d loop =
      off.samples.back().pose.position_m - off.samples.back().command.position_m - chains;
  // The two chains' offsets differ by the change of a few-mm offset over a few cm.
  constexpr double kAgreementM = 2e-4;
  EXPECT_GT(predicted.norm(), 0.01) << predicted.transpose();  // the error is not small
  EXPECT_LT((loop - predicted).norm(), kAgreementM)
      << "loop " << loop.transpose() << ", statics " << predicted.transpose();
  // With the PID, two minutes later it is down to the vibration its corrections excite.
  const LoopResult pid = Loop(controller, Hold(180.0), LoopOptions());
  constexpr double kSettledRmsM = 1e-3;
  EXPECT_LT(TailRms(pid, 60.0), kSettledRmsM) << TailRms(pid, 60.0);
}

TEST(ClosedLoop, FeedEfficiencyLossIsGansFigure) {
  // 10 mm RMS at 3 GHz: 8.2% (the factor's calibration point).
  EXPECT_NEAR(FeedEfficiencyLoss(0.010, 3e9), 0.082, 1e-3);
  EXPECT_EQ(FeedEfficiencyLoss(0.0, 3e9), 0.0);
  EXPECT_LT(FeedEfficiencyLoss(0.010, 1e9), FeedEfficiencyLoss(0.010, 3e9));
}

TEST(ClosedLoop, BadOptionsAreRefusedByName) {
  const CableRobot truth = CableRobot::NominalFast();
  LoopResult r;
  std::string error;
  LoopOptions o;
  o.control_period_s = 0.0;
  EXPECT_FALSE(RunLoop(truth, truth, Hold(1.0), o, Plant(), &r, &error));
  EXPECT_NE(error.find("control_period_s"), std::string::npos) << error;
  o = LoopOptions();
  o.kp = -1.0;
  EXPECT_FALSE(RunLoop(truth, truth, Hold(1.0), o, Plant(), &r, &error));
  EXPECT_NE(error.find("kp"), std::string::npos) << error;
  o = LoopOptions();
  o.max_winch_speed_m_per_s = std::nan("");
  EXPECT_FALSE(RunLoop(truth, truth, Hold(1.0), o, Plant(), &r, &error));
  EXPECT_NE(error.find("max_winch_speed"), std::string::npos) << error;
  EXPECT_FALSE(RunLoop(truth, truth, Hold(0.0), LoopOptions(), Plant(), &r, &error));
  EXPECT_NE(error.find("hold_s"), std::string::npos) << error;
}

}  // namespace
}  // namespace fastcal
