// The fold of one window (track_fold.h): predict at the point, whiten and screen, then
// the whitened rows [J z] summed into their Gram matrix G = [J z]^T [J z] (gram_fold.h),
// block by block, in time order: a window gives only G's parts (the information J^T J,
// the gradient J^T z, chi-square z^T z, each block's score and information rows).
//
// Streamed (issue 27): the window's samples are read twice, a piece of at most 1024 at a
// time, from the window store (or from memory): the first pass keeps per sample only
// what the screen and the second pass need (time, predicted reading, residual, warm
// start: ~260 bytes, against ~1.2 kB a sample with the samples, their predictions and
// their sort all in memory); the second evaluates, whitens and folds each piece's rows.
#include "fastcal/track_fold.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>

#include "fastcal/gross_errors.h"
#include "fastcal/internal/calibration_linearisation.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/calibration_slow_error.h"
#include "fastcal/internal/compact_start.h"
#include "fastcal/internal/folded_cost.h"
#include "fastcal/internal/gram_fold.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/sample_rows.h"
#include "fastcal/internal/slow_error_filter.h"
#include "fastcal/internal/step_scan.h"
#include "fastcal/internal/window_store.h"

namespace fastcal {
namespace {

using internal::ReadingArrays;

// Fewest samples in a block: below it the blocks' scores say little about time correlation.
constexpr int kMinBlockSamples = 16;
// Rounds of the gross-error screen at most (one more than needed: they settle at once).
constexpr int kMaxScreenRounds = 4;
// A fine scan's readings after its last cut that carry the steps' transients (the slow
// error's filter forgets a step's start within a few of its time constants: at FAST's
// 1.5 %, 70 s and 2 s sampling, to 1e-10 within 200 readings).
constexpr int kFineMarginSamples = 4000;
// Samples a pass reads at once: the prediction's chunk (its warm starts run along it), and
// the most a piece of a block holds (its rows: 1.5 MB at 31 columns).
constexpr int kPieceSamples = internal::kSampleChunk;

// A window's samples in time order, a range at a time (called from several threads).
struct SampleSource {
  long long size = 0;
  int sessions = 1;  // the model's sessions the samples' session indices need
  std::string name;  // for messages about a sample whose file is not known
  // Where the run of residuals for the slow-error estimate starts (-1: the middle).
  long long residual_first = -1;
  // Optional: `count` samples, every `step`-th from `first`, converting only those (else
  // Strided reads whole spans and keeps every step-th).
  std::function<bool(long long first, int count, int step, std::vector<Sample>*, std::vector<int>*,
                     std::string*)>
      read_every;
  std::function<bool(long long first, int count, std::vector<Sample>*, std::vector<int>*,
                     std::string*)>
      read;
};

// What the fold keeps of each sample from its first pass to its second (time order): 110
// bytes, and the warm start (144 bytes exact, 192 aas). The white sigma and the slow error's
// ratio follow from the reading (TensionSigmas) and are recomputed where needed.
struct WindowPrediction {
  std::vector<double> time_s;
  ReadingArrays reading_n;  // gain T + bias at the point
  ReadingArrays x;          // (reading - measured) / sigma_white
  internal::CompactStarts starts;
  ReadingMask excluded;  // gross errors
};

std::array<double, kNumCables> WhiteSigmas(const FoldTask& task,
                                           const std::array<double, kNumCables>& reading_n) {
  return internal::TensionSigmas(reading_n, task.tension_sigma_n, task.tension_sigma_percent);
}

// rho_i = sigma_slow(reading_i) / sigma_white_i (slow_error.h).
std::array<double, kNumCables> SlowRatios(const FoldTask& task,
                                          const std::array<double, kNumCables>& reading_n) {
  const std::array<double, kNumCables> sigma = WhiteSigmas(task, reading_n);
  std::array<double, kNumCables> rho;
  for (int i = 0; i < kNumCables; ++i) rho[i] = task.slow_error.SigmaN(reading_n[i]) / sigma[i];
  return rho;
}

std::string Where(const FoldTask& task, const SampleSource& source, const Sample& sample,
                  int file) {
  const std::string name =
      file >= 0 && file < static_cast<int>(task.files.size()) ? task.files[file] : source.name;
  return name + ":" + std::to_string(sample.line);
}

// Why the model at the task's point cannot solve `sample` (the statics' account, from a
// cold start: a fold's warm starts follow the samples before).
std::string WhyUnsolvable(const FoldTask& task, const internal::CalibrationModel& cm,
                          const Sample& sample) {
  StaticsParameters<double> params;
  std::array<double, kNumCables> gain, bias;
  Eigen::Vector3d measured_offset;
  cm.Assemble<double>(task.theta_si.data(), &params, &gain, &bias, 0, nullptr, &measured_offset);
  StaticsSolution solution;
  const StaticsOptions options = ModelFitStaticsOptions(task.forward_model);
  const Pose pose = cm.CabinPose(sample.pose, sample.joint, measured_offset);
  if (SolveStaticsWithParameters(params, cm.robot().moving_parts, sample.joint, pose, options,
                                 &solution) == StaticsStatus::kOk) {
    return "a warm start from the samples before fails, a cold one does not";
  }
  return DescribeStatus(solution);
}

// The first read error of a pass's threads.
struct ReadFailure {
  std::mutex mutex;
  std::string error;
  void Keep(const std::string& why) {
    std::lock_guard<std::mutex> lock(mutex);
    if (error.empty()) error = why;
  }
};

CalibrationSpec FoldSpec(const FoldTask& task) {
  CalibrationSpec spec;
  spec.parameters = task.parameters;
  spec.forward_model = task.forward_model;
  spec.tension_sigma_n = task.tension_sigma_n;
  spec.tension_sigma_percent = task.tension_sigma_percent;
  return spec;
}

// The first pass: the model's readings and the residuals over their white sigma at the
// point, and the warm starts there. Returns the first sample the statics cannot solve (or
// that cannot be read: *read_failure then says why), or -1.
int Predict(const FoldTask& task, const internal::CalibrationModel& cm, const SampleSource& source,
            const StaticsOptions& statics, WindowPrediction* at, ReadFailure* read_failure) {
  StaticsParameters<double> params;
  std::array<double, kNumCables> gain, bias;
  Eigen::Vector3d measured_offset;
  cm.Assemble<double>(task.theta_si.data(), &params, &gain, &bias, 0, nullptr, &measured_offset);
  const int n = static_cast<int>(source.size);
  at->time_s.resize(n);
  at->reading_n.resize(n);
  at->x.resize(n);
  at->starts = internal::CompactStarts(statics.method);
  at->starts.Reset(n);
  StaticsOptions options = statics;
  options.warm_start = true;
  return internal::ForEachChunk(
      n, task.threads,
      [&](int begin, int end) {
        std::vector<Sample> samples;
        std::vector<int> file_of;
        std::string why;
        if (!source.read(begin, end - begin, &samples, &file_of, &why)) {
          read_failure->Keep(why);
          return begin;
        }
        StaticsSolution solution;
        for (int t = begin; t < end; ++t) {
          const Sample& s = samples[t - begin];
          at->time_s[t] = s.time_s;
          // Consecutive samples are close: each starts from the one before in its chunk.
          if (t == begin) solution.status = StaticsStatus::kInvalidInput;
          // The cabin's pose: the data's through the measured frame (measured_frame.h).
          const Pose pose = cm.CabinPose(s.pose, s.joint, measured_offset);
          if (SolveStaticsWithParameters(params, cm.robot().moving_parts, s.joint, pose, options,
                                         &solution) != StaticsStatus::kOk) {
            return t;
          }
          at->starts.Set(t, solution);
          for (int i = 0; i < kNumCables; ++i) {
            at->reading_n[t][i] = gain[i] * solution.cables[i].lower_tension_n + bias[i];
          }
          const std::array<double, kNumCables> sigma = WhiteSigmas(task, at->reading_n[t]);
          for (int i = 0; i < kNumCables; ++i) {
            at->x[t][i] = (at->reading_n[t][i] - s.tension_n[i]) / sigma[i];
          }
        }
        return -1;
      },
      kPieceSamples);
}

// The residuals x whitened in place into innovations, in time order by the slow error's
// filters (readings in `excluded` innovated without updating them); unchanged for white
// noise (internal/calibration_slow_error.h, WhitenPrediction, over the window's arrays).
void WhitenResiduals(const FoldTask& task, const WindowPrediction& at, const ReadingMask& excluded,
                     ReadingArrays* x) {
  if (!task.slow_error.IsActive()) return;
  internal::ReadingWhitener whitener(task.slow_error, 1);
  for (size_t t = 0; t < x->size(); ++t) {
    const std::array<double, kNumCables> rho = SlowRatios(task, at.reading_n[t]);
    whitener.WhitenOnly(at.time_s[t], 0, rho.data(), excluded[t].data(), (*x)[t].data());
  }
}

// The innovations x whitened with the readings in `excluded` left out of the filter.
ReadingArrays Whitened(const FoldTask& task, const WindowPrediction& at,
                       const ReadingMask& excluded) {
  ReadingArrays whitened = at.x;
  WhitenResiduals(task, at, excluded, &whitened);
  return whitened;
}

// The gross errors among the innovations (all of them judged): screened, whitened again
// with them left out of the filter (a gross error that updated it would spoil the
// innovations after it), screened again, until the set stands. Returns the innovations
// whitened with the final set left out (the last round's, when it stood).
ReadingArrays ScreenWindow(const FoldTask& task, WindowPrediction* at) {
  const int n = static_cast<int>(at->x.size());
  at->excluded.assign(n, {});
  if (!task.detect_gross_errors) return Whitened(task, *at, at->excluded);
  for (int round = 0; round < kMaxScreenRounds; ++round) {
    ReadingArrays whitened = Whitened(task, *at, at->excluded);
    GrossErrorScreen screen = ScreenGrossErrors(whitened, {}, task.gross_error_threshold_sigmas);
    if (screen.flagged == at->excluded) return whitened;
    at->excluded = std::move(screen.flagged);
  }
  return Whitened(task, *at, at->excluded);
}

// The gross errors counted and the first ones named (their file, line and measured value
// are the second pass's: *named gets each one's sample), and the run of residuals the
// slow-error estimate reads. `whitened`: ScreenWindow's innovations.
void Summarise(const FoldTask& task, const SampleSource& source, const WindowPrediction& at,
               const ReadingArrays& whitened, WindowFold* fold, std::vector<int>* named) {
  const int n = static_cast<int>(at.x.size());
  for (int t = 0; t < n; ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      if (!at.excluded[t][i]) continue;
      ++fold->gross_error_count;
      if (static_cast<int>(fold->gross_errors.size()) >= kMaxFoldGrossErrors) continue;
      FoldGrossError g;
      g.cable = i + 1;
      g.predicted_n = at.reading_n[t][i];
      g.residual_sigma = whitened[t][i];
      fold->gross_errors.push_back(g);
      named->push_back(t);
    }
  }
  // The run: the middle of the window (away from its edges, where the cabin may park).
  const int run = std::min(n, std::max(0, task.residual_samples));
  const int first = source.residual_first >= 0
                        ? static_cast<int>(std::min<long long>(source.residual_first, n - run))
                        : (n - run) / 2;
  for (int t = first; t < first + run; ++t) {
    FoldResidual r;
    r.time_s = at.time_s[t];
    r.x = at.x[t];
    r.sigma_n = WhiteSigmas(task, at.reading_n[t]);
    r.reading_n = at.reading_n[t];
    r.excluded = at.excluded[t];
    fold->residuals.push_back(r);
  }
}

// A piece of the second pass: samples [begin, end) of one block.
struct Piece {
  int begin = 0, end = 0;
  int block = 0;
  bool last_of_block = false;
};

// Blocks of `block` samples (the last one shorter), each cut into pieces of at most
// kPieceSamples.
std::vector<Piece> Pieces(int count, int block) {
  std::vector<Piece> pieces;
  for (int b = 0, first = 0; first < count; ++b, first += block) {
    const int last = std::min(count, first + block);
    for (int begin = first; begin < last; begin += kPieceSamples) {
      Piece p;
      p.begin = begin;
      p.end = std::min(last, begin + kPieceSamples);
      p.block = b;
      p.last_of_block = p.end == last;
      pieces.push_back(p);
    }
  }
  return pieces;
}

// A piece's samples with what the rows need of them: FittedSamples over the piece.
struct PieceSamples {
  Dataset data;
  std::vector<int> file_of;
  std::vector<int> fit;  // 0 .. size - 1
  ReadingArrays sigma_n, rho;
  internal::CompactStarts starts;
  ReadingMask excluded;
  internal::FittedSamples fitted;

