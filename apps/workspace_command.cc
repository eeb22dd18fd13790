// `fastcal workspace`: the feasible workspace over the focal-sphere cap for the focal
// attitude law and the limits given (workspace.h), as CSV and as an HTML map.
#include <gflags/gflags.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/internal/quote.h"
#include "fastcal/plausibility.h"
#include "fastcal/trajectory.h"
#include "fastcal/version.h"
#include "fastcal/workspace.h"

// Shared with solve (solve_command.cc).
DECLARE_string(joints);     // solve_command.cc
DECLARE_string(joint_law);  // simulate_command.cc

DEFINE_double(radial_offset, 0.0,
              "workspace: > 0 adds the grid this far (m) inside and outside the focal sphere.");
DEFINE_double(min_tension_kN, 0.0, "workspace: smallest lower-end tension allowed (kN).");
DEFINE_double(max_tension_kN, std::numeric_limits<double>::infinity(),
              "workspace: largest lower-end tension allowed (kN); inf: none.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "workspace";
// Its grid defaults, finer than solve's --trajectory=grid (the flags are shared).
constexpr double kOffAxisStepDeg = 1.0, kAzimuthStepDeg = 5.0;

const char kHelp[] =
    R"(fastcal workspace: where the cabin can go with every cable within limits.

Usage:
  fastcal workspace [--min-tension-kN=KN] [--max-tension-kN=KN] [--output=ws.csv]
                    [--html=ws.html] [options]

Solves every node of a grid on the focal-sphere cap at the focal attitude law and says
per node whether it is feasible: the statics hold the cabin there within the model's
range, clear of the reflector, with every cable's lower-end tension (what the cabin-side
sensors read, solve's T<i>_kN) within the limits. Otherwise the reason and the cable.

Grid (the focal-sphere cap, as solve --trajectory=grid, with finer defaults):
  --max-off-axis-deg=40 --off-axis-step-deg=1 --azimuth-step-deg=5 --focal-radius=160
  --focal-centre=0,0,300 (also the focal law's centre)
  --radial-offset=0       m; > 0 adds the same grid this far inside and outside the sphere
Attitude: the focal law, --tilt-fraction=0.41 (docs/model.md).
Limits:
  --min-tension-kN=0 --max-tension-kN=inf   lower-end tension, kN
  --max-strain=0.05 --max-length-ratio=1.5  the model's range (tension / EA, s0 / chord)
  --reflector-clearance=0                   m, how close a cable may come to the reflector
Statics: --method=exact (default), aas-refined or aas. Model: --model=FILE.yaml (default
the nominal FAST model, whose reflector is checked; docs/model-format.md).
Moving parts (a model with cabin.moving_parts): --joint-law=zero (default) or focal (the
rotator completes the tilt the cabin does not give, as the telescope flies; its mass
centre moves with it at every node), or --joints=v1,... for every node (the model's joint
order, deg and m). Prismatic joints at 0 under a law.

Output: CSV to stdout or --output=FILE.csv, one row per node: radial_offset_m,
off_axis_deg, azimuth_deg, x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg, status (feasible,
below_min_tension, above_max_tension, or the statics' code: no_equilibrium,
sagging_cable, overstretched_cable, reflector_contact, ...), cable (1-based),
min_tension_kN, min_tension_cable, max_tension_kN, max_tension_cable,
max_upper_tension_kN (the tower end), message (quoted). --html=FILE.html writes the map:
a polar plot of the cap per layer, colour = the smallest lower-end tension, a mark per
infeasible node for its reason. Files are written only when everything succeeded; an
existing one only with --force. A summary on stderr (on stdout with --output=FILE).

Examples:
  fastcal workspace --min-tension-kN=50 --max-tension-kN=500 --html=ws.html --output=ws.csv
  fastcal workspace --max-off-axis-deg=45 --radial-offset=5 --html=edge.html --output=edge.csv
)";

const std::set<std::string> kFlags = {"model",
                                      "method",
                                      "tilt-fraction",
                                      "focal-centre",
                                      "max-off-axis-deg",
                                      "off-axis-step-deg",
                                      "azimuth-step-deg",
                                      "focal-radius",
                                      "radial-offset",
                                      "min-tension-kN",
                                      "max-tension-kN",
                                      "max-strain",
                                      "max-length-ratio",
                                      "reflector-clearance",
                                      "output",
                                      "html",
                                      "force",
                                      "joints",
                                      "joint-law"};

// Every node, on each layer, where the cabin can be (the limits of solve's trajectories
// and of the data files): a focal radius of 1e6 m is a typo, not a map.
bool CheckGridPlausible(const WorkspaceOptions& o, std::string* error) {
  std::vector<Eigen::Vector3d> positions;
  if (!FocalSpherePositions(o.grid, &positions, error)) return true;  // IsValid said why
  const PlausibilityLimits limits;
  const double radius_m = o.grid.focal_radius_m;
  for (const Eigen::Vector3d& p : positions) {
    for (double offset_m : {-o.radial_offset_m, 0.0, o.radial_offset_m}) {
      const Eigen::Vector3d q =
          o.grid.focal_centre_m + (p - o.grid.focal_centre_m) * ((radius_m + offset_m) / radius_m);
      if (std::string why; !CheckPosition(q, limits, &why)) {
        *error =
            "--focal-radius, --focal-centre, --max-off-axis-deg and --radial-offset put a "
            "node at (" +
            FormatDouble(q[0]) + ", " + FormatDouble(q[1]) + ", " + FormatDouble(q[2]) +
            ") m: " + why;
        return false;
      }
    }
  }
  return true;
}

// "2881 nodes on the focal sphere: 2881 feasible, lower-end tensions 112.3 to 316 kN".
std::string Summary(const WorkspaceMap& map, const std::string& joints) {
  std::ostringstream s;
  s << "fastcal workspace: " << map.nodes.size() << " nodes" << joints;
  for (double offset_m : map.layers_m) {
    int nodes = 0, feasible = 0;
    double lo = HUGE_VAL, hi = 0.0;
    std::map<std::string, int> reasons;
    for (const WorkspaceNode& n : map.nodes) {
      if (n.radial_offset_m != offset_m) continue;
      ++nodes;
      if (n.verdict != WorkspaceVerdict::kFeasible) {
        ++reasons[WorkspaceNodeCode(n)];
        continue;
      }
      ++feasible;
      lo = std::min(lo, n.min_tension_n);
      hi = std::max(hi, n.max_tension_n);
    }
    s << "\n  " << (offset_m == 0.0 ? "on the sphere" : FormatDouble(offset_m) + " m off it")
      << ": " << feasible << " of " << nodes << " feasible";
    if (feasible > 0) {
      s << ", lower-end tensions " << FormatDouble(lo / kNPerKn, 4) << " to "
        << FormatDouble(hi / kNPerKn, 4) << " kN";
    }
    for (const auto& [code, count] : reasons) s << "; " << code << " " << count;
  }
  return s.str();
}

// --joints or --joint-law for a model with moving parts: the joints fixed in the model
// (MassCentreAtJointsFlag) or the law in the options; *said is the summary's words.
bool JointsFromFlags(CableRobot* robot, WorkspaceOptions* options, std::string* said,
                     std::string* error) {
  const bool law = FlagGiven("joint-law");
  if (law && !FLAGS_joints.empty()) {
    *error = "give --joints (every node's joints) or --joint-law, not both";
    return false;
  }
  if (law && robot->moving_parts.empty()) {
    *error = "--joint-law: the model has no moving parts (cabin.moving_parts, --model=MODEL.yaml)";
    return false;
  }
  if (law && (!ParseRevoluteLaw(FLAGS_joint_law, &options->joint_law) ||
              options->joint_law == RevoluteLaw::kGrid)) {
    *error = "--joint-law must be zero or focal, got " + internal::Quote(FLAGS_joint_law);
    return false;
  }
  const bool parts = !robot->moving_parts.empty();
  if (!MassCentreAtJointsFlag(FLAGS_joints, robot, error)) return false;
  if (!parts) return true;
  *said = !FLAGS_joints.empty() ? ", moving parts at --joints=" + FLAGS_joints
          : options->joint_law == RevoluteLaw::kFocal
              ? ", the rotator following the focal law"
              : ", moving parts at joints 0 (--joint-law=focal: as the telescope flies)";
  return true;
}

}  // namespace

