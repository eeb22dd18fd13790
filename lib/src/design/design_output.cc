// A survey design's outputs (design.h): poses.csv, design.json and design.html. The map
// is the cap seen from above (x toward tower 1's side as in the workspace map), in metres.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "fastcal/design.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/report_document.h"
#include "fastcal/svg_plot.h"

namespace fastcal {
namespace {

// printf's text, except that a value that rounds to zero reads "0.00", not "-0.00".
std::string Fmt(const char* format, double v) {
  return internal::WithoutNegativeZero(internal::FormatDouble(format, v));
}

std::string CommentLines(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out += "# " + line + "\n";
  return out;
}

// Unit of free parameter k for display: the spec's, the one in its name, as on the
// console and in design.json (issue 39: the page said mm where they said m).
struct Shown {
  double scale;  // displayed value = SI value * scale
  std::string unit;
};
Shown ShownUnit(const Design& d, int k) { return {1.0 / d.free_to_si[k], d.free_units[k]}; }

// A free parameter's value in the spec's unit, its name's (sensor_bias_kN in kN): the
// library is SI inside, the files speak as the spec and calibrate's outputs do.
double InSpecUnit(const Design& d, size_t k, double si_value) { return si_value / d.free_to_si[k]; }

// A range parameter's group: its name before '.' or '[' ("mass_centre_m"), a moving
// part's up to its quantity ("moving_parts.rotator.first_moment_kg_m").
std::string RangeGroup(const std::string& name) {
  const std::string parts = "moving_parts.";
  if (name.compare(0, parts.size(), parts) == 0) {
    const size_t part_end = name.find('.', parts.size());
    return part_end == std::string::npos ? name : name.substr(0, name.find('.', part_end + 1));
  }
  return name.substr(0, name.find_first_of(".["));
}

// The range's parameters grouped by name before '.' or '[' with their offset in file
// units, e.g. "mass_centre_m +-0.25 m (margin); linear_density_kg_per_m +-0.36 kg/m (2
// sigma)".
std::string RangeText(const Design& d) {
  std::string out;
  for (size_t j = 0; j < d.range.size(); ++j) {
    const DesignRangeParameter& r = d.range[j];
    const std::string group = RangeGroup(r.name);
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
    const std::string g = RangeGroup(r.name);
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

// A stop's joint values for a person ("; rotator_a_deg 15, rotator_b_deg -15"), or "".
std::string JointsText(const Design& d, const DesignCandidate& c) {
  std::string out;
  for (size_t k = 0; k < d.joint_columns.size(); ++k) {
    out += (k == 0 ? "; " : ", ") + d.joint_columns[k] + " " + Fmt("%.3g", c.joints[k]);
  }
  return out;
}

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
    j.BeginObject().Key("name").String(d.free_names[k]).Key("unit").String(d.free_units[k]);
    j.Key("wanted").Bool(wanted);
    if (p.ok) {
      const ParameterBudget& b = p.budget.parameters[k];
      const double squared = InSpecUnit(d, k, InSpecUnit(d, k, 1.0));  // variances' scale
      j.Key("sigma_total").Number(InSpecUnit(d, k, b.total));
      j.Key("formal").Number(InSpecUnit(d, k, b.formal));
      j.Key("systematic").Number(InSpecUnit(d, k, b.systematic));
      j.Key("budget_variance").BeginObject().Key("noise").Number(p.noise_variance[k] * squared);
      for (size_t g = 0; g < p.parts.size(); ++g) {
        j.Key(p.parts[g]).Number(p.part_variance[g][k] * squared);
      }
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
  out += "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg";
  for (const std::string& column : design.joint_columns) out += "," + column;
  out += "\n";
  for (size_t n = 0; n < design.data_poses.size(); ++n) {
    const Pose& p = design.data_poses[n];
    const Eigen::Vector3d rpy = RpyDegFromRotation(p.rotation);
    out += Fmt("%.6f", p.position_m[0]) + "," + Fmt("%.6f", p.position_m[1]) + "," +
           Fmt("%.6f", p.position_m[2]) + "," + Fmt("%.8f", rpy[0]) + "," + Fmt("%.8f", rpy[1]) +
           "," + Fmt("%.8f", rpy[2]);
    for (size_t j = 0; j < design.joint_columns.size() && n < design.joints.size(); ++j) {
      out += "," + Fmt("%.8f", design.joints[n][j]);
    }
    out += "\n";
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
  if (!d.joint_columns.empty()) j.Key("joint_grid_deg").NumberArray(o.joint_grid_deg);
  // The noise the predictions assumed: null for white, else the slow error's parts.
  j.Key("slow_error");
  if (d.slow_error.IsActive()) {
    j.BeginObject()
        .Key("sigma_percent")
        .Number(d.slow_error.sigma_percent)
        .Key("sigma_kN")
        .Number(d.slow_error.sigma_n / 1e3)
        .Key("time_constant_s")
        .Number(d.slow_error.time_constant_s)
        .EndObject();
  } else {
    j.Null();
  }
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
  j.Key("settle_s").Number(o.speed_m_per_s > 0.0 && o.settle_after_moves ? d.settle_s : NAN);
  j.Key("settle_fraction").Number(o.settle_after_moves ? o.settle.fraction : NAN);
  if (!d.settle_note.empty()) j.Key("settle_note").String(d.settle_note);
  j.Key("duration_s").Number(o.speed_m_per_s > 0.0 ? d.duration_s : NAN);
  j.EndObject();
  j.Key("stops").BeginArray();
  for (const DesignStop& s : d.stops) {
    const DesignCandidate& c = d.candidates[s.candidate];
    const Eigen::Vector3d rpy = RpyDegFromRotation(c.data_pose.rotation);
    j.BeginObject().Key("samples").Int(s.samples);
    // The wait before its samples (move_settle.h): simulated or screened out, settled or
    // still outside the band at the longest wait.
    j.Key("settle")
        .BeginObject()
        .Key("wait_s")
        .Number(s.settle.wait_s)
        .Key("move_s")
        .Number(s.settle.move_s)
        .Key("simulated")
        .Bool(s.settle.simulated)
        .Key("settled")
        .Bool(s.settle.settled)
        .EndObject();
    j.Key("position_m")
        .NumberArray(std::vector<double>{c.data_pose.position_m[0], c.data_pose.position_m[1],
                                         c.data_pose.position_m[2]});
    j.Key("rpy_deg").NumberArray(std::vector<double>{rpy[0], rpy[1], rpy[2]});
    j.Key("off_axis_deg").Number(c.off_axis_deg).Key("azimuth_deg").Number(c.azimuth_deg);
    j.Key("extra_tilt_deg").Number(c.extra_tilt_deg);
    j.Key("tilt_direction_deg").Number(c.tilt_direction_deg);
    j.Key("extra_yaw_deg").Number(c.extra_yaw_deg);
    if (!d.joint_columns.empty()) {
      j.Key("joints").BeginObject();
      for (size_t k = 0; k < d.joint_columns.size(); ++k) {
        j.Key(d.joint_columns[k]).Number(c.joints[k]);
      }
      j.EndObject();
    }
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
    j.BeginObject().Key("name").String(d.free_names[k]).Key("unit").String(d.free_units[k]);
    j.Key("sigma_total")
        .Number(d.design.ok ? InSpecUnit(d, k, d.design.budget.parameters[k].total) : NAN);
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
    std::vector<double> sigma_total;  // of each wanted parameter, in its spec unit
    for (size_t w = 0; w < e.sigma_total.size(); ++w) {
      sigma_total.push_back(InSpecUnit(d, d.wanted[w], e.sigma_total[w]));
    }
    j.Key("sigma_total").NumberArray(sigma_total).EndObject();
  }
  j.EndArray();
  j.EndObject();
  return j.str() + "\n";
}

namespace {

// The stops' numbers beside their circles, placed where they overlap no other
// (PlaceCircleLabels): stops a few pixels apart (12 and 13 at the rim) stay readable.
std::string StopNumbers(const std::map<std::string, CircleLabel>& numbers) {
  std::vector<CircleLabel> labels;
  for (const auto& [at, n] : numbers) labels.push_back(n);
  const std::vector<LabelSpot> spots = PlaceCircleLabels(labels, 7.0, 11.0);  // 11 px bold
  std::string s;
  for (size_t k = 0; k < labels.size(); ++k) {
    s += "<text class=\"stop-number\" x=\"" + Fmt("%.1f", spots[k].x_px) + "\" y=\"" +
         Fmt("%.1f", spots[k].baseline_px) +
         "\" font-size=\"11\" font-weight=\"bold\" fill=\"#222\">" + labels[k].text + "</text>\n";
  }
  return s;
}

// The cap seen from above: candidates grey, the stops sized by their samples and filled
// by their extra tilt, the path, the paper's circle dashed, the towers on the rim.
std::string CapSvg(const Design& d, const CableRobot& robot) {
  const FocalGridSpec& g = d.options.workspace.grid;
  const double rim_m = g.focal_radius_m * std::sin(g.max_off_axis_deg * M_PI / 180.0);
  const double extent_m = rim_m;  // the towers are drawn at the rim, by their direction
  const double size = 640.0, half = size / 2.0, scale = (half - 56.0) / extent_m;
  auto X = [&](double x) { return Fmt("%.1f", half + scale * (x - g.focal_centre_m.x())); };
  auto Y = [&](double y) { return Fmt("%.1f", half - scale * (y - g.focal_centre_m.y())); };
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + Fmt("%.0f", size) +
                  "\" height=\"" + Fmt("%.0f", size) + "\" viewBox=\"0 0 " + Fmt("%.0f", size) +
                  " " + Fmt("%.0f", size) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<circle cx=\"" + X(g.focal_centre_m.x()) + "\" cy=\"" + Y(g.focal_centre_m.y()) +
       "\" r=\"" + Fmt("%.1f", scale * rim_m) + "\" fill=\"#f7f7f7\" stroke=\"#999\"/>\n";
  for (const DesignCandidate& c : d.candidates) {
    s += "<circle cx=\"" + X(c.data_pose.position_m.x()) + "\" cy=\"" +
         Y(c.data_pose.position_m.y()) + "\" r=\"0.8\" fill=\"#bbb\"/>\n";
  }
  const double r_circle = d.options.circle_radius_m;
  s += "<circle cx=\"" + X(d.options.circle_centre_m.x()) + "\" cy=\"" +
       Y(d.options.circle_centre_m.y()) + "\" r=\"" + Fmt("%.1f", scale * r_circle) +
       "\" fill=\"none\" stroke=\"#D55E00\" stroke-dasharray=\"6 4\"><title>the paper's circle" +
       "</title></circle>\n";
  std::string path;
  for (const DesignStop& st : d.stops) {
    const Eigen::Vector3d& p = d.candidates[st.candidate].data_pose.position_m;
    path += (path.empty() ? "M" : " L") + X(p.x()) + " " + Y(p.y());
  }
  s += "<path class=\"path\" d=\"" + path +
       "\" fill=\"none\" stroke=\"#0072B2\" stroke-width=\"1.2\"/>\n";
  // The flight order: each stop's number beside it, the first also marked "start" with a
  // ring, so that the path reads without its tooltips.
  if (!d.stops.empty()) {
    const Eigen::Vector3d& p0 = d.candidates[d.stops.front().candidate].data_pose.position_m;
    s += "<circle class=\"start\" cx=\"" + X(p0.x()) + "\" cy=\"" + Y(p0.y()) +
         "\" r=\"13\" fill=\"none\" stroke=\"#111\" stroke-width=\"2\"/>\n<text x=\"" +
         Fmt("%.1f", half + scale * (p0.x() - g.focal_centre_m.x()) + 16.0) + "\" y=\"" +
         Fmt("%.1f", half - scale * (p0.y() - g.focal_centre_m.y()) - 12.0) +
         "\" font-weight=\"bold\">start</text>\n";
  }
  int order = 0;
  std::map<std::string, CircleLabel> numbers;  // by drawn position
  for (const DesignStop& st : d.stops) {
    const DesignCandidate& c = d.candidates[st.candidate];
    const Eigen::Vector3d rpy = RpyDegFromRotation(c.data_pose.rotation);
    const double radius = 2.5 + 1.5 * std::sqrt(static_cast<double>(st.samples));
    const std::string fill =
        c.extra_tilt_deg > 0.0 ? "#009E73" : (c.extra_yaw_deg != 0.0 ? "#CC79A7" : "#0072B2");
    s += "<circle class=\"stop\" cx=\"" + X(c.data_pose.position_m.x()) + "\" cy=\"" +
         Y(c.data_pose.position_m.y()) + "\" r=\"" + Fmt("%.1f", radius) + "\" fill=\"" + fill +
         "\" fill-opacity=\"0.7\" stroke=\"#333\" stroke-width=\"0.5\"><title>stop " +
         std::to_string(++order) + ": " + std::to_string(st.samples) + " samples at (" +
         Fmt("%.2f", c.data_pose.position_m.x()) + ", " + Fmt("%.2f", c.data_pose.position_m.y()) +
         ", " + Fmt("%.2f", c.data_pose.position_m.z()) + ") m, rpy (" + Fmt("%.2f", rpy[0]) +
         ", " + Fmt("%.2f", rpy[1]) + ", " + Fmt("%.2f", rpy[2]) + ") deg; extra tilt " +
         Fmt("%.3g", c.extra_tilt_deg) + " deg toward " + Fmt("%.3g", c.tilt_direction_deg) +
         " deg, extra yaw " + Fmt("%.3g", c.extra_yaw_deg) + " deg" + JointsText(d, c) +
         "</title></circle>\n";
    // Stops at one position (other attitudes) share one label: "18, 19".
    CircleLabel& n = numbers[X(c.data_pose.position_m.x()) + "," + Y(c.data_pose.position_m.y())];
    n.x_px = half + scale * (c.data_pose.position_m.x() - g.focal_centre_m.x());
    n.y_px = half - scale * (c.data_pose.position_m.y() - g.focal_centre_m.y());
    n.radius_px = std::max(n.radius_px, radius);
    n.text += (n.text.empty() ? "" : ", ") + std::to_string(order);
  }
  s += StopNumbers(numbers);
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d t = robot.cables[i].tower_top_m - g.focal_centre_m;
    const double a = std::atan2(t.y(), t.x());
    const double r = scale * rim_m + 34.0;  // beyond the stops' numbers on the rim
    s += "<text x=\"" + Fmt("%.1f", half + r * std::cos(a)) + "\" y=\"" +
         Fmt("%.1f", half - r * std::sin(a) + 4.0) + "\" text-anchor=\"middle\" fill=\"#777\">T" +
         std::to_string(i + 1) + "</text>\n";
  }
  s += "<text x=\"10\" y=\"18\">seen from above; rim: " + Fmt("%.3g", g.max_off_axis_deg) +
       " deg off axis (" + Fmt("%.4g", rim_m) + " m)</text>\n</svg>\n";
  return s;
}

internal::Text SigmaCell(const DesignPrediction& p, int k, double scale) {
  if (!p.ok) return internal::Text("n/a");
  return internal::Text(Fmt("%.4g", p.budget.parameters[k].total * scale));
}

bool IsWanted(const Design& d, size_t k) {
  return std::find(d.wanted.begin(), d.wanted.end(), static_cast<int>(k)) != d.wanted.end();
}

internal::Table SigmaTable(const Design& d) {
  internal::Table t;
  t.header = {"parameter", "unit", "design", "paper's circle", "random survey"};
  t.right_align = {false, false, true, true, true};
  for (size_t k = 0; k < d.free_names.size(); ++k) {
    const Shown u = ShownUnit(d, static_cast<int>(k));
    internal::Text name;
    name.Code(d.free_names[k]);
    if (IsWanted(d, k)) name.Bold(" (wanted)");
    t.rows.push_back({name, internal::Text(u.unit),
                      SigmaCell(d.design, static_cast<int>(k), u.scale),
                      SigmaCell(d.circle, static_cast<int>(k), u.scale),
                      SigmaCell(d.random, static_cast<int>(k), u.scale)});
  }
  return t;
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

void AddLimits(const Design& d, internal::Document* doc) {
  doc->Heading(2, "What limits the design");
  doc->Paragraph(
      internal::Text("The largest part of the wanted parameters' summed variance is ")
          .Bold(d.limiting_part == "noise" ? "the tension noise of the data" : d.limiting_part)
          .Plain(": " + Fmt("%.0f", 100.0 * d.limiting_share) + "% of it."));
  if (d.prior_effects.empty()) return;
  doc->Paragraph("With one prior (or consider) sigma halved, the design's sigma_total would be:");
  internal::Table t;
  t.header = {"sigma halved"};
  t.right_align = {false};
  for (int k : d.wanted) {
    t.header.push_back(
        internal::Text().Code(d.free_names[k]).Plain(" (" + ShownUnit(d, k).unit + ")"));
    t.right_align.push_back(true);
  }
  std::vector<internal::Text> designed = {"none (as designed)"};
  for (int k : d.wanted) designed.push_back(SigmaCell(d.design, k, ShownUnit(d, k).scale));
  t.rows.push_back(designed);
  for (const DesignPriorEffect& e : d.prior_effects) {
    std::vector<internal::Text> row = {
        internal::Text().Code(e.group).Plain(e.consider ? " (consider)" : " (prior)")};
    for (size_t w = 0; w < e.sigma_total.size(); ++w) {
      row.push_back(Fmt("%.4g", e.sigma_total[w] * ShownUnit(d, d.wanted[w]).scale));
    }
    t.rows.push_back(row);
  }
  doc->AddTable(std::move(t));
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

void AddRange(const Design& d, internal::Document* doc) {
  const WorkspaceOptions& w = d.options.workspace;
  doc->Heading(2, "Poses that hold");
  doc->Paragraph(
      "Every candidate was judged at the spec's initial values and over the plausible range of "
      "its parameters: " +
      RangeText(d) +
      ". At the initial values and at the corner of that box where each cable's tension is "
      "lowest" +
      (std::isfinite(w.max_tension_n) ? std::string(" (and highest)") : std::string("")) +
      ", the statics must hold with every lower-end tension at least " +
      Fmt("%.4g", w.min_tension_n / 1e3) + " kN" +
      (std::isfinite(w.max_tension_n) ? " and at most " + Fmt("%.4g", w.max_tension_n / 1e3) + " kN"
                                      : std::string("")) +
      " and every cable " + Fmt("%.3g", w.statics.min_reflector_clearance_m) +
      " m clear of the reflector. " + std::to_string(d.rejected_off_nominal) +
      " candidates feasible at the initial values only were left out.");
  if (d.stops.empty()) return;
  const int tightest = TightestStop(d);
  doc->Paragraph(internal::Text("What binds each stop, at its worst corner (bold: the tightest). "
                                "Where in the range: per group, each parameter's side of its "
                                "initial value (+ or -), in the order of ")
                     .Code("plausible_range.parameters")
                     .Plain(" in design.json."));
  internal::Table t;
  t.header = {"stop", "position (m)", "binds", "there", "where in the range"};
  t.right_align = {true, false, false, false, false};
  for (size_t k = 0; k < d.stops.size(); ++k) {
    const DesignBinding& b = d.stops[k].binding;
    const Eigen::Vector3d& p = d.candidates[d.stops[k].candidate].data_pose.position_m;
    const bool bold = static_cast<int>(k) == tightest;
    std::vector<internal::Text> row;
    for (const std::string& cell :
         {std::to_string(k + 1),
          "(" + Fmt("%.2f", p.x()) + ", " + Fmt("%.2f", p.y()) + ", " + Fmt("%.2f", p.z()) + ")",
          b.constraint, BindingText(b), CornerText(d, b)}) {
      row.push_back(bold ? internal::Text().Bold(cell) : internal::Text(cell));
    }
    t.rows.push_back(row);
  }
  doc->AddTable(std::move(t));
}

// What was designed, in one paragraph: samples, stops, candidates, attitudes, path.
std::string SurveyText(const Design& d) {
  const DesignOptions& o = d.options;
  std::string h = std::to_string(o.samples) + " samples at " + std::to_string(d.stops.size()) +
                  " stops, chosen " + DesignCriterionName(o.criterion) + "-optimally from " +
                  std::to_string(d.candidates.size()) + " feasible candidate poses (" +
                  std::to_string(d.rejected_candidates) +
                  " infeasible left out); extra tilt up to " + Fmt("%.3g", o.max_extra_tilt_deg) +
                  " deg, extra yaw up to " + Fmt("%.3g", o.max_extra_yaw_deg) +
                  " deg off the focal law. Path " + Fmt("%.4g", d.path_length_m) + " m";
  if (o.speed_m_per_s > 0.0) {
    h += ", " + Fmt("%.3g", d.duration_s / 60.0) + " min at " + Fmt("%.3g", o.speed_m_per_s) +
         " m/s (" + Fmt("%.3g", d.travel_s / 60.0) + " min flying, " +
         Fmt("%.3g", d.dwell_s / 60.0) + " min sampling" +
         (o.settle_after_moves
              ? ", " + Fmt("%.3g", d.settle_s / 60.0) + " min waiting for the tensions to settle"
              : std::string()) +
         ")";
  }
  if (o.time_budget_s > 0.0) {
    h += "; time budget " + Fmt("%.3g", o.time_budget_s / 60.0) + " min (" +
         std::to_string(d.unconstrained_stops) + " stops without it)";
  }
  return h + ".";
}

}  // namespace

// The page in the calibration report's style (internal::RenderHtmlPage).
std::string DesignHtml(const Design& d, const CableRobot& robot, const std::string& provenance) {
  internal::Document doc;
  doc.title = "fastcal design";
  doc.Heading(1, "Calibration survey design");
  doc.Pre("", provenance, false);
  doc.Paragraph(SurveyText(d));
  doc.Heading(2, "Poses and path on the cap");
  doc.Figure({CapSvg(d, robot)},
             "Seen from above. Grey: candidate positions. Circles: the stops (area by samples; "
             "blue at the focal law, green tilted, purple turned only), numbered in flight "
             "order from the ringed start and joined by the path; dashed: the paper's circle. "
             "Hover a stop for its pose.");
  doc.Heading(2, "Predicted sigma_total");
  doc.Paragraph(
      "From the calibration's own linearisation and noise model at the spec's initial "
      "values: white residuals at the stated noise, priors, nuisance parameters "
      "marginalised, consider parameters included. The circle and the random survey have "
      "the same number of samples. Lengths in mm.");
  doc.Figure({SigmaBars(d)}, "The wanted parameters' predicted sigma_total by survey.");
  doc.AddTable(SigmaTable(d));
  AddLimits(d, &doc);
  AddRange(d, &doc);
  return internal::RenderHtmlPage(doc);
}

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

}  // namespace fastcal
