// The report's sessions section and summary.json's session_differences (sessions.h):
// each separate parameter per session with its sigma_total, and the differences between
// consecutive sessions with the sigma_total of the difference from the full covariance.
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

// One separate parameter over the sessions: the estimates as dots, +- sigma_total as
// vertical bars (one series broken by gaps).
std::string SessionPlot(const CalibrationResult& r, const std::string& name) {
  PlotSeries estimate{"estimate", {}, {}};
  estimate.markers_only = true;
  estimate.marker_radius_px = 4.0;
  PlotSeries bars{"+- sigma_total", {}, {}};
  std::string unit;
  for (size_t s = 0; s < r.session_labels.size(); ++s) {
    const ParameterEstimate* p = Find(r, SessionParameterName(name, r.session_labels[s]));
    if (p == nullptr) continue;
    unit = p->unit;
    const double x = static_cast<double>(s + 1);
    estimate.x.push_back(x);
    estimate.y.push_back(p->estimate);
    bars.x.insert(bars.x.end(), {x, x, kNaN});
    bars.y.insert(bars.y.end(), {p->estimate - p->sigma_total, p->estimate + p->sigma_total, kNaN});
  }
  PlotOptions o;
  o.title = name + " per session";
  o.x_label = "session (1 = " + r.session_labels.front() + ")";
  o.y_label = name + " [" + unit + "]";
  o.width_px = 420;
  o.height_px = 260;
  return SvgLinePlot({estimate, bars}, o);
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
  std::vector<std::string> svgs;
  for (const std::string& name : names) svgs.push_back(SessionPlot(r, name));
  doc->Figure(svgs, "Each separate parameter per session: the estimate with +- sigma_total.");
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
}

}  // namespace fastcal::internal
