// The report's sections on the mass centre over time, and their summary.json keys: the
// sessions of a joint fit (sessions.h: each separate parameter per session with its
// sigma_total, the differences between consecutive sessions) and the change scan
// (change_scan.h: the statistic over time, its threshold, the changes found).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "fastcal/internal/report_sections.h"
#include "fastcal/sessions.h"

namespace fastcal::internal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The separate parameters' shared names, in fit order, each once.
std::vector<std::string> SeparateNames(const CalibrationResult& r) {
  std::vector<std::string> names;
  for (const ParameterEstimate& p : r.parameters) {
    if (!p.free || p.name.find('@') == std::string::npos) continue;
    const std::string shared = SharedParameterName(p.name);
    if (std::find(names.begin(), names.end(), shared) == names.end()) names.push_back(shared);
  }
  return names;
}

const ParameterEstimate* Find(const CalibrationResult& r, const std::string& name) {
  for (const ParameterEstimate& p : r.parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

constexpr int kIntervalPlotWidthPx = 760, kEstimatePlotWidthPx = 420;

// "+0.0509 ± 0.0015 m (33.9 σ)": a difference with its sigma and their ratio.
std::string DifferenceNote(const SessionDifference& d) {
  return Printf("%+.3g", d.difference) + " ± " + Sig3(d.sigma_total) + " " + d.unit + " (" +
         Printf("%.1f", std::abs(d.Sigmas())) + " σ)";
}

// The differences between consecutive sessions, each with its sigma_total (thick) and
// the change threshold's width (thin) against zero: what moved reads at once, where the
// sessions' own bars would overlap (they share the errors that cancel from the
// difference). One plot per unit.
std::vector<std::string> DifferencePlots(const CalibrationResult& r) {
  std::vector<std::string> units, svgs;
  for (const SessionDifference& d : r.session_differences) {
    if (std::find(units.begin(), units.end(), d.unit) == units.end()) units.push_back(d.unit);
  }
  for (const std::string& unit : units) {
    std::vector<IntervalRow> rows;
    for (const SessionDifference& d : r.session_differences) {
      if (d.unit != unit) continue;
      rows.push_back({d.name + ": " + d.from + " → " + d.to, d.difference, d.sigma_total,
                      DifferenceNote(d), std::abs(d.Sigmas()) > kSessionChangeSigmas});
    }
    IntervalPlotOptions o;
    o.plot.title = "Later minus earlier session";
    o.plot.x_label = "difference [" + unit + "]";
    o.plot.width_px = kIntervalPlotWidthPx;
    o.reference = 0.0;
    o.wide_sigmas = kSessionChangeSigmas;
    svgs.push_back(SvgIntervalPlot(rows, o));
  }
  return svgs;
}

// One separate parameter per session, each row labelled by its session's name.
std::string EstimatesPlot(const CalibrationResult& r, const std::string& name) {
  std::vector<IntervalRow> rows;
  std::string unit;
  for (const std::string& label : r.session_labels) {
    const ParameterEstimate* p = Find(r, SessionParameterName(name, label));
    if (p == nullptr) continue;
    unit = p->unit;
    rows.push_back({label, p->estimate, p->sigma_total,
                    EstimateText(p->estimate, p->sigma_total) + " ± " + Sig3(p->sigma_total),
                    false});
  }
  IntervalPlotOptions o;
  o.plot.title = name;
  o.plot.x_label = name + " [" + unit + "]";
  o.plot.width_px = kEstimatePlotWidthPx;
  return SvgIntervalPlot(rows, o);
}

}  // namespace

void AddSessions(const CalibrationResult& r, bool with_plots, Document* doc) {
  if (r.session_labels.empty()) return;
  doc->Heading(2, "Sessions");
  std::string labels;
  for (size_t s = 0; s < r.session_labels.size(); ++s) {
    labels += (s ? ", " : "") + std::to_string(s + 1) + " = " + r.session_labels[s];
  }
  doc->Paragraph("A joint fit of " + Int(static_cast<long long>(r.session_labels.size())) +
                 " sessions (" + labels +
                 "): the parameters named NAME@LABEL have one value per session, every other free "
                 "parameter is shared and fitted once from all of them, so its error cancels from "
                 "the differences below. A difference's sigma_total is from the full covariance of "
                 "the estimates (statistical, widened, and the consider part). Beyond " +
                 Printf("%g", kSessionChangeSigmas) +
                 " sigma_total a difference counts as a change. Each session's calibrated model is "
                 "model_calibrated@LABEL.yaml.");
  const std::vector<std::string> names = SeparateNames(r);
  Table values;
  values.caption = "Separate parameters per session, estimate +- sigma_total";
  values.header.push_back("parameter");
  values.right_align.push_back(false);
  for (const std::string& label : r.session_labels) {
    values.header.push_back(Text().Code(label));
    values.right_align.push_back(true);
  }
  for (const std::string& name : names) {
    std::vector<Text> row{Text().Code(name)};
    for (const std::string& label : r.session_labels) {
      const ParameterEstimate* p = Find(r, SessionParameterName(name, label));
      row.push_back(p == nullptr ? Text("")
                                 : Text(EstimateText(p->estimate, p->sigma_total) + " +- " +
                                        Sig3(p->sigma_total) + " " + p->unit));
    }
    values.rows.push_back(row);
  }
  doc->AddTable(values);
  Table diffs;
  diffs.caption = "Differences between consecutive sessions (later minus earlier)";
  diffs.header = {"parameter", "from", "to", "difference", "sigma_total", "sigmas"};
  diffs.right_align = {false, false, false, true, true, true};
  for (const SessionDifference& d : r.session_differences) {
    diffs.rows.push_back({Text().Code(d.name), Text().Code(d.from), Text().Code(d.to),
                          Text(Printf("%+.4g", d.difference) + " " + d.unit),
                          Text(Sig3(d.sigma_total) + " " + d.unit),
                          std::abs(d.Sigmas()) > kSessionChangeSigmas
                              ? Text().Bold(Printf("%+.1f", d.Sigmas()))
                              : Text(Printf("%+.1f", d.Sigmas()))});
  }
  doc->AddTable(diffs);
  if (!with_plots) return;
  doc->Figure(DifferencePlots(r),
              "What moved between sessions: each difference (dot) with its sigma_total (thick "
              "bar) and ± " +
                  Printf("%g", kSessionChangeSigmas) +
                  " sigma_total (thin bar), against zero (dashed). A thin bar clear of zero is a "
                  "change (vermillion). Read this, not the sessions' own bars below: the estimates "
                  "share the errors of the shared parameters, which cancel from their "
                  "difference.");
  std::vector<std::string> svgs;
  for (const std::string& name : names) svgs.push_back(EstimatesPlot(r, name));
  doc->Figure(svgs,
              "Each separate parameter per session, by the sessions' names: the estimate with "
              "its own ± sigma_total.");
}

void WriteSessionsJson(const CalibrationResult& r, JsonWriter* w) {
  w->Key("sessions").BeginArray();
  for (const std::string& label : r.session_labels) w->String(label);
  w->EndArray();
  w->Key("session_differences").BeginArray();
  for (const SessionDifference& d : r.session_differences) {
    w->BeginObject();
    w->Key("name").String(d.name);
    w->Key("unit").String(d.unit);
    w->Key("from").String(d.from);
    w->Key("to").String(d.to);
    w->Key("difference").Number(d.difference);
    w->Key("sigma_total").Number(d.sigma_total);
    w->EndObject();
  }
  w->EndArray();
  const SensorStepTest& steps = r.sensor_steps;
  w->Key("sensor_steps").BeginObject();
  w->Key("tested").Bool(steps.tested);
  w->Key("threshold").Number(steps.threshold);
  w->Key("widening").Number(steps.widening);
  w->Key("tests").BeginArray();
  for (const SensorStep& s : steps.tests) {
    w->BeginObject();
    w->Key("parameter").String(s.parameter);
    w->Key("cable").Int(s.cable + 1);
    w->Key("session").String(s.session);
    w->Key("step").Number(s.step);
    w->Key("sigma").Number(s.sigma);
    w->Key("unit").String(s.unit);
    w->Key("statistic").Number(s.statistic);
    w->Key("significant").Bool(s.significant);
    w->EndObject();
  }
  w->EndArray();
  w->Key("separated").BeginArray();
  for (const std::string& name : steps.separated) w->String(name);
  w->EndArray();
  w->EndObject();
}

namespace {

// The scan statistic over the split times, the threshold, and each change as a vertical
// dashed line.
std::string ChangeScanPlot(const ChangeScanResult& scan) {
  PlotSeries statistic{"scan statistic W", scan.time_s, scan.statistic};
  const double t0 = scan.time_s.front(), t1 = scan.time_s.back();
  PlotSeries threshold{"threshold (" + Printf("%g", 100.0 * scan.significance) + "% false alarm)",
                       {t0, t1},
                       {scan.threshold, scan.threshold}};
  threshold.dashed = true;
  double top = scan.threshold;
  for (double w : scan.statistic) top = std::max(top, w);
  PlotSeries changes{"change found", {}, {}};
  changes.dashed = true;
  for (const FoundChange& c : scan.changes) {
    changes.x.insert(changes.x.end(), {c.time_s, c.time_s, kNaN});
    changes.y.insert(changes.y.end(), {0.0, top, kNaN});
  }
  PlotOptions o;
  o.title = "Change scan: a step of the scanned parameters at each time";
  const TimeDisplay& display = scan.time_display;
  o.x_unix_time = display.absolute;
  o.x_time_offset_s = display.offset_s;
  o.x_label = display.absolute ? "first sample after the step: " + TimeAxisLabel(t0, t1, display)
                               : "time of the first sample after the step [s]";
  o.y_label = "W (first round)";
  std::vector<PlotSeries> series{statistic, threshold};
  if (!scan.changes.empty()) series.push_back(changes);
  return SvgLinePlot(series, o);
}

}  // namespace

void AddChangeScan(const CalibrationResult& r, bool with_plots, Document* doc) {
  const ChangeScanResult& scan = r.change_scan;
  if (!scan.enabled) return;
  doc->Heading(2, "Change scan");
  std::string parameters;
  for (const std::string& p : scan.parameters) parameters += (parameters.empty() ? "" : ", ") + p;
  doc->Paragraph(
      "Did " + parameters + " step within the survey? At each split time (at least " +
      Int(scan.min_segment) + " fitted samples on either side" +
      (scan.unit_samples > 1 ? ", splits every " + Int(scan.unit_samples) + " samples" : "") +
      "), the Wald statistic W of a step, the rest of the model shared, from the fit "
      "linearised at its solution, and judged against the noise the residuals have (widened "
      "by " +
      Printf("%.3g", scan.widening) +
      ", as the uncertainty budget widens sigma). The largest W over the times is not "
      "chi-square: its threshold, " +
      Printf("%.3g", scan.threshold) + " for a " + Printf("%g", 100.0 * scan.significance) +
      "% false alarm, is drawn from its own null distribution for this survey's poses (" +
      Int(scan.replicates) +
      " draws of white noise through the same Jacobian). Several changes: binary "
      "segmentation, each segment between the changes found scanned again.");
  if (scan.time_s.empty()) {
    doc->Paragraph("The survey is too short to scan: fewer than twice " + Int(scan.min_segment) +
                   " fitted samples.");
    return;
  }
  if (scan.changes.empty()) {
    doc->Paragraph(
        Text()
            .Bold("No change found.")
            .Plain(" The estimates hold for the whole survey, as far as the scan can tell."));
  } else {
    doc->Paragraph(
        Text()
            .Bold(Int(static_cast<long long>(scan.changes.size())) +
                  (scan.changes.size() == 1 ? " change found." : " changes found."))
            .Plain(" The estimates are an average over the segments: cut the survey at the "
                   "change and fit with sessions: {separate: [...]}, which gives each segment "
                   "its own value and the difference its sigma_total: ")
            .Code("fastcal calibrate --sessions-at=" + SessionsAtText(scan) + " ...")
            .Plain(" (or --sessions-at=DIR/summary.json, this run's; docs/cli.md)."));
    Table t;
    t.caption = "Changes found (step: later minus earlier, +- its sigma)";
    t.header = {scan.time_display.absolute ? "time" : "time [s]", "line", "W", "p"};
    t.right_align = {true, true, true, true};
    for (const std::string& p : scan.parameters) {
      t.header.push_back(Text().Code(p));
      t.right_align.push_back(true);
    }
    for (const FoundChange& c : scan.changes) {
      const std::string when = scan.time_display.absolute ? TimeText(c.time_s, scan.time_display)
                                                          : Sig6(c.time_s);
      std::vector<Text> row{Text(when), Text(Int(c.line)), Text(Sig3(c.statistic)),
                            Text(Printf("%.2g", c.p_value))};
      for (size_t k = 0; k < c.shift.size(); ++k) {
        row.push_back(Text(Printf("%+.3g", c.shift[k]) + " +- " + Sig3(c.shift_sigma[k]) + " " +
                           scan.units[k]));
      }
      t.rows.push_back(row);
    }
    doc->AddTable(t);
  }
  if (with_plots) {
    doc->Figure({ChangeScanPlot(scan)},
                "The scan statistic against the time of the step (first round: no change in "
                "the model yet), the threshold its maximum exceeds with the stated "
                "probability when nothing changed, and the changes found.");
  }
}

void WriteChangeScanJson(const CalibrationResult& r, JsonWriter* w) {
  const ChangeScanResult& scan = r.change_scan;
  w->Key("change_scan");
  if (!scan.enabled) {
    w->Null();
  } else {
    w->BeginObject();
    w->Key("parameters").BeginArray();
    for (const std::string& p : scan.parameters) w->String(p);
    w->EndArray();
    w->Key("significance").Number(scan.significance);
    w->Key("threshold").Number(scan.threshold);
    w->Key("min_segment_samples").Number(scan.min_segment);
    w->Key("split_unit_samples").Number(scan.unit_samples);
    w->Key("replicates").Number(scan.replicates);
    w->Key("widening").Number(scan.widening);
    w->Key("time_s").NumberArray(scan.time_s);
    w->Key("statistic").NumberArray(scan.statistic);
    w->Key("best_step_statistic").Number(scan.best_step_statistic);
    w->Key("trend").BeginObject();
    w->Key("statistic").Number(scan.trend_statistic);
    w->Key("p_value").Number(scan.trend_p_value);
    w->Key("shifts").BeginObject();
    for (size_t k = 0; k < scan.trend_shift.size(); ++k) {
      w->Key(scan.parameters[k]).Number(scan.trend_shift[k]);
    }
    w->EndObject();
    w->Key("shift_sigmas").BeginObject();
    for (size_t k = 0; k < scan.trend_shift_sigma.size(); ++k) {
      w->Key(scan.parameters[k]).Number(scan.trend_shift_sigma[k]);
    }
    w->EndObject();
    w->EndObject();
    w->Key("change_time_low_s").Number(scan.change_time_low_s);
    w->Key("change_time_high_s").Number(scan.change_time_high_s);
    w->Key("wanders").Bool(scan.wanders);
    w->EndObject();
  }
  // Empty when none was found (or no scan was asked for).
  w->Key("changes").BeginArray();
  for (const FoundChange& c : scan.changes) {
    w->BeginObject();
    w->Key("time_s").ExactNumber(c.time_s);
    // The date and time when the data's times are Unix times (ISO 8601, the data's zone).
    w->Key("time");
    if (scan.time_display.absolute) {
      w->String(IsoUnixTime(c.time_s, scan.time_display.offset_s));
    } else {
      w->Null();
    }
    w->Key("line").Number(c.line);
    w->Key("statistic").Number(c.statistic);
    w->Key("p_value").Number(c.p_value);
    w->Key("shifts").BeginObject();
    for (size_t k = 0; k < c.shift.size(); ++k) w->Key(scan.parameters[k]).Number(c.shift[k]);
    w->EndObject();
    w->Key("shift_sigmas").BeginObject();
    for (size_t k = 0; k < c.shift.size(); ++k) {
      w->Key(scan.parameters[k]).Number(c.shift_sigma[k]);
    }
    w->EndObject();
    w->EndObject();
  }
  w->EndArray();
  // The value of --sessions-at that cuts the survey at the changes (null without).
  w->Key("sessions_at");
  if (scan.changes.empty()) {
    w->Null();
  } else {
    w->String(SessionsAtText(scan));
  }
}

}  // namespace fastcal::internal
