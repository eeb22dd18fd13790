// The Python module fastcal._fastcal (pybind11): the library's models, statics,
// trajectories, datasets, simulation, calibration and evaluation on numpy arrays. The
// package fastcal (python/fastcal/__init__.py) is the documented interface on top: it
// checks shapes, names arguments and wraps results; this layer converts and calls the
// library with the GIL released. Tensions and forces cross in kN (the edge), everything
// else in the library's SI units, each named with its unit.
#ifndef FASTCAL_PYTHON_BINDINGS_H_
#define FASTCAL_PYTHON_BINDINGS_H_

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/column_map.h"
#include "fastcal/internal/units.h"
#include "fastcal/pose.h"

namespace fastcal::python {

namespace py = pybind11;

// Ctrl-C inside a long call with the GIL released (issue 37): every `every` pieces of
// work the GIL is taken for a moment to ask Python whether a signal is pending; true
// stops the loop, and the caller raises it (ThrowIfInterrupted) once it holds the GIL.
class InterruptCheck {
 public:
  explicit InterruptCheck(long long every = 2048) : every_(every) {}
  bool Stop(long long k) {
    if (k % every_ != 0 || k == 0) return false;
    py::gil_scoped_acquire gil;
    interrupted_ = PyErr_CheckSignals() != 0;
    return interrupted_;
  }
  // Asks now, whatever the count: the library's should_stop (CalibrationOptions,
  // TrackOptions), called between pieces of work that each take long enough. Once true,
  // stays true without asking again.
  bool Now() {
    if (interrupted_) return true;
    py::gil_scoped_acquire gil;
    interrupted_ = PyErr_CheckSignals() != 0;
    return interrupted_;
  }
  std::function<bool()> AsShouldStop() {
    return [this] { return Now(); };
  }
  // With the GIL held: KeyboardInterrupt (or what the signal's handler raised).
  void ThrowIfInterrupted() const {
    if (interrupted_) throw py::error_already_set();
  }

 private:
  long long every_;
  bool interrupted_ = false;
};

// Progress lines on Python's sys.stderr (a notebook shows them; the C++ stream it does
// not), the GIL taken for each write; an error in writing is not the computation's.
inline std::function<void(const std::string&)> ProgressTo(const std::string& prefix) {
  return [prefix](const std::string& line) {
    py::gil_scoped_acquire gil;
    try {
      py::module_::import("sys").attr("stderr").attr("write")(prefix + line + "\n");
    } catch (const py::error_already_set&) {
    }
  };
}

using internal::kNPerKn;

// Bad input (a file, a spec, an argument): raised as fastcal.InputError, a ValueError,
// with the library's message (the one the command line prints before exiting with 2).
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An input file that does not exist: raised as FileNotFoundError (an OSError, what
// open() raises), with errno ENOENT, the library's message and the file name.
struct MissingFileError : std::runtime_error {
  MissingFileError(std::string file, const std::string& message)
      : std::runtime_error(message), path(std::move(file)) {}
  std::string path;
};

// A path from Python: InputError when it holds a NUL byte, which the system would read as
// its end (issue 29: "a.yaml\0b" was silently a.yaml).
inline void CheckPath(const std::string& path, const std::string& what) {
  if (path.find('\0') != std::string::npos) {
    throw InputError(what + " path contains a NUL byte: not a file name");
  }
}

// Throws MissingFileError when nothing exists at `path` (other problems, a directory or
// an unreadable file, are the reader's InputError with its message).
inline void RequireExistingFile(const std::string& path, const std::string& what) {
  CheckPath(path, what);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw MissingFileError(path, path + ": no such " + what + " file");
  }
}

// A Python number (int, float, numpy scalar) as a double: InputError naming `what`
// otherwise (a str, None, a bool), instead of pybind11's cast error.
double NumberArgument(py::handle value, const std::string& what);

// The model's checks, the very ones a model file passes (CheckModel, model_plausibility.h),
// with the key named as the Python attribute ("cabin_mass_kg", "ea_n[2]"): InputError
// otherwise. Every setter of fastcal.Model runs it on the changed copy before keeping it,
// and every call that takes a model runs it first.
void ValidateModel(const CableRobot& robot);

// A calibration refused or failed (the command line's exit 1): fastcal.CalibrationError,
// a RuntimeError, whose `status` says which ("undetermined", "infeasible", ...).
struct CalibrationError : std::runtime_error {
  CalibrationError(std::string status_name, const std::string& message)
      : std::runtime_error(message), status(std::move(status_name)) {}
  std::string status;
};

// A C-contiguous float64 array; anything numpy can convert is converted on the way in.
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// `array` as rows of `columns` numbers: shape (n, columns). InputError naming `name` and
// the shape otherwise.
void CheckRows(const DoubleArray& array, py::ssize_t columns, const char* name);

// A new float64 array of the given shape (C order), zero-filled.
DoubleArray NewArray(const std::vector<py::ssize_t>& shape);

// Poses from positions (n, 3) and an attitude: kind "none" (R = I), "rpy" (n, 3 roll,
// pitch, yaw in degrees) or "quat" (n, 4 unit quaternions w, x, y, z). InputError naming
// the row of a non-unit quaternion.
std::vector<Pose> PosesFromArrays(const DoubleArray& positions_m, const std::string& attitude_kind,
                                  const DoubleArray& attitude);

// The joints as (n, J) rows: an empty array (no joints: all at zero), one row (J,) for
// every pose, or one row per pose. InputError naming the shape or the value otherwise.
std::vector<JointValues> JointRows(const DoubleArray& joints, py::ssize_t n, int num_joints);

// The column map of `map_text` (YAML; "" for none: null), named `map_source` in messages
// (InputError otherwise). `csv_layout` (for text the module wrote itself from a
// spreadsheet or a DataFrame): fields separated by ',' with RFC 4180 quotes;
// `header_first` also puts the names on the first line with nothing skipped after them
// (a DataFrame's).
std::shared_ptr<const ColumnMap> MapOrThrow(const std::string& map_text,
                                            const std::string& map_source, bool csv_layout,
                                            bool header_first);

// The names of an enum's values 0 .. last, in order (the statuses' short codes Python
// maps its arrays of codes through).
template <typename Enum, typename NameOf>
py::list EnumNames(Enum last, NameOf name_of) {
  py::list names;
  for (int s = 0; s <= static_cast<int>(last); ++s) names.append(name_of(static_cast<Enum>(s)));
  return names;
}

void BindModel(py::module_& m);
void BindStatics(py::module_& m);
void BindControl(py::module_& m);
void BindLocate(py::module_& m);
void BindData(py::module_& m);
void BindCalibration(py::module_& m);
void BindDesign(py::module_& m);
void BindTrack(py::module_& m);
void BindModes(py::module_& m);
void BindDynamics(py::module_& m);

}  // namespace fastcal::python

#endif  // FASTCAL_PYTHON_BINDINGS_H_
