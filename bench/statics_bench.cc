// Time per pose of the three statics methods (statics.h), cold and warm-started, at K2
// and along the paper's 101-node line and half circle (focal attitude law); cold over a
// sweep of the workspace's edge like issue 9's, where cables sag and exact follows the
// equilibrium from the home pose where its start fails; and the C++ side of the Python
// comparison (bench/python_statics_bench.py): 10000 poses spread over the workspace,
// solved one after the other, as a C++ program would.
// Run: build/bench/statics_bench --benchmark_min_time=0.2
// items_per_second is poses per second; time per pose = 1 / items_per_second.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "fastcal/statics.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

constexpr int kPaperNodes = 101;

std::vector<Pose> PaperTrajectory(bool circle) {
  std::vector<Pose> poses;
  for (int n = 0; n < kPaperNodes; ++n) {
    Pose p;
    if (circle) {
      const double t = M_PI * n / (kPaperNodes - 1);
      p.position_m = Eigen::Vector3d(50 * std::cos(t), 50 * std::sin(t), 150);
    } else {
      p.position_m = Eigen::Vector3d(50.0 - 100.0 * n / (kPaperNodes - 1), 0, 150);
    }
    p.rotation = FocalAttitude(p.position_m, FocalAttitudeLaw());
    poses.push_back(p);
  }
  return poses;
}

StaticsMethod MethodOf(int64_t index) { return static_cast<StaticsMethod>(index); }

Pose K2Pose() {
  Pose pose;
  pose.position_m = Eigen::Vector3d(42.65, 33.73, 149.52);
  pose.rotation = FocalAttitude(pose.position_m, FocalAttitudeLaw());
  return pose;
}

void BM_SinglePoseCold(benchmark::State& state) {
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = K2Pose();
  StaticsOptions options;
  options.method = MethodOf(state.range(0));
  StaticsSolution solution;
  for (auto _ : state) {
    SolveStatics(robot, pose, options, &solution);
    benchmark::DoNotOptimize(solution);
  }
  state.SetLabel(StaticsMethodName(options.method));
  state.SetItemsProcessed(state.iterations());
}

// AAS with compute_unstretched_lengths = false (forces only, as in a fit): no s0 solves;
// its check uses the model-corrected guesses of the curve points instead.
void BM_SinglePoseColdAasForcesOnly(benchmark::State& state) {
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = K2Pose();
  StaticsOptions options;
  options.method = StaticsMethod::kAas;
  options.compute_unstretched_lengths = false;
  StaticsSolution solution;
  for (auto _ : state) {
    SolveStatics(robot, pose, options, &solution);
    benchmark::DoNotOptimize(solution);
  }
  state.SetLabel("aas, forces only");
  state.SetItemsProcessed(state.iterations());
}

// range(0): method, range(1): 0 line / 1 half circle, range(2): warm start.
void BM_PaperTrajectory(benchmark::State& state) {
  const CableRobot robot = CableRobot::NominalFast();
  const std::vector<Pose> poses = PaperTrajectory(state.range(1) == 1);
  StaticsOptions options;
  options.method = MethodOf(state.range(0));
  options.warm_start = state.range(2) == 1;
  StaticsSolution solution;
  for (auto _ : state) {
    for (const Pose& p : poses) {
      SolveStatics(robot, p, options, &solution);
      benchmark::DoNotOptimize(solution);
    }
  }
  state.SetLabel(std::string(StaticsMethodName(options.method)) +
                 (state.range(1) ? " circle" : " line") + (options.warm_start ? " warm" : " cold"));
  state.SetItemsProcessed(state.iterations() * poses.size());
}

// Solves every pose cold with range(0)'s method, one after the other. The poses are
// built before timing: a C++ caller has them.
void SolveEachCold(benchmark::State& state, const std::vector<Pose>& poses, const char* what) {
  const CableRobot robot = CableRobot::NominalFast();
  StaticsOptions options;
  options.method = MethodOf(state.range(0));
  StaticsSolution solution;
  for (auto _ : state) {
    for (const Pose& p : poses) {
      SolveStatics(robot, p, options, &solution);
      benchmark::DoNotOptimize(solution);
    }
  }
  state.SetLabel(std::string(StaticsMethodName(options.method)) + " " + what);
  state.SetItemsProcessed(state.iterations() * poses.size());
}

