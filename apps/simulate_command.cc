// `fastcal simulate`: synthetic telemetry (the dataset CSV that calibrate and evaluate read)
// from a truth model along a trajectory, with attitude control error, pose and tension
// sensor noise, outliers, sensor gain and bias and per-cable density mismatch; the truth
// model is written beside the CSV.
#include <gflags/gflags.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/cable_robot.h"
#include "fastcal/dataset.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/quote.h"
#include "fastcal/simulation.h"
#include "fastcal/statics.h"
#include "fastcal/time_text.h"
#include "fastcal/trajectory.h"
#include "fastcal/version.h"

// Shared with solve (solve_command.cc) and calibrate (calibrate_command.cc): gflags flags
// are process-global, so they are defined once and declared here.
DECLARE_bool(dynamics);  // simulate_dynamics.cc

DEFINE_string(mass_centre, "", "simulate: truth mass centre x,y,z in the cabin frame (m).");
DEFINE_double(attitude_control_deg, 0.0, "simulate: sigma of actual - planned rpy (deg).");
DEFINE_double(tension_noise_percent, 3.0, "simulate: relative tension noise sigma (%).");
DEFINE_double(outlier_fraction, 0.0, "simulate: probability of an outlier reading.");
DEFINE_double(outlier_scale_percent, 30.0, "simulate: outlier = reading (1 + U(-s, s)/100).");
DEFINE_double(density_mismatch_percent, 0.0, "simulate: per-cable density factor sigma (%).");
DEFINE_string(sensor_gain, "", "simulate: sensor gains g1,...,g6 or one for all.");
DEFINE_string(sensor_bias_kN, "", "simulate: sensor biases b1,...,b6 or one for all (kN).");
DEFINE_double(attitude_control_time_s, 0.0,
              "simulate: correlation time of the attitude control error (s); 0 = white.");
DEFINE_double(tension_drift_percent, 0.0, "simulate: slow tension error sigma per cable (%).");
DEFINE_double(tension_drift_time_s, 0.0, "simulate: its correlation time (s).");
DEFINE_double(tension_drift_kN, 0.0, "simulate: absolute part of the slow tension error (kN).");
DEFINE_double(session_gap_s, 0.0, "simulate: time between consecutive sessions (s).");
DEFINE_double(sensor_rezero_kN, 0.0,
              "simulate: sensors re-zeroed at each new session, bias change sigma (kN).");
DEFINE_double(mass_centre_drift_m, 0.0, "simulate: mass-centre drift sigma per axis (m).");
DEFINE_double(mass_centre_drift_time_s, 0.0, "simulate: its correlation time (s).");
DEFINE_bool(mass_centre_drift_centred, false,
            "simulate: each session's (day's) drift made of zero mean: a wander inside days "
            "around a constant level.");
DEFINE_string(track_minutes, "20,60",
              "simulate: tracks: each source tracked for a time in this range (min).");
DEFINE_double(sensor_gain_spread_percent, 0.0, "simulate: per-cable gain spread drawn once (%).");
DEFINE_double(sensor_bias_spread_kN, 0.0, "simulate: per-cable bias spread drawn once (kN).");
DEFINE_double(length_offset_spread_m, 0.0,
              "simulate: per-cable length-encoder offset spread drawn once (m).");
DEFINE_double(length_noise_m, 0.0, "simulate: sigma of each length reading's noise (m).");
DEFINE_int32(sessions, 1, "simulate: consecutive sessions (session column 1..N).");
DEFINE_string(session_shift_m, "",
              "simulate: mass centre moved by dx,dy,dz (m) at each new session.");
DEFINE_string(mass_centre_step, "",
              "simulate: mass centre steps T:dx,dy,dz (s: m), several joined by ';'.");
DEFINE_int32(days, 0, "simulate: a season: the samples cut into N days, one session a day.");
DEFINE_string(start, "", "simulate: time of the first sample (s, or ISO 8601).");
DEFINE_string(sensor_step, "",
              "simulate: sensors re-zeroed: T:CABLE:DKN (s, 1..6, kN), several joined by ';'.");
DEFINE_string(joint_law, "zero", "simulate: the rotator's angles: zero, focal or grid.");
DEFINE_string(joint_grid_deg, "-15,0,15",
              "simulate: with --joint-law=grid, the values each rotator angle visits (deg).");
