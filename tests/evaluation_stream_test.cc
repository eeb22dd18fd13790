// Tests of the streamed evaluation (evaluation_stream.h): exact selection against a sort,
// and a file evaluated in many small chunks against the whole-file path (EvaluateModel,
// ScreenEvaluation, WithoutGrossErrors): the same statistics, screen and gross errors bit
// for bit, the same skipped rows and the same messages for bad input.
#include "fastcal/evaluation_stream.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/evaluation_screen.h"
#include "fastcal/internal/exact_selection.h"
#include "fastcal/report.h"
#include "fastcal/sessions.h"
#include "fastcal/simulation.h"
#include "fastcal/trajectory.h"
#include "fastcal/unsolvable_rows.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;
using internal::ExactSelection;

// Runs `selection` to the end over `streams` (value v of stream s fed in each pass).
void RunSelection(const std::vector<std::vector<double>>& streams, ExactSelection* selection) {
  int passes = 0;
  while (!selection->done()) {
    ASSERT_LT(++passes, 40) << "the selection does not converge";
    selection->Begin();
    for (size_t s = 0; s < streams.size(); ++s) {
      for (double v : streams[s]) selection->Add(static_cast<int>(s), v);
    }
    selection->End();
  }
}

// Streams longer than ExactSelection keeps at once (so that it bins), with ties, a wide
// range and a constant stream: every rank asked for is the sorted value at that rank.
TEST(ExactSelectionTest, GivesTheSortedValueAtEachRank) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  std::vector<std::vector<double>> streams(4);
  const size_t n = ExactSelection::kMaxKept * 3 + 17;
  for (size_t k = 0; k < n; ++k) {
    streams[0].push_back(normal(rng));
    streams[1].push_back(std::round(normal(rng) * 3.0));  // few distinct values: ties
    streams[2].push_back(k % 1000 == 0 ? 1e12 * normal(rng) : 1e-6 * normal(rng));
    streams[3].push_back(2.5);
  }
  std::vector<std::pair<int, long long>> targets;
  const long long ranks[] = {0, 1, static_cast<long long>(n / 2), static_cast<long long>(n - 1)};
  for (int s = 0; s < 4; ++s) {
    for (long long r : ranks) targets.emplace_back(s, r);
  }
  targets.emplace_back(0, static_cast<long long>(n));  // no such rank
  ExactSelection selection(targets);
  RunSelection(streams, &selection);
  for (size_t t = 0; t + 1 < targets.size(); ++t) {
    std::vector<double> sorted = streams[targets[t].first];
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(selection.Result(t), sorted[targets[t].second])
        << "stream " << targets[t].first << " rank " << targets[t].second;
  }
  EXPECT_TRUE(std::isnan(selection.Result(targets.size() - 1)));
}

class EvaluationStreamTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "evaluation_stream_XXXXXX";
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  // A simulated random survey of `samples` samples with outliers, written to a file;
  // `edit` may change its lines (0-based, the column line included) before it is saved.
  std::string Survey(int samples, const std::function<void(std::vector<std::string>*)>& edit) {
    RandomWorkspaceSpec spec;
    spec.samples = samples;
    spec.seed = 3;
    std::vector<Eigen::Vector3d> positions;
    std::vector<Pose> poses;
    std::string error;
    EXPECT_TRUE(RandomWorkspacePositions(spec, &positions, &error)) << error;
    EXPECT_TRUE(PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, &error)) << error;
    SimulationOptions options;
    options.outlier_fraction = 0.003;
    options.seed = 5;
    Dataset data;
    EXPECT_TRUE(
        Simulate(CableRobot::NominalFast(), poses, options, &data, nullptr, nullptr, &error))
        << error;
    data.samples[samples / 3].tension_n[2] = 0.0;  // a dropout
    const std::string path = (dir_ / "survey.csv").string();
    fs::remove(path);
    EXPECT_TRUE(WriteDataset(path, data, "", &error)) << error;
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    edit(&lines);
    std::ofstream out(path, std::ios::trunc);
    for (const std::string& line : lines) out << line << "\n";
    return path;
  }

  fs::path dir_;
};

// The row with x_m = 330: near tower 4, a plausible position (within the 350 m limit)
// whose pose the cables cannot hold (a slack cable).
std::string AtX330(const std::string& row) {
  const size_t x = row.find(',');
  return row.substr(0, x) + ",330" + row.substr(row.find(',', x + 1));
}

void ExpectStatsEqual(const CableErrorStats& a, const CableErrorStats& b) {
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.excluded, b.excluded);
  EXPECT_EQ(a.mean_n, b.mean_n);
  EXPECT_EQ(a.rms_n, b.rms_n);
  EXPECT_EQ(a.max_abs_n, b.max_abs_n);
  EXPECT_EQ(a.rms_percent, b.rms_percent);
  EXPECT_EQ(a.max_abs_percent, b.max_abs_percent);
}

