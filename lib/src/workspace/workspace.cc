// The feasible workspace (workspace.h): each node of the focal-sphere grid solved and
// judged against the statics' model range and the lower-end tension limits
//   feasible  <=>  status ok  and  min_tension_n <= T_i <= max_tension_n for every cable i,
// T_i = |F_i| at the cabin end (statics.h); then the CSV and the HTML map.
#include "fastcal/workspace.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "fastcal/internal/csv.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/units.h"

namespace fastcal {
namespace {

using internal::kNPerKn;

// `value` with `digits` significant digits (no trailing zeros), for files and text.
std::string Num(double value, int digits = 10) {
  if (value == 0.0) return "0";  // never "-0" in a table
  return internal::FormatDouble("%." + std::to_string(digits) + "g", value);
}

std::string CableName(int cable) { return "cable " + std::to_string(cable + 1); }

// The layers' radial offsets: on the sphere, and dr inside and outside when dr > 0.
std::vector<double> Layers(double radial_offset_m) {
  if (radial_offset_m > 0.0) return {-radial_offset_m, 0.0, radial_offset_m};
  return {0.0};
}

// Judges a solved node against the tension limits (the statics' own checks came first).
void Judge(const StaticsSolution& s, const WorkspaceOptions& o, WorkspaceNode* node) {
  node->status = s.status;
  if (s.status != StaticsStatus::kOk) {
    node->verdict = WorkspaceVerdict::kStatics;
    node->cable = s.cable;
    node->reason = DescribeStatus(s);
    return;
  }
  node->min_tension_n = HUGE_VAL;
  for (int i = 0; i < kNumCables; ++i) {
    const CableSolution& c = s.cables[i];
    if (c.lower_tension_n < node->min_tension_n) {
      node->min_tension_n = c.lower_tension_n;
      node->min_tension_cable = i;
    }
    if (c.lower_tension_n > node->max_tension_n) {
      node->max_tension_n = c.lower_tension_n;
      node->max_tension_cable = i;
    }
    node->max_upper_tension_n = std::max(node->max_upper_tension_n, c.upper_tension_n);
  }
  // A cable near slack is the more urgent for control: below the minimum comes first.
  if (node->min_tension_n < o.min_tension_n) {
    node->verdict = WorkspaceVerdict::kBelowMinTension;
    node->cable = node->min_tension_cable;
    node->reason = CableName(node->cable) +
                   " below the minimum tension: " + Num(node->min_tension_n / kNPerKn, 4) +
                   " kN < " + Num(o.min_tension_n / kNPerKn, 4) + " kN";
  } else if (node->max_tension_n > o.max_tension_n) {
    node->verdict = WorkspaceVerdict::kAboveMaxTension;
    node->cable = node->max_tension_cable;
    node->reason = CableName(node->cable) +
                   " above the maximum tension: " + Num(node->max_tension_n / kNPerKn, 4) +
                   " kN > " + Num(o.max_tension_n / kNPerKn, 4) + " kN";
  } else {
    node->verdict = WorkspaceVerdict::kFeasible;
  }
}

}  // namespace

bool WorkspaceOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  std::vector<Eigen::Vector3d> positions;
  std::string why;
  if (!FocalSpherePositions(grid, &positions, &why)) return fail("grid." + why);
  if (!(radial_offset_m >= 0.0) || !(radial_offset_m < grid.focal_radius_m)) {
    return fail("radial_offset_m must be >= 0 and below grid.focal_radius_m (got " +
                Num(radial_offset_m) + " m)");
  }
  if (!(min_tension_n >= 0.0) || !std::isfinite(min_tension_n)) {
    return fail("min_tension_n must be >= 0 and finite (got " + Num(min_tension_n) + " N)");
  }
  if (!(max_tension_n > min_tension_n)) {
    return fail("max_tension_n must be above min_tension_n (got " + Num(max_tension_n) +
                " <= " + Num(min_tension_n) + ")");
  }
  if (!attitude_law.focal_centre_m.allFinite()) {
    return fail("attitude_law.focal_centre_m must be finite");
  }
  if (!(attitude_law.tilt_fraction >= 0.0 && attitude_law.tilt_fraction <= 1.0)) {
    return fail("attitude_law.tilt_fraction must be in [0, 1] (got " +
                Num(attitude_law.tilt_fraction) + ")");
  }
  if (!statics.IsValid(&why)) return fail("statics: " + why);
  if (joint_law == RevoluteLaw::kGrid) {
    return fail("joint_law: grid is for surveys; a workspace node takes zero or focal");
  }
  return true;
}

