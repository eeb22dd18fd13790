// A survey design's outputs (design.h): poses.csv, design.json and design.html. The map
// is the cap seen from above (x toward tower 1's side as in the workspace map), in metres.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "fastcal/design.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/svg_plot.h"

namespace fastcal {
namespace {

std::string Fmt(const char* format, double v) { return internal::FormatDouble(format, v); }

std::string CommentLines(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out += "# " + line + "\n";
  return out;
}

// Unit of free parameter k for display: mm for lengths, else the spec's unit.
struct Shown {
  double scale;  // displayed value = SI value * scale
  std::string unit;
};
Shown ShownUnit(const Design& d, int k) {
  if (d.free_units[k] == "m") return {1e3, "mm"};
  return {1.0 / d.free_to_si[k], d.free_units[k]};
}

// The range's parameters grouped by name before '.' or '[' with their offset in file
// units, e.g. "mass_centre_m +-0.25 m (margin); linear_density_kg_per_m +-0.36 kg/m (2
// sigma)".
std::string RangeText(const Design& d) {
  std::string out;
  for (size_t j = 0; j < d.range.size(); ++j) {
    const DesignRangeParameter& r = d.range[j];
    const std::string group = r.name.substr(0, r.name.find_first_of(".["));
    const std::string text =
        group + " +-" + Fmt("%.3g", r.delta_si / r.to_si) + " " + r.unit +
        (r.from_prior ? " (" + Fmt("%.3g", d.options.range_prior_sigmas) + " sigma of its prior)"
                      : " (margin)");
    if (out.find(text) == std::string::npos) out += (out.empty() ? "" : "; ") + text;
  }
  return out.empty() ? "none (the initial values only)" : out;
}

// Where in the range a binding is reached, compactly: per group of parameters (name
// before '.' or '['), the offset and each parameter's side in order, e.g.
// "mass_centre_m +-0.25 m: ++-; linear_density_kg_per_m +-0.36 kg/m: +-----" (0: at its
// initial value). design.json names each parameter.
std::string CornerText(const Design& d, const DesignBinding& b) {
  std::string out, group;
  bool off = false;
  for (size_t j = 0; j < b.corner_si.size() && j < d.range.size(); ++j) {
    const DesignRangeParameter& r = d.range[j];
    const std::string g = r.name.substr(0, r.name.find_first_of(".["));
    if (g != group) {
      group = g;
      out += (out.empty() ? "" : "; ") + g + " +-" + Fmt("%.3g", r.delta_si / r.to_si) + " " +
             r.unit + ": ";
    }
    out += b.corner_si[j] > 0.0 ? '+' : b.corner_si[j] < 0.0 ? '-' : '0';
    off |= b.corner_si[j] != 0.0;
  }
  return off ? out : "the initial values";
}

// A binding's value and limit in the units of files: kN for tensions, m for clearance.
bool IsTension(const DesignBinding& b) { return b.constraint != "reflector_clearance"; }
double BindingShown(const DesignBinding& b, double si) { return IsTension(b) ? si / 1e3 : si; }
std::string BindingUnit(const DesignBinding& b) { return IsTension(b) ? "kN" : "m"; }

// The stop whose binding has the least slack (its value nearest its limit, relatively).
int TightestStop(const Design& d) {
  int tightest = -1;
  double least = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < d.stops.size(); ++k) {
    const DesignBinding& b = d.stops[k].binding;
    if (b.constraint.empty()) continue;
    const double slack = std::abs(b.value - b.limit) / std::max(std::abs(b.limit), 1.0);
    if (slack < least) {
      least = slack;
      tightest = static_cast<int>(k);
    }
  }
  return tightest;
}

void WritePrediction(JsonWriter& j, const Design& d, const DesignPrediction& p) {
  j.BeginObject();
  j.Key("ok").Bool(p.ok);
  if (!p.note.empty()) j.Key("note").String(p.note);
  j.Key("samples").Int(p.samples);
  j.Key("criterion").Number(p.ok ? p.criterion : NAN);
  j.Key("parameters").BeginArray();
  for (size_t k = 0; k < d.free_names.size(); ++k) {
    const bool wanted =
        std::find(d.wanted.begin(), d.wanted.end(), static_cast<int>(k)) != d.wanted.end();
    j.BeginObject().Key("name").String(d.free_names[k]).Key("wanted").Bool(wanted);
    if (p.ok) {
      const ParameterBudget& b = p.budget.parameters[k];
      j.Key("sigma_total").Number(b.total).Key("formal").Number(b.formal);
      j.Key("systematic").Number(b.systematic);
      j.Key("budget_variance").BeginObject().Key("noise").Number(p.noise_variance[k]);
      for (size_t g = 0; g < p.parts.size(); ++g) j.Key(p.parts[g]).Number(p.part_variance[g][k]);
      j.EndObject();
    } else {
      j.Key("sigma_total").Null();
    }
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
}

}  // namespace

std::string DesignPosesCsv(const Design& design, const std::string& provenance) {
  std::string out = CommentLines(provenance);
  out += "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n";
  for (const Pose& p : design.poses) {
    const Eigen::Vector3d rpy = RpyDegFromRotation(p.rotation);
    out += Fmt("%.6f", p.position_m[0]) + "," + Fmt("%.6f", p.position_m[1]) + "," +
           Fmt("%.6f", p.position_m[2]) + "," + Fmt("%.8f", rpy[0]) + "," + Fmt("%.8f", rpy[1]) +
           "," + Fmt("%.8f", rpy[2]) + "\n";
  }
  return out;
}

std::string DesignJson(const Design& d, const std::string& provenance) {
  const DesignOptions& o = d.options;
  JsonWriter j;
  j.BeginObject();
  j.Key("format").String("fastcal-design-1");
  j.Key("provenance").String(provenance);
  j.Key("criterion").String(DesignCriterionName(o.criterion));
  j.Key("samples").Int(o.samples);
  j.Key("max_extra_tilt_deg").Number(o.max_extra_tilt_deg);
  j.Key("max_extra_yaw_deg").Number(o.max_extra_yaw_deg);
  j.Key("seed").Int(static_cast<long long>(o.seed));
  j.Key("candidates").Int(static_cast<long long>(d.candidates.size()));
  j.Key("rejected_candidates").Int(d.rejected_candidates);
  j.Key("wanted").BeginArray();
  for (int k : d.wanted) j.String(d.free_names[k]);
  j.EndArray();
  j.Key("path").BeginObject();
  j.Key("stops").Int(static_cast<long long>(d.stops.size()));
  j.Key("stops_before_time_budget").Int(d.unconstrained_stops);
  j.Key("length_m").Number(d.path_length_m);
  j.Key("speed_m_per_s").Number(o.speed_m_per_s);
  j.Key("sample_interval_s").Number(o.sample_interval_s);
  j.Key("time_budget_s").Number(o.time_budget_s > 0.0 ? o.time_budget_s : NAN);
  j.Key("travel_s").Number(o.speed_m_per_s > 0.0 ? d.travel_s : NAN);
  j.Key("dwell_s").Number(d.dwell_s);
  j.Key("duration_s").Number(o.speed_m_per_s > 0.0 ? d.duration_s : NAN);
  j.EndObject();
  j.Key("stops").BeginArray();
  for (const DesignStop& s : d.stops) {
    const DesignCandidate& c = d.candidates[s.candidate];
    const Eigen::Vector3d rpy = RpyDegFromRotation(c.pose.rotation);
    j.BeginObject().Key("samples").Int(s.samples);
    j.Key("position_m")
        .NumberArray(
            std::vector<double>{c.pose.position_m[0], c.pose.position_m[1], c.pose.position_m[2]});
    j.Key("rpy_deg").NumberArray(std::vector<double>{rpy[0], rpy[1], rpy[2]});
    j.Key("off_axis_deg").Number(c.off_axis_deg).Key("azimuth_deg").Number(c.azimuth_deg);
    j.Key("extra_tilt_deg").Number(c.extra_tilt_deg);
    j.Key("tilt_direction_deg").Number(c.tilt_direction_deg);
    j.Key("extra_yaw_deg").Number(c.extra_yaw_deg);
    const DesignBinding& b = s.binding;
    if (!b.constraint.empty()) {
      const std::string unit = BindingUnit(b);
      j.Key("binding").BeginObject().Key("constraint").String(b.constraint);
      if (b.cable >= 0) j.Key("cable").Int(b.cable + 1);
      j.Key("value_" + unit).Number(BindingShown(b, b.value));
      j.Key("limit_" + unit).Number(BindingShown(b, b.limit));
      j.Key("corner").BeginObject();
      for (size_t k = 0; k < b.corner_si.size() && k < d.range.size(); ++k) {
        if (b.corner_si[k] == 0.0) continue;
        j.Key(d.range[k].name).Number(b.corner_si[k] / d.range[k].to_si);
      }
      j.EndObject().EndObject();
    }
    j.EndObject();
  }
  j.EndArray();
  j.Key("plausible_range").BeginObject();
  j.Key("prior_sigmas").Number(o.range_prior_sigmas);
  j.Key("mass_centre_m").Number(o.range_mass_centre_m);
  j.Key("offset_m").Number(o.range_offset_m);
  j.Key("relative").Number(o.range_relative);
  j.Key("min_tension_kN").Number(o.workspace.min_tension_n / 1e3);
  j.Key("rejected_off_nominal").Int(d.rejected_off_nominal);
  j.Key("parameters").BeginArray();
  for (const DesignRangeParameter& r : d.range) {
    j.BeginObject().Key("name").String(r.name).Key("unit").String(r.unit);
    j.Key("delta").Number(r.delta_si / r.to_si).Key("from_prior").Bool(r.from_prior).EndObject();
  }
  j.EndArray();
  const int tightest = TightestStop(d);
  if (tightest >= 0) j.Key("tightest_stop").Int(tightest + 1);
  j.EndObject();
  j.Key("design");
  WritePrediction(j, d, d.design);
  j.Key("parameters").BeginArray();  // the design's, at the top for a quick read
  for (size_t k = 0; k < d.free_names.size(); ++k) {
    j.BeginObject().Key("name").String(d.free_names[k]);
    j.Key("sigma_total").Number(d.design.ok ? d.design.budget.parameters[k].total : NAN);
    j.EndObject();
  }
  j.EndArray();
  j.Key("circle");
  WritePrediction(j, d, d.circle);
  j.Key("random");
  WritePrediction(j, d, d.random);
  j.Key("limiting_part").String(d.limiting_part);
  j.Key("limiting_share").Number(d.limiting_share);
  j.Key("prior_halved").BeginArray();
  for (const DesignPriorEffect& e : d.prior_effects) {
    j.BeginObject().Key("group").String(e.group).Key("consider").Bool(e.consider);
    j.Key("sigma_total").NumberArray(e.sigma_total).EndObject();
  }
  j.EndArray();
  j.EndObject();
  return j.str() + "\n";
}

namespace {

// The cap seen from above: candidates grey, the stops sized by their samples and filled
// by their extra tilt, the path, the paper's circle dashed, the towers on the rim.
std::string CapSvg(const Design& d, const CableRobot& robot) {
  const FocalGridSpec& g = d.options.workspace.grid;
  const double rim_m = g.focal_radius_m * std::sin(g.max_off_axis_deg * M_PI / 180.0);
  const double extent_m = rim_m;  // the towers are drawn at the rim, by their direction
  const double size = 620.0, half = size / 2.0, scale = (half - 40.0) / extent_m;
  auto X = [&](double x) { return Fmt("%.1f", half + scale * (x - g.focal_centre_m.x())); };
  auto Y = [&](double y) { return Fmt("%.1f", half - scale * (y - g.focal_centre_m.y())); };
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + Fmt("%.0f", size) +
                  "\" height=\"" + Fmt("%.0f", size) + "\" viewBox=\"0 0 " + Fmt("%.0f", size) +
                  " " + Fmt("%.0f", size) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<circle cx=\"" + X(g.focal_centre_m.x()) + "\" cy=\"" + Y(g.focal_centre_m.y()) +
       "\" r=\"" + Fmt("%.1f", scale * rim_m) + "\" fill=\"#f7f7f7\" stroke=\"#999\"/>\n";
  for (const DesignCandidate& c : d.candidates) {
    s += "<circle cx=\"" + X(c.pose.position_m.x()) + "\" cy=\"" + Y(c.pose.position_m.y()) +
         "\" r=\"0.8\" fill=\"#bbb\"/>\n";
  }
  const double r_circle = d.options.circle_radius_m;
  s += "<circle cx=\"" + X(d.options.circle_centre_m.x()) + "\" cy=\"" +
       Y(d.options.circle_centre_m.y()) + "\" r=\"" + Fmt("%.1f", scale * r_circle) +
       "\" fill=\"none\" stroke=\"#D55E00\" stroke-dasharray=\"6 4\"><title>the paper's circle" +
       "</title></circle>\n";
  std::string path;
  for (const DesignStop& st : d.stops) {
    const Eigen::Vector3d& p = d.candidates[st.candidate].pose.position_m;
    path += (path.empty() ? "M" : " L") + X(p.x()) + " " + Y(p.y());
  }
  s += "<path class=\"path\" d=\"" + path +
       "\" fill=\"none\" stroke=\"#0072B2\" stroke-width=\"1.2\"/>\n";
  int order = 0;
  for (const DesignStop& st : d.stops) {
    const DesignCandidate& c = d.candidates[st.candidate];
    const Eigen::Vector3d rpy = RpyDegFromRotation(c.pose.rotation);
    const double radius = 2.5 + 1.5 * std::sqrt(static_cast<double>(st.samples));
    const std::string fill =
        c.extra_tilt_deg > 0.0 ? "#009E73" : (c.extra_yaw_deg != 0.0 ? "#CC79A7" : "#0072B2");
    s += "<circle class=\"stop\" cx=\"" + X(c.pose.position_m.x()) + "\" cy=\"" +
         Y(c.pose.position_m.y()) + "\" r=\"" + Fmt("%.1f", radius) + "\" fill=\"" + fill +
         "\" fill-opacity=\"0.7\" stroke=\"#333\" stroke-width=\"0.5\"><title>stop " +
         std::to_string(++order) + ": " + std::to_string(st.samples) + " samples at (" +
         Fmt("%.2f", c.pose.position_m.x()) + ", " + Fmt("%.2f", c.pose.position_m.y()) + ", " +
         Fmt("%.2f", c.pose.position_m.z()) + ") m, rpy (" + Fmt("%.2f", rpy[0]) + ", " +
         Fmt("%.2f", rpy[1]) + ", " + Fmt("%.2f", rpy[2]) + ") deg; extra tilt " +
         Fmt("%.3g", c.extra_tilt_deg) + " deg toward " + Fmt("%.3g", c.tilt_direction_deg) +
         " deg, extra yaw " + Fmt("%.3g", c.extra_yaw_deg) + " deg</title></circle>\n";
  }
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d t = robot.cables[i].tower_top_m - g.focal_centre_m;
    const double a = std::atan2(t.y(), t.x());
    const double r = scale * rim_m + 18.0;
    s += "<text x=\"" + Fmt("%.1f", half + r * std::cos(a)) + "\" y=\"" +
         Fmt("%.1f", half - r * std::sin(a)) + "\" text-anchor=\"middle\">T" +
         std::to_string(i + 1) + "</text>\n";
  }
  s += "<text x=\"10\" y=\"18\">seen from above; rim: " + Fmt("%.3g", g.max_off_axis_deg) +
       " deg off axis (" + Fmt("%.4g", rim_m) + " m)</text>\n</svg>\n";
  return s;
}

std::string SigmaCell(const DesignPrediction& p, int k, double scale) {
  if (!p.ok) return "<td>n/a</td>";
  return "<td class=\"num\">" + Fmt("%.4g", p.budget.parameters[k].total * scale) + "</td>";
}

std::string SigmaTable(const Design& d) {
  std::string h =
      "<table><thead><tr><th>parameter</th><th>unit</th><th>design</th><th>paper's "
      "circle</th><th>random survey</th></tr></thead><tbody>\n";
  for (size_t k = 0; k < d.free_names.size(); ++k) {
    const bool wanted =
        std::find(d.wanted.begin(), d.wanted.end(), static_cast<int>(k)) != d.wanted.end();
    const Shown u = ShownUnit(d, static_cast<int>(k));
    h += std::string(wanted ? "<tr class=\"wanted\">" : "<tr>") + "<th>" +
         XmlEscape(d.free_names[k]) + (wanted ? " (wanted)" : "") + "</th><td>" + u.unit + "</td>" +
         SigmaCell(d.design, static_cast<int>(k), u.scale) +
         SigmaCell(d.circle, static_cast<int>(k), u.scale) +
         SigmaCell(d.random, static_cast<int>(k), u.scale) + "</tr>\n";
  }
  return h + "</tbody></table>\n";
}

std::string SigmaBars(const Design& d) {
  std::vector<BarGroup> groups;
  for (int k : d.wanted) {
    const Shown u = ShownUnit(d, static_cast<int>(k));
    BarGroup g;
    g.label = d.free_names[k];
    for (const DesignPrediction* p : {&d.design, &d.circle, &d.random}) {
      g.values.push_back(p->ok ? p->budget.parameters[k].total * u.scale : NAN);
    }
    groups.push_back(g);
  }
  PlotOptions o;
  o.title = "predicted sigma_total of the wanted parameters";
  o.y_label = "sigma_total (" + ShownUnit(d, d.wanted[0]).unit + ")";
  return SvgGroupedBars(groups, {"design", "paper's circle", "random survey"}, o);
}

std::string LimitsText(const Design& d) {
  std::string h =
      "<h2>What limits the design</h2>\n<p>The largest part of the wanted "
      "parameters' summed variance is <b>" +
      XmlEscape(d.limiting_part == "noise" ? "the tension noise of the data" : d.limiting_part) +
      "</b>: " + Fmt("%.0f", 100.0 * d.limiting_share) + "% of it.</p>\n";
  if (d.prior_effects.empty()) return h;
  h += "<p>With one prior (or consider) sigma halved, the design's sigma_total would be:</p>\n"
       "<table><thead><tr><th>sigma halved</th>";
  for (int k : d.wanted) {
    h += "<th>" + XmlEscape(d.free_names[k]) + " (" + ShownUnit(d, k).unit + ")</th>";
  }
  h += "</tr></thead><tbody>\n<tr><th>none (as designed)</th>";
  for (int k : d.wanted) {
    h += SigmaCell(d.design, k, ShownUnit(d, k).scale);
  }
  h += "</tr>\n";
  for (const DesignPriorEffect& e : d.prior_effects) {
    h += "<tr><th>" + XmlEscape(e.group) + (e.consider ? " (consider)" : " (prior)") + "</th>";
    for (size_t w = 0; w < e.sigma_total.size(); ++w) {
      h += "<td class=\"num\">" + Fmt("%.4g", e.sigma_total[w] * ShownUnit(d, d.wanted[w]).scale) +
           "</td>";
    }
    h += "</tr>\n";
  }
  return h + "</tbody></table>\n";
}

// Stops by their binding constraint, e.g. "min_tension at 20 of 23 stops,
// reflector_clearance at 3".
std::string BindingCounts(const Design& d) {
  std::vector<std::pair<std::string, int>> counts;
  for (const DesignStop& st : d.stops) {
    auto it = std::find_if(counts.begin(), counts.end(),
                           [&](const auto& c) { return c.first == st.binding.constraint; });
    if (it == counts.end()) {
      counts.push_back({st.binding.constraint, 1});
    } else {
      ++it->second;
    }
  }
  std::string out;
  for (size_t k = 0; k < counts.size(); ++k) {
    out += (k ? ", " : "") + counts[k].first + " at " + std::to_string(counts[k].second);
    if (k == 0) out += " of " + std::to_string(d.stops.size()) + " stops";
  }
  return out;
}

// A binding in words: "cable 6 at 51.2 kN (limit 50 kN)".
std::string BindingText(const DesignBinding& b) {
  return (b.cable >= 0 ? "cable " + std::to_string(b.cable + 1) + " at " : std::string("")) +
         Fmt("%.4g", BindingShown(b, b.value)) + " " + BindingUnit(b) + " (limit " +
         Fmt("%.4g", BindingShown(b, b.limit)) + " " + BindingUnit(b) + ")";
}

std::string RangeSection(const Design& d) {
  const WorkspaceOptions& w = d.options.workspace;
  std::string h =
      "<h2>Poses that hold</h2>\n<p>Every candidate was judged at the spec's initial values and "
      "over the plausible range of its parameters: " +
      XmlEscape(RangeText(d)) +
      ". At the initial values and at the corner of that box where each cable's tension is "
      "lowest" +
      (std::isfinite(w.max_tension_n) ? std::string(" (and highest)") : std::string("")) +
      ", the statics must hold with every lower-end tension at least " +
      Fmt("%.4g", w.min_tension_n / 1e3) + " kN" +
      (std::isfinite(w.max_tension_n) ? " and at most " + Fmt("%.4g", w.max_tension_n / 1e3) + " kN"
                                      : std::string("")) +
      " and every cable " + Fmt("%.3g", w.statics.min_reflector_clearance_m) +
      " m clear of the reflector. " + std::to_string(d.rejected_off_nominal) +
      " candidates feasible at the initial values only were left out.</p>\n";
  if (d.stops.empty()) return h;
  const int tightest = TightestStop(d);
  h += "<p>What binds each stop, at its worst corner (bold: the tightest). Where in the range: "
       "per group, each parameter's side of its initial value (+ or -), in the order of "
       "<code>plausible_range.parameters</code> in design.json.</p>\n<div "
       "class=\"wrap\"><table><thead><tr><th>stop</th><th>position (m)</th><th>binds</th>"
       "<th>there</th><th>where in the range</th></tr></thead><tbody>\n";
  for (size_t k = 0; k < d.stops.size(); ++k) {
    const DesignBinding& b = d.stops[k].binding;
    const Eigen::Vector3d& p = d.candidates[d.stops[k].candidate].pose.position_m;
    const bool bold = static_cast<int>(k) == tightest;
    h += std::string(bold ? "<tr style=\"font-weight:bold\">" : "<tr>") + "<td class=\"num\">" +
         std::to_string(k + 1) + "</td><td>(" + Fmt("%.2f", p.x()) + ", " + Fmt("%.2f", p.y()) +
         ", " + Fmt("%.2f", p.z()) + ")</td><td>" + XmlEscape(b.constraint) + "</td><td>" +
         XmlEscape(BindingText(b)) + "</td><td>" + XmlEscape(CornerText(d, b)) + "</td></tr>\n";
  }
  return h + "</tbody></table></div>\n";
}

}  // namespace

