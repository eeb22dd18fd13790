// The fold of one window (track_fold.h): predict at the point, whiten and screen, then
// the whitened rows folded by QR, block by block, in time order.
#include "fastcal/track_fold.h"

#include <algorithm>
#include <cmath>

#include "fastcal/gross_errors.h"
#include "fastcal/internal/calibration_linearisation.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/calibration_slow_error.h"
#include "fastcal/internal/compact_start.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/sample_rows.h"
#include "fastcal/internal/window_store.h"

namespace fastcal {
namespace {

using internal::ReadingArrays;

// Fewest samples in a block: below it the blocks' scores say little about time correlation.
constexpr int kMinBlockSamples = 16;
// Rounds of the gross-error screen at most (one more than needed: they settle at once).
constexpr int kMaxScreenRounds = 4;

std::string Where(const FoldTask& task, const Dataset& data, const std::vector<int>& file_of,
                  int t) {
  const int f = t < static_cast<int>(file_of.size()) ? file_of[t] : -1;
  const std::string file =
      f >= 0 && f < static_cast<int>(task.files.size()) ? task.files[f] : data.path;
  return file + ":" + std::to_string(data.samples[t].line);
}

CalibrationSpec FoldSpec(const FoldTask& task) {
  CalibrationSpec spec;
  spec.parameters = task.parameters;
  spec.forward_model = task.forward_model;
  spec.tension_sigma_n = task.tension_sigma_n;
  spec.tension_sigma_percent = task.tension_sigma_percent;
  return spec;
}

// The model's readings, white sigmas and residuals over them at the point, and the warm
// starts there. Returns the first sample the statics cannot solve, or -1.
struct Prediction {
  ReadingArrays reading_n, sigma_n, x;
  internal::CompactStarts starts;
};
int Predict(const FoldTask& task, const internal::CalibrationModel& cm, const Dataset& data,
            const StaticsOptions& statics, Prediction* at) {
  StaticsParameters<double> params;
  std::array<double, kNumCables> gain, bias;
  cm.Assemble(task.theta_si.data(), &params, &gain, &bias);
  const int n = static_cast<int>(data.samples.size());
  at->reading_n.resize(n);
  at->sigma_n.resize(n);
  at->x.resize(n);
  at->starts = internal::CompactStarts(statics.method);
  at->starts.Reset(n);
  StaticsOptions options = statics;
  options.warm_start = true;
  return internal::ForEachChunk(n, task.threads, [&](int begin, int end) {
    StaticsSolution solution;
    for (int t = begin; t < end; ++t) {
      const Sample& s = data.samples[t];
      // Consecutive samples are close: each starts from the one before in its chunk.
      if (t == begin) solution.status = StaticsStatus::kInvalidInput;
      if (SolveStaticsWithParameters(params, s.pose, options, &solution) != StaticsStatus::kOk) {
        return t;
      }
      at->starts.Set(t, solution);
      for (int i = 0; i < kNumCables; ++i) {
        at->reading_n[t][i] = gain[i] * solution.cables[i].lower_tension_n + bias[i];
      }
      at->sigma_n[t] = internal::TensionSigmas(at->reading_n[t], task.tension_sigma_n,
                                               task.tension_sigma_percent);
      for (int i = 0; i < kNumCables; ++i) {
        at->x[t][i] = (at->reading_n[t][i] - s.tension_n[i]) / at->sigma_n[t][i];
      }
    }
    return -1;
  });
}

// The gross errors among the innovations (all of them judged): screened, whitened again
// with them left out of the filter (a gross error that updated it would spoil the
// innovations after it), screened again, until the set stands.
void ScreenWindow(const FoldTask& task, const internal::PredictionView& view, const Prediction& at,
                  ReadingMask* excluded) {
  const int n = static_cast<int>(at.x.size());
  excluded->assign(n, {});
  if (!task.detect_gross_errors) return;
  for (int round = 0; round < kMaxScreenRounds; ++round) {
    ReadingArrays whitened = at.x;
    internal::WhitenPrediction(task.slow_error, view, &whitened);
    GrossErrorScreen screen = ScreenGrossErrors(whitened, {}, task.gross_error_threshold_sigmas);
    if (screen.flagged == *excluded) return;
    *excluded = std::move(screen.flagged);
  }
}

// The RMS sums, the gross errors named and the run of residuals the slow-error estimate
// reads.
void Summarise(const FoldTask& task, const Dataset& data, const std::vector<int>& file_of,
               const internal::PredictionView& view, const Prediction& at,
               const ReadingMask& excluded, WindowFold* fold) {
  const int n = static_cast<int>(data.samples.size());
  ReadingArrays whitened = at.x;
  internal::WhitenPrediction(task.slow_error, view, &whitened);
  for (int t = 0; t < n; ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      const double e = at.reading_n[t][i] - data.samples[t].tension_n[i];
      if (!excluded[t][i]) {
        fold->sum_sq_n2[i] += e * e;
        ++fold->count[i];
        continue;
      }
      ++fold->gross_error_count;
      if (static_cast<int>(fold->gross_errors.size()) >= kMaxFoldGrossErrors) continue;
      FoldGrossError g;
      g.file = t < static_cast<int>(file_of.size()) ? file_of[t] : 0;
      g.line = data.samples[t].line;
      g.cable = i + 1;
      g.measured_n = data.samples[t].tension_n[i];
      g.predicted_n = at.reading_n[t][i];
      g.residual_sigma = whitened[t][i];
      fold->gross_errors.push_back(g);
    }
  }
  // The run: the middle of the window (away from its edges, where the cabin may park).
  const int run = std::min(n, std::max(0, task.residual_samples));
  const int first = (n - run) / 2;
  for (int t = first; t < first + run; ++t) {
    FoldResidual r;
    r.time_s = data.samples[t].time_s;
    r.x = at.x[t];
    r.sigma_n = at.sigma_n[t];
    r.reading_n = at.reading_n[t];
    r.excluded = excluded[t];
    fold->residuals.push_back(r);
  }
}

// The whitened rows folded block by block (a block is one chunk of the ordered pass).
bool FoldRowsInBlocks(const FoldTask& task, const internal::FittedSamples& samples,
                      const std::vector<int>& block_columns, WindowFold* fold, int* failed) {
  const int n = samples.model->num_free();
  const int count = samples.size();
  const int blocks = std::max(1, task.blocks);
  const int block = std::max(kMinBlockSamples, (count + blocks - 1) / blocks);
  struct Part {
    internal::SampleRows rows;
    Eigen::MatrixXd r;  // (n + 1) x (n + 1)
  };
  Eigen::MatrixXd total;
  std::vector<Eigen::VectorXd> scores;
  internal::SampleRowWhitener whitener(samples, n + 1);
  const std::vector<double>& theta = task.theta_si;
  const internal::ModelAtTheta at(*samples.model, theta.data(), samples.sessions());
  *failed = internal::ReduceChunksInOrder<Part>(
      count, task.threads, [] { return Part(); },
      [&](int begin, int end, Part* part) {
        part->rows.Reset(begin, end, n + 1);
        for (int t = begin; t < end; ++t) {
          if (!internal::EvaluateSampleRows(samples, t, at, t, &part->rows)) return t;
        }
        return -1;
      },
      [&](int, int, Part* part) { whitener.Whiten(&part->rows); },
      [&](int begin, int end, Part* part) {
        const Eigen::Map<
            const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
            rows(part->rows.values.data(), kNumCables * (end - begin), n + 1);
        part->r = internal::FoldRows(Eigen::MatrixXd(), rows);
        return -1;
      },
      [&](const Part& part) {
        const Eigen::MatrixXd rj = part.r.topLeftCorner(part.r.rows(), n);
        const Eigen::VectorXd zj = part.r.col(n);
        scores.push_back(rj.transpose() * zj);
        const Eigen::MatrixXd info = rj.transpose() * rj;
        Eigen::MatrixXd rows_of_window(block_columns.size(), n);
        for (size_t k = 0; k < block_columns.size(); ++k) {
          rows_of_window.row(k) = info.row(block_columns[k]);
        }
        fold->block_information.push_back(rows_of_window);
        fold->block_samples.push_back(part.rows.end - part.rows.begin);
        const std::vector<Sample>& in = samples.data->samples;
        fold->block_first_time_s.push_back(in[(*samples.fit)[part.rows.begin]].time_s);
        fold->block_last_time_s.push_back(in[(*samples.fit)[part.rows.end - 1]].time_s);
        total = internal::FoldRows(total, part.r);
      },
      block);
  if (*failed >= 0) return false;
  if (total.rows() == 0) total = Eigen::MatrixXd::Zero(n + 1, n + 1);
  const Eigen::MatrixXd r = total.topLeftCorner(total.rows(), n);
  fold->information = r.transpose() * r;
  fold->gradient = r.transpose() * total.col(n);
  fold->chi_square = total.col(n).squaredNorm();
  fold->block_scores.resize(static_cast<Eigen::Index>(scores.size()), n);
  for (size_t b = 0; b < scores.size(); ++b) fold->block_scores.row(b) = scores[b].transpose();
  return true;
}

}  // namespace

