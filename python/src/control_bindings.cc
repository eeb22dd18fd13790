// fastcal.control_cycle: the control cycle (control_cycle.h) at one planned pose or along a
// trajectory of them, each warm from the one before, the loop in C++ without the GIL.
#include <cmath>
#include <string>
#include <vector>

#include "bindings.h"
#include "fastcal/cable_robot.h"
#include "fastcal/control_cycle.h"
#include "fastcal/statics.h"

namespace fastcal::python {
namespace {

// The joints as JointRows reads them (module.cc), each within the model's range: as the
// C interface and the command line refuse it (issue 57).
std::vector<JointValues> CheckedJointRows(const DoubleArray& joints, py::ssize_t n,
                                          const MovingParts& parts) {
  std::vector<JointValues> rows = JointRows(joints, n, parts.num_joints());
  const auto model_joints = parts.Joints();
  for (size_t k = 0; k < rows.size(); ++k) {
    for (int j = 0; j < parts.num_joints(); ++j) {
      std::string why;
      if (!CheckJointValue(*model_joints[j].second, rows[k][j], &why)) {
        throw InputError("joints: row " + std::to_string(k) + ", joint " + std::to_string(j) +
                         " (" + model_joints[j].second->column + "): " + why);
      }
    }
  }
  return rows;
}

py::dict ControlCycles(const CableRobot& model, const DoubleArray& positions_m,
                       const std::string& attitude_kind, const DoubleArray& attitude,
                       const DoubleArray& joints, double min_tension_kn, double max_tension_kn,
                       double min_reflector_clearance_m) {
  const CableRobot robot = model;  // a copy with the GIL held (issue 29)
  ValidateModel(robot);
  ControlLimits limits;
  limits.min_tension_n = min_tension_kn * kNPerKn;
  limits.max_tension_n = max_tension_kn * kNPerKn;
  limits.min_reflector_clearance_m = min_reflector_clearance_m;
  std::string error;
  if (!limits.IsValid(&error)) throw InputError(error);
  const std::vector<Pose> poses = PosesFromArrays(positions_m, attitude_kind, attitude);
  const auto n = static_cast<py::ssize_t>(poses.size());
  const std::vector<JointValues> q = CheckedJointRows(joints, n, robot.moving_parts);

  using Shape = std::vector<py::ssize_t>;
  DoubleArray winch(Shape{n, kNumCables}), s0(Shape{n, kNumCables}), tension(Shape{n, kNumCables}),
      sensor(Shape{n, kNumCables}), upper(Shape{n, kNumCables});
  DoubleArray error_estimate(Shape{n}), clearance(Shape{n}), min_margin(Shape{n}),
      max_margin(Shape{n});
  py::array_t<int> statics_status(n), control_status(n), cable(n);
  StaticsOptions options;
  options.warm_start = true;
  InterruptCheck interrupt;
  {
    py::gil_scoped_release release;
    ControlCycleResult r;  // reused: each cycle warm from the last
    for (py::ssize_t k = 0; k < n && !interrupt.Stop(k); ++k) {
      // The planned pose is the data's (the model's measured frame's): the cabin's follows.
      const JointValues& joints = q[static_cast<size_t>(k)];
      const ControlStatus status =
          ControlCycle(robot, robot.CabinPose(poses[static_cast<size_t>(k)], joints), joints,
                       limits, options, &r);
      statics_status.mutable_data()[k] = static_cast<int>(r.statics.status);
      control_status.mutable_data()[k] = static_cast<int>(status);
      cable.mutable_data()[k] = r.cable;
      // A statics failure has no numbers: NaN, as fastcal.solve's.
      const double none = status == ControlStatus::kStaticsFailed ? std::nan("") : 1.0;
      for (int i = 0; i < kNumCables; ++i) {
        const CableSolution& c = r.statics.cables[i];
        const py::ssize_t at = k * kNumCables + i;
        winch.mutable_data()[at] = none * r.winch_length_m[i];
        s0.mutable_data()[at] = none * c.unstretched_length_m;
        tension.mutable_data()[at] = none * c.lower_tension_n / kNPerKn;
        sensor.mutable_data()[at] = none * r.sensor_reading_n[i] / kNPerKn;
        upper.mutable_data()[at] = none * c.upper_tension_n / kNPerKn;
      }
      error_estimate.mutable_data()[k] = none * r.statics.error_estimate;
      clearance.mutable_data()[k] = none * r.statics.reflector_clearance_m;
      min_margin.mutable_data()[k] = none * r.min_tension_margin_n / kNPerKn;
      max_margin.mutable_data()[k] = none * r.max_tension_margin_n / kNPerKn;
    }
  }
  interrupt.ThrowIfInterrupted();
  py::dict out;
  out["winch_length_m"] = winch;
  out["s0_m"] = s0;
  out["tension_kN"] = tension;
  out["sensor_reading_kN"] = sensor;
  out["upper_tension_kN"] = upper;
  out["error_estimate"] = error_estimate;
  out["reflector_clearance_m"] = clearance;
  out["min_tension_margin_kN"] = min_margin;
  out["max_tension_margin_kN"] = max_margin;
  out["statics_status_code"] = statics_status;
  out["control_status_code"] = control_status;
  out["cable"] = cable;
  return out;
}

}  // namespace

void BindControl(py::module_& m) {
  m.def("control_status_names",
        [] { return EnumNames(ControlStatus::kInsideReflectorMargin, ControlStatusName); });
  m.def("control_cycle", &ControlCycles, py::arg("model"), py::arg("position_m"),
        py::arg("attitude_kind"), py::arg("attitude"), py::arg("joints"), py::arg("min_tension_kN"),
        py::arg("max_tension_kN"), py::arg("min_reflector_clearance_m"));
}

}  // namespace fastcal::python
