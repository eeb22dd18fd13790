// The cabin's moving parts: joint kinematics and the mass-centre shift, eq. (1) of
// moving_parts.h (c(q) = c0 + sum_k [(R_k(q) - I) Q_k + (t_k(q) - t_k(0)) m_k] / M).
#include "fastcal/moving_parts.h"

#include <Eigen/Geometry>
#include <cctype>
#include <cmath>
#include <set>

#include "fastcal/internal/dataset_column_names.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A revolute joint beyond one turn, or a prismatic one beyond 100 m, is a unit slip.
constexpr double kMaxPlausibleAngleDeg = 360.0;
constexpr double kMaxPlausibleShiftM = 100.0;

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() > suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool ValidName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') return false;
  }
  return true;
}

// A column name: a letter first, then letters, digits and '_'.
bool ValidColumn(const std::string& name) {
  if (name.empty() || !std::isalpha(static_cast<unsigned char>(name[0]))) return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  }
  return true;
}

}  // namespace

const char* JointTypeName(JointType type) {
  return type == JointType::kRevolute ? "revolute" : "prismatic";
}

double Joint::ToSi() const { return type == JointType::kRevolute ? kPi / 180.0 : 1.0; }

int MovingParts::num_joints() const {
  int n = 0;
  for (const MovingPart& p : parts) n += static_cast<int>(p.joints.size());
  return n;
}

std::vector<std::pair<int, const Joint*>> MovingParts::Joints() const {
  std::vector<std::pair<int, const Joint*>> out;
  for (size_t k = 0; k < parts.size(); ++k) {
    for (const Joint& j : parts[k].joints) out.emplace_back(static_cast<int>(k), &j);
  }
  return out;
}

std::vector<std::string> MovingParts::JointColumns() const {
  std::vector<std::string> out;
  for (const MovingPart& p : parts) {
    for (const Joint& j : p.joints) out.push_back(j.column);
  }
  return out;
}

int MovingParts::Find(const std::string& name) const {
  for (size_t k = 0; k < parts.size(); ++k) {
    if (parts[k].name == name) return static_cast<int>(k);
  }
  return -1;
}

bool MovingParts::Translates(int k) const {
  bool below_a_joint = false;  // an ancestor (or this part) has a joint above this origin
  for (int a = k; a >= 0; a = parts[a].parent) {
    for (const Joint& j : parts[a].joints) {
      if (j.type == JointType::kPrismatic) return true;
    }
    if (a != k && !parts[a].joints.empty()) below_a_joint = true;
  }
  // A revolute joint above the part swings its origin when that origin is off the axis.
  if (!below_a_joint) return false;
  for (int a = k; a >= 0 && parts[a].parent >= 0; a = parts[a].parent) {
    if (parts[a].origin_m.norm() > 0.0) return true;
  }
  return false;
}

void MovingParts::FramesAt(const JointValues& joints, PartFrames* frames) const {
  // Frames in file order: a parent's is ready before its children's (IsValid).
  int next = 0;
  for (size_t k = 0; k < parts.size(); ++k) {
    const MovingPart& part = parts[k];
    PartFrame& f = (*frames)[k];
    f.rotation.setIdentity();
    f.origin_m = part.origin_m;
    f.origin_at_zero_m = part.origin_m;
    if (part.parent >= 0) {
      const PartFrame& parent = (*frames)[part.parent];
      f.rotation = parent.rotation;
      f.origin_m = parent.origin_m + parent.rotation * part.origin_m;
      f.origin_at_zero_m = parent.origin_at_zero_m + part.origin_m;
    }
    for (const Joint& j : part.joints) {
      const double q = joints[next++] * j.ToSi();
      if (j.type == JointType::kRevolute) {
        f.rotation = f.rotation * Eigen::AngleAxisd(q, j.axis).toRotationMatrix();
      } else {
        f.origin_m += f.rotation * (j.axis * q);
      }
    }
  }
}

void MovingParts::ShiftsAt(const JointValues& joints, PartShifts* shifts) const {
  PartFrames frames;
  FramesAt(joints, &frames);
  for (size_t k = 0; k < parts.size(); ++k) {
    (*shifts)[k].rotation_minus_identity = frames[k].rotation - Eigen::Matrix3d::Identity();
    (*shifts)[k].translation_m = frames[k].origin_m - frames[k].origin_at_zero_m;
  }
}

Eigen::Vector3d MovingParts::MassCentreShift(const PartShifts& shifts, double cabin_mass_kg) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < parts.size(); ++k) {
    sum += shifts[k].rotation_minus_identity * parts[k].first_moment_kg_m +
           shifts[k].translation_m * parts[k].mass_kg;
  }
  return sum / cabin_mass_kg;
}

