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
//
// BM_RealisticEndToEnd/N (issue 28): the same end to end with the recommended spec,
// calibration_data/spec_realistic.yaml (mass centre, per-cable densities, gains and biases:
// 21 free parameters, tower offsets as consider parameters), on the data of
// `fastcal simulate --trajectory=random --samples=N --tension-noise-pct=3
// --sensor-gain-spread-pct=1 --sensor-bias-spread-kn=1.5` (seed 1, focal law): wall time,
// cpu_s (user + system) and peak_rss_MB of the forked child.
//
// BM_SampleRows/part (issue 28): one sample's share of a Jacobian evaluation of the fit
// with spec_realistic.yaml, per sample over 4096 of the samples above: 0 statics (exact,
// warm-started from the initial parameters' solution, at parameters a fit step away),
// 1 derivatives (the tensions' gradient by the implicit-function theorem and the 6 x 21
// Jacobian), 2 folding with a loss (the robust loss's correction and the QR fold of the
// rows into R at full width), 3 statics and derivatives together
// (TensionResidual::Evaluate), 4 the same by a Jet as wide as n through the replayed
// statics (TensionCost::EvaluateJet: before issue 28), 5 folding without a loss as
// spec_realistic.yaml's fit does it, each reading's rows over its own columns first
// (GroupedRowFold). One thread.
// BM_RealisticStages/N (issue 41): the same run, with each stage's wall time (read, the
// pipeline's stages grouped, write) and the yardstick beside it: N bare AAS solves
// (SolveStatics, method aas, cold) on one thread over the same samples, measured in the
// same run; x_yardstick is the end-to-end wall time over it.
// BM_RealisticFloor/N (issue 41): a lower bound on that x_yardstick for this method, the
// same data read, predicted and folded twice as a one-step fit at least must (FloorChild),
// with each lap and the yardstick of the same run: floor_x_yardstick.
// BM_RealisticPartsEndToEnd/N (issue 35): the same with calibration_data/moving_parts.yaml
// (the rotator through a grid of +-15 deg, the platform spread 5 cm) and
// spec_moving_parts.yaml (the rotator's first moment and the platform's mass freed too).
// Run: build/bench/calibration_bench --benchmark_filter=EndToEnd   (about a minute)
//      build/bench/calibration_bench --benchmark_filter=RealisticStages
//          --benchmark_counters_tabular=true   (the stages and the yardstick, ~1 min)
//      build/bench/calibration_bench --benchmark_filter='Realistic|SampleRows'  (~2 min)
//      build/bench/calibration_bench --benchmark_filter=RealisticFloor/1000000
//          --benchmark_counters_tabular=true   (the floor and its yardstick, ~1 min)
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <string>

#include "fastcal/calibration.h"
#include "fastcal/internal/calibration_linearisation.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/folded_cost.h"
#include "fastcal/internal/row_fold.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/report.h"
#include "fastcal/simulation.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"
#include "forked_run.h"

