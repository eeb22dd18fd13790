// fastcal.Model: the cable robot's parameters (cable_robot.h), its YAML file, and each
// field as a number or a numpy array (per cable: shape (6,), per point: (n, 3)).
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "fastcal/cable_robot.h"

namespace fastcal::python {
namespace {

// A setter of fastcal.Model: applies `set` to a copy, checks the copy as a model file is
// checked (ValidateModel: the YAML reader's own checks), and only then keeps it, so that
// no model is ever held that the reader would refuse (issue 29: a 30 kg cabin, a NaN
// gain). A change that needs several fields at once is made on a copy (Model.copy()).
template <typename Value, typename Set>
auto Validated(Set set) {
  return [set](CableRobot& robot, Value value) {
    CableRobot changed = robot;
    set(changed, value);
    ValidateModel(changed);
    robot = std::move(changed);
  };
}

// A per-cable field of CableProperties as a (6,) array property, both ways.

// A getter's array, a copy of the model's values, made read-only: `model.ea_n[0] = 1`
// raises ("assignment destination is read-only") instead of editing a copy that nothing
// reads; a whole array assigned (model.ea_n = values) is what changes the model.
template <typename Array>
Array ReadOnly(Array array) {
  array.attr("flags").attr("writeable") = false;
  return array;
}

// cables[i].attachments as a list of six lists of dicts (docs/model-format.md): a point
// mass {at_m, mass_kg}, added weight {from_m, to_m, added_density_kg_per_m}.
py::list GetAttachments(const CableRobot& r) {
  py::list cables;
  for (const CableProperties& c : r.cables) {
    py::list on;
    for (const CableAttachment& a : c.attachments) {
      py::dict d;
      if (a.kind == AttachmentKind::kPointMass) {
        d["at_m"] = a.at_m;
        d["mass_kg"] = a.mass_kg;
      } else {
        d["from_m"] = a.from_m;
        d["to_m"] = a.to_m;
        d["added_density_kg_per_m"] = a.added_density_kg_per_m;
      }
      on.append(d);
    }
    cables.append(on);
  }
  return cables;
}

void SetAttachments(CableRobot& r, const py::sequence& cables) {
  if (py::len(cables) != kNumCables) {
    throw InputError("attachments: expected a list of 6 lists (cable 1 first), got " +
                     std::to_string(py::len(cables)));
  }
  std::array<std::vector<CableAttachment>, kNumCables> all;
  for (int i = 0; i < kNumCables; ++i) {
    if (!py::isinstance<py::sequence>(cables[i]) || py::isinstance<py::str>(cables[i])) {
      throw InputError("attachments[" + std::to_string(i) + "]: expected a list of dicts");
    }
    const py::sequence on = py::reinterpret_borrow<py::sequence>(cables[i]);
    for (size_t j = 0; j < py::len(on); ++j) {
      const std::string where = "attachments[" + std::to_string(i) + "][" + std::to_string(j) + "]";
      if (!py::isinstance<py::dict>(on[j])) throw InputError(where + ": expected a dict");
      const py::dict d = py::reinterpret_borrow<py::dict>(on[j]);
      CableAttachment a;
      const bool point = d.contains("at_m") || d.contains("mass_kg");
      a.kind = point ? AttachmentKind::kPointMass : AttachmentKind::kAddedDensity;
      const std::vector<std::pair<const char*, double*>> fields = a.Fields();
      if (py::len(d) != fields.size()) {
        throw InputError(where + ": " + CableAttachment::KeysText(a.kind));
      }
      for (const auto& [key, value] : fields) {
        if (!d.contains(key)) throw InputError(where + "." + key + ": missing");
        *value = NumberArgument(d[key], where + "." + key);
      }
      std::string why;
      if (!a.IsValid(&why)) throw InputError(where + "." + why);
      all[i].push_back(a);
    }
    if (all[i].size() > static_cast<size_t>(kMaxAttachmentsPerCable)) {
      throw InputError("attachments[" + std::to_string(i) + "]: at most " +
                       std::to_string(kMaxAttachmentsPerCable) + " per cable");
    }
  }
  for (int i = 0; i < kNumCables; ++i) r.cables[i].attachments = std::move(all[i]);
}

void PerCableProperty(py::class_<CableRobot>& model, const char* name,
                      double CableProperties::*field, const char* doc) {
  model.def_property(
      name,
      [field](const CableRobot& r) {
        DoubleArray out = NewArray({kNumCables});
        for (int i = 0; i < kNumCables; ++i) out.mutable_data()[i] = r.cables[i].*field;
        return ReadOnly(out);
      },
      Validated<const DoubleArray&>([field, name](CableRobot& r, const DoubleArray& values) {
        if (values.ndim() != 1 || values.shape(0) != kNumCables) {
          throw InputError(std::string(name) + " must have shape (6,): one value per cable");
        }
        for (int i = 0; i < kNumCables; ++i) r.cables[i].*field = values.data()[i];
      }),
      doc);
}

DoubleArray Vector3(const Eigen::Vector3d& v) {
  DoubleArray out = NewArray({3});
  for (int k = 0; k < 3; ++k) out.mutable_data()[k] = v[k];
  return out;
}
Eigen::Vector3d ToVector3(const DoubleArray& a, const char* name) {
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw InputError(std::string(name) + " must have shape (3,)");
  return Eigen::Vector3d(a.data()[0], a.data()[1], a.data()[2]);
}

// The cabin's inertia as a (3, 3) array, and back: (3,) is its diagonal, as in the file.
DoubleArray Matrix3(const Eigen::Matrix3d& m) {
  DoubleArray out = NewArray({3, 3});
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.mutable_data()[3 * r + c] = m(r, c);
  }
  return out;
}
Eigen::Matrix3d ToInertia(const DoubleArray& a) {
  if (a.ndim() == 1 && a.shape(0) == 3) return ToVector3(a, "cabin_inertia_kg_m2").asDiagonal();
  if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
    throw InputError("cabin_inertia_kg_m2 must have shape (3,) or (3, 3)");
  }
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = a.data()[3 * r + c];
  }
  return m;
}

