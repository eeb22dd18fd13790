// Model against measurement: per-cable statistics of (model - measured) lower-end
// tension, the paper's Table 6. The model's prediction of what sensor i reads is
//   predicted_i = gain_i * T_i(model, pose) + bias_i
// with T_i the lower-end tension (statics.h) and the sensor gain and bias of the model
// file (identity unless calibrated).
#ifndef FASTCAL_EVALUATION_H_
#define FASTCAL_EVALUATION_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/dataset.h"
#include "fastcal/statics.h"

namespace fastcal {

enum class AttitudeSource { kMeasured, kPlanned };

struct CableErrorStats {
  int samples = 0;
  // Readings left out per cable (gross errors, when the caller excludes them); the
  // statistics of cable i are over samples - excluded[i] readings.
  std::array<int, kNumCables> excluded{};
  std::array<double, kNumCables> mean_n{};     // mean of model - measured
  std::array<double, kNumCables> rms_n{};      // RMS of model - measured
  std::array<double, kNumCables> max_abs_n{};  // largest |model - measured|
  // RMS and largest |.| of 100 (model - measured) / model: percent of the predicted
  // reading, which is > 0 wherever the model holds the pose, so a dropout reading of
  // 0 kN cannot make it infinite (readings whose prediction is <= 0 are left out of these).
  std::array<double, kNumCables> rms_percent{};
  std::array<double, kNumCables> max_abs_percent{};
};

// Predicted sensor readings (N) for every sample. Uses the planned attitude when asked
// (the dataset must have it). Fails naming the file and line of a sample whose pose the
// model cannot hold.
bool PredictTensions(const CableRobot& robot, const Dataset& data, AttitudeSource attitude,
                     StaticsMethod method, std::vector<std::array<double, kNumCables>>* predicted,
                     std::string* error);

// PredictTensions a sample at a time, each solve warm started from the one before, so
// that a dataset read in chunks is predicted as the whole one is: the same numbers, bit
// for bit. `robot` must outlive the predictor.
class TensionPredictor {
 public:
  TensionPredictor(const CableRobot& robot, AttitudeSource attitude, StaticsMethod method);
  // The predicted readings of `sample` (of `data`, named in the message: "<file>:<line>:
  // the model cannot solve this pose: <why>"). False when the model cannot hold the pose.
  bool Predict(const Dataset& data, const Sample& sample,
               std::array<double, kNumCables>* predicted_n, std::string* error);

 private:
  const CableRobot& robot_;
  AttitudeSource attitude_;
  StaticsOptions options_;
  StaticsSolution solution_;
};

// Removes from data->samples every sample whose pose `robot` cannot solve (SolveStatics
// not ok) with one of `methods` at one of `attitudes` (kPlanned only when the data has a
// planned attitude), and appends one message per removed sample to data->skipped, after
// the rows the reader skipped: "<file>:<line>: <model_name> cannot solve this pose
// (<attitude> attitude, <method>): <why>". Returns how many were removed. For callers
// that skip invalid rows (fastcal --skip-invalid-rows): a dataset row the model cannot
// hold, e.g. a position outside the workspace, then goes the way of a malformed one.
int SkipUnsolvableSamples(const CableRobot& robot, const std::string& model_name,
                          const std::vector<AttitudeSource>& attitudes,
                          const std::vector<StaticsMethod>& methods, Dataset* data);

// Readings to leave out of statistics: excluded[n][i] for cable i of sample n (empty:
// none), e.g. the gross errors a calibration flagged.
using ReadingMask = std::vector<std::array<bool, kNumCables>>;

// Statistics over the samples with held_out[n] == select_held_out (all samples when
// held_out is empty and select_held_out is false), without the excluded readings.
CableErrorStats ErrorStats(const Dataset& data,
                           const std::vector<std::array<double, kNumCables>>& predicted,
                           const std::vector<bool>& held_out, bool select_held_out,
                           const ReadingMask& excluded = {});

// ErrorStats gathered a sample at a time, in sample order (a dataset read in chunks):
// the same sums in the same order, so the same statistics bit for bit. `excluded` (may
// be null): the readings of the sample to leave out.
class ErrorStatsAccumulator {
 public:
  void Add(const std::array<double, kNumCables>& predicted_n,
           const std::array<double, kNumCables>& measured_n,
           const std::array<bool, kNumCables>* excluded = nullptr);
  CableErrorStats Finish() const;

 private:
  CableErrorStats st_;
  std::array<double, kNumCables> sum_{}, sum2_{}, sum2_pct_{};
  std::array<int, kNumCables> percent_readings_{};
};

// One row group of the RMS table: a model, an attitude source, and its statistics on the
// fitted and the held-out samples.
struct VariantEvaluation {
  std::string name;
  CableErrorStats fit;
  CableErrorStats holdout;  // samples == 0 when nothing is held out
  std::vector<std::array<double, kNumCables>> predicted_n;
};
bool EvaluateVariant(const std::string& name, const CableRobot& robot, const Dataset& data,
                     AttitudeSource attitude, StaticsMethod method,
                     const std::vector<bool>& held_out, VariantEvaluation* evaluation,
                     std::string* error, const ReadingMask& excluded = {});

// The name of the row of `fastcal evaluate`'s table for an attitude source: "model,
// planned attitude" or "model, measured attitude".
std::string EvaluationVariantName(AttitudeSource attitude);

// The table of `fastcal evaluate`: `robot` against every sample at each attitude the data
// has, "model, planned attitude" (when it has one) then "model, measured attitude", with
// `method`. False, naming the file and line of a pose the model cannot hold, otherwise.
bool EvaluateModel(const CableRobot& robot, const Dataset& data, StaticsMethod method,
                   std::vector<VariantEvaluation>* variants, std::string* error);

// Contiguous block b of n samples cut into `blocks` (b = 0 .. blocks - 1): samples
// [b n / blocks, (b + 1) n / blocks).
int BlockOfSample(int sample, int num_samples, int blocks);

// Which samples are held out of a fit: whole contiguous blocks (BlockOfSample), as many
// as round(fraction * blocks) and at least one when fraction > 0, chosen by a seeded
// shuffle (std::mt19937_64), the same on every run with the same seed. Blocks, because
// a single sample of a slow trajectory is predicted by its neighbours on either side.
std::vector<bool> HoldoutMask(int num_samples, double fraction, std::uint64_t seed,
                              int blocks = 10);

}  // namespace fastcal

#endif  // FASTCAL_EVALUATION_H_
