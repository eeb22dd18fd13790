// `fastcal evaluate` on a file too long to hold (10^6 samples and more): the statistics of
// evaluation.h and the gross-error screen of evaluation_screen.h, computed with memory
// independent of the number of samples, and the same numbers, bit for bit, as the
// whole-file path (EvaluateModel, ScreenEvaluation, WithoutGrossErrors).
//
// Pass 1 reads the file a chunk at a time (DatasetChunkReader), predicts each sample
// (TensionPredictor: exact statics warm started from the sample before, across chunks),
// accumulates the per-cable statistics (ErrorStatsAccumulator) and appends one fixed-size
// binary record per sample (line, time, session, position, measured and predicted
// readings: 8 (12 + 6 V) bytes for V variants, 144 or 192 bytes) to an unnamed temporary
// file (in options.temporary_directory, $TMPDIR or /tmp: on disk, deleted when closed),
// which the later passes read back.
//
// The robust centre and scale of the screen (gross_errors.h: median and 1.4826 MAD of
// each cable's whitened residuals) are exact: each median is found by selection passes
// over the temporary file (internal::ExactSelection, internal/exact_selection.h: a histogram of
// 4096 bins narrows the rank to one bin until at most 65536 values remain, which are sorted), 4 to
// 6 passes. The same for the report's trajectory test (the median step between samples).
#ifndef FASTCAL_EVALUATION_STREAM_H_
#define FASTCAL_EVALUATION_STREAM_H_

#include <Eigen/Core>
#include <array>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/evaluation_screen.h"
#include "fastcal/internal/exact_selection.h"
#include "fastcal/statics.h"
#include "fastcal/unsolvable_rows.h"

namespace fastcal {

// One evaluated sample as the temporary file holds it.
struct EvaluatedSample {
  long long index = 0;  // 0-based, among the samples kept
  int line = 0;
  double time_s = 0.0;
  int session = 0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  std::array<double, kNumCables> measured_n{};
  // Per variant of StreamedEvaluation::variants that has predictions (the first ones).
  std::vector<std::array<double, kNumCables>> predicted_n;
  std::array<bool, kNumCables> gross{};  // the screen's gross errors (after Run)
};

struct EvaluationStreamOptions {
  StaticsMethod method = StaticsMethod::kExact;
  // skip_invalid_rows also removes the samples the model cannot solve (as
  // SkipUnsolvableSamples, at each attitude with `method`), listed after the rows the
  // reader skipped.
  DatasetReadOptions read;
  // Samples read, predicted and written at a time; bounds the memory of pass 1.
  size_t chunk_samples = 8192;
  // The screen's noise model and threshold floor (ScreenEvaluation's).
  CalibrationSpec spec;
  // Gross errors named in screen.gross_errors, the first in file order; the counts
  // (screen.count, count_per_cable) are exact however many there are.
  size_t max_named_gross_errors = 10000;
  // Where the temporary file goes (unnamed: O_TMPFILE, or made and unlinked at once);
  // empty: $TMPDIR when set, else /tmp.
  std::string temporary_directory;
};

enum class EvaluationStreamStatus {
  kOk,
  kInvalidInput,  // the file: unreadable, a bad header or row (ReadDataset's messages)
  kUnsolvable,    // a pose the model cannot hold (without skip_invalid_rows), or every
                  // sample skipped, or the model likely wrong (see `diagnosis`)
  kSystemError,   // the machine: the temporary file could not be made, written or read
                  // back (a full disk); the message names its directory
};

class StreamedEvaluation {
 public:
  StreamedEvaluation() = default;
  StreamedEvaluation(const StreamedEvaluation&) = delete;
  StreamedEvaluation& operator=(const StreamedEvaluation&) = delete;
  ~StreamedEvaluation();

  // Evaluates `robot` on the file at `paths` (several: one session each, merged as
  // ReadSessionDatasets merges them, with its messages; each file is then read twice,
  // once to check it and learn its sessions): the variants of EvaluateModel ("model,
  // planned attitude" when the data has it, then "model, measured attitude"), the screen
  // against the last, and the rows "... - gross errors" (when the screen names any).
  EvaluationStreamStatus Run(const CableRobot& robot, const std::vector<std::string>& paths,
                             const EvaluationStreamOptions& options, std::string* error);

  // Calls `visit` with every kept sample, in file order (reading the temporary file).
  bool ForEach(const std::function<void(const EvaluatedSample&)>& visit, std::string* error) const;