namespace fastcal {
namespace {

using bench::ForkedIterations;
using bench::ReadCalibrateReport;

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

// Read, calibrate with `spec` and report `csv` (then removed) in a forked child.
void EndToEnd(benchmark::State& state, const std::string& csv, const CalibrationSpec& spec) {
  if (csv.empty()) {
    state.SkipWithError("cannot write the dataset file");
    return;
  }
  const std::string dir = csv + ".out";
  ForkedIterations(state, [&] { return ReadCalibrateReport(csv, spec, dir); });
  std::filesystem::remove_all(dir);
  std::filesystem::remove(csv);
}

// 10^4, 10^5 and 10^6 samples, one run each, in seconds of wall time.
void EndToEndSizes(benchmark::internal::Benchmark* b) {
  b->Arg(10000)->Arg(100000)->Arg(1000000)->Iterations(1)->Unit(benchmark::kSecond);
  b->UseManualTime();
}

void BM_CalibrateEndToEnd(benchmark::State& state) {
  EndToEnd(state, DataFile(static_cast<int>(state.range(0))), Spec(StaticsMethod::kExact));
}

// ---------------------------------------------------------------------------------------
// spec_realistic.yaml (issue 28).

const char kRealisticSpec[] = FASTCAL_SOURCE_DIR "/calibration_data/spec_realistic.yaml";

// `fastcal simulate --trajectory=random --samples=N --tension-noise-pct=3
// --sensor-gain-spread-pct=1 --sensor-bias-spread-kn=1.5`'s data, to `sink`.
bool SimulateRealistic(int samples, const SampleSink& sink,
                       const CableRobot& truth = CableRobot::NominalFast()) {
  RandomWorkspaceSpec positions;
  positions.samples = samples;
  positions.seed = 1;
  PositionStream stream;
  std::string error;
  if (!RandomWorkspacePositionStream(positions, &stream, &error)) return false;
  PoseStream poses;
  poses.count = stream.count;
  poses.next = [&stream] {
    Pose pose;
    pose.position_m = stream.next();
    pose.rotation = FocalAttitude(pose.position_m, FocalAttitudeLaw());
    return pose;
  };
  SimulationOptions options;
  options.tension_noise_percent = 3.0;
  options.sensor_gain_spread_percent = 1.0;
  options.sensor_bias_spread_kn = 1.5;
  // A cabin with moving parts: the rotator through a grid of angles, the platform spread.
  options.joints.revolute = truth.moving_parts.empty() ? RevoluteLaw::kZero : RevoluteLaw::kGrid;
  options.joints.grid_deg = {-15.0, 0.0, 15.0};
  options.joints.prismatic_sigma_m = 0.05;
  CableRobot truth_used;
  SimulationSummary summary;
  return SimulateStream(truth, poses, options, sink, &truth_used, &summary, &error);
}

// calibration_data/moving_parts.yaml and spec_moving_parts.yaml (issue 35).
const char kPartsModel[] = FASTCAL_SOURCE_DIR "/calibration_data/moving_parts.yaml";
const char kPartsSpec[] = FASTCAL_SOURCE_DIR "/calibration_data/spec_moving_parts.yaml";

std::string RealisticDataFile(int samples, const CableRobot& truth = CableRobot::NominalFast()) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("fastcal_bench_realistic_" + std::to_string(getpid()) + "_" +
                             std::to_string(samples) + ".csv"))
                               .string();
  DatasetWriter writer;
  std::string error;
  if (!writer.Open(path, SimulatedDatasetLayout(1, truth.moving_parts.JointColumns()),
                   "calibration_bench", &error)) {
    return "";
  }
  const bool ok = SimulateRealistic(
      samples, [&](const Sample& s, std::string* e) { return writer.Write(s, e); }, truth);
  return ok && writer.Close(&error) ? path : "";
}

// spec_realistic.yaml into *spec; false (the benchmark skipped, saying why) when it fails.
bool RealisticSpec(benchmark::State& state, CalibrationSpec* spec) {
  std::string error;
  if (LoadCalibrationSpec(kRealisticSpec, CableRobot::NominalFast(), spec, &error)) return true;
  state.SkipWithError(error.c_str());
  return false;
}

void BM_RealisticEndToEnd(benchmark::State& state) {
  CalibrationSpec spec;
  if (!RealisticSpec(state, &spec)) return;
  EndToEnd(state, RealisticDataFile(static_cast<int>(state.range(0))), spec);
}

BENCHMARK(BM_RealisticEndToEnd)->Apply(EndToEndSizes);

