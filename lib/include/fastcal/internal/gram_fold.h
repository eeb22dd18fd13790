// Least-squares rows summed into their Gram matrix G = A^T A (A all the rows so far), a
// batch of rows at a time: a symmetric rank-k update of G's lower triangle (BLAS-3, as
// LAPACK's dsyrk), p^2 flops a row of p columns against a QR fold's 2 p^2 done one column
// of the batch at a time (row_fold.h).
//
// For sums whose consumer needs only A^T A: a window's information J^T J, its gradient
// J^T z and chi-square z^T z, a block's score (issue 41; track_fold.h). Forming G squares
// the rows' condition, as R^T R formed from a QR fold's R does: where the consumer starts
// from the information, folding by QR first keeps no digit that reaches it. Where R itself
// is needed (Ceres's residuals, the identifiability check's singular values) RowFold
// stays.
//
// The batch's update is GEMM's register tiling (Goto and van de Geijn, "Anatomy of
// high-performance matrix multiplication", ACM TOMS 34, 2008): each 8 x 4 tile of G that
// touches its lower triangle sums its products over the batch's rows in registers, the
// batch stored row after row, so that a row's 8 entries of the tile are one load and its
// 4 are broadcasts; no packing (the batch is the panel). On x86-64 with AVX2 (checked at
// run time) the same code runs 4 doubles a register, elsewhere 2 (SSE2). Every entry of G
// is one sum over the rows in row order, in one lane, unfused (gram_fold.cc is compiled
// with -ffp-contract=off): the same bits from either kernel, so a fold is the same on any
// machine. Issue 41: Eigen's rank update summed a track's 30-column readings at 2.7
// GFMA/s (bench/fold_bench.cc).
#ifndef FASTCAL_INTERNAL_GRAM_FOLD_H_
#define FASTCAL_INTERNAL_GRAM_FOLD_H_

#include <Eigen/Core>
#include <vector>

namespace fastcal::internal {

// Which code sums a batch into G: kPortable (vectors of the build's own instruction set)
// or kWide (AVX2, x86-64 only; where the processor has it, else kPortable); kBest the
// widest the processor has. The same bits from each (see above).
enum class GramKernel { kBest, kPortable, kWide };
bool WideGramKernelAvailable();

// lower(i, j) += sum over the batch's `rows` rows r of b_r[i] b_r[j], for j <= i < cols:
// row r's entries at batch[r * ld ...], ld >= cols rounded up to a multiple of 8 and
// entries cols..ld-1 zero; `lower` column-major with leading dimension ldl. Entries above
// the diagonal are not touched.
void AddBatchToLower(const double* batch, int ld, int rows, int cols, double* lower, int ldl,
                     GramKernel kernel = GramKernel::kBest);
// The batch's leading dimension for `cols` columns (AddBatchToLower).
int GramBatchStride(int cols);

class GramFold {
 public:
  // Rows gathered before they are summed (40 kB at 40 columns: in a core's L1 or L2
  // cache while its tiles run over it).
  static constexpr int kBatchRows = 128;

  explicit GramFold(int cols = 0);

  int cols() const { return cols_; }
  // Adds one row of cols() entries.
  void Add(const double* row);
  // Adds the row whose entry c is full_row[columns[c]] (columns.size() == cols()).
  void AddGathered(const double* full_row, const std::vector<int>& columns);
  // Sums the rows gathered so far into G (the result depends on where batches end: a
  // function of the sequence of calls only, so the same on any number of threads).
  void Flush();
  // Adds another fold's G (flushed first, both).
  void Add(GramFold& other);
  // Adds the symmetric matrix whose lower triangle is `lower` at rows and columns `at` of
  // G (a group's G put back at its own columns, in any order).
  void AddLowerAt(const Eigen::MatrixXd& lower, const std::vector<int>& at);
  // G of the rows so far, both triangles (Flush first).
  Eigen::MatrixXd Gram() const;
  // G's lower triangle (Flush first); its strict upper triangle is zero.
  const Eigen::MatrixXd& lower() const { return lower_; }
  // Back to no rows, keeping the width.
  void Reset();

 private:
  int cols_;
  Eigen::MatrixXd lower_;  // G's lower triangle; the strict upper stays zero
  int ld_;                 // a gathered row's stride in batch_ (GramBatchStride)
  std::vector<double> batch_;  // kBatchRows rows of ld_ entries, the last ld_ - cols_ zero
  int pending_ = 0;            // rows in batch_
};

// Rows in groups, each group's rows zero outside its own columns (one cable's readings:
// zero in the other cables' sensor columns): each group's G is summed over its columns
// only, then added at them into a GramFold of the full width.
class GroupedGramFold {
 public:
  // columns[g]: group g's columns of the full width, each once.
  explicit GroupedGramFold(std::vector<std::vector<int>> columns);

  // A full-width row of group g; its entries outside the group's columns are not read.
  void Add(int group, const double* row);
  // Adds every group's G so far into `fold` (cols() wide) and starts the groups afresh.
  void FlushInto(GramFold* fold);

 private:
  std::vector<std::vector<int>> columns_;
  std::vector<GramFold> groups_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_GRAM_FOLD_H_
