// `fastcal solve`: cable forces, tensions and unstretched lengths for one pose or a
// trajectory, by AAS, refined AAS or the exact solver, or AAS against exact ("compare",
// the paper's Tables 2-5).
#include <gflags/gflags.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <regex>
#include <sstream>

#include "cli_util.h"
#include "columns_flag.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/cable_robot.h"
#include "fastcal/internal/csv.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/quote.h"
#include "fastcal/plausibility.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"
#include "fastcal/trajectory_plot.h"
#include "fastcal/version.h"

DEFINE_string(rotvec, "", "Attitude as rotation vector x,y,z (rad).");
DEFINE_string(format, "csv", "csv | json");
DEFINE_double(secant_low, 0.99, "AAS: low secant length as a fraction of the chord.");
DEFINE_double(secant_high, 1.01, "AAS: high secant length as a fraction of the chord.");
DEFINE_int32(max_refinement_steps, 8, "aas-refined: at most this many tangent steps.");
DEFINE_double(refined_tolerance, 1e-6,
              "aas-refined: steps stop when its tension error estimate is below this.");
DEFINE_double(aas_max_error, 0.01,
              "aas, compare: aas is ok only when its tension error estimate is at most this.");
DEFINE_double(exact_tolerance, 1e-12, "exact: relative tolerance on the tensions.");
DEFINE_string(plot, "", "solve: the tensions along a trajectory as a self-contained HTML page.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "solve";

const char kHelp[] =
    R"(fastcal solve: cable forces of the FAST cable robot at a pose or along a trajectory.

Usage:
  fastcal solve --position=x,y,z [attitude] [options]
  fastcal solve --trajectory=circle|line|arc|grid|random [trajectory flags] [options]
  fastcal solve --poses=FILE.csv [options]

Each flag belongs to a mode: a flag given for another one (--nodes with --position,
--radius with --trajectory=grid, --tilt-fraction without the focal law,
--max-refinement-steps with --method=exact, --force without --output) is an error naming
it and where it belongs (exit 2), never silently ignored; so is a flag given twice.

Attitude (at most one):
  --rpy=r,p,y            roll, pitch, yaw in degrees, R = Rz(yaw) Ry(pitch) Rx(roll)
  --quat=w,x,y,z         unit quaternion (normalised if within 1e-3 of unit)
  --rotvec=x,y,z         rotation vector in radians
  --attitude-law=focal   tilt z' toward the focal-sphere centre by --tilt-fraction (0.41)
                         of the off-axis angle (--focal-centre=0,0,300)
  --attitude-law=none    R = I, the neutral attitude
  With no attitude flag: one --position has R = I; a --trajectory flies the focal law
  (as the telescope does; --attitude-law=none gives R = I); a --poses file keeps its own
  attitudes (R = I without attitude columns). --rpy, --quat and --rotvec are for one
  --position only; --attitude-law=focal|none overrides a --poses file's attitudes.
  The summary line on stderr says which attitude was used.

Trajectories:
  circle  the paper's measured circle (its Table 6): radius 71.11 m about (0,0,156.73),
          a full turn, --nodes=360 (as simulate's default trajectory)
  line    --from=50,0,150 --to=-50,0,150 --nodes=101        (the paper's Table 4)
  arc     --centre=0,0,150 --radius=50 --start-deg=0 --end-deg=180 --nodes=101
          (Table 5; --end-deg=360 is a full circle without a repeated node)
  grid    focal-sphere cap: --max-off-axis-deg=40 --off-axis-step-deg=5
          --azimuth-step-deg=15 --focal-radius=160
  random  --samples=100 --seed=1 --max-off-axis-deg=40 --radial-spread=0
          (grid and random also use --focal-centre, the focal sphere's centre)
  --poses=FILE.csv  x_m,y_m,z_m and optionally roll_deg,pitch_deg,yaw_deg or qw,qx,qy,qz,
          time_s; a dataset's other columns (planned_*_deg, T<i>_kN, s0_<i>_m) are
          ignored, so a calibration dataset works; any other column is an error
  --columns=MAP.yaml  read --poses as exported, through a column map (x_m, y_m, z_m, the
          attitude and time as the map names them, in its units; docs/data-format.md,
          "Column maps")

Method (--method):
  exact        (default) the coupled Newton solution to --exact-tolerance=1e-12; where its
               start from AAS fails it follows the equilibrium from the home pose, so it
               finds the one the cabin reaches from there, and says when there is none
  aas          the paper's approximately analytical solution (secants at 0.99k, 1.01k);
               ok only when its own error estimate is at most --aas-max-error=0.01 (1%)
  aas-refined  AAS re-linearised on the exact Fz(Fl) tangent, step after step until its
               error estimate is below --refined-tolerance=1e-6, at most
               --max-refinement-steps=8 (one step where the cables are taut)
  compare      AAS and exact side by side with per-cable relative errors and their
               maxima over the trajectory (printed on stderr; in JSON as a field)
  --secant-low=0.99 --secant-high=1.01 (every method: exact starts from AAS)
  --warm-start (default true): each trajectory node starts from the previous solution
Every solution is checked before it is ok: each catenary's end conditions (the residual
is end_residual_m) and the cabin's equilibrium; the method's error estimate comes from
them (error_estimate_pct). Then the model's range: --max-strain=0.05 (tension / EA),
--max-length-ratio=1.5 (s0 / chord) and --reflector-clearance=0 (m, how close a cable
may come to the model's reflector).

Model: --model=FILE.yaml (docs/model-format.md); default the nominal FAST model. solve
reports the model's true cable tensions: a model's sensor_gain and sensor_bias_kN are
not applied here (they are in evaluate and calibrate, which compare with readings). A
model with moving parts (cabin.moving_parts) solves every pose with its joints at
--joints=v1,... (the model's joint order, in the columns' units: deg and m; the mass
centre then follows, docs/model.md "Moving parts"); default all 0. A --poses file may
carry the model's joint columns instead (rotator_a_deg, ...: all or none), each pose then
solved at its own joints; --joints beside them is refused.

Output: CSV (default) or --format=json, to stdout or --output=FILE (written only when
everything succeeded; an existing FILE is refused unless --force, which needs --output).
Poses are solved and written one at a time: memory does not grow with their number
(about 13 MB); --output streams into a temporary beside FILE, renamed at the end, and
stdout is held back until the end (in memory up to 64 MiB, beyond that in an unnamed
file in $TMPDIR, else /tmp), so that a failed run leaves nothing on either.
CSV columns, units in the names:
  node,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,status,
  T1_kN..T6_kN            lower-end tensions (what the cabin-side sensors measure)
  T1_upper_kN..           upper-end (tower) tensions
  s0_1_m..s0_6_m          unstretched lengths
  F1x_kN,F1y_kN,F1z_kN..  force on each cable at its lower end, global frame (the cabin
                          feels the opposite)
  force_residual_N,moment_residual_Nm   equilibrium residual of the returned forces
  end_residual_m          largest distance between a cable's computed upper end and its
                          tower top (the catenaries' end conditions)
  error_estimate_pct      the method's estimate of its largest tension error, %
  equilibrium             exact: which equilibrium, where sagging cables allow several:
                          taut (the only one this taut), home (followed from the home
                          pose), several (others were met: this is the home pose's),
                          unreachable (none from the home pose, yet one exists); empty
                          for aas (docs/model.md, "Which equilibrium exact returns")
  message                 why a pose failed, in double quotes ("" when ok)
  status is a short code, one of:
@STATUSES@
  (what each means: docs/cli.md, "fastcal solve").
  compare: T<i>_aas_kN, T<i>_exact_kN, err<i>_pct = 100 (aas - exact)/exact,
  aas_error_estimate_pct, equilibrium (exact's), message.
A summary line on stderr names the model (its file, or "nominal FAST"), the attitude
used and the time per pose.

Plot: --plot=FILE.html (a trajectory or --poses) writes the six lower-end tensions along
the path, against the distance travelled (node number for grid and random), as the
paper's Figs. 9 and 10; with --method=compare AAS and exact side by side and AAS's
relative error per cable. A self-contained page (no scripts), written with the output.

A pose the cables cannot hold (no equilibrium, or one outside the model's range), a
vertical cable or a solver failure is an error naming the node, the cable and the
numbers (exit 1, no output) unless --keep-going, which writes the row with its status,
its message and empty numbers and exits 0; the summary then says how many poses failed,
as in 289 poses (69 failed), and names the first.

Examples:
  fastcal solve --position=0,0,140 --method=compare
  fastcal solve --position=42.65,33.73,149.52 --attitude-law=focal --method=exact
  fastcal solve --trajectory=arc --attitude-law=focal --method=compare --output=arc.csv
  fastcal solve --trajectory=line --method=compare --output=line.csv --plot=line.html
)";

// kHelp with the status codes listed from the library (StaticsStatusName), so that a
// status added there is never missing here.
std::string Help() {
  constexpr size_t kWidth = 88;
  const int last = static_cast<int>(kLastStaticsStatus);
  std::string codes, line = "   ";
  for (int s = 0; s <= last; ++s) {
    const std::string item =
        std::string(" ") + StaticsStatusName(static_cast<StaticsStatus>(s)) + (s < last ? "," : "");
    if (line.size() + item.size() > kWidth) {
      codes += line + "\n";
      line = "   ";
    }
    line += item;
  }
  std::string help = kHelp;
  const std::string placeholder = "@STATUSES@";
  help.replace(help.find(placeholder), placeholder.size(), codes + line);
  return help;
}

const std::set<std::string> kFlags = {"model",
                                      "joints",
                                      "columns",
                                      "method",
                                      "position",
                                      "rpy",
                                      "quat",
                                      "rotvec",
                                      "attitude-law",
                                      "tilt-fraction",
                                      "focal-centre",
                                      "trajectory",
                                      "from",
                                      "to",
                                      "nodes",
                                      "centre",
                                      "radius",
                                      "start-deg",
                                      "end-deg",
                                      "max-off-axis-deg",
                                      "off-axis-step-deg",
                                      "azimuth-step-deg",
                                      "focal-radius",
                                      "samples",
                                      "seed",
                                      "radial-spread",
                                      "poses",
                                      "format",
                                      "output",
                                      "force",
                                      "secant-low",
                                      "secant-high",
                                      "max-refinement-steps",
                                      "refined-tolerance",
                                      "aas-max-error",
                                      "exact-tolerance",
                                      "max-strain",
                                      "max-length-ratio",
                                      "reflector-clearance",
                                      "warm-start",
                                      "keep-going",
                                      "plot"};

// The trajectory generators' parameter names (trajectory.h) and the flags that set them.
const std::vector<std::pair<std::string, std::string>> kTrajectoryFlagNames = {
    {"nodes", "--nodes"},
    {"from_m", "--from"},
    {"to_m", "--to"},
    {"centre_m", "--centre"},
    {"radius_m", "--radius"},
    {"start_deg", "--start-deg"},
    {"end_deg", "--end-deg"},
    {"max_off_axis_deg", "--max-off-axis-deg"},
    {"off_axis_step_deg", "--off-axis-step-deg"},
    {"azimuth_step_deg", "--azimuth-step-deg"},
    {"focal_centre_m", "--focal-centre"},
    {"sphere.focal_centre_m", "--focal-centre"},
    {"focal_radius_m", "--focal-radius"},
    {"sphere.focal_radius_m", "--focal-radius"},
    {"samples", "--samples"},
    {"radial_spread_m", "--radial-spread"}};

// The trajectory kinds whose generator uses each flag (TrajectoryPositionsFromFlags).
const std::vector<std::pair<std::string, std::vector<std::string>>> kTrajectoryFlagKinds = {
    {"from", {"line"}},
    {"to", {"line"}},
    {"nodes", {"line", "arc"}},
    {"centre", {"arc"}},
    {"radius", {"arc"}},
    {"start-deg", {"arc"}},
    {"end-deg", {"arc"}},
    {"max-off-axis-deg", {"grid", "random"}},
    {"off-axis-step-deg", {"grid"}},
    {"azimuth-step-deg", {"grid"}},
    {"focal-radius", {"grid", "random"}},
    {"samples", {"random"}},
    {"radial-spread", {"random"}}};

}  // namespace

std::vector<FlagScope> TrajectoryFlagScopes(const std::string& kind, bool focal_law) {
  std::vector<FlagScope> scopes;
  for (auto [flag, kinds] : kTrajectoryFlagKinds) {
    if (flag == "nodes") kinds.push_back("circle");
    FlagScope scope{flag, false, "--trajectory="};
    for (size_t i = 0; i < kinds.size(); ++i) {
      scope.applies = scope.applies || kinds[i] == kind;
      scope.belongs_to += (i == 0 ? "" : i + 1 < kinds.size() ? ", " : " or ") + kinds[i];
    }
    scopes.push_back(scope);
  }
  const std::string law =
      "the focal attitude law (--attitude-law=focal, the default for trajectories)";
  scopes.push_back({"tilt-fraction", focal_law, law});
  scopes.push_back({"focal-centre", focal_law || kind == "grid" || kind == "random",
                    law + " and --trajectory=grid or random"});
  return scopes;
}

std::string WithTrajectoryFlagNames(const std::string& message) {
  return WithFlagNames(message, kTrajectoryFlagNames);
}

bool PosesWithFocalLawFromFlags(const std::vector<Eigen::Vector3d>& positions,
                                const FocalAttitudeLaw& law, std::vector<Pose>* poses,
                                std::string* error) {
  if (PosesWithAttitudeLaw(positions, law, poses, error)) return true;
  *error = "focal attitude law: " +
           std::regex_replace(WithFlagNames(*error, {{"law.focal_centre_m", "--focal-centre"},
                                                     {"law.tilt_fraction", "--tilt-fraction"}}),
                              std::regex(R"(positions\[([0-9]+)\])"), "node $1") +
           "; --attitude-law=none gives R = I";
  return false;
}

bool ReadPosesWithAttitudeLaw(const std::string& path, const std::string& attitude_law,
                              const FocalAttitudeLaw& law, std::vector<Pose>* poses,
                              std::string* error, const std::vector<std::string>* joint_columns,
                              std::vector<JointValues>* joints) {
  std::shared_ptr<const ColumnMap> columns;  // --columns: the file as exported
  if (!ColumnsFromFlag(&columns, error)) return false;
  if (joints != nullptr) joints->clear();
  const bool with_joints = joint_columns != nullptr && !joint_columns->empty() && joints != nullptr;
  const bool read =
      columns != nullptr
          ? (with_joints
                 ? ReadPosesCsv(path, *columns, *joint_columns, poses, joints, nullptr, error)
                 : ReadPosesCsv(path, *columns, poses, nullptr, error))
      : with_joints ? ReadPosesCsv(path, *joint_columns, poses, joints, nullptr, error)
                    : ReadPosesCsv(path, poses, nullptr, error);
  if (!read) {
    return false;
  }
  if (attitude_law == "focal") {
    std::vector<Eigen::Vector3d> positions;
    for (const Pose& p : *poses) positions.push_back(p.position_m);
    return PosesWithFocalLawFromFlags(positions, law, poses, error);
  }
  if (attitude_law == "none") {
    for (Pose& p : *poses) p.rotation.setIdentity();
  }
  return true;
}

namespace {

bool GenerateTrajectoryStream(const std::string& kind, const Eigen::Vector3d& focal_centre_m,
                              PositionStream* stream, bool* known, std::string* error) {
  *known = true;
  if (kind == "circle") {
    // The paper's measured circle (trajectory.h), 360 nodes unless --nodes says otherwise.
    ArcSpec circle = PaperCircleArc();
    if (FlagGiven("nodes")) circle.nodes = FLAGS_nodes;
    return ArcPositionStream(circle, stream, error);
  }
  if (kind == "line") {
    Eigen::Vector3d from, to;
    return ParsePosition("from", FLAGS_from, &from, error) &&
           ParsePosition("to", FLAGS_to, &to, error) &&
           LinePositionStream(from, to, FLAGS_nodes, stream, error);
  }
  if (kind == "arc") {
    ArcSpec arc;
    arc.radius_m = FLAGS_radius;
    arc.start_deg = FLAGS_start_deg;
    arc.end_deg = FLAGS_end_deg;
    arc.nodes = FLAGS_nodes;
    return ParseVector3("centre", FLAGS_centre, &arc.centre_m, error) &&
           ArcPositionStream(arc, stream, error);
  }
  if (kind == "grid") {
    FocalGridSpec grid;
    grid.max_off_axis_deg = FLAGS_max_off_axis_deg;
    grid.off_axis_step_deg = FLAGS_off_axis_step_deg;
    grid.azimuth_step_deg = FLAGS_azimuth_step_deg;
    grid.focal_centre_m = focal_centre_m;
    grid.focal_radius_m = FLAGS_focal_radius;
    auto positions = std::make_shared<std::vector<Eigen::Vector3d>>();
    if (!FocalSpherePositions(grid, positions.get(), error)) return false;
    stream->count = static_cast<long long>(positions->size());
    stream->next = [positions, k = size_t{0}]() mutable { return (*positions)[k++]; };
    return true;
  }
  if (kind == "random") {
    RandomWorkspaceSpec spec;
    spec.samples = FLAGS_samples;
    spec.max_off_axis_deg = FLAGS_max_off_axis_deg;
    spec.radial_spread_m = FLAGS_radial_spread;
    spec.sphere.focal_centre_m = focal_centre_m;
    spec.sphere.focal_radius_m = FLAGS_focal_radius;
    spec.seed = FLAGS_seed;
    return RandomWorkspacePositionStream(spec, stream, error);
  }
  *known = false;
  return false;
}

}  // namespace

bool TrajectoryPositionStreamFromFlags(const std::string& kind,
                                       const Eigen::Vector3d& focal_centre_m,
                                       PositionStream* stream, bool* known, std::string* error) {
  if (!GenerateTrajectoryStream(kind, focal_centre_m, stream, known, error)) return false;
  // Every node within the limits a dataset's positions obey (an arc of radius 1e6 m),
  // checked on a copy of the stream, which leaves the original at its start.
  const PlausibilityLimits limits;
  PositionStream check = *stream;
  for (long long n = 0; n < check.count; ++n) {
    const Eigen::Vector3d p = check.next();
    if (std::string why; !CheckPosition(p, limits, &why)) {
      *error = "node " + std::to_string(n) + " at position (" + FormatDouble(p[0]) + ", " +
               FormatDouble(p[1]) + ", " + FormatDouble(p[2]) + ") m: " + why;
      return false;
    }
  }
  return true;
}

bool TrajectoryPositionsFromFlags(const std::string& kind, const Eigen::Vector3d& focal_centre_m,
                                  std::vector<Eigen::Vector3d>* positions, bool* known,
                                  std::string* error) {
  PositionStream stream;
  if (!TrajectoryPositionStreamFromFlags(kind, focal_centre_m, &stream, known, error)) return false;
  positions->clear();
  positions->reserve(static_cast<size_t>(stream.count));
  for (long long n = 0; n < stream.count; ++n) positions->push_back(stream.next());
  return true;
}

// Poses held in memory (a --poses file: bounded by its size), as a stream.
PoseStream StreamOf(std::vector<Pose> poses) {
  auto held = std::make_shared<std::vector<Pose>>(std::move(poses));
  PoseStream stream;
  stream.count = static_cast<long long>(held->size());
  stream.next = [held, n = size_t{0}]() mutable { return (*held)[n++]; };
  return stream;
}

// The poses of a generated trajectory, made as they are used: the positions' stream with
// the attitude law applied to each. Checked first on a copy of the stream (no pose kept);
// a position the law cannot take is named as PosesWithFocalLawFromFlags names it, from
// the whole list, made only then.
bool PosesFromPositions(const PositionStream& positions, bool focal, const FocalAttitudeLaw& law,
                        PoseStream* poses, std::string* error) {
  if (focal) {
    PositionStream check = positions;
    std::vector<Pose> one;
    for (long long n = 0; n < check.count; ++n) {
      if (PosesWithFocalLawFromFlags({check.next()}, law, &one, error)) continue;
      std::vector<Eigen::Vector3d> all;
      PositionStream again = positions;
      for (long long k = 0; k < again.count; ++k) all.push_back(again.next());
      return PosesWithFocalLawFromFlags(all, law, &one, error);
    }
  }
  poses->count = positions.count;
  poses->next = [positions, focal, law]() mutable {
    Pose pose;
    pose.position_m = positions.next();
    pose.rotation = focal ? FocalAttitude(pose.position_m, law) : Eigen::Matrix3d::Identity();
    return pose;
  };
  return true;
}

namespace {

// "focal law (tilt fraction 0.41, focal centre 0,0,300 m)", for the summary line.
std::string FocalLawDescription(const FocalAttitudeLaw& law) {
  const Eigen::Vector3d& c = law.focal_centre_m;
  return "focal law (tilt fraction " + FormatDouble(law.tilt_fraction) + ", focal centre " +
         FormatDouble(c[0]) + "," + FormatDouble(c[1]) + "," + FormatDouble(c[2]) + " m)";
}

// The attitude flags shared by every kind of pose: the focal law's parameters, and at
// most one of --rpy, --quat, --rotvec, --attitude-law.
bool AttitudeLawFromFlags(FocalAttitudeLaw* law, std::string* error) {
  law->tilt_fraction = FLAGS_tilt_fraction;
  if (!ParseVector3("focal-centre", FLAGS_focal_centre, &law->focal_centre_m, error)) return false;
  if (!std::isfinite(law->tilt_fraction)) {
    *error = "--tilt-fraction must be finite";
    return false;
  }
  if (!FLAGS_attitude_law.empty() && FLAGS_attitude_law != "focal" &&
      FLAGS_attitude_law != "none") {
    *error = "--attitude-law must be 'focal' or 'none', got " + internal::Quote(FLAGS_attitude_law);
    return false;
  }
  const int constant_attitudes = !FLAGS_rpy.empty() + !FLAGS_quat.empty() + !FLAGS_rotvec.empty() +
                                 !FLAGS_attitude_law.empty();
  if (constant_attitudes > 1) {
    *error = "give at most one of --rpy, --quat, --rotvec, --attitude-law";
    return false;
  }
  return true;
}

constexpr char kIdentityByFlag[] = "R = I (--attitude-law=none)";

// --poses=FILE: its poses, their attitudes replaced only by --attitude-law.
bool PosesFromFile(const FocalAttitudeLaw& law, const MovingParts& parts, PoseStream* poses,
                   std::vector<JointValues>* joints, std::string* attitude, std::string* error) {
  if (FLAGS_trajectory != "point" || !FLAGS_position.empty()) {
    *error = "--poses cannot be combined with --position or --trajectory";
    return false;
  }
  if (!FLAGS_rpy.empty() || !FLAGS_quat.empty() || !FLAGS_rotvec.empty()) {
    *error = "--poses brings its own attitudes; only --attitude-law=focal|none may override them";
    return false;
  }
  *attitude = FLAGS_attitude_law == "focal" ? FocalLawDescription(law)
              : FLAGS_attitude_law == "none"
                  ? std::string(kIdentityByFlag)
                  : "as in " + FLAGS_poses + " (R = I if it has no attitude columns)";
  std::vector<Pose> from_file;
  const std::vector<std::string> joint_columns = parts.JointColumns();
  if (!ReadPosesWithAttitudeLaw(FLAGS_poses, FLAGS_attitude_law, law, &from_file, error,
                                &joint_columns, joints)) {
    return false;
  }
  if (!joints->empty() && !FLAGS_joints.empty()) {
    *error =
        FLAGS_poses + " brings its own joint values (the model's joint columns): drop --joints";
    return false;
  }
  *poses = StreamOf(std::move(from_file));
  return true;
}

// The rotation of a single --position from --rpy, --quat or --rotvec; false with
// *attitude untouched when none of them is given.
bool ConstantRotationFromFlags(Eigen::Matrix3d* rotation, std::string* attitude,
                               std::string* error) {
  if (!FLAGS_rpy.empty()) {
    Eigen::Vector3d rpy;
    if (!ParseRpyDeg("rpy", FLAGS_rpy, &rpy, error)) return false;
    *rotation = RotationFromRpyDeg(rpy[0], rpy[1], rpy[2]);
    *attitude = "--rpy=" + FLAGS_rpy + " deg";
  } else if (!FLAGS_quat.empty()) {
    Eigen::Vector4d q;
    if (!ParseVector4("quat", FLAGS_quat, &q, error)) return false;
    std::string why;
    if (!RotationFromQuaternion(q[0], q[1], q[2], q[3], rotation, &why)) {
      *error = "--quat: " + why;
      return false;
    }
    *attitude = "--quat=" + FLAGS_quat;
  } else if (!FLAGS_rotvec.empty()) {
    Eigen::Vector3d v;
    std::string why;
    if (!ParseVector3("rotvec", FLAGS_rotvec, &v, error)) return false;
    if (!CheckRotationVector(v, PlausibilityLimits(), &why)) {
      *error = "--rotvec=" + FLAGS_rotvec + ": " + why;
      return false;
    }
    *rotation = RotationFromRotationVector(v);
    *attitude = "--rotvec=" + FLAGS_rotvec + " rad";
  }
  return true;
}

// --position=x,y,z with its attitude flag (R = I without one).
bool SinglePose(const FocalAttitudeLaw& law, PoseStream* poses, std::string* attitude,
                std::string* error) {
  if (FLAGS_position.empty()) {
    *error = "give --position=x,y,z, a --trajectory or --poses (see fastcal solve --help)";
    return false;
  }
  Pose pose;
  if (!ParsePosition("position", FLAGS_position, &pose.position_m, error)) return false;
  if (FLAGS_attitude_law == "focal") {
    std::vector<Pose> one;
    if (!PosesWithFocalLawFromFlags({pose.position_m}, law, &one, error)) return false;
    *attitude = FocalLawDescription(law);
    *poses = StreamOf(std::move(one));
    return true;
  }
  *attitude = FLAGS_attitude_law == "none" ? kIdentityByFlag : "R = I (no attitude flag)";
  if (!ConstantRotationFromFlags(&pose.rotation, attitude, error)) return false;
  *poses = StreamOf({pose});
  return true;
}

// --trajectory=line|arc|grid|random, flying the focal law unless --attitude-law=none.
// The poses are made as they are solved (PosesFromPositions): none is held.
bool TrajectoryPoses(const FocalAttitudeLaw& law, PoseStream* poses, std::string* attitude,
                     std::string* error) {
  if (!FLAGS_position.empty()) {
    *error = "--position is for a single pose; drop it or --trajectory";
    return false;
  }
  if (!FLAGS_rpy.empty() || !FLAGS_quat.empty() || !FLAGS_rotvec.empty()) {
    *error =
        "--rpy, --quat and --rotvec are for one --position; a trajectory flies the focal "
        "attitude law (the default) or, with --attitude-law=none, R = I";
    return false;
  }
  PositionStream positions;
  bool known = false;
  const bool ok = TrajectoryPositionStreamFromFlags(FLAGS_trajectory, law.focal_centre_m,
                                                    &positions, &known, error);
  if (!known) {
    *error = "--trajectory must be point, circle, line, arc, grid or random, got " +
             internal::Quote(FLAGS_trajectory);
    return false;
  }
  if (!ok) {
    *error = "--trajectory=" + FLAGS_trajectory + ": " + WithTrajectoryFlagNames(*error);
    return false;
  }
  // Trajectories fly the focal law unless told otherwise: that is how the telescope
  // moves, and what the paper's Tables 4 and 5 use.
  const bool focal = FLAGS_attitude_law != "none";
  *attitude = !focal ? std::string(kIdentityByFlag)
                     : FocalLawDescription(law) +
                           (FLAGS_attitude_law == "focal" ? "" : ", the default for trajectories");
  return PosesFromPositions(positions, focal, law, poses, error);
}

// The poses to solve from the pose, trajectory and attitude flags; *attitude says in words
// which attitude they have (for the summary line).
// A --poses file with the model's joint columns fills *joints, one per pose; otherwise it
// is left empty (the joints of --joints, or all 0, are already in the model).
bool BuildPoses(const MovingParts& parts, PoseStream* poses, std::vector<JointValues>* joints,
                std::string* attitude, std::string* error) {
  FocalAttitudeLaw law;
  joints->clear();
  if (!AttitudeLawFromFlags(&law, error)) return false;
  if (!FLAGS_poses.empty()) return PosesFromFile(law, parts, poses, joints, attitude, error);
  if (FLAGS_trajectory == "point") return SinglePose(law, poses, attitude, error);
  return TrajectoryPoses(law, poses, attitude, error);
}

// Refuses a flag given for another mode than this command line's (a trajectory's
// parameters, the focal law's, a method's, --force without --output): flags are never
// silently ignored. An unknown mode is left to BuildPoses to name.
bool CheckFlagsApplyToMode(std::string* error) {
  const std::string kind = !FLAGS_poses.empty() ? "poses" : FLAGS_trajectory;
  const bool generated =
      kind == "circle" || kind == "line" || kind == "arc" || kind == "grid" || kind == "random";
  if (!generated && kind != "poses" && !(kind == "point" && !FLAGS_position.empty())) return true;
  const bool focal_law =
      FLAGS_attitude_law == "focal" || (generated && FLAGS_attitude_law != "none");
  std::vector<FlagScope> scopes = TrajectoryFlagScopes(kind, focal_law);
  scopes.push_back({"seed", kind == "random", "--trajectory=random"});
  std::string mode = kind == "point"   ? "a single --position"
                     : kind == "poses" ? "--poses"
                                       : "--trajectory=" + kind;
  if (FlagGiven("attitude-law")) mode += " with --attitude-law=" + FLAGS_attitude_law;
  const bool exact = FLAGS_method == "exact" || FLAGS_method == "compare";
  const std::vector<FlagScope> method_scopes = {
      {"max-refinement-steps", FLAGS_method == "aas-refined", "--method=aas-refined"},
      {"refined-tolerance", FLAGS_method == "aas-refined", "--method=aas-refined"},
      {"aas-max-error", FLAGS_method == "aas" || FLAGS_method == "compare",
       "--method=aas or compare"},
      {"exact-tolerance", exact, "--method=exact (the default) or compare"}};
  scopes.push_back({"plot", kind != "point", "a --trajectory or --poses"});
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  const std::vector<FlagScope> output_scopes = {
      {"force", to_file || !FLAGS_plot.empty(), "--output=FILE or --plot"}};
  return CheckFlagsApply(scopes, mode, error) &&
         CheckFlagsApply(method_scopes, "--method=" + FLAGS_method, error) &&
         CheckFlagsApply(output_scopes, "output to stdout", error);
}

bool SetOptionsFromFlags(StaticsOptions* options, bool* compare, std::string* error) {
  *compare = FLAGS_method == "compare";
  if (!*compare && !ParseStaticsMethod(FLAGS_method, &options->method)) {
    *error =
        "--method must be aas, aas-refined, exact or compare, got " + internal::Quote(FLAGS_method);
    return false;
  }
  options->secant_low_fraction = FLAGS_secant_low;
  options->secant_high_fraction = FLAGS_secant_high;
  options->max_refinement_steps = FLAGS_max_refinement_steps;
  options->refined_relative_tolerance = FLAGS_refined_tolerance;
  options->aas_max_relative_error = FLAGS_aas_max_error;
  options->exact_relative_tolerance = FLAGS_exact_tolerance;
  options->warm_start = FLAGS_warm_start;
  if (!options->IsValid(error)) {
    *error = WithFlagNames(*error, {{"secant fractions", "--secant-low and --secant-high"},
                                    {"max_refinement_steps", "--max-refinement-steps"},
                                    {"refined_relative_tolerance", "--refined-tolerance"},
                                    {"aas_max_relative_error", "--aas-max-error"},
                                    {"exact_relative_tolerance", "--exact-tolerance"}});
    return false;
  }
  if (!ModelRangeFromFlags(options, error)) return false;
  if (FLAGS_format != "csv" && FLAGS_format != "json") {
    *error = "--format must be csv or json, got " + internal::Quote(FLAGS_format);
    return false;
  }
  return true;
}

}  // namespace

bool SinglePoseFromFlags(Pose* pose, std::string* attitude, std::string* error) {
  FocalAttitudeLaw law;
  PoseStream poses;
  if (!AttitudeLawFromFlags(&law, error) || !SinglePose(law, &poses, attitude, error)) {
    return false;
  }
  *pose = poses.next();
  return true;
}

bool ModelRangeFromFlags(StaticsOptions* options, std::string* error) {
  options->max_strain = FLAGS_max_strain;
  options->max_length_ratio = FLAGS_max_length_ratio;
  options->min_reflector_clearance_m = FLAGS_reflector_clearance;
  if (options->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"max_strain", "--max-strain"},
                                  {"max_length_ratio", "--max-length-ratio"},
                                  {"min_reflector_clearance_m", "--reflector-clearance"}});
  return false;
}

namespace {

// One method's chain of solutions along the poses (the warm start's source) and the time
// it took.
struct Run {
  StaticsOptions options;
  StaticsSolution solution;  // of the current pose
  double seconds = 0.0;

  const StaticsSolution& Solve(const CableRobot& robot, const Pose& pose) {
    const auto start = std::chrono::steady_clock::now();
    SolveStatics(robot, pose, options, &solution);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return solution;
  }
  bool ok() const { return solution.status == StaticsStatus::kOk; }
};

// "node 3 at position (x, y, z) m: <why> [method exact]".
std::string NodeFailure(long long n, const Pose& pose, const StaticsSolution& solution,
                        StaticsMethod method) {
  std::ostringstream s;
  const Eigen::Vector3d& x = pose.position_m;
  s << "node " << n << " at position (" << FormatDouble(x[0]) << ", " << FormatDouble(x[1]) << ", "
    << FormatDouble(x[2]) << ") m: " << DescribeStatus(solution) << " [method "
    << StaticsMethodName(method) << "]";
  return s.str();
}

// The status code and the message of a row: "ok" and "" on success; for compare the
// message names the method that failed.
std::pair<std::string, std::string> StatusAndMessage(const StaticsSolution& s,
                                                     const char* method = nullptr) {
  if (s.status == StaticsStatus::kOk) return {"ok", ""};
  return {StaticsStatusName(s.status),
          (method != nullptr ? std::string(method) + ": " : "") + DescribeStatus(s)};
}

// `cabin`: the model declares a measured frame, so x_m..yaw_deg are its pose (the data's)
// and cabin_x_m..cabin_yaw_deg the cabin's that the statics solved.
std::string CsvHeader(bool single, bool cabin) {
  std::ostringstream out;
  out << "node,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg";
  if (cabin) out << ",cabin_x_m,cabin_y_m,cabin_z_m,cabin_roll_deg,cabin_pitch_deg,cabin_yaw_deg";
  out << ",status";
  if (single) {
    for (int i = 1; i <= kNumCables; ++i) out << ",T" << i << "_kN";
    for (int i = 1; i <= kNumCables; ++i) out << ",T" << i << "_upper_kN";
    for (int i = 1; i <= kNumCables; ++i) out << ",s0_" << i << "_m";
    for (int i = 1; i <= kNumCables; ++i)
      out << ",F" << i << "x_kN,F" << i << "y_kN,F" << i << "z_kN";
    out << ",force_residual_N,moment_residual_Nm,end_residual_m,error_estimate_pct";
  } else {
    for (int i = 1; i <= kNumCables; ++i) out << ",T" << i << "_aas_kN";
    for (int i = 1; i <= kNumCables; ++i) out << ",T" << i << "_exact_kN";
    for (int i = 1; i <= kNumCables; ++i) out << ",err" << i << "_pct";
    out << ",aas_error_estimate_pct";
  }
  out << ",equilibrium";
  out << ",message\n";
  return out.str();
}

// One CSV row: `single` (one method), else `aas` against `exact`; `cabin` (null without a
// measured frame): the cabin's pose the statics solved.
void AppendCsvRow(long long n, const Pose& pose, const Pose* cabin, const StaticsSolution* single,
                  const StaticsSolution* aas, const StaticsSolution* exact, std::string* text) {
  std::ostringstream out;
  out << n;
  for (const Pose* p : {&pose, cabin}) {
    if (p == nullptr) continue;
    const Eigen::Vector3d rpy = RpyDegFromRotation(p->rotation);
    for (int j = 0; j < 3; ++j) out << "," << FormatDouble(p->position_m[j]);
    for (int j = 0; j < 3; ++j) out << "," << FormatDouble(rpy[j]);
  }
  std::pair<std::string, std::string> status;
  if (single != nullptr) {
    const StaticsSolution& s = *single;
    status = StatusAndMessage(s);
    out << "," << status.first;
    const bool ok = s.status == StaticsStatus::kOk;
    auto put = [&](double v) { out << "," << (ok ? FormatDouble(v) : ""); };
    for (const CableSolution& c : s.cables) put(c.lower_tension_n / kNPerKn);
    for (const CableSolution& c : s.cables) put(c.upper_tension_n / kNPerKn);
    for (const CableSolution& c : s.cables) put(c.unstretched_length_m);
    for (const CableSolution& c : s.cables) {
      for (int j = 0; j < 3; ++j) put(c.force_n[j] / kNPerKn);
    }
    put(s.force_residual_n);
    put(s.moment_residual_nm);
    put(s.end_residual_m);
    put(100.0 * s.error_estimate);
    out << "," << EquilibriumCode(s);
  } else {
    const StaticsSolution& a = *aas;
    const StaticsSolution& e = *exact;
    const bool ok = a.status == StaticsStatus::kOk && e.status == StaticsStatus::kOk;
    status =
        a.status != StaticsStatus::kOk ? StatusAndMessage(a, "aas") : StatusAndMessage(e, "exact");
    out << "," << status.first;
    auto put = [&](double v) { out << "," << (ok ? FormatDouble(v) : ""); };
    for (const CableSolution& c : a.cables) put(c.lower_tension_n / kNPerKn);
    for (const CableSolution& c : e.cables) put(c.lower_tension_n / kNPerKn);
    for (int i = 0; i < kNumCables; ++i) {
      put(ok ? 100.0 * (a.cables[i].lower_tension_n / e.cables[i].lower_tension_n - 1.0) : 0.0);
    }
    put(100.0 * a.error_estimate);
    out << "," << EquilibriumCode(e);
  }
  out << "," << internal::QuotedCsvField(status.second) << "\n";
  *text += out.str();
}

void JsonSolution(JsonWriter* j, const StaticsSolution& s) {
  const auto [status, message] = StatusAndMessage(s);
  j->Key("status").String(status);
  if (s.method == StaticsMethod::kExact) j->Key("equilibrium").String(EquilibriumCode(s));
  if (s.status != StaticsStatus::kOk) {
    j->Key("message").String(message);
    if (s.cable >= 0) j->Key("cable").Int(s.cable + 1);
    return;
  }
  j->Key("cables").BeginArray();
  for (const CableSolution& c : s.cables) {
    j->BeginObject();
    j->Key("lower_tension_kN").Number(c.lower_tension_n / kNPerKn);
    j->Key("upper_tension_kN").Number(c.upper_tension_n / kNPerKn);
    j->Key("unstretched_length_m").Number(c.unstretched_length_m);
    j->Key("chord_length_m").Number(c.chord_length_m);
    j->Key("end_residual_m").Number(c.end_residual_m);
    j->Key("force_kN")
        .NumberArray(std::array<double, 3>{c.force_n[0] / kNPerKn, c.force_n[1] / kNPerKn,
                                           c.force_n[2] / kNPerKn});
    j->EndObject();
  }
  j->EndArray();
  j->Key("force_residual_N").Number(s.force_residual_n);
  j->Key("moment_residual_Nm").Number(s.moment_residual_nm);
  j->Key("end_residual_m").Number(s.end_residual_m);
  j->Key("error_estimate").Number(s.error_estimate);
  j->Key("outer_iterations").Int(s.outer_iterations);
}

void AppendJsonPose(long long n, const Pose& pose, const Pose* cabin, const StaticsSolution* single,
                    const StaticsSolution* aas, const StaticsSolution* exact, JsonWriter* j) {
  j->BeginObject();
  j->Key("node").Int(n);
  j->Key("position_m").NumberArray(pose.position_m);
  j->Key("rpy_deg").NumberArray(RpyDegFromRotation(pose.rotation));
  if (cabin != nullptr) {
    j->Key("cabin_position_m").NumberArray(cabin->position_m);
    j->Key("cabin_rpy_deg").NumberArray(RpyDegFromRotation(cabin->rotation));
  }
  if (single != nullptr) {
    JsonSolution(j, *single);
  } else {
    j->Key("aas").BeginObject();
    JsonSolution(j, *aas);
    j->EndObject();
    j->Key("exact").BeginObject();
    JsonSolution(j, *exact);
    j->EndObject();
  }
  j->EndObject();
}

// --plot=FILE.html: for a trajectory or --poses (CheckFlagsApplyToMode), a file other
// than --output's, checked before any work as --output is.
bool CheckPlotFlag(std::string* error) {
  if (FLAGS_plot.empty()) return true;
  if (FLAGS_plot == "-") {
    *error = "--plot needs a file name (--plot=FILE.html); the table is what goes to stdout";
    return false;
  }
  if (!FLAGS_output.empty() && FLAGS_output != "-" &&
      ResolveOutputPath(FLAGS_output) == ResolveOutputPath(FLAGS_plot)) {
    *error = "--output and --plot name the same file: " + internal::Quote(FLAGS_plot);
    return false;
  }
  return CheckCanWrite("plot", FLAGS_plot, FLAGS_force, error);
}

std::string PlotPage(const std::vector<Pose>& poses, const std::string& provenance,
                     const std::vector<TrajectoryRun>& runs) {
  TrajectoryPlotInputs in;
  const std::string mode =
      !FLAGS_poses.empty() ? "--poses=" + FLAGS_poses : "--trajectory=" + FLAGS_trajectory;
  in.title = "Tensions along " + mode;
  in.provenance = provenance;
  in.poses = &poses;
  // A grid or a random sample of the cap is no path: its nodes in order instead.
  in.along_path = FLAGS_trajectory != "grid" && FLAGS_trajectory != "random";
  in.runs = runs;
  return TrajectoryPlotHtml(in);
}

// What --plot draws: the poses and each method's solutions, held (a plot is of a
// trajectory a person reads, not of a million poses: the table streams, the plot does not).
struct PlotData {
  std::vector<Pose> poses;
  std::vector<StaticsSolution> single, aas, exact;

  void Add(const Pose& pose, bool compare, const Run& one, const Run& a, const Run& e) {
    poses.push_back(pose);
    if (compare) {
      aas.push_back(a.solution);
      exact.push_back(e.solution);
    } else {
      single.push_back(one.solution);
    }
  }
};

// --plot's page, written before the table is renamed into place (RunSolve).
bool WritePlot(int argc, char** argv, const std::string& attitude, bool compare,
               const PlotData& plot, std::string* error) {
  if (FLAGS_plot.empty()) return true;
  const std::string provenance = CommandLine(argc, argv, {"force"}) + "\nfastcal " +
                                 FASTCAL_VERSION + ", model " + ModelName(FLAGS_model) +
                                 ", attitude " + attitude;
  const std::string page =
      compare ? PlotPage(plot.poses, provenance, {{"aas", &plot.aas}, {"exact", &plot.exact}})
              : PlotPage(plot.poses, provenance, {{FLAGS_method, &plot.single}});
  return WriteOutput(FLAGS_plot, page, error, FLAGS_force);
}

std::string TimingLine(const char* name, const Run& run, long long n, bool warm) {
  std::ostringstream s;
  s.precision(3);
  s << name << (warm && n > 1 ? " (warm start)" : "") << ": " << 1e6 * run.seconds / n
    << " us/pose";
  return s.str();
}

// What a whole run found, for the summary lines.
struct Totals {
  long long poses = 0;
  long long failed = 0;                        // poses any method failed (--keep-going)
  std::string first_failure;                   // NodeFailure of the first
  std::array<double, kNumCables> worst_pct{};  // compare: max |aas - exact| / exact
  long long several = 0;  // poses where exact met several equilibria (EquilibriumCode)
};

// One pose's part of the run's totals: a failure named (without --keep-going it ends the
// run: false with *error), poses of several equilibria, compare's worst |aas - exact|.
bool CountPose(long long n, const Pose& pose,
               const std::vector<std::pair<const Run*, StaticsMethod>>& runs, bool compare,
               const Run& aas, const Run& exact, const Run& single, Totals* totals,
               std::string* error) {
  bool pose_ok = true;
  for (const auto& [run, method] : runs) {
    if (run->ok() || !pose_ok) continue;
    pose_ok = false;
    const std::string failure = NodeFailure(n, pose, run->solution, method);
    if (!FLAGS_keep_going) {
      *error = failure;
      return false;
    }
    if (totals->first_failure.empty()) totals->first_failure = failure;
  }
  totals->failed += pose_ok ? 0 : 1;
  const StaticsSolution& exact_solution = compare ? exact.solution : single.solution;
  totals->several += exact_solution.other_equilibrium ? 1 : 0;
  if (compare && pose_ok) {
    for (int i = 0; i < kNumCables; ++i) {
      totals->worst_pct[i] = std::max(
          totals->worst_pct[i], 100.0 * std::abs(aas.solution.cables[i].lower_tension_n /
                                                     exact.solution.cables[i].lower_tension_n -
                                                 1.0));
    }
  }
  return true;
}

// Solves the poses one at a time (one method, or aas and exact for compare), each row
// formatted and handed to `out` as it is made: memory independent of the number of poses
// (issue 29). A failure without --keep-going stops the run with the node named.
// The poses are the data's (the model's measured frame's when `loaded` declares one,
// measured_frame.h): each is solved at the cabin's pose that follows from its joints (the
// pose file's, else `flag_joints`). `loaded` is the model as loaded (its parts and measured
// frame), `robot` the one with --joints' mass centre fixed.
bool SolveStream(const CableRobot& robot, const CableRobot& loaded, const PoseStream& stream,
                 const std::vector<JointValues>& joints, const JointValues& flag_joints,
                 const StaticsOptions& options, bool compare, ResultStream* out, Run* single,
                 Run* aas, Run* exact, Totals* totals, PlotData* plot, std::string* error) {
  const bool json = FLAGS_format == "json";
  single->options = aas->options = exact->options = options;
  aas->options.method = StaticsMethod::kAas;
  exact->options.method = StaticsMethod::kExact;
  JsonWriter j;
  std::string text;
  if (json) {
    j.BeginObject();
    j.Key("method").String(compare ? "compare" : FLAGS_method);
    j.Key("model").String(ModelName(FLAGS_model));
    j.Key("poses").BeginArray();
  } else {
    text = CsvHeader(!compare, loaded.measured_frame.has_value());
  }
  PoseStream poses = stream;
  // Each pose at its own joints (a --poses file's joint columns): the model with its mass
  // centre moved there, as locate does per row.
  CableRobot at_joints = robot;
  at_joints.moving_parts.parts.clear();
  const CableRobot& model = joints.empty() ? robot : at_joints;
  constexpr size_t kWriteBytes = 1 << 20;
  for (long long n = 0; n < poses.count; ++n) {
    const Pose data = poses.next();
    if (!joints.empty()) at_joints.mass_centre_cabin_m = robot.MassCentreAt(joints[n]);
    const Pose pose = loaded.CabinPose(data, joints.empty() ? flag_joints : joints[n]);
    const Pose* cabin = loaded.measured_frame.has_value() ? &pose : nullptr;
    std::vector<std::pair<const Run*, StaticsMethod>> runs;
    if (compare) {
      aas->Solve(model, pose);
      exact->Solve(model, pose);
      runs = {{aas, StaticsMethod::kAas}, {exact, StaticsMethod::kExact}};
    } else {
      single->Solve(model, pose);
      runs = {{single, options.method}};
    }
    if (!CountPose(n, data, runs, compare, *aas, *exact, *single, totals, error)) return false;
    const StaticsSolution* one = compare ? nullptr : &single->solution;
    if (plot != nullptr) plot->Add(data, compare, *single, *aas, *exact);
    if (json) {
      AppendJsonPose(n, data, cabin, one, &aas->solution, &exact->solution, &j);
      text += j.Take();
    } else {
      AppendCsvRow(n, data, cabin, one, &aas->solution, &exact->solution, &text);
    }
    if (text.size() >= kWriteBytes) {
      if (!out->Write(text, error)) return false;
      text.clear();
    }
  }
  totals->poses = poses.count;
  if (json) {
    j.EndArray();
    const double n = static_cast<double>(poses.count);
    if (compare) {
      j.Key("max_abs_relative_error_pct").NumberArray(totals->worst_pct);
      j.Key("seconds_per_pose_aas").Number(aas->seconds / n);
      j.Key("seconds_per_pose_exact").Number(exact->seconds / n);
    } else {
      j.Key("seconds_per_pose").Number(single->seconds / n);
    }
    j.EndObject();
    text += j.Take();
  }
  return out->Write(text, error);
}

// The run's summary: poses, timing, compare's worst error; failures and several equilibria
// on stderr.
void PrintSummary(const Totals& totals, bool compare, const StaticsOptions& options,
                  const Run& single, const Run& aas, const Run& exact,
                  const std::string& attitude) {
  std::ostringstream timing;
  const long long n = totals.poses;
  if (!compare) {
    timing << TimingLine(StaticsMethodName(options.method), single, n, options.warm_start);
  } else {
    timing << TimingLine("aas", aas, n, options.warm_start) << "; "
           << TimingLine("exact", exact, n, options.warm_start) << "\n"
           << "max |aas - exact| / exact per cable (%):";
    for (double e : totals.worst_pct) timing << " " << FormatDouble(e, 4);
  }
  // stdout carries the result: the table itself, else (--output=FILE) this summary of
  // it (docs/cli.md, "Output streams").
  std::ostream& summary = FLAGS_output.empty() || FLAGS_output == "-" ? std::cerr : std::cout;
  summary << "fastcal solve: " << n << (n == 1 ? " pose" : " poses");
  if (totals.failed > 0) summary << " (" << totals.failed << " failed)";
  // Paths and flag text on the terminal: control bytes escaped.
  summary << ", model " << internal::Escape(ModelName(FLAGS_model)) << ", attitude "
          << internal::Escape(attitude) << "; " << timing.str() << std::endl;
  if (totals.failed > 0) {
    std::cerr << "fastcal solve: " << totals.failed << " of " << n
              << " poses failed; --keep-going wrote them with their status, message and empty "
                 "numbers "
                 "(exit 0). First: "
              << totals.first_failure << std::endl;
  }
  if (totals.several > 0) {
    std::cerr << "fastcal solve: several equilibria hold " << totals.several << " of " << n
              << (n == 1 ? " pose" : " poses")
              << " (column equilibrium: several, unreachable); exact returns the one followed "
                 "from the home pose (docs/model.md, \"Which equilibrium exact returns\")"
              << std::endl;
  }
}

}  // namespace

int RunSolve(int argc, char** argv) {
  int exit_code = 0;
  static const std::string help = Help();
  if (!StartCommand(argc, argv, kCommand, help.c_str(), kFlags, &exit_code)) return exit_code;
  if (FlagGiven("columns") && FLAGS_poses.empty()) {
    PrintError(kCommand, "--columns applies to --poses=FILE (a pose file read as exported)");
    return kExitUsage;
  }

  std::string error;
  if (!CheckCanWrite("output", FLAGS_output, FLAGS_force, &error) || !CheckPlotFlag(&error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  CableRobot robot;
  if (!LoadModelFlag("model", FLAGS_model, &robot, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  // As loaded: its parts and measured frame, before --joints fixes the mass centre.
  const CableRobot loaded = robot;
  const MovingParts& parts = loaded.moving_parts;
  JointValues flag_joints{};
  if (!MassCentreAtJointsFlag(FLAGS_joints, &robot, &error, &flag_joints)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  StaticsOptions options;
  bool compare = false;
  PoseStream poses;
  std::vector<JointValues> joints;
  std::string attitude;
  if (!SetOptionsFromFlags(&options, &compare, &error) || !CheckFlagsApplyToMode(&error) ||
      !BuildPoses(parts, &poses, &joints, &attitude, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  if (poses.count == 0) {
    PrintError(kCommand, "no poses to solve");
    return kExitUsage;
  }
  if (!parts.empty()) {  // the summary says at which joints the moving parts were
    attitude += !joints.empty()         ? ", joints per pose from " + FLAGS_poses
                : !FLAGS_joints.empty() ? ", joints --joints=" + FLAGS_joints
                                        : ", joints all 0 (no --joints)";
  }

  ResultStream out;
  if (!out.Open(FLAGS_output, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  Run single, aas, exact;
  Totals totals;
  PlotData plot;
  if (loaded.measured_frame.has_value()) {  // the summary says whose pose was given
    attitude += "; poses of the measured frame (" +
                DescribeMeasuredFrame(&*loaded.measured_frame, loaded.moving_parts) + ")";
  }
  if (!SolveStream(robot, loaded, poses, joints, flag_joints, options, compare, &out, &single, &aas,
                   &exact, &totals, FLAGS_plot.empty() ? nullptr : &plot, &error) ||
      !WritePlot(argc, argv, attitude, compare, plot, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;  // a pose that cannot be held, or the output (a full disk)
  }
  if (!out.Finish(FLAGS_force, &error)) {
    // The table and the plot go together: a plot without its table is removed.
    if (!FLAGS_plot.empty()) std::remove(FLAGS_plot.c_str());
    PrintError(kCommand, error);
    return kExitFailure;
  }
  PrintSummary(totals, compare, options, single, aas, exact, attitude);
  return 0;
}

}  // namespace fastcal::cli
