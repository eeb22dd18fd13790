// Model-minus-measured statistics (evaluation.h).
#include "fastcal/evaluation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace fastcal {
namespace {

// The cabin's pose of a sample: its data pose (the model's measured frame's, at its
// joints: measured_frame.h), with the planned attitude when asked.
Pose PoseOf(const CableRobot& robot, const Sample& sample, AttitudeSource attitude) {
  Pose pose = sample.pose;
  if (attitude == AttitudeSource::kPlanned) pose.rotation = sample.planned_rotation;
  return robot.CabinPose(pose, sample.joint);
}

// "<file>:<line>: <model> cannot solve this pose<detail>: <why>".
std::string CannotSolve(const Dataset& data, const Sample& sample, const std::string& model,
                        const std::string& detail, const StaticsSolution& solution) {
  return SampleWhere(data, sample) + ": " + model + " cannot solve this pose" + detail + ": " +
         DescribeStatus(solution);
}

}  // namespace

TensionPredictor::TensionPredictor(const CableRobot& robot, AttitudeSource attitude,
                                   StaticsMethod method)
    : robot_(robot), attitude_(attitude), options_(ModelFitStaticsOptions(method)) {
  // As Calibrate solves; consecutive telemetry samples are close.
  options_.warm_start = true;
}

bool TensionPredictor::Predict(const Dataset& data, const Sample& sample,
                               std::array<double, kNumCables>* predicted_n, std::string* error) {
  // Joints outside the ranges the model states are not the model's (issue 57: Python's
  // evaluate took them), whichever reader the data came through.
  if (const int j = FirstRefusedJoint(robot_.moving_parts, sample.joint); j >= 0) {
    const Joint& joint = *robot_.moving_parts.Joints()[j].second;
    std::string why;
    CheckJointValue(joint, sample.joint[j], &why);
    *error = SampleWhere(data, sample) + ": column '" + joint.column + "': " + why;
    return false;
  }
  if (SolveStatics(robot_, PoseOf(robot_, sample, attitude_), sample.joint, options_, &solution_) !=
      StaticsStatus::kOk) {
    *error = CannotSolve(data, sample, "the model", "", solution_);
    return false;
  }
  for (int i = 0; i < kNumCables; ++i) {
    (*predicted_n)[i] = robot_.cables[i].SensorReadingN(solution_.cables[i].lower_tension_n);
  }
  return true;
}

bool PredictTensions(const CableRobot& robot, const Dataset& data, AttitudeSource attitude,
                     StaticsMethod method, std::vector<std::array<double, kNumCables>>* predicted,
                     std::string* error) {
  if (attitude == AttitudeSource::kPlanned && !data.has_planned_attitude) {
    *error = data.path + ": no planned attitude columns (planned_roll_deg, ...)";
    return false;
  }
  if (!CheckJointColumns(data, robot.moving_parts, error)) return false;
  TensionPredictor predictor(robot, attitude, method);
  predicted->assign(data.samples.size(), {});
  for (size_t n = 0; n < data.samples.size(); ++n) {
    if (!predictor.Predict(data, data.samples[n], &(*predicted)[n], error)) return false;
  }
  return true;
}

int SkipUnsolvableSamples(const CableRobot& robot, const std::string& model_name,
                          const std::vector<AttitudeSource>& attitudes,
                          const std::vector<StaticsMethod>& methods, Dataset* data) {
  StaticsOptions options = ModelFitStaticsOptions(StaticsMethod::kAas);  // as Calibrate
  StaticsSolution solution;
  std::vector<Sample> kept;
  kept.reserve(data->samples.size());
  int removed = 0;
  for (Sample& s : data->samples) {
    std::string why;
    for (AttitudeSource attitude : attitudes) {
      if (attitude == AttitudeSource::kPlanned && !data->has_planned_attitude) continue;
      for (StaticsMethod method : methods) {
        options.method = method;
        if (!why.empty() || SolveStatics(robot, PoseOf(robot, s, attitude), s.joint, options,
                                         &solution) == StaticsStatus::kOk) {
          continue;
        }
        why = CannotSolve(*data, s, model_name,
                          std::string(" (") +
                              (attitude == AttitudeSource::kPlanned ? "planned" : "measured") +
                              " attitude, " + StaticsMethodName(method) + ")",
                          solution);
      }
    }
    if (why.empty()) {
      kept.push_back(std::move(s));
    } else {
      data->skipped.push_back(why);
      ++removed;
    }
  }
  data->samples = std::move(kept);
  return removed;
}

