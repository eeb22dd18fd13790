// A season tracked against the same samples calibrated as one survey (issue 27): wall
// time, CPU time and peak resident memory of each.
//
// BM_Track/N/W: `fastcal track` on N samples in W daily windows (one CSV, read, cut into
// the window store, folded on 2 threads, outputs written), spec
// calibration_data/spec_track.yaml (mass centre per window; densities, gains and biases
// shared with priors; the tower tops considered; the slow error estimated).
// BM_CalibrateOneSurvey/N/W: the same file read and calibrated as one survey with the
// same spec (one mass centre; Calibrate's whole pipeline, its evaluation included) and the
// report written, as `fastcal calibrate` does.
//
// Each run is a forked child, so that its peak resident memory (peak_rss_MB, from wait4)
// is its own. Data: W days of N / W random poses over the cap, 2 s apart (10 Hz for
// 10^5 a day) from
// 2024-05-01T20:00:00Z, mass centre (0.22, 0.11, 0.5) m, 3% tension noise, a 1% slow
// sensor error (2 minutes), per-cable spreads of density (1%), gain (1%), bias (1.5 kN);
// written once, streamed (not timed).
// BM_Track/1000000/10 has 10^5 samples a window, as /10000000/100: with /1000000/100 it
// shows that a window's own samples do not set the memory (each window streamed).
// Run: build/bench/track_bench --benchmark_filter=/100000/   (half a minute on 2 cores);
// /1000000/ two minutes; /10000000/ (the 10^7 samples in 100 windows) 3 minutes
// for the track and 4 minutes for the one survey (8.3 GB of memory), plus 1.5 minutes
// writing 4 GB of CSV, and 1.6 GB of window store, in the temporary directory.
// Figures (2026-11-26, load 2.4 to 3; docs/calibration.md, "Speed and memory"):
//   samples/windows  track: wall, CPU, peak     one survey: wall, CPU, peak
//   10^5/100         3.5 s, 4.6 s, 128 MB        4.0 s, 7.1 s, 151 MB
//   10^6/100         14.9 s, 26.4 s, 131 MB      17.4 s, 30.3 s, 852 MB
//   10^6/10          14.4 s, 26.1 s, 100 MB
//   10^7/100         162 s, 248 s, 147 MB        220 s, 290 s, 8.3 GB
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "fastcal/calibration.h"
#include "fastcal/report.h"
#include "fastcal/simulation.h"
#include "fastcal/track.h"
#include "fastcal/trajectory.h"
#include "forked_run.h"

#ifndef FASTCAL_SOURCE_DIR
#define FASTCAL_SOURCE_DIR "."
#endif

namespace fastcal {
namespace {

constexpr double kStartS = 1714593600.0;  // 2024-05-01T20:00:00Z
constexpr double kIntervalS = 2.0;
constexpr double kDayS = 86400.0;

std::string DataFile(long long samples, int days) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("fastcal_track_bench_" + std::to_string(getpid()) + "_" +
                             std::to_string(samples) + "_" + std::to_string(days) + ".csv"))
                               .string();
  if (std::filesystem::exists(path)) return path;
  RandomWorkspaceSpec spec;
  spec.samples = static_cast<int>(samples);
  spec.seed = 7;
  PositionStream positions;
  std::string error;
  if (!RandomWorkspacePositionStream(spec, &positions, &error)) return "";
  PoseStream poses;
  poses.count = samples;
  poses.next = [positions, law = FocalAttitudeLaw()]() mutable {
    Pose pose;
    pose.position_m = positions.next();
    pose.rotation = FocalAttitude(pose.position_m, law);
    return pose;
  };
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = {0.22, 0.11, 0.5};
  SimulationOptions o;
  o.seed = 7;
  // 2 s apart, or at 10 Hz where a day's samples would not fit in half a day (10^5 a day).
  const double per_day = static_cast<double>(samples / days);
  o.sample_interval_s = per_day * kIntervalS <= 0.5 * kDayS ? kIntervalS : 0.1;
  o.start_time_s = kStartS;
  o.sessions = days;
  o.session_gap_s = kDayS - per_day * o.sample_interval_s;
  o.tension_drift_percent = 1.0;
  o.tension_drift_time_s = 120.0;
  o.sensor_gain_spread_percent = 1.0;
  o.sensor_bias_spread_kn = 1.5;
  o.density_mismatch_percent = 1.0;
  DatasetWriter writer;
  if (!writer.Open(path, SimulatedDatasetLayout(1), "track_bench", &error)) return "";
  const SampleSink sink = [&writer](const Sample& s, std::string* why) {
    return writer.Write(s, why);
  };
  if (!SimulateStream(truth, poses, o, sink, nullptr, nullptr, &error) || !writer.Close(&error)) {
    std::filesystem::remove(path);
    return "";
  }
  return path;
}

CalibrationSpec Spec() {
  CalibrationSpec spec;
  std::string error;
  LoadCalibrationSpec(std::string(FASTCAL_SOURCE_DIR) + "/calibration_data/spec_track.yaml",
                      CableRobot::NominalFast(), &spec, &error);
  return spec;
}

int RunTrackChild(const std::string& csv, const std::string& dir) {
  std::filesystem::remove_all(dir);
  TrackResult result;
  std::string error;
  return RunTrack(CableRobot::NominalFast(), Spec(), {csv}, WindowSpec(), dir, TrackOptions(),
                  &result, &error) == TrackStatus::kOk
             ? 0
             : 1;
}

int RunCalibrateChild(const std::string& csv, const std::string& dir) {
  return bench::ReadCalibrateReport(csv, Spec(), dir);
}

// Runs `child` in a forked process; its wall time, CPU time and peak memory as counters.
template <typename Child>
void Measure(benchmark::State& state, const Child& child) {
  const std::string csv = DataFile(state.range(0), static_cast<int>(state.range(1)));
  if (csv.empty()) {
    state.SkipWithError("cannot write the dataset file");
    return;
  }
  const std::string dir = csv + ".out";
  bench::ForkedIterations(state, [&] { return child(csv, dir); });
  std::filesystem::remove_all(dir);
  state.counters["windows"] = static_cast<double>(state.range(1));
}

void BM_Track(benchmark::State& state) { Measure(state, RunTrackChild); }
void BM_CalibrateOneSurvey(benchmark::State& state) { Measure(state, RunCalibrateChild); }

// The same file for both (the track first: DataFile writes it once per process).
BENCHMARK(BM_Track)
    ->Args({100000, 100})
    ->Args({1000000, 100})
    ->Args({1000000, 10})  // 10^5 a window, as at 10^7 in 100: a window's own memory
    ->Args({10000000, 100})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseManualTime();
BENCHMARK(BM_CalibrateOneSurvey)
    ->Args({100000, 100})
    ->Args({1000000, 100})
    ->Args({10000000, 100})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseManualTime();

}  // namespace
}  // namespace fastcal

BENCHMARK_MAIN();
