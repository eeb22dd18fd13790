// The track's outputs (track.h): the models of the latest window and of each event-free
// stretch, track.csv, events.json, the models' files and track.html.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/number_text.h"
#include "track/track_run.h"

namespace fastcal::internal {
namespace {

namespace fs = std::filesystem;

std::string Num(double v) { return v == 0.0 ? "0" : FormatDouble("%.10g", v); }

// The labels of a window's two parts around a change inside it (TrackEvent::parts).
constexpr const char* kPartSuffix[2] = {"_before", "_after"};

std::string ValueText(double value, double sigma, const std::string& unit) {
  return FormatDouble("%.6g", value) + " +- " + FormatDouble("%.2g", sigma) +
         (unit == "1" ? "" : " " + unit);
}

// The model at the window parameters `a` (SI, window columns) with b's entries of used
// window u, and its comment lines.
CableRobot ModelAt(const TrackRun& run, const Eigen::VectorXd& a, int u) {
  CalibrationSpec spec = run.spec;
  spec.parameters = run.layout.parameters;
  const CalibrationModel cm(run.model, spec);
  std::vector<double> theta(run.layout.size());
  for (size_t k = 0; k < run.layout.window_columns.size(); ++k) {
    theta[run.layout.window_columns[k]] = a[k];
  }
  for (size_t j = 0; j < run.layout.shared_columns.size(); ++j) {
    theta[run.layout.shared_columns[j]] = run.solver.b()[run.entry_of[u][j]];
  }
  for (size_t c = 0; c < run.layout.consider_columns.size(); ++c) {
    theta[run.layout.consider_columns[c]] = run.consider_si[c];
  }
  return cm.ToRobot(theta.data());
}

std::string ModelComment(const TrackRun& run, const std::string& what, const Eigen::VectorXd& a,
                         const Eigen::MatrixXd& covariance, int u) {
  std::string text = "fastcal track: " + what + "\n";
  for (size_t k = 0; k < run.layout.window_columns.size(); ++k) {
    const ParameterSpec& s = run.layout.Column(run.layout.window_columns[k]);
    text +=
        "  " + s.name + " = " +
        ValueText(a[k] / s.to_si, std::sqrt(std::max(0.0, covariance(k, k))) / s.to_si, s.unit) +
        " (sigma_total)\n";
  }
  for (size_t j = 0; j < run.layout.shared_columns.size(); ++j) {
    const TrackShared& s = run.result->shared[run.entry_of[u][j]];
    text += "  " + s.name + " = " + ValueText(s.estimate.value, s.estimate.sigma_total, s.unit) +
            " (shared)\n";
  }
  return text;
}

std::string CsvHeader(const TrackResult& r, bool offsets) {
  std::string h = "window_start,window_end,samples";
  for (const std::string& name : r.window_parameters) h += "," + name + "," + name + "_sigma_total";
  for (int i = 1; offsets && i <= kNumCables; ++i) {
    const std::string name = "sensor_offset_kN[" + std::to_string(i) + "]";
    h += "," + name + "," + name + "_sigma_total";
  }
  return h + ",reduced_chi_square,widening,gross_errors,window\n";
}

// The parameter event inside window w with its two parts, or null.
const TrackEvent* SplitEventOf(const TrackResult& r, size_t w) {
  for (const TrackEvent& e : r.events) {
    if (e.within_window && e.window == static_cast<int>(w) && e.parts.size() == 2) return &e;
  }
  return nullptr;
}

// Window w's estimates with the event's parameters taken from one of its parts.
std::vector<TrackEstimate> PartEstimates(const TrackResult& r, const TrackWindow& w,
                                         const TrackEvent& e, const TrackWindowPart& part) {
  std::vector<TrackEstimate> out = w.estimates;
  for (size_t x = 0; x < e.parameters.size() && x < part.estimates.size(); ++x) {
    for (size_t k = 0; k < r.window_parameters.size(); ++k) {
      if (r.window_parameters[k] == e.parameters[x].name) out[k] = part.estimates[x];
    }
  }
  return out;
}

std::string TrackCsv(const TrackResult& r) {
  const bool offsets = !r.windows.empty() && r.windows.front().has_offsets;
  std::string csv = CsvHeader(r, offsets);
  for (const TrackRow& row : TrackRows(r)) {
    const TrackWindow& w = *row.window;
    csv += TrackTimeText(row.start_s, r.time_offset_s) + "," +
           TrackTimeText(row.end_s, r.time_offset_s) + "," + std::to_string(row.samples);
    for (const TrackEstimate& e : row.estimates) {
      csv += "," + Num(e.value) + "," + Num(e.sigma_total);
    }
    for (int i = 0; offsets && i < kNumCables; ++i) {
      csv += "," + Num(w.offset_kn[i].value) + "," + Num(w.offset_kn[i].sigma_total);
    }
    csv += "," + Num(w.reduced_chi_square) + "," + Num(w.widening) + "," +
           std::to_string(w.gross_errors) + "," + row.label + "\n";
  }
  return csv;
}

// Each per-window group's wander between windows beyond its errors (track.h): the
// parameter events are steps beyond it.
void WanderJson(const TrackResult& r, JsonWriter* j) {
  j->Key("wander").BeginArray();
  for (const TrackWander& w : r.wander) {
    j->BeginObject();
    j->Key("parameters").String(w.group);
    j->Key("rms").Number(w.rms);
    j->Key("unit").String(w.unit);
    // Inside the windows (track.h, TrackWander): per component, and the time constant.
    j->Key("inside").BeginObject();
    j->Key("components").BeginArray();
    for (size_t x = 0; x < w.components.size(); ++x) {
      j->BeginObject();
      j->Key("parameter").String(w.components[x]);
      j->Key("rms").Number(w.inside_rms[x]);
      j->Key("rms_sigma").Number(w.inside_rms_sigma[x]);
      j->EndObject();
    }
    j->EndArray();
    j->Key("time_constant_s").Number(w.inside_time_constant_s);
    j->Key("log_time_constant_sigma").Number(w.inside_log_time_constant_sigma);
    j->Key("windows").Int(w.inside_windows);
    j->Key("likelihood_ratio").Number(w.inside_likelihood_ratio);
    j->Key("significant").Bool(w.inside_significant);
    j->Key("left_out").BeginArray();
    for (const std::string& label : w.inside_left_out) j->String(label);
    j->EndArray();
    j->EndObject();
    j->EndObject();
  }
  j->EndArray();
}

std::string EventsJson(const TrackResult& r) {
  JsonWriter j;
  j.BeginObject();
  j.Key("format").String("fastcal-events-1");
  j.Key("false_alarm").Number(r.false_alarm);
  j.Key("false_alarm_meaning")
      .String(
          "for each kind of event, the chance that noise alone reports any over the whole "
          "track (Bonferroni over its tests)");
  j.Key("parameter_tests").Int(r.parameter_tests);
  j.Key("sensor_tests").Int(r.sensor_tests);
  j.Key("windows").Int(static_cast<long long>(r.windows.size()));
  // Events not reported by the track's previous run (each event's `new`).
  j.Key("new_events").Int(r.NewEvents());
  WanderJson(r, &j);
  j.Key("events").BeginArray();
  for (const TrackEvent& e : r.events) {
    j.BeginObject();
    j.Key("time").String(TrackTimeText(e.time_s, r.time_offset_s));
    j.Key("time_s").ExactNumber(e.time_s);
    j.Key("after").String(TrackTimeText(e.previous_time_s, r.time_offset_s));
    j.Key("after_s").ExactNumber(e.previous_time_s);
    // The likelihood interval of the change's time (track.h).
    j.Key("time_low").String(TrackTimeText(e.time_low_s, r.time_offset_s));
    j.Key("time_low_s").ExactNumber(e.time_low_s);
    j.Key("time_high").String(TrackTimeText(e.time_high_s, r.time_offset_s));
    j.Key("time_high_s").ExactNumber(e.time_high_s);
    j.Key("window").String(r.windows[e.window].label);
    j.Key("previous_window").String(r.windows[e.previous_window].label);
    j.Key("within_window").Bool(e.within_window);
    j.Key("new").Bool(e.is_new);
    j.Key("kind").String(e.kind);
    j.Key("parameters").BeginObject();
    for (const TrackEventParameter& p : e.parameters) {
      j.Key(p.name).BeginObject();
      j.Key("shift").Number(p.shift);
      j.Key("sigma_total").Number(p.sigma_total);
      j.Key("unit").String(p.unit);
      j.EndObject();
    }
    j.EndObject();
    if (e.kind == "sensor") j.Key("cables").NumberArray(e.cables);
    j.Key("statistic").Number(e.statistic);
    j.Key("degrees_of_freedom").Int(e.degrees_of_freedom);
    j.Key("threshold").Number(e.threshold);
    j.Key("p_value").Number(e.p_value);
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
  return j.str();
}

}  // namespace

// A window with a change inside it: a model for each of its two parts (the event's
// parameters from the part, the rest from the window), in place of the window's average.
void AddPartModels(TrackRun& run, const TrackEvent& e, int u) {
  TrackResult& r = *run.result;
  for (size_t x = 0; x < 2; ++x) {
    Eigen::VectorXd a = run.solver.a(u);
    Eigen::MatrixXd covariance = TotalCovariance(run, u, u);
    for (size_t k = 0; k < run.layout.window_columns.size(); ++k) {
      const ParameterSpec& s = run.layout.Column(run.layout.window_columns[k]);
      for (size_t i = 0; i < e.parameters.size() && i < e.parts[x].estimates.size(); ++i) {
        if (e.parameters[i].name != s.name) continue;
        const TrackEstimate& part = e.parts[x].estimates[i];
        a[k] = part.value * s.to_si;
        covariance.row(k).setZero();
        covariance.col(k).setZero();
        covariance(k, k) = std::pow(part.sigma_total * s.to_si, 2);
      }
    }
    const std::string label = r.windows[u].label + kPartSuffix[x];
    r.models.push_back({label, ModelAt(run, a, u)});
    r.model_comments.push_back(
        ModelComment(run,
                     "window " + r.windows[u].label + (x == 0 ? ", before" : ", after") +
                         " the change at " + TrackTimeText(e.time_s, r.time_offset_s),
                     a, covariance, u));
  }
}

TrackStatus BuildModels(TrackRun& run) {
  TrackResult& r = *run.result;
  r.models.clear();
  r.model_comments.clear();
  const int windows = static_cast<int>(run.used.size());
  if (windows == 0) return TrackStatus::kOk;
  std::vector<bool> boundary(windows + 1, false);
  for (const TrackEvent& e : r.events) {
    boundary[e.window] = true;
    // A step inside a window's telemetry: that window is a stretch of its own (mixed).
    if (e.within_window) boundary[e.window + 1] = true;
  }
  boundary[0] = boundary[windows] = true;
  const int p = static_cast<int>(run.layout.window_columns.size());
  for (int first = 0; first < windows;) {
    int last = first;
    while (!boundary[last + 1]) ++last;
    // The stretch's window parameters: its windows' estimates weighted by their
    // information (their correlation through b left out).
    Eigen::MatrixXd info = Eigen::MatrixXd::Zero(p, p);
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(p);
    for (int u = first; u <= last; ++u) {
      const Eigen::MatrixXd inverse = TotalCovariance(run, u, u).inverse();
      info += inverse;
      sum += inverse * run.solver.a(u);
    }
    const Eigen::MatrixXd covariance = info.inverse();
    const Eigen::VectorXd a = covariance * sum;
    if (first == last && SplitEventOf(r, first) != nullptr) {
      AddPartModels(run, *SplitEventOf(r, first), first);
      first = last + 1;
      continue;
    }
    const std::string label = first == last
                                  ? r.windows[first].label
                                  : r.windows[first].label + "_to_" + r.windows[last].label;
    r.models.push_back({label, ModelAt(run, a, first)});
    r.model_comments.push_back(ModelComment(
        run,
        first == last ? "window " + label
                      : "windows " + r.windows[first].label + " to " + r.windows[last].label +
                            " (no event between them; their window parameters averaged)",
        a, covariance, first));
    first = last + 1;
  }
  r.current_model = static_cast<int>(r.models.size()) - 1;  // the stretch of the latest window
  // The latest window, when its stretch is longer.
  const int u = windows - 1;
  if (SplitEventOf(r, u) == nullptr && r.models.back().first != r.windows[u].label) {
    r.models.push_back({r.windows[u].label, ModelAt(run, run.solver.a(u), u)});
    r.model_comments.push_back(ModelComment(run, "the latest window, " + r.windows[u].label,
                                            run.solver.a(u), TotalCovariance(run, u, u), u));
  }
  return TrackStatus::kOk;
}

std::vector<TrackRow> TrackRows(const TrackResult& r) {
  std::vector<TrackRow> rows;
  for (size_t k = 0; k < r.windows.size(); ++k) {
    const TrackWindow& w = r.windows[k];
    const TrackEvent* e = SplitEventOf(r, k);
    if (e == nullptr) {
      rows.push_back(
          {&w, w.label, w.start_s, w.end_s, w.first_time_s, w.last_time_s, w.samples, w.estimates});
      continue;
    }
    // A window with a change inside: its two parts, not the average of both.
    for (size_t x = 0; x < 2; ++x) {
      const TrackWindowPart& part = e->parts[x];
      rows.push_back({&w, w.label + kPartSuffix[x], part.start_s, part.end_s,
                      x == 0 ? w.first_time_s : e->time_s,
                      x == 0 ? e->previous_time_s : w.last_time_s, part.samples,
                      PartEstimates(r, w, *e, part)});
    }
  }
  return rows;
}

TrackStatus WriteOutputs(TrackRun& run) {
  const TrackResult& r = *run.result;
  const auto write = [&](const std::string& name, const std::string& text) {
    return WriteFileAtomically(run.Path(name), text, run.error);
  };
  if (!write("track.csv", TrackCsv(r)) || !write("events.json", EventsJson(r)) ||
      !write("track.html", TrackHtml(r))) {
    return TrackStatus::kFailed;
  }
  std::vector<std::string> written;
  for (size_t k = 0; k < r.models.size(); ++k) {
    const std::string name = "model_calibrated@" + r.models[k].first + ".yaml";
    if (!SaveCableRobot(r.models[k].second, run.Path(name), r.model_comments[k], run.error)) {
      return TrackStatus::kFailed;
    }
    written.push_back(name);
  }
  // The current model at a stable path, for a controller or a nightly script.
  if (r.current_model >= 0 &&
      !SaveCableRobot(r.models[r.current_model].second, run.Path(kCurrentModelFile),
                      "The current model: " + r.model_comments[r.current_model] +
                          "\n(also model_calibrated@" + r.models[r.current_model].first + ".yaml)",
                      run.error)) {
    return TrackStatus::kFailed;
  }
  // An update's models that no longer hold (a stretch an event now cuts).
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(run.dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("model_calibrated@", 0) == 0 &&
        std::find(written.begin(), written.end(), name) == written.end()) {
      fs::remove(e.path(), ec);
    }
  }
  return TrackStatus::kOk;
}

}  // namespace fastcal::internal

