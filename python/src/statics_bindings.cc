// Statics of many poses in one call (the loop in C++, without the GIL), the trajectory
// generators and the focal attitude law (statics.h, trajectory.h, pose.h).
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "bindings.h"
#include "fastcal/cable.h"
#include "fastcal/cable_robot.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"

namespace fastcal::python {
namespace {

// `settings`: the keyword arguments of fastcal.solve that set StaticsOptions (their
// names are the fields'; fastcal/__init__.py passes every one).
StaticsOptions MakeStaticsOptions(const std::string& method, const py::dict& settings) {
  StaticsOptions options;
  if (!ParseStaticsMethod(method, &options.method)) {
    throw InputError("method must be 'aas', 'aas-refined' or 'exact', got '" + method + "'");
  }
  const auto get = [&settings](const char* name, auto* field) {
    if (settings.contains(name)) {
      *field = settings[name].cast<std::remove_pointer_t<decltype(field)>>();
    }
  };
  get("warm_start", &options.warm_start);
  get("max_refinement_steps", &options.max_refinement_steps);
  get("refined_relative_tolerance", &options.refined_relative_tolerance);
  get("aas_max_relative_error", &options.aas_max_relative_error);
  get("exact_relative_tolerance", &options.exact_relative_tolerance);
  get("max_strain", &options.max_strain);
  get("max_length_ratio", &options.max_length_ratio);
  get("min_reflector_clearance_m", &options.min_reflector_clearance_m);
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  return options;
}

// Per-pose outputs, written straight into the arrays numpy will own.
struct SolveOutputs {
  DoubleArray lower_kn, upper_kn, s0_m, force_kn, chord_m, end_residual_m, error_estimate;
  py::array_t<int> status, cable;
  py::dict failures;  // pose index -> DescribeStatus, for the failed poses only
};

// The poses are the data's (the model's measured frame's, measured_frame.h), each solved
// at the cabin's pose and mass centre that follow from its joints (all zero without).
py::dict Solve(const CableRobot& model, const DoubleArray& positions_m,
               const std::string& attitude_kind, const DoubleArray& attitude,
               const std::string& method, const py::dict& settings, const DoubleArray& joints) {
  // A copy, taken with the GIL held: the loop below runs without it, while another
  // thread may assign to the model's fields (issue 29: a crash in the statics).
  const CableRobot robot = model;
  ValidateModel(robot);
  const StaticsOptions options = MakeStaticsOptions(method, settings);
  const std::vector<Pose> poses = PosesFromArrays(positions_m, attitude_kind, attitude);
  const auto n = static_cast<py::ssize_t>(poses.size());
  const std::vector<JointValues> q = JointRows(joints, n, robot.moving_parts.num_joints());
  // Every element is written below: no zero-filling.
  using Shape = std::vector<py::ssize_t>;
  SolveOutputs out{DoubleArray(Shape{n, kNumCables}),
                   DoubleArray(Shape{n, kNumCables}),
                   DoubleArray(Shape{n, kNumCables}),
                   DoubleArray(Shape{n, kNumCables, 3}),
                   DoubleArray(Shape{n, kNumCables}),
                   DoubleArray(Shape{n}),
                   DoubleArray(Shape{n}),
                   py::array_t<int>(n),
                   py::array_t<int>(n),
                   py::dict()};
  double* lower = out.lower_kn.mutable_data();
  double* upper = out.upper_kn.mutable_data();
  double* s0 = out.s0_m.mutable_data();
  double* force = out.force_kn.mutable_data();
  double* chord = out.chord_m.mutable_data();
  double* end_residual = out.end_residual_m.mutable_data();
  double* error_estimate = out.error_estimate.mutable_data();
  int* status = out.status.mutable_data();
  int* cable = out.cable.mutable_data();
  std::vector<std::pair<py::ssize_t, std::string>> failed;
  InterruptCheck interrupt;
  {
    py::gil_scoped_release release;
    StaticsSolution solution;  // reused: no allocation per pose, and the warm start's source
    for (py::ssize_t k = 0; k < n && !interrupt.Stop(k); ++k) {
      const JointValues& at = q[static_cast<size_t>(k)];
      const StaticsStatus s = SolveStatics(
          robot, robot.CabinPose(poses[static_cast<size_t>(k)], at), at, options, &solution);
      status[k] = static_cast<int>(s);
      cable[k] = solution.cable;
      end_residual[k] = solution.end_residual_m;
      error_estimate[k] = solution.error_estimate;
      if (s != StaticsStatus::kOk) failed.emplace_back(k, DescribeStatus(solution));
      // A pose the cables cannot hold has no tensions: NaN, so that a mean or a plot
      // over the poses shows the gap instead of averaging in a 0 (its status says why).
      const double none = s == StaticsStatus::kOk ? 1.0 : std::nan("");
      for (int i = 0; i < kNumCables; ++i) {
        const CableSolution& c = solution.cables[i];
        const py::ssize_t at = k * kNumCables + i;
        lower[at] = none * c.lower_tension_n / kNPerKn;
        upper[at] = none * c.upper_tension_n / kNPerKn;
        s0[at] = none * c.unstretched_length_m;
        chord[at] = c.chord_length_m;
        for (int d = 0; d < 3; ++d) force[3 * at + d] = none * c.force_n[d] / kNPerKn;
      }
    }
  }
  interrupt.ThrowIfInterrupted();
  for (const auto& [k, text] : failed) out.failures[py::int_(k)] = text;
  py::dict result;
  result["lower_tension_kN"] = out.lower_kn;
  result["upper_tension_kN"] = out.upper_kn;
  result["s0_m"] = out.s0_m;
  result["force_kN"] = out.force_kn;
  result["chord_m"] = out.chord_m;
  result["end_residual_m"] = out.end_residual_m;
  result["error_estimate"] = out.error_estimate;
  result["status_code"] = out.status;
  result["cable"] = out.cable;
  result["failures"] = out.failures;
  return result;
}

DoubleArray PositionsArray(const std::vector<Eigen::Vector3d>& positions) {
  DoubleArray out = NewArray({static_cast<py::ssize_t>(positions.size()), 3});
  for (size_t j = 0; j < positions.size(); ++j) {
    for (int k = 0; k < 3; ++k) out.mutable_data()[3 * j + k] = positions[j][k];
  }
  return out;
}

Eigen::Vector3d Point(const DoubleArray& a, const char* name) {
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw InputError(std::string(name) + " must have shape (3,)");
  return Eigen::Vector3d(a.data()[0], a.data()[1], a.data()[2]);
}

// The generator's positions, or InputError with its message (it names the parameter).
template <typename Generate>
DoubleArray Generated(Generate generate) {
  std::vector<Eigen::Vector3d> positions;
  std::string error;
  if (!generate(&positions, &error)) throw InputError(error);
  return PositionsArray(positions);
}

// The poses' attitudes as quaternions (w, x, y, z; w >= 0), shape (n, 4).
DoubleArray QuaternionsOf(const std::vector<Pose>& poses) {
  DoubleArray quat = NewArray({static_cast<py::ssize_t>(poses.size()), 4});
  for (size_t j = 0; j < poses.size(); ++j) {
    const Eigen::Vector4d q = QuaternionFromRotation(poses[j].rotation);
    for (int k = 0; k < 4; ++k) quat.mutable_data()[4 * j + k] = q[k];
  }
  return quat;
}

// Cable::Lumped as a dict of arrays (fastcal.Cable.lumped).
py::dict CableLumped(const Cable& c, const DoubleArray& lower_m, const DoubleArray& upper_m,
                     double fl_n, double fz_n, double s0_m, int segments, double gravity_m_per_s2) {
  LumpedChain chain;
  std::string error;
  if (!c.Lumped(Point(lower_m, "lower_m"), Point(upper_m, "upper_m"), fl_n, fz_n, s0_m,
                gravity_m_per_s2, segments, &chain, &error)) {
    throw InputError("lumped: " + error);
  }
  DoubleArray nodes = NewArray({static_cast<py::ssize_t>(chain.nodes_m.size()), 3});
  for (size_t j = 0; j < chain.nodes_m.size(); ++j) {
    for (int k = 0; k < 3; ++k) nodes.mutable_data()[3 * j + k] = chain.nodes_m[j][k];
  }
  py::dict out;
  out["nodes_m"] = nodes;
  out["tension_n"] = py::array_t<double>(chain.tension_n.size(), chain.tension_n.data());
  out["segment_length_m"] = chain.segment_length_m;
  out["node_mass_kg"] = chain.node_mass_kg;
  return out;
}

// One cable (cable.h): its end point and partials, the inverse, tension, mass and lumped
// chain, for fastcal.Cable.
void BindCable(py::module_& m) {
  constexpr double kGravity = -9.8;
  py::class_<Cable>(m, "Cable")
      .def(py::init([](double ea_n, double linear_density_kg_per_m) {
             Cable cable(ea_n, linear_density_kg_per_m);
             std::string error;
             if (!cable.IsValid(&error)) throw InputError(error);
             return cable;
           }),
           py::arg("ea_n"), py::arg("linear_density_kg_per_m"))
      .def_static(
          "of",
          [](const CableRobot& model, int cable) {
            if (cable < 1 || cable > kNumCables) {
              throw InputError("cable must be 1..6, got " + std::to_string(cable));
            }
            return Cable::Of(model.cables[cable - 1]);
          },
          py::arg("model"), py::arg("cable"))
      .def_property_readonly("ea_n", &Cable::ea_n)
      .def_property_readonly("linear_density_kg_per_m", &Cable::linear_density_kg_per_m)
      .def_property_readonly("uniform", &Cable::uniform)
      .def(
          "end",
          [](const Cable& c, double fl_n, double fz_n, double s0_m, double gravity_m_per_s2) {
            if (!(fl_n > 0.0) || !(s0_m > 0.0) || !std::isfinite(fz_n) || !(gravity_m_per_s2 < 0)) {
              throw InputError("end: fl_n > 0, s0_m > 0, finite fz_n and gravity_m_per_s2 < 0");
            }
            const CatenaryEnd<double> e = c.End(fl_n, fz_n, s0_m, gravity_m_per_s2);
            py::dict out;
            out["span_m"] = e.span_m;
            out["rise_m"] = e.rise_m;
            out["d_span"] = py::make_tuple(e.dspan[0], e.dspan[1], e.dspan[2]);
            out["d_rise"] = py::make_tuple(e.drise[0], e.drise[1], e.drise[2]);
            out["lower_tension_n"] = e.lower_tension_n;
            out["upper_tension_n"] = e.upper_tension_n;
            return out;
          },
          py::arg("fl_n"), py::arg("fz_n"), py::arg("s0_m"), py::arg("gravity_m_per_s2") = kGravity)
      .def(
          "forces",
          [](const Cable& c, double span_m, double rise_m, double s0_m, double gravity_m_per_s2) {
            CatenaryForces f;
            int iterations = 0;
            const CatenaryStatus status =
                c.Forces(span_m, rise_m, s0_m, gravity_m_per_s2, CatenarySolverOptions(), nullptr,
                         &f, &iterations);
            if (status != CatenaryStatus::kOk) {
              throw InputError(std::string("forces: ") + CatenaryStatusName(status));
            }
            return py::make_tuple(f.fl_n, f.fz_n);
          },
          py::arg("span_m"), py::arg("rise_m"), py::arg("s0_m"),
          py::arg("gravity_m_per_s2") = kGravity)
      .def(
          "tension",
          [](const Cable& c, double fl_n, double fz_n, double s_m, double gravity_m_per_s2) {
            if (!(fl_n > 0.0) || !std::isfinite(fl_n) || !std::isfinite(fz_n) || !(s_m >= 0.0) ||
                !std::isfinite(s_m) || !(gravity_m_per_s2 < 0.0)) {
              throw InputError("tension: finite fl_n > 0, fz_n, s_m >= 0 and gravity_m_per_s2 < 0");
            }
            return c.Tension(fl_n, fz_n, s_m, gravity_m_per_s2);
          },
          py::arg("fl_n"), py::arg("fz_n"), py::arg("s_m"), py::arg("gravity_m_per_s2") = kGravity)
      .def(
          "mass_kg",
          [](const Cable& c, double s0_m) {
            if (!(s0_m > 0.0) || !std::isfinite(s0_m)) {
              throw InputError("mass_kg: s0_m must be finite and > 0");
            }
            return c.MassKg(s0_m);
          },
          py::arg("s0_m"))
      .def("lumped", &CableLumped, py::arg("lower_m"), py::arg("upper_m"), py::arg("fl_n"),
           py::arg("fz_n"), py::arg("s0_m"), py::arg("segments"),
           py::arg("gravity_m_per_s2") = kGravity);
}

}  // namespace

void BindStatics(py::module_& m) {
  BindCable(m);
  m.def("statics_status_names", [] {
    // kUnsupportedModel is the enum's last status.
    return EnumNames(StaticsStatus::kUnsupportedModel, StaticsStatusName);
  });
  m.def("solve", &Solve, py::arg("model"), py::arg("position_m"), py::arg("attitude_kind"),
        py::arg("attitude"), py::arg("method"), py::arg("settings"),
        py::arg("joints") = DoubleArray());
  m.def("line", [](const DoubleArray& from_m, const DoubleArray& to_m, int nodes) {
    return Generated([&](std::vector<Eigen::Vector3d>* p, std::string* e) {
      return LinePositions(Point(from_m, "from_m"), Point(to_m, "to_m"), nodes, p, e);
    });
  });
  m.def("arc", [](const DoubleArray& centre_m, double radius_m, double start_deg, double end_deg,
                  int nodes) {
    ArcSpec spec;
    spec.centre_m = Point(centre_m, "centre_m");
    spec.radius_m = radius_m;
    spec.start_deg = start_deg;
    spec.end_deg = end_deg;
    spec.nodes = nodes;
    return Generated([&](auto* p, auto* e) { return ArcPositions(spec, p, e); });
  });
  m.def("focal_grid", [](double max_off_axis_deg, double off_axis_step_deg, double azimuth_step_deg,
                         const DoubleArray& focal_centre_m, double focal_radius_m) {
    FocalGridSpec spec;
    spec.max_off_axis_deg = max_off_axis_deg;
    spec.off_axis_step_deg = off_axis_step_deg;
    spec.azimuth_step_deg = azimuth_step_deg;
    spec.focal_centre_m = Point(focal_centre_m, "focal_centre_m");
    spec.focal_radius_m = focal_radius_m;
    return Generated([&](auto* p, auto* e) { return FocalSpherePositions(spec, p, e); });
  });
  m.def("random_workspace",
        [](int samples, double max_off_axis_deg, double radial_spread_m, std::uint64_t seed,
           const DoubleArray& focal_centre_m, double focal_radius_m) {
          RandomWorkspaceSpec spec;
          spec.samples = samples;
          spec.max_off_axis_deg = max_off_axis_deg;
          spec.radial_spread_m = radial_spread_m;
          spec.seed = seed;
          spec.sphere.focal_centre_m = Point(focal_centre_m, "focal_centre_m");
          spec.sphere.focal_radius_m = focal_radius_m;
          return Generated([&](auto* p, auto* e) { return RandomWorkspacePositions(spec, p, e); });
        });
  m.def("focal_attitude", [](const DoubleArray& positions_m, double tilt_fraction,
                             const DoubleArray& focal_centre_m) {
    const std::vector<Pose> at = PosesFromArrays(positions_m, "none", positions_m);
    std::vector<Eigen::Vector3d> positions;
    for (const Pose& p : at) positions.push_back(p.position_m);
    FocalAttitudeLaw law;
    law.tilt_fraction = tilt_fraction;
    law.focal_centre_m = Point(focal_centre_m, "focal_centre_m");
    std::vector<Pose> poses;
    std::string error;
    if (!PosesWithAttitudeLaw(positions, law, &poses, &error)) throw InputError(error);
    return QuaternionsOf(poses);
  });
  m.def("rpy_deg_from_quat", [](const DoubleArray& quat) {
    const std::vector<Pose> poses =
        PosesFromArrays(NewArray({quat.ndim() == 2 ? quat.shape(0) : 0, 3}), "quat", quat);
    DoubleArray rpy = NewArray({static_cast<py::ssize_t>(poses.size()), 3});
    for (size_t j = 0; j < poses.size(); ++j) {
      const Eigen::Vector3d a = RpyDegFromRotation(poses[j].rotation);
      for (int k = 0; k < 3; ++k) rpy.mutable_data()[3 * j + k] = a[k];
    }
    return rpy;
  });
  m.def("quat_from_rpy_deg", [](const DoubleArray& rpy_deg) {
    const std::vector<Pose> poses =
        PosesFromArrays(NewArray({rpy_deg.ndim() == 2 ? rpy_deg.shape(0) : 0, 3}), "rpy", rpy_deg);
    return QuaternionsOf(poses);
  });
}

}  // namespace fastcal::python
