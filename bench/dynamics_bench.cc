// Speed of the dynamics in time (dynamics.h): simulated seconds per CPU second.
//   BM_Integrate/N/wind: the integrator alone (CableDynamics::Advance at 10 Hz) over
//     `kSpanS` of the cabin held 40 deg off axis, N segments a cable, in still air (0) or
//     in a 4 m/s Kaimal wind (4): gusts keep every step's Newton at work.
//   BM_Hour: one hour of motion at 40 segments in the 4 m/s wind, once.
//   BM_Run: `fastcal dynamics`'s work (RunDynamics): a 10 m move in 60 s held 540 s,
//     with the quasi-static reference solved at every 10 Hz sample.
//   BM_LoopHour: `fastcal loop`'s work (closed_loop.h): an hour of the cabin held 20 deg
//     off axis under the default PID at 10 Hz, measured by a total station (0.4 mm,
//     0.24 s), in the 4 m/s wind, the controller's statics solved every cycle; once
//     (issue 56: under a minute of one core).
// The counter x_real_time is simulated time over the CPU time.
// Run: taskset -c 1 build/bench/dynamics_bench --benchmark_repetitions=3
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <string>

#include "fastcal/closed_loop.h"
#include "fastcal/dynamics.h"
#include "fastcal/dynamics_run.h"

namespace fastcal {
namespace {

constexpr double kSpanS = 600.0;
constexpr double kSampleS = 0.1;

Pose FocalPose(double zenith_deg) {
  const double z = zenith_deg * M_PI / 180.0;
  Pose pose;
  pose.position_m = Eigen::Vector3d(160.0 * std::sin(z), 0.0, 300.0 - 160.0 * std::cos(z));
  pose.rotation = FocalAttitude(pose.position_m, FocalAttitudeLaw());
  return pose;
}

// Advances a fresh model over span_s; false (with the state told) on failure.
bool Integrate(benchmark::State& state, int segments, double wind_m_per_s, double span_s) {
  DynamicsOptions options;
  options.segments = segments;
  options.wind.mean_speed_m_per_s = wind_m_per_s;
  options.wind.direction_deg = 30.0;
  std::string error;
  std::unique_ptr<CableDynamics> d =
      CableDynamics::Create(CableRobot::NominalFast(), FocalPose(40.0), options, span_s, &error);
  if (!d) {
    state.SkipWithError(error.c_str());
    return false;
  }
  const std::array<double, kNumCables> s0 = d->UnstretchedLengthsM();
  const long samples = std::lround(span_s / kSampleS);
  for (long k = 1; k <= samples; ++k) {
    if (!d->Advance(k * kSampleS, s0, &error)) {
      state.SkipWithError(error.c_str());
      return false;
    }
    benchmark::DoNotOptimize(d->LowerTensionsN());
  }
  state.counters["steps"] = static_cast<double>(d->stats().steps);
  state.counters["newton_per_step"] =
      static_cast<double>(d->stats().newton_iterations) / d->stats().steps;
  return true;
}

void BM_Integrate(benchmark::State& state) {
  for (auto _ : state) {
    if (!Integrate(state, static_cast<int>(state.range(0)), static_cast<double>(state.range(1)),
                   kSpanS)) {
      break;
    }
  }
  state.counters["x_real_time"] =
      benchmark::Counter(kSpanS * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Integrate)
    ->Args({20, 0})
    ->Args({40, 0})
    ->Args({40, 4})
    ->Args({80, 4})
    ->Unit(benchmark::kSecond);

void BM_Hour(benchmark::State& state) {
  constexpr double kHourS = 3600.0;
  for (auto _ : state) {
    if (!Integrate(state, 40, 4.0, kHourS)) break;
  }
  state.counters["x_real_time"] =
      benchmark::Counter(kHourS * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Hour)->Iterations(1)->Unit(benchmark::kSecond);

void BM_Run(benchmark::State& state) {
  DynamicsRunSpec spec;
  spec.start = FocalPose(0.0);
  spec.end.position_m = spec.start.position_m + Eigen::Vector3d(10.0, 0.0, 0.0);
  spec.move_s = 60.0;
  spec.hold_s = 540.0;
  DynamicsRunResult result;
  std::string error;
  for (auto _ : state) {
    if (!RunDynamics(CableRobot::NominalFast(), spec, DynamicsOptions(), &result, &error)) {
      state.SkipWithError(error.c_str());
      break;
    }
  }
  state.counters["x_real_time"] =
      benchmark::Counter(spec.DurationS() * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Run)->Unit(benchmark::kSecond);

void BM_LoopHour(benchmark::State& state) {
  LoopSpec spec;
  spec.start = FocalPose(20.0);
  spec.hold_s = 3600.0;
  LoopOptions loop;
  loop.measurement_noise_m = 0.0004;
  loop.measurement_delay_s = 0.24;
  DynamicsOptions plant;
  plant.wind.mean_speed_m_per_s = 4.0;
  plant.wind.direction_deg = 30.0;
  const CableRobot robot = CableRobot::NominalFast();
  LoopResult result;
  std::string error;
  for (auto _ : state) {
    if (!RunLoop(robot, robot, spec, loop, plant, &result, &error)) {
      state.SkipWithError(error.c_str());
      break;
    }
  }
  state.counters["x_real_time"] =
      benchmark::Counter(spec.DurationS() * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LoopHour)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
}  // namespace fastcal

BENCHMARK_MAIN();