bool ComputeWorkspace(const CableRobot& robot, const WorkspaceOptions& options, WorkspaceMap* map,
                      std::string* error) {
  if (!options.IsValid(error)) return false;
  WorkspaceMap out;
  out.options = options;
  out.layers_m = Layers(options.radial_offset_m);
  JointPlan plan;  // the joints of each node (a model with moving parts)
  JointPlanOptions joint_options;
  joint_options.revolute = options.joint_law;
  joint_options.focal_centre_m = options.attitude_law.focal_centre_m;
  if (!robot.moving_parts.empty() &&
      !JointPlan::Make(robot.moving_parts, joint_options, &plan, error)) {
    *error = "joint_law: " + *error;
    return false;
  }
  JointValues joints{};
  for (double offset_m : out.layers_m) {
    FocalGridSpec layer = options.grid;
    layer.focal_radius_m += offset_m;
    std::vector<Eigen::Vector3d> positions;
    std::vector<Pose> poses;
    if (!FocalSpherePositions(layer, &positions, error) ||
        !PosesWithAttitudeLaw(positions, options.attitude_law, &poses, error)) {
      return false;
    }
    StaticsSolution solution;  // warm starts run along each ring
    for (const Pose& pose : poses) {
      WorkspaceNode node;
      node.pose = pose;
      node.radial_offset_m = offset_m;
      FocalGridAngles(pose.position_m, layer.focal_centre_m, &node.off_axis_deg, &node.azimuth_deg);
      if (!robot.moving_parts.empty() &&
          !plan.Next(static_cast<long long>(out.nodes.size()), pose, &joints, error)) {
        return false;  // a law's angle outside a joint's range, named
      }
      SolveStatics(robot, pose, joints, options.statics, &solution);
      Judge(solution, options, &node);
      out.nodes.push_back(node);
    }
  }
  *map = std::move(out);
  return true;
}

void JudgeWorkspacePose(const CableRobot& robot, const Pose& pose, const WorkspaceOptions& options,
                        StaticsSolution* solution, WorkspaceNode* node) {
  *node = WorkspaceNode();
  node->pose = pose;
  SolveStatics(robot, pose, options.statics, solution);
  Judge(*solution, options, node);
}

std::string WorkspaceNodeCode(const WorkspaceNode& node) {
  switch (node.verdict) {
    case WorkspaceVerdict::kFeasible:
      return "feasible";
    case WorkspaceVerdict::kBelowMinTension:
      return "below_min_tension";
    case WorkspaceVerdict::kAboveMaxTension:
      return "above_max_tension";
    case WorkspaceVerdict::kStatics:
      break;
  }
  return StaticsStatusName(node.status);
}

std::string WorkspaceCsv(const WorkspaceMap& map) {
  std::ostringstream out;
  // A string stream that runs out of memory only sets badbit and returns what it has:
  // a truncated table written with exit 0 (issue 37). Out of memory is thrown instead.
  out.exceptions(std::ios::badbit);
  out << "radial_offset_m,off_axis_deg,azimuth_deg,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,"
         "status,cable,min_tension_kN,min_tension_cable,max_tension_kN,max_tension_cable,"
         "max_upper_tension_kN,message\n";
  for (const WorkspaceNode& n : map.nodes) {
    const Eigen::Vector3d rpy = RpyDegFromRotation(n.pose.rotation);
    out << Num(n.radial_offset_m) << "," << Num(n.off_axis_deg) << "," << Num(n.azimuth_deg);
    for (int k = 0; k < 3; ++k) out << "," << Num(n.pose.position_m[k]);
    for (int k = 0; k < 3; ++k) out << "," << Num(rpy[k]);
    out << "," << WorkspaceNodeCode(n) << "," << (n.cable >= 0 ? std::to_string(n.cable + 1) : "");
    if (n.status == StaticsStatus::kOk) {
      out << "," << Num(n.min_tension_n / kNPerKn) << "," << n.min_tension_cable + 1 << ","
          << Num(n.max_tension_n / kNPerKn) << "," << n.max_tension_cable + 1 << ","
          << Num(n.max_upper_tension_n / kNPerKn);
    } else {
      out << ",,,,,";
    }
    out << "," << internal::QuotedCsvField(n.reason) << "\n";
  }
  return out.str();
}

}  // namespace fastcal