CableRobot Load(const std::string& path) {
  CableRobot robot;
  std::string error;
  RequireExistingFile(path, "model");
  if (!LoadCableRobot(path, &robot, &error)) throw InputError(error);
  return robot;
}

// The file Model.load reads back: a model the reader would refuse is not written.
void Save(const CableRobot& r, const std::string& path, const std::string& header_comment) {
  CheckPath(path, "model");
  ValidateModel(r);
  std::string error;
  if (!SaveCableRobot(r, path, header_comment, &error)) throw InputError(error);
}

double GetCabinMass(const CableRobot& r) { return r.cabin_mass_kg; }
double GetGravity(const CableRobot& r) { return r.gravity_m_per_s2; }

// Model's array and dict properties: numpy arrays and a dict in, copies out.

py::object GetReflector(const CableRobot& r) {
  if (!r.reflector) return py::none();
  py::dict d;
  d["centre_m"] = ReadOnly(Vector3(r.reflector->centre_m));
  d["radius_m"] = r.reflector->radius_m;
  d["aperture_m"] = r.reflector->aperture_m;
  return std::move(d);
}

void SetReflector(CableRobot& r, const py::object& v) {
  if (v.is_none()) {
    r.reflector.reset();
    return;
  }
  if (!py::isinstance<py::dict>(v)) {
    throw InputError("reflector: expected None or a dict {centre_m, radius_m, aperture_m}");
  }
  const py::dict d = v.cast<py::dict>();
  Reflector reflector;
  for (const auto& [key, value] : d) {
    const std::string name = py::str(key);
    if (name == "centre_m") {
      reflector.centre_m = ToVector3(value.cast<DoubleArray>(), "reflector centre_m");
    } else if (name == "radius_m") {
      reflector.radius_m = NumberArgument(value, "reflector radius_m");
    } else if (name == "aperture_m") {
      reflector.aperture_m = NumberArgument(value, "reflector aperture_m");
    } else {
      throw InputError("reflector: unknown key '" + name +
                       "' (accepted: centre_m, radius_m, aperture_m)");
    }
  }
  r.reflector = reflector;
}

DoubleArray GetAnchorPoints(const CableRobot& r) {
  const auto n = static_cast<py::ssize_t>(r.anchor_points_cabin_m.size());
  DoubleArray out = NewArray({n, 3});
  for (py::ssize_t j = 0; j < n; ++j) {
    for (int k = 0; k < 3; ++k) out.mutable_data()[3 * j + k] = r.anchor_points_cabin_m[j][k];
  }
  return ReadOnly(out);
}

void SetAnchorPoints(CableRobot& r, const DoubleArray& v) {
  CheckRows(v, 3, "anchor_points_cabin_m");
  r.anchor_points_cabin_m.clear();
  for (py::ssize_t j = 0; j < v.shape(0); ++j) {
    r.anchor_points_cabin_m.emplace_back(v.data()[3 * j], v.data()[3 * j + 1], v.data()[3 * j + 2]);
  }
}

