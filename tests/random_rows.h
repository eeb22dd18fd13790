// Random least-squares rows for the fold tests (row_fold_test.cc, gram_fold_test.cc):
// normal entries, column j scaled by 1 + j so that the columns differ in size.
#ifndef FASTCAL_TESTS_RANDOM_ROWS_H_
#define FASTCAL_TESTS_RANDOM_ROWS_H_

#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace fastcal::internal {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

inline RowMajor RandomRows(int rows, int cols, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  RowMajor a(rows, cols);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) a(i, j) = normal(rng) * (1.0 + j);
  }
  return a;
}

}  // namespace fastcal::internal

#endif  // FASTCAL_TESTS_RANDOM_ROWS_H_
