// fastcal's C interface (fastcal/fastcal.h): handles around the C++ statics.
//
// Every entry point is noexcept and catches what the C++ side could throw, so that no
// exception crosses into C. The cycle's calls (solve, locate, control cycle) allocate
// nothing: the handle holds the model, both warm starts and a fixed message buffer, and
// a failure's message is written with snprintf into that buffer from the status' numbers
// (not DescribeStatus, which builds a std::string). tests/capi_test.cc counts allocations
// and locks over 10^4 warm, cold and failing solves.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/control_cycle.h"
#include "fastcal/fastcal.h"
#include "fastcal/internal/units.h"
#include "fastcal/locate.h"
#include "fastcal/plausibility.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"
#include "fastcal/version.h"

using fastcal::CableRobot;
using fastcal::JointValues;
using fastcal::kNumCables;
using fastcal::StaticsSolution;
using fastcal::StaticsStatus;

struct fastcal_solver {
  CableRobot robot;
  // The same model without moving parts, its mass centre set per locate (Locate takes a
  // robot, not joints): kept here so that a locate copies nothing.
  CableRobot fixed_robot;
  bool ready = false;
  int num_joints = 0;
  std::vector<std::string> joint_names;
  // Each joint's range as the model file states it (columns' units), if it does.
  std::vector<bool> joint_has_range;
  std::vector<double> joint_low, joint_high;
  fastcal::StaticsOptions options;
  fastcal::LocateOptions locate_options;
  StaticsSolution last;   // the last ok solve: the next one's warm start
  StaticsSolution trial;  // the solve in progress (a failure leaves `last` as it was)
  fastcal::LocateSolution located;
  fastcal::LocateSolution locate_trial;
  fastcal::ControlCycleResult cycle;
  char error[512] = "";
  // Set while a call uses the handle (issue 57: two threads sharing one got each other's
  // tensions, 241 times in 400 000 calls): a second call meanwhile returns
  // FASTCAL_ERROR_BUSY without touching anything. An atomic flag, not a lock: nothing waits.
  std::atomic<bool> busy{false};
};

