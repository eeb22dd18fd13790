// The cabin's moving parts (the A-B rotator, the Stewart platform): rigid parts carried by
// the cabin through chains of joints, whose mass moves the cabin's mass centre with the
// joint values q (docs/model.md "Moving parts", ../shared/design/methods.md).
//
// Part k's frame is its parent's (the cabin's for a part without one) moved to origin_m,
// then each joint applied in order, each in the frame after the one before:
//   revolute  (axis a, angle q):  R <- R Rot(a, q)
//   prismatic (axis a, shift q):  t <- t + R a q
// so the frame at q is (R_k(q), t_k(q)), with R_k(0) = I and t_k(0) the sum of the
// chain's origins. A part's centre sits at x_k in its own frame (first moment about its
// frame origin Q_k = m_k x_k, joints at zero). Its first moment about the cabin origin is
//   p_k(q) = m_k t_k(q) + R_k(q) Q_k,
// and only the sum of first moments enters the statics (paper eq. 29 with e = c(q)):
//   c(q) = c0 + sum_k (p_k(q) - p_k(0)) / M
//        = c0 + sum_k [ (R_k(q) - I) Q_k + (t_k(q) - t_k(0)) m_k ] / M           (1)
// with c0 the cabin's mass centre with every joint at zero (CableRobot's
// mass_centre_cabin_m) and M the whole cabin's mass, parts included. (1) is linear in the
// unknowns (Q_k, m_k): the calibration's columns are A_k = R_k(q) - I and
// b_k = t_k(q) - t_k(0), over M, through the statics' mass-centre partials.
// A part's first moment and mass are its own: a child's mass is not in its parent's Q.
// For the rotator + platform of the issue (rotator at the origin, platform on it with no
// first moment of its own) (1) reads c(q) = c0 + ((R - I) Q + R d m_s) / M.
#ifndef FASTCAL_MOVING_PARTS_H_
#define FASTCAL_MOVING_PARTS_H_

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace fastcal {

// Joints of all parts together, and parts, that a model may have: Sample carries a
// fixed-size array of joint values so that a sample stays free of allocation.
inline constexpr int kMaxJoints = 8;
inline constexpr int kMaxMovingParts = 4;

// Joint values of one instant, in the model's joint order (parts in file order, each
// part's joints in order) and in the joint columns' units, as the data gives them: deg
// for a revolute joint, m for a prismatic one (ShiftsAt converts to SI).
using JointValues = std::array<double, kMaxJoints>;

enum class JointType { kRevolute, kPrismatic };
const char* JointTypeName(JointType type);  // "revolute", "prismatic"

struct Joint {
  JointType type = JointType::kRevolute;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // unit, in the frame before the joint
  // The data column that gives the joint's value: ends in _deg for a revolute joint (the
  // file's unit, degrees) and in _m for a prismatic one.
  std::string column;
  // The joint's range in the column's unit (deg or m, as the model file gives it), when
  // the model states one: simulate and design stay in it, and the report draws the mass
  // centre over it.
  bool has_range = false;
  double range_low = 0.0, range_high = 0.0;
  // File unit -> SI: pi/180 for a revolute joint, 1 for a prismatic one.
  double ToSi() const;
  double RangeLowSi() const { return range_low * ToSi(); }
  double RangeHighSi() const { return range_high * ToSi(); }
};

struct MovingPart {
  std::string name;  // letters, digits, '_' and '-': it ends parameter names
  int parent = -1;   // index of an earlier part, or -1: the cabin
  std::vector<Joint> joints;
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();  // first joint's place, parent frame
  // The part's own mass times its centre, about its frame origin, in its frame, joints at
  // zero (Q_k of (1)); kg m.
  Eigen::Vector3d first_moment_kg_m = Eigen::Vector3d::Zero();
  // The part's own mass: it carries the part's shift where its frame origin moves in the
  // cabin (a prismatic joint in its chain); 0 when not given.
  double mass_kg = 0.0;
};

// The kinematic terms of (1) for one part at q: A = R_k(q) - I, b = t_k(q) - t_k(0), and
// R_k(q) itself (the report and design read it).
struct PartShift {
  Eigen::Matrix3d rotation_minus_identity = Eigen::Matrix3d::Zero();
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
};
using PartShifts = std::array<PartShift, kMaxMovingParts>;

// Part k's frame in the cabin frame at q: R_k(q), t_k(q), and t_k(0) (the sum of its
// chain's origins). The measured frame (measured_frame.h) reads it.
struct PartFrame {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d origin_at_zero_m = Eigen::Vector3d::Zero();
};
using PartFrames = std::array<PartFrame, kMaxMovingParts>;

// The cabin's moving parts, in file order (parents before children).
struct MovingParts {
  std::vector<MovingPart> parts;

  bool empty() const { return parts.empty(); }
  int num_joints() const;
  // Every joint in the model's joint order, with its part's index.
  std::vector<std::pair<int, const Joint*>> Joints() const;
  // The data columns of the joints, in the model's joint order.
  std::vector<std::string> JointColumns() const;
  // Index of the part called `name`, or -1.
  int Find(const std::string& name) const;
  // Whether part k's frame origin can move in the cabin (a prismatic joint in its chain,
  // or a revolute one above an offset origin): only then does its mass enter (1).
  bool Translates(int k) const;

  // Every part's frame at `joints` (the model's joint order, columns' units).
  void FramesAt(const JointValues& joints, PartFrames* frames) const;
  // A_k and b_k of (1) for every part at `joints` (the model's joint order, columns' units).
  void ShiftsAt(const JointValues& joints, PartShifts* shifts) const;
  // c(q) - c0 of (1) at the parts' current first moments and masses, for a cabin of
  // `cabin_mass_kg`.
  Eigen::Vector3d MassCentreShift(const PartShifts& shifts, double cabin_mass_kg) const;

  // Checks: names valid and unique, parents earlier parts, at most kMaxMovingParts parts
  // and kMaxJoints joints, axes finite and non-zero (normalised by the reader), columns
  // unique and ending in _deg (revolute) or _m (prismatic), ranges low < high, values
  // finite, masses >= 0. On failure names the key ("cabin.moving_parts[1].joints[0].axis").
  bool IsValid(std::string* error) const;
};

// A joint value read from a column named `column` (ending in _deg or _m; its unit) is
// plausible: an angle within one turn, a shift within 100 m. On failure says why.
bool PlausibleJointValue(const std::string& column, double value, std::string* error);

// A value `joint` can take (its column's unit): plausible (PlausibleJointValue) and, when
// the model states a range, within it (issue 57: Python's control_cycle and `evaluate`
// took 400 deg on a joint of +-40 deg). On failure *why (may be null) says so, with the
// digits that tell the value from the limit: "40.0000001 is outside the range [-40, 40]
// the model states for it".
bool CheckJointValue(const Joint& joint, double value, std::string* why);

// The index (the model's joint order) of the first of `joints` that CheckJointValue
// refuses, or -1. Allocates nothing: the C interface's cycle calls it.
int FirstRefusedJoint(const MovingParts& parts, const JointValues& joints);

}  // namespace fastcal

#endif  // FASTCAL_MOVING_PARTS_H_
