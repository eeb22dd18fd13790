// fastcal._fastcal: the module's exceptions, shared conversions and its parts.
#include <pybind11/pybind11.h>

#include <cerrno>
#include <cmath>
#include <regex>
#include <utility>

#include "bindings.h"
#include "fastcal/model_plausibility.h"
#include "fastcal/version.h"

namespace fastcal::python {

void CheckRows(const DoubleArray& array, py::ssize_t columns, const char* name) {
  if (array.ndim() != 2 || array.shape(1) != columns) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d) {
      shape += (d ? ", " : "") + std::to_string(array.shape(d));
    }
    throw InputError(std::string(name) + " must have shape (n, " + std::to_string(columns) +
                     "), got " + shape + (array.ndim() == 1 ? ",)" : ")"));
  }
}

DoubleArray NewArray(const std::vector<py::ssize_t>& shape) {
  DoubleArray array(shape);
  std::fill(array.mutable_data(), array.mutable_data() + array.size(), 0.0);
  return array;
}

std::vector<Pose> PosesFromArrays(const DoubleArray& positions_m, const std::string& attitude_kind,
                                  const DoubleArray& attitude) {
  CheckRows(positions_m, 3, "position_m");
  const py::ssize_t n = positions_m.shape(0);
  const py::ssize_t columns = attitude_kind == "rpy" ? 3 : attitude_kind == "quat" ? 4 : 0;
  const char* name = attitude_kind == "rpy" ? "rpy_deg" : "quat";
  if (columns > 0) {
    CheckRows(attitude, columns, name);
    if (attitude.shape(0) != n) {
      throw InputError(std::string(name) + " has " + std::to_string(attitude.shape(0)) +
                       " rows for " + std::to_string(n) + " positions");
    }
  } else if (attitude_kind != "none") {
    throw InputError("attitude kind must be none, rpy or quat, got '" + attitude_kind + "'");
  }
  std::vector<Pose> poses(static_cast<size_t>(n));
  const double* p = positions_m.data();
  const double* a = columns > 0 ? attitude.data() : nullptr;
  for (py::ssize_t i = 0; i < n; ++i) {
    Pose& pose = poses[static_cast<size_t>(i)];
    pose.position_m = Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    if (columns == 3) {
      pose.rotation = RotationFromRpyDeg(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
    } else if (columns == 4) {
      std::string error;
      if (!RotationFromQuaternion(a[4 * i], a[4 * i + 1], a[4 * i + 2], a[4 * i + 3],
                                  &pose.rotation, &error)) {
        throw InputError("quat[" + std::to_string(i) + "]: " + error);
      }
    }
  }
  return poses;
}

// The joints as (n, J) rows: an empty array (no joints: all at zero), one row (J,) for
// every pose, or one row per pose.
std::vector<JointValues> JointRows(const DoubleArray& joints, py::ssize_t n, int num_joints) {
  std::vector<JointValues> rows(static_cast<size_t>(n), JointValues{});
  if (joints.size() == 0) return rows;
  if (num_joints == 0) throw InputError("joints: the model has no moving parts");
  const bool one = joints.ndim() == 1;
  if ((one && joints.shape(0) != num_joints) ||
      (!one && (joints.ndim() != 2 || joints.shape(0) != n || joints.shape(1) != num_joints))) {
    throw InputError("joints must have shape (" + std::to_string(num_joints) + ",) or (" +
                     std::to_string(n) + ", " + std::to_string(num_joints) +
                     "): the model's joints in order (Model.joint_columns)");
  }
  for (py::ssize_t k = 0; k < n; ++k) {
    for (int j = 0; j < num_joints; ++j) {
      const double v = joints.data()[(one ? 0 : k * num_joints) + j];
      if (!std::isfinite(v)) {
        throw InputError("joints: row " + std::to_string(k) + ", joint " + std::to_string(j) +
                         " is not finite");
      }
      rows[static_cast<size_t>(k)][j] = v;
    }
  }
  return rows;
}

namespace {

// A model check's key paths (the model file's: "cabin.mass_kg", "cables[2].ea_n") as the
// attributes of fastcal.Model ("cabin_mass_kg", "ea_n[2]").
std::string AsPythonAttributes(std::string message) {
  static const std::pair<std::regex, const char*> kRenames[] = {
      {std::regex(R"(cabin\.mass_kg)"), "cabin_mass_kg"},
      {std::regex(R"(cabin\.mass_centre_m\.x)"), "mass_centre_cabin_m[0]"},
      {std::regex(R"(cabin\.mass_centre_m\.y)"), "mass_centre_cabin_m[1]"},
      {std::regex(R"(cabin\.mass_centre_m\.z)"), "mass_centre_cabin_m[2]"},
      {std::regex(R"(cabin\.anchor_points_m\[(\d+)\]\.x)"), "anchor_points_cabin_m[$1, 0]"},
      {std::regex(R"(cabin\.anchor_points_m\[(\d+)\]\.y)"), "anchor_points_cabin_m[$1, 1]"},
      {std::regex(R"(cabin\.anchor_points_m\[(\d+)\]\.z)"), "anchor_points_cabin_m[$1, 2]"},
      {std::regex(
           R"(cables\[(\d+)\]\.(ea_n|linear_density_kg_per_m|sensor_gain|sensor_bias_kN|tower_top_m))"),
       "$2[$1]"},
      {std::regex(R"(cables\[(\d+)\]\.anchor\b)"), "anchor_index[$1]"},
      {std::regex(R"(cables\[(\d+)\]\.attachments)"), "attachments[$1]"}};
  const size_t colon = message.find(": ");
  std::string key = message.substr(0, colon);
  for (const auto& [pattern, replacement] : kRenames)
    key = std::regex_replace(key, pattern, replacement);
  return colon == std::string::npos ? key : key + message.substr(colon);
}

}  // namespace

double NumberArgument(py::handle value, const std::string& what) {
  if (!py::isinstance<py::bool_>(value)) {
    try {
      return value.cast<double>();
    } catch (const py::cast_error&) {
    }
  }
  throw InputError(what + ": expected a number, got " +
                   std::string(py::str(value.get_type().attr("__name__"))));
}

void ValidateModel(const CableRobot& robot) {
  std::string why;
  if (!CheckModel(robot, &why)) throw InputError("model: " + AsPythonAttributes(why));
}

namespace {

// fastcal.Error and its two kinds; each also derives from the built-in exception a Python
// user would catch for it.
void RegisterExceptions(py::module_& m) {
  static PyObject* error = PyErr_NewExceptionWithDoc(
      "fastcal.Error", "Base class of the errors fastcal raises.", PyExc_Exception, nullptr);
  static PyObject* input_error = PyErr_NewExceptionWithDoc(
      "fastcal.InputError",
      "Bad input: a file, a spec or an argument. The message names the file, line, column\n"
      "or parameter, as the command line's does (its exit code 2).",
      py::make_tuple(py::handle(error), py::handle(PyExc_ValueError)).release().ptr(), nullptr);
  static PyObject* calibration_error = PyErr_NewExceptionWithDoc(
      "fastcal.CalibrationError",
      "A calibration refused or failed (the command line's exit code 1). `status` says\n"
      "which: 'undetermined', 'infeasible', 'solver failed' or 'mostly gross errors'.",
      py::make_tuple(py::handle(error), py::handle(PyExc_RuntimeError)).release().ptr(), nullptr);
  m.attr("Error") = py::handle(error);
  m.attr("InputError") = py::handle(input_error);
  m.attr("CalibrationError") = py::handle(calibration_error);
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const InputError& e) {
      PyErr_SetString(input_error, e.what());
    } catch (const MissingFileError& e) {
      PyErr_SetObject(PyExc_FileNotFoundError,
                      py::make_tuple(ENOENT, std::string(e.what()), e.path).ptr());
    } catch (const CalibrationError& e) {
      py::object instance = py::handle(calibration_error)(e.what());
      instance.attr("status") = e.status;
      PyErr_SetObject(calibration_error, instance.ptr());
    } catch (const py::cast_error& e) {
      // An argument of the wrong kind that no check above named: still bad input.
      PyErr_SetString(input_error, e.what());
    }
  });
}

}  // namespace
}  // namespace fastcal::python

PYBIND11_MODULE(_fastcal, m) {
  using namespace fastcal::python;
  m.doc() = "fastcal's C++ core; use the package fastcal, which documents it.";
  m.attr("__version__") = FASTCAL_VERSION;
  RegisterExceptions(m);
  BindModel(m);
  BindStatics(m);
  BindControl(m);
  BindLocate(m);
  BindData(m);
  BindCalibration(m);
  BindDesign(m);
  BindTrack(m);
  BindModes(m);
  BindDynamics(m);
}
