// Rows folded into an R factor (internal/row_fold.h).
#include "fastcal/internal/row_fold.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace fastcal::internal {

RowFold::RowFold(int cols)
    : cols_(cols),
      r_(Eigen::MatrixXd::Zero(cols, cols)),
      block_(kBlockRows, cols),
      v_(kBlockRows) {}

void RowFold::Add(const double* rows, int count) {
  for (int i = 0; i < count; ++i) {
    if (pending_ == kBlockRows) Flush();
    for (int j = 0; j < cols_; ++j) block_(pending_, j) = rows[i * cols_ + j];
    ++pending_;
  }
}

void RowFold::Flush() {
  const int m = pending_, p = cols_;
  pending_ = 0;
  if (m == 0) return;
  // Eigen's dot products keep several partial sums (a plain loop's one sum in order is a
  // chain of dependent additions, 3x slower here).
  for (int k = 0; k < p; ++k) {
    const auto x = block_.col(k).head(m);
    const double tail = x.squaredNorm();  // |x|^2 below the diagonal: the block's entries
    if (!(tail > 0.0)) continue;          // nothing to eliminate: the reflection is the identity
    const double alpha = r_(k, k);
    const double beta = -std::copysign(std::sqrt(alpha * alpha + tail), alpha);
    const double tau = (beta - alpha) / beta;
    auto v = v_.head(m);
    v = x * (1.0 / (alpha - beta));  // v = (1, x / (alpha - beta))
    r_(k, k) = beta;
    for (int j = k + 1; j < p; ++j) {
      auto b = block_.col(j).head(m);
      const double w = tau * (r_(k, j) + v.dot(b));
      r_(k, j) -= w;
      b -= w * v;
    }
  }
}

void RowFold::Add(const RowFold& other) {
  Flush();
  // Its R row after row; its zeros below the diagonal are not worth skipping (p rows, once
  // per chunk of samples).
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = other.r_;
  Add(rows.data(), other.cols());
  Flush();
}

Eigen::MatrixXd RowFold::r() const { return r_; }

GroupedRowFold::GroupedRowFold(std::vector<std::vector<int>> columns, int cols)
    : columns_(std::move(columns)), cols_(cols) {
  size_t widest = 0;
  for (const std::vector<int>& c : columns_) {
    groups_.emplace_back(static_cast<int>(c.size()));
    widest = std::max(widest, c.size());
  }
  gathered_.resize(widest);
}

void GroupedRowFold::Add(int group, const double* row) {
  const std::vector<int>& columns = columns_[group];
  for (size_t c = 0; c < columns.size(); ++c) gathered_[c] = row[columns[c]];
  groups_[group].Add(gathered_.data(), 1);
}

void GroupedRowFold::FlushInto(RowFold* fold) {
  for (size_t g = 0; g < groups_.size(); ++g) {
    RowFold& own = groups_[g];
    own.Flush();
    const Eigen::MatrixXd r = own.r();
    const std::vector<int>& columns = columns_[g];
    const int width = static_cast<int>(columns.size());
    expanded_.assign(static_cast<size_t>(width) * cols_, 0.0);
    for (int a = 0; a < width; ++a) {
      for (int c = a; c < width; ++c) expanded_[a * cols_ + columns[c]] = r(a, c);
    }
    fold->Add(expanded_.data(), width);
    own = RowFold(width);
  }
  fold->Flush();
}

Eigen::MatrixXd FoldRows(const Eigen::MatrixXd& top, const Eigen::MatrixXd& rows) {
  // A fold with nothing yet has a 0 x 0 R factor, not 0 x n: Eigen's assert (on in the
  // sanitizer build) refuses assigning it to a 0 x n block, so empty parts are skipped.
  const int n = static_cast<int>(std::max(top.cols(), rows.cols()));
  Eigen::MatrixXd m(top.rows() + rows.rows(), n);
  if (top.rows() > 0) m.topRows(top.rows()) = top;
  if (rows.rows() > 0) m.bottomRows(rows.rows()) = rows;
  if (m.rows() == 0) return Eigen::MatrixXd::Zero(n, n);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(m);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n, n);
  const int k = static_cast<int>(std::min<Eigen::Index>(n, m.rows()));
  r.topRows(k) = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  return r;
}

}  // namespace fastcal::internal
