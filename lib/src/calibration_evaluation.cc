// The before/after RMS table of a calibration (declaration: calibration.h).
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/evaluation.h"
#include "fastcal/sessions.h"

namespace fastcal {

bool EvaluateBeforeAndAfter(const CableRobot& model, const CalibrationSpec& spec,
                            const Dataset& data, const CalibrationResult& result,
                            std::vector<VariantEvaluation>* variants, std::string* error) {
  struct Variant {
    std::string name;
    const CableRobot* robot;
    AttitudeSource attitude;
  };
  std::vector<Variant> list;
  if (data.has_planned_attitude) {
    list.push_back({"initial model, planned attitude", &model, AttitudeSource::kPlanned});
  }
  list.push_back({"initial model, measured attitude", &model, AttitudeSource::kMeasured});
  list.push_back(
      {std::string("calibrated model, ") + (spec.use_planned_attitude ? "planned" : "measured") +
           " attitude",
       &result.calibrated,
       spec.use_planned_attitude ? AttitudeSource::kPlanned : AttitudeSource::kMeasured});
  for (const Variant& v : list) {
    VariantEvaluation e;
    // A joint fit's calibrated model is one per session (sessions.h).
    const bool per_session = v.robot == &result.calibrated && result.session_models.size() > 1;
    if (per_session ? !EvaluateSessionModels(v.name, result.session_models, data, v.attitude,
                                             StaticsMethod::kExact, result.held_out,
                                             result.excluded, &e, error)
                    : !EvaluateVariant(v.name, *v.robot, data, v.attitude, StaticsMethod::kExact,
                                       result.held_out, &e, error, result.excluded)) {
      *error = v.name + ": " + *error;
      return false;
    }
    variants->push_back(std::move(e));
  }
  return true;
}

}  // namespace fastcal