  // False (with *error) when the samples cannot be read.
  bool Load(const FoldTask& task, const SampleSource& source, const WindowPrediction& at,
            const internal::FittedSamples& window, const Piece& piece, std::string* error) {
    if (!source.read(piece.begin, piece.end - piece.begin, &data.samples, &file_of, error)) {
      return false;
    }
    const int m = piece.end - piece.begin;
    fit.resize(m);
    sigma_n.resize(m);
    rho.resize(task.slow_error.IsActive() ? m : 0);
    for (int j = 0; j < m; ++j) {
      fit[j] = j;
      sigma_n[j] = WhiteSigmas(task, at.reading_n[piece.begin + j]);
      if (!rho.empty()) rho[j] = SlowRatios(task, at.reading_n[piece.begin + j]);
    }
    starts = at.starts.Slice(piece.begin, piece.end);
    excluded.assign(at.excluded.begin() + piece.begin, at.excluded.begin() + piece.end);
    fitted = window;
    fitted.data = &data;
    fitted.fit = &fit;
    fitted.sigma_n = &sigma_n;
    // The first pass's solutions at the same point: the rows need not solve again. Only
    // with one session: the first pass assembles the model of session 0 for every sample.
    fitted.starts = &starts;
    fitted.starts_solved = source.sessions == 1;
    fitted.excluded = &excluded;
    fitted.slow_rho = rho.empty() ? nullptr : &rho;
    return true;
  }
};

// The second pass's sums over the pieces in time order: per cable the squared misfits, the
// named gross errors' file, line and measured value, and each block's rows summed.
struct BlockSums {
  const WindowPrediction& at;
  const std::vector<int>& block_columns;
  const std::vector<int>& named;  // the sample of each of fold->gross_errors
  int n = 0;
  internal::GramFold block, total;
  WindowFold* fold;

