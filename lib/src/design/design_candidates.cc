// Candidate poses of a survey design and the surveys it is compared with (design.h):
// the workspace grid at the focal law, its tilted and turned attitude variants, each
// judged as `fastcal workspace` judges a node (JudgeWorkspacePose).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "fastcal/internal/design_information.h"
#include "fastcal/joint_plan.h"
#include "fastcal/trajectory.h"
#include "fastcal/workspace.h"

namespace fastcal::internal {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// Extra attitudes off the law: (tilt, direction, yaw) in degrees, the law itself first.
struct Variant {
  double tilt_deg, direction_deg, yaw_deg;
};

std::vector<Variant> Variants(const DesignOptions& o) {
  std::vector<double> yaws = {0.0};
  if (o.max_extra_yaw_deg > 0.0) {
    yaws.push_back(-o.max_extra_yaw_deg);
    yaws.push_back(o.max_extra_yaw_deg);
  }
  std::vector<Variant> out;
  for (double yaw : yaws) {
    out.push_back({0.0, 0.0, yaw});
    if (o.max_extra_tilt_deg <= 0.0) continue;
    for (int d = 0; d < o.tilt_directions; ++d) {
      out.push_back({o.max_extra_tilt_deg, 360.0 * d / o.tilt_directions, yaw});
    }
  }
  return out;
}

// R_law Rtilt Rz(yaw): z' tilted by `tilt` toward direction `direction` of the cabin's
// x'y' plane, then the cabin turned about its (tilted) z'.
Eigen::Matrix3d VariantRotation(const Eigen::Matrix3d& law, const Variant& v) {
  const double phi = v.direction_deg * kDegToRad;
  const Eigen::Vector3d axis(-std::sin(phi), std::cos(phi), 0.0);  // z' moves toward phi
  return law * Eigen::AngleAxisd(v.tilt_deg * kDegToRad, axis).toRotationMatrix() *
         Eigen::AngleAxisd(v.yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

void GridAngles(const Eigen::Vector3d& p, const FocalGridSpec& grid, double* off_axis_deg,
                double* azimuth_deg) {
  const Eigen::Vector3d d = p - grid.focal_centre_m;
  *off_axis_deg = std::acos(std::clamp(-d.z() / d.norm(), -1.0, 1.0)) / kDegToRad;
  *azimuth_deg = std::atan2(d.y(), d.x()) / kDegToRad;
  if (*azimuth_deg < 0.0) *azimuth_deg += 360.0;
}

}  // namespace

bool DesignCandidates(const CableRobot& robot, const DesignOptions& options,
                      std::vector<DesignCandidate>* candidates, int* rejected, std::string* error) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> law_poses;
  if (!FocalSpherePositions(options.workspace.grid, &positions, error) ||
      !PosesWithAttitudeLaw(positions, options.workspace.attitude_law, &law_poses, error)) {
    return false;
  }
  const std::vector<Variant> variants = Variants(options);
  candidates->clear();
  *rejected = 0;
  StaticsSolution solution;  // warm starts along the grid and across the variants
  for (const Pose& law : law_poses) {
    double off_axis_deg = 0.0, azimuth_deg = 0.0;
    GridAngles(law.position_m, options.workspace.grid, &off_axis_deg, &azimuth_deg);
    for (const Variant& v : variants) {
      DesignCandidate c;
      c.pose.position_m = law.position_m;
      c.pose.rotation = VariantRotation(law.rotation, v);
      WorkspaceNode node;
      JudgeWorkspacePose(robot, c.pose, options.workspace, &solution, &node);
      if (node.verdict != WorkspaceVerdict::kFeasible) {
        ++*rejected;
        continue;
      }
      c.off_axis_deg = off_axis_deg;
      c.azimuth_deg = azimuth_deg;
      c.extra_tilt_deg = v.tilt_deg;
      c.tilt_direction_deg = v.direction_deg;
      c.extra_yaw_deg = v.yaw_deg;
      candidates->push_back(c);
    }
  }
  if (candidates->empty()) {
    *error = "no candidate pose is feasible: all " + std::to_string(*rejected) +
             " fail the statics or the tension limits (check them with fastcal workspace)";
    return false;
  }
  return true;
}

bool ExpandJointGrid(const CableRobot& robot, const DesignOptions& options,
                     std::vector<DesignCandidate>* candidates, std::string* error) {
  JointPlanOptions grid;
  grid.revolute = RevoluteLaw::kGrid;
  grid.grid_deg = options.joint_grid_deg;
  JointPlan plan;
  if (options.joint_grid_deg.empty() ||
      !JointPlan::Make(robot.moving_parts, grid, &plan, nullptr)) {
    return true;  // a rigid cabin, no rotator, or the rotator held at zero
  }
  const long long points =
      static_cast<long long>(options.joint_grid_deg.size() * options.joint_grid_deg.size());
  std::vector<DesignCandidate> out;
  std::string out_of_range;
  for (const DesignCandidate& c : *candidates) {
    for (long long g = 0; g < points; ++g) {
      DesignCandidate k = c;
      // Out of a joint's range: that point is not offered (the plan says why).
      if (!plan.Next(g, c.pose, &k.joints, &out_of_range)) continue;
      k.joint_point = static_cast<int>(g);
      out.push_back(k);
    }
  }
  if (out.empty()) {
    *error = "joint grid: no point of it is within the rotator's ranges (" + out_of_range + ")";
    return false;
  }
  *candidates = std::move(out);
  return true;
}

std::vector<JointValues> ObservingJoints(const CableRobot& robot, const std::vector<Pose>& poses) {
  if (robot.moving_parts.empty()) return {};
  JointPlanOptions focal;
  focal.revolute = RevoluteLaw::kFocal;
  JointPlan plan;
  const bool rotator = JointPlan::Make(robot.moving_parts, focal, &plan, nullptr);
  std::vector<JointValues> joints(poses.size(), JointValues{});
  for (size_t n = 0; rotator && n < poses.size(); ++n) {
    // A law's angle out of a joint's range: that pose flies the rotator at zero.
    if (!plan.Next(static_cast<long long>(n), poses[n], &joints[n], nullptr)) joints[n].fill(0.0);
  }
  return joints;
}

bool CirclePoses(const DesignOptions& options, int samples, std::vector<Pose>* poses,
                 std::string* error) {
  ArcSpec arc;
  arc.centre_m = options.circle_centre_m;
  arc.radius_m = options.circle_radius_m;
  arc.start_deg = 0.0;
  arc.end_deg = 360.0;
  arc.nodes = std::max(2, samples);
  std::vector<Eigen::Vector3d> positions;
  if (!ArcPositions(arc, &positions, error)) return false;
  positions.resize(samples);
  return PosesWithAttitudeLaw(positions, options.workspace.attitude_law, poses, error);
}

bool RandomSurveyPoses(const CableRobot& robot, const DesignOptions& options, int samples,
                       std::vector<Pose>* poses, std::string* error) {
  // Enough draws that a cap where most poses are feasible fills the survey.
  constexpr int kDrawsPerSample = 8;
  RandomWorkspaceSpec spec;
  spec.samples = kDrawsPerSample * samples;
  spec.max_off_axis_deg = options.workspace.grid.max_off_axis_deg;
  spec.sphere = options.workspace.grid;
  spec.seed = options.seed;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> drawn;
  if (!RandomWorkspacePositions(spec, &positions, error) ||
      !PosesWithAttitudeLaw(positions, options.workspace.attitude_law, &drawn, error)) {
    return false;
  }
  poses->clear();
  StaticsSolution solution;
  for (const Pose& pose : drawn) {
    WorkspaceNode node;
    JudgeWorkspacePose(robot, pose, options.workspace, &solution, &node);
    if (node.verdict == WorkspaceVerdict::kFeasible) poses->push_back(pose);
    if (static_cast<int>(poses->size()) == samples) return true;
  }
  *error = "the random survey found only " + std::to_string(poses->size()) + " feasible of " +
           std::to_string(spec.samples) + " random poses on the cap";
  return false;
}

}  // namespace fastcal::internal
