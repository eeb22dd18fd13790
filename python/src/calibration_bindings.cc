// Calibration and evaluation (calibration.h, evaluation.h): the result as plain Python
// values and numpy arrays, in the units of the spec and the report (tensions in kN).
#include <pybind11/stl.h>

#include <cerrno>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "fastcal/cable_robot.h"
#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/report.h"
#include "fastcal/version.h"

namespace fastcal::python {
namespace {

template <typename Array>
DoubleArray PerCableKn(const Array& values_n) {
  DoubleArray out = NewArray({kNumCables});
  for (int i = 0; i < kNumCables; ++i) out.mutable_data()[i] = values_n[i] / kNPerKn;
  return out;
}

template <typename Array>
DoubleArray PerCable(const Array& values) {
  DoubleArray out = NewArray({kNumCables});
  for (int i = 0; i < kNumCables; ++i) out.mutable_data()[i] = values[i];
  return out;
}

DoubleArray Matrix(const Eigen::MatrixXd& m) {
  DoubleArray out = NewArray({m.rows(), m.cols()});
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) out.mutable_data()[r * m.cols() + c] = m(r, c);
  }
  return out;
}

py::dict Stats(const CableErrorStats& s) {
  py::dict d;
  d["samples"] = s.samples;
  d["rms_kN"] = PerCableKn(s.rms_n);
  d["mean_kN"] = PerCableKn(s.mean_n);
  d["max_abs_kN"] = PerCableKn(s.max_abs_n);
  d["rms_percent"] = PerCable(s.rms_percent);
  d["max_abs_percent"] = PerCable(s.max_abs_percent);
  d["excluded"] = std::vector<int>(s.excluded.begin(), s.excluded.end());
  return d;
}

py::dict Variant(const VariantEvaluation& v) {
  py::dict d;
  d["fit"] = Stats(v.fit);
  d["holdout"] = v.holdout.samples > 0 ? py::object(Stats(v.holdout)) : py::object(py::none());
  DoubleArray predicted = NewArray({static_cast<py::ssize_t>(v.predicted_n.size()), kNumCables});
  for (size_t n = 0; n < v.predicted_n.size(); ++n) {
    for (int i = 0; i < kNumCables; ++i) {
      predicted.mutable_data()[n * kNumCables + i] = v.predicted_n[n][i] / kNPerKn;
    }
  }
  d["predicted_kN"] = predicted;
  return d;
}

py::dict Reading(const ReadingResidual& r) {
  py::dict d;
  d["line"] = r.line;
  d["cable"] = r.cable;
  d["reading"] = r.length ? "length" : "tension";
  if (r.length) {
    d["measured_m"] = r.measured_m;
    d["predicted_m"] = r.predicted_m;
  } else {
    d["measured_kN"] = r.measured_n / kNPerKn;
    d["predicted_kN"] = r.predicted_n / kNPerKn;
  }
  d["residual_sigma"] = r.residual_sigma;
  d["held_out"] = r.held_out;
  return d;
}

py::dict Parameter(const ParameterEstimate& p, const std::vector<std::string>& groups) {
  py::dict d;
  d["name"] = p.name;
  d["unit"] = p.unit;
  d["free"] = p.free;
  d["consider"] = p.consider;
  d["initial"] = p.initial;
  d["estimate"] = p.estimate;
  d["sigma"] = p.sigma;
  d["sigma_total"] = p.sigma_total;
  d["sigma_statistical"] = p.sigma_statistical;
  d["sigma_systematic"] = p.sigma_systematic;
  d["widening"] = p.widening;
  d["tau"] = p.tau;
  py::dict by_group;
  for (size_t g = 0; g < groups.size() && g < p.systematic_by_group.size(); ++g) {
    by_group[py::str(groups[g])] = p.systematic_by_group[g];
  }
  d["systematic_by_group"] = by_group;
  d["prior_mean"] = p.has_prior ? py::object(py::float_(p.prior_mean)) : py::object(py::none());
  d["prior_sigma"] = p.has_prior ? py::object(py::float_(p.prior_sigma)) : py::object(py::none());
  d["note"] = p.note;
  return d;
}

