// One control cycle (control_cycle.h): the exact statics at the planned pose, the
// encoders' and sensors' readings from the model's offsets and gains, then the limits.
#include "fastcal/control_cycle.h"

#include <algorithm>
#include <cmath>

namespace fastcal {

bool ControlLimits::IsValid(std::string* error) const {
  auto fail = [&](const char* why) {
    if (error != nullptr) *error = why;
    return false;
  };
  if (!std::isfinite(min_tension_n) || min_tension_n < 0.0) {
    return fail("the minimum tension (min_tension) must be finite and >= 0");
  }
  // +infinity is allowed (no rated load); NaN and values up to the minimum are not (a
  // zeroed struct from C would otherwise call every pose above its maximum).
  if (!(max_tension_n > min_tension_n)) {
    return fail("the maximum tension (max_tension) must be > the minimum (min_tension)");
  }
  if (!std::isfinite(min_reflector_clearance_m) || min_reflector_clearance_m < 0.0) {
    return fail("min_reflector_clearance_m must be finite and >= 0");
  }
  return true;
}

const char* ControlStatusName(ControlStatus status) {
  switch (status) {
    case ControlStatus::kOk:
      return "ok";
    case ControlStatus::kStaticsFailed:
      return "statics_failed";
    case ControlStatus::kBelowMinTension:
      return "below_min_tension";
    case ControlStatus::kAboveMaxTension:
      return "above_max_tension";
    case ControlStatus::kInsideReflectorMargin:
      return "inside_reflector_margin";
  }
  return "unknown";
}

namespace {

// The limits in order of harm: the reflector, an overload, a slack cable. Sets
// result->status and cable; margins are computed for every cable whatever broke.
void CheckLimits(const ControlLimits& limits, ControlCycleResult* result) {
  const StaticsSolution& s = result->statics;
  double min_margin = std::numeric_limits<double>::infinity();
  double max_margin = std::numeric_limits<double>::infinity();
  int min_cable = -1, max_cable = -1;
  for (int i = 0; i < kNumCables; ++i) {
    const CableSolution& c = s.cables[i];
    const double low = c.lower_tension_n - limits.min_tension_n;
    const double high = limits.max_tension_n - std::max(c.lower_tension_n, c.upper_tension_n);
    if (low < min_margin) min_margin = low, min_cable = i;
    if (high < max_margin) max_margin = high, max_cable = i;
  }
  result->min_tension_margin_n = min_margin;
  result->max_tension_margin_n = max_margin;
  if (s.reflector_clearance_m < limits.min_reflector_clearance_m) {
    result->status = ControlStatus::kInsideReflectorMargin;
    result->cable = s.cable;  // the statics name the closest cable only on failure
  } else if (max_margin < 0.0) {
    result->status = ControlStatus::kAboveMaxTension;
    result->cable = max_cable;
  } else if (min_margin < 0.0) {
    result->status = ControlStatus::kBelowMinTension;
    result->cable = min_cable;
  } else {
    result->status = ControlStatus::kOk;
    result->cable = -1;
  }
}

}  // namespace

ControlStatus ControlCycle(const CableRobot& robot, const Pose& pose, const JointValues& joints,
                           const ControlLimits& limits, const StaticsOptions& options,
                           ControlCycleResult* result) {
  result->winch_length_m = {};
  result->sensor_reading_n = {};
  result->min_tension_margin_n = result->max_tension_margin_n = 0.0;
  result->cable = -1;
  // Limits IsValid refuses, or a joint outside what the model states for it (issue 57:
  // 400 deg on a joint of +-40 deg came back ok): invalid input, nothing solved.
  if (!limits.IsValid(nullptr) || FirstRefusedJoint(robot.moving_parts, joints) >= 0) {
    result->statics.status = StaticsStatus::kInvalidInput;
    result->statics.cables = {};
    return result->status = ControlStatus::kStaticsFailed;
  }
  if (SolveStatics(robot, pose, joints, options, &result->statics) != StaticsStatus::kOk) {
    result->cable = result->statics.cable;
    return result->status = ControlStatus::kStaticsFailed;
  }
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = robot.cables[i];
    const CableSolution& s = result->statics.cables[i];
    result->winch_length_m[i] = c.EncoderReadingM(s.unstretched_length_m);
    result->sensor_reading_n[i] = c.SensorReadingN(s.lower_tension_n);
  }
  CheckLimits(limits, result);
  return result->status;
}

}  // namespace fastcal
