// Tracking over windows (track.h): the window flags; the chi-square helpers; the track
// equal to calibrate's joint fit with a session per day; a simulated season whose
// mass-centre step and re-zeroed sensor are found (and nothing else); another fold
// runner giving the same outputs; an update that folds only the new day; bad input.
#include "fastcal/track.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/internal/calibration_slow_error.h"
#include "fastcal/internal/chi_square.h"
#include "fastcal/simulation.h"
#include "fastcal/track_fold.h"
#include "fastcal/trajectory.h"
#include "random_cap_poses.h"
#include "temp_path.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

constexpr double kDayS = 86400.0;
constexpr double kStartS = 1714593600.0;  // 2024-05-01T20:00:00Z
// Samples 20 s apart: 300 a day are 100 minutes of telemetry.
constexpr double kIntervalS = 20.0;

// spec_track.yaml's parameters with the slow error stated (calibrate and the track then
// minimise the same function: the equality test) or estimated (the season).
std::string Spec(const std::string& slow_error) {
  return R"(format: fastcal-calibration-spec-1
noise:
  tension_sigma_kN: 0
  tension_sigma_percent: 3
  slow_error: )" +
         slow_error + R"(
gross_errors: {detect: true, threshold_sigmas: 5, max_fraction: 0.25}
parameters:
  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}
  linear_density_kg_per_m: {mode: per_cable, free: true, prior: {mean: 11.718, sigma: 0.18}}
  sensor_gain: {mode: per_cable, free: true, prior: {mean: 1, sigma: 0.01}}
  sensor_bias_kN: {mode: per_cable, free: true, prior: {mean: 0, sigma: 2}}
  tower_offset_m: {all: {free: false, prior: {mean: 0, sigma: 0.01}}}
sessions: {separate: [mass_centre_m]}
)";
}

// A season of `days` days of `per_day` samples each, `kIntervalS` apart from 20:00 UTC,
// with the slow sensor error of real telemetry and per-cable sensors and densities.
Dataset Season(int days, int per_day, std::uint64_t seed, SimulationOptions o, CableRobot* truth) {
  CableRobot model = CableRobot::NominalFast();
  model.mass_centre_cabin_m = {0.22, 0.11, 0.5};
  o.seed = seed;
  o.sample_interval_s = kIntervalS;
  o.start_time_s = kStartS;
  o.sessions = days;
  o.session_gap_s = kDayS - per_day * kIntervalS;
  o.tension_drift_percent = 1.0;
  o.tension_drift_time_s = 120.0;
  o.sensor_gain_spread_percent = 1.0;
  o.sensor_bias_spread_kn = 1.5;
  o.density_mismatch_percent = 1.0;
  Dataset data;
  std::string error;
  EXPECT_TRUE(
      Simulate(model, RandomCapPoses(days * per_day, seed + 1), o, &data, truth, nullptr, &error))
      << error;
  return data;
}

// A directory of this process's own (ctest runs each test in a process, in parallel).
std::string TempDir(const std::string& name) {
  const std::string dir = test::TempPath("track_test_" + name);
  fs::remove_all(dir);
  return dir;
}

std::string Write(const Dataset& data, const std::string& path) {
  std::string error;
  EXPECT_TRUE(WriteDataset(path, data, "", &error)) << error;
  return path;
}

CalibrationSpec LoadSpec(const std::string& text) {
  CalibrationSpec spec;
  std::string error;
  EXPECT_TRUE(ParseCalibrationSpecYaml(text, "spec.yaml", CableRobot::NominalFast(), &spec, &error))
      << error;
  return spec;
}

TrackResult Track(const CalibrationSpec& spec, const std::vector<std::string>& files,
                  const std::string& out, const TrackOptions& options = {}) {
  TrackResult result;
  std::string error;
  EXPECT_EQ(
      RunTrack(CableRobot::NominalFast(), spec, files, WindowSpec(), out, options, &result, &error),
      TrackStatus::kOk)
      << error;
  return result;
}

