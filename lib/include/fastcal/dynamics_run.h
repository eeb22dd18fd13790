// A run in time: what the winches do (a move between two poses, a table of lengths, or
// nothing after a displacement: a free decay), the record sampled at a rate beside the
// quasi-static answer at the same winch lengths, and how far the two part
// (`fastcal dynamics`; docs/model.md, "Dynamics"; docs/cli.md).
//
// Moves: the pose follows a minimum-jerk profile (Flash and Hogan 1985, J. Neurosci. 5),
// p(t) = p0 + (p1 - p0) s(t/T), s(u) = 10 u^3 - 15 u^4 + 6 u^5, the attitude either the
// focal law at p(t) or turned from R0 to R1 by the same fraction of their relative
// rotation; the winches pay out the exact statics' unstretched lengths of p(t) (statics.h)
// at every integration step, then hold them for hold_s.
//
// The quasi-static reference at each sample: the chains' statics at the sample's winch
// lengths, without wind (dynamics.h, QuasiStatic): what a statics model of the same
// cables says, so that the departure is the dynamics' alone (the discretisation's own
// offset from the exact statics is reported apart, DynamicsStart).
//
// Departures, over the samples from `summary_from_s` on: for each cable the tension's
// T - T_qs (kN) and (T - T_qs)/T_qs, their peak |.| and RMS; the position's |p - p_qs|
// (mm). The residual vibration: the same peaks over the last residual_window_s. The settle
// time: from the end of the winches' motion (the move's end, the table's last change, or 0
// for a free decay) to the first sample from which every tension stays within
// settle_fraction of its quasi-static value to the end of the record; not settled when
// the last sample is outside.
#ifndef FASTCAL_DYNAMICS_RUN_H_
#define FASTCAL_DYNAMICS_RUN_H_

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/dynamics.h"
#include "fastcal/pose.h"

namespace fastcal {

// The winches' paid-out lengths in time: rows of (time_s, s0_1..s0_6), times increasing
// from 0, linear between rows, held after the last.
struct WinchTable {
  std::vector<double> time_s;
  std::vector<std::array<double, kNumCables>> s0_m;
};

// Reads a lengths CSV: a header naming time_s and s0_1_m .. s0_6_m (in any order; other
// columns are ignored), then one row per time; '#' lines and blank lines skipped. False
// with *error naming the file, the line and the column for a missing column, a field that
// is not a finite number, a length <= 0, a time that does not increase, a first time
// other than 0, or no rows.
bool ReadWinchTable(const std::string& path, WinchTable* table, std::string* error);
bool ParseWinchTable(const std::string& text, const std::string& source_name, WinchTable* table,
                     std::string* error);

struct DynamicsRunSpec {
  enum class Kind { kMove, kLengths, kFreeDecay };
  Kind kind = Kind::kMove;
  Pose start;
  // kMove: the end pose and the move's duration (> 0). With `focal_law`, every pose of
  // the path (and the end's attitude) follows it.
  Pose end;
  double move_s = 60.0;
  std::optional<FocalAttitudeLaw> focal_law;
  // kLengths: the winches' table (its first row is where the cabin starts: the chains'
  // equilibrium at those lengths, found from `start`).
  WinchTable lengths;
  // kFreeDecay: the cabin's displacement from its equilibrium (m) and turn (deg, a
  // rotation vector in global axes), released at rest.
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();
  // After the winches stop (the move's end, the table's last row; from 0 for a decay).
  double hold_s = 120.0;
  // Samples a second in the record (> 0; the integration step divides the interval).
  double rate_hz = 10.0;
  // The settle time's band, a fraction of each quasi-static tension (> 0).
  double settle_fraction = 0.005;
  // The residual vibration's window at the end (s, > 0).
  double residual_window_s = 20.0;
  // The departures from this time on (s; 0: the whole record).
  double summary_from_s = 0.0;

  bool IsValid(std::string* error) const;
  // When the winches stop moving, and the record's length.
  double MotionEndS() const;
  double DurationS() const;
};

struct DynamicsSample {
  double time_s = 0.0;
  Pose pose;
  std::array<double, kNumCables> tension_n{};
  Pose quasi_static_pose;
  std::array<double, kNumCables> quasi_static_tension_n{};
  std::array<double, kNumCables> s0_m{};
  double wind_speed_m_per_s = 0.0;
};

struct DynamicsDeparture {
  // Per cable and the largest over the cables.
  std::array<double, kNumCables> peak_kn{}, rms_kn{}, peak_percent{}, rms_percent{};
  double max_peak_kn = 0.0, max_rms_kn = 0.0, max_peak_percent = 0.0, max_rms_percent = 0.0;
  // |p - p_qs| of O' (mm) and the attitude's angle from the quasi-static (deg).
  double peak_position_mm = 0.0, rms_position_mm = 0.0, peak_attitude_deg = 0.0;
};

struct DynamicsRunResult {
  DynamicsRunSpec spec;
  DynamicsOptions options;
  DynamicsStart start;
  std::vector<DynamicsSample> samples;
  DynamicsDeparture departure;  // from summary_from_s on
  DynamicsDeparture residual;   // over the last residual_window_s
  double motion_end_s = 0.0;
  // From motion_end_s; NaN when not settled by the record's end.
  double settle_s = 0.0;
  bool settled = false;
  DynamicsStats stats;
  double seconds = 0.0;  // the run's wall-clock time
};

// The run. `progress` (may be empty) is called now and then with the simulated time and
// the duration. False with *error: an invalid spec or options, a start or end pose the
// statics cannot hold (named), a table's lengths the chains cannot hold, or a failed step.
bool RunDynamics(const CableRobot& robot, const DynamicsRunSpec& spec,
                 const DynamicsOptions& options, DynamicsRunResult* result, std::string* error,
                 const std::function<void(double, double)>& progress = {});

// The record as CSV (docs/cli.md, "dynamics"): time_s, x_m, y_m, z_m, roll_deg,
// pitch_deg, yaw_deg, T1_kN..T6_kN, x_qs_m, y_qs_m, z_qs_m, roll_qs_deg, pitch_qs_deg,
// yaw_qs_deg, T1_qs_kN..T6_qs_kN, s0_1_m..s0_6_m, wind_m_per_s.
std::string DynamicsCsv(const DynamicsRunResult& result);
// The summary as JSON: the run, the start, the departures, the residual, the settle time.
std::string DynamicsSummaryJson(const DynamicsRunResult& result);

// The minimum-jerk fraction s(u) for u in [0, 1] (0 before, 1 after).
double MinimumJerk(double u);
// The pose a fraction `u` (0..1) of the way through a minimum-jerk move from `from` to
// `to`: the position by s(u); the attitude the focal law's there when `law` is given,
// else turned from from's toward to's by s(u) of their relative rotation.
Pose MinimumJerkPose(const Pose& from, const Pose& to, double u, const FocalAttitudeLaw* law);

}  // namespace fastcal

#endif  // FASTCAL_DYNAMICS_RUN_H_