DoubleArray GetTowerTops(const CableRobot& r) {
  DoubleArray out = NewArray({kNumCables, 3});
  for (int i = 0; i < kNumCables; ++i) {
    for (int k = 0; k < 3; ++k) out.mutable_data()[3 * i + k] = r.cables[i].tower_top_m[k];
  }
  return ReadOnly(out);
}

void SetTowerTops(CableRobot& r, const DoubleArray& v) {
  CheckRows(v, 3, "tower_top_m");
  if (v.shape(0) != kNumCables) throw InputError("tower_top_m must have shape (6, 3)");
  for (int i = 0; i < kNumCables; ++i) {
    r.cables[i].tower_top_m =
        Eigen::Vector3d(v.data()[3 * i], v.data()[3 * i + 1], v.data()[3 * i + 2]);
  }
}

py::array_t<int> GetAnchorIndex(const CableRobot& r) {
  py::array_t<int> out(kNumCables);
  for (int i = 0; i < kNumCables; ++i) out.mutable_data()[i] = r.cables[i].anchor_index;
  return ReadOnly(out);
}

// Whole numbers only: 1.5 is refused, not truncated to 1.
void SetAnchorIndex(CableRobot& r, const DoubleArray& v) {
  if (v.ndim() != 1 || v.shape(0) != kNumCables) {
    throw InputError("anchor_index must have shape (6,)");
  }
  for (int i = 0; i < kNumCables; ++i) {
    const double index = v.data()[i];
    if (!(index >= 0.0 && index < 1e6 && index == std::floor(index))) {
      throw InputError("anchor_index[" + std::to_string(i) + "]: expected a whole number >= 0");
    }
    r.cables[i].anchor_index = static_cast<int>(index);
  }
}

}  // namespace

