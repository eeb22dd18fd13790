// `fastcal modes`: the natural frequencies and modes of the cabin on its six sagging
// cables at one pose (modes.h), as CSV with a summary.
#include <gflags/gflags.h>

#include <chrono>
#include <iostream>
#include <sstream>

#include "cli_util.h"
#include "commands.h"
#include "fastcal/modes.h"

DECLARE_string(model);
DECLARE_string(position);
DECLARE_string(output);
DECLARE_bool(force);

DEFINE_int32(segments, fastcal::ModesOptions().segments,
             "modes: segments per cable (the lumped-mass chain's resolution).");
DEFINE_int32(modes, fastcal::ModesOptions().modes, "modes: how many of the lowest modes.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "modes";

const char kHelp[] =
    R"(fastcal modes: natural frequencies and modes of the cabin and its cables at a pose.

Usage:
  fastcal modes --position=X,Y,Z [--attitude-law=focal | --rpy=R,P,Y | --quat=W,X,Y,Z]
                [--model=FILE.yaml] [--segments=24] [--modes=20] [--output=modes.csv]

The system linearised about the exact static equilibrium of the pose (docs/model.md,
"Vibrations"): each cable a lumped-mass chain of --segments segments with its nodes on the
elastic catenary (axial stiffness EA/l0 and geometric T/l per segment; the tower end held,
the cabin end moving with the cabin's anchor), the cabin a rigid body with its mass,
mass centre and inertia (model key cabin.inertia_kg_m2; an assumed default otherwise),
with the load stiffness of gravity and the cable forces. No damping, no aerodynamics, no
bending stiffness; the winches are held. The default 24 segments put the 20 lowest
frequencies within 0.1% of the converged ones (docs/model.md gives the figures).

Pose: --position=X,Y,Z (m) of the cabin frame's origin; its attitude from
--attitude-law=focal (with --tilt-fraction=0.41, --focal-centre=0,0,300), --rpy=R,P,Y
(deg, R = Rz(yaw) Ry(pitch) Rx(roll)), --quat=W,X,Y,Z or --rotvec=X,Y,Z (rad); R = I
without one (as solve).
Model: --model=FILE.yaml (docs/model-format.md); default the nominal FAST model. A model
whose cables carry attachments is refused (not described yet).

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
)";

// clang-format off
const std::set<std::string> kFlags = {
    "model", "position", "attitude-law", "rpy", "quat", "rotvec", "tilt-fraction",
    "focal-centre", "segments", "modes", "output", "force"};
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

}  // namespace

int RunModes(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  std::string error;
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  if (FLAGS_force && !to_file) {
    PrintError(kCommand, "--force applies to --output=FILE");
    return kExitUsage;
  }
  if (to_file && !CheckCanWrite("output", FLAGS_output, FLAGS_force, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  CableRobot robot;
  Pose pose;
  std::string attitude;
  ModesOptions options;
  options.segments = FLAGS_segments;
  options.modes = FLAGS_modes;
  if (!LoadModelFlag("model", FLAGS_model, &robot, &error) ||
      !SinglePoseFromFlags(&pose, &attitude, &error) || !options.IsValid(&error)) {
    PrintError(kCommand, WithFlagNames(error, {{"segments", "--segments"}, {"modes", "--modes"}}));
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

}  // namespace fastcal::cli
