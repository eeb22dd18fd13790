// The slow-error process's amplitude and time constant from a fit's residuals, by
// restricted maximum likelihood (Durbin and Koopman 2012, ch. 7; Harvey 1989).
//
// With the Kalman filter of slow_error_filter.h, for readings x_t (residuals over their
// white sigma s_t) of the fit at its parameters:
//   -2 l(a, tau) = sum_t (log F_t + x~_t^2)
// (the prediction-error decomposition). The fit's parameters have already taken out of
// the residuals what they can absorb; the sensors' biases (and gains), constant over a
// session, absorb most of a slow error's low frequencies, and plain maximum likelihood
// would then see too little of it. Per cable i and session k the biases' (and gains')
// columns X (1 / s_t, reading_t / s_t), whitened alongside, are profiled out
// restrictedly (REML for a linear nuisance; Harville 1974):
//   -2 l_R = sum_t (log F_t + x~_t^2) + sum_{i,k} (log det X~^T X~ - b^T (X~^T X~)^-1 b),
//   b = X~^T x~,
// which also keeps a sensor re-zeroed between sessions from reading as slow error.
// Maximised over (log a, log tau) by a coarse grid then Nelder-Mead; uncertainties from
// the curvature (central differences) at the maximum.
#ifndef FASTCAL_INTERNAL_SLOW_ERROR_ESTIMATE_H_
#define FASTCAL_INTERNAL_SLOW_ERROR_ESTIMATE_H_

#include <array>
#include <optional>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/slow_error.h"

namespace fastcal::internal {

// The floor of the estimated amplitude, as a fraction of the white sigma: below it a slow
// error changes the likelihood by less than its own noise on any survey.
inline constexpr double kMinSlowErrorRatio = 0.02;

// One fitted sample's readings, for the estimate.
struct SlowErrorSample {
  double time_s = 0.0;
  int session = 0;
  std::array<double, kNumCables> x{};          // (prediction - measured) / s
  std::array<double, kNumCables> sigma_n{};    // s, the white sigma (N)
  std::array<double, kNumCables> reading_n{};  // the predicted reading (N)
  std::array<bool, kNumCables> excluded{};     // gross errors: left out
};

struct SlowErrorEstimateInputs {
  std::vector<SlowErrorSample> samples;  // time order (file order)
  SlowErrorSpec spec;                    // what is stated and what is estimated
  // Nuisance columns profiled out per cable and session: the bias (always) and the gain.
  bool gain_nuisance = false;
  // Threads the likelihood's filters run on (the cables split among them); the results
  // are the same bits on any number.
  int num_threads = 1;
  // A previous estimate's maximum-likelihood process, where the searches start instead of
  // at a coarse grid's best node (the grid guards a first estimate against a ridge along
  // which Nelder-Mead alone would stall; a re-estimate after a step of the fit starts
  // next to its maximum, and the grid was a third of its likelihood evaluations). Unset,
  // or without a positive amplitude and time constant: the grid.
  std::optional<SlowErrorProcess> start;
};

// -2 l_R of `process` (white noise only when inactive), up to a constant.
double SlowErrorMinusTwoLogLikelihood(const SlowErrorEstimateInputs& in,
                                      const SlowErrorProcess& process);

// The estimate: the spec's stated parts with the estimated ones at their maximum, and the
// checks of SlowErrorReport (likelihood ratio against white noise; the stated process
// against the maximum-likelihood one). `in.spec.enabled` must be true.
SlowErrorReport EstimateSlowError(const SlowErrorEstimateInputs& in);

// Up to `budget` fitted samples for the estimate: all of them, or contiguous runs spread
// evenly over them (each run's filter starts afresh: runs far apart are independent), so
// that the estimate of a long dataset costs a bounded time. Returns indices 0..count-1.
std::vector<int> SlowErrorEstimateSamples(int count, int budget);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_SLOW_ERROR_ESTIMATE_H_
