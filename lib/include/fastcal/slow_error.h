// Slow tension-sensor errors: a first-order Gauss-Markov error of each cable's reading
// (docs/calibration.md, "Slow sensor errors"; methods.md).
//
// A strain-gauge load cell's error wanders with temperature, electronics and the cable's
// own slow motion over tens of seconds to minutes. Each cable's reading is modelled as
//   y_t = model_t + e_t + eps_t,
// eps_t white with the spec's tension sigma s_t (tension_sigma_kN, tension_sigma_percent),
// and e_t a first-order Gauss-Markov process (the continuous-time AR(1); Gelb (ed.),
// "Applied Optimal Estimation", 1974, ch. 3):
//   de = -e / tau dt + sqrt(2 / tau) sigma_e dW,
//   sigma_e(t)^2 = sigma_abs^2 + (percent / 100 * reading_t)^2   (stationary sd).
// Between readings dt apart its standardised state u = e / sigma_e steps as
//   u_t = phi_t u_{t-1} + sqrt(1 - phi_t^2) w_t,   phi_t = exp(-dt / tau),   w_t ~ N(0, 1),
// so that readings hours or days apart are independent (phi ~ 0): sessions days apart get
// independent offsets from the process itself. A new session, a time that goes backwards
// or a non-finite time starts an independent series (the state drawn afresh).
//
// The calibration whitens each cable's readings by this process (a Kalman filter in time
// order: internal/slow_error_filter.h), so that its estimates are generalised least
// squares, and estimates the process's amplitude and time constant from its own
// residuals by restricted maximum likelihood (EstimateSlowError, slow_error_estimate.h).
#ifndef FASTCAL_SLOW_ERROR_H_
#define FASTCAL_SLOW_ERROR_H_

#include <string>

namespace fastcal {

// The process's parameters (SI). Inactive (white noise only) unless tau > 0 and some
// amplitude > 0.
struct SlowErrorProcess {
  double sigma_n = 0.0;          // absolute part of the stationary sd (N), >= 0
  double sigma_percent = 0.0;    // relative part, percent of the reading, >= 0
  double time_constant_s = 0.0;  // tau (s), > 0 when active

  bool IsActive() const { return time_constant_s > 0.0 && (sigma_n > 0.0 || sigma_percent > 0.0); }
  // The stationary sd at a reading (N).
  double SigmaN(double reading_n) const;
  // False, naming the field, for negative or non-finite values.
  bool IsValid(std::string* error) const;
};

// The process a calibration used, and what its residuals say of it (CalibrationResult,
// console, report, summary.json).
struct SlowErrorReport {
  bool enabled = false;      // the spec models a slow error (noise.slow_error)
  SlowErrorProcess process;  // what the final fit whitened with
  // Which parts were estimated from the residuals (the others are the spec's).
  bool amplitude_estimated = false;  // sigma_percent, or sigma_n when the spec says so
  bool amplitude_in_percent = true;  // the estimated (or stated) amplitude's part
  bool time_constant_estimated = false;
  // 1-sigma uncertainties of the estimated parts (the amplitude in its own unit: percent
  // or N; tau in s), from the curvature of the restricted likelihood; 0 when stated.
  double amplitude_sigma = 0.0;
  double time_constant_sigma_s = 0.0;
  // The amplitude reached its floor (kMinSlowErrorRatio of the white sigma): the residuals
  // show no slow error, and tau is then undetermined.
  bool amplitude_at_floor = false;
  // tau reached a bound of its search range (below the sampling interval: the error is
  // white at this sampling; beyond the longest series: a constant, the biases take it).
  bool time_constant_at_bound = false;
  // 2 (l(process) - l(white noise alone)), l the restricted log-likelihood.
  double likelihood_ratio_vs_white = 0.0;
  // A track's update kept the process the track was built with (not re-estimated: the
  // fields above but `process` are not this run's).
  bool kept_from_track = false;
  // Where the spec states both parts: the maximum-likelihood process, the likelihood-ratio
  // statistic of the stated one against it (chi-square, 2 degrees of freedom), its
  // p-value, and whether the residuals contradict the stated process (p < 1%).
  SlowErrorProcess maximum_likelihood;
  double stated_likelihood_ratio = 0.0;
  double stated_p_value = 1.0;
  bool stated_contradicted = false;
  int series = 0;        // independent series in the fitted samples (sessions, gaps)
  int samples_used = 0;  // fitted samples the estimate used (a subset on long data)
  int passes = 0;        // fits the process was re-estimated over
  // The likelihood's evaluations the searches took (each a filter over every sample used):
  // the estimate's cost, and whether a re-estimate started at the one before (internal::
  // SlowErrorEstimateInputs::start) or at the grid.
  int likelihood_evaluations = 0;
};

// One paragraph for consoles and reports: the process, estimated or stated, with its
// uncertainties and the likelihood ratio against white noise ("" when not enabled).
std::string DescribeSlowError(const SlowErrorReport& report);
// Where a stated process is contradicted by the residuals: what they say instead ("" when
// it is not).
std::string DescribeStatedSlowErrorCheck(const SlowErrorReport& report);

// phi = exp(-dt / tau) between two readings of one series dt apart; 0 for tau <= 0.
double SlowErrorCorrelation(double dt_s, double time_constant_s);

// Whether a reading at (time_s, session) starts a new independent series after the
// previous one at (previous_time_s, previous_session): another session, a time that
// goes backwards, or a non-finite time. (Equal times are one instant: phi = 1.)
bool StartsNewSeries(double previous_time_s, int previous_session, double time_s, int session);

}  // namespace fastcal

#endif  // FASTCAL_SLOW_ERROR_H_
