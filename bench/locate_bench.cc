// Time per pose of the forward statics (locate.h): where the cabin hangs for six given
// lengths, cold (the continuation from the home pose) at K2 and warm along the paper's
// 101-node half circle and line (focal attitude law), without and with the search for
// other equilibria; and the fit of lengths, attitude and tensions together, warm. The
// lengths are the inverse statics' at those poses, computed before timing.
// Run: build/bench/locate_bench --benchmark_min_time=0.2
// items_per_second is poses per second; time per pose = 1 / items_per_second.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "fastcal/locate.h"
#include "fastcal/statics.h"

namespace fastcal {
namespace {

constexpr int kPaperNodes = 101;
using Lengths = std::array<double, kNumCables>;

// The paper's trajectory (circle: the half circle of radius 50 m at z = 150 m; else the
// line from (50, 0, 150) to (-50, 0, 150)) as measurements: the inverse statics' lengths
// and tensions and the attitude at each node.
std::vector<LocateMeasurement> PaperMeasurements(bool circle) {
  const CableRobot robot = CableRobot::NominalFast();
  std::vector<LocateMeasurement> out;
  for (int n = 0; n < kPaperNodes; ++n) {
    Pose p;
    const double t = M_PI * n / (kPaperNodes - 1);
    p.position_m = circle ? Eigen::Vector3d(50 * std::cos(t), 50 * std::sin(t), 150)
                          : Eigen::Vector3d(50.0 - 100.0 * n / (kPaperNodes - 1), 0, 150);
    p.rotation = FocalAttitude(p.position_m, FocalAttitudeLaw());
    StaticsSolution s;
    SolveStatics(robot, p, StaticsOptions(), &s);
    LocateMeasurement m;
    m.has_attitude = m.has_tensions = true;
    m.rotation = p.rotation;
    for (int i = 0; i < kNumCables; ++i) {
      m.length_m[i] = s.cables[i].unstretched_length_m;
      m.tension_n[i] = s.cables[i].lower_tension_n;
    }
    out.push_back(m);
  }
  return out;
}

// range(0): 1 searches for other equilibria (LocateOptions::search_radius_m), 0 does not.
void BM_LocateColdK2(benchmark::State& state) {
  const CableRobot robot = CableRobot::NominalFast();
  Pose k2;
  k2.position_m = Eigen::Vector3d(42.65, 33.73, 149.52);
  k2.rotation = FocalAttitude(k2.position_m, FocalAttitudeLaw());
  StaticsSolution s;
  SolveStatics(robot, k2, StaticsOptions(), &s);
  Lengths s0;
  for (int i = 0; i < kNumCables; ++i) s0[i] = s.cables[i].unstretched_length_m;
  LocateOptions options;
  if (state.range(0) == 0) options.search_radius_m = 0.0;
  LocateSolution solution;
  for (auto _ : state) {
    Locate(robot, s0, options, &solution);
    benchmark::DoNotOptimize(solution);
  }
  state.SetLabel(state.range(0) ? "cold, search" : "cold");
  state.SetItemsProcessed(state.iterations());
}

// range(0): 0 line / 1 half circle; range(1): search; range(2): fit with attitude and
// tensions (LocateFromMeasurements) instead of lengths alone.
void BM_LocatePaperTrajectoryWarm(benchmark::State& state) {
  const CableRobot robot = CableRobot::NominalFast();
  const std::vector<LocateMeasurement> nodes = PaperMeasurements(state.range(0) == 1);
  LocateOptions options;
  options.warm_start = true;
  if (state.range(1) == 0) options.search_radius_m = 0.0;
  const bool fit = state.range(2) == 1;
  const LocateNoise noise;
  LocateSolution solution;
  for (auto _ : state) {
    for (const LocateMeasurement& m : nodes) {
      if (fit) {
        LocateFromMeasurements(robot, m, noise, options, &solution);
      } else {
        Locate(robot, m.length_m, options, &solution);
      }
      benchmark::DoNotOptimize(solution);
    }
  }
  state.SetLabel(std::string(state.range(0) ? "circle" : "line") + " warm" +
                 (state.range(1) ? ", search" : "") + (fit ? ", fit" : ""));
  state.SetItemsProcessed(state.iterations() * nodes.size());
}

BENCHMARK(BM_LocateColdK2)->Arg(0)->Arg(1);
BENCHMARK(BM_LocatePaperTrajectoryWarm)
    ->Args({0, 0, 0})
    ->Args({1, 0, 0})
    ->Args({1, 1, 0})
    ->Args({1, 0, 1});

}  // namespace
}  // namespace fastcal

BENCHMARK_MAIN();
