// Rows summed into their Gram matrix (internal/gram_fold.h): G += B^T B a batch B of rows
// at a time, tile by tile of G's lower triangle.
#include "fastcal/internal/gram_fold.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace fastcal::internal {
namespace {

// A tile of G: two vectors of rows by kTileCols columns, summed in registers over the
// batch. Rows are padded to kPadRows (GramBatchStride), the widest tile's height.
constexpr int kTileCols = 4;
constexpr int kPadRows = 8;

#if defined(__GNUC__)
// Two doubles: an SSE2 register (the portable code's); four: an AVX one (the wide code's).
using Pair = double __attribute__((vector_size(16)));
using Quad = double __attribute__((vector_size(32)));

// Through a pointer, not returned: a vector returned by value is passed in an AVX register
// in the wide code and in memory in the portable (GCC's -Wpsabi).
template <typename V>
__attribute__((always_inline)) inline void LoadVector(const double* p, V* v) {
  std::memcpy(v, p, sizeof *v);
}

// The tile at rows i0.., columns j0.. of G: the sums over the batch's rows, added to G's
// lower triangle.
template <typename V>
__attribute__((always_inline)) inline void Tile(const double* batch, int ld, int rows, int cols,
                                                int i0, int j0, double* lower, int ldl) {
  constexpr int kLanes = sizeof(V) / sizeof(double);
  V lo[kTileCols] = {}, hi[kTileCols] = {};
  for (int r = 0; r < rows; ++r) {
    const double* row = batch + static_cast<long>(r) * ld;
    V a, b;
    LoadVector(row + i0, &a);
    LoadVector(row + i0 + kLanes, &b);
    for (int c = 0; c < kTileCols; ++c) {
      lo[c] += a * row[j0 + c];
      hi[c] += b * row[j0 + c];
    }
  }
  for (int c = 0; c < kTileCols && j0 + c < cols; ++c) {
    const int j = j0 + c;
    for (int k = 0; k < 2 * kLanes; ++k) {
      const int i = i0 + k;
      if (i < j || i >= cols) continue;
      lower[static_cast<long>(j) * ldl + i] += k < kLanes ? lo[c][k] : hi[c][k - kLanes];
    }
  }
}

// Every tile that touches the lower triangle: for columns j0..j0+3 the row tiles from the
// one holding j0 down.
template <typename V>
__attribute__((always_inline)) inline void Tiles(const double* batch, int ld, int rows, int cols,
                                                 double* lower, int ldl) {
  constexpr int kTileRows = 2 * static_cast<int>(sizeof(V) / sizeof(double));
  for (int j0 = 0; j0 < cols; j0 += kTileCols) {
    for (int i0 = j0 - j0 % kTileRows; i0 < cols; i0 += kTileRows) {
      Tile<V>(batch, ld, rows, cols, i0, j0, lower, ldl);
    }
  }
}

void TilesPortable(const double* batch, int ld, int rows, int cols, double* lower, int ldl) {
  Tiles<Pair>(batch, ld, rows, cols, lower, ldl);
}
#else
void TilesPortable(const double* batch, int ld, int rows, int cols, double* lower, int ldl) {
  for (int r = 0; r < rows; ++r) {
    const double* row = batch + static_cast<long>(r) * ld;
    for (int j = 0; j < cols; ++j) {
      for (int i = j; i < cols; ++i) lower[static_cast<long>(j) * ldl + i] += row[i] * row[j];
    }
  }
}
#endif

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2"))) void TilesWide(const double* batch, int ld, int rows, int cols,
                                               double* lower, int ldl) {
  Tiles<Quad>(batch, ld, rows, cols, lower, ldl);
}
#endif

}  // namespace

bool WideGramKernelAvailable() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool available = __builtin_cpu_supports("avx2");
  return available;
#else
  return false;
#endif
}

int GramBatchStride(int cols) {
  return std::max(kPadRows, (cols + kPadRows - 1) / kPadRows * kPadRows);
}

void AddBatchToLower(const double* batch, int ld, int rows, int cols, double* lower, int ldl,
                     GramKernel kernel) {
  if (rows <= 0 || cols <= 0) return;
#if defined(__x86_64__) && defined(__GNUC__)
  if (kernel != GramKernel::kPortable && WideGramKernelAvailable()) {
    TilesWide(batch, ld, rows, cols, lower, ldl);
    return;
  }
#endif
  TilesPortable(batch, ld, rows, cols, lower, ldl);
}

GramFold::GramFold(int cols)
    : cols_(cols),
      lower_(Eigen::MatrixXd::Zero(cols, cols)),
      ld_(GramBatchStride(cols)),
      batch_(static_cast<size_t>(ld_) * kBatchRows, 0.0) {}

void GramFold::Add(const double* row) {
  if (pending_ == kBatchRows) Flush();
  std::copy(row, row + cols_, batch_.data() + static_cast<size_t>(pending_) * ld_);
  ++pending_;
}

void GramFold::AddGathered(const double* full_row, const std::vector<int>& columns) {
  if (pending_ == kBatchRows) Flush();
  double* to = batch_.data() + static_cast<size_t>(pending_) * ld_;
  for (int c = 0; c < cols_; ++c) to[c] = full_row[columns[c]];
  ++pending_;
}

void GramFold::Flush() {
  if (pending_ == 0) return;
  AddBatchToLower(batch_.data(), ld_, pending_, cols_, lower_.data(),
                  static_cast<int>(lower_.outerStride()));
  pending_ = 0;
}

void GramFold::Add(GramFold& other) {
  Flush();
  other.Flush();
  lower_.triangularView<Eigen::Lower>() += other.lower_;
}

void GramFold::AddLowerAt(const Eigen::MatrixXd& lower, const std::vector<int>& at) {
  Flush();
  const int width = static_cast<int>(at.size());
  for (int c = 0; c < width; ++c) {
    for (int r = c; r < width; ++r) {
      lower_(std::max(at[r], at[c]), std::min(at[r], at[c])) += lower(r, c);
    }
  }
}

void GramFold::Reset() {
  lower_.setZero();
  pending_ = 0;
}

Eigen::MatrixXd GramFold::Gram() const {
  Eigen::MatrixXd g = lower_;
  g.triangularView<Eigen::StrictlyUpper>() = lower_.transpose();
  return g;
}

GroupedGramFold::GroupedGramFold(std::vector<std::vector<int>> columns)
    : columns_(std::move(columns)) {
  for (const std::vector<int>& c : columns_) groups_.emplace_back(static_cast<int>(c.size()));
}

void GroupedGramFold::Add(int group, const double* row) {
  groups_[group].AddGathered(row, columns_[group]);
}

void GroupedGramFold::FlushInto(GramFold* fold) {
  for (size_t g = 0; g < groups_.size(); ++g) {
    GramFold& own = groups_[g];
    own.Flush();
    fold->AddLowerAt(own.lower(), columns_[g]);
    own.Reset();
  }
}

}  // namespace fastcal::internal