// A simulated season (Season) tracked with the slow error estimated, in a directory of
// its own named `name`.
TrackResult TrackSeason(int days, int per_day, std::uint64_t seed, const SimulationOptions& o,
                        const std::string& name) {
  CableRobot truth;
  const Dataset data = Season(days, per_day, seed, o, &truth);
  const std::string dir = TempDir(name);
  fs::create_directories(dir);
  return Track(LoadSpec(Spec("{sigma_percent: estimate, time_constant_s: estimate}")),
               {Write(data, dir + "/season.csv")}, dir + "/track");
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(TrackWindowTest, WindowFlags) {
  WindowSpec w;
  std::string error;
  ASSERT_TRUE(ParseWindowSpec("1d", &w, &error)) << error;
  EXPECT_EQ(w.duration_s, kDayS);
  ASSERT_TRUE(ParseWindowSpec("12h", &w, &error));
  EXPECT_EQ(w.duration_s, 43200.0);
  EXPECT_EQ(WindowSpecText(w), "12h");
  ASSERT_TRUE(ParseWindowSpec("90m", &w, &error));
  EXPECT_EQ(WindowSpecText(w), "90m");
  ASSERT_TRUE(ParseWindowSpec("file", &w, &error));
  EXPECT_EQ(w.kind, WindowSpec::Kind::kFile);
  for (const char* bad : {"", "d", "1.5h", "-1d", "0s", "3x", "1 d"}) {
    EXPECT_FALSE(ParseWindowSpec(bad, &w, &error)) << bad;
    EXPECT_NE(error.find("window"), std::string::npos) << error;
  }
}

// Issue 59: windows cut at a time of day on a clock ("@12:00+08:00": local noon in
// Beijing, 04:00 UTC), written back as they were given; bad origins refused by name.
TEST(TrackWindowTest, AnOriginMovesTheBoundaries) {
  WindowSpec w;
  std::string error;
  ASSERT_TRUE(ParseWindowSpec("1d@12:00+08:00", &w, &error)) << error;
  EXPECT_EQ(w.origin_s, 4.0 * 3600.0);
  EXPECT_EQ(w.label_offset_s, 8 * 3600);
  EXPECT_EQ(WindowSpecText(w), "1d@12:00+08:00");
  ASSERT_TRUE(ParseWindowSpec("12h@06:00-0500", &w, &error)) << error;
  EXPECT_EQ(w.origin_s, 11.0 * 3600.0 - 43200.0 * std::floor(11.0 / 12.0));
  EXPECT_EQ(WindowSpecText(w), "12h@06:00-05:00");
  ASSERT_TRUE(ParseWindowSpec("1d@00:00Z", &w, &error)) << error;
  EXPECT_EQ(w.origin_s, 0.0);
  EXPECT_EQ(WindowSpecText(w), "1d@00:00Z");
  for (const char* bad :
       {"1d@25:00", "1d@12:00+8", "1d@12:00+15:00", "1d@1200", "file@12:00", "1d@12:00UTC"}) {
    EXPECT_FALSE(ParseWindowSpec(bad, &w, &error)) << bad;
    EXPECT_NE(error.find(bad), std::string::npos) << error;
  }
  // A season cut there: nights of 9 h from 20:00 UTC cross 04:00 UTC, where the windows
  // now start (labelled by their dates in UTC+8); every sample lies in its window.
  ASSERT_TRUE(ParseWindowSpec("1d@12:00+08:00", &w, &error));
  CableRobot truth;
  const Dataset data = Season(2, 1620, 7, SimulationOptions(), &truth);
  const std::string dir = TempDir("origin");
  fs::create_directories(dir);
  TrackResult r;
  ASSERT_EQ(
      RunTrack(CableRobot::NominalFast(),
               LoadSpec(Spec("{sigma_percent: estimate, time_constant_s: estimate}")),
               {Write(data, dir + "/season.csv")}, w, dir + "/track", TrackOptions(), &r, &error),
      TrackStatus::kOk)
      << error;
  ASSERT_EQ(r.windows.size(), 3u);  // 20:00-04:00, 04:00-05:00 + 20:00-04:00, 04:00-05:00
  for (const TrackWindow& window : r.windows) {
    EXPECT_EQ(std::fmod(window.start_s, kDayS), 4.0 * 3600.0) << window.label;
    EXPECT_GE(window.first_time_s, window.start_s) << window.label;
    EXPECT_LT(window.last_time_s, window.end_s) << window.label;
    EXPECT_EQ(window.label, FormatUnixTime(window.start_s, 8 * 3600).substr(0, 10));
  }
}

TEST(TrackChiSquareTest, TailAndQuantileAgainstTables) {
  // Tabulated 5% and 1% points (Abramowitz and Stegun, table 26.8).
  EXPECT_NEAR(internal::ChiSquareTailProbability(3.841459, 1), 0.05, 1e-6);
  EXPECT_NEAR(internal::ChiSquareTailProbability(5.991465, 2), 0.05, 1e-6);
  EXPECT_NEAR(internal::ChiSquareTailProbability(7.814728, 3), 0.05, 1e-6);
  EXPECT_NEAR(internal::ChiSquareTailProbability(52.19139, 31), 0.01, 1e-6);
  EXPECT_NEAR(internal::ChiSquareQuantile(0.01, 3), 11.34487, 1e-4);
  EXPECT_NEAR(internal::ChiSquareQuantile(0.01, 30), 50.89218, 1e-4);
  EXPECT_EQ(internal::ChiSquareTailProbability(0.0, 4), 1.0);
}

// The track is the joint fit of windows: with the slow error stated (one objective for
// both), its estimates are calibrate's joint fit's with a session per day.
TEST(TrackTest, EqualsTheJointFitWithASessionPerDay) {
  CableRobot truth;
  const Dataset data = Season(3, 250, 11, {}, &truth);
  const CalibrationSpec spec = LoadSpec(Spec("{sigma_percent: 1, time_constant_s: 120}"));
  CalibrationResult joint;
  std::string error;
  CalibrationOptions copts;
  copts.evaluate = false;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, copts, &joint, &error),
            CalibrationStatus::kOk)
      << error;
  const std::string dir = TempDir("equal");
  fs::create_directories(dir);
  const TrackResult track = Track(spec, {Write(data, dir + "/season.csv")}, dir + "/track");
  ASSERT_TRUE(track.converged);
  ASSERT_EQ(track.windows.size(), 3u);
  const char* axes[] = {"x", "y", "z"};
  for (int w = 0; w < 3; ++w) {
    for (int a = 0; a < 3; ++a) {
      const std::string name =
          std::string("mass_centre_m.") + axes[a] + "@" + std::to_string(w + 1);
      const ParameterEstimate* p = nullptr;
      for (const ParameterEstimate& e : joint.parameters) p = e.name == name ? &e : p;
      ASSERT_NE(p, nullptr) << name;
      const TrackEstimate& t = track.windows[w].estimates[a];
      // Both stop within ~1% of a sigma of the common minimum.
      EXPECT_NEAR(t.value, p->estimate, 0.05 * p->sigma) << name;
      EXPECT_NEAR(t.sigma_formal, p->sigma, 0.01 * p->sigma) << name;
    }
  }
  for (const TrackShared& s : track.shared) {
    for (const ParameterEstimate& e : joint.parameters) {
      if (e.name != s.name) continue;
      EXPECT_NEAR(s.estimate.value, e.estimate, 0.05 * e.sigma) << s.name;
      EXPECT_NEAR(s.estimate.sigma_formal, e.sigma, 0.01 * e.sigma) << s.name;
    }
  }
}

// Two tracks of the same data that stop at the same minimum by different paths: every
// estimate within the step tolerance (0.05 sigma) of the other's, every sigma (each at a
// point within it of the solution) the same to well under a percent.
void ExpectSameTrack(const TrackResult& a, const TrackResult& b) {
  constexpr double kStepToleranceSigmas = 0.05;
  constexpr double kSameSigmaRelative = 1e-3;
  const auto same = [&](const TrackEstimate& x, const TrackEstimate& y, const std::string& name) {
    EXPECT_NEAR(y.value, x.value, kStepToleranceSigmas * x.sigma_total) << name;
    EXPECT_NEAR(y.sigma_total, x.sigma_total, kSameSigmaRelative * x.sigma_total) << name;
  };
  ASSERT_EQ(b.windows.size(), a.windows.size());
  for (size_t w = 0; w < a.windows.size(); ++w) {
    ASSERT_EQ(b.windows[w].estimates.size(), a.windows[w].estimates.size());
    for (size_t k = 0; k < a.windows[w].estimates.size(); ++k) {
      same(a.windows[w].estimates[k], b.windows[w].estimates[k],
           a.windows[w].label + " " + std::to_string(k));
    }
  }
  ASSERT_EQ(b.shared.size(), a.shared.size());
  for (size_t e = 0; e < a.shared.size(); ++e) {
    same(a.shared[e].estimate, b.shared[e].estimate, a.shared[e].name);
  }
}

// The consider parameters' columns ride on the fold that may be the last (issue 41: a
// separate fold of every window at the solution was a fifth of a track's time); where
// the last fold has none (a track started at its own solution converges at its first
// fold), the windows are folded at the solution as before, and the uncertainties are the
// same either way.
TEST(TrackTest, ConsiderColumnsComeWithTheLastFoldOrAreFoldedAtTheSolution) {
  CableRobot truth;
  const Dataset data = Season(1, 400, 13, {}, &truth);
  const CalibrationSpec spec = LoadSpec(Spec("{sigma_percent: 1, time_constant_s: 120}"));
  const std::string dir = TempDir("consider");
  fs::create_directories(dir);
  const std::string csv = Write(data, dir + "/day.csv");
  // Per round of folds: whether its tasks carry the consider columns.
  std::vector<bool> rounds;
  TrackOptions options;
  options.runner = [&rounds](const std::vector<std::string>& tasks, std::vector<std::string>* folds,
                             std::string* error) {
    bool consider = false;
    for (const std::string& t : tasks) {
      FoldTask task;
      if (!ParseFoldTask(t, &task, error)) return false;
      for (FoldRole r : task.roles) consider = consider || r == FoldRole::kConsider;
    }
    rounds.push_back(consider);
    folds->clear();
    for (const std::string& t : tasks) {
      folds->emplace_back();
      if (!RunFoldTask(t, &folds->back(), error)) return false;
    }
    return true;
  };
  const TrackResult first = Track(spec, {csv}, dir + "/first", options);
  ASSERT_TRUE(first.converged);
  ASSERT_GE(rounds.size(), 2u);
  EXPECT_FALSE(rounds.front()) << "the first fold's step is not the last";
  EXPECT_TRUE(rounds.back());
  EXPECT_EQ(static_cast<int>(rounds.size()), first.iterations) << "no fold of their own";

  // Again from the model the first track calibrated.
  CableRobot solved;
  std::string error;
  ASSERT_TRUE(LoadCableRobot(dir + "/first/model_calibrated@2024-05-01.yaml", &solved, &error))
      << error;
  rounds.clear();
  TrackResult again;
  ASSERT_EQ(RunTrack(solved, spec, {csv}, WindowSpec(), dir + "/again", options, &again, &error),
            TrackStatus::kOk)
      << error;
  ASSERT_TRUE(again.converged);
  ASSERT_EQ(again.iterations, 1);
  ASSERT_EQ(rounds.size(), 2u);
  EXPECT_FALSE(rounds[0]);
  EXPECT_TRUE(rounds[1]) << "the consider columns folded at the solution";
  ExpectSameTrack(first, again);
}

