// The exact whitened columns of a step that starts at a reading (a sensor re-zeroed, a move
// of a window's own parameters), for every reading of a stretch at once: the likelihood of
// a change at each gap between samples (issue 53), where the slow sensor error's whitening
// (slow_error_filter.h) makes a step's column more than the whitened column cut at the step.
//
// A column x of one cable's readings is whitened by the filter as
//   w_t = (x_t - rho_t m-_t(x)) / sqrt(F_t),   m-_{t+1}(x) = phi_{t+1} (m-_t + K_t (x_t - rho_t
//   m-_t))
// (K_t = P-_t rho_t / F_t; a reading out of the fit only predicts: K = 0, and its row is 0).
// The step column x^k (0 before reading k, x from it on) has m-(x^k) = 0 up to k, so the
// difference d_t = m-_t(x) - m-_t(x^k) starts at d_k = m-_k(x) and follows
//   d_{t+1} = a_t d_t,   a_t = phi_{t+1} (1 - K_t rho_t)   (0 where t + 1 starts a series)
// and w_t(x^k) = w_t(x) + c_t d_t, c_t = rho_t / sqrt(F_t), for t >= k. So with A(k, t) =
// a_k ... a_{t-1}, per cable,
//   sum_{t>=k} w_t(x^k) y_t = sum_{t>=k} w_t(x) y_t + m-_k(x) G_k(y),
//   G_k(y) = sum_{t>=k} c_t A(k, t) y_t = c_k y_k + a_k G_{k+1}(y)
//   sum_{t>=k} w_t(x^k) w_t(z^k) = sum_{t>=k} w(x) w(z) + m-_k(x) G_k(w(z)) + m-_k(z) G_k(w(x))
//                                  + m-_k(x) m-_k(z) Q_k,   Q_k = c_k^2 + a_k^2 Q_{k+1}
// for any whitened column y (each fitted parameter's and the residual): the step's cross
// information with every column, its own information and its score, for every cut k of
// the stretch in one backward pass, summed over the cables. Without the slow error (white
// noise) m- = 0 and the step's column is the whitened column cut at the step.
#ifndef FASTCAL_INTERNAL_STEP_SCAN_H_
#define FASTCAL_INTERNAL_STEP_SCAN_H_

#include <Eigen/Core>
#include <array>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/internal/slow_error_filter.h"

namespace fastcal::internal {

// A stretch of a pass's readings as the filters saw them: samples 0 .. samples - 1 in time
// order, the cuts before samples 0 .. cuts - 1 scanned (the samples after them only carry
// the steps' transients).
struct StepScanInput {
  int columns = 0;         // the rows' width: the fitted columns and the residual (last)
  std::vector<int> steps;  // the columns whose steps are scanned
  int cuts = 0;
  int samples = 0;
  // Per sample t and cable i (index t * kNumCables + i): the whitened row (`columns`
  // values, zero for a reading out of the fit), c_t, a_t, and m-_t of each step column.
  std::vector<double> rows, c, a, prior_mean;
  // The rows' sums w^T w of the step columns (steps x columns) over every reading after
  // the stretch's cuts, samples `cuts` on and those beyond the stretch (the window's
  // blocks after it): the steps' columns there are the columns themselves.
  Eigen::MatrixXd after;
  double* Row(int t, int i) {
    return rows.data() + (static_cast<size_t>(t) * kNumCables + i) * columns;
  }
  const double* Row(int t, int i) const {
    return rows.data() + (static_cast<size_t>(t) * kNumCables + i) * columns;
  }
};

// Per cut k (before sample k): the step columns' sums with every column (steps x columns:
// their cross information with the fitted columns, and in the last column their score
// J^T r) and among themselves (steps x steps), from k to the window's end.
struct StepScan {
  std::vector<Eigen::MatrixXd> cross, self;
};

StepScan ScanSteps(const StepScanInput& in);

// Records a pass's filters (a ReadingWhitener over all six cables, its observer) and rows
// over samples [first, first + samples) of the pass, the cuts before the first `cuts` of
// them scanned: the StepScanInput of that stretch (but `after`, the caller's).
class StepScanRecorder : public WhitenObserver {
 public:
  StepScanRecorder(int columns, std::vector<int> steps, long long first, int cuts, int samples);
  void Reading(int cable, double phi, bool fresh, double rho, bool update,
               const SlowErrorFilter& prior) override;
  // Sample `sample` of the pass, whitened (its six readings' rows, `columns` each, zero for
  // a reading out of the fit): kept when it is in the stretch.
  void Rows(long long sample, const double* rows);
  StepScanInput& input() { return in_; }
  long long first() const { return first_; }

 private:
  StepScanInput in_;
  long long first_ = 0;
  long long readings_ = 0;  // Reading calls so far: sample readings_ / 6, cable readings_ % 6
  std::array<double, kNumCables> gain_rho_{};  // K rho of each cable's last recorded reading
  std::array<bool, kNumCables> updated_{};
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_STEP_SCAN_H_
