// summary.json of a calibration or an evaluation (report.h, SummaryJson): provenance, the
// spec's options, the solver, every parameter with its budget, correlations, the
// diagnostics (report_diagnostics.cc), sessions and the change scan
// (report_sessions.cc), the RMS tables and per-sample statistics. Split from report.cc,
// which renders the same inputs as Markdown and HTML.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "fastcal/internal/json.h"
#include "fastcal/internal/report_sections.h"
#include "fastcal/internal/units.h"
#include "fastcal/report.h"

namespace fastcal::internal {

double RmsAllCables(const std::array<double, kNumCables>& rms) {
  double sum = 0.0;
  for (double r : rms) sum += r * r;
  return std::sqrt(sum / kNumCables);
}

int NumSamples(const ReportInputs& in) {
  if (in.sample_stream != nullptr) return static_cast<int>(in.sample_stream->samples);
  return in.data ? static_cast<int>(in.data->samples.size()) : 0;
}

int NumHeldOut(const ReportInputs& in) {
  if (!in.result) return 0;
  return static_cast<int>(std::count(in.result->held_out.begin(), in.result->held_out.end(), true));
}

std::vector<std::vector<double>> CorrelationRows(const CalibrationResult& r) {
  std::vector<std::vector<double>> m(r.correlation.rows(),
                                     std::vector<double>(r.correlation.cols()));
  for (Eigen::Index i = 0; i < r.correlation.rows(); ++i) {
    for (Eigen::Index j = 0; j < r.correlation.cols(); ++j) m[i][j] = r.correlation(i, j);
  }
  return m;
}

bool CorrelationUsable(const CalibrationResult& r) {
  const Eigen::Index n = static_cast<Eigen::Index>(r.free_names.size());
  return r.covariance_ok && n > 0 && r.correlation.rows() == n && r.correlation.cols() == n;
}

namespace {

void JsonFile(JsonWriter* w, const std::string& key, const std::string& path,
              const std::string& digest) {
  w->Key(key).BeginObject();
  w->Key("path");
  if (path.empty())
    w->Null();
  else
    w->String(path);
  w->Key("sha256");
  if (digest.empty())
    w->Null();
  else
    w->String(digest);
  w->EndObject();
}

template <typename Array>
void JsonKnArray(JsonWriter* w, const std::string& key, const Array& values_n) {
  std::vector<double> kn;
  for (double v : values_n) kn.push_back(v / kNPerKn);
  w->Key(key).NumberArray(kn);
}

void JsonStats(JsonWriter* w, const CableErrorStats& s) {
  w->BeginObject();
  w->Key("samples").Int(s.samples);
  JsonKnArray(w, "rms_kN", s.rms_n);
  w->Key("rms_all_cables_kN").Number(RmsAllCables(s.rms_n) / kNPerKn);
  JsonKnArray(w, "max_abs_kN", s.max_abs_n);
  w->Key("rms_percent").NumberArray(s.rms_percent);
  w->Key("max_abs_percent").NumberArray(s.max_abs_percent);
  JsonKnArray(w, "mean_kN", s.mean_n);
  w->EndObject();
}

void JsonDirections(JsonWriter* w, const std::string& key,
                    const std::vector<ParameterDirection>& directions) {
  w->Key(key).BeginArray();
  for (const ParameterDirection& d : directions) {
    w->BeginObject();
    w->Key("ratio").Number(d.singular_value_ratio);
    w->Key("description").String(d.Describe());
    w->Key("weights").BeginObject();
    for (const auto& [name, weight] : d.weights) w->Key(name).Number(weight);
    w->EndObject();
    w->EndObject();
  }
  w->EndArray();
}

void JsonIdentifiability(JsonWriter* w, const std::string& key, const Identifiability& id) {
  w->Key(key).BeginObject();
  w->Key("singular_value_ratios").NumberArray(id.singular_value_ratios);
  JsonDirections(w, "undetermined", id.undetermined);
  JsonDirections(w, "poorly_determined", id.poorly_determined);
  w->EndObject();
}

// Writes `key` with the object `body` writes, or null when `present` is false (the
// summary's sections that only a calibration, or only a spec, has).
template <typename Body>
void ObjectOrNull(JsonWriter* w, const char* key, bool present, Body&& body) {
  w->Key(key);
  if (!present) {
    w->Null();
    return;
  }
  w->BeginObject();
  body();
  w->EndObject();
}

// What was run, on what: version, command line, time, inputs, spec.
void JsonProvenance(const ReportInputs& in, JsonWriter* w) {
  const CalibrationResult* r = in.result;
  const CalibrationSpec* spec = in.spec;
  w->Key("report").String(r ? "calibration" : "evaluation");
  w->Key("software_version").String(in.software_version);
  w->Key("command_line").String(in.command_line);
  w->Key("run_utc");
  if (in.run_utc.empty())
    w->Null();
  else
    w->String(in.run_utc);
  w->Key("inputs").BeginObject();
  JsonFile(w, "model", in.model_path, in.model_digest);
  JsonFile(w, "spec", in.spec_path, in.spec_digest);
  JsonFile(w, "data", in.data_path, in.data_digest);
  JsonFile(w, "columns", in.columns_path, in.columns_digest);
  w->EndObject();
  // Whose pose the data give (measured_frame.h): null for the cabin's own frame.
  const CableRobot* model = in.initial_model != nullptr ? in.initial_model
                            : r != nullptr              ? &r->calibrated
                                                        : nullptr;
  ObjectOrNull(w, "data_frame", model != nullptr && model->measured_frame.has_value(), [&] {
    const MeasuredFrame& f = *model->measured_frame;
    w->Key("part").String(f.part < 0 ? "cabin" : model->moving_parts.parts[f.part].name);
    w->Key("offset_m").NumberArray(f.offset_m);
  });
  w->Key("spec_yaml");
  if (spec)
    w->String(CalibrationSpecToYaml(*spec));
  else
    w->Null();
  w->Key("forward_model");
  if (spec)
    w->String(StaticsMethodName(spec->forward_model));
  else
    w->Null();
  w->Key("evaluation_method").String(in.evaluation_method);
}

// The spec's noise model, robust loss and hold-out.
void JsonSpecOptions(const ReportInputs& in, JsonWriter* w) {
  const CalibrationSpec* spec = in.spec;
  ObjectOrNull(w, "noise", spec != nullptr, [&] {
    w->Key("sigma_kN").Number(spec->tension_sigma_n / kNPerKn);
    w->Key("sigma_percent").Number(spec->tension_sigma_percent);
  });
  ObjectOrNull(w, "robust_loss", spec != nullptr, [&] {
    w->Key("type").String(RobustLossName(spec->robust_loss));
    w->Key("scale_sigma").Number(spec->robust_loss_scale);
  });
  ObjectOrNull(w, "holdout", spec != nullptr, [&] {
    w->Key("fraction").Number(spec->holdout_fraction);
    w->Key("blocks").Int(spec->holdout_blocks);
    w->Key("seed");
    if (spec->holdout_seed <= static_cast<unsigned long long>(LLONG_MAX)) {
      w->Int(static_cast<long long>(spec->holdout_seed));
    } else {
      w->String(std::to_string(spec->holdout_seed));
    }
  });
}

// The solver's summary and the forward model's own error.
void JsonSolver(const ReportInputs& in, JsonWriter* w) {
  const CalibrationResult* r = in.result;
  ObjectOrNull(w, "solver", r != nullptr, [&] {
    w->Key("termination").String(r->termination);
    w->Key("converged").Bool(r->converged);
    w->Key("iterations").Int(r->iterations);
    w->Key("initial_cost").Number(r->initial_cost);
    w->Key("final_cost").Number(r->final_cost);
    w->Key("reduced_chi_square").Number(r->reduced_chi_square);
    const ChiSquareBand band = ReducedChiSquareBand(*r);
    w->Key("reduced_chi_square_band_half_width").Number(band.half_width);
    w->Key("reduced_chi_square_within_band").Bool(band.within);
    w->Key("num_residuals").Int(r->num_residuals);
    w->Key("num_free").Int(r->num_free);
    w->Key("covariance_ok").Bool(r->covariance_ok);
    w->Key("seconds").Number(r->seconds);
  });
  ObjectOrNull(w, "forward_model_error", r != nullptr, [&] {
    w->Key("max_relative").Number(r->forward_model_max_rel_error);
    w->Key("rms_relative").Number(r->forward_model_rms_rel_error);
  });
}

// Every parameter the spec names, with its budget.
void JsonParameters(const ReportInputs& in, JsonWriter* w) {
  const CalibrationResult* r = in.result;
  w->Key("parameters").BeginArray();
  if (r) {
    for (const ParameterEstimate& p : r->parameters) {
      w->BeginObject();
      w->Key("name").String(p.name);
      w->Key("unit").String(p.unit);
      w->Key("free").Bool(p.free);
      w->Key("initial").Number(p.initial);
      w->Key("estimate").Number(p.estimate);
      w->Key("consider").Bool(p.consider);
      w->Key("sigma");  // formal
      if (p.free && r->covariance_ok)
        w->Number(p.sigma);
      else
        w->Null();
      w->Key("sigma_total");
      if ((p.free && r->covariance_ok) || p.consider)
        w->Number(p.sigma_total);
      else
        w->Null();
      ObjectOrNull(w, "budget", p.free && r->covariance_ok, [&] {
        w->Key("formal").Number(p.sigma);
        w->Key("statistical").Number(p.sigma_statistical);
        w->Key("widening").Number(p.widening);
        w->Key("misfit_factor").Number(r->budget.misfit_factor);
        w->Key("correlation_factor").Number(p.widening / r->budget.misfit_factor);
        w->Key("autocorrelation_time_samples").Number(p.tau);
        w->Key("systematic").Number(p.sigma_systematic);
        w->Key("systematic_by_group").BeginObject();
        for (size_t g = 0; g < r->budget.consider_groups.size(); ++g) {
          w->Key(r->budget.consider_groups[g])
              .Number(g < p.systematic_by_group.size() ? p.systematic_by_group[g] : 0.0);
        }
        w->EndObject();
      });
      ObjectOrNull(w, "prior", p.has_prior, [&] {
        w->Key("mean").Number(p.prior_mean);
        w->Key("sigma").Number(p.prior_sigma);
      });
      ObjectOrNull(w, "not_sound", !p.moved_by.empty(), [&] {
        w->Key("candidate").String(p.moved_by);
        w->Key("shift").Number(p.moved_by_shift);
        w->Key("sigma_total_multiples").Number(p.moved_by_sigmas);
      });
      w->Key("note").String(p.note);
      w->EndObject();
    }
  }
  w->EndArray();
}

// Correlation, the diagnostics of calibration.h and identifiability.
void JsonCorrelations(const ReportInputs& in, JsonWriter* w) {
  const CalibrationResult* r = in.result;
  ObjectOrNull(w, "correlation", r && CorrelationUsable(*r), [&] {
    w->Key("names").BeginArray();
    for (const std::string& n : r->free_names) w->String(n);
    w->EndArray();
    w->Key("matrix").BeginArray();
    for (const auto& row : CorrelationRows(*r)) w->NumberArray(row);
    w->EndArray();
  });
  w->Key("strong_correlations").BeginArray();
  if (r) {
    for (const std::string& c : r->strong_correlations) w->String(c);
  }
  w->EndArray();
  if (r) internal::WriteDiagnosticsJson(*r, w);
  if (r) internal::WriteSessionsJson(*r, w);
  if (r) internal::WriteChangeScanJson(*r, w);
  ObjectOrNull(w, "identifiability", r != nullptr, [&] {
    JsonIdentifiability(w, "before", r->before);
    JsonIdentifiability(w, "after", r->after);
    JsonIdentifiability(w, "data_only", r->data_only);
  });
}

// The RMS tables of each variant.
void JsonEvaluation(const ReportInputs& in, JsonWriter* w) {
  w->Key("evaluation").BeginArray();
  for (const VariantEvaluation& v : in.variants) {
    w->BeginObject();
    w->Key("name").String(v.name);
    w->Key("fit");
    JsonStats(w, v.fit);
    w->Key("holdout");
    if (v.holdout.samples > 0)
      JsonStats(w, v.holdout);
    else
      w->Null();
    w->EndObject();
  }
  w->EndArray();
  internal::WriteEvaluationGrossErrorsJson(in, w);  // evaluate's screen, when it has one
}

// How many samples, fitted, held out and skipped.
void JsonSamples(const ReportInputs& in, JsonWriter* w) {
  const CalibrationResult* r = in.result;
  w->Key("samples").BeginObject();
  w->Key("total").Int(NumSamples(in));
  w->Key("fitted");
  if (r)
    w->Int(r->num_fit_samples);
  else
    w->Null();
  w->Key("held_out");
  if (r)
    w->Int(NumHeldOut(in));
  else
    w->Null();
  // Rows left out of the dataset (malformed, or a pose the model cannot solve), each
  // "file:line: why".
  w->Key("skipped").Int(in.data ? static_cast<long long>(in.data->skipped.size()) : 0);
  w->Key("skipped_rows").BeginArray();
  if (in.data) {
    for (const std::string& why : in.data->skipped) w->String(why);
  }
  w->EndArray();
  // The samples' first and last time: time_s to 17 digits, and as dates and times (ISO
  // 8601, the data's zone) when they are Unix times (time_text.h), else null.
  double first = std::numeric_limits<double>::infinity(), last = -first;
  if (in.sample_stream != nullptr) {
    first = in.sample_stream->time_min_s;
    last = in.sample_stream->time_max_s;
  } else if (in.data) {
    for (const Sample& s : in.data->samples) {
      first = std::min(first, s.time_s);
      last = std::max(last, s.time_s);
    }
  }
  const TimeDisplay display = TimeDisplayFor(first, in.data ? in.data->time_offset_s : 0);
  w->Key("time_first_s").ExactNumber(first);
  w->Key("time_last_s").ExactNumber(last);
  w->Key("time_first");
  if (display.absolute) w->String(IsoUnixTime(first, display.offset_s)); else w->Null();
  w->Key("time_last");
  if (display.absolute) w->String(IsoUnixTime(last, display.offset_s)); else w->Null();
  w->EndObject();
}

}  // namespace

std::string RenderJson(const ReportInputs& in) {
  JsonWriter w;
  w.BeginObject();
  for (const auto section : {JsonProvenance, JsonSpecOptions, JsonSolver, JsonParameters,
                             JsonCorrelations, JsonEvaluation, JsonSamples}) {
    section(in, &w);
  }
  w.EndObject();
  return w.str();
}

}  // namespace fastcal::internal