bool MovingParts::IsValid(std::string* error) const {
  auto fail = [&](const std::string& key, const std::string& why) {
    if (error != nullptr) *error = key + ": " + why;
    return false;
  };
  const std::string list = "cabin.moving_parts";
  if (parts.size() > static_cast<size_t>(kMaxMovingParts)) {
    return fail(list, "has " + std::to_string(parts.size()) + " parts; at most " +
                          std::to_string(kMaxMovingParts) + " are supported");
  }
  if (num_joints() > kMaxJoints) {
    return fail(list, "has " + std::to_string(num_joints()) + " joints; at most " +
                          std::to_string(kMaxJoints) + " in all are supported");
  }
  std::set<std::string> names, columns;
  for (size_t k = 0; k < parts.size(); ++k) {
    const MovingPart& p = parts[k];
    const std::string key = list + "[" + std::to_string(k) + "]";
    if (!ValidName(p.name)) {
      return fail(key + ".name", "must be 1 to 64 letters, digits, '_' or '-'");
    }
    if (!names.insert(p.name).second) return fail(key + ".name", "'" + p.name + "' is given twice");
    if (p.parent >= static_cast<int>(k) || p.parent < -1) {
      return fail(key + ".parent", "must name a part listed before this one");
    }
    if (!p.origin_m.allFinite()) return fail(key + ".origin_m", "must be finite");
    if (!p.first_moment_kg_m.allFinite()) return fail(key + ".first_moment_kg_m", "must be finite");
    if (!(p.mass_kg >= 0.0) || !std::isfinite(p.mass_kg))
      return fail(key + ".mass_kg", "must be >= 0");
    for (size_t j = 0; j < p.joints.size(); ++j) {
      const Joint& joint = p.joints[j];
      const std::string jkey = key + ".joints[" + std::to_string(j) + "]";
      if (!joint.axis.allFinite() || !(joint.axis.norm() > 0.0)) {
        return fail(jkey + ".axis", "must be a finite, non-zero vector");
      }
      const char* suffix = joint.type == JointType::kRevolute ? "_deg" : "_m";
      if (!ValidColumn(joint.column) || !EndsWith(joint.column, suffix)) {
        return fail(jkey + ".column", std::string("a ") + JointTypeName(joint.type) +
                                          " joint's column is a name (letters, digits, '_') "
                                          "ending in " +
                                          suffix + ", got '" + joint.column + "'");
      }
      if (internal::IsDatasetColumnName(joint.column)) {
        return fail(jkey + ".column",
                    "'" + joint.column +
                        "' is a column of the dataset itself (docs/data-format.md); "
                        "a joint's column needs a name of its own");
      }
      if (!columns.insert(joint.column).second) {
        return fail(jkey + ".column", "'" + joint.column + "' is used by another joint");
      }
      if (joint.has_range && !(std::isfinite(joint.range_low) && std::isfinite(joint.range_high) &&
                               joint.range_low < joint.range_high)) {
        return fail(jkey + ".range", "must be [low, high] with low < high, finite");
      }
    }
  }
  return true;
}

bool PlausibleJointValue(const std::string& column, double value, std::string* error) {
  const bool angle = EndsWith(column, "_deg");
  const double limit = angle ? kMaxPlausibleAngleDeg : kMaxPlausibleShiftM;
  if (std::isfinite(value) && std::abs(value) <= limit) return true;
  if (error != nullptr) {
    *error = angle ? "a joint angle beyond one turn (360 deg) is not plausible"
                   : "a joint shift beyond 100 m is not plausible";
  }
  return false;
}

bool CheckJointValue(const Joint& joint, double value, std::string* why) {
  if (!PlausibleJointValue(joint.column, value, why)) return false;
  if (!joint.has_range || (value >= joint.range_low && value <= joint.range_high)) return true;
  if (why != nullptr) {
    const double limit = value < joint.range_low ? joint.range_low : joint.range_high;
    *why = internal::FormatBeyond(value, limit) + " is outside the range [" +
           internal::FormatDouble("%.6g", joint.range_low) + ", " +
           internal::FormatDouble("%.6g", joint.range_high) + "] the model states for it";
  }
  return false;
}

int FirstRefusedJoint(const MovingParts& parts, const JointValues& joints) {
  int j = 0;
  for (const MovingPart& part : parts.parts) {
    for (const Joint& joint : part.joints) {
      if (!CheckJointValue(joint, joints[j], nullptr)) return j;
      ++j;
    }
  }
  return -1;
}

}  // namespace fastcal
