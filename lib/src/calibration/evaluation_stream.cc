// `fastcal evaluate` on a file too long to hold (evaluation_stream.h).
#include "fastcal/evaluation_stream.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "fastcal/gross_errors.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/quote.h"
#include "fastcal/sessions.h"
#include "fastcal/tension_scale.h"

namespace fastcal {
namespace {

using internal::ExactSelection;

// As RobustScaleOf (uncertainty.h): the standard deviation of a normal sample per MAD.
constexpr double kMadToSigma = 1.4826;

std::vector<AttitudeSource> Attitudes(bool planned) {
  if (planned) return {AttitudeSource::kPlanned, AttitudeSource::kMeasured};
  return {AttitudeSource::kMeasured};
}

// DiagnoseUnsolvableRows of two parts of one dataset, as if of the whole (its rule:
// at least two failures, the nominal model solving at least half of them).
void AddDiagnosis(const UnsolvableRows& part, UnsolvableRows* total) {
  constexpr int kFewestForNominalTest = 2;
  total->rows += part.rows;
  if (part.failed == 0) return;
  if (total->failed == 0) {
    total->first = part.first;
    total->furthest_from_nominal = part.furthest_from_nominal;
  }
  total->failed += part.failed;
  total->solved_by_nominal += part.solved_by_nominal;
  total->model_likely =
      total->failed >= kFewestForNominalTest && 2 * total->solved_by_nominal >= total->failed;
}

// The median of a stream's n values from its selected ranks n / 2 (and n / 2 - 1 when n is
// even), as Median (uncertainty.cc) computes it: 0.5 (upper + lower).
std::vector<std::pair<int, long long>> MedianRanks(const std::array<long long, kNumCables>& n) {
  std::vector<std::pair<int, long long>> targets;
  for (int i = 0; i < kNumCables; ++i) {
    targets.emplace_back(i, n[i] / 2);
    targets.emplace_back(i, n[i] % 2 == 0 ? n[i] / 2 - 1 : n[i] / 2);
  }
  return targets;
}
double MedianOf(const ExactSelection& s, int cable, long long n) {
  if (n == 0) return 0.0;
  const double upper = s.Result(2 * cable), lower = s.Result(2 * cable + 1);
  return n % 2 == 1 ? upper : 0.5 * (upper + lower);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// StreamedEvaluation

StreamedEvaluation::~StreamedEvaluation() {
  if (spill_ != nullptr) std::fclose(spill_);
}

// Pass 1's state: a predictor and the statistics of each variant, the whitened residuals'
// counts, the rows the model cannot solve.
struct StreamedEvaluation::Pass1 {
  std::vector<TensionPredictor> predictors;
  std::vector<ErrorStatsAccumulator> stats;
  std::array<long long, kNumCables> finite{};             // finite whitened residuals per cable
  std::vector<std::string> unsolvable;                    // messages, listed after the reader's
  std::vector<std::array<double, kNumCables>> predicted;  // the sample's, per variant
  std::vector<double> record;
};

bool StreamedEvaluation::ReadRecord(std::FILE* file, EvaluatedSample* s) const {
  const size_t size = 12 + kNumCables * static_cast<size_t>(predicted_variants_);
  double r[12 + kNumCables * 2];
  if (std::fread(r, sizeof(double), size, file) != size) return false;
  s->line = static_cast<int>(r[0]);
  s->time_s = r[1];
  s->session = static_cast<int>(r[2]);
  s->position_m = Eigen::Vector3d(r[3], r[4], r[5]);
  std::copy(r + 6, r + 12, s->measured_n.begin());
  s->predicted_n.resize(predicted_variants_);
  for (int v = 0; v < predicted_variants_; ++v) {
    std::copy(r + 12 + kNumCables * v, r + 12 + kNumCables * (v + 1), s->predicted_n[v].begin());
  }
  return true;
}

std::string StreamedEvaluation::SpillError(const std::string& what, int err) const {
  return "evaluation: cannot " + what + " its temporary file in " +
         internal::Escape(spill_directory_) + " (about " +
         std::to_string(8 * (12 + kNumCables * (1 + std::max(predicted_variants_, 1)))) +
         " bytes a sample; TMPDIR names another directory): " +
         (err != 0 ? std::strerror(err) : "read or write error");
}

bool StreamedEvaluation::ForEach(const std::function<void(const EvaluatedSample&)>& visit,
                                 std::string* error) const {
  if (spill_ == nullptr || samples_ == 0) return true;
  std::rewind(spill_);
  EvaluatedSample s;
  const bool screened = screen_.threshold.readings > 0;
  for (long long t = 0; t < samples_; ++t) {
    if (!ReadRecord(spill_, &s)) {
      *error = SpillError("read back", errno);
      return false;
    }
    s.index = t;
    s.gross.fill(false);
    if (screened) {
      const std::array<double, kNumCables> w = Whitened(s.predicted_n.back(), s.measured_n);
      for (int i = 0; i < kNumCables; ++i) {
        const double d = std::abs(w[i] - screen_.cables[i].centre);
        // A non-finite residual (a reading the model cannot predict) is a gross error too.
        s.gross[i] = !(d <= screen_.threshold.sigmas * screen_.cables[i].scale);
      }
    }
    visit(s);
  }
  return true;
}

std::array<double, kNumCables> StreamedEvaluation::Whitened(
    const std::array<double, kNumCables>& predicted_n,
    const std::array<double, kNumCables>& measured_n) const {
  const std::array<double, kNumCables> sigma_n =
      internal::TensionSigmas(predicted_n, sigma_abs_n_, sigma_percent_);
  std::array<double, kNumCables> w;
  for (int i = 0; i < kNumCables; ++i) w[i] = (predicted_n[i] - measured_n[i]) / sigma_n[i];
  return w;
}

bool StreamedEvaluation::Select(
    ExactSelection* selection,
    const std::function<void(const EvaluatedSample&, ExactSelection*)>& feed,
    std::string* error) const {
  while (!selection->done()) {
    selection->Begin();
    if (!ForEach([&](const EvaluatedSample& s) { feed(s, selection); }, error)) return false;
    selection->End();
  }
  return true;
}

bool StreamedEvaluation::Prepare(const std::vector<std::string>& paths,
                                 const EvaluationStreamOptions& options, std::string* error) {
  if (paths.size() < 2) return true;
  // Several files: each read through once (its errors first, in file order, as
  // ReadSessionDatasets reads them), then merged without samples for MergeSessionFiles'
  // checks, messages and session labels.
  std::vector<Dataset> files;
  for (const std::string& path : paths) {
    DatasetChunkReader reader;
    if (!reader.Open(path, options.read, error)) return false;
    Dataset chunk;
    for (bool done = false; !done;) {
      if (!reader.Next(options.chunk_samples, &chunk, &done, error)) return false;
    }
    chunk.samples.clear();
    chunk.skipped.clear();
    files.push_back(std::move(chunk));
  }
  if (!MergeSessionFiles(files, &merged_, error)) return false;
  for (const Dataset& file : files) {
    std::vector<std::string> labels = file.session_labels;
    if (labels.empty()) labels.push_back(SessionLabelOfPath(file.path));
    std::vector<int> map;
    for (const std::string& label : labels) {
      const auto at =
          std::find(merged_.session_labels.begin(), merged_.session_labels.end(), label);
      map.push_back(static_cast<int>(at - merged_.session_labels.begin()));
    }
    session_maps_.push_back(std::move(map));
  }
  return true;
}

bool StreamedEvaluation::Chunks(const std::vector<std::string>& paths,
                                const EvaluationStreamOptions& options,
                                const std::function<bool(Dataset*)>& visit, std::string* error) {
  Dataset chunk;
  for (size_t f = 0; f < paths.size(); ++f) {
    DatasetChunkReader reader;
    if (!reader.Open(paths[f], options.read, error)) return false;
    for (bool done = false; !done;) {
      if (!reader.Next(options.chunk_samples, &chunk, &done, error)) return false;
      if (f < session_maps_.size()) {
        // The merged dataset's sessions and column groups (its planned attitude only
        // when every file has one).
        for (Sample& s : chunk.samples) {
          s.session = session_maps_[f][chunk.session_labels.empty() ? 0 : s.session];
        }
        chunk.has_planned_attitude = merged_.has_planned_attitude;
      }
      if (!visit(&chunk)) return true;
    }
  }
  if (session_maps_.empty()) {
    merged_.path = chunk.path;
    merged_.has_planned_attitude = chunk.has_planned_attitude;
    merged_.has_unstretched_lengths = chunk.has_unstretched_lengths;
    merged_.attitude_as_quaternion = chunk.attitude_as_quaternion;
    merged_.session_labels = chunk.session_labels;
    merged_.time_offset_s = chunk.time_offset_s;
  }
  return true;
}

EvaluationStreamStatus StreamedEvaluation::Run(const CableRobot& robot,
                                               const std::vector<std::string>& paths,
                                               const EvaluationStreamOptions& options,
                                               std::string* error) {
  sigma_abs_n_ = options.spec.tension_sigma_n;
  sigma_percent_ = options.spec.tension_sigma_percent;
  if (!Prepare(paths, options, error)) return EvaluationStreamStatus::kInvalidInput;
  spill_directory_ = options.temporary_directory;
  if (spill_directory_.empty()) {
    const char* tmpdir = std::getenv("TMPDIR");
    spill_directory_ = tmpdir != nullptr && *tmpdir != '\0' ? tmpdir : "/tmp";
  }
  int err = 0;
  spill_ = internal::OpenUnnamedFile(spill_directory_, &err);
  if (spill_ == nullptr) {
    *error = SpillError("create", err);
    return EvaluationStreamStatus::kSystemError;
  }
  Pass1 p;
  bool unsolvable = false, write_failed = false, wrong_unit = false;
  std::string checked_path;
  const auto pass1 = [&](Dataset* chunk) {
    // The tensions' unit on each file's first chunk (a slip is in every row), as calibrate
    // and track check it (issue 37: kN read as N gave an RMS of 99.9% and exit 0).
    if (!chunk->samples.empty() && chunk->path != checked_path) {
      checked_path = chunk->path;
      if (!CheckTensionScale(*chunk, robot, error)) {
        wrong_unit = true;
        return false;
      }
    }
    if (PassOneChunk(robot, options, chunk, &p, &unsolvable, error)) return true;
    write_failed = !unsolvable;
    return false;
  };
  if (!Chunks(paths, options, pass1, error) || write_failed || wrong_unit) {
    if (wrong_unit) return EvaluationStreamStatus::kInvalidInput;
    return write_failed ? EvaluationStreamStatus::kSystemError
                        : EvaluationStreamStatus::kInvalidInput;
  }
  if (unsolvable) return Failure(robot, paths, options, error);
  layout_.path = merged_.path;
  layout_.has_planned_attitude = merged_.has_planned_attitude;
  layout_.has_unstretched_lengths = merged_.has_unstretched_lengths;
  layout_.attitude_as_quaternion = merged_.attitude_as_quaternion;
  layout_.session_labels = merged_.session_labels;
  layout_.session_paths = merged_.session_paths;
  layout_.time_offset_s = merged_.time_offset_s;
  for (std::string& why : p.unsolvable) layout_.skipped.push_back(std::move(why));
  if (std::fflush(spill_) != 0) {
    *error = SpillError("write", errno);
    return EvaluationStreamStatus::kSystemError;
  }
  for (size_t v = 0; v < p.stats.size(); ++v) {
    VariantEvaluation e;
    e.name = EvaluationVariantName(Attitudes(predicted_variants_ == 2)[v]);
    e.fit = p.stats[v].Finish();
    variants_.push_back(std::move(e));
  }
  finite_ = p.finite;
  if (samples_ == 0) return EvaluationStreamStatus::kOk;  // the caller says no sample is left
  // These only read the temporary file back.
  if (!Screen(options, error) || !Trajectory(error) || !GrossErrorRows(options, error)) {
    return EvaluationStreamStatus::kSystemError;
  }
  return EvaluationStreamStatus::kOk;
}

bool StreamedEvaluation::PassOneChunk(const CableRobot& robot,
                                      const EvaluationStreamOptions& options, Dataset* chunk,
                                      Pass1* p, bool* unsolvable, std::string* error) {
  for (std::string& why : chunk->skipped) layout_.skipped.push_back(std::move(why));
  chunk->skipped.clear();
  if (chunk->samples.empty()) return true;
  if (p->predictors.empty()) {
    for (AttitudeSource a : Attitudes(chunk->has_planned_attitude)) {
      p->predictors.emplace_back(robot, a, options.method);
      p->stats.emplace_back();
    }
    predicted_variants_ = static_cast<int>(p->predictors.size());
    p->predicted.resize(p->predictors.size());
  }
  if (options.read.skip_invalid_rows) {
    // As fastcal evaluate --skip-invalid-rows: the diagnosis over every valid row, then
    // the rows the model cannot solve removed (listed after the reader's).
    AddDiagnosis(DiagnoseUnsolvableRows(robot, "the model", *chunk,
                                        {AttitudeSource::kPlanned, AttitudeSource::kMeasured},
                                        {options.method}),
                 &diagnosis_);
    SkipUnsolvableSamples(robot, "the model", {AttitudeSource::kPlanned, AttitudeSource::kMeasured},
                          {options.method}, chunk);
    for (std::string& why : chunk->skipped) p->unsolvable.push_back(std::move(why));
    chunk->skipped.clear();
  }
  for (const Sample& s : chunk->samples) {
    for (size_t v = 0; v < p->predictors.size(); ++v) {
      if (!p->predictors[v].Predict(*chunk, s, &p->predicted[v], error)) {
        *unsolvable = true;
        return false;
      }
      p->stats[v].Add(p->predicted[v], s.tension_n);
    }
    if (!Append(s, p->predicted, p, error)) return false;
  }
  return true;
}

bool StreamedEvaluation::Append(const Sample& s,
                                const std::vector<std::array<double, kNumCables>>& predicted,
                                Pass1* p, std::string* error) {
  if (samples_ == 0) {
    time_min_s_ = time_max_s_ = s.time_s;
  }
  time_min_s_ = std::min(time_min_s_, s.time_s);
  time_max_s_ = std::max(time_max_s_, s.time_s);
  position_sum_m_ += s.pose.position_m;
  ++samples_;
  std::vector<double>& r = p->record;
  r.assign({static_cast<double>(s.line), s.time_s, static_cast<double>(s.session),
            s.pose.position_m.x(), s.pose.position_m.y(), s.pose.position_m.z()});
  r.insert(r.end(), s.tension_n.begin(), s.tension_n.end());
  for (const auto& v : predicted) r.insert(r.end(), v.begin(), v.end());
  const std::array<double, kNumCables> w = Whitened(predicted.back(), s.tension_n);
  for (int i = 0; i < kNumCables; ++i) p->finite[i] += std::isfinite(w[i]);
  if (std::fwrite(r.data(), sizeof(double), r.size(), spill_) != r.size()) {
    *error = SpillError("write", errno);
    return false;
  }
  return true;
}

// A pose the model cannot hold (without --skip-invalid-rows, or one a warm start fails):
// the message and diagnosis the whole-file path gives, from a second reading of the file:
// each variant predicted again (the same warm starts) to its first failure, the first
// variant's failure named, and DiagnoseUnsolvableRows over every row.
EvaluationStreamStatus StreamedEvaluation::Failure(const CableRobot& robot,
                                                   const std::vector<std::string>& paths,
                                                   const EvaluationStreamOptions& options,
                                                   std::string* error) {
  diagnosis_ = UnsolvableRows();
  std::vector<TensionPredictor> predictors;
  std::vector<std::string> failures;
  const auto again = [&](Dataset* chunk) {
    if (chunk->samples.empty()) return true;
    if (predictors.empty()) {
      for (AttitudeSource a : Attitudes(chunk->has_planned_attitude)) {
        predictors.emplace_back(robot, a, options.method);
      }
      failures.resize(predictors.size());
    }
    if (options.read.skip_invalid_rows) {
      SkipUnsolvableSamples(robot, "the model",
                            {AttitudeSource::kPlanned, AttitudeSource::kMeasured}, {options.method},
                            chunk);
    }
    AddDiagnosis(DiagnoseUnsolvableRows(robot, "the model", *chunk,
                                        {AttitudeSource::kPlanned, AttitudeSource::kMeasured},
                                        {options.method}),
                 &diagnosis_);
    std::array<double, kNumCables> unused;
    for (size_t v = 0; v < predictors.size(); ++v) {
      for (const Sample& s : chunk->samples) {
        if (!failures[v].empty()) break;
        predictors[v].Predict(*chunk, s, &unused, &failures[v]);
      }
    }
    return true;
  };
  if (!Chunks(paths, options, again, error)) {
    return EvaluationStreamStatus::kInvalidInput;
  }
  for (const std::string& f : failures) {
    if (!f.empty()) {
      *error = f;
      break;
    }
  }
  return EvaluationStreamStatus::kUnsolvable;
}

bool StreamedEvaluation::Screen(const EvaluationStreamOptions& options, std::string* error) {
  screen_.variant = variants_.back().name;
  // Centre: the median of each cable's finite whitened residuals.
  ExactSelection centre(MedianRanks(finite_));
  const auto feed_residuals = [this](const EvaluatedSample& s, ExactSelection* sel) {
    const std::array<double, kNumCables> w = Whitened(s.predicted_n.back(), s.measured_n);
    for (int i = 0; i < kNumCables; ++i) {
      if (std::isfinite(w[i])) sel->Add(i, w[i]);
    }
  };
  if (!Select(&centre, feed_residuals, error)) return false;
  for (int i = 0; i < kNumCables; ++i) screen_.cables[i].centre = MedianOf(centre, i, finite_[i]);
  // Scale: 1.4826 times the median absolute deviation from it, at least 1.
  ExactSelection mad(MedianRanks(finite_));
  const auto feed_deviations = [this](const EvaluatedSample& s, ExactSelection* sel) {
    const std::array<double, kNumCables> w = Whitened(s.predicted_n.back(), s.measured_n);
    for (int i = 0; i < kNumCables; ++i) {
      if (std::isfinite(w[i])) sel->Add(i, std::abs(w[i] - screen_.cables[i].centre));
    }
  };
  if (!Select(&mad, feed_deviations, error)) return false;
  for (int i = 0; i < kNumCables; ++i) {
    screen_.cables[i].scale = std::max(1.0, kMadToSigma * MedianOf(mad, i, finite_[i]));
  }
  screen_.threshold = ChooseGrossErrorThreshold(static_cast<long long>(kNumCables) * samples_,
                                                options.spec.gross_error_threshold_sigmas);
  return true;
}

bool StreamedEvaluation::Trajectory(std::string* error) {
  if (samples_ < 3) return true;
  const Eigen::Vector3d mean = position_sum_m_ / static_cast<double>(samples_);
  double spread2 = 0.0;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  ExactSelection median({{0, (samples_ - 1) / 2}});
  bool first_pass = true;
  if (!Select(
          &median,
          [&](const EvaluatedSample& s, ExactSelection* sel) {
            if (first_pass) spread2 += (s.position_m - mean).squaredNorm();
            if (s.index > 0) sel->Add(0, (s.position_m - previous).norm());
            previous = s.position_m;
            if (s.index + 1 == samples_) first_pass = false;
          },
          error)) {
    return false;
  }
  median_step_m_ = median.Result(0);
  position_spread_m_ = std::sqrt(spread2 / samples_);
  return true;
}

bool StreamedEvaluation::GrossErrorRows(const EvaluationStreamOptions& options,
                                        std::string* error) {
  std::vector<ErrorStatsAccumulator> without(predicted_variants_);
  const bool ok = ForEach(
      [&](const EvaluatedSample& s) {
        for (int v = 0; v < predicted_variants_; ++v)
          without[v].Add(s.predicted_n[v], s.measured_n, &s.gross);
        const std::array<double, kNumCables> w = Whitened(s.predicted_n.back(), s.measured_n);
        for (int i = 0; i < kNumCables; ++i) {
          if (!s.gross[i]) continue;
          ++screen_.count;
          ++screen_.count_per_cable[i];
          if (screen_.gross_errors.size() >= options.max_named_gross_errors) continue;
          ReadingResidual g;
          g.sample = static_cast<int>(s.index);
          g.line = s.line;
          g.cable = i + 1;
          g.measured_n = s.measured_n[i];
          g.predicted_n = s.predicted_n.back()[i];
          g.residual_sigma = w[i];
          screen_.gross_errors.push_back(g);
        }
      },
      error);
  if (!ok) return false;
  if (screen_.count == 0) return true;
  for (int v = 0; v < predicted_variants_; ++v) {
    VariantEvaluation w;
    w.name = variants_[v].name + " - gross errors";
    w.fit = without[v].Finish();
    variants_.push_back(std::move(w));
  }
  return true;
}

}  // namespace fastcal