// A new track's first folds read one sample in k of a large window (issue 41); the folds
// after them read them all, and the track ends where one of every sample throughout does.
TEST(TrackTest, AFirstStepThroughASubsampleEndsWhereTheWholeDoes) {
  CableRobot truth;
  const Dataset data = Season(1, 2000, 17, {}, &truth);  // one "day" of samples
  const CalibrationSpec spec = LoadSpec(Spec("{sigma_percent: 1, time_constant_s: 120}"));
  const std::string dir = TempDir("first_step");
  fs::create_directories(dir);
  const std::string csv = Write(data, dir + "/day.csv");
  std::vector<int> strides;        // per round of folds, the largest
  std::vector<int> residual_runs;  // per round of folds, the largest run of residuals
  std::vector<int> smallest;       // per round of folds, the smallest stride
  TrackOptions options;
  options.runner = [&strides, &residual_runs, &smallest](const std::vector<std::string>& tasks,
                                                         std::vector<std::string>* folds,
                                                         std::string* error) {
    int largest = 0, run = 0, least = std::numeric_limits<int>::max();
    folds->clear();
    for (const std::string& t : tasks) {
      FoldTask task;
      if (!ParseFoldTask(t, &task, error)) return false;
      largest = std::max(largest, task.stride);
      least = std::min(least, task.stride);
      run = std::max(run, task.residual_samples);
      folds->emplace_back();
      if (!RunFoldTask(t, &folds->back(), error)) return false;
    }
    strides.push_back(largest);
    smallest.push_back(least);
    residual_runs.push_back(run);
    return true;
  };
  // No step taken back: the subsample's chi-square is not compared with the whole's.
  std::string halved;
  options.progress = [&halved](const std::string& line) {
    if (line.find("halved") != std::string::npos) halved += line + "\n";
  };
  // 2000 samples from 20:00 UTC, 20 s apart: 720 on the first day, 1280 on the second.
  options.first_fold_samples = 300;
  const TrackResult first_step = Track(spec, {csv}, dir + "/first_step", options);
  ASSERT_TRUE(first_step.converged);
  ASSERT_EQ(first_step.windows.size(), 2u);
  EXPECT_EQ(first_step.windows[1].samples, 1280);
  ASSERT_GE(strides.size(), 2u);
  // The rounds through the subsample first (1280 / 300 = 4, rounded down), at most 4 of
  // them, each with its run of residuals, then every sample.
  const size_t subsampled = static_cast<size_t>(std::count(strides.begin(), strides.end(), 4));
  EXPECT_GE(subsampled, 1u);
  EXPECT_LE(subsampled, 4u);
  for (size_t r = 0; r < strides.size(); ++r) {
    EXPECT_EQ(strides[r], r < subsampled ? 4 : 1) << r;
    EXPECT_GT(residual_runs[r], 0) << r;
  }
  EXPECT_EQ(halved, "");

  // The slow error estimated: from a subsample's round after the first (whose point is
  // the initial model), over the residual run's samples, all of them; the first fold of
  // every sample estimates it again. The track ends where the whole's does, with the
  // slow error the whole's within the change that lets a process stand.
  {
    const CalibrationSpec estimated =
        LoadSpec(Spec("{sigma_percent: estimate, time_constant_s: estimate}"));
    strides.clear();
    residual_runs.clear();
    // Each round's progress: "s" a fold of the subsample, "f" of every sample, "e" an
    // estimate of the slow error.
    std::string rounds_seen;
    TrackOptions seen = options;
    seen.progress = [&rounds_seen](const std::string& line) {
      if (line.find("folding") != std::string::npos) {
        rounds_seen += line.find("one sample in") != std::string::npos ? "s" : "f";
      }
      if (line.find("slow sensor error") != std::string::npos) rounds_seen += "e";
    };
    const TrackResult sub = Track(estimated, {csv}, dir + "/estimated_sub", seen);
    // With the slow error estimated, the very first round is coarser and has no run of
    // residuals (a quarter of 300, raised to min_window_samples = 100: 1280 / 100 = 12):
    // the estimate starts from the second, which the first is never the last before.
    ASSERT_GE(strides.size(), 3u);
    EXPECT_EQ(strides[0], 12);
    EXPECT_EQ(residual_runs[0], 0);
    const size_t rounds = static_cast<size_t>(std::count(strides.begin(), strides.end(), 4));
    EXPECT_GE(rounds, 1u);
    EXPECT_EQ(strides[1], 4);
    EXPECT_GT(residual_runs[1], 0);
    // The subsample rounds leave the slow error standing: the first fold of every sample
    // estimates it again (and the track reports that estimate), the second converges
    // with the consider columns. Before, a subsample's run of residuals spanning k times
    // the time moved the estimate, and a third fold of every sample followed.
    const size_t full = rounds_seen.find('f');
    ASSERT_NE(full, std::string::npos) << rounds_seen;
    EXPECT_EQ(rounds_seen.substr(full, 3), "fef") << rounds_seen;
    EXPECT_EQ(rounds_seen.find('f', full + 3), std::string::npos) << rounds_seen;
    TrackOptions o = options;
    o.first_fold_samples = 0;
    const TrackResult all = Track(estimated, {csv}, dir + "/estimated_all", o);
    ASSERT_TRUE(sub.converged && all.converged);
    const SlowErrorProcess& p = sub.slow_error.process;
    const SlowErrorProcess& q = all.slow_error.process;
    EXPECT_NEAR(p.sigma_percent, q.sigma_percent, internal::kSlowErrorSettled * q.sigma_percent);
    EXPECT_NEAR(p.time_constant_s, q.time_constant_s,
                internal::kSlowErrorSettled * q.time_constant_s);
    ExpectSameTrack(all, sub);

    // The coarser round strides only the windows the later rounds stride (720 / 400 = 1:
    // every sample of the first day; 1280 / 400 = 3, then 4 x 3 = 12 in the first round),
    // and is not taken where max_iterations leaves no room for a round after it.
    TrackOptions wider = options;
    wider.first_fold_samples = 400;
    strides.clear();
    smallest.clear();
    Track(estimated, {csv}, dir + "/estimated_wider", wider);
    ASSERT_GE(strides.size(), 2u);
    EXPECT_EQ(strides[0], 12);
    EXPECT_EQ(smallest[0], 1);
    EXPECT_EQ(strides[1], 3);
    wider.max_iterations = 3;
    strides.clear();
    Track(estimated, {csv}, dir + "/estimated_three", wider);
    ASSERT_GE(strides.size(), 1u);
    EXPECT_EQ(strides[0], 3);
  }

  strides.clear();
  options.first_fold_samples = 0;
  const TrackResult whole = Track(spec, {csv}, dir + "/whole", options);
  ASSERT_TRUE(whole.converged);
  for (int s : strides) EXPECT_EQ(s, 1);
  ExpectSameTrack(whole, first_step);

  // From the solution: the whole's chi-square after the first step is about k times the
  // subsample's, which is no reason to take that step back.
  CableRobot solved;
  std::string error;
  ASSERT_TRUE(LoadCableRobot(dir + "/whole/model_calibrated@2024-05-02.yaml", &solved, &error))
      << error;
  options.first_fold_samples = 300;
  TrackResult again;
  ASSERT_EQ(RunTrack(solved, spec, {csv}, WindowSpec(), dir + "/again", options, &again, &error),
            TrackStatus::kOk)
      << error;
  EXPECT_TRUE(again.converged);
  EXPECT_EQ(halved, "");

  // A track of one iteration takes no first step through a subsample: its folds are the
  // track's (and its saved state's).
  strides.clear();
  options.max_iterations = 1;
  Track(spec, {csv}, dir + "/one", options);
  ASSERT_EQ(strides.size(), 2u);  // the iteration, then the consider columns
  EXPECT_EQ(strides[0], 1);
  options.max_iterations = TrackOptions().max_iterations;

  // A fold that fails after the first step (as where that step left the model's range) is
  // halved back towards the initial point, not the end of the track.
  halved.clear();
  int round = 0;
  TrackOptions failing = options;
  failing.runner = [&round, &options](const std::vector<std::string>& tasks,
                                      std::vector<std::string>* folds, std::string* error) {
    if (++round == 2) {
      *error = "day.csv:7: the model at the track's point cannot solve this pose";
      return false;
    }
    return options.runner(tasks, folds, error);
  };
  TrackResult recovered;
  ASSERT_EQ(RunTrack(CableRobot::NominalFast(), spec, {csv}, WindowSpec(), dir + "/recovered",
                     failing, &recovered, &error),
            TrackStatus::kOk)
      << error;
  EXPECT_NE(halved.find("step halved"), std::string::npos);
  EXPECT_TRUE(recovered.converged);
  ExpectSameTrack(whole, recovered);

  // The same failure on the last iteration, without consider columns (no fold at the
  // solution follows): the subsample's folds are folded again in full, never left as the
  // track's, whose sigmas would then be sqrt(k) times too large.
  std::string no_consider = Spec("{sigma_percent: 1, time_constant_s: 120}");
  no_consider.erase(no_consider.find("  tower_offset_m"),
                    no_consider.find('\n', no_consider.find("  tower_offset_m")) + 1 -
                        no_consider.find("  tower_offset_m"));
  const CalibrationSpec plain = LoadSpec(no_consider);
  strides.clear();
  round = 0;
  failing.max_iterations = 2;
  TrackResult last;
  ASSERT_EQ(RunTrack(CableRobot::NominalFast(), plain, {csv}, WindowSpec(), dir + "/last", failing,
                     &last, &error),
            TrackStatus::kOk)
      << error;
  EXPECT_FALSE(last.converged);
  EXPECT_EQ(strides, (std::vector<int>{4, 1}));  // the first step, then the whole again
  const TrackResult plain_whole = [&] {
    TrackOptions o = options;
    o.first_fold_samples = 0;
    return Track(plain, {csv}, dir + "/plain_whole", o);
  }();
  constexpr double kSigmaAtAnotherPointRelative = 0.25;  // a strided fold's: 2x at k = 4
  for (size_t w = 0; w < 2; ++w) {
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(last.windows[w].estimates[k].sigma_formal,
                  plain_whole.windows[w].estimates[k].sigma_formal,
                  kSigmaAtAnotherPointRelative * plain_whole.windows[w].estimates[k].sigma_formal)
          << w << " " << k;
    }
  }

  options.first_fold_samples = 99;  // below min_window_samples: a window of one sample
  TrackResult bad;
  EXPECT_EQ(RunTrack(CableRobot::NominalFast(), spec, {csv}, WindowSpec(), dir + "/bad", options,
                     &bad, &error),
            TrackStatus::kInvalidInput);
  EXPECT_NE(error.find("first_fold_samples"), std::string::npos) << error;
}

