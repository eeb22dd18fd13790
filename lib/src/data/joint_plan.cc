// Joint values along a planned trajectory (joint_plan.h): the rotator's focal law
//   b = asin(v_x), a = atan2(-v_y, v_z),  v = R^T (C - p) / |C - p|,
// its grid, and the platform's spread.
#include "fastcal/joint_plan.h"

#include <cmath>

#include "fastcal/internal/fail.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;

using internal::Fail;

// The first joint index of the first part whose first two joints are revolute about x and
// then y (the A-B rotator), or -1.
int RotatorFirstJoint(const MovingParts& parts) {
  int first = 0;
  for (const MovingPart& p : parts.parts) {
    if (p.joints.size() >= 2 && p.joints[0].type == JointType::kRevolute &&
        p.joints[1].type == JointType::kRevolute &&
        p.joints[0].axis.isApprox(Eigen::Vector3d::UnitX()) &&
        p.joints[1].axis.isApprox(Eigen::Vector3d::UnitY())) {
      return first;
    }
    first += static_cast<int>(p.joints.size());
  }
  return -1;
}

}  // namespace

const char* RevoluteLawName(RevoluteLaw law) {
  switch (law) {
    case RevoluteLaw::kZero:
      return "zero";
    case RevoluteLaw::kFocal:
      return "focal";
    case RevoluteLaw::kGrid:
      return "grid";
  }
  return "zero";
}

bool ParseRevoluteLaw(const std::string& name, RevoluteLaw* law) {
  for (RevoluteLaw l : {RevoluteLaw::kZero, RevoluteLaw::kFocal, RevoluteLaw::kGrid}) {
    if (name == RevoluteLawName(l)) {
      *law = l;
      return true;
    }
  }
  return false;
}

bool JointPlan::Make(const MovingParts& parts, const JointPlanOptions& options, JointPlan* plan,
                     std::string* error) {
  plan->parts_ = &parts;
  plan->options_ = options;
  plan->rotator_first_joint_ = RotatorFirstJoint(parts);
  plan->engine_.seed(options.seed ^ 0x6a6f696e74706c61ULL);  // "jointpla": a stream of its own
  if (!options.given.empty()) {
    if (options.revolute != RevoluteLaw::kZero || options.prismatic_sigma_m > 0.0) {
      return Fail(error,
                  "joint values given per sample (the pose file's joint columns) "
                  "and a joint law or prismatic spread: give one");
    }
    return true;
  }
  if (options.revolute != RevoluteLaw::kZero && plan->rotator_first_joint_ < 0) {
    return Fail(error, std::string("joint law ") + RevoluteLawName(options.revolute) +
                           " needs a rotator: a moving part whose first two joints are "
                           "revolute about [1, 0, 0] and then [0, 1, 0]");
  }
  if (options.revolute == RevoluteLaw::kGrid) {
    if (options.grid_deg.empty()) return Fail(error, "joint grid: no values");
    for (double v : options.grid_deg) {
      if (!std::isfinite(v) || std::abs(v) > 180.0) {
        return Fail(error, "joint grid: values must be finite angles within +-180 deg");
      }
    }
  }
  if (!(options.prismatic_sigma_m >= 0.0) || !std::isfinite(options.prismatic_sigma_m)) {
    return Fail(error, "prismatic joint spread: must be >= 0 (m)");
  }
  if (!options.focal_centre_m.allFinite()) return Fail(error, "focal centre: must be finite");
  return true;
}

bool JointPlan::Next(long long n, const Pose& pose, JointValues* joints, std::string* error) {
  joints->fill(0.0);
  const int r = rotator_first_joint_;
  if (!options_.given.empty()) {
    *joints = options_.given[static_cast<size_t>(n) % options_.given.size()];
  } else if (options_.revolute == RevoluteLaw::kFocal) {
    const Eigen::Vector3d to_centre = options_.focal_centre_m - pose.position_m;
    if (!(to_centre.norm() > 0.0)) return Fail(error, "focal law: the pose is at the centre");
    const Eigen::Vector3d v = pose.rotation.transpose() * to_centre.normalized();
    (*joints)[r + 1] = std::asin(std::max(-1.0, std::min(1.0, v.x()))) * kDegPerRad;
    (*joints)[r] = std::atan2(-v.y(), v.z()) * kDegPerRad;
  } else if (options_.revolute == RevoluteLaw::kGrid) {
    const long long size = static_cast<long long>(options_.grid_deg.size());
    const long long point = n % (size * size);
    (*joints)[r] = options_.grid_deg[point / size];
    (*joints)[r + 1] = options_.grid_deg[point % size];
  }
  int next = 0;
  for (const MovingPart& part : parts_->parts) {
    for (const Joint& joint : part.joints) {
      double& q = (*joints)[next++];
      if (joint.type == JointType::kPrismatic && options_.prismatic_sigma_m > 0.0) {
        // Box-Muller from the top 53 bits, the same on every standard library.
        const double u1 = 1.0 - static_cast<double>(engine_() >> 11) * 0x1.0p-53;
        const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
        q = options_.prismatic_sigma_m * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
        if (joint.has_range) q = std::max(joint.range_low, std::min(joint.range_high, q));
      }
      if (joint.has_range && (q < joint.range_low || q > joint.range_high)) {
        return Fail(error, "node " + std::to_string(n) + ": joint " + joint.column + " = " +
                               internal::FormatDouble("%.6g", q) + " is outside its range [" +
                               internal::FormatDouble("%.6g", joint.range_low) + ", " +
                               internal::FormatDouble("%.6g", joint.range_high) + "]");
      }
    }
  }
  return true;
}

}  // namespace fastcal
