// Rows summed into their Gram matrix (internal/gram_fold.h): G = A^T A however the rows
// are cut into batches, grouped rows put back at their columns in any order, merged folds,
// and the same G as the QR fold's R^T R (row_fold.h), which the track's fold replaced.
#include "fastcal/internal/gram_fold.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <vector>

#include "fastcal/internal/row_fold.h"
#include "random_rows.h"

namespace fastcal::internal {
namespace {

// Entries of G to rounding: each a sum of a few hundred products.
constexpr double kRelTol = 1e-13;

TEST(GramFoldTest, GramIsTheRowsOwnAcrossBatches) {
  // More rows than a batch holds, and a flush in the middle of one.
  const int rows = 3 * GramFold::kBatchRows + 17;
  const RowMajor a = RandomRows(rows, 7, 1);
  GramFold fold(7);
  for (int i = 0; i < rows; ++i) {
    fold.Add(a.row(i).data());
    if (i == 100) fold.Flush();
  }
  fold.Flush();
  const Eigen::MatrixXd normal = a.transpose() * a;
  const Eigen::MatrixXd g = fold.Gram();
  EXPECT_LT((g - normal).norm(), kRelTol * normal.norm());
  EXPECT_EQ(g, g.transpose());
  EXPECT_TRUE(fold.lower().isLowerTriangular());
}

TEST(GramFoldTest, GroupsInAnyColumnOrderGiveTheFullWidthsGram) {
  // Three groups of rows, each zero outside its own columns (two of its own, four shared,
  // the third group's out of order), twice (FlushInto starts the groups afresh).
  const std::vector<std::vector<int>> columns = {
      {0, 1, 6, 7, 8, 9}, {2, 3, 6, 7, 8, 9}, {9, 4, 5, 8, 7, 6}};
  RowMajor a = RandomRows(900, 10, 4);
  for (int i = 0; i < a.rows(); ++i) {
    const std::vector<int>& own = columns[i % 3];
    for (int j = 0; j < a.cols(); ++j) {
      if (std::find(own.begin(), own.end(), j) == own.end()) a(i, j) = 0.0;
    }
  }
  GroupedGramFold grouped(columns);
  GramFold fold(10);
  for (int i = 0; i < a.rows(); ++i) {
    grouped.Add(i % 3, a.row(i).data());
    if (i == 299) grouped.FlushInto(&fold);
  }
  grouped.FlushInto(&fold);
  const Eigen::MatrixXd normal = a.transpose() * a;
  EXPECT_LT((fold.Gram() - normal).norm(), kRelTol * normal.norm());
  EXPECT_TRUE(fold.lower().isLowerTriangular());
}

TEST(GramFoldTest, MergedFoldsAreTheFoldOfAllTheRowsAndResetEmpties) {
  const RowMajor a = RandomRows(500, 5, 3);
  GramFold first(5), second(5);
  for (int i = 0; i < 200; ++i) first.Add(a.row(i).data());
  for (int i = 200; i < 500; ++i) second.Add(a.row(i).data());  // left unflushed: Add flushes
  first.Add(second);
  const Eigen::MatrixXd normal = a.transpose() * a;
  EXPECT_LT((first.Gram() - normal).norm(), kRelTol * normal.norm());
  first.Reset();
  first.Add(a.row(0).data());
  first.Flush();
  const Eigen::MatrixXd one = a.row(0).transpose() * a.row(0);
  EXPECT_LT((first.Gram() - one).norm(), kRelTol * one.norm());
}

TEST(GramFoldTest, SameAsTheQrFoldsNormalMatrix) {
  // What the track's fold gave before (R^T R of the QR fold) and gives now, to rounding.
  const RowMajor a = RandomRows(2000, 12, 5);
  RowFold qr(12);
  qr.Add(a.data(), static_cast<int>(a.rows()));
  qr.Flush();
  GramFold gram(12);
  for (int i = 0; i < a.rows(); ++i) gram.Add(a.row(i).data());
  gram.Flush();
  const Eigen::MatrixXd r = qr.r();
  const Eigen::MatrixXd from_qr = r.transpose() * r;
  EXPECT_LT((gram.Gram() - from_qr).norm(), kRelTol * from_qr.norm());
}

TEST(GramFoldTest, EveryWidthEitherKernelIsTheRowsGram) {
  // Widths about the 8 x 4 tiles' edges and the batch stride's padding, rows not a whole
  // number of batches; G's strict upper triangle never written; the kernels agree bit for
  // bit.
  const int rows = GramFold::kBatchRows + 37;
  for (int cols = 1; cols <= 41; ++cols) {
    const RowMajor a = RandomRows(rows, cols, 100 + cols);
    const int ld = GramBatchStride(cols);
    ASSERT_GE(ld, cols);
    ASSERT_EQ(ld % 8, 0);
    std::vector<double> batch(static_cast<size_t>(ld) * rows, 0.0);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) batch[static_cast<size_t>(r) * ld + c] = a(r, c);
    }
    const Eigen::MatrixXd normal = a.transpose() * a;
    Eigen::MatrixXd portable;
    for (GramKernel kernel : {GramKernel::kPortable, GramKernel::kWide, GramKernel::kBest}) {
      // Ones above the diagonal: left as they are.
      Eigen::MatrixXd lower = Eigen::MatrixXd::Ones(cols, cols);
      lower.triangularView<Eigen::Lower>().setZero();
      AddBatchToLower(batch.data(), ld, rows, cols, lower.data(), cols, kernel);
      const Eigen::MatrixXd upper_ones = lower.triangularView<Eigen::StrictlyUpper>();
      Eigen::MatrixXd expected_upper = Eigen::MatrixXd::Ones(cols, cols);
      expected_upper.triangularView<Eigen::Lower>().setZero();
      EXPECT_EQ(upper_ones, expected_upper) << cols << " columns";
      Eigen::MatrixXd g = lower.triangularView<Eigen::Lower>();
      g.triangularView<Eigen::StrictlyUpper>() = g.transpose();
      EXPECT_LT((g - normal).norm(), kRelTol * normal.norm())
          << cols << " columns, kernel " << static_cast<int>(kernel);
      // The same bits from every kernel: a fold is the same on any machine (each entry one
      // sum in row order, unfused).
      if (kernel == GramKernel::kPortable) portable = g;
      EXPECT_EQ(g, portable) << cols << " columns, kernel " << static_cast<int>(kernel);
    }
  }
  if (!WideGramKernelAvailable()) {
    std::cout << "[ NOTE     ] no AVX2 on this processor: the wide kernel was the portable one\n";
  }
}

TEST(GramFoldTest, NoRowsIsZero) {
  GramFold fold(3);
  fold.Flush();
  EXPECT_EQ(fold.Gram(), Eigen::MatrixXd::Zero(3, 3));
  GroupedGramFold grouped({{0, 2}, {1}});
  grouped.FlushInto(&fold);
  EXPECT_EQ(fold.Gram(), Eigen::MatrixXd::Zero(3, 3));
}

}  // namespace
}  // namespace fastcal::internal
