// The records' block mean, decimation and scaling (record_preparation.h has the equations).
#include "dynamics/record_preparation.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fastcal::internal {

int DecimationFactor(double sample_interval_s, double max_frequency_hz) {
  // In double first: a record stamped every 1e-12 s asks for blocks of 5e11 samples, and
  // an int cast of that is undefined (issue 57); such a factor leaves no sample anyway.
  const double factor = std::floor(1.0 / (4.0 * max_frequency_hz * sample_interval_s));
  if (!(factor >= 1.0)) return 1;
  return factor >= static_cast<double>(std::numeric_limits<int>::max())
             ? std::numeric_limits<int>::max()
             : static_cast<int>(factor);
}

Eigen::MatrixXd DecimatedScaled(const Eigen::MatrixXd& channels, int factor) {
  const int n = static_cast<int>(channels.cols()) / factor;
  Eigen::MatrixXd y(channels.rows(), n);
  for (int k = 0; k < n; ++k) y.col(k) = channels.middleCols(k * factor, factor).rowwise().mean();
  y = y.colwise() - y.rowwise().mean();
  for (int c = 0; c < y.rows(); ++c) {
    const double spread = std::sqrt(y.row(c).squaredNorm() / n);
    if (spread > 0.0) y.row(c) /= spread;
  }
  return y;
}

}  // namespace fastcal::internal
