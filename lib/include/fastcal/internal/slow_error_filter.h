// Whitening of each cable's readings by the slow-error process (slow_error.h): the Kalman
// filter of the state-space model (Durbin and Koopman, "Time Series Analysis by State
// Space Methods", 2nd ed. 2012, ch. 4)
//   x_t = rho_t u_t + eps_t,                    eps_t ~ N(0, 1)
//   u_t = phi_t u_{t-1} + sqrt(1 - phi_t^2) w_t,  w_t ~ N(0, 1),  u ~ N(0, 1) at a series' start
// with x_t a residual over its white sigma s_t and rho_t = sigma_e(t) / s_t. Per reading:
//   predict    m- = phi m,  P- = phi^2 P + 1 - phi^2     (a series' first: m- = 0, P- = 1)
//   innovate   v = x - rho m-,  F = rho^2 P- + 1,  whitened x~ = v / sqrt(F)
//   update     K = P- rho / F,  m = m- + K v,  P = P- - K rho P-
// Under the model the x~ are independent N(0, 1), and
//   -2 log L = sum_t (log F_t + x~_t^2) + const      (prediction-error decomposition),
// so least squares on the x~ is generalised least squares on the x, with the exact
// likelihood of irregular sampling and gaps, in O(1) memory per cable. The gains depend
// on the times and rho only, never on x: the same filter run over each column of a
// Jacobian (a linear function of the parameters) whitens it the same way, so m is kept per
// column. For evenly spaced readings without white noise this is the Prais-Winsten
// transformation (tests/slow_error_test.cc checks both against a dense GLS).
//
// A reading left out (a gross error) is innovated, so that it can be judged, but does not
// update the state: the filter then runs as if it were missing.
#ifndef FASTCAL_INTERNAL_SLOW_ERROR_FILTER_H_
#define FASTCAL_INTERNAL_SLOW_ERROR_FILTER_H_

#include <array>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/slow_error.h"

namespace fastcal::internal {

// One cable's filter over `columns` columns (a residual, or a Jacobian row and residual).
class SlowErrorFilter {
 public:
  explicit SlowErrorFilter(int columns = 1) : mean_(columns, 0.0) {}

  // The next reading starts a new, independent series.
  void Reset() { fresh_ = true; }
  // The next reading is phi = exp(-dt / tau) after the previous one.
  void Predict(double phi);
  // Whitens row[0 .. columns) in place (x -> x~) and returns F; the state takes the
  // reading in when `update`.
  double Innovate(double rho, double* row, bool update);
  // Before the next Innovate (after Predict or Reset): its prior P- and the prior mean m-
  // of column c (a series' first reading: 1 and 0).
  double PriorVariance() const { return fresh_ ? 1.0 : p_; }
  // The next reading starts the filter afresh (nothing taken in yet).
  bool Fresh() const { return fresh_; }
  double PriorMean(int c) const { return fresh_ ? 0.0 : mean_[c]; }

 private:
  std::vector<double> mean_;  // E[u | readings so far], per column
  double p_ = 1.0;            // Var[u | readings so far]
  bool fresh_ = true;         // the next reading starts a series
};

// What a pass's filters did to each reading, for the exact whitening of a step that starts
// at a reading (internal/step_scan.h): called for each cable's reading before it is
// innovated, with the prediction's phi (0 where the reading starts a series), rho, and the
// filter's prior (its variance, and its mean of each column).
class WhitenObserver {
 public:
  virtual ~WhitenObserver() = default;
  virtual void Reading(int cable, double phi, bool fresh, double rho, bool update,
                       const SlowErrorFilter& prior) = 0;
};

// The six cables' filters over a pass's samples in time order (file order); or those of
// cables [first_cable, end_cable) only (each cable's filter is independent of the others':
// cables can be whitened on separate threads).
class ReadingWhitener {
 public:
  // White noise only when !process.IsActive(): Whiten leaves rows alone.
  ReadingWhitener(const SlowErrorProcess& process, int columns, int first_cable = 0,
                  int end_cable = kNumCables);

  bool active() const { return active_; }
  // Told of every reading from now on (null: none); not owned.
  void set_observer(WhitenObserver* observer) { observer_ = observer; }
  // One sample: `rows` holds its six readings' rows, cable i's at rows + i * columns;
  // rho[i] = sigma_e / s of cable i's reading; excluded (may be null) the readings that do
  // not update the state. Returns sum log F over the readings that updated it (in cable
  // order), and, when log_f is not null, each cable's log F in log_f[i] (0 where the
  // reading did not update the state). Only the range's cables are read and written.
  double Whiten(double time_s, int session, const double* rho, const bool* excluded, double* rows,
                double* log_f = nullptr);
  // The same whitening without the likelihood's terms, for a pass that only folds or
  // screens the innovations (a log per reading was ~6% of a track's fold).
  void WhitenOnly(double time_s, int session, const double* rho, const bool* excluded,
                  double* rows);

 private:
  // phi for the step from the previous reading (0 with *fresh at a series' start); the
  // last interval's phi is kept: telemetry comes at one rate, and exp was a call a sample.
  double Advance(double time_s, int session, bool* fresh);
  // One sample's whitening; with kLikelihood its log F terms (Whiten's return).
  template <bool kLikelihood>
  double Step(double time_s, int session, const double* rho, const bool* excluded, double* rows,
              double* log_f_each);

  bool active_ = false;
  double time_constant_s_ = 0.0;
  int columns_ = 1;
  int first_cable_ = 0, end_cable_ = kNumCables;
  std::array<SlowErrorFilter, kNumCables> filters_;
  bool started_ = false;
  double previous_time_s_ = 0.0;
  int previous_session_ = 0;
  double last_dt_s_ = -1.0, last_phi_ = 0.0;
  WhitenObserver* observer_ = nullptr;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_SLOW_ERROR_FILTER_H_
