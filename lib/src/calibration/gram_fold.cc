// Rows summed into their Gram matrix (internal/gram_fold.h).
#include "fastcal/internal/gram_fold.h"

#include <algorithm>
#include <utility>

namespace fastcal::internal {

GramFold::GramFold(int cols)
    : cols_(cols), lower_(Eigen::MatrixXd::Zero(cols, cols)), batch_(cols, kBatchRows) {}

void GramFold::Add(const double* row) {
  if (pending_ == kBatchRows) Flush();
  std::copy(row, row + cols_, batch_.col(pending_).data());
  ++pending_;
}

void GramFold::Flush() {
  if (pending_ == 0) return;
  // G += B B^T for B the gathered rows as columns: the lower triangle only.
  lower_.selfadjointView<Eigen::Lower>().rankUpdate(batch_.leftCols(pending_));
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
  size_t widest = 0;
  for (const std::vector<int>& c : columns_) {
    groups_.emplace_back(static_cast<int>(c.size()));
    widest = std::max(widest, c.size());
  }
  gathered_.resize(widest);
}

void GroupedGramFold::Add(int group, const double* row) {
  const std::vector<int>& columns = columns_[group];
  for (size_t c = 0; c < columns.size(); ++c) gathered_[c] = row[columns[c]];
  groups_[group].Add(gathered_.data());
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
