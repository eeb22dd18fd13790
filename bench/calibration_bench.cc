// Calibration wall time against dataset size, mass centre (x, y, z) and a common cable
// density free, for the aas and exact forward models; peak resident memory as a counter.
// Data: random poses over the focal-sphere cap (<= 40 deg, +-3 m), focal law, truth mass
// centre (0.22, 0.11, 0.5) m, 3% tension noise.
// Run: build/bench/calibration_bench   (about a minute; 1e5 samples dominate)
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <random>

#include "fastcal/calibration.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

Dataset MakeData(int samples) {
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = Eigen::Vector3d(0.22, 0.11, 0.5);
  RandomWorkspaceSpec spec;
  spec.samples = samples;
  spec.radial_spread_m = 3.0;
  spec.seed = 7;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  std::string error;
  RandomWorkspacePositions(spec, &positions, &error);
  PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, &error);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  StaticsOptions exact;
  exact.method = StaticsMethod::kExact;
  Dataset d;
  d.path = "bench";
  for (size_t n = 0; n < poses.size(); ++n) {
    StaticsSolution s;
    if (SolveStatics(truth, poses[n], exact, &s) != StaticsStatus::kOk) continue;
    Sample sample;
    sample.time_s = n;
    sample.pose = poses[n];
    for (int i = 0; i < kNumCables; ++i) {
      sample.tension_n[i] = s.cables[i].lower_tension_n * (1.0 + 0.03 * normal(rng));
    }
    d.samples.push_back(sample);
  }
  return d;
}

CalibrationSpec Spec(StaticsMethod forward) {
  CalibrationSpec spec;
  spec.forward_model = forward;
  spec.num_threads = 2;
  for (int c = 0; c < 4; ++c) {
    ParameterSpec p;
    p.kind = c < 3 ? ParameterKind::kMassCentre : ParameterKind::kLinearDensity;
    p.component = c < 3 ? c : -1;
    p.name = c < 3 ? std::string("mass_centre_m.") + "xyz"[c] : "linear_density_kg_per_m";
    p.unit = c < 3 ? "m" : "kg/m";
    p.free = true;
    spec.parameters.push_back(p);
  }
  return spec;
}

// range(0): samples, range(1): 0 aas, 2 exact.
void BM_Calibrate(benchmark::State& state) {
  const Dataset data = MakeData(static_cast<int>(state.range(0)));
  const CalibrationSpec spec = Spec(static_cast<StaticsMethod>(state.range(1)));
  CalibrationResult result;
  for (auto _ : state) {
    std::string error;
    if (Calibrate(CableRobot::NominalFast(), spec, data, CalibrationOptions(), &result, &error) !=
        CalibrationStatus::kOk) {
      state.SkipWithError(error.c_str());
      return;
    }
  }
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  state.counters["samples"] = static_cast<double>(data.samples.size());
  state.counters["iterations"] = result.iterations;
  state.counters["peak_rss_MB"] = usage.ru_maxrss / 1024.0;
  state.SetLabel(StaticsMethodName(spec.forward_model));
}

BENCHMARK(BM_Calibrate)
    ->ArgsProduct({{1000, 10000, 100000}, {0, 2}})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace fastcal

BENCHMARK_MAIN();
