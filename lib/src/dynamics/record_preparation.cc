// The records' block mean, decimation and scaling (record_preparation.h has the equations).
#include "dynamics/record_preparation.h"

#include <algorithm>
#include <cmath>

namespace fastcal::internal {

int DecimationFactor(double sample_interval_s, double max_frequency_hz) {
  return std::max(1, static_cast<int>(1.0 / (4.0 * max_frequency_hz * sample_interval_s)));
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