std::vector<int> BlockRowColumns(const std::vector<ParameterSpec>& columns,
                                 const std::vector<FoldRole>& roles) {
  std::vector<int> out;
  for (size_t k = 0; k < roles.size() && k < columns.size(); ++k) {
    if (roles[k] == FoldRole::kWindow) out.push_back(static_cast<int>(k));
  }
  for (size_t k = 0; k < roles.size() && k < columns.size(); ++k) {
    if (roles[k] == FoldRole::kShared && columns[k].kind == ParameterKind::kSensorBias &&
        columns[k].index >= 0) {
      out.push_back(static_cast<int>(k));
    }
  }
  return out;
}

bool FoldSamples(const FoldTask& task, const Dataset& data, const std::vector<int>& file_of,
                 WindowFold* fold, std::string* error) {
  if (!task.IsValid(error)) return false;
  CableRobot model;
  if (!ParseCableRobotYaml(task.model_yaml, "the fold task's model", &model, error)) return false;
  const CalibrationSpec spec = FoldSpec(task);
  const internal::CalibrationModel cm(model, spec);
  if (cm.num_free() != static_cast<int>(task.theta_si.size())) {
    *error = "fold task " + task.label + ": " + std::to_string(task.theta_si.size()) +
             " values for " + std::to_string(cm.num_free()) + " columns";
    return false;
  }
  *fold = WindowFold();
  fold->label = task.label;
  fold->samples = static_cast<long long>(data.samples.size());
  fold->theta_si = task.theta_si;
  fold->roles = task.roles;
  fold->slow_error = task.slow_error;
  fold->gross_error_threshold_sigmas = task.gross_error_threshold_sigmas;
  std::vector<ParameterSpec> columns;
  for (int k = 0; k < cm.num_free(); ++k) {
    fold->columns.push_back(task.parameters[cm.spec_index(k)].name);
    columns.push_back(task.parameters[cm.spec_index(k)]);
  }
  const std::vector<int> block_columns = BlockRowColumns(columns, task.roles);
  const int n = static_cast<int>(data.samples.size());
  if (n == 0) {
    *error = "fold task " + task.label + ": the window has no samples";
    return false;
  }
  fold->first_time_s = data.samples.front().time_s;
  fold->last_time_s = data.samples.back().time_s;
  const StaticsOptions statics = ModelFitStaticsOptions(task.forward_model);
  Prediction at;
  const auto cannot_solve = [&](int t) {
    *error =
        Where(task, data, file_of, t) + ": the model at the track's point cannot solve this pose";
    return false;
  };
  if (const int failed = Predict(task, cm, data, statics, &at); failed >= 0) {
    return cannot_solve(failed);
  }
  std::vector<int> fit(n);
  for (int t = 0; t < n; ++t) fit[t] = t;
  ReadingMask excluded;
  internal::PredictionView view;
  view.data = &data;
  view.reading_n = &at.reading_n;
  view.sigma_n = &at.sigma_n;
  view.fit = &fit;
  view.excluded = &excluded;
  ScreenWindow(task, view, at, &excluded);
  Summarise(task, data, file_of, view, at, excluded, fold);
  const ReadingArrays rho = internal::SlowErrorRatios(task.slow_error, view);
  internal::FittedSamples samples;
  samples.model = &cm;
  samples.data = &data;
  samples.fit = &fit;
  samples.sigma_n = &at.sigma_n;
  samples.starts = &at.starts;
  samples.excluded = &excluded;
  samples.statics = statics;
  samples.slow_error = task.slow_error;
  samples.slow_rho = &rho;
  int failed = -1;
  if (!FoldRowsInBlocks(task, samples, block_columns, fold, &failed)) return cannot_solve(failed);
  for (long long c : fold->count) fold->readings += c;
  return true;
}

bool FoldWindow(const FoldTask& task, WindowFold* fold, std::string* error) {
  Dataset data;
  std::vector<int> file_of;
  if (!internal::ReadStoredWindow(task.samples_path, &data, &file_of, error)) return false;
  return FoldSamples(task, data, file_of, fold, error);
}

}  // namespace fastcal