// The whole-file path of fastcal evaluate: read, (skip), predict, screen, rows without
// the gross errors.
struct WholeFile {
  Dataset data;
  std::vector<VariantEvaluation> variants;
  EvaluationScreen screen;
};
WholeFile EvaluateWhole(const std::string& path, bool skip) {
  WholeFile w;
  DatasetReadOptions read;
  read.skip_invalid_rows = skip;
  std::string error;
  EXPECT_TRUE(ReadDataset(path, read, &w.data, &error)) << error;
  if (skip) {
    SkipUnsolvableSamples(CableRobot::NominalFast(), "the model",
                          {AttitudeSource::kPlanned, AttitudeSource::kMeasured},
                          {StaticsMethod::kExact}, &w.data);
  }
  EXPECT_TRUE(
      EvaluateModel(CableRobot::NominalFast(), w.data, StaticsMethod::kExact, &w.variants, &error))
      << error;
  w.screen = ScreenEvaluation(w.data, w.variants.back());
  if (w.screen.count > 0) {
    for (VariantEvaluation& v : WithoutGrossErrors(w.data, w.variants, w.screen.excluded)) {
      w.variants.push_back(std::move(v));
    }
  }
  return w;
}

// fastcal evaluate streams its file (issue 20): in chunks of 97 samples, 3000 samples
// (31 chunks, warm starts carried across them) give the whole-file path's RMS table,
// screen and gross errors bit for bit, and the same predictions sample by sample; with
// --skip-invalid-rows, the same rows skipped (malformed, and a pose the model cannot
// hold) in the same order; and the same report.
TEST_F(EvaluationStreamTest, ChunksGiveTheWholeFilesNumbers) {
  for (bool skip : {false, true}) {
    SCOPED_TRACE(skip ? "skip invalid rows" : "all rows valid");
    const std::string path = Survey(3000, [skip](std::vector<std::string>* lines) {
      if (!skip) return;
      (*lines)[500] += ",1";  // one field too many
      (*lines)[1700] = AtX330((*lines)[1700]);
    });
    const WholeFile whole = EvaluateWhole(path, skip);
    EvaluationStreamOptions options;
    options.chunk_samples = 97;
    options.read.skip_invalid_rows = skip;
    StreamedEvaluation streamed;
    std::string error;
    ASSERT_EQ(streamed.Run(CableRobot::NominalFast(), {path}, options, &error),
              EvaluationStreamStatus::kOk)
        << error;
    ASSERT_EQ(streamed.samples(), static_cast<long long>(whole.data.samples.size()));
    EXPECT_EQ(streamed.layout().skipped, whole.data.skipped);
    if (skip) {
      EXPECT_EQ(whole.data.skipped.size(), 2u);
    }
    ASSERT_EQ(streamed.variants().size(), whole.variants.size());
    for (size_t v = 0; v < whole.variants.size(); ++v) {
      EXPECT_EQ(streamed.variants()[v].name, whole.variants[v].name);
      ExpectStatsEqual(streamed.variants()[v].fit, whole.variants[v].fit);
    }
    const EvaluationScreen& s = streamed.screen();
    ASSERT_GT(whole.screen.count, 0);  // the dropout and the outliers
    EXPECT_EQ(s.count, whole.screen.count);
    EXPECT_EQ(s.count_per_cable, whole.screen.count_per_cable);
    EXPECT_EQ(s.threshold.sigmas, whole.screen.threshold.sigmas);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(s.cables[i].centre, whole.screen.cables[i].centre);
      EXPECT_EQ(s.cables[i].scale, whole.screen.cables[i].scale);
    }
    ASSERT_EQ(s.gross_errors.size(), whole.screen.gross_errors.size());
    for (size_t k = 0; k < s.gross_errors.size(); ++k) {
      EXPECT_EQ(s.gross_errors[k].line, whole.screen.gross_errors[k].line);
      EXPECT_EQ(s.gross_errors[k].cable, whole.screen.gross_errors[k].cable);
      EXPECT_EQ(s.gross_errors[k].residual_sigma, whole.screen.gross_errors[k].residual_sigma);
    }
    long long n = 0;
    ASSERT_TRUE(streamed.ForEach(
        [&](const EvaluatedSample& e) {
          const size_t t = static_cast<size_t>(n++);
          EXPECT_EQ(e.line, whole.data.samples[t].line);
          EXPECT_EQ(e.measured_n, whole.data.samples[t].tension_n);
          for (size_t v = 0; v < e.predicted_n.size(); ++v) {
            EXPECT_EQ(e.predicted_n[v], whole.variants[v].predicted_n[t]) << t;
          }
          for (int i = 0; i < kNumCables; ++i) EXPECT_EQ(e.gross[i], whole.screen.excluded[t][i]);
        },
        &error))
        << error;
    EXPECT_EQ(n, streamed.samples());

    // The report from the replayed samples is the whole dataset's, plots (thinned: 3000
    // samples is more than a series draws) and histogram included.
    ReportInputs in_memory;
    in_memory.data = &whole.data;
    in_memory.variants = whole.variants;
    in_memory.evaluation_screen = &whole.screen;
    in_memory.evaluation_method = "exact";
    ReportInputs replayed = in_memory;
    replayed.data = &streamed.layout();
    replayed.variants = streamed.variants();
    replayed.evaluation_screen = &streamed.screen();
    const ReportSampleStream samples = ReportSamplesOf(streamed);
    replayed.sample_stream = &samples;
    const std::string html = ReportHtml(in_memory);
    EXPECT_NE(html.find("Thinned for drawing"), std::string::npos);
    EXPECT_EQ(ReportHtml(replayed), html);
    EXPECT_EQ(ReportMarkdown(replayed), ReportMarkdown(in_memory));
    EXPECT_EQ(SummaryJson(replayed), SummaryJson(in_memory));
  }
}

