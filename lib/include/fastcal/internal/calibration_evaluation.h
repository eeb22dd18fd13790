// The RMS table of a calibration (the paper's Table 6; the CLI's and the report's), for
// Calibrate (calibration.h): the initial `model` at each attitude the data has ("initial
// model, planned attitude", "initial model, measured attitude") and the calibrated one at
// the fit's attitude ("calibrated model, measured attitude"), exact statics, on the
// fitted and the held-out samples, gross errors left out.
#ifndef FASTCAL_INTERNAL_CALIBRATION_EVALUATION_H_
#define FASTCAL_INTERNAL_CALIBRATION_EVALUATION_H_

#include <array>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/internal/compact_start.h"

namespace fastcal::internal {

struct RmsTableInputs {
  // Per dataset sample (may be null): exact statics near each variant's, e.g. the fit's
  // at its solution, each sample's warm start (at the same pose: ~3 times cheaper than
  // cold, and the same answer to the solver's tolerance). Null: cold starts.
  const CompactStarts* starts = nullptr;
  // The calibrated model's readings of every sample, when already predicted with exact
  // statics at the fit's attitude (may be null; moved from: saves a pass over the data).
  std::vector<std::array<double, kNumCables>>* calibrated_readings = nullptr;
  // The initial model's readings of every sample at `initial_attitude`, when already
  // predicted with exact statics (may be null; moved from): the fit's first prediction.
  std::vector<std::array<double, kNumCables>>* initial_readings = nullptr;
  AttitudeSource initial_attitude = AttitudeSource::kMeasured;
};

// The rows, in table order. Predictions run on spec.num_threads threads, each sample on
// its own: the same numbers on any number of threads. False, naming the variant and the
// sample's line, when a model cannot hold a pose.
bool EvaluateBeforeAndAfter(const CableRobot& model, const CalibrationSpec& spec,
                            const Dataset& data, const CalibrationResult& result,
                            const RmsTableInputs& inputs, std::vector<VariantEvaluation>* variants,
                            std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_CALIBRATION_EVALUATION_H_