void ErrorStatsAccumulator::Add(const std::array<double, kNumCables>& predicted_n,
                                const std::array<double, kNumCables>& measured_n,
                                const std::array<bool, kNumCables>* excluded) {
  ++st_.samples;
  for (int i = 0; i < kNumCables; ++i) {
    if (excluded != nullptr && (*excluded)[i]) {
      ++st_.excluded[i];
      continue;
    }
    const double d = predicted_n[i] - measured_n[i];
    sum_[i] += d;
    sum2_[i] += d * d;
    st_.max_abs_n[i] = std::max(st_.max_abs_n[i], std::abs(d));
    // Percent of the predicted reading, not of the measured one: a dropout reads 0 kN
    // (100 d / 0 = inf), and the prediction of a pose the model holds is > 0. A
    // prediction <= 0 (a negative sensor bias) leaves the reading out of the percents.
    if (!(predicted_n[i] > 0.0)) continue;
    const double pct = 100.0 * d / predicted_n[i];
    sum2_pct_[i] += pct * pct;
    ++percent_readings_[i];
    st_.max_abs_percent[i] = std::max(st_.max_abs_percent[i], std::abs(pct));
  }
}

CableErrorStats ErrorStatsAccumulator::Finish() const {
  CableErrorStats st = st_;
  for (int i = 0; i < kNumCables; ++i) {
    const int readings = st.samples - st.excluded[i];
    if (readings == 0) continue;
    st.mean_n[i] = sum_[i] / readings;
    st.rms_n[i] = std::sqrt(sum2_[i] / readings);
    if (percent_readings_[i] > 0) {
      st.rms_percent[i] = std::sqrt(sum2_pct_[i] / percent_readings_[i]);
    }
  }
  return st;
}

CableErrorStats ErrorStats(const Dataset& data,
                           const std::vector<std::array<double, kNumCables>>& predicted,
                           const std::vector<bool>& held_out, bool select_held_out,
                           const ReadingMask& excluded) {
  ErrorStatsAccumulator acc;
  for (size_t n = 0; n < data.samples.size(); ++n) {
    const bool h = !held_out.empty() && held_out[n];
    if (h != select_held_out) continue;
    acc.Add(predicted[n], data.samples[n].tension_n, excluded.empty() ? nullptr : &excluded[n]);
  }
  return acc.Finish();
}

bool EvaluateVariant(const std::string& name, const CableRobot& robot, const Dataset& data,
                     AttitudeSource attitude, StaticsMethod method,
                     const std::vector<bool>& held_out, VariantEvaluation* evaluation,
                     std::string* error, const ReadingMask& excluded) {
  evaluation->name = name;
  if (!PredictTensions(robot, data, attitude, method, &evaluation->predicted_n, error)) {
    return false;
  }
  evaluation->fit = ErrorStats(data, evaluation->predicted_n, held_out, false, excluded);
  evaluation->holdout = ErrorStats(data, evaluation->predicted_n, held_out, true, excluded);
  return true;
}

std::string EvaluationVariantName(AttitudeSource attitude) {
  return attitude == AttitudeSource::kPlanned ? "model, planned attitude"
                                              : "model, measured attitude";
}

bool EvaluateModel(const CableRobot& robot, const Dataset& data, StaticsMethod method,
                   std::vector<VariantEvaluation>* variants, std::string* error) {
  std::vector<AttitudeSource> list;
  if (data.has_planned_attitude) list.push_back(AttitudeSource::kPlanned);
  list.push_back(AttitudeSource::kMeasured);
  for (AttitudeSource attitude : list) {
    VariantEvaluation e;
    if (!EvaluateVariant(EvaluationVariantName(attitude), robot, data, attitude, method, {}, &e,
                         error)) {
      return false;
    }
    variants->push_back(std::move(e));
  }
  return true;
}

int BlockOfSample(int sample, int num_samples, int blocks) {
  if (num_samples <= 0 || blocks <= 1) return 0;
  // The largest b whose start floor(b n / blocks) is <= sample.
  return static_cast<int>(((static_cast<long long>(sample) + 1) * blocks - 1) / num_samples);
}

std::vector<bool> HoldoutMask(int num_samples, double fraction, std::uint64_t seed, int blocks) {
  std::vector<bool> mask(std::max(num_samples, 0), false);
  blocks = std::clamp(blocks, 1, std::max(num_samples, 1));
  int held = static_cast<int>(std::lround(fraction * blocks));
  if (fraction > 0.0) held = std::max(held, 1);
  held = std::min(held, blocks - 1);  // something must be left to fit
  if (held <= 0 || num_samples <= 0) return mask;
  std::vector<int> order(blocks);
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(seed);
  // Fisher-Yates with the raw generator (std::shuffle's use of it is unspecified).
  for (int i = blocks - 1; i > 0; --i) {
    const int j = static_cast<int>(rng() % static_cast<std::uint64_t>(i + 1));
    std::swap(order[i], order[j]);
  }
  std::vector<bool> held_block(blocks, false);
  for (int k = 0; k < held; ++k) held_block[order[k]] = true;
  for (int t = 0; t < num_samples; ++t) mask[t] = held_block[BlockOfSample(t, num_samples, blocks)];
  return mask;
}

}  // namespace fastcal
