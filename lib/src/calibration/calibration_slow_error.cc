// The calibration's slow-error stages (internal/calibration_slow_error.h).
#include "fastcal/internal/calibration_slow_error.h"

#include <algorithm>
#include <cmath>

#include "fastcal/internal/slow_error_filter.h"

namespace fastcal::internal {
namespace {

bool Excluded(const PredictionView& at, int t, int i) {
  return at.excluded != nullptr && !at.excluded->empty() && (*at.excluded)[t][i];
}

}  // namespace

ReadingArrays SlowErrorRatios(const SlowErrorProcess& process, const PredictionView& at) {
  if (!process.IsActive()) return {};  // not read (FittedSamples::whitened): no 48 MB of zeros
  ReadingArrays rho(at.fit->size());
  for (size_t j = 0; j < at.fit->size(); ++j) {
    const int t = (*at.fit)[j];
    for (int i = 0; i < kNumCables; ++i) {
      rho[j][i] = process.SigmaN((*at.reading_n)[t][i]) / (*at.sigma_n)[t][i];
    }
  }
  return rho;
}

void WhitenPrediction(const SlowErrorProcess& process, const PredictionView& at, ReadingArrays* x) {
  if (!process.IsActive()) return;
  const ReadingArrays rho = SlowErrorRatios(process, at);
  std::vector<bool> fitted(at.data->samples.size(), false);
  ReadingWhitener whitener(process, 1);
  for (size_t j = 0; j < at.fit->size(); ++j) {
    const int t = (*at.fit)[j];
    fitted[t] = true;
    const Sample& s = at.data->samples[t];
    std::array<bool, kNumCables> excluded{};
    for (int i = 0; i < kNumCables; ++i) excluded[i] = Excluded(at, t, i);
    whitener.WhitenOnly(s.time_s, s.session, rho[j].data(), excluded.data(), (*x)[t].data());
  }
  for (size_t t = 0; t < at.data->samples.size(); ++t) {
    if (fitted[t]) continue;
    for (int i = 0; i < kNumCables; ++i) {
      const double r = process.SigmaN((*at.reading_n)[t][i]) / (*at.sigma_n)[t][i];
      (*x)[t][i] /= std::sqrt(1.0 + r * r);
    }
  }
}

SlowErrorEstimateInputs SlowErrorInputs(const CalibrationSpec& spec, const PredictionView& at,
                                        int budget) {
  SlowErrorEstimateInputs in;
  in.spec = spec.slow_error;
  in.num_threads = spec.num_threads;
  for (const ParameterSpec& p : spec.parameters) {
    in.gain_nuisance = in.gain_nuisance || (p.free && p.kind == ParameterKind::kSensorGain);
  }
  const std::vector<int> used = SlowErrorEstimateSamples(static_cast<int>(at.fit->size()), budget);
  in.samples.reserve(used.size());
  for (int j : used) {
    const int t = (*at.fit)[j];
    const Sample& s = at.data->samples[t];
    SlowErrorSample e;
    e.time_s = s.time_s;
    e.session = s.session;
    e.sigma_n = (*at.sigma_n)[t];
    e.reading_n = (*at.reading_n)[t];
    for (int i = 0; i < kNumCables; ++i) e.x[i] = (e.reading_n[i] - s.tension_n[i]) / e.sigma_n[i];
    for (int i = 0; i < kNumCables; ++i) e.excluded[i] = Excluded(at, t, i);
    in.samples.push_back(e);
  }
  return in;
}

namespace {

bool Settled(double before, double after) {
  return std::abs(after - before) <= kSlowErrorSettled * std::max(std::abs(before), 1e-300);
}

}  // namespace

bool AdoptSlowErrorEstimate(const SlowErrorReport& estimate, bool may_change,
                            SlowErrorProcess* used, SlowErrorReport* report) {
  const SlowErrorProcess& next = estimate.process;
  const bool floor = estimate.amplitude_at_floor && report->amplitude_at_floor;
  const bool settled =
      used->IsActive() &&
      ((Settled(used->sigma_percent, next.sigma_percent) && Settled(used->sigma_n, next.sigma_n) &&
        Settled(used->time_constant_s, next.time_constant_s)) ||
       floor);
  const int passes = report->passes + 1;
  *report = estimate;
  report->passes = passes;
  if (!settled && may_change) *used = next;
  report->process = *used;
  return settled;
}

}  // namespace fastcal::internal
