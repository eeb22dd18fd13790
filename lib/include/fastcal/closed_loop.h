// The cabin in its control loop (issue 56; docs/model.md, "The closed loop"): what a
// calibrated model is worth in millimetres of cabin error.
//
// The plant is a truth model in time (dynamics.h: the lumped cables, the cabin, the wind);
// the controller is the telescope's control cycle (control_cycle.h, the C interface's
// fastcal_control_cycle) on the controller's own model. Every control period T, at cycle
// time t_k:
//
//   measured      m_k = p(t_k - d) + n_k              (d the measurement's delay, rounded
//                                                      to whole periods; n_k ~ N(0, s^2 I))
//   error         e_k = c(t_k - d) - m_k              (c the commanded position), low-passed
//                 twice at error_filter_hz: f_k
//   PID           u_k = Kp f_k + Ki sum_j<=k f_j T + Kd (f_k - f_k-1) / T
//   feed-forward  w_k = ControlCycle(controller model, pose (c(t_k + T) + u_k,
//                       R_c(t_k + T))).winch_length_m   (reached at t_k + T)
//   winches       s0_k = w_k - length_offset_m (the truth's), its rate limited to v_max and
//                 the rate's change to a_max T, reached linearly over the next period.
//
// The integral holds while a winch is at a limit (conditional integration, against wind-up
// in a slew).
//
// The PID's output is a position correction the feed-forward solves for (the statics map
// it to lengths exactly, not through a Jacobian). (0, 0, 0) is the feed-forward alone, the
// model's error then the cabin's: with a controller model's mass centre 5 cm off, the
// cabin settles where the truth hangs at the controller's lengths (locate.h).
//
// The error, over the record from summary_from_s on: the cabin's O' against the
// commanded position, |p - c|, split along the feed's axis (the commanded attitude's z')
// and across it (lateral). The feed's efficiency lost to a lateral error of RMS delta at
// wavelength lambda: 1 - exp(-(2 pi kappa delta / lambda)^2), a Ruze-like factor with
// kappa = 0.466 set so that 10 mm RMS loses 8.2% at 3 GHz (Gan et al., FAST's feed
// error; methods.md, "The closed loop"): an estimate of its order, not a beam model.
#ifndef FASTCAL_CLOSED_LOOP_H_
#define FASTCAL_CLOSED_LOOP_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/control_cycle.h"
#include "fastcal/dynamics.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"

namespace fastcal {

struct LoopOptions {
  // The controller's period (s, > 0): 0.1, a 10 Hz cycle.
  double control_period_s = 0.1;
  // The PID on the position error (Kp dimensionless, Ki in 1/s, Kd in s; >= 0), the
  // error first low-passed by two first-order filters at error_filter_hz (> 0; 0: none).
  // Why the filter: the cabin's modes (0.13-0.2 Hz) are damped 0.004, so that a correction
  // at their frequency comes back 125 times larger; unfiltered, Kp = 0.2 with a 0.24 s
  // measurement delay rang up over ten minutes in still air (to 300 mm; the wind's drag
  // damped it). The defaults (Kp 0.05, Ki 0.02 /s, 0.02 Hz) put the crossover near
  // 0.003 Hz with ~70 deg of phase margin and a loop gain of ~0.2 at 0.15 Hz; a static
  // error goes with a time constant of ~50 s.
  double kp = 0.05;
  double ki_per_s = 0.02;
  double kd_s = 0.0;
  double error_filter_hz = 0.02;
  // The position measurement: per-axis noise (m, >= 0) and delay (s, >= 0): a total
  // station's 0.4 mm at 240 ms is (0.0004, 0.24).
  double measurement_noise_m = 0.0;
  double measurement_delay_s = 0.0;
  // The winches (> 0): the largest paying-out speed and its change a second (assumed:
  // 0.5 m/s, 0.2 m/s^2; FAST's are not in the paper).
  double max_winch_speed_m_per_s = 0.5;
  double max_winch_acceleration_m_per_s2 = 0.2;
  // The installation's limits the control cycle checks (a broken one is counted, the
  // loop goes on: the controller decides).
  ControlLimits limits;
  // The controller's statics (exact, warm from the last cycle).
  StaticsOptions statics;
  // The measurement noise's generator.
  std::uint64_t seed = 1;
  // The summary from this time on (s, >= 0).
  double summary_from_s = 0.0;

