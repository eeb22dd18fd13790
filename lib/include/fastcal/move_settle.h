// How long a survey waits after a move before its samples are quasi-static: the settle
// time of a minimum-jerk move between two stops, from the time-domain model (dynamics_run.h;
// issue 55: `design` puts it after each move).
//
// The move p(t) = p0 + (p1 - p0) s(t/T), s(u) = 10u^3 - 15u^4 + 6u^5 (Flash and Hogan
// 1985), has a peak acceleration of (10 / sqrt 3) |p1 - p0| / T^2. While it moves the
// tensions depart from quasi-static by the cabin's inertia, of the order of m a (docs/
// model.md, "Dynamics": at most 0.5 m a over the table's moves); what the move leaves
// behind is smaller still. A move whose screen_factor * m * a_peak is below
// fraction * (the smallest lower-end tension at either end) cannot leave a tension outside
// the band, and is not simulated (wait 0). Any other is run in time at `segments` a cable
// (the settle time is set by the lowest modes, which 8 segments place within ~1%) and held
// until every tension stays within `fraction` of its quasi-static value, or max_wait_s.
#ifndef FASTCAL_MOVE_SETTLE_H_
#define FASTCAL_MOVE_SETTLE_H_

#include <string>

#include "fastcal/cable_robot.h"
#include "fastcal/pose.h"

namespace fastcal {

struct MoveSettleOptions {
  // The band: every lower-end tension within this fraction of its quasi-static value
  // (issue 55's default, 0.5%; > 0).
  double fraction = 0.005;
  // The lumped chains' segments a cable (>= 2) and their damping ratio (the lowest mode's,
  // FAST's measured 0.004; in (0, 1)).
  int segments = 8;
  double damping_ratio = 0.004;
  // The longest wait simulated (s, > 0): a move not settled by then waits this long and
  // says so. The lowest mode's time constant 1 / (zeta omega) is about 4 minutes.
  double max_wait_s = 600.0;
  // A move shorter than this (s, > 0) is taken to last this long: a turn in place has no
  // travel time at a speed, yet the winches need some.
  double min_move_s = 10.0;
  // The screen's margin over m a_peak (>= 1).
  double screen_factor = 2.0;
  bool IsValid(std::string* error) const;
};

struct MoveSettle {
  double move_s = 0.0;             // the move's duration taken (>= min_move_s)
  double peak_acceleration = 0.0;  // (10 / sqrt 3) D / T^2, m/s^2
  bool simulated = false;          // false: the screen said the band holds throughout
  bool settled = true;             // false: still outside the band after max_wait_s
  double wait_s = 0.0;             // from the move's end; max_wait_s when not settled
};

// The wait after a minimum-jerk move of `move_s` from `from` to `to` (the attitude turned
// by the same fraction; the cabin rigid, its moving parts where the model holds them).
// False with *error for invalid options or move_s, or a pose or move the model cannot
// hold (the dynamics' message).
bool MoveSettleTime(const CableRobot& robot, const Pose& from, const Pose& to, double move_s,
                    const MoveSettleOptions& options, MoveSettle* settle, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_MOVE_SETTLE_H_
