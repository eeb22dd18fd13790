// The slow-error process's Kalman filter (internal/slow_error_filter.h).
#include "fastcal/internal/slow_error_filter.h"

#include <algorithm>
#include <cmath>

namespace fastcal::internal {

void SlowErrorFilter::Predict(double phi) {
  if (fresh_) return;
  for (double& m : mean_) m *= phi;
  p_ = phi * phi * p_ + (1.0 - phi * phi);
}

double SlowErrorFilter::Innovate(double rho, double* row, bool update) {
  if (fresh_) {
    std::fill(mean_.begin(), mean_.end(), 0.0);
    p_ = 1.0;
  }
  const double f = rho * rho * p_ + 1.0;
  const double scale = 1.0 / std::sqrt(f);
  const double gain = p_ * rho / f;
  const int columns = static_cast<int>(mean_.size());
  for (int c = 0; c < columns; ++c) {
    const double v = row[c] - rho * mean_[c];
    if (update) mean_[c] += gain * v;
    row[c] = v * scale;
  }
  if (update) {
    p_ -= gain * rho * p_;
    fresh_ = false;
  }
  return f;
}

ReadingWhitener::ReadingWhitener(const SlowErrorProcess& process, int columns, int first_cable,
                                 int end_cable)
    : active_(process.IsActive()),
      time_constant_s_(process.time_constant_s),
      columns_(columns),
      first_cable_(first_cable),
      end_cable_(end_cable) {
  for (SlowErrorFilter& f : filters_) f = SlowErrorFilter(columns);
}

double ReadingWhitener::Advance(double time_s, int session, bool* fresh) {
  *fresh = !started_ || StartsNewSeries(previous_time_s_, previous_session_, time_s, session);
  double phi = 0.0;
  if (!*fresh) {
    const double dt_s = time_s - previous_time_s_;
    if (dt_s != last_dt_s_) {
      last_dt_s_ = dt_s;
      last_phi_ = SlowErrorCorrelation(dt_s, time_constant_s_);
    }
    phi = last_phi_;
  }
  started_ = true;
  previous_time_s_ = time_s;
  previous_session_ = session;
  return phi;
}

template <bool kLikelihood>
double ReadingWhitener::Step(double time_s, int session, const double* rho, const bool* excluded,
                             double* rows, double* log_f_each) {
  if (!active_) return 0.0;
  bool fresh = false;
  const double phi = Advance(time_s, session, &fresh);
  double log_f = 0.0;
  for (int i = first_cable_; i < end_cable_; ++i) {
    SlowErrorFilter& filter = filters_[i];
    if (fresh) {
      filter.Reset();
    } else {
      filter.Predict(phi);
    }
    const bool update = excluded == nullptr || !excluded[i];
    if (observer_ != nullptr)
      observer_->Reading(i, fresh ? 0.0 : phi, fresh, rho[i], update, filter);
    const double f = filter.Innovate(rho[i], rows + i * columns_, update);
    if constexpr (kLikelihood) {
      const double term = update ? std::log(f) : 0.0;
      if (update) log_f += term;
      if (log_f_each != nullptr) log_f_each[i] = term;
    }
  }
  return log_f;
}

double ReadingWhitener::Whiten(double time_s, int session, const double* rho, const bool* excluded,
                               double* rows, double* log_f_each) {
  return Step<true>(time_s, session, rho, excluded, rows, log_f_each);
}

void ReadingWhitener::WhitenOnly(double time_s, int session, const double* rho,
                                 const bool* excluded, double* rows) {
  Step<false>(time_s, session, rho, excluded, rows, nullptr);
}

}  // namespace fastcal::internal