// Runs `child` in a forked process and waits: true when it exited 0.
template <typename Child>
bool ForkedChild(const Child& child) {
  const pid_t pid = fork();
  if (pid == 0) _exit(child());
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// The yardstick of issue 41: one bare AAS solve (SolveStatics, StaticsOptions' defaults
// but method kAas, cold) per sample of `csv`, on one thread, in a forked child (the
// dataset read first, not timed). Seconds; NaN on failure.
double AasYardstickSeconds(const std::string& csv) {
  const std::string out = csv + ".yardstick";
  const bool ok = ForkedChild([&] {
    Dataset data;
    DatasetReadOptions read;
    read.max_file_bytes = 1LL << 40;
    std::string error;
    if (!ReadDataset(csv, read, &data, &error)) return 1;
    const CableRobot model = CableRobot::NominalFast();
    StaticsOptions options;
    options.method = StaticsMethod::kAas;
    StaticsSolution solution;
    int solved = 0;
    const auto start = std::chrono::steady_clock::now();
    for (const Sample& s : data.samples) {
      solved += SolveStatics(model, s.pose, options, &solution) == StaticsStatus::kOk;
    }
    const double seconds = bench::SecondsSince(start);
    benchmark::DoNotOptimize(solved);
    std::FILE* f = std::fopen(out.c_str(), "w");
    if (f == nullptr) return 1;
    std::fprintf(f, "%.6f\n", seconds);
    return std::fclose(f) == 0 ? 0 : 1;
  });
  double seconds = std::nan("");
  if (std::FILE* f = ok ? std::fopen(out.c_str(), "r") : nullptr) {
    if (std::fscanf(f, "%lf", &seconds) != 1) seconds = std::nan("");
    std::fclose(f);
  }
  std::filesystem::remove(out);
  return seconds;
}

// The stages' wall times of a child's run (bench::ReadCalibrateReport's file) as counters,
// grouped: read, predict (and screen), check (build and identifiability), solve (and
// reweight: the IRLS passes), linearise, uncertainty, evaluate (the RMS table), write
// (report.html, report.md, summary.json), other (the rest of the pipeline).
void StageCounters(const std::string& path, benchmark::State& state) {
  static const std::map<std::string, std::string> kGroup = {{"read", "read_s"},
                                                            {"predict and screen", "predict_s"},
                                                            {"build and check", "check_s"},
                                                            {"solve and reweight", "solve_s"},
                                                            {"linearise", "linearise_s"},
                                                            {"uncertainty", "uncertainty_s"},
                                                            {"evaluate", "evaluate_s"},
                                                            {"write", "write_s"}};
  for (const auto& [name, counter] : kGroup) state.counters[counter] = 0.0;
  state.counters["other_s"] = 0.0;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const size_t tab = line.find('\t');
    if (tab == std::string::npos) continue;
    const auto group = kGroup.find(line.substr(0, tab));
    state.counters[group == kGroup.end() ? "other_s" : group->second] +=
        std::stod(line.substr(tab + 1));
  }
}

// BM_RealisticStages/N (issue 41): BM_RealisticEndToEnd's run with the wall time of each
// stage, beside the yardstick measured in the same run: N bare AAS solves on one thread
// (x_yardstick = the end-to-end wall time over it; the goal is 2.0 at 10^6).
void BM_RealisticStages(benchmark::State& state) {
  CalibrationSpec spec;
  if (!RealisticSpec(state, &spec)) return;
  const std::string csv = RealisticDataFile(static_cast<int>(state.range(0)));
  if (csv.empty()) {
    state.SkipWithError("cannot write the dataset file");
    return;
  }
  const std::string dir = csv + ".out";
  const std::string stages = csv + ".stages";
  const auto start = std::chrono::steady_clock::now();
  ForkedIterations(state, [&] {
    return ReadCalibrateReport(csv, spec, dir, CableRobot::NominalFast(), stages);
  });
  const double wall_s = bench::SecondsSince(start);
  StageCounters(stages, state);
  const double yardstick_s = AasYardstickSeconds(csv);
  state.counters["yardstick_s"] = yardstick_s;
  state.counters["x_yardstick"] = wall_s / yardstick_s;
  std::filesystem::remove_all(dir);
  std::filesystem::remove(stages);
  std::filesystem::remove(csv);
}