  bool IsValid(std::string* error) const;
};

// What the loop is asked to do: hold `start` for hold_s; or move from `start` to `end` in
// move_s along a minimum-jerk profile (dynamics_run.h, MinimumJerkPose) and then hold; or
// follow `path` (a source tracked, a circle): its poses at path_time_s (from 0,
// increasing), the position linear between them, the attitude the focal law's when given
// (else the nodes' turned along the shortest rotation), then hold the last for hold_s.
struct LoopSpec {
  Pose start;
  std::optional<Pose> end;
  double move_s = 60.0;
  double hold_s = 120.0;
  std::optional<FocalAttitudeLaw> focal_law;  // the path's attitude, when given
  std::vector<double> path_time_s;
  std::vector<Pose> path;  // start is path[0] when given
  // The path's clock eases in and out over this long (s, >= 0, at most the path's
  // duration): its speed goes from 0 to the path's along a minimum-jerk profile,
  // tau(t) = T (2.5 u^4 - 3 u^5 + u^6), u = t / T, then tau = t - T / 2, and back to 0 at
  // the end (the path ends T later). A path started or stopped at full speed rings the
  // 0.13-0.2 Hz modes: ~45 mm at 0.1 m/s.
  double path_ramp_s = 0.0;

  bool IsValid(std::string* error) const;
  double DurationS() const;
  Pose CommandAt(double time_s) const;
};

struct LoopSample {
  double time_s = 0.0;
  Pose pose;                                             // the cabin (the plant)
  Pose command;                                          // what the controller was asked for
  Eigen::Vector3d measured_m = Eigen::Vector3d::Zero();  // what it was told (delayed, noisy)
  double error_m = 0.0;                                  // |p - c|
  double axial_m = 0.0;                                  // (p - c) . z'_c
  double lateral_m = 0.0;                                // |(p - c) - axial z'_c|
  std::array<double, kNumCables> tension_n{};            // the plant's lower ends
  std::array<double, kNumCables> planned_tension_n{};    // the controller's at its pose
  std::array<double, kNumCables> s0_m{};                 // the winches' (the plant's s0)
};

struct LoopSummary {
  int samples = 0;
  double error_rms_m = 0.0, error_peak_m = 0.0;
  double lateral_rms_m = 0.0, lateral_peak_m = 0.0;
  double axial_rms_m = 0.0, axial_peak_m = 0.0;
  // The plant's tensions against the controller's plan (RMS over cables and samples, and
  // the largest), N.
  double tension_error_rms_n = 0.0, tension_error_peak_n = 0.0;
  // The winches' effort: the paid-out length summed over the cables (m, sum |ds0|).
  double winch_travel_m = 0.0;
  // Cycles at which a limit was broken (ControlStatus other than ok), and the first's name.
  int limit_cycles = 0;
  std::string first_limit;
};

struct LoopResult {
  LoopSpec spec;
  LoopOptions options;
  DynamicsStart start;              // the plant's
  std::vector<LoopSample> samples;  // one per control cycle
  LoopSummary summary;
  DynamicsStats stats;
  double seconds = 0.0;  // wall-clock
};

// The loop. `truth` is the plant, `controller` the model the control cycle uses (both
// with their moving parts' mass centre fixed: dynamics.h). False with *error: invalid
// options or spec, a plant that cannot start, a pose the controller's statics cannot
// solve (the time named), or a failed integration step.
bool RunLoop(const CableRobot& truth, const CableRobot& controller, const LoopSpec& spec,
             const LoopOptions& options, const DynamicsOptions& dynamics, LoopResult* result,
             std::string* error);

// The feed's efficiency lost to a lateral error of RMS `lateral_rms_m` at `frequency_hz`
// (the file's opening), in [0, 1].
double FeedEfficiencyLoss(double lateral_rms_m, double frequency_hz);

// The record as CSV: time_s, x_m, y_m, z_m, x_cmd_m, y_cmd_m, z_cmd_m, x_meas_m, y_meas_m,
// z_meas_m, error_mm, lateral_mm, axial_mm, T1_kN..T6_kN, T1_plan_kN..T6_plan_kN,
// s0_1_m..s0_6_m.
std::string LoopCsv(const LoopResult& result);
// The summary as JSON (error_rms_mm, error_peak_mm, lateral_*, axial_*, tension error,
// winch travel, limits, the efficiency loss at `frequency_hz`, the options).
std::string LoopSummaryJson(const LoopResult& result, double frequency_hz);

}  // namespace fastcal

#endif  // FASTCAL_CLOSED_LOOP_H_
