// The vibrations of one pose (modes.h) on numpy arrays: a position and an attitude in, the
// lowest modes' frequencies, energy shares and dominant cables out.
#include <string>
#include <vector>

#include "bindings.h"
#include "fastcal/modes.h"

namespace fastcal::python {

void BindModes(py::module_& m) {
  m.def(
      "modes",
      [](const CableRobot& model_argument, const DoubleArray& position_m,
         const std::string& attitude_kind,
         const DoubleArray& attitude, int segments, int count, bool cable_inertia) {
        const CableRobot robot = model_argument;  // a copy with the GIL held (issue 37)
        ValidateModel(robot);
        const std::vector<Pose> poses = PosesFromArrays(position_m, attitude_kind, attitude);
        if (poses.size() != 1) throw InputError("modes take one pose");
        ModesOptions options;
        options.segments = segments;
        options.modes = count;
        options.cable_inertia = cable_inertia;
        ModesResult result;
        std::string error;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = ComputeModes(robot, poses[0], options, &result, &error);
        }
        if (!ok) {
          // Bad options are the caller's input; a pose without modes is a failed computation.
          if (!options.IsValid(&error)) throw InputError(error);
          throw std::runtime_error(error);
        }
        const py::ssize_t n = static_cast<py::ssize_t>(result.modes.size());
        DoubleArray hz = NewArray({n}), shares = NewArray({n, 7}), cable = NewArray({n, 6}),
                    shape = NewArray({n, 6});
        py::array_t<int> dominant(n);
        for (py::ssize_t k = 0; k < n; ++k) {
          const Mode& mode = result.modes[static_cast<size_t>(k)];
          hz.mutable_at(k) = mode.frequency_hz;
          for (int j = 0; j < 3; ++j) {
            shares.mutable_at(k, j) = mode.cabin_translation_share[j];
            shares.mutable_at(k, 3 + j) = mode.cabin_rotation_share[j];
          }
          shares.mutable_at(k, 6) = mode.cables_share;
          for (int i = 0; i < kNumCables; ++i) cable.mutable_at(k, i) = mode.cable_share[i];
          for (int j = 0; j < 6; ++j) shape.mutable_at(k, j) = mode.cabin_shape[j];
          dominant.mutable_at(k) = mode.dominant_cable + 1;
        }
        py::dict out;
        out["frequency_hz"] = hz;
        out["shares"] = shares;
        out["cable_share"] = cable;
        out["dominant_cable"] = dominant;
        out["cabin_shape"] = shape;
        out["degrees_of_freedom"] = result.degrees_of_freedom;
        return out;
      },
      py::arg("model"), py::arg("position_m"), py::arg("attitude_kind"), py::arg("attitude"),
      py::arg("segments"), py::arg("modes"), py::arg("cable_inertia"));
}

}  // namespace fastcal::python
