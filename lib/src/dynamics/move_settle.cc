// The settle time after a move (move_settle.h has the screen and the equations).
#include "fastcal/move_settle.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "fastcal/dynamics.h"
#include "fastcal/dynamics_run.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/statics.h"

namespace fastcal {
namespace {

// The minimum-jerk profile's peak acceleration over D / T^2: s''(u) = 60u - 180u^2 +
// 120u^3 peaks at u = (3 - sqrt 3) / 6 with 10 / sqrt 3.
const double kMinimumJerkPeak = 10.0 / std::sqrt(3.0);

std::string Num(double v) { return internal::FormatDouble("%.6g", v); }

// The smallest lower-end tension at `pose` (N), or false with the statics' reason.
bool SmallestTension(const CableRobot& robot, const Pose& pose, double* tension_n,
                     std::string* error) {
  StaticsSolution solution;
  if (SolveStatics(robot, pose, StaticsOptions(), &solution) != StaticsStatus::kOk) {
    *error = "the statics cannot hold the pose at (" + Num(pose.position_m.x()) + ", " +
             Num(pose.position_m.y()) + ", " + Num(pose.position_m.z()) + ") m";
    return false;
  }
  *tension_n = solution.cables[0].lower_tension_n;
  for (const CableSolution& c : solution.cables)
    *tension_n = std::min(*tension_n, c.lower_tension_n);
  return true;
}

}  // namespace

bool MoveSettleOptions::IsValid(std::string* error) const {
  const auto fail = [error](const std::string& what) {
    *error = "move settle options: " + what;
    return false;
  };
  if (!(fraction > 0.0) || !(fraction < 1.0)) return fail("fraction must be in (0, 1)");
  if (segments < 2 || segments > 1000) return fail("segments must be in [2, 1000]");
  if (!(damping_ratio > 0.0) || !(damping_ratio < 1.0)) {
    return fail("damping_ratio must be in (0, 1)");
  }
  if (!(max_wait_s > 0.0) || !std::isfinite(max_wait_s) || max_wait_s > 86400.0) {
    return fail("max_wait_s must be in (0, 86400] s");
  }
  if (!(min_move_s > 0.0) || !std::isfinite(min_move_s) || min_move_s > 86400.0) {
    return fail("min_move_s must be in (0, 86400] s");
  }
  if (!(screen_factor >= 1.0) || !std::isfinite(screen_factor)) {
    return fail("screen_factor must be >= 1 and finite");
  }
  return true;
}

bool MoveSettleTime(const CableRobot& robot, const Pose& from, const Pose& to, double move_s,
                    const MoveSettleOptions& options, MoveSettle* settle, std::string* error) {
  if (!options.IsValid(error)) return false;
  if (!(move_s >= 0.0) || !std::isfinite(move_s)) {
    *error = "move_s must be >= 0 and finite (got " + Num(move_s) + ")";
    return false;
  }
  MoveSettle out;
  out.move_s = std::max(move_s, options.min_move_s);
  const double distance_m = (to.position_m - from.position_m).norm();
  out.peak_acceleration = kMinimumJerkPeak * distance_m / (out.move_s * out.move_s);
  // The screen holds for translation; a turn of the cabin (its inertia, not its mass) is
  // always run in time.
  const double turn_rad = Eigen::AngleAxisd(from.rotation.transpose() * to.rotation).angle();
  double low_from = 0.0, low_to = 0.0;
  if (!SmallestTension(robot, from, &low_from, error) ||
      !SmallestTension(robot, to, &low_to, error)) {
    return false;
  }
  const double inertial_n = options.screen_factor * robot.cabin_mass_kg * out.peak_acceleration;
  if (turn_rad < 1e-9 && inertial_n < options.fraction * std::min(low_from, low_to)) {
    *settle = out;
    return true;
  }
  DynamicsRunSpec spec;
  spec.kind = DynamicsRunSpec::Kind::kMove;
  spec.start = from;
  spec.end = to;
  spec.move_s = out.move_s;
  spec.hold_s = options.max_wait_s;
  spec.rate_hz = 1.0;
  spec.settle_fraction = options.fraction;
  DynamicsOptions dynamics;
  dynamics.segments = options.segments;
  dynamics.damping_ratio = options.damping_ratio;
  dynamics.max_step_s = 0.05;
  DynamicsRunResult run;
  if (!RunDynamics(robot, spec, dynamics, &run, error)) return false;
  out.simulated = true;
  out.settled = run.settled;
  out.wait_s = run.settled ? run.settle_s : options.max_wait_s;
  *settle = out;
  return true;
}

}  // namespace fastcal
