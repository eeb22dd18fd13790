// The feasible workspace: where the cabin can go with every cable within given limits,
// over a grid of the focal-sphere cap (trajectory.h, FocalSpherePositions), optionally
// also dr inside and outside the sphere, at the attitude of the focal law (pose.h).
//
// Each node is solved (statics.h; exact by default, warm-started along the grid) and is
// feasible when its statics are ok, which includes the model's range (max_strain,
// max_length_ratio) and the reflector's clearance (min_reflector_clearance_m), and every
// cable's lower-end tension lies in [min_tension_n, max_tension_n]. Otherwise the node
// says why, and which cable: the statics' status (no equilibrium, a cable beyond the
// model's range or touching the reflector, ...), else a tension below the minimum (the
// lowest such cable), else one above the maximum (the highest).
//
// The tension limits apply to the lower-end tensions: what the cabin-side sensors read,
// the paper's tables give and `fastcal solve` writes as T<i>_kN. The tower end carries
// the cable's weight on top (~10 kN more on FAST); each node reports that maximum too.
//
// A model with moving parts (moving_parts.h) is solved at each node's joints: the rotator
// at zero, or following the focal law (joint_plan.h, RevoluteLaw::kFocal: it completes
// the tilt the cabin does not give, as the telescope flies), the mass centre with them.
#ifndef FASTCAL_WORKSPACE_H_
#define FASTCAL_WORKSPACE_H_

#include <limits>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/joint_plan.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"

namespace fastcal {

struct WorkspaceOptions {
  // The cap: every 1 deg off axis up to 40 deg (FAST's zenith range), every 5 deg of
  // azimuth, on the focal sphere of radius 160 m about (0, 0, 300) m: 2881 nodes.
  FocalGridSpec grid = {/*max_off_axis_deg=*/40.0, /*off_axis_step_deg=*/1.0,
                        /*azimuth_step_deg=*/5.0, Eigen::Vector3d(0.0, 0.0, 300.0),
                        /*focal_radius_m=*/160.0};
  // > 0: the same grid also this far inside and outside the sphere (m), three layers.
  double radial_offset_m = 0.0;
  // The attitude at every node; its focal centre is normally the grid's.
  FocalAttitudeLaw attitude_law;
  // A model with moving parts: the rotator's angles at each node, kZero (default) or
  // kFocal (toward attitude_law's focal centre); kGrid is refused. Prismatic joints at 0.
  RevoluteLaw joint_law = RevoluteLaw::kZero;
  // Limits on every cable's lower-end tension (N); 0 and +infinity: none.
  double min_tension_n = 0.0;
  double max_tension_n = std::numeric_limits<double>::infinity();
  // The statics at each node: method, model range, reflector clearance. Warm-started by
  // default (each node from the previous one on its ring; a warm start that fails is
  // retried cold, so the results do not depend on it).
  StaticsOptions statics = [] {
    StaticsOptions o;
    o.warm_start = true;
    return o;
  }();

  // False with *error naming the field (grid.*, radial_offset_m, min_tension_n,
  // max_tension_n, attitude_law.*, joint_law, or the statics option) when an option is
  // invalid.
  bool IsValid(std::string* error) const;
};

// Why a node is not feasible.
enum class WorkspaceVerdict {
  kFeasible = 0,
  kStatics,          // the statics failed: WorkspaceNode::status says why
  kBelowMinTension,  // a cable's lower-end tension is below min_tension_n
  kAboveMaxTension,  // one is above max_tension_n
};

struct WorkspaceNode {
  Pose pose;
  double off_axis_deg = 0.0, azimuth_deg = 0.0;
  double radial_offset_m = 0.0;  // along the sphere's outward normal (outward: lower)
  WorkspaceVerdict verdict = WorkspaceVerdict::kStatics;
  StaticsStatus status = StaticsStatus::kInvalidInput;
  int cable = -1;      // the limiting cable (0-based); -1 when feasible or none is named
  std::string reason;  // why it is not feasible, with the numbers; empty when feasible
  // With the statics ok: the smallest and largest lower-end tension and their cables
  // (0-based), and the largest upper-end (tower) tension. 0 and -1 otherwise.
  double min_tension_n = 0.0, max_tension_n = 0.0, max_upper_tension_n = 0.0;
  int min_tension_cable = -1, max_tension_cable = -1;
};

struct WorkspaceMap {
  WorkspaceOptions options;
  // The layers' radial offsets (m): {0}, or {-dr, 0, dr} (inside, on, outside).
  std::vector<double> layers_m;
  // Layer by layer, each in FocalSpherePositions' order (the axis, then ring by ring).
  std::vector<WorkspaceNode> nodes;
};

// Solves every node of the map. Returns false with *error (naming the option) only for
// invalid options; infeasible nodes are results, not errors.
bool ComputeWorkspace(const CableRobot& robot, const WorkspaceOptions& options, WorkspaceMap* map,
                      std::string* error);

// Solves and judges one pose as ComputeWorkspace judges a node (statics ok, tensions
// within the limits); `solution` is the warm start in and the solution out. The node's
// grid angles and radial offset are left at 0 (design.h judges tilted poses with it).
void JudgeWorkspacePose(const CableRobot& robot, const Pose& pose, const WorkspaceOptions& options,
                        StaticsSolution* solution, WorkspaceNode* node);
// A node's short code: "feasible", "below_min_tension", "above_max_tension", or the
// statics' status code (StaticsStatusName).
std::string WorkspaceNodeCode(const WorkspaceNode& node);

// One row per node: radial_offset_m, off_axis_deg, azimuth_deg, x_m, y_m, z_m, roll_deg,
// pitch_deg, yaw_deg, status (WorkspaceNodeCode), cable (1-based, empty when none),
// min_tension_kN, min_tension_cable, max_tension_kN, max_tension_cable,
// max_upper_tension_kN (empty when the statics failed), message (quoted; "" when
// feasible).
std::string WorkspaceCsv(const WorkspaceMap& map);

// A self-contained HTML page (inline style and SVG, no scripts): what was computed and
// with which limits, counts per reason for each layer, and for each layer a polar map of
// the cap (svg_plot.h, SvgPolarMap) seen from above, x toward tower 1: colour = the
// smallest lower-end tension in kN, grey where the statics failed, a mark for each
// infeasible node's reason, tooltips with each node's numbers, the towers on the rim.
// `model_name` and `provenance` (e.g. the command line) are printed as given.
std::string WorkspaceHtml(const WorkspaceMap& map, const CableRobot& robot,
                          const std::string& model_name, const std::string& provenance);

}  // namespace fastcal

#endif  // FASTCAL_WORKSPACE_H_