class SeasonTest : public ::testing::Test {
 protected:
  static constexpr int kDays = 7;
  static constexpr int kPerDay = 300;
  static constexpr int kStepDay = 3;  // the mass centre moves before day 3's telemetry
  static constexpr int kZeroDay = 5;  // cable 4 re-zeroed before day 5's
  static void SetUpTestSuite() {
    SimulationOptions o;
    o.mass_centre_steps.push_back({kStartS + kStepDay * kDayS - 3600.0, {0.04, -0.02, 0.0}});
    o.sensor_bias_steps.push_back({kStartS + kZeroDay * kDayS - 3600.0, 3, 4000.0});
    data_ = new Dataset(Season(kDays, kPerDay, 21, o, &truth_));
    dir_ = new std::string(TempDir("season"));
    fs::create_directories(*dir_);
    path_ = new std::string(Write(*data_, *dir_ + "/season.csv"));
    spec_ =
        new CalibrationSpec(LoadSpec(Spec("{sigma_percent: estimate, time_constant_s: estimate}")));
    result_ = new TrackResult(Track(*spec_, {*path_}, *dir_ + "/track"));
  }
  static void TearDownTestSuite() {
    delete data_;
    delete dir_;
    delete path_;
    delete spec_;
    delete result_;
  }
  static Eigen::Vector3d TruthOn(int day) {
    Eigen::Vector3d m(0.22, 0.11, 0.5);
    if (day >= kStepDay) m += Eigen::Vector3d(0.04, -0.02, 0.0);
    return m;
  }
  static void WindowEstimatesCoverTheTruth();
  static void OutputsAreWritten();
  static CableRobot truth_;
  static Dataset* data_;
  static std::string *dir_, *path_;
  static CalibrationSpec* spec_;
  static TrackResult* result_;
};
CableRobot SeasonTest::truth_;
Dataset* SeasonTest::data_ = nullptr;
std::string* SeasonTest::dir_ = nullptr;
std::string* SeasonTest::path_ = nullptr;
CalibrationSpec* SeasonTest::spec_ = nullptr;
TrackResult* SeasonTest::result_ = nullptr;

// One test (each ctest process tracks the season again): the events, the coverage, the
// files.
TEST_F(SeasonTest, FindsTheStepAndTheReZeroedSensorAndNothingElse) {
  const TrackResult& r = *result_;
  ASSERT_EQ(r.windows.size(), static_cast<size_t>(kDays));
  EXPECT_TRUE(r.converged);
  ASSERT_EQ(r.events.size(), 2u);
  const TrackEvent& step = r.events[0];
  EXPECT_EQ(step.kind, "parameter");
  EXPECT_EQ(r.windows[step.window].label, "2024-05-04");  // day 3 counted from 0
  const double truth[] = {0.04, -0.02, 0.0};
  ASSERT_EQ(step.parameters.size(), 3u);
  for (int a = 0; a < 3; ++a) {
    // Its size within 3 of its sigma_total.
    EXPECT_NEAR(step.parameters[a].shift, truth[a], 3.0 * step.parameters[a].sigma_total)
        << step.parameters[a].name;
  }
  EXPECT_FALSE(step.within_window);  // between two days' telemetry: the window's resolution
  const TrackEvent& zero = r.events[1];
  EXPECT_EQ(zero.kind, "sensor");
  EXPECT_EQ(r.windows[zero.window].label, "2024-05-06");
  ASSERT_EQ(zero.cables, std::vector<int>{4});
  EXPECT_NEAR(zero.parameters[0].shift, 4.0, 3.0 * zero.parameters[0].sigma_total);
  EXPECT_LT(zero.p_value, 0.01);
  // The event's time: the first sample of its window.
  EXPECT_EQ(zero.time_s, kStartS + kZeroDay * kDayS);
  WindowEstimatesCoverTheTruth();
  OutputsAreWritten();
}

void SeasonTest::WindowEstimatesCoverTheTruth() {
  int within_two = 0, total = 0;
  for (int day = 0; day < kDays; ++day) {
    const Eigen::Vector3d t = TruthOn(day);
    for (int a = 0; a < 3; ++a) {
      const TrackEstimate& e = result_->windows[day].estimates[a];
      EXPECT_GT(e.sigma_total, 0.0);
      EXPECT_LT(std::abs(e.value - t[a]), 4.0 * e.sigma_total) << "day " << day << " axis " << a;
      within_two += std::abs(e.value - t[a]) < 2.0 * e.sigma_total;
      ++total;
    }
  }
  // 95% expected; the windows share b, so their errors are correlated: a loose floor.
  EXPECT_GE(within_two, 0.8 * total);
}