namespace {

using fastcal::internal::kNPerKn;  // the one kN constant (internal/units.h)
constexpr double kKnPerN = 1.0 / kNPerKn;

void SetError(fastcal_solver* s, const char* text) {
  std::snprintf(s->error, sizeof(s->error), "%s", text);
}

// "no_equilibrium: cable 3, ..." from a solution's numbers, into the handle's buffer.
void DescribeFailure(fastcal_solver* s, const char* what, const StaticsSolution& sol) {
  const char* name = fastcal::StaticsStatusName(sol.status);
  char cable[32] = "";
  if (sol.cable >= 0) std::snprintf(cable, sizeof(cable), ", cable %d", sol.cable + 1);
  const char* detail = "";
  switch (sol.status) {
    case StaticsStatus::kSaggingCable:
      detail = ": s0/k %.4g over the model's limit %.4g";
      break;
    case StaticsStatus::kOverstretchedCable:
      detail = sol.limit_value > 0.0 ? ": strain %.4g over the model's max_strain %.4g"
                                     : ": its unstretched length would be <= 0 (s0/k %.4g)";
      break;
    case StaticsStatus::kReflectorContact:
      detail = ": clearance %.4g m under %.4g m";
      break;
    case StaticsStatus::kNotConverged:
    case StaticsStatus::kInaccurate:
      detail = sol.limit > 0.0
                   ? ": error estimate %.3g over %.3g"
                   : ": neither Newton from the start nor the continuation from the home pose "
                     "found an equilibrium within their iteration bounds (a mass centre, with "
                     "the joints, beyond what the cables can hold?)";
      break;
    case StaticsStatus::kNoEquilibrium:
      detail =
          ": the equilibrium followed from the home pose ends before this pose (the "
          "cables cannot hold the cabin there with every cable pulling)";
      break;
    case StaticsStatus::kAttachmentBeyondCable:
      detail = ": an attachment at %.4g m, beyond s0 %.4g m";
      break;
    default:
      break;
  }
  char numbers[256] = "";
  if (*detail != '\0') std::snprintf(numbers, sizeof(numbers), detail, sol.limit_value, sol.limit);
  std::snprintf(s->error, sizeof(s->error), "%s: %s%s%s", what, name, cable, numbers);
}

// `value` with the fewest of 6, 10 or 17 significant digits that tell it from `limit`
// (internal::FormatBeyond's rule, without allocating: "40.0000001", not "40", beside 40).
void FormatBeyond(double value, double limit, char* out, size_t size) {
  char shown_limit[32];
  std::snprintf(shown_limit, sizeof(shown_limit), "%.6g", limit);
  for (const char* format : {"%.6g", "%.10g"}) {
    std::snprintf(out, size, format, value);
    if (std::strcmp(out, shown_limit) != 0) return;
  }
  std::snprintf(out, size, "%.17g", value);
}

// Reads the joints into *q: FASTCAL_OK, or FASTCAL_INVALID_INPUT naming the joint (the
// library's rule, fastcal::CheckJointValue: plausible and within the model's range).
int ReadJoints(fastcal_solver* s, const double* joints, JointValues* q) {
  *q = {};
  if (joints == nullptr || s->num_joints == 0) return FASTCAL_OK;
  std::copy(joints, joints + s->num_joints, q->begin());
  const int j = fastcal::FirstRefusedJoint(s->robot.moving_parts, *q);
  if (j < 0) return FASTCAL_OK;
  const std::string& name = s->joint_names[j];
  const bool angle = name.size() > 4 && name.compare(name.size() - 4, 4, "_deg") == 0;
  if (!std::isfinite((*q)[j]) || !fastcal::PlausibleJointValue(name, (*q)[j], nullptr)) {
    std::snprintf(s->error, sizeof(s->error),
                  "invalid_input: joint %d (%s) = %g is not a %s within %g", j, name.c_str(),
                  (*q)[j], angle ? "finite angle (deg)" : "finite shift (m)",
                  angle ? 360.0 : 100.0);
  } else {
    const double limit = (*q)[j] < s->joint_low[j] ? s->joint_low[j] : s->joint_high[j];
    char value[32];
    FormatBeyond((*q)[j], limit, value, sizeof(value));
    std::snprintf(s->error, sizeof(s->error),
                  "invalid_input: joint %d (%s) = %s is outside the range [%g, %g] the model "
                  "states for it",
                  j, name.c_str(), value, s->joint_low[j], s->joint_high[j]);
  }
  *q = {};
  return FASTCAL_INVALID_INPUT;
}

// A position or attitude that is not finite, or that no pose of FAST can have (issue 57:
// a position of 1e300 m answered "vertical_cable"), named: FASTCAL_INVALID_INPUT. The
// plausibility limits of the files and flags (plausibility.h), without their messages'
// strings.
int CheckPose(fastcal_solver* s, const double position_m[3], const double rpy_deg[3]) {
  for (int k = 0; k < 3; ++k) {
    const bool position = !std::isfinite(position_m[k]);
    if (position || !std::isfinite(rpy_deg[k])) {
      std::snprintf(s->error, sizeof(s->error), "invalid_input: %s[%d] = %g is not finite",
                    position ? "position_m" : "rpy_deg", k, position ? position_m[k] : rpy_deg[k]);
      return FASTCAL_INVALID_INPUT;
    }
  }
  const fastcal::PlausibilityLimits limits;
  const double rho = std::hypot(position_m[0], position_m[1]);
  const double lowest = fastcal::LowestPlausibleZ(rho, limits);
  if (!(rho <= limits.max_horizontal_radius_m) || !(position_m[2] <= limits.max_height_m) ||
      !(position_m[2] >= lowest)) {
    std::snprintf(s->error, sizeof(s->error),
                  "invalid_input: position_m (%g, %g, %g) is not a place the cabin can be: "
                  "within %g m of the axis, z from %g m (the reflector there) to %g m",
                  position_m[0], position_m[1], position_m[2], limits.max_horizontal_radius_m,
                  lowest, limits.max_height_m);
    return FASTCAL_INVALID_INPUT;
  }
  for (int k = 0; k < 3; ++k) {
    if (!(std::fabs(rpy_deg[k]) <= limits.max_abs_angle_deg)) {
      std::snprintf(s->error, sizeof(s->error),
                    "invalid_input: rpy_deg[%d] = %g is beyond the plausible +-%g deg", k,
                    rpy_deg[k], limits.max_abs_angle_deg);
      return FASTCAL_INVALID_INPUT;
    }
  }
  return FASTCAL_OK;
}

void Zero(double* a, int n) {
  if (a != nullptr) std::fill(a, a + n, 0.0);
}

fastcal::Pose PoseOf(const double position_m[3], const double rpy_deg[3]) {
  fastcal::Pose pose;
  pose.position_m = Eigen::Vector3d(position_m[0], position_m[1], position_m[2]);
  pose.rotation = fastcal::RotationFromRpyDeg(rpy_deg[0], rpy_deg[1], rpy_deg[2]);
  return pose;
}

// A call's hold on its handle (fastcal_solver::busy) for its duration, if no other call
// has it.
class Claim {
 public:
  explicit Claim(fastcal_solver* s)
      : s_(s), held_(s != nullptr && !s->busy.exchange(true, std::memory_order_acquire)) {}
  Claim(const Claim&) = delete;
  Claim& operator=(const Claim&) = delete;
  ~Claim() {
    if (held_) s_->busy.store(false, std::memory_order_release);
  }
  bool held() const { return held_; }