// The workspace the Python bench solves: kWorkspacePoses positions of
// RandomWorkspacePositions (seed 1, defaults otherwise) with the focal attitude law.
constexpr int kWorkspacePoses = 10000;

void BM_WorkspaceArray(benchmark::State& state) {
  RandomWorkspaceSpec spec;
  spec.samples = kWorkspacePoses;
  spec.seed = 1;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  if (!RandomWorkspacePositions(spec, &positions, nullptr) ||
      !PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, nullptr)) {
    state.SkipWithError("workspace poses");
    return;
  }
  SolveEachCold(state, poses, "workspace cold");
}

// 2000 poses off the cap's edge: up to 45 deg off axis, +-5 m off the focal sphere, the
// focal law times an extra rotation of 2 to 5 deg per axis (about 10% of them cannot be
// held, or only beyond the model's range).
void BM_EdgeSweepCold(benchmark::State& state) {
  constexpr int kPoses = 2000;
  std::vector<Pose> poses;
  std::string error;
  if (!RandomPosesAroundFocalLaw(EdgeSweepSpec(kPoses, 20260101), &poses, &error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  SolveEachCold(state, poses, "edge sweep");
}

// Cables as built (issue 18): exact with two attachments per cable (a point mass 2-6 m up
// and hung lines over the lowest 120-200 m), against the same solve with uniform cables
// (argument 0: uniform, 1: two attachments per cable); cold at K2, and warm along the
// paper's half circle.
CableRobot AsBuiltRobot(bool attachments) {
  CableRobot robot = CableRobot::NominalFast();
  if (!attachments) return robot;
  for (int i = 0; i < kNumCables; ++i) {
    robot.cables[i].attachments = {
        CableAttachment::PointMass(2.0 + 0.8 * i, 250.0 + 80.0 * i),
        CableAttachment::AddedDensity(0.0, 120.0 + 16.0 * i, 0.6 + 0.2 * i)};
  }
  return robot;
}

void BM_AttachmentsExactCold(benchmark::State& state) {
  const CableRobot robot = AsBuiltRobot(state.range(0) != 0);
  const Pose pose = K2Pose();
  StaticsOptions options;
  StaticsSolution solution;
  for (auto _ : state) {
    SolveStatics(robot, pose, options, &solution);
    benchmark::DoNotOptimize(solution);
  }
  state.SetLabel(state.range(0) != 0 ? "two attachments per cable" : "uniform cables");
  state.SetItemsProcessed(state.iterations());
}

void BM_AttachmentsExactWarmCircle(benchmark::State& state) {
  const CableRobot robot = AsBuiltRobot(state.range(0) != 0);
  const std::vector<Pose> poses = PaperTrajectory(/*circle=*/true);
  StaticsOptions options;
  options.warm_start = true;
  StaticsSolution solution;
  for (auto _ : state) {
    solution.status = StaticsStatus::kInvalidInput;  // each pass starts cold
    for (const Pose& pose : poses) SolveStatics(robot, pose, options, &solution);
    benchmark::DoNotOptimize(solution);
  }
  state.SetLabel(state.range(0) != 0 ? "two attachments per cable" : "uniform cables");
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(poses.size()));
}

BENCHMARK(BM_SinglePoseCold)->DenseRange(0, 2);
BENCHMARK(BM_AttachmentsExactCold)->DenseRange(0, 1);
BENCHMARK(BM_AttachmentsExactWarmCircle)->DenseRange(0, 1);
BENCHMARK(BM_WorkspaceArray)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SinglePoseColdAasForcesOnly);
BENCHMARK(BM_PaperTrajectory)->ArgsProduct({{0, 1, 2}, {0, 1}, {0, 1}});
BENCHMARK(BM_EdgeSweepCold)->DenseRange(0, 2);

}  // namespace
}  // namespace fastcal

BENCHMARK_MAIN();
