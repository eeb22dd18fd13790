// `fastcal dynamics`: the cabin and its cables in time (dynamics.h, dynamics_run.h): a
// move, a winch table or a free decay, with or without wind; the record beside the
// quasi-static answer as CSV, the departures and the settle time as a summary and JSON.
#include <gflags/gflags.h>

#include <cmath>
#include <iostream>
#include <sstream>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/dynamics_run.h"
#include "fastcal/internal/quote.h"
#include "fastcal/version.h"

DEFINE_double(rate_hz, 10.0, "dynamics: samples a second in the record.");
DEFINE_string(initial_offset, "",
              "dynamics: a free decay from dx,dy,dz[,rx,ry,rz] (m, deg) off the equilibrium.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "dynamics";

const char kHelp[] =
    R"(fastcal dynamics: the cabin and its sagging cables in time, against the quasi-static answer.

Usage:
  fastcal dynamics --position=X,Y,Z [attitude] --to=X,Y,Z [--to-rpy=R,P,Y] [--move-s=60]
                   [--hold-s=120] [common flags]                       a move
  fastcal dynamics --position=X,Y,Z [attitude] --lengths=PLAN.csv [--hold-s=120] [...]
  fastcal dynamics --position=X,Y,Z [attitude] --initial-offset=DX,DY,DZ[,RX,RY,RZ]
                   [--hold-s=120] [...]                                a free decay
  fastcal dynamics --position=X,Y,Z [attitude] --wind=4,30 --hold-s=3600 [...]   held, in wind
Common: [--model=FILE.yaml] [--joints=v1,...] [--segments=40] [--damping-ratio=0.004 |
  --cable-damping-ratio=z1,...,z6] [--wind=SPEED,DIRECTION_DEG --gust-spectrum=kaimal
  --turbulence-intensity=0.15 --seed=1] [--rate-hz=10] [--step-s=0.02]
  [--settle-fraction=0.005] [--output=record.csv] [--summary=summary.json] [--force]

The model (docs/model.md, "Dynamics"): each cable a lumped-mass chain of --segments
segments (as fastcal modes), nonlinear, a slack segment carrying no force, damped in
proportion to its strain rate so that the lowest mode has --damping-ratio (or each
cable's first axial mode its own ratio); the cabin a rigid body with its mass, mass
centre and inertia; the air's drag on both, with a mean wind blowing toward
DIRECTION_DEG (from +x toward +y) and gusts from the Kaimal or Davenport spectrum
(seeded, fully coherent). Integrated by generalised-alpha with Newton steps of at most
--step-s. It starts at rest in the chains' own equilibrium at the exact statics'
unstretched lengths of the start pose.

Start pose: --position=X,Y,Z (m) and its attitude as solve takes one pose:
--attitude-law=focal (--tilt-fraction=0.41 --focal-centre=0,0,300), --rpy=R,P,Y (deg),
--quat=W,X,Y,Z or --rotvec=X,Y,Z (rad); R = I without one.
What the winches do (one of):
  --to=X,Y,Z      the pose follows a minimum-jerk profile over --move-s seconds to the end
                  pose (its attitude the focal law's with --attitude-law=focal, else
                  --to-rpy, else the start's), the winches paying out the exact statics'
                  unstretched lengths of every pose on the way; then they hold.
  --lengths=FILE  a table of time_s, s0_1_m .. s0_6_m (from 0 s, increasing; linear
                  between rows): any winch command; the cabin starts where the chains hang
                  at the first row's lengths.
  --initial-offset=DX,DY,DZ[,RX,RY,RZ]  a free decay: the cabin moved from its
                  equilibrium (m) and turned (deg, a rotation vector), the cables settled
                  onto it, released at rest.
  none            the winches hold: with --wind, the record of the cabin in the wind.
The record runs --hold-s beyond the winches' last motion.

Output: CSV to stdout or --output=FILE.csv, one row per sample at --rate-hz: time_s,
x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg (the cabin), T1_kN..T6_kN (the lower ends'
tensions), the quasi-static pose and tensions at the same winch lengths (x_qs_m ..
yaw_qs_deg, T1_qs_kN..T6_qs_kN: the chains at rest, no wind), s0_1_m..s0_6_m,
wind_m_per_s. --summary=FILE.json: the run, the start, the departures from quasi-static
(peak and RMS, kN and % of the quasi-static tension per cable; position mm), the
residual vibration over the last 20 s, the settle time (from the winches' stop until
every tension stays within --settle-fraction of its quasi-static value). Files are
written only on success, an existing one only with --force. The summary goes to stderr
(to stdout with --output).

Examples:
  fastcal dynamics --position=0,0,140 --to=10,0,140 --move-s=30 --hold-s=300 --output=move.csv
  fastcal dynamics --position=0,0,140 --initial-offset=0.1,0,0 --hold-s=400 --output=decay.csv
  fastcal dynamics --position=0,0,140 --wind=4,30 --hold-s=3600 --output=wind.csv
)";

// clang-format off
const std::set<std::string> kFlags = {
    "model", "position", "attitude-law", "rpy", "quat", "rotvec", "tilt-fraction",
    "focal-centre", "joints", "segments", "damping-ratio", "cable-damping-ratio", "wind",
    "gust-spectrum", "turbulence-intensity", "seed", "rate-hz", "to", "to-rpy", "move-s",
    "hold-s", "lengths", "initial-offset", "settle-fraction", "step-s", "output", "summary",
    "force"};
// clang-format on

}  // namespace

bool DynamicsOptionsFromFlags(DynamicsOptions* o, std::string* error) {
  if (FlagGiven("segments")) o->segments = FLAGS_segments;
  o->damping_ratio = FLAGS_damping_ratio;
  o->max_step_s = FLAGS_step_s;
  if (!FLAGS_cable_damping_ratio.empty()) {
    if (FlagGiven("damping-ratio")) {
      *error = "give --damping-ratio (the lowest mode's) or --cable-damping-ratio, not both";
      return false;
    }
    if (!ParseNumberList("cable-damping-ratio", FLAGS_cable_damping_ratio, &o->cable_damping_ratio,
                         error)) {
      return false;
    }
  }
  if (!WindFromFlags(&o->wind, error)) return false;
  if (o->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"segments", "--segments"},
                                  {"damping_ratio", "--damping-ratio"},
                                  {"cable_damping_ratio", "--cable-damping-ratio"},
                                  {"max_step_s", "--step-s"},
                                  {"wind.mean_speed_m_per_s", "--wind (its speed)"},
                                  {"wind.direction_deg", "--wind (its direction)"},
                                  {"wind.turbulence_intensity", "--turbulence-intensity"}});
  return false;
}