void SeasonTest::OutputsAreWritten() {
  const std::string out = *dir_ + "/track";
  const std::string csv = ReadText(out + "/track.csv");
  EXPECT_EQ(
      csv.rfind("window_start,window_end,samples,mass_centre_m.x,mass_centre_m.x_sigma_total,", 0),
      0u)
      << csv.substr(0, 200);
  EXPECT_NE(csv.find("\n2024-05-01T00:00:00Z,2024-05-02T00:00:00Z,300,"), std::string::npos);
  const std::string events = ReadText(out + "/events.json");
  EXPECT_NE(events.find("\"time\": \"2024-05-04T20:00:00Z\""), std::string::npos) << events;
  EXPECT_NE(events.find("\"kind\": \"sensor\""), std::string::npos);
  EXPECT_NE(events.find("\"cables\": [4]"), std::string::npos) << events;
  EXPECT_TRUE(fs::exists(out + "/model_calibrated@2024-05-06_to_2024-05-07.yaml"));
  EXPECT_TRUE(fs::exists(out + "/model_calibrated@2024-05-07.yaml"));
  EXPECT_TRUE(fs::exists(out + "/model_calibrated@2024-05-01_to_2024-05-03.yaml"));
  EXPECT_NE(ReadText(out + "/track.html").find("<svg"), std::string::npos);
  CableRobot latest;
  std::string error;
  ASSERT_TRUE(LoadCableRobot(out + "/model_calibrated@2024-05-07.yaml", &latest, &error)) << error;
  EXPECT_NEAR(latest.mass_centre_cabin_m.x(), result_->windows.back().estimates[0].value, 1e-9);
}

TEST_F(SeasonTest, AnotherRunnerGivesTheSameTrack) {
  // A runner that folds the tasks one after the other in this thread (as a Dask client
  // would on its workers) gives the same bytes.
  TrackOptions options;
  options.runner = [](const std::vector<std::string>& tasks, std::vector<std::string>* folds,
                      std::string* error) {
    folds->clear();
    for (const std::string& t : tasks) {
      folds->emplace_back();
      if (!RunFoldTask(t, &folds->back(), error)) return false;
    }
    return true;
  };
  const std::string out = *dir_ + "/serial";
  Track(*spec_, {*path_}, out, options);
  EXPECT_EQ(ReadText(out + "/track.csv"), ReadText(*dir_ + "/track/track.csv"));
  EXPECT_EQ(ReadText(out + "/events.json"), ReadText(*dir_ + "/track/events.json"));
}

TEST_F(SeasonTest, UpdateFoldsOnlyTheNewDay) {
  // The first six days, then the seventh added.
  Dataset first = *data_, last = *data_;
  first.samples.clear();
  last.samples.clear();
  for (const Sample& s : data_->samples) {
    (s.time_s < kStartS + (kDays - 1) * kDayS - 3600.0 ? first : last).samples.push_back(s);
  }
  const std::string dir = *dir_ + "/update";
  fs::create_directories(dir);
  const std::string a = Write(first, dir + "/a.csv"), b = Write(last, dir + "/b.csv");
  const TrackResult before = Track(*spec_, {a}, dir + "/track");
  EXPECT_EQ(before.windows.size(), static_cast<size_t>(kDays - 1));
  const TrackResult after = Track(*spec_, {a, b}, dir + "/track");
  EXPECT_TRUE(after.updated);
  ASSERT_EQ(after.windows.size(), static_cast<size_t>(kDays));
  EXPECT_GT(after.folds, 0);
  for (int w = 0; w < kDays - 1; ++w) EXPECT_FALSE(after.windows[w].folded) << w;
  EXPECT_TRUE(after.windows.back().folded);
  // The same estimates as the track of all days at once, to a small part of their sigma
  // (the old folds are quadratic models at their own points; the slow error is kept).
  for (int w = 0; w < kDays; ++w) {
    for (int k = 0; k < 3; ++k) {
      const TrackEstimate& u = after.windows[w].estimates[k];
      const TrackEstimate& f = result_->windows[w].estimates[k];
      EXPECT_NEAR(u.value, f.value, 0.2 * f.sigma_total) << "window " << w << " axis " << k;
    }
  }
  ASSERT_EQ(after.events.size(), 2u);
  // The slow error an update keeps is said to be the track's, not "likelihood ratio
  // against white noise 0" (issue 59).
  EXPECT_FALSE(before.slow_error.kept_from_track);
  EXPECT_TRUE(after.slow_error.kept_from_track);
  const std::string said = DescribeSlowError(after.slow_error);
  EXPECT_NE(said.find("kept by this update"), std::string::npos) << said;
  EXPECT_EQ(said.find("likelihood ratio"), std::string::npos) << said;
  // Nothing new: nothing folded.
  const TrackResult again = Track(*spec_, {a, b}, dir + "/track");
  EXPECT_EQ(again.folds, 0);
}

// A run told to stop (TrackOptions::should_stop: a Python caller's Ctrl-C, issue 37) at
// any point before its outputs returns kCancelled and leaves an existing track exactly
// as it was; the next run updates it as if nothing had happened.
TEST_F(SeasonTest, ACancelledUpdateLeavesTheTrackAsItWas) {
  Dataset first = *data_, last = *data_;
  first.samples.clear();
  last.samples.clear();
  for (const Sample& s : data_->samples) {
    (s.time_s < kStartS + (kDays - 1) * kDayS - 3600.0 ? first : last).samples.push_back(s);
  }
  const std::string dir = *dir_ + "/cancel";
  fs::create_directories(dir);
  const std::string a = Write(first, dir + "/a.csv"), b = Write(last, dir + "/b.csv");
  const std::string out = dir + "/track";
  Track(*spec_, {a}, out);
  // Every file of the track, with its bytes.
  auto snapshot = [&] {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      if (!e.is_regular_file()) continue;
      std::ifstream in(e.path(), std::ios::binary);
      std::ostringstream bytes;
      bytes << in.rdbuf();
      files[e.path().string()] = bytes.str();
    }
    return files;
  };
  const auto before = snapshot();
  // Stops at the 1st ask (before any stage), the 4th (reading the new file), the 8th
  // (inside the iterations).
  for (int allowed : {0, 3, 7}) {
    int asked = 0;
    TrackOptions options;
    options.should_stop = [&] { return ++asked > allowed; };
    TrackResult result;
    std::string error;
    EXPECT_EQ(RunTrack(CableRobot::NominalFast(), *spec_, {a, b}, WindowSpec(), out, options,
                       &result, &error),
              TrackStatus::kCancelled)
        << "after " << allowed << " asks: " << error;
    EXPECT_NE(error.find("stopped on request"), std::string::npos) << error;
    EXPECT_EQ(asked, allowed + 1);  // not asked again once it said stop
    EXPECT_TRUE(snapshot() == before) << "after " << allowed << " asks the track changed";
  }
  const TrackResult after = Track(*spec_, {a, b}, out);
  EXPECT_TRUE(after.updated);
  EXPECT_EQ(after.windows.size(), static_cast<size_t>(kDays));
}