BENCHMARK(BM_RealisticStages)->Apply(EndToEndSizes);

// The fit's samples over `data` as the calibration builds them (exact statics, no loss, no
// slow error): every sample fitted, whitened by `sigma`, started from `starts`.
internal::FittedSamples ExactFittedSamples(const internal::CalibrationModel& cm,
                                           const Dataset& data, const std::vector<int>& fit,
                                           const std::vector<std::array<double, kNumCables>>& sigma,
                                           const internal::CompactStarts& starts) {
  internal::FittedSamples samples;
  samples.model = &cm;
  samples.data = &data;
  samples.fit = &fit;
  samples.sigma_n = &sigma;
  samples.starts = &starts;
  samples.statics = ModelFitStaticsOptions(StaticsMethod::kExact);
  return samples;
}

// A fit step away from `theta`: the mass centre moved by 2 cm, the gains by 0.5%.
void StepAway(const CalibrationSpec& spec, const internal::CalibrationModel& cm,
              std::vector<double>* theta) {
  for (int k = 0; k < cm.num_free(); ++k) {
    const ParameterKind kind = spec.parameters[cm.spec_index(k)].kind;
    if (kind == ParameterKind::kMassCentre) (*theta)[k] += 0.02;
    if (kind == ParameterKind::kSensorGain) (*theta)[k] *= 1.005;
  }
}

// The floor's child: read `csv` as the command line does, then the least a Gauss-Newton
// fit of spec_realistic.yaml does on the spec's 2 threads, with the library's own passes:
// the prediction (one exact solve per sample, cold: no start is known before), the
// Jacobian fold at the initial parameters (FoldedTensionCost::Fold, which takes the
// prediction's solutions as solved: derivatives and fold only), and the fold one step
// away (statics warm from the prediction, derivatives, fold), where any fit must look at
// least once to know that it has converged, and linearises. Each lap's seconds to
// `out_path`, one per line: read, predict, fold at the start, fold a step away.
int FloorChild(const std::string& csv, const std::string& out_path) {
  auto lap = std::chrono::steady_clock::now();
  Dataset data;
  DatasetReadOptions read;
  read.threads = 2;  // as fastcal calibrate reads
  read.max_file_bytes = 1LL << 40;
  std::string error;
  if (!ReadDataset(csv, read, &data, &error)) return 1;
  std::vector<double> laps = {bench::SecondsSince(lap)};
  const CableRobot model = CableRobot::NominalFast();
  CalibrationSpec spec;
  if (!LoadCalibrationSpec(kRealisticSpec, model, &spec, &error)) return 1;
  const internal::CalibrationModel cm(model, spec);
  const int n = cm.num_free();
  const int count = static_cast<int>(data.samples.size());
  std::vector<double> theta = cm.InitialTheta();
  StaticsParameters<double> params;
  std::array<double, kNumCables> gain, bias;
  cm.Assemble(theta.data(), &params, &gain, &bias);
  std::vector<int> fit(count);
  std::vector<std::array<double, kNumCables>> sigma(count);
  internal::CompactStarts starts(StaticsMethod::kExact);
  starts.Reset(count);
  const StaticsOptions statics = ModelFitStaticsOptions(StaticsMethod::kExact);
  lap = std::chrono::steady_clock::now();
  const int failed = internal::ForEachChunk(count, spec.num_threads, [&](int begin, int end) {
    StaticsSolution s;
    for (int t = begin; t < end; ++t) {
      fit[t] = t;
      if (SolveStaticsWithParameters(params, data.samples[t].pose, statics, &s) !=
          StaticsStatus::kOk) {
        return t;
      }
      starts.Set(t, s);
      std::array<double, kNumCables> reading;
      for (int i = 0; i < kNumCables; ++i) {
        reading[i] = gain[i] * s.cables[i].lower_tension_n + bias[i];
      }
      sigma[t] = internal::TensionSigmas(reading, spec.tension_sigma_n, spec.tension_sigma_percent);
    }
    return -1;
  });
  if (failed >= 0) return 1;
  starts.MarkSolvedAt(&cm, theta.data(), n);
  laps.push_back(bench::SecondsSince(lap));
  const internal::FittedSamples samples = ExactFittedSamples(cm, data, fit, sigma, starts);
  const internal::FoldedTensionCost cost(samples, nullptr, spec.num_threads, true);
  // Through Ceres's entry point, as the solver calls it (the fold is the cost's whole work).
  std::vector<double> residuals(n + 1), jacobian((n + 1) * n);
  double* jacobians[] = {jacobian.data()};
  for (int step = 0; step < 2; ++step) {
    if (step == 1) StepAway(spec, cm, &theta);
    lap = std::chrono::steady_clock::now();
    const double* parameters[] = {theta.data()};
    if (!cost.Evaluate(parameters, residuals.data(), jacobians)) return 1;
    laps.push_back(bench::SecondsSince(lap));
  }
  benchmark::DoNotOptimize(residuals[n]);
  std::FILE* f = std::fopen(out_path.c_str(), "w");
  if (f == nullptr) return 1;
  for (const double s : laps) std::fprintf(f, "%.6f\n", s);
  return std::fclose(f) == 0 ? 0 : 1;
}

