// The change scan's wall time (change_scan.h) against survey length: a linear survey of
// N samples of 6 readings, 24 free parameters, 3 of them scanned (the mass centre of the
// recommended spec), white noise, no step; 1000 null draws per round, max_changes 3.
// Beyond kMaxScanUnits (2000) samples are grouped, so the cost levels off.
// Run: build/bench/change_scan_bench
#include <benchmark/benchmark.h>

#include <random>
#include <string>

#include "fastcal/change_scan.h"

namespace fastcal {
namespace {

constexpr int kRows = 6, kFree = 24;

void BM_ChangeScan(benchmark::State& state) {
  const int samples = static_cast<int>(state.range(0));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd residuals(samples, kRows);
  SampleJacobians jacobians(samples, kRows * kFree);
  for (int t = 0; t < samples; ++t) {
    for (int i = 0; i < kRows; ++i) {
      residuals(t, i) = normal(rng);
      for (int k = 0; k < kFree; ++k) jacobians(t, i * kFree + k) = static_cast<float>(normal(rng));
    }
  }
  ChangeScanInputs in;
  in.residuals = &residuals;
  in.jacobians = &jacobians;
  in.num_free = kFree;
  in.prior_information = Eigen::VectorXd::Zero(kFree);
  in.prior_gradient = Eigen::VectorXd::Zero(kFree);
  in.scanned = {0, 1, 2};
  ChangeScanOutput out;
  for (auto _ : state) {
    std::string error;
    if (!ScanForChanges(in, &out, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
  }
  state.counters["units"] = static_cast<double>(samples / out.unit_samples);
  state.counters["changes"] = static_cast<double>(out.changes.size());
}

BENCHMARK(BM_ChangeScan)
    ->Arg(500)
    ->Arg(2000)
    ->Arg(20000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace fastcal

BENCHMARK_MAIN();
