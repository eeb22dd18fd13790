// The forward statics of many rows in one call (locate.h; the loop in C++, without the
// GIL): lengths (n, 6), optionally a measured attitude and tensions, in; the poses, their
// tensions, stability, other equilibria and sigmas out.
#include <cmath>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "bindings.h"
#include "fastcal/cable_robot.h"
#include "fastcal/locate.h"

namespace fastcal::python {
namespace {

// `settings`: fastcal.locate's keyword arguments that set the options and the noise
// (fastcal/__init__.py passes every one, named as the fields).
void MakeLocateSettings(const py::dict& settings, LocateOptions* options, LocateNoise* noise) {
  const auto get = [&settings](const char* name, auto* field) {
    if (settings.contains(name)) {
      *field = settings[name].cast<std::remove_pointer_t<decltype(field)>>();
    }
  };
  get("warm_start", &options->warm_start);
  get("search_radius_m", &options->search_radius_m);
  get("max_strain", &options->statics.max_strain);
  get("max_length_ratio", &options->statics.max_length_ratio);
  get("min_reflector_clearance_m", &options->statics.min_reflector_clearance_m);
  get("length_sigma_m", &noise->length_sigma_m);
  get("tension_sigma_percent", &noise->tension_sigma_percent);
  double tension_sigma_kn = noise->tension_sigma_n / kNPerKn;
  get("tension_sigma_kN", &tension_sigma_kn);
  noise->tension_sigma_n = tension_sigma_kn * kNPerKn;
  get("attitude_sigma_deg", &noise->attitude_sigma_deg);
  std::string error;
  if (!options->IsValid(&error) || !noise->IsValid(&error)) throw InputError(error);
}

// The rows' measurements; an attitude (kind "rpy" or "quat") and tensions (kN, may have
// 0 rows: none) as fastcal.solve takes them.
std::vector<LocateMeasurement> Measurements(const DoubleArray& lengths_m,
                                            const std::string& attitude_kind,
                                            const DoubleArray& attitude,
                                            const DoubleArray& tensions_kn) {
  CheckRows(lengths_m, kNumCables, "lengths_m");
  const py::ssize_t n = lengths_m.shape(0);
  // PosesFromArrays checks the attitude's shape and its quaternions, row by row.
  const std::vector<Pose> attitudes = PosesFromArrays(NewArray({n, 3}), attitude_kind, attitude);
  const bool tensions = tensions_kn.ndim() == 2 && tensions_kn.shape(0) > 0;
  if (tensions) {
    CheckRows(tensions_kn, kNumCables, "tensions_kN");
    if (tensions_kn.shape(0) != n) {
      throw InputError("tensions_kN has " + std::to_string(tensions_kn.shape(0)) + " rows for " +
                       std::to_string(n) + " rows of lengths_m");
    }
  }
  std::vector<LocateMeasurement> rows(static_cast<size_t>(n));
  for (py::ssize_t k = 0; k < n; ++k) {
    LocateMeasurement& m = rows[static_cast<size_t>(k)];
    for (int i = 0; i < kNumCables; ++i) {
      m.length_m[i] = lengths_m.data()[k * kNumCables + i];
      if (tensions) m.tension_n[i] = tensions_kn.data()[k * kNumCables + i] * kNPerKn;
    }
    m.has_attitude = attitude_kind != "none";
    m.rotation = attitudes[static_cast<size_t>(k)].rotation;
    m.has_tensions = tensions;
  }
  return rows;
}

struct LocateOutputs {
  DoubleArray position_m, quat, cabin_position_m, cabin_quat, lower_kn, s0_m, covariance,
      pose_per_length, min_stiffness, nearest_other_m, chi2, error_estimate_m;
  py::array_t<int> status, stability, other_equilibria, readings;
};

// One row's answer into the arrays at index k (NaN where it failed: its status says why).
// `data`: the answer in the data's frame (the model's measured frame's; the cabin's
// without one). The covariance and pose_per_length are the data pose's: the measured
// point m = r_p + w moves by dr_p - [w]x dtheta, and the frame turns with the cabin.
void Store(const LocateSolution& s, const Pose& data, py::ssize_t k, LocateOutputs* out) {
  const bool ok = s.status == StaticsStatus::kOk;
  const double none = ok ? 1.0 : std::nan("");
  for (const auto& [pose, position, quat] :
       {std::tuple{&data, &out->position_m, &out->quat},
        std::tuple{&s.pose, &out->cabin_position_m, &out->cabin_quat}}) {
    const Eigen::Vector4d q = QuaternionFromRotation(pose->rotation);
    for (int d = 0; d < 3; ++d) position->mutable_data()[3 * k + d] = none * pose->position_m[d];
    for (int d = 0; d < 4; ++d) quat->mutable_data()[4 * k + d] = none * q[d];
  }
  Eigen::Matrix<double, 6, 6> to_data = Eigen::Matrix<double, 6, 6>::Identity();
  const Eigen::Vector3d w = data.position_m - s.pose.position_m;
  to_data.topRightCorner<3, 3>() << 0.0, w.z(), -w.y(), -w.z(), 0.0, w.x(), w.y(), -w.x(), 0.0;
  const Eigen::Matrix<double, 6, 6> covariance = to_data * s.fit.covariance * to_data.transpose();
  const Eigen::Matrix<double, 6, kNumCables> per_length = to_data * s.pose_per_length;
  for (int i = 0; i < kNumCables; ++i) {
    out->lower_kn.mutable_data()[kNumCables * k + i] =
        none * s.statics.cables[i].lower_tension_n / kNPerKn;
    out->s0_m.mutable_data()[kNumCables * k + i] = none * s.unstretched_length_m[i];
  }
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      out->covariance.mutable_data()[36 * k + 6 * r + c] = none * covariance(r, c);
      out->pose_per_length.mutable_data()[36 * k + 6 * r + c] = none * per_length(r, c);
    }
  }
  out->min_stiffness.mutable_data()[k] = none * s.min_stiffness_n_per_m / kNPerKn;
  out->nearest_other_m.mutable_data()[k] =
      ok && s.other_equilibria > 0 ? s.nearest_other.distance_m : std::nan("");
  out->chi2.mutable_data()[k] = none * s.fit.chi2;
  out->error_estimate_m.mutable_data()[k] = none * s.error_estimate_m;
  out->status.mutable_data()[k] = static_cast<int>(s.status);
  out->stability.mutable_data()[k] = static_cast<int>(s.stability);
  out->other_equilibria.mutable_data()[k] = s.other_equilibria;
  out->readings.mutable_data()[k] = s.fit.readings;
}