  void Add(const Piece& piece, const PieceSamples& p, internal::GramFold& rows) {
    const std::vector<Sample>& in = p.data.samples;
    for (int t = piece.begin; t < piece.end; ++t) {
      const Sample& s = in[t - piece.begin];
      for (int i = 0; i < kNumCables; ++i) {
        if (at.excluded[t][i]) continue;
        const double e = at.reading_n[t][i] - s.tension_n[i];
        fold->sum_sq_n2[i] += e * e;
        ++fold->count[i];
      }
    }
    for (size_t g = 0; g < named.size(); ++g) {
      if (named[g] < piece.begin || named[g] >= piece.end) continue;
      FoldGrossError& e = fold->gross_errors[g];
      e.file = std::max(0, p.file_of[named[g] - piece.begin]);
      e.line = in[named[g] - piece.begin].line;
      e.measured_n = in[named[g] - piece.begin].tension_n[e.cable - 1];
    }
    if (static_cast<int>(fold->block_samples.size()) == piece.block) {
      fold->block_samples.push_back(0);
      fold->block_first_time_s.push_back(in.front().time_s);
      fold->block_last_time_s.push_back(0.0);
    }
    fold->block_samples.back() += piece.end - piece.begin;
    fold->block_last_time_s.back() = in.back().time_s;
    block.Add(rows);
    if (piece.last_of_block) CloseBlock();
  }