bool WorkspaceOptionsFromFlags(WorkspaceOptions* o, std::string* error) {
  if (!ParseVector3("focal-centre", FLAGS_focal_centre, &o->grid.focal_centre_m, error)) {
    return false;
  }
  o->grid.max_off_axis_deg = FLAGS_max_off_axis_deg;
  o->grid.off_axis_step_deg =
      FlagGiven("off-axis-step-deg") ? FLAGS_off_axis_step_deg : kOffAxisStepDeg;
  o->grid.azimuth_step_deg =
      FlagGiven("azimuth-step-deg") ? FLAGS_azimuth_step_deg : kAzimuthStepDeg;
  o->grid.focal_radius_m = FLAGS_focal_radius;
  o->attitude_law.focal_centre_m = o->grid.focal_centre_m;
  o->attitude_law.tilt_fraction = FLAGS_tilt_fraction;
  o->radial_offset_m = FLAGS_radial_offset;
  // Checked here too, so that the message gives the flags' own numbers (kN).
  if (!(FLAGS_min_tension_kN >= 0.0) || !std::isfinite(FLAGS_min_tension_kN)) {
    *error =
        "--min-tension-kN must be >= 0 and finite (got " + FormatDouble(FLAGS_min_tension_kN) + ")";
    return false;
  }
  if (!(FLAGS_max_tension_kN > FLAGS_min_tension_kN)) {
    *error = "--max-tension-kN must be above --min-tension-kN (got " +
             FormatDouble(FLAGS_max_tension_kN) + " <= " + FormatDouble(FLAGS_min_tension_kN) + ")";
    return false;
  }
  o->min_tension_n = FLAGS_min_tension_kN * kNPerKn;
  o->max_tension_n = FLAGS_max_tension_kN * kNPerKn;
  if (!ParseStaticsMethod(FLAGS_method, &o->statics.method)) {
    *error = "--method must be exact, aas-refined or aas, got '" + FLAGS_method + "'";
    return false;
  }
  if (!ModelRangeFromFlags(&o->statics, error)) return false;
  if (o->IsValid(error)) return true;
  *error = WithGridFlagNames(*error, {{"radial_offset_m", "--radial-offset"},
                                      {"min_tension_n", "--min-tension-kN"},
                                      {"max_tension_n", "--max-tension-kN"}});
  return false;
}