void BindModel(py::module_& m) {
  py::class_<CableRobot> model(m, "Model",
                               R"(The cable robot's model parameters (docs/model-format.md).

Model.nominal() is the paper's FAST; Model.load(path) reads a model file, e.g. the
model_calibrated.yaml of a calibration. Fields are plain numbers or numpy arrays in SI
units named with their unit; per-cable fields have shape (6,), cable i at index i-1.
Arrays are read-only copies: assign a whole array to change one
(v = model.ea_n.copy(); v[0] *= 1.01; model.ea_n = v); editing one in place raises
ValueError ("assignment destination is read-only") instead of changing nothing.
)");
  model.def_static("nominal", &CableRobot::NominalFast, "The nominal FAST model (paper Table 1).")
      .def_static("load", &Load, py::arg("path"),
                  "Reads a model file. fastcal.InputError names the file, line and key.")
      .def("save", &Save, py::arg("path"), py::arg("header_comment") = "",
           "Writes the model file (atomically: a failure leaves no partial file). Refuses, "
           "with fastcal.InputError, a model Model.load would refuse.")
      .def("to_yaml", &CableRobotToYaml, py::arg("header_comment") = "", "The model file's text.")
      .def(
          "validate", [](const CableRobot& r) { ValidateModel(r); },
          "Raises fastcal.InputError naming the attribute of a value a model file could not "
          "hold (the reader's checks; every setter runs them too).")
      .def(
          "copy", [](const CableRobot& r) { return CableRobot(r); }, "An independent copy.")
      .def_property("cabin_mass_kg", &GetCabinMass,
                    Validated<const py::object&>([](CableRobot& r, const py::object& v) {
                      r.cabin_mass_kg = NumberArgument(v, "cabin_mass_kg");
                    }),
                    "Cabin mass (kg).")
      .def_property("gravity_m_per_s2", &GetGravity,
                    Validated<const py::object&>([](CableRobot& r, const py::object& v) {
                      r.gravity_m_per_s2 = NumberArgument(v, "gravity_m_per_s2");
                    }),
                    "Gravitational acceleration along z (negative: z is up).")
      .def_property(
          "mass_centre_cabin_m",
          [](const CableRobot& r) { return ReadOnly(Vector3(r.mass_centre_cabin_m)); },
          Validated<const DoubleArray&>([](CableRobot& r, const DoubleArray& v) {
            r.mass_centre_cabin_m = ToVector3(v, "mass_centre_cabin_m");
          }),
          "Mass centre of the cabin in the cabin frame, shape (3,).")
      .def_property_readonly(
          "joint_columns", [](const CableRobot& r) { return r.moving_parts.JointColumns(); },
          "The data columns of the moving parts' joints (cabin.moving_parts, "
          "docs/model-format.md), in the model's joint order; empty for a rigid cabin.")
      .def(
          "mass_centre_at",
          [](const CableRobot& r, const std::vector<double>& joints) {
            const int n = r.moving_parts.num_joints();
            if (static_cast<int>(joints.size()) != n) {
              throw InputError("mass_centre_at: the model has " + std::to_string(n) +
                               " joints, got " + std::to_string(joints.size()) + " values");
            }
            JointValues q{};
            for (int j = 0; j < n; ++j) q[j] = joints[j];
            return Vector3(r.MassCentreAt(q));
          },
          py::arg("joints"),
          "The mass centre (cabin frame, m, shape (3,)) with the moving parts at `joints` "
          "(joint_columns order, deg and m): docs/model.md, \"Moving parts\".")
      .def_property(
          "measured_frame",
          [](const CableRobot& r) -> py::object {
            if (!r.measured_frame.has_value()) return py::none();
            const MeasuredFrame& f = *r.measured_frame;
            py::dict d;
            d["part"] = f.part < 0 ? std::string("cabin") : r.moving_parts.parts[f.part].name;
            d["offset_m"] = ReadOnly(Vector3(f.offset_m));
            return d;
          },
          Validated<const py::object&>([](CableRobot& r, const py::object& v) {
            if (v.is_none()) {
              r.measured_frame.reset();
              return;
            }
            if (!py::isinstance<py::dict>(v)) {
              throw InputError("measured_frame must be None or a dict {part, offset_m}");
            }
            const py::dict d = v.cast<py::dict>();
            for (const auto& item : d) {
              const std::string key = py::str(item.first);
              if (key != "part" && key != "offset_m") {
                throw InputError("measured_frame: unknown key '" + key +
                                 "' (allowed: part, offset_m)");
              }
            }
            MeasuredFrame f;
            if (d.contains("part")) {
              const std::string part = py::str(d["part"]);
              f.part = part == "cabin" ? -1 : r.moving_parts.Find(part);
              if (part != "cabin" && f.part < 0) {
                throw InputError("measured_frame.part: '" + part +
                                 "' is not a moving part of the model (or cabin)");
              }
            }
            if (d.contains("offset_m")) {
              f.offset_m = ToVector3(d["offset_m"].cast<DoubleArray>(), "measured_frame.offset_m");
            }
            r.measured_frame = f;
          }),
          "Whose pose the data give (cabin.measured_frame, docs/model-format.md): None for the "
          "cabin's own frame, or {'part': a moving part's name or 'cabin', 'offset_m': (3,) the "
          "measured point in that part's frame}. solve, locate, control_cycle and every "
          "dataset then give that frame's pose; the cabin's follows from the joints.")
      .def(
          "cabin_pose",
          [](const CableRobot& r, const DoubleArray& position_m, const DoubleArray& rpy_deg,
             const std::vector<double>& joints) {
            const int n = r.moving_parts.num_joints();
            if (!joints.empty() && static_cast<int>(joints.size()) != n) {
              throw InputError("cabin_pose: the model has " + std::to_string(n) + " joints, got " +
                               std::to_string(joints.size()) + " values");
            }
            JointValues q{};
            for (size_t j = 0; j < joints.size(); ++j) q[j] = joints[j];
            const Eigen::Vector3d rpy = ToVector3(rpy_deg, "rpy_deg");
            Pose data;
            data.position_m = ToVector3(position_m, "position_m");
            data.rotation = RotationFromRpyDeg(rpy[0], rpy[1], rpy[2]);
            if (!data.position_m.allFinite() || !rpy.allFinite()) {
              throw InputError("cabin_pose: position_m and rpy_deg must be finite");
            }
            const Pose cabin = r.CabinPose(data, q);
            return py::make_tuple(Vector3(cabin.position_m),
                                  Vector3(RpyDegFromRotation(cabin.rotation)));
          },
          py::arg("position_m"), py::arg("rpy_deg"), py::arg("joints") = std::vector<double>{},
          "The cabin's own pose (position (3,) m, rpy (3,) deg) where the model's measured "
          "frame has this pose at `joints` (joint_columns order; empty: all zero); the same "
          "pose without a measured frame (docs/model.md, \"The measured frame\").")
      .def_property(
          "cabin_inertia_kg_m2",
          [](const CableRobot& r) { return ReadOnly(Matrix3(r.cabin_inertia_kg_m2)); },
          Validated<const DoubleArray&>(
              [](CableRobot& r, const DoubleArray& v) { r.cabin_inertia_kg_m2 = ToInertia(v); }),
          "The cabin's inertia about its mass centre, cabin frame (kg m^2), shape (3, 3); "
          "assign (3,) for a diagonal. An assumed default (docs/model-format.md); only the "
          "vibrations (fastcal.modes) use it.")
      .def_property("reflector", &GetReflector, Validated<const py::object&>(&SetReflector),
                    "The reflector cables are checked against: None, or a dict {centre_m (3,), "
                    "radius_m, aperture_m} (a sphere's lower cap; docs/model-format.md). Assign a "
                    "whole dict; keys left out keep FAST's values.")
      .def_property("anchor_points_cabin_m", &GetAnchorPoints,
                    Validated<const DoubleArray&>(&SetAnchorPoints),
                    "Cabin anchor points in the cabin frame, shape (n, 3).")
      .def_property("attachments", &GetAttachments, Validated<const py::sequence&>(&SetAttachments),
                    "What each cable carries (docs/model-format.md): a list of 6 lists (cable "
                    "1 first) of dicts, {at_m, mass_kg} for a point mass, {from_m, to_m, "
                    "added_density_kg_per_m} for added weight; arc lengths in m from the lower "
                    "(cabin) end, unstretched. Assign a whole list; fastcal.InputError names a "
                    "bad entry.")
      .def_property("tower_top_m", &GetTowerTops, Validated<const DoubleArray&>(&SetTowerTops),
                    "Upper end of each cable (tower top), global frame, shape (6, 3).")
      .def_property(
          "anchor_index", &GetAnchorIndex, Validated<const DoubleArray&>(&SetAnchorIndex),
          "Index into anchor_points_cabin_m of each cable's cabin point (0-based), shape (6,).")
      .def("__repr__", [](const CableRobot& r) {
        return "<fastcal.Model: cabin " + std::to_string(r.cabin_mass_kg) + " kg, " +
               std::to_string(r.anchor_points_cabin_m.size()) + " anchor points>";
      });
  PerCableProperty(model, "ea_n", &CableProperties::ea_n,
                   "Axial stiffness E*A of each cable (N), shape (6,).");
  PerCableProperty(model, "linear_density_kg_per_m", &CableProperties::linear_density_kg_per_m,
                   "Mass per unit unstretched length of each cable, shape (6,).");
  PerCableProperty(model, "sensor_gain", &CableProperties::sensor_gain,
                   "Tension sensor gain per cable: reading = gain * tension + bias, shape (6,).");
  PerCableProperty(model, "length_offset_m", &CableProperties::length_offset_m,
                   "Length encoder zero per cable (m): reading = unstretched length + offset, "
                   "shape (6,).");
  // The bias in kN, as every tension of the module and the model file's key
  // (sensor_bias_kN); formerly sensor_bias_n, in N (docs/python.md, Decisions).
  model.def_property(
      "sensor_bias_kN",
      [](const CableRobot& r) {
        DoubleArray out = NewArray({kNumCables});
        for (int i = 0; i < kNumCables; ++i) {
          out.mutable_data()[i] = r.cables[i].sensor_bias_n / kNPerKn;
        }
        return ReadOnly(out);
      },
      Validated<const DoubleArray&>([](CableRobot& r, const DoubleArray& values) {
        if (values.ndim() != 1 || values.shape(0) != kNumCables) {
          throw InputError("sensor_bias_kN must have shape (6,): one value per cable");
        }
        for (int i = 0; i < kNumCables; ++i) r.cables[i].sensor_bias_n = values.data()[i] * kNPerKn;
      }),
      "Tension sensor bias per cable (kN, as every tension), shape (6,).");
  // The old name, in N, is refused with the new one rather than kept: two units for one
  // quantity is what the rename removes.
  auto renamed = [](const py::object&) -> py::object {
    throw py::attribute_error(
        "Model.sensor_bias_n (N) is now Model.sensor_bias_kN (kN, as every tension)");
  };
  model.def_property(
      "sensor_bias_n", renamed,
      [renamed](const py::object& self, const py::object&) { renamed(self); },
      "Renamed: use sensor_bias_kN (kN).");
}

}  // namespace fastcal::python
