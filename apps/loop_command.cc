// fastcal loop: the cabin in its control loop (closed_loop.h; docs/cli.md, "loop").
#include <gflags/gflags.h>

#include <cmath>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/closed_loop.h"

DEFINE_string(controller_model, "",
              "loop: the controller's model YAML (what its control cycle solves with); empty "
              "= nominal FAST.");
DEFINE_string(pid, "", "loop: KP,KI,KD (1, 1/s, s); 0,0,0 is the feed-forward alone.");
DEFINE_double(control_period_s, fastcal::LoopOptions().control_period_s,
              "loop: the controller's period (s).");
DEFINE_double(error_filter_hz, fastcal::LoopOptions().error_filter_hz,
              "loop: the PID's error low-passed twice at this frequency (Hz; 0: none).");
DEFINE_double(measurement_noise_mm, 0.0, "loop: the position measurement's noise per axis (mm).");
DEFINE_double(measurement_delay_s, 0.0, "loop: the position measurement's delay (s).");
DEFINE_double(max_winch_speed, fastcal::LoopOptions().max_winch_speed_m_per_s,
              "loop: the winches' largest speed (m/s).");
DEFINE_double(max_winch_acceleration, fastcal::LoopOptions().max_winch_acceleration_m_per_s2,
              "loop: the winches' largest acceleration (m/s^2).");
DEFINE_double(frequency_ghz, 3.0, "loop: the observing frequency of the efficiency estimate.");
DEFINE_double(summary_from_s, 0.0, "loop: the summary from this time on (s).");
DEFINE_double(path_ramp_s, 60.0,
              "loop --trajectory: the path's speed eases in over this long (s; minimum jerk).");
DEFINE_double(path_speed, 0.0116,
              "loop --trajectory: the cabin's speed along the path (m/s; 0.0116, a source "
              "tracked at the sidereal rate on the 160 m focal sphere).");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "loop";

const char kHelp[] =
    R"(fastcal loop: the cabin in its control loop, a truth model against a controller's model.

Usage:
  fastcal loop --truth=TRUTH.yaml --controller-model=MODEL.yaml --position=X,Y,Z [attitude]
               [--hold-s=120] [options]                                  hold a pose
  fastcal loop ... --position=X,Y,Z [attitude] --to=X,Y,Z [--to-rpy=R,P,Y] [--move-s=60]
               [--hold-s=120] [options]                                  a slew, then hold
  fastcal loop ... --trajectory=arc|circle|line [its flags] [--path-speed=0.0116]
               [--attitude-law=focal] [--hold-s=120] [options]          a path, then hold

