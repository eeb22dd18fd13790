// Least-squares rows folded into the R factor of their QR decomposition, a block of rows at
// a time: R upper triangular with R^T R = A^T A for A all the rows so far (Golub and Van
// Loan, "Matrix Computations", 4th ed., sect. 6.5.3, updating a QR factorisation by rows).
//
// Rows are gathered in a block of kBlockRows (column-major, ~20 kB: in the first-level
// cache); a full block B is folded as the QR of [R; B] with R already triangular: column
// k's Householder reflection acts on R's row k and on B only, a dot product and an update
// along B's contiguous column per column j > k. The flops are a tall QR's (2 m p^2 for m
// rows of p columns); issue 20's fold, Eigen's HouseholderQR of 6144-row chunks, streamed
// each chunk (1 MB) through memory once per column. Reflections as LAPACK's dlarfg:
// beta = -sign(alpha) |(alpha, x)|; backward stable as any QR: the condition of the rows
// is not squared (no normal equations), which the identifiability check's singular values
// need.
#ifndef FASTCAL_INTERNAL_ROW_FOLD_H_
#define FASTCAL_INTERNAL_ROW_FOLD_H_

#include <Eigen/Core>
#include <vector>

namespace fastcal::internal {

class RowFold {
 public:
  // Rows gathered before a block is folded.
  static constexpr int kBlockRows = 96;

  explicit RowFold(int cols = 0);

  int cols() const { return cols_; }
  // Adds `count` rows of cols() entries each, row after row from `rows` (row-major).
  void Add(const double* rows, int count);
  // Folds the rows gathered so far (the result depends on where blocks end: a function
  // of the sequence of Add calls only).
  void Flush();
  // Folds another fold's rows (its R; it must have been flushed) into this one.
  void Add(const RowFold& other);
  // R (cols() x cols(), upper triangular) of the rows folded so far (Flush first).
  Eigen::MatrixXd r() const;

 private:
  int cols_;
  Eigen::MatrixXd r_;      // upper triangular (column-major)
  Eigen::MatrixXd block_;  // kBlockRows x cols, the rows gathered (column-major)
  int pending_ = 0;        // rows in block_
  Eigen::VectorXd v_;      // the reflection's vector (workspace)
};

// Upper-triangular R with R^T R = A^T A for A the rows of `top` stacked on `rows` (a QR
// of the stack; `top` may be empty).
// Rows in groups, each group's rows zero outside its own columns (e.g. one cable's
// readings: zero in the other cables' sensor columns). Each group's rows are folded into an
// R over its columns only (a row of p columns costs ~2 p^2), then those R's rows, put back
// in the full width, into a RowFold: the same R^T R as folding every row at full width.
class GroupedRowFold {
 public:
  // columns[g]: group g's columns, < cols (the full width).
  GroupedRowFold(std::vector<std::vector<int>> columns, int cols);

  // A full-width row of group g; its entries outside the group's columns are not read.
  void Add(int group, const double* row);
  // Folds every group's rows so far into `fold` (cols() wide, flushed after) and starts
  // the groups afresh.
  void FlushInto(RowFold* fold);

 private:
  std::vector<std::vector<int>> columns_;
  int cols_;
  std::vector<RowFold> groups_;
  std::vector<double> gathered_, expanded_;
};

Eigen::MatrixXd FoldRows(const Eigen::MatrixXd& top, const Eigen::MatrixXd& rows);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_ROW_FOLD_H_