DEFINE_double(prismatic_spread_m, 0.0,
              "simulate: sigma of each prismatic joint (the Stewart platform), m.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "simulate";

const char kHelp[] =
    R"(fastcal simulate: synthetic telemetry of the FAST cable robot from a known truth model.

Usage:
  fastcal simulate --out=FILE.csv [--force] [--truth=MODEL.yaml] [trajectory] [errors]
  fastcal simulate --vibration --position=X,Y,Z [attitude] --out=FILE.csv [--excite=1,2,3]
                   [--damping=0.005,0.01,0.015] [--amplitude-m=0.05] [--duration-s=400]
                   [--interval-s=0.1] [--position-noise-m=M] [--attitude-noise-deg=D]
                   [--tension-noise-kN=T] [--segments=48] [--seed=1]
  fastcal simulate --dynamics --out=FILE.csv [trajectory] [errors] [--speed-m-per-s=0.5]
                   [--min-move-s=10] [--wait-s=30 | --waits=design.json] [--interval-s=1]
                   [--wind=SPEED,DIR_DEG]
                   [--gust-spectrum=kaimal] [--turbulence-intensity=0.15] [--segments=40]
                   [--damping-ratio=0.004] [--step-s=0.02]

--dynamics: the survey flown in time (fastcal dynamics' model) instead of the cabin
standing at each planned pose: to each new pose a minimum-jerk move lasting the longer of
--min-move-s and its distance over --speed-m-per-s, the winches paying out the truth
statics' lengths, then --wait-s before the sample (or, with --waits=design.json, each
move's own wait, fastcal design's stops[].settle.wait_s: one per move, the design's poses
flown in its order); a pose that repeats the one before
(a stop's further samples, or the same pose throughout: an ambient record) is sampled
--interval-s later. The samples' time, pose, tensions and lengths are the dynamics' (in
--wind, seeded by --seed), then measured with the errors below. Not with an attitude
control error, a mass-centre drift or steps, sensor steps, sessions or moving parts.

--vibration: a record of the cabin's free vibration at one pose from the linearised model
(fastcal modes): the predicted modes --excite'd (1-based) with the given damping ratios
(0.01 each without --damping for other modes than 1,2,3), each moving a point of the cabin
(O' or an anchor point) by at most --amplitude-m at t = 0 (at most 1 m: the
linearisation's small motions), superposed; the tensions follow the cabin's motion
quasi-statically; white noise of the given sigmas, none unless given (each noise flag
defaults to 0; the summary says the damping and the noise). At most 10^6 samples
(--duration-s / --interval-s); a mode with under 0.1% of its energy in the cabin, and a
motion that would slacken a cable, are refused. A dataset CSV (time_s, the pose,
T1_kN..T6_kN) that `fastcal modes --data` identifies. Only the flags shown apply.

Writes FILE.csv (the dataset format calibrate and evaluate read, docs/data-format.md) and
the truth model actually used beside it as FILE.truth.yaml (FILE.csv minus ".csv", plus
".truth.yaml"), both with the command line (without --force) in a header comment. Both
are written to temporary files and renamed into place: on any failure neither is left.
An existing FILE.csv or FILE.truth.yaml is refused (exit 2) unless --force.

Per planned pose n at time t = n * interval-s (position p, planned attitude a_plan as
roll,pitch,yaw):
  actual attitude     a_act  = a_plan + c(t), c per angle AR(1): sigma
                      attitude-control-deg, correlation time attitude-control-time-s
  actual position     p (held exactly)
  mass centre         the truth model's + d(t), d per axis AR(1): sigma
                      mass-centre-drift-m, correlation time mass-centre-drift-time-s
  truth tensions      T_i, s0_i from the truth model's statics at (p, a_act), --method
  sensor reading      y_i = gain_i T_i + bias_i
  measured tension    y_i (1 + N(0, tension-noise-percent/100) + u_i(t))
                      + N(0, tension-noise-kN), u_i per cable AR(1): sigma
                      tension-drift-percent/100, correlation time tension-drift-time-s (a
                      slow sensor error); or, with probability outlier-fraction,
                      y_i (1 + U(-s, s)/100), s = outlier-scale-percent
An AR(1) process with correlation time tau steps by phi = exp(-interval / tau) and starts
stationary; tau = 0 draws it afresh every sample (white).
  measured attitude   a_act + N(0, attitude-noise-deg)                per angle
  measured position   p + N(0, position-noise-m)                      per axis
  measured length     s0_i + o_i + N(0, length-noise-m), o_i the encoder's offset (the
                      truth model's length_offset_m, spread by length-offset-spread-m)
The CSV has time_s = n * interval-s, the measured pose (x_m,y_m,z_m,roll_deg,pitch_deg,
yaw_deg), the planned attitude (planned_roll_deg,..), T1_kN..T6_kN and the measured
lengths s0_1_m..s0_6_m (the truth solution's unstretched lengths exactly, without
--length-offset-spread-m and --length-noise-m or offsets in the truth model).

Truth model:
  --truth=FILE.yaml               model (docs/model-format.md); default the nominal FAST
                                  model
  --mass-centre=x,y,z             override its mass centre, cabin frame (m)
  --sensor-gain=g|g1,..,g6        override the sensor gains (one value = all cables)
  --sensor-bias-kN=b|b1,..,b6     override the sensor biases (kN)
  --density-mismatch-percent=0    multiply each cable's linear density by 1 + N(0, p/100),
                                  drawn once (non-uniform cables); the result is the truth
                                  model written to FILE.truth.yaml
  --sensor-gain-spread-percent=0  multiply each cable's sensor gain by 1 + N(0, p/100),
                                  drawn once (written to FILE.truth.yaml)
  --sensor-bias-spread-kN=0       add N(0, kN) to each cable's sensor bias, drawn once
  --length-offset-spread-m=0      add N(0, m) to each cable's length-encoder offset, drawn
                                  once (written to FILE.truth.yaml as length_offset_m)
  --method=exact                  statics of the truth tensions: exact (default),
                                  aas-refined, aas
  (Until 0.2 the units were spelt -kn and -pct: --sensor-bias-kn, --tension-noise-pct...;
  those names still work, with a note on stderr.)

Moving parts (a truth model with cabin.moving_parts, docs/model-format.md): the dataset
gets each joint's column (rotator_a_deg, stewart_x_m, ...) and the mass centre moves with
the joints (docs/model.md, "Moving parts"):
  --joint-law=zero                the rotator's two angles: zero; focal (it completes the
                                  tilt the cabin does not give: the feed axis along the
                                  focal sphere's radius, toward --focal-centre); grid
                                  (sample n visits point n mod G of the grid below, G its
                                  size squared: the angles vary at fixed cabin poses)
  --joint-grid-deg=-15,0,15       with grid: the values each of the two angles visits
  --prismatic-spread-m=0          each prismatic joint (the platform) N(0, m), per sample
A model without moving parts refuses these flags.

Trajectory (--trajectory=, default circle):
  circle  the paper's measured circle: centre (0,0,156.73), radius 71.11 m, full turn,
          --nodes=360 (default for circle)
  line    --from=50,0,150 --to=-50,0,150 --nodes=101
  arc     --centre=0,0,150 --radius=50 --start-deg=0 --end-deg=180 --nodes=101
  grid    focal-sphere cap: --max-off-axis-deg=40 --off-axis-step-deg=5
          --azimuth-step-deg=15 --focal-radius=160
  random  --samples=100 --max-off-axis-deg=40 --radial-spread=0 (m, off the sphere),
          positions drawn with --seed
  tracks  --samples at --interval-s: sources tracked at the sidereal rate (the feed's
          focal point moving on the focal sphere, ~11 mm/s), each for --track-minutes=20,60
          (a time drawn in the range) or until it leaves the cap to --max-off-axis-deg=40,
          then the next (the slew not sampled); with --days each day starts a source;
          drawn with --seed
  poses   --poses=FILE.csv: x_m,y_m,z_m and optionally roll_deg,pitch_deg,yaw_deg or
          qw,qx,qy,qz (the planned attitudes), and with a truth model with moving parts
          its joint columns (a design's poses.csv: each row's joints, then no joint law);
          --poses alone implies this trajectory; --columns=MAP.yaml reads it as
          exported, through a column map (docs/data-format.md, "Column maps")
Planned attitude (--attitude-law): focal (default for trajectories: tilt z' toward
--focal-centre=0,0,300 by --tilt-fraction=0.41 of the off-axis angle) or none (R = I).
A --poses file keeps its own attitudes unless --attitude-law is given.
A trajectory flag given for another trajectory (--nodes with grid, --radius with the
default circle, --tilt-fraction with --attitude-law=none) is an error naming it (exit 2),
never silently ignored; so is a flag given twice.

Errors (all zero-mean Gaussian unless stated; one --seed=1 drives them all, each error
source with its own generator, so changing one sigma leaves the others' numbers alone):
  --attitude-control-deg=0        actual minus planned attitude, per angle (deg)
  --attitude-control-time-s=0     its correlation time (s); 0 = white
  --mass-centre-drift-m=0         drift of the mass centre about the truth model's, per
                                  axis (m)
  --mass-centre-drift-time-s=0    its correlation time (s)
  --mass-centre-drift-centred     each session's (day's) drift made of zero mean: a
                                  wander inside days about a level that does not move
  --tension-drift-percent=0       slow relative tension error per cable (%)
  --tension-drift-time-s=0        its correlation time (s)
  --tension-drift-kN=0            absolute part of the slow error (kN): its sd is then
                                  sqrt(kN^2 + (percent/100 y_i)^2), one process per cable
  --attitude-noise-deg=0          measured minus actual attitude, per angle (deg)
  --position-noise-m=0            measured minus actual position, per axis (m)
  --tension-noise-percent=3       relative tension noise (%, the paper's sensors: ~3%)
  --tension-noise-kN=0            absolute tension noise (kN), added to the relative one
  --outlier-fraction=0            probability that a reading is an outlier instead
  --outlier-scale-percent=30      outlier half-width (%), in [0, 100)
  --length-noise-m=0              noise of each length reading (m)
A noise draw that would make a reading <= 0 is redrawn (counted in the summary).

Sessions and steps of the mass centre (the cabin's structure changed):
  --sessions=1                    cut the samples into N consecutive sessions of equal
                                  length, labelled 1..N in a session column
                                  (docs/data-format.md)
  --session-shift-m=dx,dy,dz      the mass centre moves by this at the first sample of
                                  each session after the first (needs --sessions >= 2)
  --mass-centre-step=T:dx,dy,dz   the mass centre moves by this at time T (s or ISO 8601)
                                  and stays; several joined by ';' (steps add up)
  --session-gap-s=0               time between one session's end and the next one's start
                                  (s), added to time_s; the slow errors decorrelate over it
  --sensor-rezero-kN=0            sensors re-zeroed at the start of each session after the
                                  first: each cable's bias moves by N(0, kN)
  --sensor-step=T:CABLE:DKN       one sensor re-zeroed: cable CABLE's bias moves by DKN kN
                                  at time T (s or ISO 8601) and stays; several joined by ';'
A season (fastcal track): --start=T, the first sample's time (s, or ISO 8601 such as
2024-05-01T20:00:00Z; a zone-less one is UTC), and --days=N, the samples cut into N
sessions a day apart (each day's samples --interval-s apart from --start + k days; the
slow errors decorrelate overnight; no session column). Steps' times T are in the same
seconds, or ISO 8601 times.
The truth model written out has the mass centre before any step and the first session's
sensor biases; its header lists the steps and every session's biases.

Output: --out=FILE.csv (required), --force to replace existing files, --interval-s=1
between samples. A summary of what was written on stdout (> sim.txt keeps it): samples,
RMS of the noise added per cable (kN and %), outliers, pose-error RMS; notes and errors
on stderr.

Exit codes: 0 ok, 1 the truth model cannot hold a pose (the node is named) or the machine
failed (a full disk: the file named), 2 bad input.

Examples (the bundled datasets):
  # the paper's measured circle, mass centre moved as the authors found it
  fastcal simulate --mass-centre=0.22,0.11,0.5 --nodes=360 --attitude-control-deg=0.2 \
    --attitude-noise-deg=0.02 --position-noise-m=0.01 --tension-noise-percent=3 --seed=1 \
    --force --out=calibration_data/circle_paper.csv
  # many zenith angles: 600 random poses on the focal-sphere cap up to 40 deg, +-3 m
  fastcal simulate --trajectory=random --samples=600 --max-off-axis-deg=40 \
    --radial-spread=3 --attitude-law=focal --mass-centre=0.22,0.11,0.5 \
    --attitude-control-deg=0.2 --attitude-noise-deg=0.02 --position-noise-m=0.01 \
    --tension-noise-percent=3 --seed=2 --force \
    --out=calibration_data/workspace_multi_zenith.csv
  # realistic telemetry: rings over the cap, smooth control error, slow tension error,
  # drifting mass centre, per-cable densities, gains and biases (calibration_data/README.md)
  fastcal simulate --trajectory=grid --max-off-axis-deg=40 --off-axis-step-deg=5 \
    --azimuth-step-deg=2 --interval-s=2 --mass-centre=0.22,0.11,0.5 \
    --attitude-control-deg=0.2 --attitude-control-time-s=60 --attitude-noise-deg=0.02 \
    --position-noise-m=0.01 --tension-noise-percent=3 --tension-drift-percent=2 \
    --tension-drift-time-s=120 --mass-centre-drift-m=0.01 --mass-centre-drift-time-s=600 \
    --density-mismatch-percent=1.5 --sensor-gain-spread-percent=1 --sensor-bias-spread-kN=2 \
    --outlier-fraction=0.002 --outlier-scale-percent=90 --seed=5 --force \
    --out=calibration_data/realistic_survey.csv
  # sensor gain errors and 2% outliers on a straight line
  fastcal simulate --trajectory=line --sensor-gain=1.02,0.98,1,1,1.01,0.99 \
    --outlier-fraction=0.02 --out=line.csv
)";

// clang-format off
const std::set<std::string> kFlags = {
    "truth", "columns", "mass-centre", "sensor-gain", "sensor-bias-kN", "density-mismatch-percent",
    "method",
    "trajectory", "nodes", "from", "to", "centre", "radius", "start-deg", "end-deg",
    "max-off-axis-deg", "off-axis-step-deg", "azimuth-step-deg", "focal-radius", "samples",
    "radial-spread", "poses", "attitude-law", "tilt-fraction", "focal-centre",
    "attitude-control-deg", "attitude-noise-deg", "position-noise-m", "tension-noise-percent",
    "tension-noise-kN", "outlier-fraction", "outlier-scale-percent", "seed", "interval-s", "out",
    "force", "attitude-control-time-s", "tension-drift-percent", "tension-drift-time-s",
    "mass-centre-drift-m", "mass-centre-drift-time-s", "mass-centre-drift-centred",
    "track-minutes", "sensor-gain-spread-percent",
    "sensor-bias-spread-kN", "sessions", "session-shift-m", "mass-centre-step",
    "tension-drift-kN", "session-gap-s", "sensor-rezero-kN", "length-offset-spread-m",
    "length-noise-m", "days", "start", "sensor-step", "joint-law", "joint-grid-deg",
    "prismatic-spread-m",
    // --vibration (simulate_vibration.cc)
    "vibration", "position", "rpy", "quat", "rotvec", "excite", "damping", "amplitude-m",
    "duration-s", "segments",
    // --dynamics (simulate_dynamics.cc)
    "dynamics", "wait-s", "waits", "min-move-s", "speed-m-per-s", "wind", "damping-ratio",
    "turbulence-intensity", "gust-spectrum", "step-s"};
// clang-format on

// "v" (the same for every cable) or "v1,...,v6": finite numbers.
bool ParseOneOrSix(const std::string& name, const std::string& text,
                   std::array<double, kNumCables>* values, std::string* error) {
  std::vector<double> parsed;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    double v = 0.0;
    std::string why;
    if (!ParseNumberItem(item, &v, &why)) {
      *error = "--" + name + ": " + why;
      return false;
    }
    parsed.push_back(v);
  }
  if ((parsed.size() != 1 && parsed.size() != kNumCables) || text.back() == ',') {
    *error = "--" + name + " needs one value or six comma-separated values, got " +
             internal::Quote(text);
    return false;
  }
  for (int i = 0; i < kNumCables; ++i) (*values)[i] = parsed[parsed.size() == 1 ? 0 : i];
  return true;
}

bool LoadTruth(CableRobot* truth, std::string* error) {
  if (!LoadModelFlag("truth", FLAGS_truth, truth, error)) return false;
  if (!FLAGS_mass_centre.empty() &&
      !ParseVector3("mass-centre", FLAGS_mass_centre, &truth->mass_centre_cabin_m, error)) {
    return false;
  }
  std::array<double, kNumCables> values{};
  if (!FLAGS_sensor_gain.empty()) {
    if (!ParseOneOrSix("sensor-gain", FLAGS_sensor_gain, &values, error)) return false;
    for (int i = 0; i < kNumCables; ++i) {
      if (!(values[i] > 0.0)) {
        *error = "--sensor-gain: the gain of cable " + std::to_string(i + 1) +
                 " must be > 0 (got " + FormatDouble(values[i]) + ")";
        return false;
      }
      truth->cables[i].sensor_gain = values[i];
    }
  }
  if (!FLAGS_sensor_bias_kN.empty()) {
    if (!ParseOneOrSix("sensor-bias-kN", FLAGS_sensor_bias_kN, &values, error)) return false;
    for (int i = 0; i < kNumCables; ++i) truth->cables[i].sensor_bias_n = values[i] * kNPerKn;
  }
  std::string why;
  if (!truth->IsValid(&why)) {
    *error = "truth model: " + why;
    return false;
  }
  return true;
}

// --mass-centre-step (T:dx,dy,dz;...) and --session-shift-m (a step at the first sample
// of each session after the first; needs --sessions and the trajectory's length, so its
// times are set in RunSimulate: StepsAtSessions).
bool SetStepsFromFlags(SimulationOptions* options, std::string* error) {
  std::stringstream list(FLAGS_mass_centre_step);
  std::string item;
  while (!FLAGS_mass_centre_step.empty() && std::getline(list, item, ';')) {
    // The shift follows the last ':' (an ISO 8601 time has its own).
    const size_t colon = item.rfind(':');
    MassCentreStep step;
    std::string why;
    if (colon == std::string::npos ||
        !ParseTimeValue(item.substr(0, colon), 0, &step.time_s, &why) ||
        !ParseVector3("mass-centre-step", item.substr(colon + 1), &step.shift_m, error)) {
      *error =
          "--mass-centre-step needs T:dx,dy,dz (time in s or ISO 8601, shift in m), several "
          "joined by ';', got " +
          internal::Quote(item) + (why.empty() ? "" : ": " + why);
      return false;
    }
    options->mass_centre_steps.push_back(step);
  }
  if (!FLAGS_session_shift_m.empty() && FLAGS_sessions < 2) {
    *error = "--session-shift-m needs --sessions=N with N >= 2";
    return false;
  }
  std::stringstream sensors(FLAGS_sensor_step);
  while (!FLAGS_sensor_step.empty() && std::getline(sensors, item, ';')) {
    // CABLE and DKN follow the last two ':' (an ISO 8601 time has its own).
    const size_t second = item.rfind(':');
    const size_t first = second == std::string::npos || second == 0 ? std::string::npos
                                                                    : item.rfind(':', second - 1);
    SensorBiasStep step;
    double cable = 0.0, shift_kn = 0.0;
    std::string why;
    if (first == std::string::npos ||
        !ParseTimeValue(item.substr(0, first), 0, &step.time_s, &why) ||
        !ParseNumberItem(item.substr(first + 1, second - first - 1), &cable, &why) ||
        !ParseNumberItem(item.substr(second + 1), &shift_kn, &why) || cable < 1 ||
        cable > kNumCables || cable != std::floor(cable)) {
      *error =
          "--sensor-step needs T:CABLE:DKN (time in s, cable 1..6, bias change in kN), "
          "several joined by ';', got " +
          internal::Quote(item) + (why.empty() ? "" : ": " + why);
      return false;
    }
    step.cable = static_cast<int>(cable) - 1;
    step.shift_n = shift_kn * kNPerKn;
    options->sensor_bias_steps.push_back(step);
  }
  return true;
}

// --days: the samples cut into one session a day, each starting 24 h after the one before
// (needs the trajectory's length, known in RunSimulate).
bool DaysFromFlags(long long samples, SimulationOptions* options, std::string* error) {
  if (FLAGS_days == 0) return true;
  constexpr double kDayS = 86400.0;
  if (FLAGS_days < 1 || FlagGiven("sessions") || FlagGiven("session-gap-s")) {
    *error =
        "--days=N (N >= 1) sets the sessions and the gaps between them: give it without "
        "--sessions and --session-gap-s";
    return false;
  }
  const double per_day = static_cast<double>(samples) / FLAGS_days;
  if (samples % FLAGS_days != 0 || per_day * options->sample_interval_s > kDayS) {
    *error = "--days=" + std::to_string(FLAGS_days) + ": the trajectory's " +
             std::to_string(samples) +
             " samples must be a whole number a day, each day's lasting at most 24 h at "
             "--interval-s";
    return false;
  }
  options->sessions = FLAGS_days;
  options->session_gap_s = kDayS - per_day * options->sample_interval_s;
  return true;
}

// The steps of --session-shift-m: one at the first sample of each session after the first.
bool StepsAtSessions(int samples, SimulationOptions* options, std::string* error) {
  if (FLAGS_session_shift_m.empty()) return true;
  Eigen::Vector3d shift;
  if (!ParseVector3("session-shift-m", FLAGS_session_shift_m, &shift, error)) return false;
  for (int k = 1; k < options->sessions; ++k) {
    // The first sample t with t * sessions / samples == k (LabelSessions' rule).
    const long long first =
        (static_cast<long long>(k) * samples + options->sessions - 1) / options->sessions;
    options->mass_centre_steps.push_back(
        {options->start_time_s + static_cast<double>(first) * options->sample_interval_s +
             k * options->session_gap_s,
         shift});
  }
  return true;
}

// --joint-law, --joint-grid-deg, --prismatic-spread-m (checked against the truth model's
// parts when the plan is made: Simulate).
bool SetJointsFromFlags(SimulationOptions* options, std::string* error) {
  JointPlanOptions& j = options->joints;
  if (!ParseRevoluteLaw(FLAGS_joint_law, &j.revolute)) {
    *error = "--joint-law must be zero, focal or grid, got " + internal::Quote(FLAGS_joint_law);
    return false;
  }
  if (FlagGiven("joint-grid-deg") && j.revolute != RevoluteLaw::kGrid) {
    *error = "--joint-grid-deg needs --joint-law=grid";
    return false;
  }
  if (!ParseNumberList("joint-grid-deg", FLAGS_joint_grid_deg, &j.grid_deg, error)) return false;
  j.prismatic_sigma_m = FLAGS_prismatic_spread_m;
  j.seed = FLAGS_seed;
  return ParseVector3("focal-centre", FLAGS_focal_centre, &j.focal_centre_m, error);
}

bool SetOptionsFromFlags(SimulationOptions* options, std::string* error) {
  options->attitude_control_sigma_deg = FLAGS_attitude_control_deg;
  options->attitude_measurement_sigma_deg = FLAGS_attitude_noise_deg;
  options->position_measurement_sigma_m = FLAGS_position_noise_m;
  options->tension_noise_percent = FLAGS_tension_noise_percent;
  options->tension_noise_kn = FLAGS_tension_noise_kN;
  options->outlier_fraction = FLAGS_outlier_fraction;
  options->outlier_scale_percent = FLAGS_outlier_scale_percent;
  options->density_mismatch_percent = FLAGS_density_mismatch_percent;
  options->attitude_control_time_s = FLAGS_attitude_control_time_s;
  options->tension_drift_percent = FLAGS_tension_drift_percent;
  options->tension_drift_time_s = FLAGS_tension_drift_time_s;
  options->mass_centre_drift_m = FLAGS_mass_centre_drift_m;
  options->mass_centre_drift_time_s = FLAGS_mass_centre_drift_time_s;
  options->mass_centre_drift_centred = FLAGS_mass_centre_drift_centred;
  options->sensor_gain_spread_percent = FLAGS_sensor_gain_spread_percent;
  options->sensor_bias_spread_kn = FLAGS_sensor_bias_spread_kN;
  options->length_offset_spread_m = FLAGS_length_offset_spread_m;
  options->length_noise_m = FLAGS_length_noise_m;
  options->seed = FLAGS_seed;
  options->sample_interval_s = FLAGS_interval_s;
  options->sessions = FLAGS_sessions;
  options->tension_drift_kn = FLAGS_tension_drift_kN;
  options->session_gap_s = FLAGS_session_gap_s;
  options->sensor_rezero_kn = FLAGS_sensor_rezero_kN;
  if (!FLAGS_start.empty()) {
    std::string why;
    if (!ParseTimeValue(FLAGS_start, 0, &options->start_time_s, &why)) {
      *error = "--start=" + internal::Quote(FLAGS_start) +
               ": give the first sample's time in s or ISO 8601 (2024-05-01T20:00:00Z): " + why;
      return false;
    }
  }
  for (const char* flag : {"session-gap-s", "sensor-rezero-kN"}) {
    if (FlagGiven(flag) && FLAGS_sessions < 2) {
      *error = std::string("--") + flag + " needs --sessions=N with N >= 2";
      return false;
    }
  }
  if (!SetStepsFromFlags(options, error) || !SetJointsFromFlags(options, error)) return false;
  options->method = StaticsMethod::kExact;
  if (FlagGiven("method") && !ParseStaticsMethod(FLAGS_method, &options->method)) {
    *error = "--method must be exact, aas-refined or aas, got " + internal::Quote(FLAGS_method);
    return false;
  }
  std::string why;
  if (!options->IsValid(&why)) {
    *error = WithFlagNames(why, {{"attitude_control_sigma_deg", "--attitude-control-deg"},
                                 {"attitude_measurement_sigma_deg", "--attitude-noise-deg"},
                                 {"position_measurement_sigma_m", "--position-noise-m"},
                                 {"tension_noise_percent", "--tension-noise-percent"},
                                 {"tension_noise_kn", "--tension-noise-kN"},
                                 {"outlier_fraction", "--outlier-fraction"},
                                 {"outlier_scale_percent", "--outlier-scale-percent"},
                                 {"density_mismatch_percent", "--density-mismatch-percent"},
                                 {"attitude_control_time_s", "--attitude-control-time-s"},
                                 {"tension_drift_percent", "--tension-drift-percent"},
                                 {"tension_drift_time_s", "--tension-drift-time-s"},
                                 {"mass_centre_drift_m", "--mass-centre-drift-m"},
                                 {"mass_centre_drift_time_s", "--mass-centre-drift-time-s"},
                                 {"sensor_gain_spread_percent", "--sensor-gain-spread-percent"},
                                 {"sensor_bias_spread_kn", "--sensor-bias-spread-kN"},
                                 {"length_offset_spread_m", "--length-offset-spread-m"},
                                 {"length_noise_m", "--length-noise-m"},
                                 {"sample_interval_s", "--interval-s"},
                                 {"sessions", "--sessions"},
                                 {"tension_drift_kn", "--tension-drift-kN"},
                                 {"session_gap_s", "--session-gap-s"},
                                 {"sensor_rezero_kn", "--sensor-rezero-kN"},
                                 {"start_time_s", "--start"},
                                 {"sensor_bias_steps", "--sensor-step"}});
    return false;
  }
  return true;
}

// Refuses a trajectory flag given for another trajectory than `trajectory` (or, for
// --tilt-fraction and --focal-centre, without the focal law): flags are never silently
// ignored. An unknown trajectory is left to BuildPoses to name.
bool CheckFlagsApplyToTrajectory(const std::string& trajectory, std::string* error) {
  if (trajectory == "circle") {
    for (const char* flag : {"centre", "radius", "start-deg", "end-deg"}) {
      if (FlagGiven(flag)) {
        *error = std::string("--") + flag +
                 ": --trajectory=circle (the default) is the paper's fixed circle; use "
                 "--trajectory=arc with --centre, --radius, --start-deg, --end-deg";
        return false;
      }
    }
  }
  const std::set<std::string> kinds = {"circle", "line", "arc", "grid", "random", "poses"};
  if (!kinds.count(trajectory)) return true;
  const bool focal_law =
      FLAGS_attitude_law == "focal" || (trajectory != "poses" && FLAGS_attitude_law != "none");
  const std::vector<FlagScope> scopes = TrajectoryFlagScopes(trajectory, focal_law);
  std::string mode = "--trajectory=" + trajectory;
  if (trajectory == "poses") mode = "--poses";
  if (trajectory == "circle" && !FlagGiven("trajectory")) mode += " (the default)";
  if (FlagGiven("attitude-law")) mode += " with --attitude-law=" + FLAGS_attitude_law;
  return CheckFlagsApply(scopes, mode, error);
}

// --trajectory=tracks (trajectory.h, SourceTrackSpec): --samples at --interval-s, sources
// tracked --track-minutes=MIN,MAX each on the cap to --max-off-axis-deg, a new one each
// --days' day.
bool SourceTracksFromFlags(const Eigen::Vector3d& focal_centre_m, PositionStream* positions,
                           std::string* error) {
  SourceTrackSpec spec;
  spec.samples = FLAGS_samples;
  spec.interval_s = FLAGS_interval_s;
  spec.max_off_axis_deg = FLAGS_max_off_axis_deg;
  spec.sphere.focal_centre_m = focal_centre_m;
  spec.sphere.focal_radius_m = FLAGS_focal_radius;
  spec.days = std::max(0, FLAGS_days);
  spec.seed = FLAGS_seed;
  std::vector<double> minutes;
  if (!ParseNumberList("track-minutes", FLAGS_track_minutes, &minutes, error)) return false;
  if (minutes.size() != 2) {
    *error = "--track-minutes takes MIN,MAX (minutes), got " + internal::Quote(FLAGS_track_minutes);
    return false;
  }
  if (!(minutes[0] > 0.0 && minutes[1] >= minutes[0])) {
    *error = "--track-minutes=MIN,MAX must satisfy 0 < MIN <= MAX (got " +
             internal::Quote(FLAGS_track_minutes) + ")";
    return false;
  }
  spec.min_track_s = 60.0 * minutes[0];
  spec.max_track_s = 60.0 * minutes[1];
  if (SourceTrackPositionStream(spec, positions, error)) return true;
  *error = "--trajectory=tracks: " +
           WithFlagNames(*error, {{"min_track_s and max_track_s", "--track-minutes"},
                                  {"max_off_axis_deg", "--max-off-axis-deg"},
                                  {"interval_s", "--interval-s"},
                                  {"samples", "--samples"},
                                  {"days", "--days"},
                                  {"sphere.focal_radius_m", "--focal-radius"}});
  return false;
}

// The flags --trajectory=tracks takes, of the trajectories' (CheckFlagsApplyToTrajectory).
bool CheckTrackFlags(const std::string& trajectory, std::string* error) {
  if (trajectory != "tracks") {
    if (FlagGiven("track-minutes")) {
      *error = "--track-minutes applies to --trajectory=tracks";
      return false;
    }
    return true;
  }
  for (const char* flag : {"nodes", "from", "to", "centre", "radius", "start-deg", "end-deg",
                           "off-axis-step-deg", "azimuth-step-deg", "radial-spread"}) {
    if (FlagGiven(flag)) {
      *error = std::string("--") + flag + " does not apply to --trajectory=tracks (it takes " +
               "--samples, --max-off-axis-deg, --focal-radius, --track-minutes, --seed)";
      return false;
    }
  }
  return true;
}

// A pose file's poses are the data's (the truth's measured frame's, measured_frame.h):
// the cabin's to fly follow from each row's joints, which a frame on a moving part needs.
bool CabinPosesOfFile(const CableRobot& truth, const std::vector<JointValues>& joints,
                      std::vector<Pose>* poses, std::string* error) {
  if (!truth.measured_frame.has_value()) return true;
  if (truth.measured_frame->part >= 0 && joints.empty()) {
    std::string names;
    for (const std::string& c : truth.moving_parts.JointColumns()) {
      names += (names.empty() ? "" : ",") + c;
    }
    *error = "--poses=" + FLAGS_poses +
             " gives the measured frame's poses (the truth model's cabin.measured_frame, on " +
             truth.moving_parts.parts[truth.measured_frame->part].name +
             "): the cabin's follow from the joints, so the file needs the joint columns (" +
             names + ")";
    return false;
  }
  for (size_t n = 0; n < poses->size(); ++n) {
    (*poses)[n] = truth.CabinPose((*poses)[n], joints.empty() ? JointValues{} : joints[n]);
  }
  return true;
}

// The poses to fly; from a pose file with the truth model's joint columns, their values
// per sample (*joints; else left empty).
bool BuildPoses(const CableRobot& truth, PoseStream* poses, std::vector<JointValues>* joints,
                std::string* error) {
  FocalAttitudeLaw law;
  law.tilt_fraction = FLAGS_tilt_fraction;
  if (!ParseVector3("focal-centre", FLAGS_focal_centre, &law.focal_centre_m, error)) return false;
  if (!(law.tilt_fraction >= 0.0 && law.tilt_fraction <= 1.0)) {
    *error = "--tilt-fraction must be in [0, 1] (got " + FormatDouble(law.tilt_fraction) + ")";
    return false;
  }
  if (FlagGiven("attitude-law") && FLAGS_attitude_law != "focal" && FLAGS_attitude_law != "none") {
    *error = "--attitude-law must be 'focal' or 'none', got " + internal::Quote(FLAGS_attitude_law);
    return false;
  }
  std::string trajectory = FlagGiven("trajectory") ? FLAGS_trajectory : "circle";
  if (!FLAGS_poses.empty() && !FlagGiven("trajectory")) trajectory = "poses";
  if ((trajectory == "poses") != !FLAGS_poses.empty()) {
    *error = "--trajectory=poses and --poses=FILE go together";
    return false;
  }
  if (!CheckFlagsApplyToTrajectory(trajectory, error) || !CheckTrackFlags(trajectory, error)) {
    return false;
  }

  if (trajectory == "poses") {
    std::vector<Pose> from_file;
    const std::vector<std::string> joint_columns = truth.moving_parts.JointColumns();
    if (!ReadPosesWithAttitudeLaw(FLAGS_poses, FLAGS_attitude_law, law, &from_file, error,
                                  &joint_columns, joints) ||
        !CabinPosesOfFile(truth, *joints, &from_file, error)) {
      return false;
    }
    *poses = StreamOf(std::move(from_file));
    return true;
  }

  PositionStream positions;
  if (trajectory == "tracks") {
    if (!SourceTracksFromFlags(law.focal_centre_m, &positions, error)) return false;
    return PosesFromPositions(positions, FLAGS_attitude_law != "none", law, poses, error);
  }
  bool known = false;
  const bool ok =
      TrajectoryPositionStreamFromFlags(trajectory, law.focal_centre_m, &positions, &known, error);
  if (!known) {
    *error = "--trajectory must be circle, line, arc, grid, random, tracks or poses, got " +
             internal::Quote(trajectory);
    return false;
  }
  if (!ok) {
    *error = "--trajectory=" + trajectory + ": " + WithTrajectoryFlagNames(*error);
    return false;
  }
  return PosesFromPositions(positions, FLAGS_attitude_law != "none", law, poses, error);
}

// FILE.csv -> FILE.truth.yaml; any other name gets ".truth.yaml" appended.
std::string TruthPathFor(const std::string& csv_path) {
  const std::string suffix = ".csv";
  const bool has_suffix =
      csv_path.size() > suffix.size() &&
      csv_path.compare(csv_path.size() - suffix.size(), suffix.size(), suffix) == 0;
  return (has_suffix ? csv_path.substr(0, csv_path.size() - suffix.size()) : csv_path) +
         ".truth.yaml";
}

// Streams the simulation into a temporary beside csv_path (memory independent of the
// number of samples), then writes the truth model (known only at the end: the
// mass centre's average) to a temporary beside yaml_path and renames both into place
// (over an existing file only with `replace`, --force: a file another run made meanwhile
// is kept) and syncs their directories; on failure removes whatever it wrote, so that
// neither file is left. *exit_code on failure: kExitFailure for a failed simulation or a
// failed write (the machine: a full disk), kExitUsage for a value the dataset cannot hold.
bool SimulateAndWrite(const CableRobot& truth, const PoseStream& poses,
                      const SimulationOptions& options, const std::string& csv_path,
                      const std::string& csv_header, const std::string& yaml_path,
                      const std::function<std::string(const SimulationSummary&)>& yaml_header,
                      bool replace, SimulationSummary* summary, int* exit_code,
                      std::string* error) {
  internal::RemoveStaleTemporaries(csv_path);  // what killed runs left (their pid gone)
  internal::RemoveStaleTemporaries(yaml_path);
  const std::string csv_tmp = internal::TemporaryNameFor(csv_path);
  *exit_code = kExitFailure;
  // The writer names its temporary: the user's file instead.
  const auto name_the_users_file = [&] {
    for (size_t at = error->find(csv_tmp); at != std::string::npos; at = error->find(csv_tmp)) {
      error->replace(at, csv_tmp.size(), csv_path);
    }
  };
  DatasetWriter writer;
  // A season's days are not surveys: no session column (a track cuts the data by time).
  const int labelled = FLAGS_days > 0 ? 1 : options.sessions;
  if (!writer.Open(csv_tmp, SimulatedDatasetLayout(labelled, truth.moving_parts.JointColumns()),
                   csv_header, error)) {
    name_the_users_file();
    return false;
  }
  bool write_failed = false;
  const SampleSink sink = [&](const Sample& sample, std::string* why) {
    write_failed = !writer.Write(sample, why);
    return !write_failed;
  };
  CableRobot truth_used;
  const bool simulated = SimulateStream(truth, poses, options, sink, &truth_used, summary, error);
  if (!simulated || !writer.Close(error)) {
    std::remove(csv_tmp.c_str());
    if (simulated || write_failed) {
      name_the_users_file();
      if (error->rfind(csv_path, 0) != 0) *error = "writing " + csv_path + ": " + *error;
      if (!writer.io_failed()) *exit_code = kExitUsage;
    }
    return false;
  }
  internal::AtomicFileWriter yaml;
  int err = 0;
  if (!yaml.Open(yaml_path, error) ||
      !yaml.Write(CableRobotToYaml(truth_used, yaml_header(*summary)), error) ||
      !yaml.Commit(replace, error)) {
    std::remove(csv_tmp.c_str());
    return false;
  }
  if (replace ? std::rename(csv_tmp.c_str(), csv_path.c_str()) != 0
              : !internal::RenameNoReplace(csv_tmp, csv_path, &err)) {
    if (replace) err = errno;
    std::remove(csv_tmp.c_str());
    std::remove(yaml_path.c_str());
    *error = csv_path + ": cannot move into place: " + std::strerror(err) +
             (err == EEXIST ? " (another run made it meanwhile; kept as it is)" : "");
    return false;
  }
  if (!internal::SyncDirectory(internal::ParentDirectory(csv_path), &err)) {
    *error = csv_path + ": written, but its directory cannot be synced: " + std::strerror(err);
    return false;
  }
  return true;
}

std::string Summary(const SimulationSummary& s, const SimulationOptions& options,
                    const std::string& csv_path, const std::string& yaml_path) {
  std::ostringstream out;
  out << "fastcal simulate: " << s.samples << " samples -> " << internal::Escape(csv_path)
      << ", truth model -> " << internal::Escape(yaml_path)
      << "\n  tension noise added, RMS per cable (kN):";
  for (double v : s.tension_noise_rms_n) out << " " << FormatDouble(v / kNPerKn, 4);
  out << "\n  tension noise added, RMS per cable (%):";
  for (double v : s.tension_noise_rms_relative) out << " " << FormatDouble(100.0 * v, 4);
  if (options.outlier_fraction > 0.0) {
    out << "\n  outliers per cable:";
    for (int n : s.outliers) out << " " << n;
  }
  out << "\n  attitude control error RMS " << FormatDouble(s.attitude_control_rms_deg, 4)
      << " deg, attitude noise RMS " << FormatDouble(s.attitude_measurement_rms_deg, 4)
      << " deg, position noise RMS " << FormatDouble(s.position_measurement_rms_m, 4) << " m";
  if (options.density_mismatch_percent > 0.0) {
    out << "\n  density factors:";
    for (double f : s.density_factor) out << " " << FormatDouble(f, 6);
  }
  if (options.tension_drift_percent > 0.0 || options.tension_drift_kn > 0.0) {
    out << "\n  slow tension error RMS per cable (%):";
    for (double v : s.tension_drift_rms_relative) out << " " << FormatDouble(100.0 * v, 4);
  }
  if (options.mass_centre_drift_m > 0.0) {
    out << "\n  mass centre drift RMS " << FormatDouble(s.mass_centre_drift_rms_m, 4)
        << " m per axis; average actual mass centre (" << FormatDouble(s.mass_centre_mean_m.x(), 6)
        << ", " << FormatDouble(s.mass_centre_mean_m.y(), 6) << ", "
        << FormatDouble(s.mass_centre_mean_m.z(), 6) << ") m";
  }
  if (options.length_offset_spread_m > 0.0 || options.length_noise_m > 0.0) {
    out << "\n  length-encoder offsets (m):";
    for (double v : s.length_offset_m) out << " " << FormatDouble(v, 4);
    out << "; length noise RMS per cable (m):";
    for (double v : s.length_noise_rms_m) out << " " << FormatDouble(v, 4);
  }
  if (s.redrawn > 0) out << "\n  " << s.redrawn << " noise draws redrawn (reading <= 0)";
  return out.str();
}

}  // namespace

int RunSimulate(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  for (const std::string& flag : kFlags) {
    const bool dynamics = SimulateDynamicsFlags().count(flag) > 0;
    // --segments is --vibration's too (the modes' segments).
    const bool shared = FLAGS_vibration && VibrationFlags().count(flag) > 0;
    if (FlagGiven(flag) && dynamics && !FLAGS_dynamics && !shared) {
      PrintError(kCommand, "--" + flag + " applies to --dynamics only");
      return kExitUsage;
    }
    if (dynamics && FLAGS_dynamics && !FLAGS_vibration) continue;
    const bool vibration = VibrationFlags().count(flag) > 0;
    if (FlagGiven(flag) && vibration != FLAGS_vibration && flag != "truth" && flag != "seed" &&
        flag != "out" && flag != "force" && flag != "attitude-law" && flag != "tilt-fraction" &&
        flag != "focal-centre" && flag != "interval-s" && flag != "position-noise-m" &&
        flag != "attitude-noise-deg" && flag != "tension-noise-kN") {
      PrintError(kCommand, "--" + flag +
                               (FLAGS_vibration ? " does not apply to --vibration"
                                                : " applies to --vibration only"));
      return kExitUsage;
    }
  }
  if (FLAGS_vibration) return RunSimulateVibration(argc, argv);
  if (FlagGiven("columns") && FLAGS_poses.empty()) {
    PrintError(kCommand, "--columns applies to --poses=FILE (a pose file read as exported)");
    return kExitUsage;
  }

  if (FLAGS_out.empty() || FLAGS_out == "-") {
    PrintError(kCommand, "give --out=FILE.csv (the truth model goes beside it)");
    return kExitUsage;
  }
  std::string error;
  if (!CheckCanWrite("out", FLAGS_out, FLAGS_force, &error) ||
      !CheckCanWrite("out", TruthPathFor(FLAGS_out), FLAGS_force, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  CableRobot truth;
  SimulationOptions options;
  PoseStream poses;
  if (!LoadTruth(&truth, &error) || !SetOptionsFromFlags(&options, &error) ||
      !BuildPoses(truth, &poses, &options.joints.given, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  if (!options.joints.given.empty() &&
      (FlagGiven("joint-law") || FlagGiven("joint-grid-deg") || FlagGiven("prismatic-spread-m"))) {
    PrintError(kCommand, "--poses=" + FLAGS_poses +
                             " gives the joint values (its joint columns): --joint-law, "
                             "--joint-grid-deg and --prismatic-spread-m cannot also set them");
    return kExitUsage;
  }
  if (poses.count == 0) {
    PrintError(kCommand, "no poses to simulate");
    return kExitUsage;
  }
  for (const char* flag : {"joint-law", "joint-grid-deg", "prismatic-spread-m"}) {
    if (truth.moving_parts.empty() && FlagGiven(flag)) {
      PrintError(kCommand, std::string("--") + flag +
                               " needs a truth model with moving parts (cabin.moving_parts, "
                               "--truth=MODEL.yaml)");
      return kExitUsage;
    }
  }
  {
    JointPlan plan;  // the plan's own checks (a law without a rotator), before any work
    if (!JointPlan::Make(truth.moving_parts, options.joints, &plan, &error)) {
      PrintError(kCommand, "--joint-law: " + error);
      return kExitUsage;
    }
  }
  if (!DaysFromFlags(poses.count, &options, &error) ||
      !StepsAtSessions(static_cast<int>(poses.count), &options, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  std::string flight_note;
  if (FLAGS_dynamics) {
    if (!SurveyFlightFromFlags(poses, &options, &flight_note, &error) || !options.IsValid(&error)) {
      PrintError(kCommand,
                 "--dynamics: " + WithFlagNames(error, {{"actual_source", "--dynamics"}}));
      return kExitUsage;
    }
    if (!truth.moving_parts.empty()) {
      PrintError(kCommand, "--dynamics: a truth model with moving parts is not flown in time");
      return kExitUsage;
    }
  }

  const std::string csv_path = FLAGS_out;
  const std::string yaml_path = TruthPathFor(csv_path);
  // Without --force: it changes nothing in the files, so a dataset regenerated with it
  // is the same bit for bit.
  const std::string command = CommandLine(argc, argv, {"force"});
  const std::string version = FASTCAL_VERSION;
  const std::string csv_header =
      "Simulated by fastcal " + version + "\n" + command + "\nTruth model: " + yaml_path;
  auto yaml_header = [&](const SimulationSummary& summary) {
    std::string header =
        "Truth model of " + csv_path + ", simulated by fastcal " + version + "\n" + command;
    if (options.mass_centre_drift_m > 0.0) {
      const Eigen::Vector3d& m = summary.mass_centre_mean_m;
      header += "\nThe mass centre drifted about mass_centre_m below (AR(1), sigma " +
                FormatDouble(options.mass_centre_drift_m) + " m per axis, correlation time " +
                FormatDouble(options.mass_centre_drift_time_s) +
                " s); its average over the samples was (" + FormatDouble(m.x(), 6) + ", " +
                FormatDouble(m.y(), 6) + ", " + FormatDouble(m.z(), 6) + ") m.";
    }
    // The steps, as simulate --help promises: the truth written out is before any of them.
    const TimeDisplay display = TimeDisplayFor(options.start_time_s, 0);
    for (const MassCentreStep& step : options.mass_centre_steps) {
      header += "\nMass centre step at " + TimeText(step.time_s, display) + ": (" +
                FormatDouble(step.shift_m.x(), 6) + ", " + FormatDouble(step.shift_m.y(), 6) +
                ", " + FormatDouble(step.shift_m.z(), 6) + ") m, added from then on";
    }
    for (const SensorBiasStep& step : options.sensor_bias_steps) {
      header += "\nSensor step at " + TimeText(step.time_s, display) + ": cable " +
                std::to_string(step.cable + 1) + "'s bias " + FormatDouble(step.shift_n / 1e3, 6) +
                " kN, added from then on";
    }
    if (summary.session_bias_n.size() > 1 && options.sensor_rezero_kn > 0.0) {
      header +=
          "\nSensors re-zeroed at each new session; the biases (kN) per session, cables "
          "1..6:";
      for (size_t k = 0; k < summary.session_bias_n.size(); ++k) {
        header += "\n  session " + std::to_string(k + 1) + ":";
        for (double b : summary.session_bias_n[k]) header += " " + FormatDouble(b / 1e3, 6);
      }
    }
    return header;
  };
  SimulationSummary summary;
  int failure_code = kExitFailure;
  if (!SimulateAndWrite(truth, poses, options, csv_path, csv_header, yaml_path, yaml_header,
                        FLAGS_force, &summary, &failure_code, &error)) {
    PrintError(kCommand, error);
    return failure_code;
  }
  // The summary of what was written is the result: stdout (docs/cli.md, "Output streams").
  std::cout << Summary(summary, options, csv_path, yaml_path)
            << (flight_note.empty() ? "" : "\n  " + flight_note) << std::endl;
  return 0;
}

}  // namespace fastcal::cli