namespace {

// The winches' part of the spec from --to, --lengths or --initial-offset (at most one).
bool KindFromFlags(DynamicsRunSpec* spec, std::string* mode, std::string* error) {
  const int kinds = FlagGiven("to") + !FLAGS_lengths.empty() + !FLAGS_initial_offset.empty();
  if (kinds > 1) {
    *error = "give one of --to (a move), --lengths (a winch table), --initial-offset (a decay)";
    return false;
  }
  *mode = FlagGiven("to")          ? "a move"
          : !FLAGS_lengths.empty() ? "the winch lengths of " + FLAGS_lengths
          : !FLAGS_initial_offset.empty()
              ? "a free decay from --initial-offset=" + FLAGS_initial_offset
              : "the winches held";
  const std::string given = FlagGiven("to")                 ? "--to"
                            : !FLAGS_lengths.empty()        ? "--lengths"
                            : !FLAGS_initial_offset.empty() ? "--initial-offset"
                                                            : "a hold";
  if (!CheckFlagsApply({{"move-s", FlagGiven("to"), "--to"}, {"to-rpy", FlagGiven("to"), "--to"}},
                       given, error)) {
    return false;
  }
  if (FlagGiven("to")) {
    spec->kind = DynamicsRunSpec::Kind::kMove;
    spec->move_s = FLAGS_move_s;
    if (!ParsePosition("to", FLAGS_to, &spec->end.position_m, error)) return false;
    if (FLAGS_attitude_law == "focal") {
      if (!FLAGS_to_rpy.empty()) {
        *error = "--to-rpy: with --attitude-law=focal every pose of the move flies the law";
        return false;
      }
      FocalAttitudeLaw law;
      law.tilt_fraction = FLAGS_tilt_fraction;
      if (!ParseVector3("focal-centre", FLAGS_focal_centre, &law.focal_centre_m, error)) {
        return false;
      }
      spec->focal_law = law;
      spec->end.rotation = FocalAttitude(spec->end.position_m, law);
    } else if (!FLAGS_to_rpy.empty()) {
      Eigen::Vector3d rpy;
      if (!ParseRpyDeg("to-rpy", FLAGS_to_rpy, &rpy, error)) return false;
      spec->end.rotation = RotationFromRpyDeg(rpy.x(), rpy.y(), rpy.z());
    } else {
      spec->end.rotation = spec->start.rotation;
    }
  } else if (!FLAGS_lengths.empty()) {
    spec->kind = DynamicsRunSpec::Kind::kLengths;
    if (!ReadWinchTable(FLAGS_lengths, &spec->lengths, error)) {
      *error = "--lengths: " + *error;
      return false;
    }
  } else {
    spec->kind = DynamicsRunSpec::Kind::kFreeDecay;
    if (!FLAGS_initial_offset.empty()) {
      std::vector<double> v;
      if (!ParseNumberList("initial-offset", FLAGS_initial_offset, &v, error)) return false;
      if (v.size() != 3 && v.size() != 6) {
        *error = "--initial-offset=" + FLAGS_initial_offset +
                 ": give dx,dy,dz (m) or dx,dy,dz,rx,ry,rz (m, deg)";
        return false;
      }
      spec->offset_m = Eigen::Vector3d(v[0], v[1], v[2]);
      if (v.size() == 6) spec->rotation_deg = Eigen::Vector3d(v[3], v[4], v[5]);
    }
  }
  return true;
}

bool SpecFromFlags(DynamicsRunSpec* spec, std::string* attitude, std::string* mode,
                   std::string* error) {
  if (!SinglePoseFromFlags(&spec->start, attitude, error)) return false;
  spec->hold_s = FLAGS_hold_s;
  spec->rate_hz = FLAGS_rate_hz;
  spec->settle_fraction = FLAGS_settle_fraction;
  if (!KindFromFlags(spec, mode, error)) return false;
  if (spec->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"move_s", "--move-s"},
                                  {"hold_s", "--hold-s"},
                                  {"rate_hz", "--rate-hz"},
                                  {"settle_fraction", "--settle-fraction"},
                                  {"offset_m, rotation_deg", "--initial-offset"}});
  return false;
}

