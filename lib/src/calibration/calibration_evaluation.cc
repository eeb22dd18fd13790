// The before/after RMS table of a calibration (internal/calibration_evaluation.h).
//
// Each variant's readings are predicted with exact statics, each sample from its own warm
// start (or cold), in chunks on the spec's threads (internal/sample_chunks.h).
#include "fastcal/internal/calibration_evaluation.h"

#include <string>
#include <vector>

#include "fastcal/evaluation.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/statics_core.h"

namespace fastcal::internal {
namespace {

// Every sample's reading predicted by models[sample.session] (models[0] for all when
// there is one). False, naming the first sample a model cannot hold.
bool PredictReadings(const std::vector<const CableRobot*>& models, const Dataset& data,
                     AttitudeSource attitude, int threads, const CompactStarts* starts,
                     std::vector<std::array<double, kNumCables>>* predicted, std::string* error) {
  StaticsOptions options = ModelFitStaticsOptions(StaticsMethod::kExact);
  options.warm_start = true;
  std::vector<StaticsParameters<double>> parameters;
  for (const CableRobot* m : models) parameters.push_back(MakeStaticsParameters(*m));
  const auto model_of = [&](const Sample& s) { return models.size() > 1 ? s.session : 0; };
  // The cabin's pose: the data's, through the model's measured frame (measured_frame.h).
  const auto pose_of = [&](const Sample& s) {
    Pose pose = s.pose;
    if (attitude == AttitudeSource::kPlanned) pose.rotation = s.planned_rotation;
    return models[model_of(s)]->CabinPose(pose, s.joint);
  };
  const auto solve = [&](int t, StaticsSolution* solution) {
    const Sample& s = data.samples[t];
    const Pose pose = pose_of(s);
    if (starts != nullptr && !starts->empty()) {
      starts->At(t).Restore(pose, StaticsMethod::kExact, solution);
    } else {
      solution->status = StaticsStatus::kInvalidInput;  // no start: cold
    }
    return SolveStaticsWithParameters(parameters[model_of(s)], models[model_of(s)]->moving_parts,
                                      s.joint, pose, options, solution);
  };
  predicted->resize(data.samples.size());
  const int failed =
      ForEachChunk(static_cast<int>(data.samples.size()), threads, [&](int begin, int end) {
        StaticsSolution solution;
        for (int t = begin; t < end; ++t) {
          if (solve(t, &solution) != StaticsStatus::kOk) return t;
          const CableRobot& robot = *models[model_of(data.samples[t])];
          for (int i = 0; i < kNumCables; ++i) {
            (*predicted)[t][i] = robot.cables[i].SensorReadingN(solution.cables[i].lower_tension_n);
          }
        }
        return -1;
      });
  if (failed < 0) return true;
  StaticsSolution solution;  // the failure again, for its message
  solve(failed, &solution);
  *error = SampleWhere(data, data.samples[failed]) +
           ": the model cannot solve this pose: " + DescribeStatus(solution);
  return false;
}

}  // namespace

bool EvaluateBeforeAndAfter(const CableRobot& model, const CalibrationSpec& spec,
                            const Dataset& data, const CalibrationResult& result,
                            const RmsTableInputs& inputs, std::vector<VariantEvaluation>* variants,
                            std::string* error) {
  std::vector<std::array<double, kNumCables>>* calibrated_readings = inputs.calibrated_readings;
  std::vector<std::array<double, kNumCables>>* initial_readings = inputs.initial_readings;
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
    e.name = v.name;
    // A joint fit's calibrated model is one per session (sessions.h).
    std::vector<const CableRobot*> models = {v.robot};
    if (v.robot == &result.calibrated && result.session_models.size() > 1) {
      models.clear();
      for (const CableRobot& m : result.session_models) models.push_back(&m);
    }
    if (v.attitude == AttitudeSource::kPlanned && !data.has_planned_attitude) {
      *error = v.name + ": " + data.path + ": no planned attitude columns (planned_roll_deg, ...)";
      return false;
    }
    if (v.robot == &result.calibrated && calibrated_readings != nullptr &&
        calibrated_readings->size() == data.samples.size()) {
      e.predicted_n = std::move(*calibrated_readings);
    } else if (v.robot == &model && v.attitude == inputs.initial_attitude &&
               initial_readings != nullptr && initial_readings->size() == data.samples.size()) {
      e.predicted_n = std::move(*initial_readings);
    } else if (!PredictReadings(models, data, v.attitude, spec.num_threads, inputs.starts,
                                &e.predicted_n, error)) {
      *error = v.name + ": " + *error;
      return false;
    }
    e.fit = ErrorStats(data, e.predicted_n, result.held_out, false, result.excluded);
    e.holdout = ErrorStats(data, e.predicted_n, result.held_out, true, result.excluded);
    variants->push_back(std::move(e));
  }
  return true;
}

}  // namespace fastcal::internal
