// The joint values the cabin's moving parts take along a planned trajectory
// (moving_parts.h), for simulated telemetry and surveys.
//
// Revolute joints, three laws:
//   zero   every angle 0;
//   focal  the rotator completes the tilt the cabin does not give, so that the feed axis
//          (the part's z axis) lies along the focal sphere's radius: with u the unit vector
//          from the cabin origin p to the sphere's centre C and v = R^T u in the cabin
//          frame (R the planned attitude), a rotator R_x(a) R_y(b) has
//            R_x(a) R_y(b) z = (sin b, -sin a cos b, cos a cos b) = v,
//          so b = asin(v_x), a = atan2(-v_y, v_z) (docs/model.md "Moving parts");
//   grid   sample n visits grid point n mod G of the grid of `grid_deg` values over the
//          rotator's two angles (G = size^2): at fixed cabin poses the rotator's angles vary
//          independently of the cabin's tilt, which separates its first moment from the
//          fixed mass centre (../shared/design/methods.md).
// The rotator is the first part whose first two joints are revolute about x then y.
// Prismatic joints (the Stewart platform's translation): N(0, prismatic_sigma_m) per joint
// and sample, from a generator of their own (seeded), within the joint's range.
// Given values (a pose file's joint columns, e.g. a design's): sample n takes given[n mod
// size] as they are, every joint; the laws and the spread are then not used.
#ifndef FASTCAL_JOINT_PLAN_H_
#define FASTCAL_JOINT_PLAN_H_

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "fastcal/moving_parts.h"
#include "fastcal/pose.h"

namespace fastcal {

enum class RevoluteLaw { kZero, kFocal, kGrid };
// "zero", "focal", "grid"; ParseRevoluteLaw is false for another name.
const char* RevoluteLawName(RevoluteLaw law);
bool ParseRevoluteLaw(const std::string& name, RevoluteLaw* law);

struct JointPlanOptions {
  RevoluteLaw revolute = RevoluteLaw::kZero;
  // With kGrid: the values (deg) each of the rotator's two angles visits; at least one.
  std::vector<double> grid_deg;
  // The focal sphere's centre (global frame), for kFocal; FAST's by default.
  Eigen::Vector3d focal_centre_m = Eigen::Vector3d(0.0, 0.0, 300.0);
  // Spread of every prismatic joint (m), >= 0; 0: at zero.
  double prismatic_sigma_m = 0.0;
  std::uint64_t seed = 1;
  // Joint values per sample given (the model's joint order, the columns' units); empty:
  // the laws above.
  std::vector<JointValues> given;
};

// Joint values of sample n at planned pose `pose` (the model's joint order, the columns'
// units: deg and m). A law's angles outside a joint's range are an error of the plan
// (JointPlan::Next's *error), never clipped silently.
class JointPlan {
 public:
  // False with *error (naming the option) when `parts` has no rotator a law needs, the
  // grid is empty or not finite, or the spread is negative.
  static bool Make(const MovingParts& parts, const JointPlanOptions& options, JointPlan* plan,
                   std::string* error);
  bool Next(long long n, const Pose& pose, JointValues* joints, std::string* error);

 private:
  const MovingParts* parts_ = nullptr;
  JointPlanOptions options_;
  int rotator_first_joint_ = -1;  // index of the rotator's first joint, or -1
  std::mt19937_64 engine_;        // the prismatic joints' generator
};

}  // namespace fastcal

#endif  // FASTCAL_JOINT_PLAN_H_