std::string DesignRangeSummary(const Design& d) {
  std::string out = "holds over the plausible range: " + RangeText(d) + "; " +
                    std::to_string(d.rejected_off_nominal) +
                    " candidates feasible at the initial values only left out";
  const int tightest = TightestStop(d);
  if (tightest < 0) return out;
  const DesignBinding& b = d.stops[tightest].binding;
  return out + "\nbinding: " + BindingCounts(d) + "; tightest: stop " +
         std::to_string(tightest + 1) + ", " + b.constraint + ", " + BindingText(b) +
         (d.range.empty() ? std::string(" at the initial values")
                          : " at a corner of the range (design.json: stops[" +
                                std::to_string(tightest) + "].binding.corner)");
}

std::string DesignHtml(const Design& d, const CableRobot& robot, const std::string& provenance) {
  const DesignOptions& o = d.options;
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>fastcal design"
      "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:1em auto;padding:0 "
      "1em}table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #ccc;padding:"
      "3px 8px;text-align:left}td.num{text-align:right;font-variant-numeric:tabular-nums}"
      "tr.wanted th{color:#0072B2}.wrap{overflow-x:auto}code{background:#f3f3f3}</style>"
      "</head><body>\n<h1>Calibration survey design</h1>\n";
  // One line of the provenance per line of the page (command line, then version and model).
  std::string lines = XmlEscape(provenance);
  for (size_t at = lines.find('\n'); at != std::string::npos; at = lines.find('\n', at + 6)) {
    lines.replace(at, 1, "<br>\n");
  }
  h += "<p><code>" + lines + "</code></p>\n";
  h += "<p>" + std::to_string(o.samples) + " samples at " + std::to_string(d.stops.size()) +
       " stops, chosen " + DesignCriterionName(o.criterion) + "-optimally from " +
       std::to_string(d.candidates.size()) + " feasible candidate poses (" +
       std::to_string(d.rejected_candidates) + " infeasible left out); extra tilt up to " +
       Fmt("%.3g", o.max_extra_tilt_deg) + " deg, extra yaw up to " +
       Fmt("%.3g", o.max_extra_yaw_deg) + " deg off the focal law. Path " +
       Fmt("%.4g", d.path_length_m) + " m";
  if (o.speed_m_per_s > 0.0) {
    h += ", " + Fmt("%.4g", d.duration_s / 60.0) + " min at " + Fmt("%.3g", o.speed_m_per_s) +
         " m/s (" + Fmt("%.4g", d.travel_s / 60.0) + " min flying, " +
         Fmt("%.4g", d.dwell_s / 60.0) + " min sampling)";
  }
  if (o.time_budget_s > 0.0) {
    h += "; time budget " + Fmt("%.4g", o.time_budget_s / 60.0) + " min (" +
         std::to_string(d.unconstrained_stops) + " stops without it)";
  }
  h += ".</p>\n<h2>Poses and path on the cap</h2>\n<div class=\"wrap\">" + CapSvg(d, robot) +
       "</div>\n<p>Grey: candidate positions. Circles: the stops (area by samples; blue at "
       "the focal law, green tilted, purple turned only), joined by the path in flight order; "
       "dashed: the paper's circle.</p>\n";
  h += "<h2>Predicted sigma_total</h2>\n<p>From the calibration's own linearisation and noise "
       "model at the spec's initial values: white residuals at the stated noise, priors, "
       "nuisance parameters marginalised, consider parameters included. The circle and the "
       "random survey have the same number of samples.</p>\n<div class=\"wrap\">" +
       SigmaBars(d) + "</div>\n" + SigmaTable(d);
  h += LimitsText(d);
  h += RangeSection(d);
  return h + "</body></html>\n";
}

}  // namespace fastcal