// Several files are one session each, merged as ReadSessionDatasets merges them: the same
// labels, paths, sessions and statistics, streamed file after file.
TEST_F(EvaluationStreamTest, SeveralFilesAreMergedAsSessions) {
  const std::string first = Survey(700, [](std::vector<std::string>*) {});
  const std::string second = (dir_ / "day-2.csv").string();
  fs::copy_file(first, second);
  const std::string third = Survey(500, [](std::vector<std::string>*) {});  // survey.csv again
  fs::rename(third, dir_ / "day-3.csv");
  const std::vector<std::string> paths = {second, (dir_ / "day-3.csv").string()};
  Dataset whole;
  std::string error;
  ASSERT_TRUE(ReadSessionDatasets(paths, DatasetReadOptions(), &whole, &error)) << error;
  std::vector<VariantEvaluation> variants;
  ASSERT_TRUE(
      EvaluateModel(CableRobot::NominalFast(), whole, StaticsMethod::kExact, &variants, &error));
  EvaluationStreamOptions options;
  options.chunk_samples = 64;
  StreamedEvaluation streamed;
  ASSERT_EQ(streamed.Run(CableRobot::NominalFast(), paths, options, &error),
            EvaluationStreamStatus::kOk)
      << error;
  EXPECT_EQ(streamed.layout().path, whole.path);
  EXPECT_EQ(streamed.layout().session_labels, whole.session_labels);
  EXPECT_EQ(streamed.layout().session_paths, whole.session_paths);
  ASSERT_EQ(streamed.samples(), static_cast<long long>(whole.samples.size()));
  for (size_t v = 0; v < variants.size(); ++v) {
    ExpectStatsEqual(streamed.variants()[v].fit, variants[v].fit);
  }
  std::vector<int> sessions;
  ASSERT_TRUE(
      streamed.ForEach([&](const EvaluatedSample& e) { sessions.push_back(e.session); }, &error));
  for (size_t t = 0; t < sessions.size(); ++t) EXPECT_EQ(sessions[t], whole.samples[t].session);
  // A label in two files: MergeSessionFiles' message.
  std::string expected;
  ASSERT_FALSE(ReadSessionDatasets({second, second}, DatasetReadOptions(), &whole, &expected));
  StreamedEvaluation twice;
  EXPECT_EQ(twice.Run(CableRobot::NominalFast(), {second, second}, options, &error),
            EvaluationStreamStatus::kInvalidInput);
  EXPECT_EQ(error, expected);
}

// Bad input met in a late chunk fails with ReadDataset's message; a pose the model cannot
// hold (without --skip-invalid-rows) with EvaluateModel's.
TEST_F(EvaluationStreamTest, LateBadRowsGiveTheWholeFilesMessages) {
  const std::string path = Survey(600, [](std::vector<std::string>* lines) {
    (*lines)[550].replace((*lines)[550].find(','), 1, ",x");
  });
  Dataset unused;
  std::string expected, error;
  ASSERT_FALSE(ReadDataset(path, DatasetReadOptions(), &unused, &expected));
  EvaluationStreamOptions options;
  options.chunk_samples = 50;
  StreamedEvaluation bad_row;
  EXPECT_EQ(bad_row.Run(CableRobot::NominalFast(), {path}, options, &error),
            EvaluationStreamStatus::kInvalidInput);
  EXPECT_EQ(error, expected);

  const std::string unsolvable =
      Survey(600, [](std::vector<std::string>* lines) { (*lines)[450] = AtX330((*lines)[450]); });
  Dataset data;
  ASSERT_TRUE(ReadDataset(unsolvable, DatasetReadOptions(), &data, &error)) << error;
  std::vector<VariantEvaluation> variants;
  ASSERT_FALSE(
      EvaluateModel(CableRobot::NominalFast(), data, StaticsMethod::kExact, &variants, &expected));
  StreamedEvaluation pose;
  EXPECT_EQ(pose.Run(CableRobot::NominalFast(), {unsolvable}, options, &error),
            EvaluationStreamStatus::kUnsolvable);
  EXPECT_EQ(error, expected);
  const UnsolvableRows d = DiagnoseUnsolvableRows(
      CableRobot::NominalFast(), "the model", data,
      {AttitudeSource::kPlanned, AttitudeSource::kMeasured}, {StaticsMethod::kExact});
  EXPECT_EQ(pose.diagnosis().rows, d.rows);
  EXPECT_EQ(pose.diagnosis().failed, d.failed);
  EXPECT_EQ(pose.diagnosis().first, d.first);
}

}  // namespace
}  // namespace fastcal