 private:
  fastcal_solver* s_;
  bool held_;
};

// An input array copied before any output is written, since outputs may overlap it
// (issue 57: fastcal_solve_pose(s, buf, buf + 3, NULL, buf, NULL) solved at (0, 0, 0):
// zeroing the tensions zeroed the position). `p` is null for a null input.
template <int N>
struct InputCopy {
  InputCopy(const double* from, int count = N) {
    if (from == nullptr) return;
    std::copy(from, from + std::min(count, N), v);
    p = v;
  }
  double v[N] = {};
  const double* p = nullptr;
};

// The joint values a handle's calls read (0 for a handle without a model): fixed at
// creation, so read without the call's claim.
int JointsOf(const fastcal_solver* s) { return s != nullptr && s->ready ? s->num_joints : 0; }

// Common entry checks: a handle, no other call on it, a loaded model, the arrays.
int Enter(fastcal_solver* s, const Claim& claim, bool arrays_given) {
  if (s == nullptr) return FASTCAL_ERROR_NULL_ARGUMENT;
  if (!claim.held()) return FASTCAL_ERROR_BUSY;  // the other call's state left alone
  if (!s->ready) return FASTCAL_ERROR_NO_MODEL;  // the creation's message stays
  if (!arrays_given) {
    SetError(s, "null_argument: a required array is NULL");
    return FASTCAL_ERROR_NULL_ARGUMENT;
  }
  s->error[0] = '\0';
  return FASTCAL_OK;
}

// Enter for a call that fills a struct (fastcal_statics, fastcal_cycle): the struct is
// zeroed first (cable -1), and carries the status of a refused call.
template <typename Out>
int EnterWithStruct(fastcal_solver* s, const Claim& claim, bool arrays_given, Out* out) {
  if (out != nullptr) {
    std::memset(out, 0, sizeof(*out));
    out->cable = -1;
  }
  const int e = Enter(s, claim, arrays_given && out != nullptr);
  if (e != 0 && out != nullptr) out->status = e;
  return e;
}

// The exact statics at a pose, warm from s->last; on ok, s->last is the answer.
int Solve(fastcal_solver* s, const double position_m[3], const double rpy_deg[3],
          const double* joints) {
  if (const int status = CheckPose(s, position_m, rpy_deg); status != FASTCAL_OK) return status;
  JointValues q;
  if (const int status = ReadJoints(s, joints, &q); status != FASTCAL_OK) return status;
  s->trial = s->last;
  // The pose given is the data's (the model's measured frame's): the cabin's follows.
  const StaticsStatus status = fastcal::SolveStatics(
      s->robot, s->robot.CabinPose(PoseOf(position_m, rpy_deg), q), q, s->options, &s->trial);
  if (status != StaticsStatus::kOk) {
    DescribeFailure(s, "solve", s->trial);
    return static_cast<int>(status);
  }
  s->last = s->trial;
  return FASTCAL_OK;
}

void FillStatics(const StaticsSolution& sol, int status, fastcal_statics* out) {
  std::memset(out, 0, sizeof(*out));
  out->status = status;
  out->cable = sol.cable;
  out->iterations = sol.outer_iterations;
  out->continuation = sol.continuation ? 1 : 0;
  if (status != FASTCAL_OK) return;
  for (int i = 0; i < kNumCables; ++i) {
    const fastcal::CableSolution& c = sol.cables[i];
    out->tension_kN[i] = c.lower_tension_n * kKnPerN;
    out->upper_tension_kN[i] = c.upper_tension_n * kKnPerN;
    for (int k = 0; k < 3; ++k) out->force_kN[i][k] = c.force_n[k] * kKnPerN;
    out->unstretched_m[i] = c.unstretched_length_m;
  }
  out->error_estimate = sol.error_estimate;
  out->reflector_clearance_m = sol.reflector_clearance_m;
}

}  // namespace