// The measured attitudes and the answers are the data's (the model's measured frame's,
// measured_frame.h), each row at its joints (all zero without), which also move the mass
// centre.
py::dict Locate(const CableRobot& model_argument, const DoubleArray& lengths_m,
                const std::string& attitude_kind, const DoubleArray& attitude,
                const DoubleArray& tensions_kn, const py::dict& settings,
                const DoubleArray& joints) {
  // A copy taken with the GIL held: the solves run without it while another thread may
  // assign to the model's fields (issue 37: a segfault before).
  const CableRobot robot = model_argument;
  ValidateModel(robot);
  LocateOptions options;
  LocateNoise noise;
  MakeLocateSettings(settings, &options, &noise);
  std::vector<LocateMeasurement> rows =
      Measurements(lengths_m, attitude_kind, attitude, tensions_kn);
  const auto n = static_cast<py::ssize_t>(rows.size());
  const std::vector<JointValues> q = JointRows(joints, n, robot.moving_parts.num_joints());
  // The model each row is located with: its mass centre at the row's joints, the parts
  // then fixed (Locate takes a robot), so the measured frame is converted here.
  CableRobot at = robot;
  at.moving_parts.parts.clear();
  at.measured_frame.reset();
  for (py::ssize_t k = 0; k < n; ++k) {
    Pose attitude_only;
    attitude_only.rotation = rows[static_cast<size_t>(k)].rotation;
    rows[static_cast<size_t>(k)].rotation =
        robot.CabinPose(attitude_only, q[static_cast<size_t>(k)]).rotation;
  }
  using Shape = std::vector<py::ssize_t>;
  LocateOutputs out{DoubleArray(Shape{n, 3}),
                    DoubleArray(Shape{n, 4}),
                    DoubleArray(Shape{n, 3}),
                    DoubleArray(Shape{n, 4}),
                    DoubleArray(Shape{n, kNumCables}),
                    DoubleArray(Shape{n, kNumCables}),
                    DoubleArray(Shape{n, 6, 6}),
                    DoubleArray(Shape{n, 6, kNumCables}),
                    DoubleArray(Shape{n}),
                    DoubleArray(Shape{n}),
                    DoubleArray(Shape{n}),
                    DoubleArray(Shape{n}),
                    py::array_t<int>(n),
                    py::array_t<int>(n),
                    py::array_t<int>(n),
                    py::array_t<int>(n)};
  std::vector<std::pair<py::ssize_t, std::string>> messages;
  InterruptCheck interrupt(64);  // a locate is slower than a solve
  {
    py::gil_scoped_release release;
    LocateSolution solution;  // reused: the warm start's source
    for (py::ssize_t k = 0; k < n && !interrupt.Stop(k); ++k) {
      const JointValues& joints_k = q[static_cast<size_t>(k)];
      at.mass_centre_cabin_m = robot.MassCentreAt(joints_k);
      LocateFromMeasurements(at, rows[static_cast<size_t>(k)], noise, options, &solution);
      Store(solution, robot.MeasuredPose(solution.pose, joints_k), k, &out);
      if (solution.status != StaticsStatus::kOk || solution.stability != Stability::kStable ||
          solution.other_equilibria > 0) {
        messages.emplace_back(k, DescribeLocateStatus(solution));
      }
    }
  }
  interrupt.ThrowIfInterrupted();
  py::dict result, text;
  for (const auto& [k, message] : messages) text[py::int_(k)] = message;
  result["position_m"] = out.position_m;
  result["quat"] = out.quat;
  result["cabin_position_m"] = out.cabin_position_m;
  result["cabin_quat"] = out.cabin_quat;
  result["lower_tension_kN"] = out.lower_kn;
  result["s0_m"] = out.s0_m;
  result["covariance"] = out.covariance;
  result["pose_per_length"] = out.pose_per_length;
  result["min_stiffness_kN_per_m"] = out.min_stiffness;
  result["nearest_other_m"] = out.nearest_other_m;
  result["chi2"] = out.chi2;
  result["error_estimate_m"] = out.error_estimate_m;
  result["status_code"] = out.status;
  result["stability_code"] = out.stability;
  result["other_equilibria"] = out.other_equilibria;
  result["readings"] = out.readings;
  result["messages"] = text;
  return result;
}

}  // namespace

void BindLocate(py::module_& m) {
  m.def("stability_names", [] {
    py::list names;
    for (Stability s :
         {Stability::kUnknown, Stability::kStable, Stability::kUnstable, Stability::kMarginal}) {
      names.append(StabilityName(s));
    }
    return names;
  });
  m.def("locate", &Locate, py::arg("model"), py::arg("lengths_m"), py::arg("attitude_kind"),
        py::arg("attitude"), py::arg("tensions_kN"), py::arg("settings"),
        py::arg("joints") = DoubleArray());
  m.def("rpy_deg_per_rotation_vector", [](const DoubleArray& quat) {
    const std::vector<Pose> poses =
        PosesFromArrays(NewArray({quat.ndim() == 2 ? quat.shape(0) : 0, 3}), "quat", quat);
    DoubleArray out = NewArray({static_cast<py::ssize_t>(poses.size()), 3, 3});
    for (size_t j = 0; j < poses.size(); ++j) {
      const Eigen::Matrix3d d = RpyDegPerRotationVector(poses[j].rotation);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) out.mutable_data()[9 * j + 3 * r + c] = d(r, c);
      }
    }
    return out;
  });
}

}  // namespace fastcal::python
