// track.html (track.h): a self-contained page (inline SVG, no scripts) with each
// per-window parameter over time with its sigma_total as bars, the sensors' offsets, the
// events marked, the shared parameters and the windows' table.
#include <cmath>
#include <limits>
#include <string>

#include "fastcal/internal/number_text.h"
#include "fastcal/slow_error.h"
#include "fastcal/svg_plot.h"
#include "fastcal/time_text.h"
#include "track/track_run.h"

namespace fastcal::internal {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Esc(const std::string& s) { return XmlEscape(s); }

// The time axis: dates and clock times in the track's zone (TrackResult::time_offset_s) for Unix
// times (svg_plot.h's clock-time axis), seconds otherwise.
struct TimeAxis {
  bool absolute = false;
  int offset_s = 0;
  std::string label;
  double span_lo = kNaN, span_hi = kNaN;  // the windows' bounds: the axis spans them
  double X(double t) const { return t; }
  void Apply(PlotOptions* o) const {
    o->x_label = label;
    o->x_unix_time = absolute;
    o->x_time_offset_s = offset_s;
    o->x_span_lo = span_lo;
    o->x_span_hi = span_hi;
  }
};

TimeAxis AxisOf(const TrackResult& r) {
  TimeAxis axis;
  const TimeDisplay display = TimeDisplayFor(r.windows.front().first_time_s, r.time_offset_s);
  axis.offset_s = r.time_offset_s;
  axis.absolute = display.absolute;
  axis.label = axis.absolute ? TimeAxisLabel(r.windows.front().first_time_s,
                                             r.windows.back().last_time_s, display)
                             : "time_s [s]";
  // The windows' bounds, not only their dots' times: a single window's dot sat alone in an
  // axis of a minute around it.
  axis.span_lo = r.windows.front().start_s;
  axis.span_hi = r.windows.back().end_s;
  return axis;
}

double Middle(const TrackWindow& w) { return 0.5 * (w.first_time_s + w.last_time_s); }

// Vertical dashed lines at the events, spanning [lo, hi].
PlotSeries EventLines(const TrackResult& r, const TimeAxis& axis, double lo, double hi,
                      const std::string& kind) {
  PlotSeries s;
  s.name = kind + " events";
  s.dashed = true;
  for (const TrackEvent& e : r.events) {
    if (e.kind != kind) continue;
    const double x = axis.X(0.5 * (e.time_s + e.previous_time_s));
    s.x.insert(s.x.end(), {x, x, kNaN});
    s.y.insert(s.y.end(), {lo, hi, kNaN});
  }
  if (s.x.empty()) s.name.clear();
  return s;
}

std::string ParameterPlot(const TrackResult& r, const TimeAxis& axis, size_t k) {
  PlotSeries value, bars;
  value.name = r.window_parameters[k];
  value.markers_only = true;
  value.marker_radius_px = r.windows.size() > 120 ? 1.6 : 2.5;
  bars.name = "+- sigma_total";
  bars.opacity = 0.6;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const TrackRow& w : TrackRows(r)) {  // a window with a change inside: its parts
    const TrackEstimate& e = w.estimates[k];
    const double x = axis.X(0.5 * (w.first_time_s + w.last_time_s));
    value.x.push_back(x);
    value.y.push_back(e.value);
    bars.x.insert(bars.x.end(), {x, x, kNaN});
    bars.y.insert(bars.y.end(), {e.value - e.sigma_total, e.value + e.sigma_total, kNaN});
    lo = std::min(lo, e.value - e.sigma_total);
    hi = std::max(hi, e.value + e.sigma_total);
  }
  PlotOptions o;
  o.title = r.window_parameters[k] + " per window";
  axis.Apply(&o);
  o.y_label = r.window_parameters[k] + " [" + r.window_units[k] + "]";
  o.width_px = 1100;
  o.height_px = 260;
  return SvgLinePlot({value, bars, EventLines(r, axis, lo, hi, "parameter")}, o);
}

std::string OffsetPlot(const TrackResult& r, const TimeAxis& axis) {
  std::vector<PlotSeries> series;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int i = 0; i < kNumCables; ++i) {
    PlotSeries s;
    s.name = "cable " + std::to_string(i + 1);
    for (const TrackWindow& w : r.windows) {
      s.x.push_back(axis.X(Middle(w)));
      s.y.push_back(w.offset_kn[i].value);
      lo = std::min(lo, w.offset_kn[i].value);
      hi = std::max(hi, w.offset_kn[i].value);
    }
    series.push_back(s);
  }
  series.push_back(EventLines(r, axis, lo, hi, "sensor"));
  PlotOptions o;
  o.title = "what each sensor's bias reads per window";
  axis.Apply(&o);
  o.y_label = "offset [kN]";
  o.width_px = 1100;
  o.height_px = 300;
  return SvgLinePlot(series, o);
}