namespace fastcal {

std::string DescribeGaussNewton(const TrackResult& r) {
  const std::string iterations =
      std::to_string(r.iterations) + " iteration" + (r.iterations == 1 ? "" : "s");
  return std::string("Gauss-Newton ") + (r.converged ? "converged in " : "did not converge in ") +
         iterations + " (the last step " + internal::FormatDouble("%.2g", r.last_step_sigmas) +
         " sigma, " + (r.converged ? "below " : "above ") +
         internal::FormatDouble("%g", r.step_tolerance_sigmas) + ")";
}

std::string DescribeEventTime(const TrackResult& r, const TrackEvent& e) {
  using internal::TrackTimeText;
  const auto time = [&](double t) { return TrackTimeText(t, r.time_offset_s); };
  std::string s = e.within_window ? "inside the window, at " + time(e.time_s)
                                  : "between " + time(e.previous_time_s) + " and " + time(e.time_s);
  const bool night_only =
      !e.within_window && e.time_low_s >= e.previous_time_s && e.time_high_s <= e.time_s;
  if (night_only) return s;
  s += " (" + internal::FormatDouble("%g", 100.0 * internal::kIntervalLevel) + "% interval " +
       time(e.time_low_s) + " to " + time(e.time_high_s);
  // The nights the interval spans (between consecutive windows' data) and the windows whose
  // telemetry it reaches into.
  int nights = 0, windows = 0;
  for (size_t w = 0; w < r.windows.size(); ++w) {
    const TrackWindow& x = r.windows[w];
    windows += e.time_low_s < x.last_time_s && e.time_high_s > x.first_time_s ? 1 : 0;
    if (w + 1 < r.windows.size()) {
      nights += e.time_low_s <= x.last_time_s && e.time_high_s >= r.windows[w + 1].first_time_s;
    }
  }
  if (nights > 0 && windows > 0) {
    const auto count = [](int n, const char* one, const char* many) {
      return n == 1 ? std::string(one) : std::to_string(n) + " " + many;
    };
    s += ": it spans " + count(nights, "a night", "nights") + " and " +
         count(windows, "a day's telemetry", "days' telemetry") +
         ", which the data cannot tell apart";
  }
  return s + ")";
}

std::string DescribeWander(const TrackWander& w) {
  using internal::FormatDouble;
  const bool inside = w.inside_time_constant_s > 0.0;
  if (!inside && !(w.rms > 0.0)) return "";
  std::string s = w.group + " wanders";
  if (inside) {
    s += " inside the windows by";
    for (size_t x = 0; x < w.components.size(); ++x) {
      const std::string& name = w.components[x];
      const size_t dot = name.rfind('.');
      s += std::string(x > 0 ? "," : "") + " " +
           (dot == std::string::npos ? name : name.substr(dot + 1)) + " " +
           FormatDouble("%.2g", w.inside_rms[x]) + " +- " +
           FormatDouble("%.1g", w.inside_rms_sigma[x]);
    }
    const double tau = w.inside_time_constant_s;
    const std::string tau_text = tau >= 7200.0  ? FormatDouble("%.3g h", tau / 3600.0)
                                 : tau >= 120.0 ? FormatDouble("%.3g min", tau / 60.0)
                                                : FormatDouble("%.3g s", tau);
    s += " " + w.unit + " rms (a Gauss-Markov process, time constant " + tau_text;
    if (w.inside_log_time_constant_sigma > 0.0) {
      s += " x/ " + FormatDouble("%.2g", std::exp(w.inside_log_time_constant_sigma));
    }
    s += "; from " + std::to_string(w.inside_windows) + " windows";
    if (!w.inside_significant) {
      s += "; not beyond chance: likelihood ratio " +
           FormatDouble("%.2g", w.inside_likelihood_ratio) + " against none";
    }
    if (!w.inside_left_out.empty()) {
      s += ", " + std::to_string(w.inside_left_out.size()) + " left out as beyond it";
    }
    s += ")";
  }
  if (w.rms > 0.0) {
    s += std::string(inside ? " and" : "") + " between windows by " + FormatDouble("%.3g", w.rms) +
         " " + w.unit + " rms per component beyond " + (inside ? "that" : "its errors");
  }
  return s + ": the events are steps beyond " + (inside && w.rms > 0.0 ? "both" : "that");
}

}  // namespace fastcal
