// The slow-error process (slow_error.h): its parameters, series, and description.
#include "fastcal/slow_error.h"

#include <cmath>

#include "fastcal/internal/number_text.h"
#include "fastcal/internal/slow_error_estimate.h"

namespace fastcal {

double SlowErrorProcess::SigmaN(double reading_n) const {
  const double relative = sigma_percent / 100.0 * reading_n;
  return std::sqrt(sigma_n * sigma_n + relative * relative);
}

bool SlowErrorProcess::IsValid(std::string* error) const {
  const auto fail = [&](const char* field, double v) {
    if (error != nullptr) {
      *error =
          std::string(field) + " must be finite and >= 0, got " + internal::FormatDouble("%g", v);
    }
    return false;
  };
  if (!(std::isfinite(sigma_n) && sigma_n >= 0.0)) return fail("sigma_n", sigma_n);
  if (!(std::isfinite(sigma_percent) && sigma_percent >= 0.0)) {
    return fail("sigma_percent", sigma_percent);
  }
  if (!(std::isfinite(time_constant_s) && time_constant_s >= 0.0)) {
    return fail("time_constant_s", time_constant_s);
  }
  return true;
}

double SlowErrorCorrelation(double dt_s, double time_constant_s) {
  if (!(time_constant_s > 0.0)) return 0.0;
  return std::exp(-dt_s / time_constant_s);
}

bool StartsNewSeries(double previous_time_s, int previous_session, double time_s, int session) {
  return session != previous_session || !std::isfinite(time_s) || !std::isfinite(previous_time_s) ||
         time_s < previous_time_s;
}

namespace {

std::string Num(const char* format, double v) { return internal::FormatDouble(format, v); }

// "1.52 +- 0.11 % of the reading", "0.8 kN" (the estimated part with its sigma).
std::string Amplitude(const SlowErrorReport& r) {
  const bool percent = r.amplitude_in_percent;
  const double value = percent ? r.process.sigma_percent : r.process.sigma_n / 1e3;
  const double sigma = percent ? r.amplitude_sigma : r.amplitude_sigma / 1e3;
  std::string text = Num("%.3g", value);
  if (r.amplitude_estimated && sigma > 0.0) text += " +- " + Num("%.2g", sigma);
  text += percent ? " % of the reading" : " kN";
  // The other, stated part, if any.
  if (percent && r.process.sigma_n > 0.0)
    text += " and " + Num("%.3g", r.process.sigma_n / 1e3) + " kN";
  if (!percent && r.process.sigma_percent > 0.0) {
    text += " and " + Num("%.3g", r.process.sigma_percent) + " %";
  }
  return text;
}

}  // namespace

std::string DescribeSlowError(const SlowErrorReport& r) {
  if (!r.enabled) return "";
  if (r.kept_from_track) {
    // Issue 59: an update said "likelihood ratio against white noise 0", which read as a
    // finding; it had not been estimated.
    const bool percent = r.amplitude_in_percent;
    return "slow sensor error (the track's, kept by this update; --refold re-estimates it): sd " +
           Num("%.3g", percent ? r.process.sigma_percent : r.process.sigma_n / 1e3) +
           (percent ? " % of the reading" : " kN") + ", time constant " +
           Num("%.3g", r.process.time_constant_s) +
           " s; the fit whitens the readings by it (generalised least squares)";
  }
  const bool estimated = r.amplitude_estimated || r.time_constant_estimated;
  std::string text = std::string("slow sensor error (") + (estimated ? "estimated" : "stated") +
                     ", a Gauss-Markov process per cable): ";
  if (r.amplitude_estimated && r.amplitude_at_floor) {
    return text + "none found in the residuals (amplitude at its floor, below " +
           Num("%.2g", internal::kMinSlowErrorRatio * 100.0) +
           "% of the white noise's); readings treated as white";
  }
  text += "sd " + Amplitude(r) + ", time constant " + Num("%.3g", r.process.time_constant_s);
  if (r.time_constant_estimated && r.time_constant_sigma_s > 0.0) {
    text += " +- " + Num("%.2g", r.time_constant_sigma_s);
  }
  text += " s";
  if (r.time_constant_estimated && r.time_constant_at_bound) {
    text +=
        " (at the edge of its range: shorter than the sampling interval, or longer than the "
        "survey)";
  }
  text += "; likelihood ratio against white noise " + Num("%.3g", r.likelihood_ratio_vs_white) +
          "; the fit whitens the readings by it (generalised least squares)";
  return text;
}

std::string DescribeStatedSlowErrorCheck(const SlowErrorReport& r) {
  if (!r.enabled || !r.stated_contradicted) return "";
  const SlowErrorProcess& m = r.maximum_likelihood;
  const bool percent = r.amplitude_in_percent;
  return std::string("the residuals contradict the stated slow error: maximum likelihood gives ") +
         "sd " + Num("%.3g", percent ? m.sigma_percent : m.sigma_n / 1e3) +
         (percent ? " %" : " kN") + " and time constant " + Num("%.3g", m.time_constant_s) +
         " s (likelihood ratio " + Num("%.3g", r.stated_likelihood_ratio) +
         ", p = " + Num("%.2g", r.stated_p_value) +
         "); state those, or write estimate, in noise.slow_error";
}

}  // namespace fastcal
