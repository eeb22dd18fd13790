// The rows of a chunk of fitted samples, and their whitening in time order: the stage
// between computing each sample's residuals and Jacobian (on several threads) and using
// them (the folded cost's QR, the linearisation's sums).
//
// Each sample has a row per reading, each `columns` wide: the Jacobian's n columns and
// then the residual r = (prediction - measured) / sigma_white (columns = 1: the residual
// alone); six rows, the tensions, or twelve with the lengths in the fit (rows 6..11, white:
// the slow error is the tension sensors'). With a slow sensor error (FittedSamples::slow_error) the
// rows of each cable are whitened by its Kalman filter (slow_error_filter.h) in time order, which
// needs the chunks in order: SampleRowWhitener carries the filters from chunk to chunk,
// inside ReduceChunksInOrder's ordered stage (sample_chunks.h). Readings kept out of the
// fit (gross errors) move the filters on in time only, and their rows are zero.
#ifndef FASTCAL_INTERNAL_SAMPLE_ROWS_H_
#define FASTCAL_INTERNAL_SAMPLE_ROWS_H_

#include <vector>

#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/slow_error_filter.h"

namespace fastcal::internal {

struct SampleRows {
  int begin = 0, end = 0;  // fitted samples [begin, end)
  int columns = 1;
  int readings = kNumCables;   // rows per sample (FittedSamples::readings)
  std::vector<double> values;  // sample t's rows at Of(t), row-major, readings x columns

  void Reset(int first, int last, int width, int rows_per_sample = kNumCables) {
    begin = first;
    end = last;
    columns = width;
    readings = rows_per_sample;
    values.assign(static_cast<size_t>(last - first) * readings * width, 0.0);
  }
  double* Of(int t) { return values.data() + static_cast<size_t>(t - begin) * readings * columns; }
  const double* Of(int t) const {
    return values.data() + static_cast<size_t>(t - begin) * readings * columns;
  }
  // Row `i` of sample t.
  double* Row(int t, int i) { return Of(t) + i * columns; }
};

// Fitted sample j's rows at `at` (FittedSamples::Rows) into rows->Of(t): Jacobian (when
// rows->columns > 1, it must be at.model().num_free() + 1) and residual; rows of readings
// kept out of the fit are zero. False where the statics fail.
bool EvaluateSampleRows(const FittedSamples& samples, int j, const ModelAtTheta& at, int t,
                        SampleRows* rows);

// The filters of one pass over the fitted samples (or any ordered subset of them).
class SampleRowWhitener {
 public:
  SampleRowWhitener(const FittedSamples& samples, int columns);
  bool active() const { return whitener_.active(); }
  // ReadingWhitener::set_observer of the pass's filters.
  void set_observer(WhitenObserver* observer) { whitener_.set_observer(observer); }
  // Whitens the rows of fitted samples rows->begin .. end (`index` maps a row's position
  // to its fitted sample when the pass runs over a subset; null: the identity). Call for
  // the chunks of a pass in order.
  void Whiten(SampleRows* rows, const std::vector<int>* index = nullptr);
  // The same for the rows of `piece`, samples that continue the pass (a window streamed a
  // piece at a time: the filters carry on from the pieces before; its slow error must be
  // the one the whitener was made with).
  void Whiten(const FittedSamples& piece, SampleRows* rows);

 private:
  static void WhitenRows(const FittedSamples& samples, ReadingWhitener* whitener, SampleRows* rows,
                         const std::vector<int>* index);

  const FittedSamples& samples_;
  ReadingWhitener whitener_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_SAMPLE_ROWS_H_
