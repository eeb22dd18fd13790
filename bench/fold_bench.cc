// The two ways a window's whitened rows are summed (issue 41), on a track's shape: 1024
// samples of 6 readings, 39 columns and the residual's, each reading over 30 of them (its
// own gain and bias, the 28 shared), as calibration_data/spec_track.yaml folds them.
//   BM_GroupedRowFold:  the QR fold by reading, then into the full width (row_fold.h)
//   BM_GroupedGramFold: the Gram matrix by reading, then into the full width (gram_fold.h)
//   BM_GramKernel:      one batch's sum into G by the portable and the wide kernel
// Run: build/bench/fold_bench
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "fastcal/internal/gram_fold.h"
#include "fastcal/internal/row_fold.h"

namespace fastcal::internal {
namespace {

constexpr int kSamples = 1024, kReadings = 6, kCols = 40;

std::vector<std::vector<int>> Columns() {
  std::vector<std::vector<int>> columns(kReadings);
  for (int i = 0; i < kReadings; ++i) {
    columns[i] = {9 + i, 15 + i};                              // the reading's gain and bias
    for (int k = 0; k < 9; ++k) columns[i].push_back(k);       // mass centre, densities
    for (int k = 21; k < kCols; ++k) columns[i].push_back(k);  // tower tops, residual
  }
  return columns;
}

std::vector<double> Rows() {
  std::mt19937_64 rng(41);
  std::normal_distribution<double> normal;
  std::vector<double> rows(static_cast<size_t>(kSamples) * kReadings * kCols);
  for (double& x : rows) x = normal(rng);
  return rows;
}

void BM_GroupedRowFold(benchmark::State& state) {
  const std::vector<double> rows = Rows();
  for (auto _ : state) {
    RowFold fold(kCols);
    GroupedRowFold grouped(Columns(), kCols);
    for (int j = 0; j < kSamples * kReadings; ++j) {
      grouped.Add(j % kReadings, rows.data() + static_cast<size_t>(j) * kCols);
    }
    grouped.FlushInto(&fold);
    benchmark::DoNotOptimize(fold.r().data());
  }
  state.SetItemsProcessed(state.iterations() * kSamples);
}

void BM_GroupedGramFold(benchmark::State& state) {
  const std::vector<double> rows = Rows();
  for (auto _ : state) {
    GramFold fold(kCols);
    GroupedGramFold grouped(Columns());
    for (int j = 0; j < kSamples * kReadings; ++j) {
      grouped.Add(j % kReadings, rows.data() + static_cast<size_t>(j) * kCols);
    }
    grouped.FlushInto(&fold);
    benchmark::DoNotOptimize(fold.lower().data());
  }
  state.SetItemsProcessed(state.iterations() * kSamples);
}

// One batch of GramFold::kBatchRows rows of 31 columns (a track's reading and its
// residual) summed into G's lower triangle by each kernel; arg 0 portable, 1 wide (AVX2,
// skipped where the processor lacks it).
void BM_GramKernel(benchmark::State& state) {
  const GramKernel kernel = state.range(0) == 0 ? GramKernel::kPortable : GramKernel::kWide;
  if (kernel == GramKernel::kWide && !WideGramKernelAvailable()) {
    state.SkipWithError("no AVX2 on this processor");
    return;
  }
  constexpr int kWidth = 31;
  const int ld = GramBatchStride(kWidth);
  std::vector<double> batch(static_cast<size_t>(ld) * GramFold::kBatchRows, 0.0);
  const std::vector<double> rows = Rows();
  for (int r = 0; r < GramFold::kBatchRows; ++r) {
    for (int c = 0; c < kWidth; ++c) batch[static_cast<size_t>(r) * ld + c] = rows[r * kCols + c];
  }
  Eigen::MatrixXd lower = Eigen::MatrixXd::Zero(kWidth, kWidth);
  for (auto _ : state) {
    AddBatchToLower(batch.data(), ld, GramFold::kBatchRows, kWidth, lower.data(), kWidth, kernel);
    benchmark::DoNotOptimize(lower.data());
  }
  // Multiply-adds of the lower triangle a row.
  state.SetItemsProcessed(state.iterations() * GramFold::kBatchRows * kWidth * (kWidth + 1) / 2);
}

BENCHMARK(BM_GroupedRowFold)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_GroupedGramFold)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_GramKernel)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace fastcal::internal

BENCHMARK_MAIN();
