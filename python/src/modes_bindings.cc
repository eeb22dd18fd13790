// The vibrations of one pose (modes.h) on numpy arrays: a position and an attitude in, the
// lowest modes' frequencies, energy shares and dominant cables out. The map of the cap
// (modes_map.h): the grid and the modes' options in, the CSV `fastcal modes --cap` writes
// out. Modes identified from a record (modal_identification.h, subspace_identification.h)
// and compared with the prediction: the CSV `fastcal modes --data` writes, and its verdict.
#include <string>
#include <vector>

#include "bindings.h"
#include "fastcal/modal_identification.h"
#include "fastcal/modes.h"
#include "fastcal/modes_map.h"
#include "fastcal/subspace_identification.h"
#include "fastcal/vibration_record.h"

namespace fastcal::python {

namespace {

// fastcal.modes.
void BindPoseModes(py::module_& m) {
  m.def(
      "modes",
      [](const CableRobot& model_argument, const DoubleArray& position_m,
         const std::string& attitude_kind, const DoubleArray& attitude, int segments, int count,
         bool cable_inertia) {
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

// fastcal.modes_cap.
void BindModesCap(py::module_& m) {
  m.def(
      "modes_cap",
      [](const CableRobot& model_argument, double max_off_axis_deg, double off_axis_step_deg,
         double azimuth_step_deg, double focal_radius_m, const DoubleArray& focal_centre_m,
         double tilt_fraction, int segments, int count) {
        const CableRobot robot = model_argument;  // a copy with the GIL held (issue 37)
        ValidateModel(robot);
        ModesMapOptions options;
        options.grid.max_off_axis_deg = max_off_axis_deg;
        options.grid.off_axis_step_deg = off_axis_step_deg;
        options.grid.azimuth_step_deg = azimuth_step_deg;
        options.grid.focal_radius_m = focal_radius_m;
        CheckRows(focal_centre_m, 3, "focal_centre");
        options.grid.focal_centre_m = Eigen::Vector3d(
            focal_centre_m.at(0, 0), focal_centre_m.at(0, 1), focal_centre_m.at(0, 2));
        options.attitude_law.focal_centre_m = options.grid.focal_centre_m;
        options.attitude_law.tilt_fraction = tilt_fraction;
        options.modes.segments = segments;
        options.modes.modes = count;
        std::string error;
        if (!options.IsValid(&error)) throw InputError(error);
        ModesMap map;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = ComputeModesMap(robot, options, &map, &error);
        }
        if (!ok) throw InputError(error);
        return ModesMapCsv(map);
      },
      py::arg("model"), py::arg("max_off_axis_deg"), py::arg("off_axis_step_deg"),
      py::arg("azimuth_step_deg"), py::arg("focal_radius_m"), py::arg("focal_centre_m"),
      py::arg("tilt_fraction"), py::arg("segments"), py::arg("modes"));
}

// fastcal.identify_modes.
void BindIdentifyModes(py::module_& m) {
  m.def(
      "identify_modes",
      [](const CableRobot& model_argument, const std::string& path, std::string method,
         int identified_modes, int segments, int count) {
        const CableRobot robot = model_argument;  // a copy with the GIL held (issue 37)
        ValidateModel(robot);
        if (method != "auto" && method != "era" && method != "ssi") {
          throw InputError(
              "identification must be 'era' (a free decay), 'ssi' (an ambient "
              "record) or 'auto', got '" +
              method + "'");
        }
        EraOptions era;
        SsiOptions ssi;
        era.modes = ssi.modes = identified_modes;
        ModesOptions options;
        options.segments = segments;
        options.modes = count;
        std::string error;
        if (!era.IsValid(&error) || !ssi.IsValid(&error) || !options.IsValid(&error)) {
          throw InputError(error);
        }
        VibrationRecordFile file;
        if (!ReadVibrationRecord(path, DatasetReadOptions(), &file, &error)) {
          throw InputError(error.rfind("the record", 0) == 0 ? path + ": " + error : error);
        }
        if (method == "auto") {
          method = EnvelopeDecayRatio(file.record) >= kFreeDecayRatio ? "era" : "ssi";
        }
        if (method == "era" && !CheckRecordSampling(file.record, era, &error)) {
          throw InputError(path + ": " + error);
        }
        std::vector<IdentifiedMode> identified;
        ModesComparisonResult comparison;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = (method == "era" ? IdentifyModesEra(file.record, era, &identified, &error)
                                : IdentifyModesSsi(file.record, ssi, &identified, &error)) &&
               CompareWithPrediction(robot, file.mean_pose, identified, options, &comparison,
                                     &error);
        }
        if (!ok) throw std::runtime_error(path + ": " + error);
        py::dict out;
        out["csv"] = ModesComparisonCsv(comparison);
        out["method"] = method;
        out["chi2_model"] = comparison.chi2_model;
        out["agrees"] = comparison.agrees;
        out["best"] = std::string(ModeParameterName(comparison.best));
        py::dict fits;
        for (int p = 0; p < kModeParameters; ++p) {
          py::dict f;
          f["relative_change"] = comparison.fits[p].relative_change;
          f["sigma"] = comparison.fits[p].sigma;
          f["chi2"] = comparison.fits[p].chi2;
          fits[py::str(ModeParameterName(p))] = f;
        }
        out["fits"] = fits;
        DoubleArray position = NewArray({3});
        for (int j = 0; j < 3; ++j) position.mutable_at(j) = file.mean_pose.position_m[j];
        out["mean_position_m"] = position;
        return out;
      },
      py::arg("model"), py::arg("path"), py::arg("identification"), py::arg("identified_modes"),
      py::arg("segments"), py::arg("modes"));
}

}  // namespace

void BindModes(py::module_& m) {
  BindPoseModes(m);
  BindModesCap(m);
  BindIdentifyModes(m);
}

}  // namespace fastcal::python
