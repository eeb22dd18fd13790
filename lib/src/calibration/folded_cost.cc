// The fit's data term folded into one residual block (internal/folded_cost.h).
#include "fastcal/internal/folded_cost.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "fastcal/internal/row_fold.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/sample_rows.h"

namespace fastcal::internal {

double CorrectForLoss(const ceres::LossFunction* loss, double* residuals, double* jacobian, int n,
                      int readings) {
  double sq_norm = 0.0;
  for (int i = 0; i < readings; ++i) sq_norm += residuals[i] * residuals[i];
  if (loss == nullptr) return sq_norm;
  double rho[3];
  loss->Evaluate(sq_norm, rho);
  const double sqrt_rho1 = std::sqrt(std::max(rho[1], 0.0));
  double residual_scaling = sqrt_rho1, alpha_sq_norm = 0.0;
  if (sq_norm > 0.0 && rho[2] > 0.0 && rho[1] > 0.0) {
    const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
    residual_scaling = sqrt_rho1 / (1.0 - alpha);
    alpha_sq_norm = alpha / sq_norm;
  }
  if (jacobian != nullptr) {
    for (int k = 0; k < n; ++k) {
      double r_dot_j = 0.0;  // (r^T J)_k
      for (int i = 0; i < readings; ++i) r_dot_j += residuals[i] * jacobian[i * n + k];
      for (int i = 0; i < readings; ++i) {
        jacobian[i * n + k] =
            sqrt_rho1 * (jacobian[i * n + k] - alpha_sq_norm * residuals[i] * r_dot_j);
      }
    }
  }
  for (int i = 0; i < readings; ++i) residuals[i] *= residual_scaling;
  return rho[0];
}

FoldedTensionCost::FoldedTensionCost(const FittedSamples& samples, const ceres::LossFunction* loss,
                                     int threads, bool by_reading)
    : samples_(samples), loss_(loss), threads_(threads), n_(samples.model->num_free()) {
  set_num_residuals(n_ + 1);
  mutable_parameter_block_sizes()->push_back(n_);
  if (by_reading) reading_columns_ = ReadingColumns(samples, loss);
}

std::vector<std::vector<int>> ReadingColumns(const FittedSamples& samples,
                                             const ceres::LossFunction* loss) {
  if (loss != nullptr || samples.readings() != kNumCables) return {};
  const CalibrationModel& model = *samples.model;
  const int n = model.num_free();
  std::vector<std::vector<int>> columns(kNumCables);
  std::vector<int> shared;
  for (int k = 0; k < n; ++k) {
    const ParameterSpec& p = model.spec().parameters[model.spec_index(k)];
    const bool sensor =
        p.kind == ParameterKind::kSensorGain || p.kind == ParameterKind::kSensorBias;
    if (sensor && p.index >= 0 && p.index < kNumCables) {
      columns[p.index].push_back(k);
    } else {
      shared.push_back(k);
    }
  }
  if (shared.size() == static_cast<size_t>(n)) return {};  // nothing to gain
  for (std::vector<int>& c : columns) {
    c.insert(c.end(), shared.begin(), shared.end());
    c.push_back(n);  // the residual
  }
  return columns;
}

void FoldedTensionCost::FoldByReading(const SampleRows& rows, int begin, int end, RowFold* fold,
                                      double* rho) const {
  const int n = n_;
  GroupedRowFold grouped(reading_columns_, n + 1);
  for (int t = begin; t < end; ++t) {
    double sq_norm = 0.0;  // as CorrectForLoss sums it without a loss
    for (int i = 0; i < kNumCables; ++i) {
      const double* row = rows.Of(t) + i * rows.columns;
      sq_norm += row[n] * row[n];
      grouped.Add(i, row);
    }
    *rho += sq_norm;
  }
  grouped.FlushInto(fold);
}

bool FoldedTensionCost::Fold(const double* theta, Eigen::MatrixXd* r_aug, double* rho_sum) const {
  struct Part {
    SampleRows rows;  // the chunk's rows, Jacobian then residual
    RowFold fold;     // of the rows with the loss's correction, (n + 1) columns
    double rho = 0.0;
  };
  const int n = n_;
  const int m = samples_.readings();
  const ModelAtTheta at(*samples_.model, theta, samples_.sessions());
  // Starts solved at this very theta (the prediction's, compact_start.h) are taken as
  // solved; a fold anywhere else makes whatever it writes them into no longer so.
  FittedSamples samples = samples_;
  const CalibrationModel* model = samples_.model;
  samples.starts_solved = samples_.starts != nullptr && samples_.starts->SolvedAt(model, theta, n);
  if (samples_.solved.starts != nullptr && !samples_.solved.starts->SolvedAt(model, theta, n)) {
    samples_.solved.starts->ForgetSolved();
  }
  RowFold total(n + 1);
  *rho_sum = 0.0;
  SampleRowWhitener whitener(samples, n + 1);
  const int failed = ReduceChunksInOrder<Part>(
      samples_.size(), threads_,
      [n] {
        return Part{{}, RowFold(n + 1)};
      },
      [&](int begin, int end, Part* part) {
        part->rows.Reset(begin, end, n + 1, m);
        for (int t = begin; t < end; ++t) {
          if (!EvaluateSampleRows(samples, t, at, t, &part->rows)) return t;
        }
        return -1;
      },
      [&](int, int, Part* part) { whitener.Whiten(&part->rows); },
      [&](int begin, int end, Part* part) {
        if (folds_by_reading()) {
          FoldByReading(part->rows, begin, end, &part->fold, &part->rho);
          return -1;
        }
        std::vector<double> j(m * n), rows(m * (n + 1));
        double r[kMaxReadings];
        for (int t = begin; t < end; ++t) {
          for (int i = 0; i < m; ++i) {
            const double* row = part->rows.Row(t, i);
            std::copy(row, row + n, &j[i * n]);
            r[i] = row[n];
          }
          part->rho += CorrectForLoss(loss_, r, j.data(), n, m);
          for (int i = 0; i < m; ++i) {
            std::copy(&j[i * n], &j[i * n] + n, &rows[i * (n + 1)]);
            rows[i * (n + 1) + n] = r[i];
          }
          part->fold.Add(rows.data(), m);
        }
        part->fold.Flush();
        return -1;
      },
      [&](const Part& part) {
        total.Add(part.fold);
        *rho_sum += part.rho;
      });
  *r_aug = total.r();
  return failed < 0;
}

bool FoldedTensionCost::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  const double* theta = parameters[0];
  const int n = n_;
  // Every evaluation folds the Jacobian too (see Memo in the header): a trial step's cost
  // is followed, when the step is taken, by the Jacobian at the same theta.
  std::lock_guard<std::mutex> lock(mutex_);
  if (memo_theta_.empty() || !std::equal(theta, theta + n, memo_theta_.begin())) {
    memo_theta_.assign(theta, theta + n);
    memo_ok_ = Fold(theta, &memo_r_aug_, &memo_rho_sum_);
  }
  if (!memo_ok_) return false;
  if (jacobians == nullptr || jacobians[0] == nullptr) {
    std::fill(residuals, residuals + n, 0.0);
    residuals[n] = std::sqrt(memo_rho_sum_);
    return true;
  }
  const Eigen::VectorXd z = memo_r_aug_.col(n).head(n);
  for (int k = 0; k < n; ++k) residuals[k] = z[k];
  residuals[n] = std::sqrt(std::max(0.0, memo_rho_sum_ - z.squaredNorm()));
  // Row-major (n + 1) x n: R, then a row of zeros.
  double* jac = jacobians[0];
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) jac[i * n + k] = memo_r_aug_(i, k);
  }
  std::fill(jac + n * n, jac + (n + 1) * n, 0.0);
  return true;
}

bool FoldedTensionCost::SolvedAt(const double* theta) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return samples_.FillsSolved() && memo_ok_ && !memo_theta_.empty() &&
         std::equal(theta, theta + n_, memo_theta_.begin());
}

bool FoldedTensionCost::FoldedAt(const double* theta, Eigen::MatrixXd* r_aug) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!memo_ok_ || memo_theta_.empty() || !std::equal(theta, theta + n_, memo_theta_.begin())) {
    return false;
  }
  *r_aug = memo_r_aug_;
  return true;
}

}  // namespace fastcal::internal
