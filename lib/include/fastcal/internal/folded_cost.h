// The fit's data term as one Ceres residual block of n + 1 residuals (issue 20: one
// block per sample cost ~1.5 kB a sample in Ceres and a dense 6N x n Jacobian).
//
// Ceres's Levenberg-Marquardt sees the data only through the cost
//   F = 1/2 sum_t rho(|r_t|^2),
// the gradient J_c^T r_c and the Gauss-Newton matrix J_c^T J_c, where r_c, J_c are each
// sample's six rows with the robust loss's correction (Triggs et al. 2000, as Ceres's
// own corrector applies it per residual block; rho(s) = s without a loss). With the QR
// factorisation of the stacked rows, [J_c r_c] = Q [R z; 0 e],
//   r~ = (z, sqrt(2F - |z|^2)),   J~ = (R; 0)
// give J~^T J~ = R^T R = J_c^T J_c, J~^T r~ = R^T z = J_c^T r_c and 1/2 |r~|^2 = F: the
// solver takes the steps it would take on the 6N rows, and the condition of J is not
// squared (no normal equations). 2F - |z|^2 >= 0 because |z|^2 <= |r_c|^2 =
// sum rho'(s) s <= sum rho(s) for a concave loss with rho(0) = 0 (none, Huber, Cauchy);
// it is clamped at 0 against rounding. Without Jacobians (a trial step's cost),
// r~ = (0, ..., 0, sqrt(2F)).
//
// The QR is folded chunk by chunk over the samples on `threads` threads
// (sample_chunks.h): memory independent of N, and the same numbers on any number of
// threads.
//
// Memo: the last fold with its Jacobian is kept, and every evaluation folds the Jacobian
// too, a trial step's cost included: Levenberg-Marquardt evaluates a trial step's cost,
// then, when it takes the step (nearly always near the optimum), the Jacobian at the same
// theta; the identifiability check's Jacobian at the initial point is the solver's first
// one too. The statics of each sample are then solved once per theta, not twice (issue
// 28: a third less work in the fit at 10^6 samples); a rejected trial step costs a
// Jacobian's derivatives and fold for nothing. The memo holds the value of a pure
// function of theta (the same cost, bit for bit, as a fold without Jacobian), so results
// are as without it.
#ifndef FASTCAL_INTERNAL_FOLDED_COST_H_
#define FASTCAL_INTERNAL_FOLDED_COST_H_

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <array>
#include <mutex>
#include <vector>

#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/row_fold.h"
#include "fastcal/internal/sample_rows.h"

namespace fastcal::internal {

// One sample's rows with the robust loss's correction applied in place (Ceres's
// Corrector): r <- s_r r, J <- sqrt(rho') (J - (alpha / |r|^2) r r^T J), with
// alpha = 1 - sqrt(1 + 2 |r|^2 rho'' / rho') when rho'' > 0, else 0 and s_r = sqrt(rho').
// Returns rho(|r|^2) (|r|^2 without a loss). `jacobian` (6 x n, row-major) may be null.
double CorrectForLoss(const ceres::LossFunction* loss, double* residuals, double* jacobian, int n,
                      int readings = kNumCables);

// By reading (issue 28): a sensor's gain and bias enter one cable's reading only, so the
// rows of reading i are zero outside its own columns and the shared ones (the statics').
// Per reading, those columns (own, then shared, then the residual's, n), for a
// GroupedRowFold (row_fold.h: 12 of 22 columns for the recommended spec, a third of the
// flops); empty when nothing is gained: no cable's own column, or a loss (its correction
// mixes a sample's rows), or lengths' rows.
std::vector<std::vector<int>> ReadingColumns(const FittedSamples& samples,
                                             const ceres::LossFunction* loss);

class FoldedTensionCost : public ceres::CostFunction {
 public:
  // `samples` and `loss` (may be null) must outlive the cost. `by_reading`: each
  // reading's rows folded on their own first where that saves work (ReadingColumns);
  // false folds every row at full width (the same R^T R to rounding; for tests).
  FoldedTensionCost(const FittedSamples& samples, const ceres::LossFunction* loss, int threads,
                    bool by_reading = true);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // The last evaluation's folded rows [R z] when it was at theta (no new evaluation);
  // false otherwise.
  bool FoldedAt(const double* theta, Eigen::MatrixXd* r_aug) const;
  // Whether the last evaluation folded every fitted sample at theta and left what their
  // statics solved in the samples' `solved` (FittedSamples::FillsSolved): the readings a
  // prediction at theta would compute, without solving again.
  bool SolvedAt(const double* theta) const;
  // Whether each reading's rows are folded on their own first (ReadingColumns).
  bool folds_by_reading() const { return !reading_columns_.empty(); }

 private:
  // Chunk rows [begin, end) folded by reading into `fold`; their squared norms into rho.
  void FoldByReading(const SampleRows& rows, int begin, int end, RowFold* fold, double* rho) const;
  bool Fold(const double* theta, Eigen::MatrixXd* r_aug, double* rho_sum) const;

  FittedSamples samples_;
  const ceres::LossFunction* loss_;
  int threads_, n_;
  // Per reading, its columns when the rows are folded by reading; empty otherwise.
  std::vector<std::vector<int>> reading_columns_;
  // The last evaluation (see Memo above).
  mutable std::mutex mutex_;
  mutable std::vector<double> memo_theta_;
  mutable Eigen::MatrixXd memo_r_aug_;
  mutable double memo_rho_sum_ = 0.0;
  mutable bool memo_ok_ = false;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_FOLDED_COST_H_