// The per-window estimates cover the truth at their stated rate: over seasons drawn with
// the cables' and sensors' spreads the spec's priors state (narrower truths make the
// shared part, common to every window, conservative), 68% within one sigma_total and 95%
// within two. A season's windows share the error of the shared parameters, so the
// seasons, not the windows, are the independent draws: the bounds allow for that (48
// seasons gave 64% and 96%, rms z 1.05; these 12: 78% and 100%, rms z 0.79).
TEST(TrackTest, WindowEstimatesCoverTheTruthAtTheirStatedRate) {
  constexpr int kSeasons = 12, kDays = 3, kPerDay = 250;
  const CalibrationSpec spec =
      LoadSpec(Spec("{sigma_percent: estimate, time_constant_s: estimate}"));
  const std::string dir = TempDir("coverage");
  fs::create_directories(dir);
  int within_one = 0, within_two = 0, total = 0, events = 0;
  double sum_z2 = 0.0;
  for (int k = 0; k < kSeasons; ++k) {
    SimulationOptions o;
    CableRobot truth;
    Dataset data;
    // Season()'s telemetry with the priors' spreads: density 0.18 kg/m of 11.718, gain 1%, bias 2
    // kN.
    o.seed = 100 + 7 * k;
    o.sample_interval_s = kIntervalS;
    o.start_time_s = kStartS;
    o.sessions = kDays;
    o.session_gap_s = kDayS - kPerDay * kIntervalS;
    o.tension_drift_percent = 1.0;
    o.tension_drift_time_s = 120.0;
    o.sensor_gain_spread_percent = 1.0;
    o.sensor_bias_spread_kn = 2.0;
    o.density_mismatch_percent = 100.0 * 0.18 / 11.718;
    CableRobot model = CableRobot::NominalFast();
    model.mass_centre_cabin_m = {0.22, 0.11, 0.5};
    std::string error;
    ASSERT_TRUE(Simulate(model, RandomCapPoses(kDays * kPerDay, o.seed + 1), o, &data, &truth,
                         nullptr, &error))
        << error;
    const std::string out = dir + "/" + std::to_string(k);
    const TrackResult r = Track(spec, {Write(data, out + ".csv")}, out);
    ASSERT_EQ(r.windows.size(), static_cast<size_t>(kDays));
    events += static_cast<int>(r.events.size());
    for (const TrackWindow& w : r.windows) {
      for (int a = 0; a < 3; ++a) {
        const double z =
            (w.estimates[a].value - model.mass_centre_cabin_m[a]) / w.estimates[a].sigma_total;
        within_one += std::abs(z) < 1.0;
        within_two += std::abs(z) < 2.0;
        sum_z2 += z * z;
        ++total;
      }
    }
  }
  const double one = static_cast<double>(within_one) / total;
  const double two = static_cast<double>(within_two) / total;
  const double rms = std::sqrt(sum_z2 / total);
  std::printf("coverage: %.2f within 1 sigma_total, %.2f within 2, rms z %.2f (%d estimates)\n",
              one, two, rms, total);
  EXPECT_GT(one, 0.45);
  EXPECT_LT(one, 0.9);
  EXPECT_GT(two, 0.85);
  EXPECT_GT(rms, 0.6);
  EXPECT_LT(rms, 1.4);
  // No step was drawn: no event (each kind at 1% over a season).
  EXPECT_EQ(events, 0);
}

// A step inside a day's telemetry shows as a change on both sides of that day: one event,
// timed at its block within the day.
TEST(TrackTest, StepInsideADayIsOneEventAtItsBlock) {
  constexpr int kDays = 5, kPerDay = 300;
  const double step_s = kStartS + 2 * kDayS + 0.5 * kPerDay * kIntervalS;  // mid-day 3
  SimulationOptions o;
  o.mass_centre_steps.push_back({step_s, {0.05, 0.0, 0.0}});
  const TrackResult r = TrackSeason(kDays, kPerDay, 31, o, "inside");
  ASSERT_EQ(r.events.size(), 1u);
  const TrackEvent& e = r.events[0];
  EXPECT_TRUE(e.within_window);
  EXPECT_EQ(r.windows[e.window].label, "2024-05-03");
  EXPECT_EQ(r.windows[e.previous_window].label, "2024-05-02");
  // Within two blocks (a block: about 10 samples, 200 s) of the truth.
  EXPECT_NEAR(e.time_s, step_s, 2 * kPerDay / 32.0 * kIntervalS + kIntervalS);
  EXPECT_NEAR(e.parameters[0].shift, 0.05, 3.0 * e.parameters[0].sigma_total);
}

