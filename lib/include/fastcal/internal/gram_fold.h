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
#ifndef FASTCAL_INTERNAL_GRAM_FOLD_H_
#define FASTCAL_INTERNAL_GRAM_FOLD_H_

#include <Eigen/Core>
#include <vector>

namespace fastcal::internal {

class GramFold {
 public:
  // Rows gathered before they are summed (cols x kBatchRows doubles: 80 kB at 40 columns).
  static constexpr int kBatchRows = 256;

  explicit GramFold(int cols = 0);

  int cols() const { return cols_; }
  // Adds one row of cols() entries.
  void Add(const double* row);
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
  Eigen::MatrixXd batch_;  // cols x kBatchRows: each gathered row is a column
  int pending_ = 0;        // rows in batch_
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
  std::vector<double> gathered_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_GRAM_FOLD_H_
