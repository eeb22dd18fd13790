// The tension readings' scale against the cabin's weight (fastcal/tension_scale.h):
// sum_i T_i >= |sum_i T_i u_i,z| = m |g| at equilibrium (the cables' lower-end forces
// hold the cabin's weight), so the median sum over the samples bounds the unit.
#include "fastcal/tension_scale.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "fastcal/internal/number_text.h"

namespace fastcal {

bool CheckTensionScale(const Dataset& data, const CableRobot& model, std::string* error) {
  if (!data.has_tensions || data.samples.empty()) return true;
  std::vector<double> sums;
  sums.reserve(data.samples.size());
  for (const Sample& s : data.samples) {
    double sum = 0.0;
    for (double t : s.tension_n) sum += t;
    sums.push_back(sum);
  }
  const auto middle = sums.begin() + static_cast<std::ptrdiff_t>(sums.size() / 2);
  std::nth_element(sums.begin(), middle, sums.end());
  const double median_n = *middle;
  const double weight_n = model.cabin_mass_kg * std::abs(model.gravity_m_per_s2);
  const auto plausible = [&](double sum_n) {
    return sum_n >= kMinWeightFraction * weight_n && sum_n <= kMaxWeightMultiple * weight_n;
  };
  if (plausible(median_n)) return true;
  constexpr double kNPerKgf = 9.80665;  // a tonne-force per kN, a kgf per N
  const bool small = median_n < kMinWeightFraction * weight_n;
  *error = (data.path.empty() ? std::string("the data") : data.path) +
           ": the six tensions sum to " + internal::FormatDouble("%.4g", median_n / 1e3) +
           " kN a sample (median), where the cabin's weight alone (" +
           internal::FormatDouble("%.4g", model.cabin_mass_kg) + " kg, " +
           internal::FormatDouble("%.4g", weight_n / 1e3) + " kN) needs at least that much: " +
           (!small ? "read 1000x large? (tensions in kN where the column map says N)"
            : plausible(median_n * 1e3)
                ? "read 1000x small? (tensions in N where the column map says kN)"
            : plausible(median_n * kNPerKgf)
                ? "read 9.8x small? (tonne-force or kgf where the column map says kN or N)"
                : "read in the wrong unit?") +
           "; check the tension columns' unit (T1_kN ... T6_kN are in kN)";
  return false;
}

}  // namespace fastcal
