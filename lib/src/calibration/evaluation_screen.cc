// Gross errors in a model evaluation (evaluation_screen.h).
#include "fastcal/evaluation_screen.h"

#include <algorithm>

#include "fastcal/internal/calibration_model.h"

namespace fastcal {

EvaluationScreen ScreenEvaluation(const Dataset& data, const VariantEvaluation& variant,
                                  const CalibrationSpec& spec) {
  EvaluationScreen out;
  out.variant = variant.name;
  const size_t n = std::min(data.samples.size(), variant.predicted_n.size());
  out.threshold = ChooseGrossErrorThreshold(static_cast<long long>(kNumCables) * n,
                                            spec.gross_error_threshold_sigmas);
  std::vector<std::array<double, kNumCables>> whitened(n);
  for (size_t t = 0; t < n; ++t) {
    const std::array<double, kNumCables> sigma_n = internal::TensionSigmas(
        variant.predicted_n[t], spec.tension_sigma_n, spec.tension_sigma_percent);
    for (int i = 0; i < kNumCables; ++i) {
      whitened[t][i] = (variant.predicted_n[t][i] - data.samples[t].tension_n[i]) / sigma_n[i];
    }
  }
  GrossErrorScreen screen = ScreenGrossErrors(whitened, {}, out.threshold.sigmas);
  out.cables = screen.cables;
  for (size_t t = 0; t < n; ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      if (!screen.flagged[t][i]) continue;
      ReadingResidual g;
      g.sample = static_cast<int>(t);
      g.line = data.samples[t].line;
      g.cable = i + 1;
      g.measured_n = data.samples[t].tension_n[i];
      g.predicted_n = variant.predicted_n[t][i];
      g.residual_sigma = whitened[t][i];
      out.gross_errors.push_back(g);
      ++out.count;
      ++out.count_per_cable[i];
    }
  }
  out.excluded = std::move(screen.flagged);
  return out;
}

std::vector<VariantEvaluation> WithoutGrossErrors(const Dataset& data,
                                                  const std::vector<VariantEvaluation>& variants,
                                                  const ReadingMask& excluded) {
  std::vector<VariantEvaluation> out;
  for (const VariantEvaluation& v : variants) {
    VariantEvaluation w;
    w.name = v.name + " - gross errors";
    w.fit = ErrorStats(data, v.predicted_n, {}, false, excluded);
    out.push_back(std::move(w));
  }
  return out;
}

}  // namespace fastcal
