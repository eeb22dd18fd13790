// Tracking (track.h): the track run with the GIL released, its folds on this machine's
// threads or handed to a Python callable (the package sends them to Dask workers), and
// one fold task run without the GIL (what a worker calls). The result as plain values.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.h"
#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/track.h"
#include "fastcal/track_fold.h"

namespace fastcal::python {
namespace {

py::dict Estimate(const TrackEstimate& e) {
  py::dict d;
  d["value"] = e.value;
  d["sigma_total"] = e.sigma_total;
  d["sigma_formal"] = e.sigma_formal;
  return d;
}

py::dict WindowDict(const TrackResult& r, const TrackWindow& w) {
  py::dict d;
  d["label"] = w.label;
  d["start_s"] = w.start_s;
  d["end_s"] = w.end_s;
  d["first_time_s"] = w.first_time_s;
  d["last_time_s"] = w.last_time_s;
  d["samples"] = w.samples;
  d["readings"] = w.readings;
  d["gross_errors"] = w.gross_errors;
  d["reduced_chi_square"] = w.reduced_chi_square;
  d["widening"] = w.widening;
  d["folded"] = w.folded;
  py::dict estimates;
  for (size_t k = 0; k < r.window_parameters.size(); ++k) {
    estimates[py::str(r.window_parameters[k])] = Estimate(w.estimates[k]);
  }
  d["estimates"] = estimates;
  py::dict offsets;
  for (int i = 0; w.has_offsets && i < kNumCables; ++i) {
    offsets[py::int_(i + 1)] = Estimate(w.offset_kn[i]);
  }
  d["sensor_offset_kN"] = offsets;
  return d;
}

py::dict EventDict(const TrackResult& r, const TrackEvent& e) {
  py::dict d;
  d["kind"] = e.kind;
  d["time_s"] = e.time_s;
  d["after_s"] = e.previous_time_s;
  d["time_low_s"] = e.time_low_s;
  d["time_high_s"] = e.time_high_s;
  d["window"] = r.windows[e.window].label;
  d["previous_window"] = r.windows[e.previous_window].label;
  d["within_window"] = e.within_window;
  d["new"] = e.is_new;
  py::dict parameters;
  for (const TrackEventParameter& p : e.parameters) {
    py::dict q;
    q["shift"] = p.shift;
    q["sigma_total"] = p.sigma_total;
    q["unit"] = p.unit;
    parameters[py::str(p.name)] = q;
  }
  d["parameters"] = parameters;
  // A change inside a window: the window's two parts (track.h, TrackEvent::parts).
  py::list parts;
  for (const TrackWindowPart& part : e.parts) {
    py::dict x;
    x["start_s"] = part.start_s;
    x["end_s"] = part.end_s;
    x["samples"] = part.samples;
    py::dict estimates;
    for (size_t k = 0; k < part.estimates.size() && k < e.parameters.size(); ++k) {
      py::dict v;
      v["value"] = part.estimates[k].value;
      v["sigma_total"] = part.estimates[k].sigma_total;
      estimates[py::str(e.parameters[k].name)] = v;
    }
    x["estimates"] = estimates;
    parts.append(x);
  }
  d["parts"] = parts;
  d["cables"] = e.cables;
  d["statistic"] = e.statistic;
  d["degrees_of_freedom"] = e.degrees_of_freedom;
  d["threshold"] = e.threshold;
  d["p_value"] = e.p_value;
  return d;
}

py::dict ResultDict(const TrackResult& r) {
  py::dict d;
  py::list windows, events, shared;
  for (const TrackWindow& w : r.windows) windows.append(WindowDict(r, w));
  for (const TrackEvent& e : r.events) events.append(EventDict(r, e));
  for (const TrackShared& s : r.shared) {
    py::dict p;
    p["name"] = s.name;
    p["unit"] = s.unit;
    p["estimate"] = Estimate(s.estimate);
    p["from_window"] = r.windows[s.from_window].label;
    p["to_window"] = r.windows[s.to_window].label;
    shared.append(p);
  }
  d["windows"] = windows;
  d["events"] = events;
  d["shared"] = shared;
  d["window_parameters"] = r.window_parameters;
  d["files"] = r.files;
  d["window"] = WindowSpecText(r.window);
  d["slow_error"] = r.slow_error.enabled ? DescribeSlowError(r.slow_error) : std::string();
  d["samples"] = r.samples;
  d["reduced_chi_square"] = r.reduced_chi_square;
  d["iterations"] = r.iterations;
  d["converged"] = r.converged;
  d["folds"] = r.folds;
  d["updated"] = r.updated;
  d["notes"] = r.notes;
  py::list wander;
  for (const TrackWander& w : r.wander) {
    py::dict x;
    x["parameters"] = w.group;
    x["rms"] = w.rms;
    x["unit"] = w.unit;
    py::dict inside;
    inside["components"] = w.components;
    inside["rms"] = w.inside_rms;
    inside["rms_sigma"] = w.inside_rms_sigma;
    inside["time_constant_s"] = w.inside_time_constant_s;
    inside["log_time_constant_sigma"] = w.inside_log_time_constant_sigma;
    inside["windows"] = w.inside_windows;
    inside["likelihood_ratio"] = w.inside_likelihood_ratio;
    inside["significant"] = w.inside_significant;
    inside["left_out"] = w.inside_left_out;
    x["inside"] = inside;
    x["description"] = DescribeWander(w);
    wander.append(x);
  }
  d["wander"] = wander;
  std::vector<std::string> models;
  for (const auto& m : r.models) models.push_back("model_calibrated@" + m.first + ".yaml");
  d["models"] = models;
  return d;
}

const char* StatusName(TrackStatus status) {
  switch (status) {
    case TrackStatus::kOk:
      return "ok";
    case TrackStatus::kInvalidInput:
      return "invalid input";
    case TrackStatus::kInfeasible:
      return "infeasible";
    case TrackStatus::kUndetermined:
      return "undetermined";
    case TrackStatus::kFailed:
      return "failed";
    case TrackStatus::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

// fold_many(list of task bytes) -> list of fold bytes, or None to fold on threads.
py::dict Track(const CableRobot& model_argument, const std::string& spec_path_or_text,
               bool spec_is_text, const std::string& spec_source,
               const std::vector<std::string>& data, const std::string& out,
               const std::string& window_text, int threads, bool refold, bool force,
               const std::string& map_text, const std::string& map_source,
               const py::object& fold_many, bool quiet) {
  // A copy with the GIL held: the track runs without it, and wrote another model than the
  // one it fitted when another thread assigned to this one meanwhile (issue 37).
  const CableRobot model = model_argument;
  ValidateModel(model);
  CalibrationSpec spec;
  std::string error;
  if (!spec_is_text) RequireExistingFile(spec_path_or_text, "spec");
  if (!(spec_is_text
            ? ParseCalibrationSpecYaml(spec_path_or_text, spec_source, model, &spec, &error)
            : LoadCalibrationSpec(spec_path_or_text, model, &spec, &error))) {
    throw InputError(error);
  }
  WindowSpec window;
  if (!ParseWindowSpec(window_text, &window, &error)) throw InputError(error);
  TrackOptions options;
  options.threads = threads;
  options.refold_all = refold;
  options.force = force;
  if (!quiet) options.progress = ProgressTo("fastcal.track: ");
  InterruptCheck interrupt;  // Ctrl-C between files, stages and iterations
  options.should_stop = interrupt.AsShouldStop();
  options.read.columns = MapOrThrow(map_text, map_source, false, false);
  if (!fold_many.is_none()) {
    options.runner = [&fold_many](const std::vector<std::string>& tasks,
                                  std::vector<std::string>* folds, std::string* why) {
      py::gil_scoped_acquire acquire;
      try {
        py::list bytes;
        for (const std::string& t : tasks) bytes.append(py::bytes(t));
        folds->clear();
        for (const py::handle& f : fold_many(bytes)) folds->push_back(f.cast<std::string>());
        return true;
      } catch (const py::error_already_set& e) {
        *why = std::string("the fold runner failed: ") + e.what();
        return false;
      }
    };
  }
  TrackResult result;
  TrackStatus status;
  {
    py::gil_scoped_release release;
    status = RunTrack(model, spec, data, window, out, options, &result, &error);
  }
  interrupt.ThrowIfInterrupted();
  if (status == TrackStatus::kInvalidInput) throw InputError(error);
  if (status != TrackStatus::kOk) throw CalibrationError(StatusName(status), error);
  return ResultDict(result);
}

// One fold task's bytes to the fold's bytes, without the GIL: a Dask worker's task.
py::bytes FoldTaskBytes(const py::bytes& task) {
  const std::string in = task;
  std::string out, error;
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = RunFoldTask(in, &out, &error);
  }
  if (!ok) throw CalibrationError("infeasible", error);
  return py::bytes(out);
}

}  // namespace

void BindTrack(py::module_& m) {
  m.def("track", &Track, py::arg("model"), py::arg("spec"), py::arg("spec_is_text"),
        py::arg("spec_source"), py::arg("data"), py::arg("out"), py::arg("window"),
        py::arg("threads"), py::arg("refold"), py::arg("force"), py::arg("map_text"),
        py::arg("map_source"), py::arg("fold_many"), py::arg("quiet") = true);
  m.def("fold_task", &FoldTaskBytes, py::arg("task"));
}

}  // namespace fastcal::python