std::string EventsTable(const TrackResult& r) {
  if (r.events.empty()) {
    return "<p>No event: nothing changed between windows beyond what noise explains (each kind "
           "tested at a " +
           FormatDouble("%g", 100.0 * r.false_alarm) + "% false-alarm rate over the track).</p>\n";
  }
  std::string h =
      "<table><tr><th>time (UTC)</th><th>last sample before</th><th>when</th><th>kind</th>"
      "<th>what changed</th><th>statistic</th><th>p (family-wise)</th></tr>\n";
  for (const TrackEvent& e : r.events) {
    std::string what;
    for (const TrackEventParameter& p : e.parameters) {
      what += (what.empty() ? "" : "<br>") + Esc(p.name) + " " + FormatDouble("%+.4g", p.shift) +
              " +- " + FormatDouble("%.2g", p.sigma_total) + " " + Esc(p.unit);
    }
    h += "<tr><td>" + TrackTimeText(e.time_s, r.time_offset_s) + "</td><td>" +
         TrackTimeText(e.previous_time_s, r.time_offset_s) + "</td><td>" +
         Esc(DescribeEventTime(r, e)) + "</td><td>" + (e.is_new && r.updated ? "<b>new</b> " : "") +
         e.kind + "</td><td>" + what + "</td><td>" + FormatDouble("%.1f", e.statistic) +
         " (threshold " + FormatDouble("%.1f", e.threshold) + ")</td><td>" +
         FormatDouble("%.2g", e.p_value) + "</td></tr>\n";
  }
  return h + "</table>\n";
}

std::string SharedTable(const TrackResult& r) {
  std::string h =
      "<table><tr><th>shared parameter</th><th>estimate</th><th>sigma_total</th>"
      "<th>windows</th></tr>\n";
  for (const TrackShared& s : r.shared) {
    const std::string unit = s.unit == "1" || s.unit.empty() ? "" : " " + Esc(s.unit);
    h += "<tr><td>" + Esc(s.name) + "</td><td>" + FormatDouble("%.6g", s.estimate.value) + unit +
         "</td><td>" + FormatDouble("%.2g", s.estimate.sigma_total) + "</td><td>" +
         Esc(r.windows[s.from_window].label) + " to " + Esc(r.windows[s.to_window].label) +
         "</td></tr>\n";
  }
  return h + "</table>\n";
}

std::string WindowsTable(const TrackResult& r) {
  std::string h = "<details><summary>The windows (" + std::to_string(r.windows.size()) +
                  ")</summary>\n<table><tr><th>window</th><th>samples</th>";
  for (const std::string& n : r.window_parameters) h += "<th>" + Esc(n) + "</th>";
  h += "<th>chi2/nu</th><th>widening</th><th>gross errors</th></tr>\n";
  for (const TrackRow& row : TrackRows(r)) {  // a window with a change inside: its parts
    const TrackWindow& w = *row.window;
    h += "<tr><td>" + Esc(row.label) + "</td><td>" + std::to_string(row.samples) + "</td>";
    for (const TrackEstimate& e : row.estimates) {
      h += "<td>" + FormatDouble("%.5g", e.value) + " +- " + FormatDouble("%.2g", e.sigma_total) +
           "</td>";
    }
    h += "<td>" + FormatDouble("%.3g", w.reduced_chi_square) + "</td><td>" +
         FormatDouble("%.3g", w.widening) + "</td><td>" + std::to_string(w.gross_errors) +
         "</td></tr>\n";
  }
  return h + "</table></details>\n";
}

}  // namespace

std::string TrackHtml(const TrackResult& r) {
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>fastcal "
      "track</title>"
      "<style>body{font-family:sans-serif;margin:1.5em;max-width:1180px}"
      "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #ccc;"
      "padding:2px 6px;font-size:90%;text-align:left}svg{max-width:100%;height:auto}"
      "</style></head><body>\n<h1>Track over " +
      Counted(static_cast<long long>(r.windows.size()), "window", "windows") + "</h1>\n";
  if (r.windows.empty()) return h + "<p>No window.</p></body></html>\n";
  h += "<p>" + Counted(r.samples, "sample", "samples") + " from " +
       Counted(static_cast<long long>(r.files.size()), "file", "files") + ", windows of " +
       WindowSpecText(r.window) + " from " +
       TrackTimeText(r.windows.front().start_s, r.time_offset_s) + " to " +
       TrackTimeText(r.windows.back().end_s, r.time_offset_s) + "; " + Esc(DescribeGaussNewton(r)) +
       ", " + Counted(r.folds, "fold", "folds") + " this run; chi2/nu " +
       FormatDouble("%.3f", r.reduced_chi_square) + ".</p>\n";
  if (r.slow_error.enabled) h += "<p>" + Esc(DescribeSlowError(r.slow_error)) + "</p>\n";
  h += "<h2>Events</h2>\n" + EventsTable(r);
  const TimeAxis axis = AxisOf(r);
  h += "<h2>Per-window parameters</h2>\n<p>Each window's estimate (dots) with its sigma_total "
       "(bars); dashed lines: parameter events. A bar holds the error every window shares "
       "(the cables' and sensors' shared parameters): it cancels from the differences "
       "between windows, which the events test: the dots can scatter less than the bars suggest, "
       "and a step well inside them can be significant.</p>\n";
  for (const TrackWander& w : r.wander) {
    const std::string text = DescribeWander(w);
    if (!text.empty()) h += "<p>" + Esc(text) + ".</p>\n";
  }
  for (size_t k = 0; k < r.window_parameters.size(); ++k) h += ParameterPlot(r, axis, k) + "\n";
  if (r.windows.front().has_offsets) {
    h += "<h2>Sensors</h2>\n<p>The shared bias of each sensor plus the window's own departure "
         "from it (one Gauss-Newton step); dashed lines: sensor events.</p>\n" +
         OffsetPlot(r, axis) + "\n";
  }
  h += "<h2>Shared parameters</h2>\n" + SharedTable(r);
  h += "<h2>Windows</h2>\n" + WindowsTable(r);
  if (!r.notes.empty()) {
    h += "<h2>Notes</h2>\n<ul>";
    for (const std::string& n : r.notes) h += "<li>" + Esc(n) + "</li>";
    h += "</ul>\n";
  }
  return h + "</body></html>\n";
}

}  // namespace fastcal::internal
