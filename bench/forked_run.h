// What the end-to-end benchmarks share (calibration_bench, track_bench): a survey read,
// calibrated and reported in a child process, and the forked measurement of a child's
// wall time, CPU time and peak memory (a fresh process per run, so that the peak is the
// run's own).
#ifndef FASTCAL_BENCH_FORKED_RUN_H_
#define FASTCAL_BENCH_FORKED_RUN_H_

#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/report.h"

namespace fastcal::bench {

// Seconds since `start` (steady clock).
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// In the child: read, calibrate with `spec`, write the report into `dir`. Exit code 0 on
// success; else 1 (read), 2 (calibrate) or 3 (report), the reason on stderr. With
// `stages_path`, each stage's wall time there as lines "NAME<TAB>SECONDS": "read", the
// pipeline's stages (CalibrationResult::stages), "write".
inline int ReadCalibrateReport(const std::string& csv, const CalibrationSpec& spec,
                               const std::string& dir,
                               const CableRobot& model = CableRobot::NominalFast(),
                               const std::string& stages_path = "") {
  auto lap = std::chrono::steady_clock::now();
  Dataset data;
  std::string error;
  const auto failed = [&error](int code) {
    std::fprintf(stderr, "the child failed: %s\n", error.c_str());
    return code;
  };
  DatasetReadOptions read;
  read.threads = 2;  // as fastcal calibrate reads
  // The library's reader, without the CLI's 1 GiB refusal: track_bench's one survey of
  // 10^7 samples is a 4 GB file (its memory, ~8 GB, is what the comparison shows).
  read.max_file_bytes = 1LL << 40;
  read.joint_columns = model.moving_parts.JointColumns();
  if (!ReadDataset(csv, read, &data, &error)) return failed(1);
  const double read_s = SecondsSince(lap);
  CalibrationResult result;
  if (Calibrate(model, spec, data, CalibrationOptions(), &result, &error) !=
      CalibrationStatus::kOk) {
    return failed(2);
  }
  ReportInputs inputs;
  inputs.initial_model = &model;
  inputs.spec = &spec;
  inputs.data = &data;
  inputs.result = &result;
  inputs.variants = std::move(result.variants);
  lap = std::chrono::steady_clock::now();
  std::filesystem::create_directories(dir);
  if (!WriteReportFiles(dir, inputs, &error)) return failed(3);
  if (!stages_path.empty()) {
    std::FILE* out = std::fopen(stages_path.c_str(), "w");
    if (out == nullptr) return 3;
    std::fprintf(out, "read\t%.6f\n", read_s);
    for (const CalibrationResult::Stage& stage : result.stages) {
      std::fprintf(out, "%s\t%.6f\n", stage.name.c_str(), stage.seconds);
    }
    std::fprintf(out, "write\t%.6f\n", SecondsSince(lap));
    if (std::fclose(out) != 0) return 3;
  }
  return 0;
}

// Runs `child` in a forked process per iteration: wall time, its CPU time and peak memory.
template <typename Child>
inline void ForkedIterations(benchmark::State& state, const Child& child) {
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) _exit(child());
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      state.SkipWithError("the run failed");
      break;
    }
    state.counters["peak_rss_MB"] = usage.ru_maxrss / 1024.0;
    state.counters["cpu_s"] = usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 +
                              usage.ru_stime.tv_sec + usage.ru_stime.tv_usec * 1e-6;
  }
  state.counters["samples"] = static_cast<double>(state.range(0));
}

}  // namespace fastcal::bench

#endif  // FASTCAL_BENCH_FORKED_RUN_H_
