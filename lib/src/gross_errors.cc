// Robust screening of the tension readings (gross_errors.h).
#include "fastcal/gross_errors.h"

#include <algorithm>
#include <cmath>

namespace fastcal {

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
