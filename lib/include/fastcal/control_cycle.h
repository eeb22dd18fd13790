// One control cycle: at a planned pose (and the moving parts' joints), what the winches
// should pay out and the tension sensors should read, with the checks a controller needs.
//
//   s0_i                    = the exact statics' unstretched length at the pose (statics.h)
//   winch_length_m_i        = s0_i + length_offset_m_i           (CableProperties::EncoderReadingM)
//   sensor_reading_n_i      = gain_i |F_i| + bias_i              (CableProperties::SensorReadingN)
//   min_tension_margin_n    = min_i |F_i| - limits.min_tension_n
//   max_tension_margin_n    = min_i (limits.max_tension_n - max(|F_i|, upper tension_i))
//
// The model's own range (strain, sag, reflector contact) is the statics' check; the limits
// here are the installation's: a tension floor (where a cable sags, its length moves by
// metres with a small error of the model), a rated load, a clearance margin above the
// reflector. A broken limit is reported with every number filled, so that the controller
// decides; a statics failure leaves them zero.
//
// Nothing here allocates, locks or throws (tests/control_cycle_test.cc counts).
#ifndef FASTCAL_CONTROL_CYCLE_H_
#define FASTCAL_CONTROL_CYCLE_H_

#include <array>
#include <limits>
#include <string>

#include "fastcal/cable_robot.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"

namespace fastcal {

struct ControlLimits {
  // Every lower-end tension at least this (N). 50 kN: the survey design's margin
  // (kDesignMinTensionN, design.h): below it the cables sag enough that the model's
  // lengths move by metres with a 1.5% error of the density.
  double min_tension_n = 50e3;
  // Every lower- and upper-end tension at most this (N). The model states no rated load:
  // +infinity leaves only the model's max_strain; a controller sets its cables' load.
  double max_tension_n = std::numeric_limits<double>::infinity();
  // Every cable at least this far from the reflector (m; kDesignReflectorClearanceM).
  double min_reflector_clearance_m = 5.0;

  // False with *error naming the field: non-finite minimums, negative values, max <= min.
  bool IsValid(std::string* error) const;
};

enum class ControlStatus {
  kOk = 0,
  kStaticsFailed,          // StaticsSolution::status says which (numbers zero)
  kBelowMinTension,        // cable `cable`'s lower-end tension < min_tension_n
  kAboveMaxTension,        // cable `cable`'s lower or upper tension > max_tension_n
  kInsideReflectorMargin,  // the smallest clearance < min_reflector_clearance_m
};
// "ok", "statics_failed", "below_min_tension", "above_max_tension",
// "inside_reflector_margin".
const char* ControlStatusName(ControlStatus status);

struct ControlCycleResult {
  ControlStatus status = ControlStatus::kStaticsFailed;
  int cable = -1;  // 0-based cable a failure or limit concerns, else -1
  std::array<double, kNumCables> winch_length_m{};
  std::array<double, kNumCables> sensor_reading_n{};
  double min_tension_margin_n = 0.0;
  double max_tension_margin_n = 0.0;
  // The statics at the pose: tensions, s0, error estimate, clearance, status. Also the
  // warm start of the next cycle (pass the same result again).
  StaticsSolution statics;
};

// One cycle. `options` are the statics' (exact, warm_start true for a trajectory: the
// previous cycle's result->statics starts it). `joints`: the model's joint order, columns'
// units. Returns result->status. Limits that IsValid refuses, and joints that
// CheckJointValue refuses (not plausible, or outside the range the model states), return
// kStaticsFailed with statics.status kInvalidInput.
ControlStatus ControlCycle(const CableRobot& robot, const Pose& pose, const JointValues& joints,
                           const ControlLimits& limits, const StaticsOptions& options,
                           ControlCycleResult* result);

}  // namespace fastcal

#endif  // FASTCAL_CONTROL_CYCLE_H_