// Issue 59: a window with a move inside its telemetry is reported in its two parts, before
// and after, in track.csv and as two models, not as one average (a mass centre the cabin
// never had); the current model is the part after. The move: +5 cm in x mid-day 3.
TEST(TrackTest, AWindowWithAMoveInsideIsReportedInItsTwoParts) {
  constexpr int kDays = 5, kPerDay = 300;
  constexpr double kMoveM = 0.05;
  const double step_s = kStartS + 2 * kDayS + 0.5 * kPerDay * kIntervalS;  // mid-day 3
  SimulationOptions o;
  o.mass_centre_steps.push_back({step_s, {kMoveM, 0.0, 0.0}});
  const TrackResult r = TrackSeason(kDays, kPerDay, 31, o, "inside_parts");
  ASSERT_EQ(r.events.size(), 1u);
  const TrackEvent& e = r.events[0];
  ASSERT_TRUE(e.within_window);
  ASSERT_EQ(e.parts.size(), 2u);
  EXPECT_EQ(e.parts[0].samples + e.parts[1].samples, r.windows[e.window].samples);
  EXPECT_EQ(e.parts[0].end_s, e.time_s);
  EXPECT_EQ(e.parts[1].start_s, e.time_s);
  // Each part holds its own level: x before within 3 sigma_total of the days before, after
  // of the days after; the window's own estimate lies between them.
  const double x0 = r.windows[1].estimates[0].value, x1 = r.windows[3].estimates[0].value;
  const TrackEstimate& before = e.parts[0].estimates[0];
  const TrackEstimate& after = e.parts[1].estimates[0];
  EXPECT_NEAR(before.value, x0, 3.0 * before.sigma_total);
  EXPECT_NEAR(after.value, x1, 3.0 * after.sigma_total);
  EXPECT_NEAR(after.value - before.value, kMoveM, 3.0 * e.parameters[0].sigma_total);
  const double mixed = r.windows[e.window].estimates[0].value;
  EXPECT_GT(mixed, before.value);
  EXPECT_LT(mixed, after.value);
  // track.csv: the day's two rows, labelled; two model files, the current one the after's.
  const std::string dir = test::TempPath("track_test_inside_parts") + "/track";  // TempDir clears
  const std::string csv = ReadText(dir + "/track.csv");
  EXPECT_NE(csv.find(",2024-05-03_before\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",2024-05-03_after\n"), std::string::npos) << csv;
  EXPECT_EQ(csv.find(",2024-05-03\n"), std::string::npos) << csv;
  CableRobot part_model;
  std::string error;
  ASSERT_TRUE(LoadCableRobot(dir + "/model_calibrated@2024-05-03_after.yaml", &part_model, &error))
      << error;
  EXPECT_NEAR(part_model.mass_centre_cabin_m.x(), after.value, 1e-9);
  EXPECT_TRUE(fs::exists(dir + "/model_calibrated@2024-05-03_before.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/model_calibrated@2024-05-03.yaml"));
}

// A sensor re-zeroed inside a day's telemetry: one sensor event, timed at its block within
// the day, the whole step between the days before and after (that day's bias its own),
// and no move of the mass centre.
TEST(TrackTest, SensorReZeroedInsideADayIsTimedAtItsBlock) {
  constexpr int kDays = 5, kPerDay = 300;
  const double step_s = kStartS + 2 * kDayS + 0.5 * kPerDay * kIntervalS;  // mid-day 3
  SimulationOptions o;
  o.sensor_bias_steps.push_back({step_s, 1, 6000.0});  // cable 2, +6 kN
  const TrackResult r = TrackSeason(kDays, kPerDay, 41, o, "sensor_inside");
  ASSERT_EQ(r.events.size(), 1u);
  const TrackEvent& e = r.events[0];
  EXPECT_EQ(e.kind, "sensor");
  ASSERT_EQ(e.cables, std::vector<int>{2});
  EXPECT_TRUE(e.within_window);
  EXPECT_EQ(r.windows[e.window].label, "2024-05-03");
  EXPECT_NEAR(e.time_s, step_s, 2 * kPerDay / 32.0 * kIntervalS + kIntervalS);
  EXPECT_NEAR(e.parameters[0].shift, 6.0, 3.0 * e.parameters[0].sigma_total);
  // The day of the step is a stretch of its own: the bias has three values.
  int entries = 0;
  for (const TrackShared& s : r.shared) entries += s.name == "sensor_bias_kN[2]";
  EXPECT_EQ(entries, 3);
}

// A mass centre that wanders within and between days (1 cm per axis, 10 minutes, as
// calibration_data/realistic_survey.csv's) is not a string of steps: its wander inside the
// windows is estimated and stated (the days' means then differ by what it explains, so
// that little or no wander between windows is left), and no event is reported; a step
// well beyond the wander still is, on its day.
TEST(TrackTest, AWanderingMassCentreIsNotAStringOfSteps) {
  constexpr int kDays = 10, kPerDay = 200;
  for (const bool step : {false, true}) {
    SimulationOptions o;
    o.mass_centre_drift_m = 0.01;
    o.mass_centre_drift_time_s = 600.0;
    if (step) o.mass_centre_steps.push_back({kStartS + 6 * kDayS - 3600.0, {0.1, 0.0, 0.0}});
    CableRobot truth;
    const Dataset data = Season(kDays, kPerDay, 61, o, &truth);
    const std::string dir = TempDir(step ? "wander_step" : "wander");
    fs::create_directories(dir);
    const TrackResult r =
        Track(LoadSpec(Spec("{sigma_percent: estimate, time_constant_s: estimate}")),
              {Write(data, dir + "/season.csv")}, dir + "/track");
    ASSERT_EQ(r.wander.size(), 1u);
    const TrackWander& w = r.wander[0];
    EXPECT_EQ(w.group, "mass_centre_m");
    EXPECT_TRUE(w.inside_significant) << DescribeWander(w);
    // x and y, which a day's poses determine to a few mm: the truth's 1 cm within a factor
    // of two (z, seen only through the tilt, is left free); the time constant within 4.
    for (int a = 0; a < 2; ++a) {
      EXPECT_GT(w.inside_rms[a], 0.005) << DescribeWander(w);
      EXPECT_LT(w.inside_rms[a], 0.02) << DescribeWander(w);
    }
    EXPECT_GT(w.inside_time_constant_s, 600.0 / 4.0) << DescribeWander(w);
    EXPECT_LT(w.inside_time_constant_s, 600.0 * 4.0) << DescribeWander(w);
    EXPECT_LT(w.rms, 0.01);
    if (!step) {
      EXPECT_TRUE(r.events.empty()) << r.events.size() << " events";
      continue;
    }
    ASSERT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.windows[r.events[0].window].label, "2024-05-07");
    EXPECT_NEAR(r.events[0].parameters[0].shift, 0.1, 3.0 * r.events[0].parameters[0].sigma_total);
  }
}

// Issue 36: a month with three mass-centre moves of 3 cm (two inside a day's telemetry,
// one overnight), a sensor re-zeroed overnight and another inside a day. Every event is
// reported once, of its kind and cable; an overnight one is dated between the two days'
// data, one inside a day within 15 minutes of its true time and inside its likelihood
// interval; each size within 2.5 sigma_total; no other event.
struct TrueEvent {
  std::string kind;
  double time_s = 0.0;
  bool overnight = false;
  int cable = 0;          // a sensor's, 1-based
  Eigen::Vector3d shift;  // m; a sensor's in kN in x
};

// Tolerances of the issue's "done when".
constexpr double kDatingToleranceS = 15.0 * 60.0;
constexpr double kSizeSigmas = 2.5;

void ExpectEventsFoundAndDated(const TrackResult& r, const std::vector<TrueEvent>& truth) {
  ASSERT_EQ(r.events.size(), truth.size());
  for (const TrueEvent& t : truth) {
    const TrackEvent* found = nullptr;
    for (const TrackEvent& e : r.events) {
      const bool cable = t.kind == "parameter" || e.cables == std::vector<int>{t.cable};
      if (e.kind == t.kind && cable && e.time_low_s <= t.time_s + kDatingToleranceS &&
          e.time_high_s >= t.time_s - kDatingToleranceS) {
        found = &e;
      }
    }
    ASSERT_NE(found, nullptr) << t.kind << " at " << t.time_s;
    const TrackEvent& e = *found;
    if (t.overnight) {
      EXPECT_FALSE(e.within_window) << t.time_s;
      EXPECT_LT(e.previous_time_s, t.time_s);
      EXPECT_GT(e.time_s, t.time_s);
      EXPECT_EQ(e.time_s, r.windows[e.window].first_time_s);
      EXPECT_EQ(e.previous_time_s, r.windows[e.window - 1].last_time_s);
    } else {
      EXPECT_TRUE(e.within_window) << t.time_s;
      EXPECT_NEAR(e.time_s, t.time_s, kDatingToleranceS);
      EXPECT_LE(e.time_low_s, t.time_s);
      EXPECT_GE(e.time_high_s, t.time_s);
    }
    const int components = t.kind == "sensor" ? 1 : 3;
    ASSERT_EQ(e.parameters.size(), static_cast<size_t>(components));
    for (int a = 0; a < components; ++a) {
      EXPECT_NEAR(e.parameters[a].shift, t.shift[a], kSizeSigmas * e.parameters[a].sigma_total)
          << t.kind << " at " << t.time_s << ": " << e.parameters[a].name;
    }
  }
}

TEST(TrackTest, EveryMoveFoundAndDated) {
  constexpr int kDays = 30, kPerDay = 300;  // 100 minutes of telemetry a day
  const auto in_day = [&](int day, double fraction) {
    return kStartS + day * kDayS + fraction * kPerDay * kIntervalS;
  };
  const double night = 3600.0;  // before the day's telemetry
  const std::vector<TrueEvent> truth = {
      {"parameter", in_day(5, 0.4), false, 0, {0.03, 0.0, 0.0}},
      {"sensor", kStartS + 9 * kDayS - night, true, 3, {4.0, 0.0, 0.0}},
      {"parameter", kStartS + 13 * kDayS - night, true, 0, {0.0, 0.03, 0.0}},
      {"sensor", in_day(18, 0.35), false, 5, {-3.5, 0.0, 0.0}},
      {"parameter", in_day(23, 0.7), false, 0, {-0.03, 0.0, 0.0}}};
  SimulationOptions o;
  for (const TrueEvent& t : truth) {
    if (t.kind == "parameter") o.mass_centre_steps.push_back({t.time_s, t.shift});
    if (t.kind == "sensor")
      o.sensor_bias_steps.push_back({t.time_s, t.cable - 1, 1e3 * t.shift[0]});
  }
  const TrackResult r = TrackSeason(kDays, kPerDay, 71, o, "month");
  for (const TrackEvent& e : r.events) {
    std::printf("%s %s %.0f [%.0f, %.0f] %s %+.4g +- %.2g\n", e.kind.c_str(),
                e.within_window ? "inside" : "between", e.time_s - kStartS, e.time_low_s - kStartS,
                e.time_high_s - kStartS, e.parameters[0].name.c_str(), e.parameters[0].shift,
                e.parameters[0].sigma_total);
  }
  ExpectEventsFoundAndDated(r, truth);
}

// Issue 53: a sensor re-zeroed (+3.5 kN) 14 minutes before the end of a day's telemetry
// was reported overnight with an interval of the night alone, the truth outside it. Now
// the interval holds the moment, and the size is within 2.5 sigma_total.
TEST(TrackTest, AReZeroingInADaysLastMinutesIsInsideItsInterval) {
  constexpr int kDays = 8, kPerDay = 300;  // 100 minutes a day
  const double t = kStartS + 4 * kDayS + kPerDay * kIntervalS - 14.0 * 60.0;
  SimulationOptions o;
  o.sensor_bias_steps.push_back({t, 3, 3.5e3});
  const TrackResult r = TrackSeason(kDays, kPerDay, 53, o, "edge");
  ASSERT_EQ(r.events.size(), 1u);
  const TrackEvent& e = r.events[0];
  EXPECT_EQ(e.kind, "sensor");
  EXPECT_EQ(e.cables, std::vector<int>{4});
  EXPECT_LE(e.time_low_s, t) << DescribeEventTime(r, e);
  EXPECT_GE(e.time_high_s, t) << DescribeEventTime(r, e);
  ASSERT_EQ(e.parameters.size(), 1u);
  EXPECT_NEAR(e.parameters[0].shift, 3.5, kSizeSigmas * e.parameters[0].sigma_total);
}

// The console's and track.html's words for when an event happened: a night alone is
// "between A and B"; an interval reaching into a day's telemetry says so, as the issue's
// "between <end of day> and <start of next day>" did not; one inside a window is dated.
TEST(TrackTest, EventTimesSayWhenTheIntervalSpansANightAndADay) {
  TrackResult r;
  r.windows.resize(2);
  r.windows[0].first_time_s = 0.0;
  r.windows[0].last_time_s = 3600.0;
  r.windows[1].first_time_s = 86400.0;
  r.windows[1].last_time_s = 90000.0;
  TrackEvent e;
  e.window = 1;
  e.within_window = false;
  e.previous_time_s = 3600.0;
  e.time_s = 86400.0;
  e.time_low_s = 3600.0;
  e.time_high_s = 86400.0;
  const std::string night = DescribeEventTime(r, e);
  EXPECT_EQ(night.find("interval"), std::string::npos) << night;
  EXPECT_EQ(night.rfind("between ", 0), 0u) << night;
  e.time_low_s = 3000.0;  // into the first day's last ten minutes
  const std::string spans = DescribeEventTime(r, e);
  EXPECT_NE(spans.find("95% interval"), std::string::npos) << spans;
  EXPECT_NE(spans.find("spans a night and a day's telemetry"), std::string::npos) << spans;
  e.within_window = true;
  e.time_s = 88000.0;
  e.time_low_s = 87500.0;
  e.time_high_s = 88500.0;
  const std::string inside = DescribeEventTime(r, e);
  EXPECT_EQ(inside.rfind("inside the window, at ", 0), 0u) << inside;
  EXPECT_NE(inside.find("95% interval"), std::string::npos) << inside;
  EXPECT_EQ(inside.find("spans"), std::string::npos) << inside;
}

// Each kind of event at 1% over the season: seasons without any event report one of a
// kind in about 1% (scripts/track_false_alarms.sh runs hundreds; docs/calibration.md has
// the figures). 20 seasons of ten days: at 1%, two or more of a kind come by chance in
// 1.7% of such suites (seeded: the same every run).
TEST(TrackTest, SeasonsWithoutAnEventReportNone) {
  constexpr int kSeasons = 20, kDays = 10, kPerDay = 200;
  constexpr int kMaxAlarmed = 1;
  const CalibrationSpec spec =
      LoadSpec(Spec("{sigma_percent: estimate, time_constant_s: estimate}"));
  const std::string dir = TempDir("null");
  fs::create_directories(dir);
  int parameter = 0, sensor = 0;
  for (int k = 0; k < kSeasons; ++k) {
    CableRobot truth;
    const Dataset data = Season(kDays, kPerDay, 500 + 11 * k, SimulationOptions(), &truth);
    const std::string out = dir + "/" + std::to_string(k);
    const TrackResult r = Track(spec, {Write(data, out + ".csv")}, out);
    bool p = false, s = false;
    for (const TrackEvent& e : r.events) (e.kind == "sensor" ? s : p) = true;
    parameter += p;
    sensor += s;
  }
  std::printf("seasons with a false alarm: %d parameter, %d sensor of %d\n", parameter, sensor,
              kSeasons);
  EXPECT_LE(parameter, kMaxAlarmed);
  EXPECT_LE(sensor, kMaxAlarmed);
}

TEST(TrackBadInputTest, RefusesWhatItCannotTrack) {
  const std::string dir = TempDir("bad");
  fs::create_directories(dir + "/full");
  std::ofstream(dir + "/full/x.txt") << "not a track";
  CalibrationSpec spec = LoadSpec(Spec("{sigma_percent: 1, time_constant_s: 120}"));
  TrackResult result;
  std::string error;
  const auto run = [&](const CalibrationSpec& s, const std::vector<std::string>& files,
                       const std::string& out) {
    return RunTrack(CableRobot::NominalFast(), s, files, WindowSpec(), out, {}, &result, &error);
  };
  EXPECT_EQ(run(spec, {dir + "/missing.csv"}, dir + "/out"), TrackStatus::kInvalidInput);
  EXPECT_NE(error.find("missing.csv"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  // A directory that holds something else.
  EXPECT_EQ(run(spec, {dir + "/missing.csv"}, dir + "/full"), TrackStatus::kInvalidInput);
  EXPECT_NE(error.find("holds no track"), std::string::npos) << error;
  // A spec without per-window groups.
  CalibrationSpec shared = spec;
  shared.separate_groups.clear();
  EXPECT_EQ(run(shared, {dir + "/missing.csv"}, dir + "/out"), TrackStatus::kInvalidInput);
  EXPECT_NE(error.find("sessions: {separate"), std::string::npos) << error;
}

// Issue 53: an overnight re-zeroing (2.5 kN) on telemetry whose errors are correlated over
// minutes (an attitude-control error with a minute's memory) and tens of minutes (the mass
// centre wandering 8 mm inside each day): judged against the samples' misfit alone, a
// wander's dip in the next day's first minutes outweighed the night, and the interval held
// only minutes of that day. Judged against the placements' noise at the blocks' scale and
// the wander's (PlacementNoise), it holds the night. Over seeds 1001-1040 (either sign) the
// intervals held the truth in 36 before, in 37 now (95% stated): seed 1010 is the one that
// moved.
TEST(TrackTest, AnOvernightReZeroingIsNotPutInADaysWander) {
  constexpr int kDays = 6, kPerDay = 300;
  const double t = kStartS + 3 * kDayS - 8 * 3600.0;
  SimulationOptions o;
  o.sensor_bias_steps.push_back({t, 2, -2.5e3});
  o.mass_centre_drift_m = 0.008;
  o.mass_centre_drift_time_s = 900.0;
  o.mass_centre_drift_centred = true;
  o.attitude_control_sigma_deg = 0.3;
  o.attitude_control_time_s = 60.0;
  const TrackResult r = TrackSeason(kDays, kPerDay, 1010, o, "wander_night");
  const TrackEvent* found = nullptr;
  for (const TrackEvent& e : r.events) {
    if (e.kind == "sensor" && e.cables == std::vector<int>{3}) found = &e;
  }
  ASSERT_NE(found, nullptr);
  EXPECT_LE(found->time_low_s, t) << DescribeEventTime(r, *found);
  EXPECT_GE(found->time_high_s, t) << DescribeEventTime(r, *found);
}

}  // namespace
}  // namespace fastcal