// BM_RealisticFloor/N (issue 41): a lower bound on BM_RealisticStages's x_yardstick for
// this method: FloorChild's laps (read, predict, the two folds; no screening, no second
// IRLS pass, no identifiability check, no uncertainty, nothing written), in a forked
// child, beside the yardstick measured in the same run.
void BM_RealisticFloor(benchmark::State& state) {
  const std::string csv = RealisticDataFile(static_cast<int>(state.range(0)));
  if (csv.empty()) {
    state.SkipWithError("cannot write the dataset file");
    return;
  }
  const std::string laps_path = csv + ".floor";
  const bool ok = ForkedChild([&] { return FloorChild(csv, laps_path); });
  std::vector<double> laps;
  if (std::FILE* f = ok ? std::fopen(laps_path.c_str(), "r") : nullptr) {
    double s = 0.0;
    while (std::fscanf(f, "%lf", &s) == 1) laps.push_back(s);
    std::fclose(f);
  }
  std::filesystem::remove(laps_path);
  if (laps.size() != 4) {
    std::filesystem::remove(csv);
    state.SkipWithError("the floor's child failed");
    return;
  }
  const double floor_s = laps[0] + laps[1] + laps[2] + laps[3];
  for (auto _ : state) state.SetIterationTime(floor_s);
  state.counters["read_s"] = laps[0];
  state.counters["predict_s"] = laps[1];
  state.counters["fold_start_s"] = laps[2];
  state.counters["fold_step_s"] = laps[3];
  const double yardstick_s = AasYardstickSeconds(csv);
  state.counters["yardstick_s"] = yardstick_s;
  state.counters["floor_x_yardstick"] = floor_s / yardstick_s;
  std::filesystem::remove(csv);
}

BENCHMARK(BM_RealisticFloor)->Apply(EndToEndSizes);

