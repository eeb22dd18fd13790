// Rows folded into an R factor (internal/row_fold.h): R^T R = A^T A however the rows are
// cut into Adds and blocks, the same R as a QR of all the rows (up to the rows' signs),
// merges, and an exact degeneracy resolved to rounding (no normal equations).
#include "fastcal/internal/row_fold.h"

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <algorithm>
#include <vector>

#include "random_rows.h"

namespace fastcal::internal {
namespace {

// The rows of `a` added in pieces of the given sizes, cycling.
RowFold Folded(const RowMajor& a, const std::vector<int>& pieces) {
  RowFold fold(static_cast<int>(a.cols()));
  int row = 0;
  for (size_t k = 0; row < a.rows(); ++k) {
    const int count = std::min<int>(pieces[k % pieces.size()], static_cast<int>(a.rows()) - row);
    fold.Add(a.row(row).data(), count);
    row += count;
  }
  fold.Flush();
  return fold;
}

TEST(RowFoldTest, NormalMatrixIsTheRowsOwnWhateverThePieces) {
  constexpr double kRelTol = 1e-12;
  const RowMajor a = RandomRows(1000, 8, 1);
  const Eigen::MatrixXd normal = a.transpose() * a;
  for (const std::vector<int>& pieces :
       std::vector<std::vector<int>>{{1}, {6}, {96}, {7, 200, 3}}) {
    const Eigen::MatrixXd r = Folded(a, pieces).r();
    EXPECT_TRUE(r.isUpperTriangular());
    EXPECT_LT((r.transpose() * r - normal).norm(), kRelTol * normal.norm()) << pieces[0];
  }
}

TEST(GroupedRowFoldTest, SameNormalMatrixAsTheFullWidthFold) {
  // Three groups of rows, each zero outside its own columns (two of its own, four shared,
  // in no particular order), folded by group then into the full width, twice (FlushInto
  // starts the groups afresh).
  constexpr double kRelTol = 1e-12;
  const std::vector<std::vector<int>> columns = {
      {0, 1, 6, 7, 8, 9}, {2, 3, 6, 7, 8, 9}, {9, 4, 5, 8, 7, 6}};
  RowMajor a = RandomRows(600, 10, 4);
  for (int i = 0; i < a.rows(); ++i) {
    const std::vector<int>& own = columns[i % 3];
    for (int j = 0; j < a.cols(); ++j) {
      if (std::find(own.begin(), own.end(), j) == own.end()) a(i, j) = 0.0;
    }
  }
  const Eigen::MatrixXd normal = a.transpose() * a;
  GroupedRowFold grouped(columns, 10);
  RowFold fold(10);
  for (int i = 0; i < a.rows(); ++i) {
    grouped.Add(i % 3, a.row(i).data());
    if (i == 299) grouped.FlushInto(&fold);
  }
  grouped.FlushInto(&fold);
  const Eigen::MatrixXd r = fold.r();
  EXPECT_TRUE(r.isUpperTriangular());
  EXPECT_LT((r.transpose() * r - normal).norm(), kRelTol * normal.norm());
}

TEST(RowFoldTest, SameRAsAQrOfAllTheRowsUpToSigns) {
  constexpr double kRelTol = 1e-11;
  const RowMajor a = RandomRows(300, 6, 2);
  const Eigen::MatrixXd r = Folded(a, {6}).r();
  const Eigen::MatrixXd reference = FoldRows(Eigen::MatrixXd(), Eigen::MatrixXd(a));
  for (int i = 0; i < 6; ++i) {
    const double sign = (r(i, i) > 0) == (reference(i, i) > 0) ? 1.0 : -1.0;
    EXPECT_LT((r.row(i) - sign * reference.row(i)).norm(), kRelTol * reference.norm()) << i;
  }
}

TEST(RowFoldTest, MergedFoldsAreTheFoldOfAllTheRows) {
  constexpr double kRelTol = 1e-12;
  const RowMajor a = RandomRows(500, 5, 3);
  RowFold first = Folded(a.topRows(200), {6});
  const RowFold second = Folded(a.bottomRows(300), {6});
  first.Add(second);
  const Eigen::MatrixXd r = first.r();
  const Eigen::MatrixXd normal = a.transpose() * a;
  EXPECT_LT((r.transpose() * r - normal).norm(), kRelTol * normal.norm());
}

TEST(RowFoldTest, ExactDegeneracyShowsAtRoundingNotAtItsSquareRoot) {
  // Column 3 = column 0 + column 1: R's last diagonal is ~1e-16 of the others (a QR);
  // the normal equations could not tell it from 1e-8 (the identifiability check's line).
  constexpr double kDegenerateRatio = 1e-12;
  RowMajor a = RandomRows(400, 4, 4);
  a.col(3) = a.col(0) + a.col(1);
  const Eigen::MatrixXd r = Folded(a, {6}).r();
  EXPECT_LT(std::abs(r(3, 3)), kDegenerateRatio * std::abs(r(0, 0)));
}

TEST(RowFoldTest, NoRowsIsZero) {
  RowFold fold(3);
  fold.Flush();
  EXPECT_EQ(fold.r(), Eigen::MatrixXd::Zero(3, 3));
  double zeros[3] = {0.0, 0.0, 0.0};
  fold.Add(zeros, 1);
  fold.Flush();
  EXPECT_EQ(fold.r(), Eigen::MatrixXd::Zero(3, 3));
}

}  // namespace
}  // namespace fastcal::internal