// The sessions of a joint fit and the change scan (sessions.h, change_scan.h).
void AddSessionsAndChanges(const CalibrationResult& r, py::dict* d) {
  (*d)["sessions"] = r.session_labels;
  py::dict models;
  for (size_t s = 0; s < r.session_models.size(); ++s) {
    models[py::str(r.session_labels[s])] = r.session_models[s];
  }
  (*d)["session_models"] = models;
  py::list differences;
  for (const SessionDifference& x : r.session_differences) {
    py::dict e;
    e["name"] = x.name;
    e["unit"] = x.unit;
    e["from"] = x.from;
    e["to"] = x.to;
    e["difference"] = x.difference;
    e["sigma_total"] = x.sigma_total;
    differences.append(e);
  }
  (*d)["session_differences"] = differences;
  const ChangeScanResult& scan = r.change_scan;
  py::list changes;
  for (const FoundChange& c : scan.changes) {
    py::dict e, shifts, sigmas;
    e["time_s"] = c.time_s;
    e["line"] = c.line;
    e["sample"] = c.sample;
    e["statistic"] = c.statistic;
    e["p_value"] = c.p_value;
    for (size_t k = 0; k < c.shift.size(); ++k) {
      shifts[py::str(scan.parameters[k])] = c.shift[k];
      sigmas[py::str(scan.parameters[k])] = c.shift_sigma[k];
    }
    e["shifts"] = shifts;
    e["shift_sigmas"] = sigmas;
    changes.append(e);
  }
  (*d)["changes"] = changes;
  if (!scan.enabled) {
    (*d)["change_scan"] = py::none();
    return;
  }
  py::dict s;
  s["parameters"] = scan.parameters;
  s["time_s"] = scan.time_s;
  s["statistic"] = scan.statistic;
  s["threshold"] = scan.threshold;
  s["significance"] = scan.significance;
  s["widening"] = scan.widening;
  s["min_segment_samples"] = scan.min_segment;
  (*d)["change_scan"] = s;
}

py::dict ResultDict(const CalibrationResult& r) {
  py::dict d;
  py::list parameters;
  for (const ParameterEstimate& p : r.parameters)
    parameters.append(Parameter(p, r.budget.consider_groups));
  d["parameters"] = parameters;
  d["free_names"] = r.free_names;
  d["correlation"] = Matrix(r.correlation);
  d["covariance_ok"] = r.covariance_ok;
  py::list outliers, worst, ranking;
  for (const ReadingResidual& e : r.gross_errors) outliers.append(Reading(e));
  for (const ReadingResidual& e : r.worst_readings) worst.append(Reading(e));
  for (const MisfitCandidate& c : r.misfit_ranking) {
    py::dict m;
    m["name"] = c.name;
    m["expected_chi_square_decrease"] = c.expected_decrease;
    m["significant"] = c.significant;
    m["change"] = c.change;  // in `unit`; not meaningful when beyond_linear_range
    m["unit"] = c.unit;
    m["beyond_linear_range"] = c.beyond_linear_range;
    ranking.append(m);
  }
  d["outliers"] = outliers;
  d["worst_readings"] = worst;
  d["misfit_ranking"] = ranking;
  d["misfit_threshold"] = r.misfit_threshold;
  py::dict evaluation;
  for (const VariantEvaluation& v : r.variants) evaluation[py::str(v.name)] = Variant(v);
  d["evaluation"] = evaluation;
  d["cross_validation_rms_kN"] = r.cross_validation.folds_used > 0
                                     ? py::object(PerCableKn(r.cross_validation.rms_n))
                                     : py::object(py::none());
  d["residual_tau"] = PerCable(r.residual_tau);
  if (r.lengths.used) {  // model minus measured lengths per cable (m), before and after
    py::dict lengths;
    lengths["sigma_m"] = r.lengths.sigma_m;
    lengths["initial_rms_m"] = PerCable(r.lengths.initial.rms_m);
    lengths["calibrated_rms_m"] = PerCable(r.lengths.calibrated.rms_m);
    lengths["calibrated_mean_m"] = PerCable(r.lengths.calibrated.mean_m);
    d["lengths"] = lengths;
  } else {
    d["lengths"] = py::none();
  }
  py::dict budget;
  budget["reduced_chi_square"] = r.budget.reduced_chi_square;
  budget["misfit_factor"] = r.budget.misfit_factor;
  budget["autocorrelation_time_samples"] = r.budget.tau;
  budget["batch_length_samples"] = r.budget.bandwidth;
  budget["effective_samples"] = r.budget.effective_samples;
  budget["residuals_correlated"] = r.budget.correlated;
  budget["correlation_reliable"] = r.budget.correlation_reliable;
  budget["consider_groups"] = r.budget.consider_groups;
  d["budget"] = budget;
  d["verdict"] = std::string(FitVerdictName(r.verdict));
  d["verdict_text"] = r.verdict_text;
  d["notes"] = r.notes;
  d["strong_correlations"] = r.strong_correlations;
  d["model"] = r.calibrated;
  d["held_out"] = r.held_out;
  py::array_t<bool> excluded(
      {static_cast<py::ssize_t>(r.excluded.size()), static_cast<py::ssize_t>(kNumCables)});
  for (size_t n = 0; n < r.excluded.size(); ++n) {
    for (int i = 0; i < kNumCables; ++i)
      excluded.mutable_data()[n * kNumCables + i] = r.excluded[n][i];
  }
  d["gross_error_mask"] = excluded;
  d["num_fit_samples"] = r.num_fit_samples;
  d["num_residuals"] = r.num_residuals;
  d["num_free"] = r.num_free;
  d["initial_cost"] = r.initial_cost;
  d["final_cost"] = r.final_cost;
  d["reduced_chi_square"] = r.reduced_chi_square;
  d["iterations"] = r.iterations;
  d["converged"] = r.converged;
  d["termination"] = r.termination;
  d["forward_model_max_rel_error"] = r.forward_model_max_rel_error;
  d["seconds"] = r.seconds;
  d["ceres_report"] = r.ceres_full_report;
  AddSessionsAndChanges(r, &d);
  return d;
}