// The same with the cabin's moving parts (issue 35: within 1.2x of the above).
void BM_RealisticPartsEndToEnd(benchmark::State& state) {
  CableRobot model;
  CalibrationSpec spec;
  std::string error;
  if (!LoadCableRobot(kPartsModel, &model, &error) ||
      !LoadCalibrationSpec(kPartsSpec, model, &spec, &error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  const std::string csv = RealisticDataFile(static_cast<int>(state.range(0)), model);
  if (csv.empty()) {
    state.SkipWithError("cannot write the dataset file");
    return;
  }
  const std::string dir = csv + ".out";
  ForkedIterations(state, [&] { return ReadCalibrateReport(csv, spec, dir, model); });
  std::filesystem::remove_all(dir);
  std::filesystem::remove(csv);
}

BENCHMARK(BM_RealisticPartsEndToEnd)->Apply(EndToEndSizes);

// The per-sample parts of a Jacobian evaluation (file comment), range(0): the part.
// BM_SampleRows's inputs: 4096 samples of the realistic data, each solved at the initial
// parameters (the starts), a fit step away from there (theta), each sample's statics there
// (solutions, for the derivatives alone) and its rows there (rows, for the folding alone).
// Built in place: `samples` points into the members.
struct SampleRowsSetup {
  static constexpr int kSamples = 4096;
  Dataset data;
  CalibrationSpec spec;
  std::unique_ptr<internal::CalibrationModel> cm;
  std::vector<int> fit;
  std::vector<std::array<double, kNumCables>> sigma;
  internal::CompactStarts starts{StaticsMethod::kExact};
  StaticsOptions statics = ModelFitStaticsOptions(StaticsMethod::kExact);
  internal::FittedSamples samples;
  std::vector<double> theta;
  StaticsParameters<double> params;
  std::array<double, kNumCables> gain, bias;
  std::vector<StaticsSolution> solutions;
  Eigen::MatrixXd rows;
  std::string error;

  int n() const { return cm->num_free(); }
  int count() const { return static_cast<int>(data.samples.size()); }

  // False with `error` when the spec does not load.
  bool Build() {
    SimulateRealistic(kSamples, [&](const Sample& s, std::string*) {
      data.samples.push_back(s);
      return true;
    });
    const CableRobot model = CableRobot::NominalFast();
    if (!LoadCalibrationSpec(kRealisticSpec, model, &spec, &error)) return false;
    cm = std::make_unique<internal::CalibrationModel>(model, spec);
    fit.resize(count());
    sigma.resize(count());
    starts.Reset(count());
    for (int t = 0; t < count(); ++t) {
      fit[t] = t;
      StaticsSolution s;
      SolveStatics(model, data.samples[t].pose, statics, &s);
      starts.Set(t, s);
      sigma[t] = internal::TensionSigmas(data.samples[t].tension_n, 0.0, 3.0);
    }
    samples = ExactFittedSamples(*cm, data, fit, sigma, starts);
    theta = cm->InitialTheta();
    StepAway(spec, *cm, &theta);
    cm->Assemble(theta.data(), &params, &gain, &bias);
    SolveAndRow();
    return true;
  }

  // Each sample's statics and rows at theta.
  void SolveAndRow() {
    const int n = this->n();
    solutions.resize(count());
    rows.resize(kNumCables * count(), n + 1);
    std::vector<double> j(kNumCables * n);
    StaticsOptions warm = statics;
    warm.warm_start = true;
    for (int t = 0; t < count(); ++t) {
      const internal::TensionResidual f = samples.At(t);
      f.start.Restore(f.pose, statics.method, &solutions[t]);
      SolveStaticsWithParameters(params, f.pose, warm, &solutions[t]);
      double r[kNumCables];
      f.Evaluate(theta.data(), r, j.data());
      for (int i = 0; i < kNumCables; ++i) {
        for (int k = 0; k < n; ++k) rows(kNumCables * t + i, k) = j[i * n + k];
        rows(kNumCables * t + i, n) = r[i];
      }
    }
  }
};

// Parts 0, 3 and 4: every sample's residuals (0), with their Jacobian (3), by Jets (4).
double EvaluateEverySample(const SampleRowsSetup& in, int part) {
  std::vector<double> j(kNumCables * in.n());
  double sink = 0.0;
  for (int t = 0; t < in.count(); ++t) {
    const internal::TensionResidual f = in.samples.At(t);
    double r[internal::kMaxReadings];  // tensions, and lengths when the spec has them
    if (part == 0) {
      f(in.theta.data(), r);
    } else if (part == 3) {
      f.Evaluate(in.theta.data(), r, j.data());
    } else {
      internal::TensionCost::EvaluateJet(f, in.theta.data(), r, j.data());
    }
    sink += r[0];
  }
  return sink;
}

// Part 1: the derivatives alone, from the solutions.
double DerivativesOfEverySample(const SampleRowsSetup& in) {
  std::vector<double> j(kNumCables * in.n());
  double sink = 0.0;
  for (int t = 0; t < in.count(); ++t) {
    internal::TensionGradient g;
    internal::ExactTensionGradient(in.params, in.data.samples[t].pose, in.solutions[t],
                                   in.statics.catenary.vertical_span_fraction,
                                   in.cm->frees_geometry(), &g);
    in.cm->ReadingJacobian(g, in.gain, 0, j.data());
    sink += j[0];
  }
  return sink;
}

// Part 5: as FoldedTensionCost::Fold without a loss (the recommended spec's): each
// reading's rows over its own columns first (GroupedRowFold), then into R.
double FoldByReading(const SampleRowsSetup& in) {
  const int n = in.n();
  internal::RowFold fold(n + 1);
  internal::GroupedRowFold grouped(internal::ReadingColumns(in.samples, nullptr), n + 1);
  double sink = 0.0;
  for (int t = 0; t < in.count(); ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      sink += in.rows(kNumCables * t + i, n) * in.rows(kNumCables * t + i, n);
      const Eigen::RowVectorXd row = in.rows.row(kNumCables * t + i);
      grouped.Add(i, row.data());
    }
  }
  grouped.FlushInto(&fold);
  return sink + fold.r()(0, 0);
}

// Part 2: as FoldedTensionCost::Fold with a loss: each sample's rows corrected for the
// loss and folded into R at full width (row_fold.h).
double FoldWithLoss(const SampleRowsSetup& in, const ceres::LossFunction& loss) {
  const int n = in.n();
  internal::RowFold fold(n + 1);
  std::vector<double> jt(kNumCables * n), block(kNumCables * (n + 1));
  double sink = 0.0;
  for (int t = 0; t < in.count(); ++t) {
    double r[kNumCables];
    for (int i = 0; i < kNumCables; ++i) {
      r[i] = in.rows(kNumCables * t + i, n);
      for (int k = 0; k < n; ++k) jt[i * n + k] = in.rows(kNumCables * t + i, k);
    }
    sink += internal::CorrectForLoss(&loss, r, jt.data(), n);
    for (int i = 0; i < kNumCables; ++i) {
      std::copy(&jt[i * n], &jt[i * n] + n, &block[i * (n + 1)]);
      block[i * (n + 1) + n] = r[i];
    }
    fold.Add(block.data(), kNumCables);
  }
  fold.Flush();
  return sink + fold.r()(0, 0);
}

void BM_SampleRows(benchmark::State& state) {
  SampleRowsSetup in;
  if (!in.Build()) {
    state.SkipWithError(in.error.c_str());
    return;
  }
  const ceres::HuberLoss huber(3.0);
  const int part = static_cast<int>(state.range(0));
  for (auto _ : state) {
    double sink = 0.0;
    if (part == 0 || part == 3 || part == 4) {
      sink = EvaluateEverySample(in, part);
    } else if (part == 1) {
      sink = DerivativesOfEverySample(in);
    } else if (part == 5) {
      sink = FoldByReading(in);
    } else {
      sink = FoldWithLoss(in, huber);
    }
    benchmark::DoNotOptimize(sink);
  }
  state.SetItemsProcessed(state.iterations() * in.count());
  const char* names[] = {"statics",
                         "derivatives",
                         "folding with a loss",
                         "statics and derivatives",
                         "statics and derivatives by Jets",
                         "folding by reading"};
  state.SetLabel(names[part]);
}

BENCHMARK(BM_SampleRows)->DenseRange(0, 5)->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_CalibrateEndToEnd)->Apply(EndToEndSizes);

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