extern "C" {

const char* fastcal_version(void) { return FASTCAL_VERSION; }

const char* fastcal_status_name(int status) {
  if (status >= 0 && status <= static_cast<int>(fastcal::kLastStaticsStatus)) {
    return fastcal::StaticsStatusName(static_cast<StaticsStatus>(status));
  }
  switch (status) {
    case FASTCAL_BELOW_MIN_TENSION:
      return "below_min_tension";
    case FASTCAL_ABOVE_MAX_TENSION:
      return "above_max_tension";
    case FASTCAL_INSIDE_REFLECTOR_MARGIN:
      return "inside_reflector_margin";
    case FASTCAL_ERROR_NULL_ARGUMENT:
      return "null_argument";
    case FASTCAL_ERROR_NO_MODEL:
      return "no_model";
    case FASTCAL_ERROR_BAD_LIMITS:
      return "bad_limits";
    case FASTCAL_ERROR_INTERNAL:
      return "internal_error";
    case FASTCAL_ERROR_BUSY:
      return "busy";
    default:
      return "unknown";
  }
}

fastcal_solver* fastcal_solver_create(const char* model_path) {
  fastcal_solver* s = new (std::nothrow) fastcal_solver;
  if (s == nullptr) return nullptr;
  try {
    std::string error;
    if (model_path == nullptr) {
      s->robot = CableRobot::NominalFast();
    } else if (!fastcal::LoadCableRobot(model_path, &s->robot, &error)) {
      SetError(s, error.c_str());
      return s;
    }
    s->num_joints = s->robot.moving_parts.num_joints();
    s->joint_names = s->robot.moving_parts.JointColumns();
    for (const auto& [part, joint] : s->robot.moving_parts.Joints()) {
      s->joint_has_range.push_back(joint->has_range);
      s->joint_low.push_back(joint->range_low);
      s->joint_high.push_back(joint->range_high);
    }
    s->fixed_robot = s->robot;
    s->fixed_robot.moving_parts = {};
    s->fixed_robot.measured_frame.reset();  // its part is gone: poses convert with `robot`
    s->options.warm_start = true;
    s->locate_options.warm_start = true;
    // A controller asks for the pose, not for other equilibria near it: the search's 12
    // extra Newton runs would only add time (fastcal locate reports them).
    s->locate_options.search_radius_m = 0.0;
    s->locate_options.statics = s->options;
    s->locate_options.statics.warm_start = false;
    s->ready = true;
  } catch (const std::exception& e) {
    SetError(s, e.what());
  } catch (...) {
    SetError(s, "fastcal_solver_create: unknown exception");
  }
  return s;
}

const char* fastcal_solver_error(const fastcal_solver* s) {
  return s == nullptr ? "null_argument: the fastcal_solver handle is NULL "
                        "(fastcal_solver_create returns NULL only when out of memory)"
                      : s->error;
}

int fastcal_solver_num_joints(const fastcal_solver* s) {
  return s == nullptr || !s->ready ? 0 : s->num_joints;
}

const char* fastcal_solver_joint_name(const fastcal_solver* s, int j) {
  if (s == nullptr || !s->ready || j < 0 || j >= s->num_joints) return nullptr;
  return s->joint_names[j].c_str();
}

void fastcal_solver_reset(fastcal_solver* s) {
  const Claim claim(s);
  if (!claim.held()) return;  // NULL, or another call using the handle: nothing to reset
  s->last.status = StaticsStatus::kInvalidInput;
  s->located.status = StaticsStatus::kInvalidInput;
  s->cycle.statics.status = StaticsStatus::kInvalidInput;
}

void fastcal_solver_destroy(fastcal_solver* s) { delete s; }

int fastcal_solve_pose(fastcal_solver* s, const double position_m[3], const double rpy_deg[3],
                       const double* joints, double tension_kN[6], double unstretched_m[6]) {
  const InputCopy<3> position(position_m), rpy(rpy_deg);
  const InputCopy<FASTCAL_MAX_JOINTS> q(joints, JointsOf(s));
  Zero(tension_kN, kNumCables);
  Zero(unstretched_m, kNumCables);
  const Claim claim(s);
  if (const int e = Enter(s, claim, position.p && rpy.p); e != 0) return e;
  try {
    const int status = Solve(s, position.p, rpy.p, q.p);
    if (status != FASTCAL_OK) return status;
    for (int i = 0; i < kNumCables; ++i) {
      if (tension_kN != nullptr) tension_kN[i] = s->last.cables[i].lower_tension_n * kKnPerN;
      if (unstretched_m != nullptr) unstretched_m[i] = s->last.cables[i].unstretched_length_m;
    }
    return FASTCAL_OK;
  } catch (...) {
    SetError(s, "internal_error: an exception in fastcal_solve_pose");
    return FASTCAL_ERROR_INTERNAL;
  }
}

int fastcal_solve_pose_full(fastcal_solver* s, const double position_m[3], const double rpy_deg[3],
                            const double* joints, fastcal_statics* out) {
  const InputCopy<3> position(position_m), rpy(rpy_deg);
  const InputCopy<FASTCAL_MAX_JOINTS> q(joints, JointsOf(s));
  const Claim claim(s);
  if (const int e = EnterWithStruct(s, claim, position.p && rpy.p, out); e != 0) return e;
  try {
    const int status = Solve(s, position.p, rpy.p, q.p);
    FillStatics(status == FASTCAL_OK ? s->last : s->trial, status, out);
    if (status == FASTCAL_INVALID_INPUT) {  // refused before a solve: nothing of one
      out->cable = -1;
      out->iterations = out->continuation = 0;
    }
    return status;
  } catch (...) {
    SetError(s, "internal_error: an exception in fastcal_solve_pose_full");
    return FASTCAL_ERROR_INTERNAL;
  }
}

int fastcal_locate(fastcal_solver* s, const double unstretched_m[6], const double* joints,
                   double position_m[3], double rpy_deg[3], double tension_kN[6]) {
  const InputCopy<kNumCables> given(unstretched_m);
  const InputCopy<FASTCAL_MAX_JOINTS> joint_values(joints, JointsOf(s));
  Zero(position_m, 3);
  Zero(rpy_deg, 3);
  Zero(tension_kN, kNumCables);
  const Claim claim(s);
  if (const int e = Enter(s, claim, given.p && position_m && rpy_deg); e != 0) return e;
  try {
    JointValues q;
    if (const int status = ReadJoints(s, joint_values.p, &q); status != FASTCAL_OK) return status;
    s->fixed_robot.mass_centre_cabin_m = s->robot.MassCentreAt(q);
    std::array<double, kNumCables> lengths;
    std::copy(given.v, given.v + kNumCables, lengths.begin());
    s->locate_trial = s->located;
    const StaticsStatus status =
        fastcal::Locate(s->fixed_robot, lengths, s->locate_options, &s->locate_trial);
    if (status != StaticsStatus::kOk) {
      if (status == StaticsStatus::kInvalidInput) {
        SetError(s, "invalid_input: a length is not finite or not > 0 (unstretched_m, m)");
      } else {
        DescribeFailure(s, "locate", s->locate_trial.statics);
      }
      return static_cast<int>(status);
    }
    s->located = s->locate_trial;
    // The answer in the data's frame (the model's measured frame), as the solves take it.
    const fastcal::Pose pose = s->robot.MeasuredPose(s->located.pose, q);
    const Eigen::Vector3d rpy = fastcal::RpyDegFromRotation(pose.rotation);
    for (int k = 0; k < 3; ++k) {
      position_m[k] = pose.position_m[k];
      rpy_deg[k] = rpy[k];
    }
    if (tension_kN != nullptr) {
      for (int i = 0; i < kNumCables; ++i) {
        tension_kN[i] = s->located.statics.cables[i].lower_tension_n * kKnPerN;
      }
    }
    return FASTCAL_OK;
  } catch (...) {
    SetError(s, "internal_error: an exception in fastcal_locate");
    return FASTCAL_ERROR_INTERNAL;
  }
}

int fastcal_locate_winch(fastcal_solver* s, const double winch_length_m[6], const double* joints,
                         double position_m[3], double rpy_deg[3], double tension_kN[6]) {
  double unstretched_m[kNumCables];
  const bool ready = s != nullptr && s->ready && winch_length_m != nullptr;
  for (int i = 0; i < kNumCables; ++i) {
    unstretched_m[i] = ready ? winch_length_m[i] - s->robot.cables[i].length_offset_m : 0.0;
  }
  return fastcal_locate(s, winch_length_m != nullptr ? unstretched_m : nullptr, joints, position_m,
                        rpy_deg, tension_kN);
}

int fastcal_cabin_pose(fastcal_solver* s, const double position_m[3], const double rpy_deg[3],
                       const double* joints, double cabin_position_m[3], double cabin_rpy_deg[3]) {
  // Inputs copied before the outputs are zeroed: the outputs may alias them (issue 57).
  const InputCopy<3> position(position_m), rpy(rpy_deg);
  const InputCopy<FASTCAL_MAX_JOINTS> joint_copy(joints, JointsOf(s));
  Zero(cabin_position_m, 3);
  Zero(cabin_rpy_deg, 3);
  const Claim claim(s);
  if (const int e = Enter(s, claim, position.p && rpy.p && cabin_position_m && cabin_rpy_deg);
      e != 0) {
    return e;
  }
  try {
    if (const int status = CheckPose(s, position.p, rpy.p); status != FASTCAL_OK) return status;
    JointValues q;
    if (const int status = ReadJoints(s, joint_copy.p, &q); status != FASTCAL_OK) return status;
    const fastcal::Pose cabin = s->robot.CabinPose(PoseOf(position.p, rpy.p), q);
    const Eigen::Vector3d rpy = fastcal::RpyDegFromRotation(cabin.rotation);
    for (int k = 0; k < 3; ++k) {
      cabin_position_m[k] = cabin.position_m[k];
      cabin_rpy_deg[k] = rpy[k];
    }
    return FASTCAL_OK;
  } catch (...) {
    SetError(s, "internal_error: an exception in fastcal_cabin_pose");
    return FASTCAL_ERROR_INTERNAL;
  }
}

int fastcal_solver_sensors(const fastcal_solver* s, double length_offset_m[6],
                           double sensor_gain[6], double sensor_bias_kN[6]) {
  Zero(length_offset_m, kNumCables);
  Zero(sensor_gain, kNumCables);
  Zero(sensor_bias_kN, kNumCables);
  if (s == nullptr) return FASTCAL_ERROR_NULL_ARGUMENT;
  if (!s->ready) return FASTCAL_ERROR_NO_MODEL;
  for (int i = 0; i < kNumCables; ++i) {
    const fastcal::CableProperties& c = s->robot.cables[i];
    if (length_offset_m != nullptr) length_offset_m[i] = c.length_offset_m;
    if (sensor_gain != nullptr) sensor_gain[i] = c.sensor_gain;
    if (sensor_bias_kN != nullptr) sensor_bias_kN[i] = c.sensor_bias_n * kKnPerN;
  }
  return FASTCAL_OK;
}

fastcal_cycle_limits fastcal_default_cycle_limits(void) {
  const fastcal::ControlLimits d;
  return {d.min_tension_n * kKnPerN, d.max_tension_n * kKnPerN, d.min_reflector_clearance_m};
}

int fastcal_control_cycle(fastcal_solver* s, const double position_m[3], const double rpy_deg[3],
                          const double* joints, const fastcal_cycle_limits* limits,
                          fastcal_cycle* out) {
  const InputCopy<3> position(position_m), rpy(rpy_deg);
  const InputCopy<FASTCAL_MAX_JOINTS> joint_values(joints, JointsOf(s));
  const Claim claim(s);
  if (const int e = EnterWithStruct(s, claim, position.p && rpy.p, out); e != 0) return e;
  try {
    fastcal::ControlLimits lim;
    if (limits != nullptr) {
      lim.min_tension_n = limits->min_tension_kN * kNPerKn;
      lim.max_tension_n = limits->max_tension_kN * kNPerKn;
      lim.min_reflector_clearance_m = limits->min_reflector_clearance_m;
      if (!lim.IsValid(nullptr)) {
        std::snprintf(s->error, sizeof(s->error),
                      "bad_limits: min_tension_kN %g (finite, >= 0), max_tension_kN %g "
                      "(> min), min_reflector_clearance_m %g (finite, >= 0); start from "
                      "fastcal_default_cycle_limits()",
                      limits->min_tension_kN, limits->max_tension_kN,
                      limits->min_reflector_clearance_m);
        return out->status = FASTCAL_ERROR_BAD_LIMITS;
      }
    }
    if (const int status = CheckPose(s, position.p, rpy.p); status != FASTCAL_OK) {
      return out->status = status;
    }
    JointValues q;
    if (const int status = ReadJoints(s, joint_values.p, &q); status != FASTCAL_OK) {
      return out->status = status;
    }
    // Warm from the handle's last solve, whichever call made it.
    s->cycle.statics = s->last;
    const fastcal::ControlStatus status =
        fastcal::ControlCycle(s->robot, s->robot.CabinPose(PoseOf(position.p, rpy.p), q), q, lim,
                              s->options, &s->cycle);
    const fastcal::ControlCycleResult& r = s->cycle;
    out->cable = r.cable;
    if (status == fastcal::ControlStatus::kStaticsFailed) {
      DescribeFailure(s, "control cycle", r.statics);
      return out->status = static_cast<int>(r.statics.status);
    }
    s->last = r.statics;
    for (int i = 0; i < kNumCables; ++i) {
      const fastcal::CableSolution& c = r.statics.cables[i];
      out->winch_length_m[i] = r.winch_length_m[i];
      out->unstretched_m[i] = c.unstretched_length_m;
      out->tension_kN[i] = c.lower_tension_n * kKnPerN;
      out->sensor_reading_kN[i] = r.sensor_reading_n[i] * kKnPerN;
      out->upper_tension_kN[i] = c.upper_tension_n * kKnPerN;
    }
    out->error_estimate = r.statics.error_estimate;
    out->reflector_clearance_m = r.statics.reflector_clearance_m;
    out->min_tension_margin_kN = r.min_tension_margin_n * kKnPerN;
    out->max_tension_margin_kN = r.max_tension_margin_n * kKnPerN;
    switch (status) {
      case fastcal::ControlStatus::kBelowMinTension:
        out->status = FASTCAL_BELOW_MIN_TENSION;
        std::snprintf(s->error, sizeof(s->error),
                      "below_min_tension: cable %d at %.4g kN, under %.4g kN", r.cable + 1,
                      out->tension_kN[r.cable], lim.min_tension_n * kKnPerN);
        break;
      case fastcal::ControlStatus::kAboveMaxTension:
        out->status = FASTCAL_ABOVE_MAX_TENSION;
        std::snprintf(s->error, sizeof(s->error),
                      "above_max_tension: cable %d over %.4g kN by %.4g kN", r.cable + 1,
                      lim.max_tension_n * kKnPerN, -out->max_tension_margin_kN);
        break;
      case fastcal::ControlStatus::kInsideReflectorMargin:
        out->status = FASTCAL_INSIDE_REFLECTOR_MARGIN;
        std::snprintf(s->error, sizeof(s->error),
                      "inside_reflector_margin: a cable %.3g m from the reflector, under %.3g m",
                      out->reflector_clearance_m, lim.min_reflector_clearance_m);
        break;
      default:
        out->status = FASTCAL_OK;
    }
    return out->status;
  } catch (...) {
    SetError(s, "internal_error: an exception in fastcal_control_cycle");
    return FASTCAL_ERROR_INTERNAL;
  }
}

}  // extern "C"