// The start and end poses the statics must hold (a computation refused: exit 1), each
// named by its flag.
bool PosesHold(const CableRobot& robot, const DynamicsRunSpec& spec, std::string* error) {
  StaticsSolution s;
  if (SolveStatics(robot, spec.start, StaticsOptions(), &s) != StaticsStatus::kOk) {
    *error = "--position=" + FLAGS_position +
             ": the statics cannot hold the start pose: " + DescribeStatus(s);
    return false;
  }
  if (spec.kind == DynamicsRunSpec::Kind::kMove &&
      SolveStatics(robot, spec.end, StaticsOptions(), &s) != StaticsStatus::kOk) {
    *error = "--to=" + FLAGS_to + ": the statics cannot hold the end pose: " + DescribeStatus(s);
    return false;
  }
  return true;
}

// "peak 0.207 kN (0.129%, cable 3), RMS 0.058 kN (0.036%); position peak 7.4 mm, RMS 2.1 mm".
std::string Departure(const DynamicsDeparture& d) {
  int worst = 0;
  for (int i = 1; i < kNumCables; ++i) {
    if (d.peak_percent[i] > d.peak_percent[worst]) worst = i;
  }
  std::ostringstream s;
  s << "tensions peak " << FormatDouble(d.max_peak_kn, 4) << " kN ("
    << FormatDouble(d.max_peak_percent, 3) << "%, cable " << worst + 1 << "), RMS "
    << FormatDouble(d.max_rms_kn, 4) << " kN (" << FormatDouble(d.max_rms_percent, 3)
    << "%); position peak " << FormatDouble(d.peak_position_mm, 3) << " mm, RMS "
    << FormatDouble(d.rms_position_mm, 3) << " mm";
  return s.str();
}

