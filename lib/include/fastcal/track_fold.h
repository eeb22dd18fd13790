// The fold of one window of a track (track.h; docs/calibration.md, "Tracking"): the unit
// of work a track hands to a thread or to a Dask worker, and what it keeps on disk so
// that a new day's data updates the track without refolding the old days.
//
// A window's samples, at a linearisation point theta0 (its own parameters, the shared
// ones, the consider ones: the "columns", in the spec's order), give whitened rows
// [J_t r_t] per sample: r = (gain T(theta0; pose) + bias - measured) / sigma, sigma the
// white sigma from the predicted reading at theta0 (tension_sigma_kN and _percent), then
// each cable's rows whitened in time order by the slow-error filter (slow_error.h) and
// the readings the gross-error screen names (gross_errors.h: the innovations at theta0,
// judged against the window's robust scale) zeroed. Folded by QR into
//   H = J^T J (information), g = J^T r (gradient), c = r^T r (chi-square)
// the window's chi-square near theta0 is c + 2 g^T d + d^T H d, d = theta - theta0: what
// the block-arrow solve of the track needs (internal/block_arrow.h). Beside it, for the
// uncertainty and the events: per contiguous block of samples (about `blocks` of them,
// in time order) the block's score J_b^T r_b and the rows of its information of the
// window's own parameters (the block scores at another point follow linearly: the
// time-correlation check of the window's estimates), the RMS model-minus-measured per
// cable, the gross errors named, and a contiguous run of residuals over their white
// sigma for the estimate of the slow error's amplitude and time constant.
//
// FoldWindow is a pure function of the task: the same task gives the same bits on any
// machine and any number of threads (sample_chunks.h). It streams the window: two passes
// over its samples a piece at a time, keeping ~260 bytes a sample between them, so that
// a fold's memory is about a quarter of a kB per sample of its window (issue 27). Tasks and folds
// travel as bytes (SerializeFoldTask, SerializeWindowFold; little-endian IEEE doubles, the layout
// in docs/calibration.md, "Tracking: files"): a fold file in a track's DIR/folds is
// SerializeWindowFold's bytes.
#ifndef FASTCAL_TRACK_FOLD_H_
#define FASTCAL_TRACK_FOLD_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/slow_error.h"
#include "fastcal/statics.h"

namespace fastcal {

// What a column of a fold is to the track.
enum class FoldRole : int {
  kWindow = 0,    // a parameter of each window (spec sessions.separate)
  kShared = 1,    // one value for every window (or every stretch between sensor steps)
  kConsider = 2,  // fixed with a prior: held at its value, its sigma propagated
};

// The fold columns whose block information rows a fold keeps (WindowFold::
// block_information), in row order: the kWindow columns, then the kShared per-cable
// sensor biases.
std::vector<int> BlockRowColumns(const std::vector<ParameterSpec>& columns,
                                 const std::vector<FoldRole>& roles);

struct FoldTask {
  std::string label;  // the window's
  // The window's sample store (internal/window_store.h), and the data files its samples
  // came from (for messages: a sample names its file by index into this list).
  std::string samples_path;
  std::vector<std::string> files;
  std::string model_yaml;  // CableRobotToYaml: an exact round trip
  // The spec's parameters; the fold's columns are those free here, in this order (a
  // consider parameter is made free for the fold and held by the track).
  std::vector<ParameterSpec> parameters;
  std::vector<FoldRole> roles;  // per column
  StaticsMethod forward_model = StaticsMethod::kExact;
  double tension_sigma_n = 0.0;
  double tension_sigma_percent = 3.0;
  bool detect_gross_errors = true;
  double gross_error_threshold_sigmas = 5.0;  // the track's family-wise threshold
  SlowErrorProcess slow_error;                // inactive: white noise only
  std::vector<double> theta_si;               // the point, per column (SI)
  int blocks = 32;              // contiguous blocks of samples (at least 16 samples each)
  int residual_samples = 1000;  // the run of residuals kept for the slow-error estimate
  // Every `stride`-th sample of the window is folded (1: all; a new track's first steps,
  // TrackOptions::first_fold_samples), and every sample of the residual run (the middle
  // residual_samples): its slow-error estimate is then the one of a fold of every sample.
  int stride = 1;
  int threads = 1;  // threads of the passes over the samples
  // A fine scan (issue 53; WindowFold::fine): the exact whitened columns of a step of each
  // of `fine_columns` (fold columns among BlockRowColumns) at every gap between the samples
  // of blocks [fine_first_block, fine_end_block). An empty range: none (a track's folds);
  // only with stride 1.
  int fine_first_block = 0, fine_end_block = 0;
  std::vector<int> fine_columns;

