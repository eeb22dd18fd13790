// `fastcal modes`: the natural frequencies and modes of the cabin on its six sagging
// cables at one pose (modes.h), as CSV with a summary.
#include <gflags/gflags.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <sstream>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/modes.h"
#include "fastcal/modes_map.h"
#include "fastcal/trajectory.h"
#include "fastcal/version.h"

DECLARE_string(joints);  // solve_command.cc

DEFINE_int32(modes, fastcal::ModesOptions().modes, "modes: how many of the lowest modes.");
DEFINE_bool(cap, false,
            "modes: over a grid on the focal-sphere cap (the focal law) instead of a pose.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "modes";

const char kHelp[] =
    R"(fastcal modes: natural frequencies and modes of the cabin and its cables at a pose.

Usage:
  fastcal modes --position=X,Y,Z [--attitude-law=focal | --rpy=R,P,Y | --quat=W,X,Y,Z]
                [--model=FILE.yaml] [--segments=48] [--modes=20] [--output=modes.csv]
  fastcal modes --cap [grid flags] [--output=cap.csv] [--html=cap.html]
  fastcal modes --data=RECORD.csv [--columns=MAP.yaml] [--identified-modes=3]
                [--identification=auto|era|ssi]

The system linearised about the exact static equilibrium of the pose (docs/model.md,
"Vibrations"): each cable a lumped-mass chain of --segments segments with its nodes on the
elastic catenary (axial stiffness EA/l0 and geometric T/l per segment; the tower end held,
the cabin end moving with the cabin's anchor), the cabin a rigid body with its mass,
mass centre and inertia (model key cabin.inertia_kg_m2; an assumed default otherwise),
with the load stiffness of gravity and the cable forces. No damping, no aerodynamics, no
bending stiffness; the winches are held. The default 48 segments put the 20 lowest
frequencies within 0.1% of the converged ones (docs/model.md gives the figures);
--segments from 2 to 1000 (memory and time grow linearly: 35 MB and 0.6 s at 1000),
--modes from 1 to 200.

Pose: --position=X,Y,Z (m) of the cabin frame's origin; its attitude from
--attitude-law=focal (with --tilt-fraction=0.41, --focal-centre=0,0,300), --rpy=R,P,Y
(deg, R = Rz(yaw) Ry(pitch) Rx(roll)), --quat=W,X,Y,Z or --rotvec=X,Y,Z (rad); R = I
without one (as solve).
Model: --model=FILE.yaml (docs/model-format.md); default the nominal FAST model. A model
whose cables carry attachments is refused (not described yet). A model with moving parts
(cabin.moving_parts) is linearised with its mass centre at --joints=v1,... (the model's
joint order, deg and m; default all 0); the parts' own inertia is in the cabin's.

Over the cap: --cap [--max-off-axis-deg=40 --off-axis-step-deg=5 --azimuth-step-deg=15
--focal-radius=160 --focal-centre=0,0,300 --tilt-fraction=0.41] [--html=PAGE.html]: the
modes at every node of the grid (193 by default) at the focal law; CSV one row per node
(off_axis_deg, azimuth_deg, x_m..yaw_deg, status ok|no_modes, lowest_hz,
lowest_cabin_share, first_cabin_mode and first_cabin_hz (the first mode whose energy is
over half the cabin's; empty when none of the --modes is), for each cabin motion x, y, z,
rx, ry, rz the frequency and share of the mode holding the most of it, message);
--html draws the lowest, the first cabin-dominated and the vertical mode's frequency as
polar maps of the cap, as workspace draws tensions.

Identified modes: --data=RECORD.csv (a dataset, docs/data-format.md, or an export read
through --columns=MAP.yaml), evenly sampled (e.g. inertial navigation at 1-100 Hz; a
sample at least every 0.5 s, 80 to 4000 s long, at most 10^6 samples): a free vibration
after a disturbance, its --identified-modes=3 (1 to 20) dominant modes by the eigensystem
realisation algorithm (ERA, Juang and Pappa 1985) with bootstrap sigmas; or an ambient
record (the cabin in the wind, ordinary operation), its most stable modes by
covariance-driven stochastic subspace identification (SSI-cov, Peeters and De Roeck 1999)
with jackknife sigmas (at least 8 x 100 s). --identification=auto (the default) takes ERA
when the record's envelope falls (its mean square 4x lower in the last quarter than in
the first: a free decay), SSI otherwise, and says which and why; era or ssi forces one.
Both use the pose (x, y, z, roll, pitch, yaw) and the tensions; each mode compared with the nearest
predicted mode at the record's mean pose, and the differences fitted by each parameter
alone (the cables' density, the cabin's mass, its inertia): the smallest chi2 is what they
point to. CSV: mode, frequency_hz, frequency_sigma_hz, damping_ratio, damping_sigma,
predicted_mode, predicted_hz, predicted_kind, difference_percent,
difference_sigma_percent, dlnf_dln_<parameter> (the predicted mode's sensitivity).

Output: CSV to stdout or --output=FILE.csv (written only on success; an existing file
only with --force), one row per mode, ascending:
  mode, frequency_hz, period_s
  share_x, share_y, share_z      the cabin's translation (of its mass centre, global axes)
  share_rx, share_ry, share_rz   its rotation about the global axes
  share_cables                   the six cables together
  dominant_cable, dominant_cable_share   the cable (1-6) with the most, and its share
  kind                           cabin (the cabin holds over half the energy) or cable
The shares split each mode's kinetic energy and sum to 1. A summary goes to stderr (to
stdout with --output=FILE). Exit 1 when the pose has no equilibrium or it is unstable.

Examples:
  fastcal modes --position=0,0,140 --output=zenith.csv
  fastcal modes --position=102.8,0,177.4 --attitude-law=focal --segments=40
  fastcal modes --cap --output=cap.csv --html=cap.html
)";

// clang-format off
const std::set<std::string> kFlags = {
    "model", "position", "attitude-law", "rpy", "quat", "rotvec", "tilt-fraction",
    "focal-centre", "segments", "modes", "output", "force", "cap", "max-off-axis-deg",
    "off-axis-step-deg", "azimuth-step-deg", "focal-radius", "html", "data", "columns",
    "identified-modes", "identification", "joints"};
// clang-format on

// "mode 4, 0.18208 Hz; cabin 56.5% (most z 56.5%), cables 43.5% (most cable 1 7.24%)".
std::string DescribeMode(int index, const Mode& m) {
  const char* kAxes[] = {"x", "y", "z", "rx", "ry", "rz"};
  Eigen::Matrix<double, 6, 1> shares;
  shares << m.cabin_translation_share, m.cabin_rotation_share;
  int axis = 0;
  shares.maxCoeff(&axis);
  return "mode " + std::to_string(index + 1) + ", " + FormatDouble(m.frequency_hz, 5) +
         " Hz; cabin " + FormatDouble(100 * m.CabinShare(), 3) + "% (most " + kAxes[axis] + " " +
         FormatDouble(100 * shares[axis], 3) + "%), cables " +
         FormatDouble(100 * m.cables_share, 3) + "% (most cable " +
         std::to_string(m.dominant_cable + 1) + " " +
         FormatDouble(100 * m.cable_share[m.dominant_cable], 3) + "%)";
}

// The size of the problem, the lowest mode and the first the cabin dominates (if any).
std::string Summary(const ModesResult& result, const std::string& attitude, int segments,
                    double seconds) {
  std::ostringstream s;
  s << "fastcal modes: " << result.modes.size() << " lowest of " << result.degrees_of_freedom
    << " degrees of freedom (" << segments << " segments per cable), " << attitude << ", "
    << FormatDouble(seconds, 3) << " s";
  if (result.modes.empty()) return s.str();
  s << "\n  lowest: " << DescribeMode(0, result.modes[0]);
  for (size_t i = 0; i < result.modes.size(); ++i) {
    if (result.modes[i].CabinShare() <= 0.5) continue;
    s << "\n  first cabin-dominated: " << DescribeMode(static_cast<int>(i), result.modes[i]);
    return s.str();
  }
  s << "\n  none of these is cabin-dominated (the cabin's share above 50%)";
  return s.str();
}

// The single pose's modes: CSV and summary. Returns the exit code.
int RunPose(const CableRobot& robot, const ModesOptions& options, bool to_file) {
  std::string error, attitude;
  Pose pose;
  if (!SinglePoseFromFlags(&pose, &attitude, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  const auto start = std::chrono::steady_clock::now();
  ModesResult result;
  if (!ComputeModes(robot, pose, options, &result, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The output was checked before the work: a failure now is the machine's.
  if (!WriteOutput(to_file ? FLAGS_output : "-", ModesCsv(result), &error, FLAGS_force)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  (to_file ? std::cout : std::cerr)
      << Summary(result, attitude, options.segments, seconds) << std::endl;
  return 0;
}

// --cap: the grid's options from the trajectory flags solve's grid uses.
bool CapOptionsFromFlags(const ModesOptions& modes, ModesMapOptions* o, std::string* error) {
  for (const char* flag : {"position", "rpy", "quat", "rotvec", "attitude-law"}) {
    if (FlagGiven(flag)) {
      *error =
          std::string("--") + flag + " is for one pose; --cap flies the focal law over the grid";
      return false;
    }
  }
  if (!ParseVector3("focal-centre", FLAGS_focal_centre, &o->grid.focal_centre_m, error)) {
    return false;
  }
  o->grid.max_off_axis_deg = FLAGS_max_off_axis_deg;
  o->grid.off_axis_step_deg = FLAGS_off_axis_step_deg;
  o->grid.azimuth_step_deg = FLAGS_azimuth_step_deg;
  o->grid.focal_radius_m = FLAGS_focal_radius;
  o->attitude_law.focal_centre_m = o->grid.focal_centre_m;
  o->attitude_law.tilt_fraction = FLAGS_tilt_fraction;
  o->modes = modes;
  if (o->IsValid(error)) return true;
  *error =
      WithGridFlagNames(*error, {{"modes.segments", "--segments"}, {"modes.modes", "--modes"}});
  return false;
}

// "193 nodes with modes of 193; lowest 0.138 to 0.155 Hz; ...".
std::string CapSummary(const ModesMap& map, double seconds) {
  int ok = 0, cabin = 0;
  double lo = HUGE_VAL, hi = 0.0, cabin_lo = HUGE_VAL, cabin_hi = 0.0;
  for (const ModesMapNode& n : map.nodes) {
    if (!n.ok) continue;
    ++ok;
    lo = std::min(lo, n.lowest_hz);
    hi = std::max(hi, n.lowest_hz);
    if (n.first_cabin_mode == 0) continue;
    ++cabin;
    cabin_lo = std::min(cabin_lo, n.first_cabin_hz);
    cabin_hi = std::max(cabin_hi, n.first_cabin_hz);
  }
  std::ostringstream s;
  s << "fastcal modes --cap: " << ok << " of " << map.nodes.size() << " nodes with modes, "
    << FormatDouble(seconds, 3) << " s";
  if (ok > 0) {
    s << "\n  lowest frequency " << FormatDouble(lo, 4) << " to " << FormatDouble(hi, 4) << " Hz";
    s << "\n  a cabin-dominated mode among the " << map.options.modes.modes << " lowest at "
      << cabin << " nodes";
    if (cabin > 0)
      s << ", " << FormatDouble(cabin_lo, 4) << " to " << FormatDouble(cabin_hi, 4) << " Hz";
  }
  return s.str();
}

// --cap: the map's CSV and, with --html, its page, written together.
int RunCap(int argc, char** argv, const CableRobot& robot, const ModesOptions& modes,
           bool to_file) {
  std::string error;
  ModesMapOptions options;
  if (!CapOptionsFromFlags(modes, &options, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  // Issue 59: seconds of silence read as a hang; say what is being done first.
  std::vector<Eigen::Vector3d> positions;
  if (FocalSpherePositions(options.grid, &positions, &error)) {
    std::cerr << "fastcal modes --cap: the " << options.modes.modes << " lowest modes at "
              << positions.size() << " nodes of the cap (" << options.modes.segments
              << " segments per cable; about 2 to 5 s for 193 nodes at 48 on 2 cores)..."
              << std::endl;
  }
  const auto start = std::chrono::steady_clock::now();
  ModesMap map;
  if (!ComputeModesMap(robot, options, &map, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<std::pair<std::string, std::string>> files;
  if (to_file) files.push_back({FLAGS_output, ModesMapCsv(map)});
  if (!FLAGS_html.empty()) {
    files.push_back({FLAGS_html, ModesMapHtml(map, robot, ModelName(FLAGS_model),
                                              "Made by fastcal " + std::string(FASTCAL_VERSION) +
                                                  ": " + CommandLine(argc, argv))});
  }
  if (!WriteOutputsTogether(files, FLAGS_force, &error) ||
      (!to_file && !WriteOutput("-", ModesMapCsv(map), &error))) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  (to_file ? std::cout : std::cerr) << CapSummary(map, seconds) << std::endl;
  return 0;
}

// Refuses outputs that cannot be written before any work.
bool CheckOutputs(std::string* error) {
  if (!FLAGS_html.empty() && !FLAGS_cap) {
    *error = "--html applies to --cap (the map of the cap)";
    return false;
  }
  return CheckRecordOutputs("html", FLAGS_html, error);
}

}  // namespace

int RunModes(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  std::string error;
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  CableRobot robot;
  ModesOptions options;
  options.segments = FLAGS_segments;
  options.modes = FLAGS_modes;
  if (!CheckOutputs(&error) || !LoadModelFlag("model", FLAGS_model, &robot, &error) ||
      !MassCentreAtJointsFlag(FLAGS_joints, &robot, &error) || !options.IsValid(&error)) {
    PrintError(kCommand, WithFlagNames(error, {{"segments", "--segments"}, {"modes", "--modes"}}));
    return kExitUsage;
  }
  if (!FLAGS_data.empty()) return RunModesIdentify(robot, options, to_file);
  return FLAGS_cap ? RunCap(argc, argv, robot, options, to_file) : RunPose(robot, options, to_file);
}

}  // namespace fastcal::cli
