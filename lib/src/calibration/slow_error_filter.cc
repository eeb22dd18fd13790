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

double ReadingWhitener::Whiten(double time_s, int session, const double* rho, const bool* excluded,
                               double* rows, double* log_f_each) {
  if (!active_) return 0.0;
  const bool fresh =
      !started_ || StartsNewSeries(previous_time_s_, previous_session_, time_s, session);
  const double phi =
      fresh ? 0.0 : SlowErrorCorrelation(time_s - previous_time_s_, time_constant_s_);
  started_ = true;
  previous_time_s_ = time_s;
  previous_session_ = session;
  double log_f = 0.0;
  for (int i = first_cable_; i < end_cable_; ++i) {
    SlowErrorFilter& filter = filters_[i];
    if (fresh) {
      filter.Reset();
    } else {
      filter.Predict(phi);
    }
    const bool update = excluded == nullptr || !excluded[i];
    const double f = filter.Innovate(rho[i], rows + i * columns_, update);
    const double term = update ? std::log(f) : 0.0;
    if (update) log_f += term;
    if (log_f_each != nullptr) log_f_each[i] = term;
  }
  return log_f;
}

}  // namespace fastcal::internal