std::string WithGridFlagNames(const std::string& message,
                              std::vector<std::pair<std::string, std::string>> more) {
  more.insert(more.end(), {{"grid.max_off_axis_deg", "--max-off-axis-deg"},
                           {"grid.off_axis_step_deg", "--off-axis-step-deg"},
                           {"grid.azimuth_step_deg", "--azimuth-step-deg"},
                           {"grid.focal_radius_m", "--focal-radius"},
                           {"grid.focal_centre_m", "--focal-centre"},
                           {"attitude_law.focal_centre_m", "--focal-centre"},
                           {"attitude_law.tilt_fraction", "--tilt-fraction"}});
  return WithFlagNames(WithTrajectoryFlagNames(message), more);
}

int RunWorkspace(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  std::string error;
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  if (FLAGS_force && !to_file && FLAGS_html.empty()) {
    PrintError(kCommand, "--force applies to --output=FILE or --html=FILE");
    return kExitUsage;
  }
  if (FLAGS_html == "-") {
    PrintError(kCommand,
               "--html=-: the map goes to a file; give its name (--output=- is the CSV "
               "on standard output)");
    return kExitUsage;
  }
  if (to_file && !FLAGS_html.empty() &&
      ResolveOutputPath(FLAGS_output) == ResolveOutputPath(FLAGS_html)) {
    PrintError(kCommand, "--output and --html name the same file; give two names");
    return kExitUsage;
  }
  if ((to_file && !CheckCanWrite("output", FLAGS_output, FLAGS_force, &error)) ||
      (!FLAGS_html.empty() && !CheckCanWrite("html", FLAGS_html, FLAGS_force, &error))) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  CableRobot robot;
  WorkspaceOptions options;
  std::string joints;  // the summary's words on the moving parts
  if (!LoadModelFlag("model", FLAGS_model, &robot, &error) ||
      !WorkspaceOptionsFromFlags(&options, &error) || !CheckGridPlausible(options, &error) ||
      !JointsFromFlags(&robot, &options, &joints, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  WorkspaceMap map;
  if (!ComputeWorkspace(robot, options, &map, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  const std::string command = CommandLine(argc, argv);
  std::vector<std::pair<std::string, std::string>> files;
  if (to_file) files.push_back({FLAGS_output, WorkspaceCsv(map)});
  if (!FLAGS_html.empty()) {
    files.push_back({FLAGS_html, WorkspaceHtml(map, robot, ModelName(FLAGS_model),
                                               "Made by fastcal " + std::string(FASTCAL_VERSION) +
                                                   ": " + command)});
  }
  // The outputs were checked before the work: a failure now is the machine's.
  if (!WriteOutputsTogether(files, FLAGS_force, &error) ||
      (!to_file && !WriteOutput("-", WorkspaceCsv(map), &error))) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  // stdout carries the result: the CSV itself, else the summary of what was written
  // (docs/cli.md, "Output streams").
  (to_file ? std::cout : std::cerr) << Summary(map, joints) << std::endl;
  return 0;
}

}  // namespace fastcal::cli