  // The path, column flags, session labels and skipped rows (no samples).
  const Dataset& layout() const { return layout_; }
  long long samples() const { return samples_; }
  double time_min_s() const { return time_min_s_; }
  double time_max_s() const { return time_max_s_; }
  // The median distance between consecutive positions and the RMS distance of the
  // positions from their mean (internal::IsTrajectory's two numbers), exact.
  double median_step_m() const { return median_step_m_; }
  double position_spread_m() const { return position_spread_m_; }
  // As EvaluateModel then WithoutGrossErrors; predicted_n left empty.
  const std::vector<VariantEvaluation>& variants() const { return variants_; }
  // How many of variants() have predictions (in EvaluatedSample::predicted_n).
  int predicted_variants() const { return predicted_variants_; }
  // As ScreenEvaluation, without `excluded` (EvaluatedSample::gross holds it).
  const EvaluationScreen& screen() const { return screen_; }
  // With skip_invalid_rows: DiagnoseUnsolvableRows over every valid row (the model's
  // failures and whether the nominal model solves them); otherwise filled only when
  // Run failed on a pose (kUnsolvable), over every row of the file.
  const UnsolvableRows& diagnosis() const { return diagnosis_; }

 private:
  struct Pass1;
  bool ReadRecord(std::FILE* file, EvaluatedSample* s) const;
  // The whitened residuals of the screened (last predicted) variant's readings.
  std::array<double, kNumCables> Whitened(const std::array<double, kNumCables>& predicted_n,
                                          const std::array<double, kNumCables>& measured_n) const;
  // Selection passes over the temporary file: `feed` gives each sample's values to the
  // selection; `first_pass`, if given, sees every sample of the first pass too.
  bool Select(internal::ExactSelection* selection,
              const std::function<void(const EvaluatedSample&, internal::ExactSelection*)>& feed,
              std::string* error) const;
  // Pass 1 on one chunk: skip (with skip_invalid_rows), predict, sum, spill. False when
  // a pose cannot be solved (*unsolvable) or the temporary file cannot be written.
  bool PassOneChunk(const CableRobot& robot, const EvaluationStreamOptions& options, Dataset* chunk,
                    Pass1* p, bool* unsolvable, std::string* error);
  EvaluationStreamStatus Failure(const CableRobot& robot, const std::vector<std::string>& paths,
                                 const EvaluationStreamOptions& options, std::string* error);
  // Several files: checks them and merges their sessions (merged_, session_maps_).
  bool Prepare(const std::vector<std::string>& paths, const EvaluationStreamOptions& options,
               std::string* error);
  // The files' chunks in order, as one dataset's (merged sessions and planned flag);
  // `visit` returning false stops them. False, with ReadDataset's message, on a read
  // error.
  bool Chunks(const std::vector<std::string>& paths, const EvaluationStreamOptions& options,
              const std::function<bool(Dataset*)>& visit, std::string* error);
  bool Append(const Sample& s, const std::vector<std::array<double, kNumCables>>& predicted,
              Pass1* p, std::string* error);
  bool Screen(const EvaluationStreamOptions& options, std::string* error);
  bool Trajectory(std::string* error);
  bool GrossErrorRows(const EvaluationStreamOptions& options, std::string* error);
  // "evaluation: cannot <what> its temporary file in <dir> (...): <strerror(err)>".
  std::string SpillError(const std::string& what, int err) const;

  Dataset layout_;
  Dataset merged_;  // path, column groups and sessions of the data (no samples)
  std::vector<std::vector<int>> session_maps_;  // several files: file's session -> merged
  long long samples_ = 0;
  double time_min_s_ = 0.0, time_max_s_ = 0.0;
  Eigen::Vector3d position_sum_m_ = Eigen::Vector3d::Zero();
  double median_step_m_ = 0.0, position_spread_m_ = 0.0;
  std::vector<VariantEvaluation> variants_;
  int predicted_variants_ = 0;
  EvaluationScreen screen_;
  UnsolvableRows diagnosis_;
  double sigma_abs_n_ = 0.0, sigma_percent_ = 0.0;  // the screen's noise model
  std::array<long long, kNumCables> finite_{};      // finite whitened residuals per cable
  std::FILE* spill_ = nullptr;
  std::string spill_directory_;
};

}  // namespace fastcal

#endif  // FASTCAL_EVALUATION_STREAM_H_
