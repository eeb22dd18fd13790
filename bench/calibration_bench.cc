// Calibration against dataset size (issue 20): wall time and peak resident memory.
//
// BM_CalibrateEndToEnd/N: what `fastcal calibrate` does with N samples: read the CSV,
// calibrate (the whole pipeline: gross errors, budget, autocorrelation, misfit ranking,
// cross-validation, the RMS table) and write report.html, report.md and summary.json.
// Each run is a forked child, so that its peak resident memory (peak_rss_MB, from wait4)
// is its own and not the benchmark process's; the dataset file is written once, streamed,
// before (not timed). Spec: calibration_data/spec_mass_centre_density.yaml's (mass
// centre x, y, z and a common density, exact forward model, 3% noise), on the spec's
// default 2 threads.
//
// BM_Calibrate/N/method: Calibrate alone, in process, for the aas and exact forward
// models (peak_rss_MB is then the process's so far: run one size at a time).
//
// Data: random poses over the focal-sphere cap (<= 40 deg, +-3 m), focal law, truth mass
// centre (0.22, 0.11, 0.5) m, 3% tension noise (seeded).
// Run: build/bench/calibration_bench --benchmark_filter=EndToEnd   (about a minute)
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>

#include "fastcal/calibration.h"
#include "fastcal/report.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

CableRobot Truth() {
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = Eigen::Vector3d(0.22, 0.11, 0.5);
  return truth;
}

std::vector<Pose> Poses(int samples) {
  RandomWorkspaceSpec spec;
  spec.samples = samples;
  spec.radial_spread_m = 3.0;
  spec.seed = 7;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  std::string error;
  RandomWorkspacePositions(spec, &positions, &error);
  PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, &error);
  return poses;
}

// Samples at `poses` with 3% seeded noise on the truth's exact tensions, to `sink`.
template <typename Sink>
void MakeSamples(const std::vector<Pose>& poses, const Sink& sink) {
  const CableRobot truth = Truth();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  StaticsOptions exact;
  for (size_t n = 0; n < poses.size(); ++n) {
    StaticsSolution s;
    if (SolveStatics(truth, poses[n], exact, &s) != StaticsStatus::kOk) continue;
    Sample sample;
    sample.line = static_cast<int>(n) + 2;
    sample.time_s = static_cast<double>(n);
    sample.pose = poses[n];
    for (int i = 0; i < kNumCables; ++i) {
      sample.tension_n[i] = s.cables[i].lower_tension_n * (1.0 + 0.03 * normal(rng));
    }
    sink(sample);
  }
}

Dataset MakeData(int samples) {
  Dataset d;
  d.path = "bench";
  MakeSamples(Poses(samples), [&](const Sample& s) { d.samples.push_back(s); });
  return d;
}

// The dataset file of `samples` samples, written once (streamed: the benchmark process
// stays small, since a forked child's resident memory starts as its parent's).
std::string DataFile(int samples) {
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("fastcal_bench_" + std::to_string(getpid()) + "_" + std::to_string(samples) + ".csv"))
          .string();
  if (std::filesystem::exists(path)) return path;
  Dataset layout;
  DatasetWriter writer;
  std::string error;
  if (!writer.Open(path, layout, "calibration_bench", &error)) return "";
  bool ok = true;
  MakeSamples(Poses(samples), [&](const Sample& s) { ok = ok && writer.Write(s, &error); });
  return ok && writer.Close(&error) ? path : "";
}

CalibrationSpec Spec(StaticsMethod forward) {
  CalibrationSpec spec;
  spec.forward_model = forward;
  spec.num_threads = 2;
  spec.tension_sigma_percent = 3.0;
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

// In the child: read, calibrate, write the report into `dir`. Exit code 0 on success.
int ReadCalibrateReport(const std::string& csv, const std::string& dir) {
  Dataset data;
  std::string error;
  DatasetReadOptions read;
  read.threads = 2;  // as fastcal calibrate reads
  if (!ReadDataset(csv, read, &data, &error)) return 1;
  const CableRobot model = CableRobot::NominalFast();
  const CalibrationSpec spec = Spec(StaticsMethod::kExact);
  CalibrationResult result;
  if (Calibrate(model, spec, data, CalibrationOptions(), &result, &error) !=
      CalibrationStatus::kOk) {
    return 2;
  }
  ReportInputs inputs;
  inputs.initial_model = &model;
  inputs.spec = &spec;
  inputs.data = &data;
  inputs.result = &result;
  inputs.variants = std::move(result.variants);
  std::filesystem::create_directories(dir);
  return WriteReportFiles(dir, inputs, &error) ? 0 : 3;
}

void BM_CalibrateEndToEnd(benchmark::State& state) {
  const std::string csv = DataFile(static_cast<int>(state.range(0)));
  if (csv.empty()) {
    state.SkipWithError("cannot write the dataset file");
    return;
  }
  const std::string dir = csv + ".out";
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const pid_t child = fork();
    if (child == 0) _exit(ReadCalibrateReport(csv, dir));
    int status = 0;
    rusage usage{};
    wait4(child, &status, 0, &usage);
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      state.SkipWithError("the calibration failed");
      break;
    }
    state.counters["peak_rss_MB"] = usage.ru_maxrss / 1024.0;
    state.counters["cpu_s"] = usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 +
                              usage.ru_stime.tv_sec + usage.ru_stime.tv_usec * 1e-6;
  }
  std::filesystem::remove_all(dir);
  std::filesystem::remove(csv);
  state.counters["samples"] = static_cast<double>(state.range(0));
}

BENCHMARK(BM_CalibrateEndToEnd)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseManualTime();

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
