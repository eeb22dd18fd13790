// Time of one pose's modes (modes.h): the exact statics, the chains' assembly and the
// eigenproblem for the 20 lowest modes, at the zenith and 40 deg off axis (focal law),
// for several segment counts (range(0)); the default is ModesOptions().segments. And the
// map of the focal-sphere cap (193 poses).
// Run: build/bench/modes_bench --benchmark_min_time=0.5
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "fastcal/modes.h"
#include "fastcal/modes_map.h"

namespace fastcal {
namespace {

Pose FocalPose(double zenith_deg) {
  const double z = zenith_deg * M_PI / 180.0;
  Pose pose;
  pose.position_m = Eigen::Vector3d(160.0 * std::sin(z), 0.0, 300.0 - 160.0 * std::cos(z));
  pose.rotation = FocalAttitude(pose.position_m, FocalAttitudeLaw());
  return pose;
}

// range(0): segments per cable; range(1): the pose's off-axis angle (deg).
void BM_Modes(benchmark::State& state) {
  const CableRobot robot = CableRobot::NominalFast();
  const Pose pose = FocalPose(static_cast<double>(state.range(1)));
  ModesOptions options;
  options.segments = static_cast<int>(state.range(0));
  options.modes = 20;
  ModesResult result;
  std::string error;
  for (auto _ : state) {
    if (!ComputeModes(robot, pose, options, &result, &error)) {
      state.SkipWithError(error.c_str());
      break;
    }
    benchmark::DoNotOptimize(result.modes.data());
  }
  state.counters["dofs"] = result.degrees_of_freedom;
}
BENCHMARK(BM_Modes)
    ->Args({12, 0})
    ->Args({24, 0})
    ->Args({ModesOptions().segments, 0})
    ->Args({ModesOptions().segments, 40})
    ->Args({64, 0})
    ->Unit(benchmark::kMillisecond);

// The map of the cap (modes_map.h) at its defaults: 193 poses, 20 modes each.
void BM_ModesMap(benchmark::State& state) {
  const CableRobot robot = CableRobot::NominalFast();
  ModesMapOptions options;
  ModesMap map;
  std::string error;
  for (auto _ : state) {
    if (!ComputeModesMap(robot, options, &map, &error)) {
      state.SkipWithError(error.c_str());
      break;
    }
    benchmark::DoNotOptimize(map.nodes.data());
  }
  state.counters["poses"] = static_cast<double>(map.nodes.size());
}
BENCHMARK(BM_ModesMap)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace fastcal

BENCHMARK_MAIN();
