// Rows of fitted samples and their whitening in time order (internal/sample_rows.h).
#include "fastcal/internal/sample_rows.h"

#include <algorithm>

namespace fastcal::internal {

bool EvaluateSampleRows(const FittedSamples& samples, int j, const ModelAtTheta& at, int t,
                        SampleRows* rows) {
  double r[kMaxReadings];
  double* out = rows->Of(t);
  const int columns = rows->columns;
  const int readings = samples.readings();
  if (columns == 1) {
    if (!samples.Rows(j, at, r, nullptr)) return false;
    std::copy(r, r + readings, out);
    return true;
  }
  const int n = columns - 1;
  thread_local std::vector<double> jacobian;
  jacobian.resize(static_cast<size_t>(readings) * n);
  if (!samples.Rows(j, at, r, jacobian.data())) return false;
  for (int i = 0; i < readings; ++i) {
    double* row = out + i * columns;
    std::copy(jacobian.data() + i * n, jacobian.data() + (i + 1) * n, row);
    row[n] = r[i];
  }
  return true;
}

SampleRowWhitener::SampleRowWhitener(const FittedSamples& samples, int columns)
    : samples_(samples),
      whitener_(samples.whitened() ? samples.slow_error : SlowErrorProcess(), columns) {}

void SampleRowWhitener::Whiten(SampleRows* rows, const std::vector<int>* index) {
  WhitenRows(samples_, &whitener_, rows, index);
}

void SampleRowWhitener::Whiten(const FittedSamples& piece, SampleRows* rows) {
  WhitenRows(piece, &whitener_, rows, nullptr);
}

void SampleRowWhitener::WhitenRows(const FittedSamples& samples, ReadingWhitener* whitener,
                                   SampleRows* rows, const std::vector<int>* index) {
  if (!whitener->active()) return;
  for (int k = rows->begin; k < rows->end; ++k) {
    const int j = index != nullptr ? (*index)[k] : k;
    const int t = (*samples.fit)[j];
    const Sample& sample = samples.data->samples[t];
    std::array<bool, kNumCables> excluded{};
    if (samples.excluded != nullptr && !samples.excluded->empty()) {
      excluded = (*samples.excluded)[t];
    }
    whitener->WhitenOnly(sample.time_s, sample.session, (*samples.slow_rho)[j].data(),
                         excluded.data(), rows->Of(k));
    for (int i = 0; i < kNumCables; ++i) {
      if (excluded[i]) std::fill(rows->Row(k, i), rows->Row(k, i) + rows->columns, 0.0);
    }
  }
}

}  // namespace fastcal::internal