const char* StatusName(CalibrationStatus status) {
  switch (status) {
    case CalibrationStatus::kOk:
      return "ok";
    case CalibrationStatus::kInvalidInput:
      return "invalid input";
    case CalibrationStatus::kUndetermined:
      return "undetermined";
    case CalibrationStatus::kInfeasible:
      return "infeasible";
    case CalibrationStatus::kSolverFailed:
      return "solver failed";
    case CalibrationStatus::kMostlyGrossErrors:
      return "mostly gross errors";
    case CalibrationStatus::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

// The spec from a file, or from YAML text (the package turns a dict into it).
CalibrationSpec Spec(const CableRobot& model, const std::string& path_or_text, bool is_text,
                     const std::string& source_name) {
  CalibrationSpec spec;
  std::string error;
  if (!is_text) RequireExistingFile(path_or_text, "spec");
  const bool ok = is_text
                      ? ParseCalibrationSpecYaml(path_or_text, source_name, model, &spec, &error)
                      : LoadCalibrationSpec(path_or_text, model, &spec, &error);
  if (!ok) throw InputError(error);
  return spec;
}

// What a calibration's report needs after the call (CalibrationResult.report_html()):
// held by the Python result, opaque there. The data stay the caller's Dataset object.
struct CalibrationState {
  CableRobot model;
  CalibrationSpec spec;
  CalibrationResult result;
  std::string spec_source;
};

py::tuple Calibrate(const CableRobot& model_argument, const std::string& spec_path_or_text,
                    bool spec_is_text, const std::string& spec_source, const Dataset& data,
                    bool quiet) {
  // A copy, taken with the GIL held: the fit runs without it, while another thread may
  // assign to the model's fields (issue 29). The Dataset has no setters.
  auto state = std::make_shared<CalibrationState>();
  state->model = model_argument;
  ValidateModel(state->model);
  state->spec = Spec(state->model, spec_path_or_text, spec_is_text, spec_source);
  state->spec_source = spec_source;
  std::string error;
  CalibrationStatus status;
  CalibrationOptions options;
  if (!quiet) options.progress = ProgressTo("fastcal.calibrate: ");
  InterruptCheck interrupt;  // Ctrl-C between stages and solver iterations
  options.should_stop = interrupt.AsShouldStop();
  {
    py::gil_scoped_release release;
    // Calibrate's evaluation stage fills result.variants (the before/after table).
    status = fastcal::Calibrate(state->model, state->spec, data, options, &state->result, &error);
  }
  interrupt.ThrowIfInterrupted();
  if (status == CalibrationStatus::kInvalidInput) throw InputError(error);
  if (status != CalibrationStatus::kOk) throw CalibrationError(StatusName(status), error);
  return py::make_tuple(ResultDict(state->result), state);
}

// The report of a calibration (report.h) as Markdown or HTML, from its state and data.
std::string CalibrationReport(const CalibrationState& state, const Dataset& data,
                              const std::string& kind, const std::string& data_name) {
  ReportInputs inputs;
  inputs.spec_path = state.spec_source;
  inputs.data_path = data_name;
  inputs.software_version = FASTCAL_VERSION;
  inputs.command_line = "fastcal.calibrate (Python)";
  inputs.initial_model = &state.model;
  inputs.spec = &state.spec;
  inputs.data = &data;
  inputs.result = &state.result;
  inputs.variants = state.result.variants;
  inputs.evaluation_method = "exact";
  std::string text;
  {
    py::gil_scoped_release release;
    text = kind == "html" ? ReportHtml(inputs) : ReportMarkdown(inputs);
  }
  if (text.empty()) throw std::bad_alloc();
  return text;
}

py::dict Evaluate(const CableRobot& model_argument, const Dataset& data,
                  const std::string& method_name) {
  const CableRobot model = model_argument;  // as in Calibrate: a copy before the GIL goes
  ValidateModel(model);
  StaticsMethod method;
  if (!ParseStaticsMethod(method_name, &method)) {
    throw InputError("method must be 'aas', 'aas-refined' or 'exact', got '" + method_name + "'");
  }
  std::vector<VariantEvaluation> variants;
  std::string error;
  bool ok = true;
  {
    py::gil_scoped_release release;
    ok = EvaluateModel(model, data, method, &variants, &error);
  }
  if (!ok) throw CalibrationError("infeasible", error);
  py::dict out;
  for (const VariantEvaluation& v : variants) out[py::str(v.name)] = Variant(v);
  return out;
}

// A spec's white noise, for locate's weights (fastcal.locate(spec=...)): the tension
// sigmas, and the lengths' when the spec has them (None otherwise).
py::dict SpecNoise(const CableRobot& model, const std::string& spec_path_or_text, bool spec_is_text,
                   const std::string& spec_source) {
  const CalibrationSpec spec = Spec(model, spec_path_or_text, spec_is_text, spec_source);
  py::dict d;
  d["tension_sigma_kN"] = spec.tension_sigma_n / kNPerKn;
  d["tension_sigma_percent"] = spec.tension_sigma_percent;
  d["length_sigma_m"] =
      spec.UsesLengths() ? py::object(py::float_(spec.length_sigma_m)) : py::object(py::none());
  return d;
}

// Writes `text` to the new file `path` as the command line publishes its outputs (issue
// 57: report_html(path) under a file-size limit left a partial file): a temporary beside
// it, written, fsynced and renamed into place without replacing anything; a failure leaves
// nothing. FileExistsError when `path` exists (as open(path, "x") raised), OSError with
// the library's message otherwise (a full disk, a file-size limit).
void WriteNewFile(const std::string& path, const std::string& text) {
  CheckPath(path, "output");
  std::error_code ec;
  std::string error = path + ": exists (never written over)";
  bool ok = !std::filesystem::exists(path, ec);
  if (ok) {
    py::gil_scoped_release release;
    ok = internal::WriteFileAtomically(path, text, &error, /*replace=*/false);
  }
  if (ok) return;
  PyObject* kind = std::filesystem::exists(path, ec) ? PyExc_FileExistsError : PyExc_OSError;
  PyErr_SetObject(kind,
                  py::make_tuple(kind == PyExc_FileExistsError ? EEXIST : EIO, error, path).ptr());
  throw py::error_already_set();
}

}  // namespace

void BindCalibration(py::module_& m) {
  m.def("write_new_file", &WriteNewFile, py::arg("path"), py::arg("text"));
  m.def("spec_noise", &SpecNoise, py::arg("model"), py::arg("spec"), py::arg("spec_is_text"),
        py::arg("spec_source"));
  py::class_<CalibrationState, std::shared_ptr<CalibrationState>>(m, "_CalibrationState");
  m.def("calibrate", &Calibrate, py::arg("model"), py::arg("spec"), py::arg("spec_is_text"),
        py::arg("spec_source"), py::arg("data"), py::arg("quiet") = true);
  m.def("calibration_report", &CalibrationReport, py::arg("state"), py::arg("data"),
        py::arg("kind"), py::arg("data_name"));
  m.def("evaluate", &Evaluate, py::arg("model"), py::arg("data"), py::arg("method"));
}

}  // namespace fastcal::python