std::string Summary(const DynamicsRunResult& r, const std::string& attitude,
                    const std::string& mode) {
  const DynamicsRunSpec& spec = r.spec;
  std::ostringstream s;
  const double duration = spec.DurationS();
  s << "fastcal dynamics: " << mode;
  if (spec.kind == DynamicsRunSpec::Kind::kMove) {
    s << " of " << FormatDouble((spec.end.position_m - spec.start.position_m).norm(), 4) << " m in "
      << FormatDouble(spec.move_s, 4) << " s";
  }
  s << ", held " << FormatDouble(spec.hold_s, 4) << " s; " << attitude << "; " << r.options.segments
    << " segments, damping " << FormatDouble(r.start.damping_ratio[0], 3) << " on the lowest mode ("
    << FormatDouble(r.start.frequency_hz[0], 4) << " Hz), ";
  if (r.options.wind.mean_speed_m_per_s > 0.0) {
    s << "wind " << FormatDouble(r.options.wind.mean_speed_m_per_s, 3) << " m/s toward "
      << FormatDouble(r.options.wind.direction_deg, 4) << " deg ("
      << GustSpectrumName(r.options.wind.spectrum) << ", seed " << r.options.wind.seed << ")";
  } else {
    s << "no wind";
  }
  s << "\n  " << r.samples.size() << " samples at " << FormatDouble(spec.rate_hz, 4) << " Hz in "
    << FormatDouble(r.seconds, 3) << " s (" << FormatDouble(duration / r.seconds, 3)
    << "x real time, " << r.stats.steps << " steps)";
  s << "\n  start: the chains' equilibrium " << FormatDouble(1e3 * r.start.position_offset_m, 3)
    << " mm from the exact statics' pose, tensions within "
    << FormatDouble(100.0 * r.start.tension_offset, 2) << "%";
  s << "\n  dynamic - quasi-static: " << Departure(r.departure);
  s << "\n  residual (last " << FormatDouble(spec.residual_window_s, 3)
    << " s): " << Departure(r.residual);
  s << "\n  settle (every tension within " << FormatDouble(100.0 * spec.settle_fraction, 3)
    << "% of quasi-static): ";
  if (!r.settled) {
    s << "not settled by the record's end";
  } else {
    s << FormatDouble(r.settle_s, 4) << " s after the winches stopped (at "
      << FormatDouble(r.motion_end_s, 4) << " s)";
  }
  return s.str();
}

}  // namespace

bool WindFromFlags(WindOptions* wind, std::string* error) {
  if (!FLAGS_wind.empty()) {
    std::vector<double> v;
    if (!ParseNumberList("wind", FLAGS_wind, &v, error)) return false;
    if (v.size() != 2) {
      *error = "--wind=" + FLAGS_wind + ": give SPEED,DIRECTION_DEG (m/s, deg)";
      return false;
    }
    wind->mean_speed_m_per_s = v[0];
    wind->direction_deg = v[1];
  }
  if (!ParseGustSpectrum(FLAGS_gust_spectrum, &wind->spectrum)) {
    *error =
        "--gust-spectrum must be kaimal or davenport, got " + internal::Quote(FLAGS_gust_spectrum);
    return false;
  }
  wind->turbulence_intensity = FLAGS_turbulence_intensity;
  wind->seed = FLAGS_seed;
  return true;
}

int RunDynamicsCommand(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  std::string error, attitude, mode;
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  CableRobot robot;
  DynamicsOptions options;
  DynamicsRunSpec spec;
  if (!CheckRecordOutputs("summary", FLAGS_summary, &error) ||
      !LoadModelFlag("model", FLAGS_model, &robot, &error) ||
      !MassCentreAtJointsFlag(FLAGS_joints, &robot, &error) ||
      !DynamicsOptionsFromFlags(&options, &error) ||
      !SpecFromFlags(&spec, &attitude, &mode, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  if (!PosesHold(robot, spec, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  // Progress on stderr at each tenth of a run longer than ten minutes of motion.
  double next_report = 0.1;
  auto progress = [&](double t, double duration) {
    if (duration < 600.0 || t < next_report * duration) return;
    std::cerr << "fastcal dynamics: t = " << FormatDouble(t, 6) << " s of "
              << FormatDouble(duration, 6) << " s\n";
    next_report = std::floor(10.0 * t / duration + 1.0) / 10.0;
  };
  DynamicsRunResult result;
  if (!RunDynamics(robot, spec, options, &result, &error, progress)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  if (!WriteRecordOutputs(DynamicsCsv(result), FLAGS_summary,
                          FLAGS_summary.empty() ? "" : DynamicsSummaryJson(result), &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  (to_file ? std::cout : std::cerr) << Summary(result, attitude, mode) << std::endl;
  return 0;
}

}  // namespace fastcal::cli