The plant is TRUTH in time (as fastcal dynamics: lumped-mass cables, the cabin, structural
damping, the wind's drag); the controller is the telescope's control cycle (the C
interface's fastcal_control_cycle) on MODEL. Every --control-period-s it measures the
cabin's position (with --measurement-noise-mm per axis and --measurement-delay-s), runs a
PID on the error to the command, low-passed twice at --error-filter-hz=0.02 (--pid=KP,KI,KD;
default 0.05,0.02,0: a crossover near 0.003 Hz; the 0.13-0.2 Hz modes, damped 0.004, would
ring up under a faster loop), solves the commanded pose plus the PID's correction
with MODEL's exact statics and pays out those winch lengths, within --max-winch-speed and
--max-winch-acceleration. --pid=0,0,0 is the feed-forward alone: the model's error is
then the cabin's. The plant starts at rest where TRUTH hangs at MODEL's lengths for the
start pose.

Start pose: --position=X,Y,Z (m) and its attitude as solve takes one pose:
--attitude-law=focal (--tilt-fraction=0.41 --focal-centre=0,0,300), --rpy=R,P,Y (deg),
--quat=W,X,Y,Z or --rotvec=X,Y,Z (rad); R = I without one. --to=X,Y,Z: a minimum-jerk
slew over --move-s seconds to the end pose (its attitude the focal law's with
--attitude-law=focal, else --to-rpy, else the start's), then --hold-s. --trajectory:
the command follows solve's trajectory (arc: --centre --radius --start-deg --end-deg
--nodes; circle: the paper's; line: --from --to --nodes) at --path-speed along it (the
default is a source tracked at the sidereal rate: 15 deg an hour on the 160 m focal
sphere), easing in over --path-ramp-s=60 (a path taken at full speed from rest rings the
modes), flying the focal law (the default) or --attitude-law=none, then --hold-s.

Options: [--joints=v1,...] (both models' moving parts held there) [--segments=40]
  [--damping-ratio=0.004 | --cable-damping-ratio=z1,...,z6] [--wind=SPEED,DIRECTION_DEG
  --gust-spectrum=kaimal --turbulence-intensity=0.15] [--seed=1] (the wind's and the
  measurement noise's) [--step-s=0.02] [--frequency-ghz=3] [--summary-from-s=0]
  [--output=loop.csv] [--summary=loop.json] [--force]

Output: CSV to stdout or --output=FILE.csv, one row per control cycle: time_s, x_m, y_m,
z_m (the cabin's O'), x_cmd_m, y_cmd_m, z_cmd_m (the command), x_meas_m, y_meas_m,
z_meas_m (what the controller was told), error_mm (|cabin - command|), lateral_mm and
axial_mm (across and along the feed's axis), T1_kN..T6_kN (the cabin's), T1_plan_kN..
T6_plan_kN (the controller's at its pose), s0_1_m..s0_6_m (the winches').
--summary=FILE.json: error_rms_mm, error_peak_mm, their lateral and axial parts, the
tension error, the winches' travel, limits broken, and the feed's efficiency lost at
--frequency-ghz: 1 - exp(-(2 pi 0.466 lateral_rms / wavelength)^2), a Ruze-like factor set
so that 10 mm RMS loses 8.2% at 3 GHz (Gan et al.). The console says the same. Files are
written only on success, an existing one only with --force.

Examples:
  fastcal loop --truth=calibration_data/nominal_fast.yaml --controller-model=model.yaml \
      --position=0,0,140 --attitude-law=focal --hold-s=300 --pid=0,0,0
  fastcal loop --truth=truth.yaml --controller-model=model_calibrated.yaml \
      --position=0,0,140 --to=20,0,140 --move-s=60 --hold-s=120 --wind=4,30 --output=slew.csv
)";

// clang-format off
const std::set<std::string> kFlags = {
    "truth", "controller-model", "position", "attitude-law", "rpy", "quat", "rotvec",
    "tilt-fraction", "focal-centre", "joints", "to", "to-rpy", "move-s", "hold-s", "pid",
    "control-period-s", "error-filter-hz", "measurement-noise-mm", "measurement-delay-s", "max-winch-speed",
    "max-winch-acceleration", "segments", "damping-ratio", "cable-damping-ratio", "wind",
    "gust-spectrum", "turbulence-intensity", "seed", "step-s", "frequency-ghz",
    "summary-from-s", "output", "summary", "force", "trajectory", "from", "nodes", "centre",
    "radius", "start-deg", "end-deg", "path-speed", "path-ramp-s"};
// clang-format on

bool LoopOptionsFromFlags(LoopOptions* o, std::string* error) {
  if (!FLAGS_pid.empty()) {
    std::vector<double> v;
    if (!ParseNumberList("pid", FLAGS_pid, &v, error)) return false;
    if (v.size() != 3) {
      *error = "--pid=" + FLAGS_pid + ": give KP,KI,KD (0,0,0: the feed-forward alone)";
      return false;
    }
    o->kp = v[0];
    o->ki_per_s = v[1];
    o->kd_s = v[2];
  }
  o->control_period_s = FLAGS_control_period_s;
  o->error_filter_hz = FLAGS_error_filter_hz;
  o->measurement_noise_m = FLAGS_measurement_noise_mm * 1e-3;
  o->measurement_delay_s = FLAGS_measurement_delay_s;
  o->max_winch_speed_m_per_s = FLAGS_max_winch_speed;
  o->max_winch_acceleration_m_per_s2 = FLAGS_max_winch_acceleration;
  o->seed = FLAGS_seed;
  o->summary_from_s = FLAGS_summary_from_s;
  if (!(FLAGS_frequency_ghz > 0.0) || !std::isfinite(FLAGS_frequency_ghz)) {
    *error = "--frequency-ghz must be > 0";
    return false;
  }
  if (o->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"control_period_s", "--control-period-s"},
                                  {"the PID's gains (kp, ki_per_s, kd_s)", "--pid"},
                                  {"measurement_noise_m", "--measurement-noise-mm"},
                                  {"error_filter_hz", "--error-filter-hz"},
                                  {"measurement_delay_s", "--measurement-delay-s"},
                                  {"max_winch_speed_m_per_s", "--max-winch-speed"},
                                  {"max_winch_acceleration_m_per_s2", "--max-winch-acceleration"},
                                  {"summary_from_s", "--summary-from-s"}});
  return false;
}

// A path: solve's trajectory (arc, circle, line) at --path-speed, the focal law's attitude
// unless --attitude-law=none.
bool PathFromFlags(LoopSpec* spec, std::string* attitude, std::string* error) {
  const std::string kind = FLAGS_trajectory;
  if (kind != "arc" && kind != "circle" && kind != "line") {
    *error = "--trajectory=" + kind + ": loop follows an arc, the circle or a line";
    return false;
  }
  for (const char* flag : {"position", "rpy", "quat", "rotvec", "to-rpy", "move-s"}) {
    if (FlagGiven(flag)) {
      *error = std::string("--") + flag + " applies to a hold or a slew, not to --trajectory";
      return false;
    }
  }
  if (!(FLAGS_path_speed > 0.0) || !std::isfinite(FLAGS_path_speed)) {
    *error = "--path-speed must be > 0";
    return false;
  }
  FocalAttitudeLaw law;
  law.tilt_fraction = FLAGS_tilt_fraction;
  if (!ParseVector3("focal-centre", FLAGS_focal_centre, &law.focal_centre_m, error)) return false;
  std::vector<Eigen::Vector3d> positions;
  bool known = true;
  if (!TrajectoryPositionsFromFlags(kind, law.focal_centre_m, &positions, &known, error)) {
    return false;
  }
  const bool focal = FLAGS_attitude_law != "none";
  if (focal) spec->focal_law = law;
  double t = 0.0;
  for (size_t k = 0; k < positions.size(); ++k) {
    if (k > 0) t += (positions[k] - positions[k - 1]).norm() / FLAGS_path_speed;
    if (k > 0 && !(t > spec->path_time_s.back())) continue;  // a repeated node
    Pose pose;
    pose.position_m = positions[k];
    if (focal) pose.rotation = FocalAttitude(pose.position_m, law);
    spec->path.push_back(pose);
    spec->path_time_s.push_back(t);
  }
  spec->start = spec->path.front();
  spec->path_ramp_s = FLAGS_path_ramp_s;
  *attitude = focal ? "the focal law along the path" : "R = I along the path";
  return true;
}

bool SpecFromFlags(LoopSpec* spec, std::string* attitude, std::string* error) {
  if (FlagGiven("trajectory")) {
    spec->hold_s = FLAGS_hold_s;
    if (!PathFromFlags(spec, attitude, error)) return false;
    if (spec->IsValid(error)) return true;
    *error = WithFlagNames(*error, {{"hold_s", "--hold-s"}, {"path_ramp_s", "--path-ramp-s"}});
    return false;
  }
  if (!SinglePoseFromFlags(&spec->start, attitude, error)) return false;
  spec->hold_s = FLAGS_hold_s;
  if (!CheckFlagsApply({{"move-s", FlagGiven("to"), "--to"}, {"to-rpy", FlagGiven("to"), "--to"}},
                       FlagGiven("to") ? "--to" : "a hold", error)) {
    return false;
  }
  if (FLAGS_attitude_law == "focal") {
    FocalAttitudeLaw law;
    law.tilt_fraction = FLAGS_tilt_fraction;
    if (!ParseVector3("focal-centre", FLAGS_focal_centre, &law.focal_centre_m, error)) return false;
    spec->focal_law = law;
  }
  if (FlagGiven("to")) {
    Pose end;
    spec->move_s = FLAGS_move_s;
    if (!ParsePosition("to", FLAGS_to, &end.position_m, error)) return false;
    if (spec->focal_law) {
      if (!FLAGS_to_rpy.empty()) {
        *error = "--to-rpy: with --attitude-law=focal every pose of the slew flies the law";
        return false;
      }
      end.rotation = FocalAttitude(end.position_m, *spec->focal_law);
    } else if (!FLAGS_to_rpy.empty()) {
      Eigen::Vector3d rpy;
      if (!ParseRpyDeg("to-rpy", FLAGS_to_rpy, &rpy, error)) return false;
      end.rotation = RotationFromRpyDeg(rpy.x(), rpy.y(), rpy.z());
    } else {
      end.rotation = spec->start.rotation;
    }
    spec->end = end;
  }
  if (spec->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"move_s", "--move-s"}, {"hold_s", "--hold-s"}});
  return false;
}

