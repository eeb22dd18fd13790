// The tension readings' scale against the cabin's weight (fastcal/tension_scale.h):
// sum_i T_i >= |sum_i T_i u_i,z| = m |g| at equilibrium (the cables' lower-end forces
// hold the cabin's weight), so the median sum over the samples bounds the unit.
#include "fastcal/tension_scale.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "fastcal/internal/number_text.h"
#include "fastcal/plausibility.h"

namespace fastcal {

namespace {

// The median of `values` (reordered).
double Median(std::vector<double>* values) {
  const auto middle = values->begin() + static_cast<std::ptrdiff_t>(values->size() / 2);
  std::nth_element(values->begin(), middle, values->end());
  return *middle;
}

std::string Where(const Dataset& data) {
  return data.path.empty() ? std::string("the data") : data.path;
}

// The whole sample's check: the median sum of the six against the weight.
bool CheckSum(const Dataset& data, const CableRobot& model, const char* whose, std::string* error) {
  std::vector<double> sums;
  sums.reserve(data.samples.size());
  for (const Sample& s : data.samples) {
    double sum = 0.0;
    for (double t : s.tension_n) sum += t;
    sums.push_back(sum);
  }
  const double median_n = Median(&sums);
  const double weight_n = model.cabin_mass_kg * std::abs(model.gravity_m_per_s2);
  const auto plausible = [&](double sum_n) {
    return sum_n >= kMinWeightFraction * weight_n && sum_n <= kMaxWeightMultiple * weight_n;
  };
  if (plausible(median_n)) return true;
  constexpr double kNPerKgf = 9.80665;  // a tonne-force per kN, a kgf per N
  const bool small = median_n < kMinWeightFraction * weight_n;
  // Read 1000x small: the file's kN declared N (its 180 read as 180 N); 1000x large: N
  // declared kN.
  *error = Where(data) + ": the six tensions sum to " +
           internal::FormatDouble("%.4g", median_n / 1e3) + " kN a sample (median), where " +
           whose + " weight alone (" + internal::FormatDouble("%.6g", model.cabin_mass_kg) +
           " kg, " + internal::FormatDouble("%.4g", weight_n / 1e3) +
           " kN) needs at least that much: " +
           (!small && plausible(median_n / 1e3)
                ? "read 1000x large? (tensions in N where the column map says kN)"
            : !small && plausible(median_n / kNPerKgf)
                ? "read 9.8x large? (kN where the column map says tonne-force, or N where it "
                  "says kgf)"
            : !small ? "read in the wrong unit?"
            : plausible(median_n * 1e3)
                ? "read 1000x small? (tensions in kN where the column map says N)"
            : plausible(median_n * kNPerKgf)
                ? "read 9.8x small? (tonne-force or kgf where the column map says kN or N)"
                : "read in the wrong unit?") +
           "; check the tension columns' unit (T1_kN ... T6_kN are in kN)";
  return false;
}

// Each cable against the others: one tension column in another unit than the rest (issue
// 37: a map's `unit: N` on T3 alone gave sensor_gain[3] = 0.001, exit 0) leaves the sum
// plausible but that cable's median kRatio or more from the median of the six medians.
// FAST's cables hold 50-800 kN anywhere on the cap, so no survey's medians differ by that.
bool CheckEachCable(const Dataset& data, std::string* error) {
  constexpr double kRatio = 30.0;
  constexpr size_t kMaxSamples = 200000;  // a strided subsample: a median needs no more
  const size_t stride = std::max<size_t>(1, data.samples.size() / kMaxSamples);
  std::array<double, kNumCables> median_n{};
  std::vector<double> values;
  for (int i = 0; i < kNumCables; ++i) {
    values.clear();
    for (size_t t = 0; t < data.samples.size(); t += stride) {
      values.push_back(data.samples[t].tension_n[i]);
    }
    median_n[i] = Median(&values);
  }
  std::vector<double> medians(median_n.begin(), median_n.end());
  const double typical_n = Median(&medians);
  if (!(typical_n > 0.0)) return true;  // the sum's check judges a file of zeros
  for (int i = 0; i < kNumCables; ++i) {
    const double ratio = median_n[i] / typical_n;
    if (ratio > 1.0 / kRatio && ratio < kRatio) continue;
    const bool near_thousand = std::abs(std::abs(std::log10(ratio)) - 3.0) < 0.6;  // NaN: no
    *error = Where(data) + ": cable " + std::to_string(i + 1) + "'s tensions (median " +
             internal::FormatDouble("%.4g", median_n[i] / 1e3) + " kN) are " +
             internal::FormatDouble("%.3g", ratio) + " times the other cables' (median " +
             internal::FormatDouble("%.4g", typical_n / 1e3) + " kN): " +
             (near_thousand ? ratio < 1.0 ? "read 1000x small? (T" + std::to_string(i + 1) +
                                                " in kN where the column map says N)"
                                          : "read 1000x large? (T" + std::to_string(i + 1) +
                                                " in N where the column map says kN)"
                            : std::string("another unit or sensor than the others?")) +
             "; check that column's unit";
    return false;
  }
  return true;
}

}  // namespace

bool CheckTensionScale(const Dataset& data, const CableRobot& model, std::string* error) {
  if (!data.has_tensions || data.samples.empty()) return true;
  // The cable first: one column slipped 1000x large makes the sum implausible too.
  return CheckEachCable(data, error) && CheckSum(data, model, "the cabin's", error);
}

bool CheckTensionScaleOfAnyCabin(const Dataset& data, std::string* error) {
  if (!data.has_tensions || data.samples.empty()) return true;
  CableRobot lightest = CableRobot::NominalFast();
  lightest.cabin_mass_kg = PlausibilityLimits().min_cabin_mass_kg;
  return CheckEachCable(data, error) &&
         CheckSum(data, lightest, "the lightest plausible cabin's", error);
}

}  // namespace fastcal