  bool IsValid(std::string* error) const;
};

// A fold's fine scan (FoldTask::fine_columns; internal/step_scan.h): per cut before each
// sample of the scanned blocks, the step columns' (a step of the column from the cut on,
// whitened as the readings are) sums with every fold column and, last, the residual (the
// score: steps x (columns + 1)), and among themselves (steps x steps), from the cut to the
// window's end; the cut's first sample's time and the last before's.
struct FoldFineScan {
  std::vector<int> columns;
  std::vector<double> after_s, before_s;
  std::vector<Eigen::MatrixXd> cross, self;
  bool empty() const { return cross.empty(); }
};

// One reading named a gross error.
struct FoldGrossError {
  int file = 0;  // index into FoldTask::files
  int line = 0;
  int cable = 0;  // 1..6
  double measured_n = 0.0, predicted_n = 0.0;
  double residual_sigma = 0.0;  // the innovation over its sigma
};

// One sample of the residual run (the slow-error estimate's input).
struct FoldResidual {
  double time_s = 0.0;
  std::array<double, kNumCables> x{};          // (prediction - measured) / sigma_white
  std::array<double, kNumCables> sigma_n{};    // sigma_white
  std::array<double, kNumCables> reading_n{};  // the predicted reading
  std::array<bool, kNumCables> excluded{};
};

struct WindowFold {
  std::string label;
  long long samples = 0;
  long long readings = 0;  // readings in the fit (not gross errors)
  double first_time_s = 0.0, last_time_s = 0.0;
  std::vector<std::string> columns;  // the columns' names
  std::vector<FoldRole> roles;
  std::vector<double> theta_si;  // the point
  SlowErrorProcess slow_error;   // the process it was whitened by
  double gross_error_threshold_sigmas = 0.0;
  Eigen::MatrixXd information;  // H (n x n)
  Eigen::VectorXd gradient;     // g (n)
  double chi_square = 0.0;      // c
  // Per block, in time order: its samples, its first and last sample's time, its score
  // J^T r (blocks x n) and the rows of its information of the kWindow columns, then of the
  // kShared per-cable sensor biases (BlockRowColumns; per block rows x n, in column order):
  // a step of the window's own parameters or of a sensor inside the window's telemetry.
  std::vector<long long> block_samples;
  std::vector<double> block_first_time_s, block_last_time_s;
  Eigen::MatrixXd block_scores;
  std::vector<Eigen::MatrixXd> block_information;
  // Per cable, over the fitted readings: sum of (reading - measured)^2 (N^2) and count.
  std::array<double, kNumCables> sum_sq_n2{};
  std::array<long long, kNumCables> count{};
  long long gross_error_count = 0;
  std::vector<FoldGrossError> gross_errors;  // the first kMaxFoldGrossErrors, time order
  std::vector<FoldResidual> residuals;       // the run for the slow-error estimate
  FoldFineScan fine;                         // a fine scan's (FoldTask::fine_columns)
};

inline constexpr int kMaxFoldGrossErrors = 20;

// Folds the task's window. False, with *error naming the file and line of a sample whose
// pose the model cannot solve, or the store that cannot be read.
bool FoldWindow(const FoldTask& task, WindowFold* fold, std::string* error);
// The same on samples in memory, in time order (their pose is the attitude the fit uses);
// file_of[t] (may be empty) indexes sample t's file in task.files, for messages.
bool FoldSamples(const FoldTask& task, const Dataset& samples, const std::vector<int>& file_of,
                 WindowFold* fold, std::string* error);

std::string SerializeFoldTask(const FoldTask& task);
bool ParseFoldTask(const std::string& bytes, FoldTask* task, std::string* error);
std::string SerializeWindowFold(const WindowFold& fold);
// `source` names the bytes in messages (a file path).
bool ParseWindowFold(const std::string& bytes, const std::string& source, WindowFold* fold,
                     std::string* error);

// Runs a serialized task: the function a Dask worker calls (python/fastcal: track).
bool RunFoldTask(const std::string& task_bytes, std::string* fold_bytes, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_TRACK_FOLD_H_