bool LoadModels(CableRobot* truth, CableRobot* controller, std::string* error) {
  if (FLAGS_truth.empty()) {
    *error = "--truth=MODEL.yaml is required (the plant: the cabin and cables as they are)";
    return false;
  }
  return LoadModelFlag("truth", FLAGS_truth, truth, error) &&
         LoadModelFlag("controller-model", FLAGS_controller_model, controller, error) &&
         MassCentreAtJointsFlag(FLAGS_joints, truth, error) &&
         MassCentreAtJointsFlag(FLAGS_joints, controller, error);
}

std::string Millimetres(double m) { return FormatDouble(m * 1e3, 3) + " mm"; }

std::string Summary(const LoopResult& r, const std::string& attitude) {
  const LoopSummary& s = r.summary;
  std::ostringstream o;
  o << "fastcal loop: ";
  if (!r.spec.path.empty()) {
    o << "a path of " << r.spec.path.size() << " nodes in "
      << FormatDouble(r.spec.path_time_s.back(), 5) << " s, then ";
  } else if (r.spec.end) {
    o << "a slew of " << FormatDouble((r.spec.end->position_m - r.spec.start.position_m).norm(), 4)
      << " m in " << FormatDouble(r.spec.move_s, 4) << " s, then ";
  }
  o << "held " << FormatDouble(r.spec.hold_s, 4) << " s; " << attitude << "; PID "
    << FormatDouble(r.options.kp, 3) << ", " << FormatDouble(r.options.ki_per_s, 3) << " /s, "
    << FormatDouble(r.options.kd_s, 3) << " s at "
    << FormatDouble(1.0 / r.options.control_period_s, 3) << " Hz; measured with "
    << FormatDouble(r.options.measurement_noise_m * 1e3, 3) << " mm noise, "
    << FormatDouble(r.options.measurement_delay_s, 3) << " s delay";
  o << "\n  " << r.samples.size() << " cycles in " << FormatDouble(r.seconds, 3) << " s ("
    << FormatDouble(r.spec.DurationS() / r.seconds, 3) << "x real time, " << r.stats.steps
    << " steps)";
  o << "\n  cabin - command (from " << FormatDouble(r.options.summary_from_s, 4) << " s): RMS "
    << Millimetres(s.error_rms_m) << ", peak " << Millimetres(s.error_peak_m) << "; lateral RMS "
    << Millimetres(s.lateral_rms_m) << ", peak " << Millimetres(s.lateral_peak_m) << "; axial RMS "
    << Millimetres(s.axial_rms_m) << ", peak " << Millimetres(s.axial_peak_m);
  o << "\n  tensions - the controller's plan: RMS " << FormatDouble(s.tension_error_rms_n / 1e3, 3)
    << " kN, peak " << FormatDouble(s.tension_error_peak_n / 1e3, 3) << " kN; winches' travel "
    << FormatDouble(s.winch_travel_m, 4) << " m";
  o << "\n  the feed's efficiency lost at " << FormatDouble(FLAGS_frequency_ghz, 3)
    << " GHz to the lateral error: "
    << FormatDouble(100.0 * FeedEfficiencyLoss(s.lateral_rms_m, FLAGS_frequency_ghz * 1e9), 3)
    << "% (1 - exp(-(2 pi 0.466 lateral_rms / wavelength)^2), 8.2% at 10 mm and 3 GHz: Gan "
       "et al.)";
  o << "\n  the plant's chains hang " << Millimetres(r.start.position_offset_m)
    << " from the exact statics' pose at the truth's own lengths (the discretisation)";
  if (s.limit_cycles > 0) {
    o << "\n  limits broken in " << s.limit_cycles << " cycles (first: " << s.first_limit << ")";
  }
  return o.str();
}

}  // namespace

int RunLoopCommand(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  std::string error, attitude;
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  CableRobot truth, controller;
  DynamicsOptions dynamics;
  LoopOptions options;
  LoopSpec spec;
  if (!CheckRecordOutputs("summary", FLAGS_summary, &error) ||
      !LoadModels(&truth, &controller, &error) || !DynamicsOptionsFromFlags(&dynamics, &error) ||
      !LoopOptionsFromFlags(&options, &error) || !SpecFromFlags(&spec, &attitude, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  LoopResult result;
  if (!RunLoop(truth, controller, spec, options, dynamics, &result, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  const std::string summary =
      FLAGS_summary.empty() ? "" : LoopSummaryJson(result, FLAGS_frequency_ghz * 1e9);
  if (!WriteRecordOutputs(LoopCsv(result), FLAGS_summary, summary, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  (to_file ? std::cout : std::cerr) << Summary(result, attitude) << std::endl;
  return 0;
}

}  // namespace fastcal::cli