  // The block's score J_b^T z_b and its information rows of the block columns, its sums
  // into the window's.
  void CloseBlock() {
    block.Flush();
    const Eigen::MatrixXd g = block.Gram();
    fold->block_scores.conservativeResize(fold->block_scores.rows() + 1, n);
    fold->block_scores.row(fold->block_scores.rows() - 1) = g.col(n).head(n).transpose();
    Eigen::MatrixXd rows_of_window(block_columns.size(), n);
    for (size_t k = 0; k < block_columns.size(); ++k) {
      rows_of_window.row(k) = g.row(block_columns[k]).head(n);
    }
    fold->block_information.push_back(rows_of_window);
    total.Add(block);
    block.Reset();
  }
};

// The recorder of a fine scan's readings (FoldTask::fine_columns; null: none), told of the
// whitening from the first sample of its first block to kFineMarginSamples past its last.
std::unique_ptr<internal::StepScanRecorder> FineRecorder(const FoldTask& task, int count,
                                                         int block_samples, int n) {
  if (task.fine_columns.empty() || task.fine_end_block <= task.fine_first_block) return nullptr;
  const long long first = std::min<long long>(count, 1LL * task.fine_first_block * block_samples);
  const long long end = std::min<long long>(count, 1LL * task.fine_end_block * block_samples);
  const long long captured = std::min<long long>(count, end + kFineMarginSamples) - first;
  if (end <= first) return nullptr;
  return std::make_unique<internal::StepScanRecorder>(
      n + 1, task.fine_columns, first, static_cast<int>(end - first), static_cast<int>(captured));
}

// The fine scan from its recorder: the rows after its cuts are the window's blocks' from
// fine_end_block on (their sums of the step columns' rows and scores).
void FinishFineScan(const FoldTask& task, const WindowPrediction& at,
                    const std::vector<int>& block_columns, internal::StepScanRecorder* recorder,
                    WindowFold* fold) {
  internal::StepScanInput& in = recorder->input();
  const int n = in.columns - 1;
  const int nf = static_cast<int>(in.steps.size());
  in.after = Eigen::MatrixXd::Zero(nf, n + 1);
  for (int f = 0; f < nf; ++f) {
    const int row = static_cast<int>(
        std::find(block_columns.begin(), block_columns.end(), in.steps[f]) - block_columns.begin());
    for (size_t b = task.fine_end_block; b < fold->block_information.size(); ++b) {
      in.after.row(f).head(n) += fold->block_information[b].row(row);
      in.after(f, n) += fold->block_scores(b, in.steps[f]);
    }
  }
  internal::StepScan scan = internal::ScanSteps(in);
  const long long first = recorder->first();
  FoldFineScan& out = fold->fine;
  out.columns = in.steps;
  for (int k = 0; k < in.cuts; ++k) {
    out.after_s.push_back(at.time_s[first + k]);
    out.before_s.push_back(first + k > 0 ? at.time_s[first + k - 1] : at.time_s[first + k]);
  }
  out.cross = std::move(scan.cross);
  out.self = std::move(scan.self);
}

// The second pass: the whitened rows folded piece by piece, in time order, into the blocks
// and the window. Returns the first sample the statics cannot solve (or that cannot be
// read), or -1.
int FoldRowsInBlocks(const FoldTask& task, const SampleSource& source, const WindowPrediction& at,
                     const internal::FittedSamples& window, const std::vector<int>& block_columns,
                     const std::vector<int>& named, WindowFold* fold, ReadFailure* read_failure) {
  const int n = window.model->num_free();
  const int count = static_cast<int>(source.size);
  const int blocks = std::max(1, task.blocks);
  const int block_samples = std::max(kMinBlockSamples, (count + blocks - 1) / blocks);
  const std::vector<Piece> pieces = Pieces(count, block_samples);
  std::unique_ptr<internal::StepScanRecorder> fine = FineRecorder(task, count, block_samples, n);
  struct Part {
    int piece = 0;
    PieceSamples samples;
    internal::SampleRows rows;
    internal::GramFold fold;
  };
  std::vector<int> failed_sample(pieces.size(), -1);
  BlockSums sums{at,  block_columns, named, n, internal::GramFold(n + 1), internal::GramFold(n + 1),
                 fold};
  fold->block_scores.resize(0, n);
  internal::SampleRowWhitener whitener(window, n + 1);
  if (fine != nullptr) whitener.set_observer(fine.get());
  const internal::ModelAtTheta model_at(*window.model, task.theta_si.data(), source.sessions);
  // Each reading's rows over its own columns first where its sensor has some (issue 41:
  // the full-width QR fold was a sixth of a track's time; folded_cost.h, ReadingColumns).
  const std::vector<std::vector<int>> reading_columns = internal::ReadingColumns(window, nullptr);
  const int failed = internal::ReduceChunksInOrder<Part>(
      static_cast<int>(pieces.size()), task.threads, [] { return Part(); },
      [&](int k, int, Part* part) {
        const Piece& piece = pieces[k];
        part->piece = k;
        std::string why;
        if (!part->samples.Load(task, source, at, window, piece, &why)) {
          read_failure->Keep(why);
          failed_sample[k] = piece.begin;
          return k;
        }
        const int m = piece.end - piece.begin;
        part->rows.Reset(0, m, n + 1);
        for (int j = 0; j < m; ++j) {
          if (!internal::EvaluateSampleRows(part->samples.fitted, j, model_at, j, &part->rows)) {
            failed_sample[k] = piece.begin + j;
            return k;
          }
        }
        return -1;
      },
      [&](int, int, Part* part) {
        whitener.Whiten(part->samples.fitted, &part->rows);
        if (fine == nullptr) return;
        const int begin = pieces[part->piece].begin;
        for (int j = 0; j < part->rows.end; ++j) fine->Rows(begin + j, part->rows.Of(j));
      },
      [&](int k, int, Part* part) {
        const Piece& piece = pieces[k];
        part->fold = internal::GramFold(n + 1);
        const int m = piece.end - piece.begin;
        if (reading_columns.empty()) {
          for (int j = 0; j < m; ++j) {
            for (int i = 0; i < kNumCables; ++i) part->fold.Add(part->rows.Row(j, i));
          }
          part->fold.Flush();
          return -1;
        }
        internal::GroupedGramFold grouped(reading_columns);
        for (int j = 0; j < m; ++j) {
          for (int i = 0; i < kNumCables; ++i) grouped.Add(i, part->rows.Row(j, i));
        }
        grouped.FlushInto(&part->fold);
        return -1;
      },
      [&](Part& part) { sums.Add(pieces[part.piece], part.samples, part.fold); }, 1);
  if (failed >= 0) return failed_sample[failed];
  sums.total.Flush();
  const Eigen::MatrixXd g = sums.total.Gram();
  fold->information = g.topLeftCorner(n, n);
  fold->gradient = g.col(n).head(n);
  fold->chi_square = g(n, n);
  if (fine != nullptr) FinishFineScan(task, at, block_columns, fine.get(), fold);
  return -1;
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

namespace {

// No row of a file given twice in the window (issue 37: a file holding its rows twice was
// folded twice, exit 0). In time order (stable) the copies lie in one run of equal times;
// two samples there whose residuals agree to 1e-3 sigma on every cable are read back and
// compared: the same file and time, and the pose, joints and tensions the same to the
// digits an export keeps, is one row given twice. Samples of two files at one instant
// are the overlap check's (track.cc), allowed by --keep-overlapping. Runs of equal times longer
// than kMaxEqualTimes (coarse time stamps) are compared over their first kMaxEqualTimes.
bool NoSampleTwice(const FoldTask& task, const SampleSource& source, const WindowPrediction& at,
                   std::string* error) {
  constexpr int kMaxEqualTimes = 64;
  constexpr double kAlikeSigmas = 1e-3;  // candidates only: confirmed on the raw samples
  // A copy written with fewer digits (9 significant: a second re-check) is the same row:
  // FAST's readings differ between two samples by far more (3% noise, the cabin moving).
  constexpr double kSamePositionM = 1e-5, kSameRotation = 1e-7, kSameTensionRelative = 1e-5;
  constexpr double kSameJoint = 1e-6;  // in the file's units (deg or m)
  const auto same = [&](const Sample& s, const Sample& t) {
    bool alike = (s.pose.position_m - t.pose.position_m).cwiseAbs().maxCoeff() <= kSamePositionM &&
                 (s.pose.rotation - t.pose.rotation).cwiseAbs().maxCoeff() <= kSameRotation;
    for (int i = 0; i < kNumCables && alike; ++i) {
      alike = std::abs(s.tension_n[i] - t.tension_n[i]) <=
              kSameTensionRelative * std::max(std::abs(s.tension_n[i]), std::abs(t.tension_n[i]));
    }
    for (size_t j = 0; j < s.joint.size() && alike; ++j) {
      alike = std::abs(s.joint[j] - t.joint[j]) <= kSameJoint;
    }
    return alike;
  };
  const int n = static_cast<int>(at.time_s.size());
  for (int a = 0; a < n;) {
    int b = a + 1;
    while (b < n && at.time_s[b] == at.time_s[a]) ++b;
    const int end = std::min(b, a + kMaxEqualTimes);
    for (int p = a; p < end; ++p) {
      for (int q = p + 1; q < end; ++q) {
        bool alike = true;  // to the statics' convergence (each warm from its neighbour)
        for (int i = 0; i < kNumCables && alike; ++i) {
          alike = std::abs(at.x[p][i] - at.x[q][i]) <= kAlikeSigmas;
        }
        if (!alike) continue;
        std::vector<Sample> one, two;
        std::vector<int> file_one, file_two;
        if (!source.read(p, 1, &one, &file_one, error) ||
            !source.read(q, 1, &two, &file_two, error)) {
          return false;
        }
        const Sample& s = one[0];
        const Sample& t = two[0];
        if (file_one[0] != file_two[0] || !same(s, t)) continue;
        *error = Where(task, source, t, file_two[0]) + " repeats line " + std::to_string(s.line) +
                 " (the same time, pose and tensions): each sample is folded once; remove "
                 "the repeated rows from the file";
        return false;
      }
    }
    a = b;
  }
  return true;
}

// Every `stride`-th sample of `all` (its first, then every stride-th after it), but the
// middle `run` samples, the run of residuals the slow-error estimate reads (Summarise),
// all of them: a subsample's fold then gives the estimate a fold of every sample gives
// (its residuals a step away; of every k-th sample, they spanned k times the time). Read
// in spans of at most kStridedSpanSamples (a large stride reads its samples one by one:
// the fold's memory stays that of a piece whatever the stride).
constexpr int kStridedSpanSamples = 4096;
SampleSource Strided(const SampleSource& all, int stride, int run) {
  // The sample positions in three parts: [0, run_first) strided, the run, then strided
  // from run_end.
  run = static_cast<int>(std::min<long long>(all.size, std::max(0, run)));
  const long long run_first = (all.size - run) / 2, run_end = run_first + run;
  const long long before = (run_first + stride - 1) / stride;
  const long long after = (all.size - run_end + stride - 1) / stride;
  SampleSource s = all;
  s.size = before + run + after;
  s.residual_first = before;
  // Samples [from, from + count) of one part, every `step`-th from position `at`.
  const auto read_part = [all](long long at, int step, int count, std::vector<Sample>* samples,
                               std::vector<int>* files, std::string* why) {
    std::vector<Sample> span;
    std::vector<int> span_files;
    const int per_span = std::max(1, (kStridedSpanSamples - 1) / step + 1);
    for (int k = 0; k < count; k += per_span) {
      const int m = std::min(per_span, count - k);
      const long long from = at + static_cast<long long>(k) * step;
      if (all.read_every) {
        if (!all.read_every(from, m, step, &span, &span_files, why)) return false;
        for (int j = 0; j < m; ++j) {
          samples->push_back(std::move(span[j]));
          files->push_back(span_files[j]);
        }
        continue;
      }
      const int length = static_cast<int>(
          std::min<long long>(all.size - from, static_cast<long long>(m - 1) * step + 1));
      if (!all.read(from, length, &span, &span_files, why)) return false;
      for (int j = 0; j < m; ++j) {
        samples->push_back(std::move(span[static_cast<size_t>(j) * step]));
        files->push_back(span_files[static_cast<size_t>(j) * step]);
      }
    }
    return true;
  };
  s.read_every = nullptr;  // all's, over all's indices
  s.read = [=](long long first, int count, std::vector<Sample>* samples, std::vector<int>* files,
               std::string* why) {
    samples->clear();
    files->clear();
    const long long last = first + count;  // source indices [first, last)
    if (first < 0 || count < 0 || last > before + run + after) {
      *why = all.name + ": samples " + std::to_string(first) + " to " + std::to_string(last) +
             " of a subsample of " + std::to_string(before + run + after);
      return false;
    }
    const long long bounds[4] = {0, before, before + run, before + run + after};
    const long long starts[3] = {0, run_first, run_end};
    const int steps[3] = {stride, 1, stride};
    for (int part = 0; part < 3; ++part) {
      const long long lo = std::max(first, bounds[part]), hi = std::min(last, bounds[part + 1]);
      if (lo >= hi) continue;
      const long long at = starts[part] + (lo - bounds[part]) * steps[part];
      if (!read_part(at, steps[part], static_cast<int>(hi - lo), samples, files, why)) {
        return false;
      }
    }
    return true;
  };
  return s;
}

// The task checked and its model read (once a fold: FoldWindow needs the model's joints
// before it reads the store).
bool ModelOfTask(const FoldTask& task, CableRobot* model, std::string* error) {
  return task.IsValid(error) &&
         ParseCableRobotYaml(task.model_yaml, "the fold task's model", model, error);
}

// The fold of the window `all` reads (or of its subsample, the task's stride): the first
// pass (predictions), the screen, the summary, the second pass (rows). `model`: the task's
// (ModelOfTask).
bool FoldSource(const FoldTask& task, const CableRobot& model, const SampleSource& all,
                WindowFold* fold, std::string* error) {
  const SampleSource source =
      task.stride > 1 ? Strided(all, task.stride, task.residual_samples) : all;
  const CalibrationSpec spec = FoldSpec(task);
  const internal::CalibrationModel cm(model, spec);
  if (cm.num_free() != static_cast<int>(task.theta_si.size())) {
    *error = "fold task " + task.label + ": " + std::to_string(task.theta_si.size()) +
             " values for " + std::to_string(cm.num_free()) + " columns";
    return false;
  }
  if (source.size == 0) {
    *error = "fold task " + task.label + ": the window has no samples";
    return false;
  }
  if (source.size > std::numeric_limits<int>::max() / kNumCables) {
    *error = "fold task " + task.label + ": " + std::to_string(source.size) +
             " samples in one window; cut the track into shorter windows";
    return false;
  }
  *fold = WindowFold();
  fold->label = task.label;
  fold->samples = source.size;
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
  const StaticsOptions statics = ModelFitStaticsOptions(task.forward_model);
  ReadFailure read_failure;
  const auto failed_at = [&](int t) {
    if (!read_failure.error.empty()) {
      *error = read_failure.error;
      return false;
    }
    std::vector<Sample> sample;
    std::vector<int> file_of;
    if (!source.read(t, 1, &sample, &file_of, error)) return false;
    *error = Where(task, source, sample[0], file_of[0]) +
             ": the model at the track's point cannot solve this pose: " +
             WhyUnsolvable(task, cm, sample[0]) +
             " (--skip-invalid-rows leaves out the samples the initial model cannot solve)";
    return false;
  };
  WindowPrediction at;
  if (const int failed = Predict(task, cm, source, statics, &at, &read_failure); failed >= 0) {
    return failed_at(failed);
  }
  if (!NoSampleTwice(task, source, at, error)) return false;
  fold->first_time_s = at.time_s.front();
  fold->last_time_s = at.time_s.back();
  std::vector<int> named;
  Summarise(task, source, at, ScreenWindow(task, &at), fold, &named);
  internal::FittedSamples window;
  window.model = &cm;
  window.statics = statics;
  window.slow_error = task.slow_error;
  // Each piece brings its own ratios; non-null here so that the whitener is made active.
  const ReadingArrays no_ratios;
  window.slow_rho = &no_ratios;
  if (const int failed =
          FoldRowsInBlocks(task, source, at, window, block_columns, named, fold, &read_failure);
      failed >= 0) {
    return failed_at(failed);
  }
  for (long long c : fold->count) fold->readings += c;
  return true;
}

}  // namespace

bool FoldSamples(const FoldTask& task, const Dataset& data, const std::vector<int>& file_of,
                 WindowFold* fold, std::string* error) {
  SampleSource source;
  source.size = static_cast<long long>(data.samples.size());
  source.sessions = std::max<int>(1, static_cast<int>(data.session_labels.size()));
  source.name = data.path;
  source.read = [&](long long first, int count, std::vector<Sample>* samples,
                    std::vector<int>* files, std::string*) {
    samples->assign(data.samples.begin() + first, data.samples.begin() + first + count);
    files->assign(count, -1);
    for (int k = 0; k < count && first + k < static_cast<long long>(file_of.size()); ++k) {
      (*files)[k] = file_of[first + k];
    }
    return true;
  };
  CableRobot model;
  return ModelOfTask(task, &model, error) && FoldSource(task, model, source, fold, error);
}

bool FoldWindow(const FoldTask& task, WindowFold* fold, std::string* error) {
  // The store's records carry the model's joints (window_store.h).
  CableRobot model;
  if (!ModelOfTask(task, &model, error)) return false;
  internal::StoredWindowReader reader;
  if (!reader.Open(task.samples_path, model.moving_parts.num_joints(), error)) return false;
  SampleSource source;
  source.size = reader.size();
  source.name = task.samples_path;
  source.read = [&](long long first, int count, std::vector<Sample>* samples,
                    std::vector<int>* files,
                    std::string* why) { return reader.Read(first, count, samples, files, why); };
  source.read_every = [&](long long first, int count, int step, std::vector<Sample>* samples,
                          std::vector<int>* files, std::string* why) {
    return reader.ReadEvery(first, count, step, samples, files, why);
  };
  return FoldSource(task, model, source, fold, error);
}

}  // namespace fastcal
