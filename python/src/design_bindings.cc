// fastcal._fastcal.design: the survey design (design.h) as a dict of numpy arrays and
// plain values; the package's fastcal.design names the arguments and documents them.
#include <pybind11/stl.h>

#include "bindings.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/design.h"

namespace fastcal::python {
namespace {

py::dict Prediction(const Design& d, const DesignPrediction& p) {
  py::dict out;
  out["ok"] = p.ok;
  out["note"] = p.note;
  py::dict sigma;  // in each parameter's spec unit (kN for sensor_bias_kN), as calibrate's
  for (size_t k = 0; k < d.free_names.size(); ++k) {
    sigma[py::str(d.free_names[k])] = p.ok ? p.budget.parameters[k].total / d.free_to_si[k] : NAN;
  }
  out["sigma_total"] = sigma;
  out["criterion"] = p.ok ? p.criterion : NAN;
  return out;
}

py::dict DesignDict(const Design& d) {
  py::dict out;
  // In the data's frame (the model's measured frame), as poses.csv.
  DoubleArray poses = NewArray({static_cast<py::ssize_t>(d.data_poses.size()), 6});
  for (size_t n = 0; n < d.data_poses.size(); ++n) {
    const Eigen::Vector3d rpy = RpyDegFromRotation(d.data_poses[n].rotation);
    for (int c = 0; c < 3; ++c) {
      poses.mutable_data()[6 * n + c] = d.data_poses[n].position_m[c];
      poses.mutable_data()[6 * n + 3 + c] = rpy[c];
    }
  }
  out["poses"] = poses;
  py::list stops;
  for (const DesignStop& s : d.stops) {
    const DesignCandidate& c = d.candidates[s.candidate];
    py::dict stop;
    stop["samples"] = s.samples;
    stop["position_m"] =
        std::vector<double>(c.data_pose.position_m.data(), c.data_pose.position_m.data() + 3);
    stop["extra_tilt_deg"] = c.extra_tilt_deg;
    stop["tilt_direction_deg"] = c.tilt_direction_deg;
    stop["extra_yaw_deg"] = c.extra_yaw_deg;
    stop["settle_s"] = s.settle.wait_s;
    stops.append(stop);
  }
  out["stops"] = stops;
  py::list wanted;
  for (int k : d.wanted) wanted.append(d.free_names[k]);
  out["wanted"] = wanted;
  out["candidates"] = d.candidates.size();
  out["rejected_candidates"] = d.rejected_candidates;
  out["path_length_m"] = d.path_length_m;
  out["duration_s"] = d.options.speed_m_per_s > 0.0 ? d.duration_s : NAN;
  out["settle_s"] = d.settle_s;
  py::dict units;
  for (size_t k = 0; k < d.free_names.size(); ++k)
    units[py::str(d.free_names[k])] = d.free_units[k];
  out["units"] = units;
  out["design"] = Prediction(d, d.design);
  out["circle"] = Prediction(d, d.circle);
  out["random"] = Prediction(d, d.random);
  out["limiting_part"] = d.limiting_part;
  out["limiting_share"] = d.limiting_share;
  py::dict halved;
  for (const DesignPriorEffect& e : d.prior_effects) {
    py::dict sigma;
    for (size_t w = 0; w < e.sigma_total.size(); ++w) {
      sigma[py::str(d.free_names[d.wanted[w]])] = e.sigma_total[w] / d.free_to_si[d.wanted[w]];
    }
    halved[py::str(e.group)] = sigma;
  }
  out["prior_halved"] = halved;
  return out;
}

py::dict RunDesign(const CableRobot& model_argument, const std::string& spec_path_or_text,
                   bool is_text, const std::string& spec_source, const py::dict& o) {
  // A copy before the GIL is released (issue 29: another thread may change the model).
  const CableRobot model = model_argument;
  ValidateModel(model);
  if (!is_text) RequireExistingFile(spec_path_or_text, "spec");
  CalibrationSpec spec;
  std::string error;
  const int anchors = static_cast<int>(model.anchor_points_cabin_m.size());
  if (!(is_text ? ParseCalibrationSpecYaml(spec_path_or_text, spec_source, anchors, &spec, &error)
                : LoadCalibrationSpec(spec_path_or_text, anchors, &spec, &error))) {
    throw InputError(error);
  }
  DesignOptions options;
  options.samples = o["samples"].cast<int>();
  options.max_extra_tilt_deg = o["max_extra_tilt_deg"].cast<double>();
  options.max_extra_yaw_deg = o["max_extra_yaw_deg"].cast<double>();
  const std::string criterion = o["criterion"].cast<std::string>();
  if (criterion != "A" && criterion != "D") {
    throw InputError("criterion must be 'A' or 'D', got '" + criterion + "'");
  }
  options.criterion = criterion == "A" ? DesignCriterion::kA : DesignCriterion::kD;
  options.wanted = o["parameters"].cast<std::vector<std::string>>();
  options.seed = o["seed"].cast<std::uint64_t>();
  options.speed_m_per_s = o["speed_m_per_s"].cast<double>();
  options.sample_interval_s = o["sample_interval_s"].cast<double>();
  options.time_budget_s = o["time_budget_s"].cast<double>();
  const double settle_fraction = o["settle_fraction"].cast<double>();
  options.settle_after_moves = settle_fraction != 0.0;
  if (options.settle_after_moves) options.settle.fraction = settle_fraction;
  // None keeps the library's default (design.h: the workspace grid, the design's margins).
  auto set = [&o](const char* key, double scale, double* value) {
    if (!o[key].is_none()) *value = o[key].cast<double>() * scale;
  };
  WorkspaceOptions& w = options.workspace;
  set("min_tension_kN", kNPerKn, &w.min_tension_n);
  set("max_tension_kN", kNPerKn, &w.max_tension_n);
  set("reflector_clearance_m", 1.0, &w.statics.min_reflector_clearance_m);
  set("max_off_axis_deg", 1.0, &w.grid.max_off_axis_deg);
  set("off_axis_step_deg", 1.0, &w.grid.off_axis_step_deg);
  set("azimuth_step_deg", 1.0, &w.grid.azimuth_step_deg);
  Design d;
  bool ok = true;
  {
    py::gil_scoped_release release;
    ok = DesignSurvey(model, spec, options, &d, &error);
  }
  if (!ok) throw InputError(error);
  return DesignDict(d);
}

}  // namespace

void BindDesign(py::module_& m) {
  m.def("design", &RunDesign, py::arg("model"), py::arg("spec"), py::arg("spec_is_text"),
        py::arg("spec_source"), py::arg("options"));
}

}  // namespace fastcal::python
