// Robust screening of the tension readings (gross_errors.h).
#include "fastcal/gross_errors.h"

#include <algorithm>
#include <cmath>

#include "fastcal/internal/number_text.h"

namespace fastcal {

double TwoSidedNormalQuantile(double tail) {
  double lo = 0.0, hi = 40.0;  // erfc(40 / sqrt 2) underflows to 0 < any tail asked
  for (int i = 0; i < 200 && lo < hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

GrossErrorThreshold ChooseGrossErrorThreshold(long long readings, double floor_sigmas,
                                              double family_false_alarm) {
  GrossErrorThreshold t;
  t.readings = std::max(1LL, readings);
  t.floor_sigmas = floor_sigmas;
  t.family_wise_sigmas =
      TwoSidedNormalQuantile(family_false_alarm / static_cast<double>(t.readings));
  t.sigmas = std::max(floor_sigmas, t.family_wise_sigmas);
  return t;
}

std::string DescribeGrossErrorThreshold(const GrossErrorThreshold& t) {
  // Locale-independent numbers (a report must not change with LC_NUMERIC).
  auto g3 = [](double v) { return internal::FormatDouble("%.3g", v); };
  const std::string n = std::to_string(t.readings);
  const std::string chance =
      "(a " + internal::FormatDouble("%g", 100.0 * kGrossErrorFamilyFalseAlarm) +
      "% chance that Gaussian noise names any)";
  if (t.family_wise_decides()) {
    return g3(t.sigmas) + " robust sigmas: the family-wise threshold for " + n + " readings " +
           chance + ", above the floor threshold_sigmas = " + g3(t.floor_sigmas);
  }
  return g3(t.sigmas) + " robust sigmas: the floor threshold_sigmas, above the family-wise " +
         g3(t.family_wise_sigmas) + " for " + n + " readings " + chance;
}

GrossErrorScreen ScreenGrossErrors(const std::vector<std::array<double, kNumCables>>& whitened,
                                   const std::vector<bool>& judge, double threshold_sigmas) {
  GrossErrorScreen s;
  const size_t n = whitened.size();
  auto judged = [&](size_t t) { return judge.empty() || judge[t]; };
  for (int i = 0; i < kNumCables; ++i) {
    std::vector<double> values;
    values.reserve(n);
    for (size_t t = 0; t < n; ++t) {
      if (judged(t) && std::isfinite(whitened[t][i])) values.push_back(whitened[t][i]);
    }
    s.cables[i] = RobustScaleOf(std::move(values));
    s.cables[i].scale = std::max(1.0, s.cables[i].scale);
  }
  s.flagged.assign(n, {});
  for (size_t t = 0; t < n; ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      const double d = std::abs(whitened[t][i] - s.cables[i].centre);
      // A non-finite residual (a reading the model cannot predict) is a gross error too.
      const bool flag = !(d <= threshold_sigmas * s.cables[i].scale);
      s.flagged[t][i] = flag;
      s.count_all += flag;
      if (judged(t)) {
        s.count += flag;
        ++s.judged;
      }
    }
  }
  return s;
}

}  // namespace fastcal
