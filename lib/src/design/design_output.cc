// A survey design's outputs (design.h): poses.csv, design.json and design.html. The map
// is the cap seen from above (x toward tower 1's side as in the workspace map), in metres.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "fastcal/design.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/report_document.h"
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

// A free parameter's value in the spec's unit, its name's (sensor_bias_kN in kN): the
// library is SI inside, the files speak as the spec and calibrate's outputs do.
double InSpecUnit(const Design& d, size_t k, double si_value) { return si_value / d.free_to_si[k]; }

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
    j.EndObject();
  }
  j.EndArray();
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
  // The flight order: each stop's number beside it, the first also marked "start" with a
  // ring, so that the path reads without its tooltips.
  if (!d.stops.empty()) {
    const Eigen::Vector3d& p0 = d.candidates[d.stops.front().candidate].pose.position_m;
    s += "<circle class=\"start\" cx=\"" + X(p0.x()) + "\" cy=\"" + Y(p0.y()) +
         "\" r=\"13\" fill=\"none\" stroke=\"#111\" stroke-width=\"2\"/>\n<text x=\"" +
         Fmt("%.1f", half + scale * (p0.x() - g.focal_centre_m.x()) + 16.0) + "\" y=\"" +
         Fmt("%.1f", half - scale * (p0.y() - g.focal_centre_m.y()) - 12.0) +
         "\" font-weight=\"bold\">start</text>\n";
  }
  int order = 0;
  struct Number {
    double x_px = 0.0, y_px = 0.0, radius_px = 0.0;
    std::string label;
  };
  std::map<std::string, Number> numbers;  // by drawn position
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
    // Stops at one position (other attitudes) share one label: "18, 19".
    Number& n = numbers[X(c.pose.position_m.x()) + "," + Y(c.pose.position_m.y())];
    n.x_px = half + scale * (c.pose.position_m.x() - g.focal_centre_m.x());
    n.y_px = half - scale * (c.pose.position_m.y() - g.focal_centre_m.y());
    n.radius_px = std::max(n.radius_px, radius);
    n.label += (n.label.empty() ? "" : ", ") + std::to_string(order);
  }
  for (const auto& [at, n] : numbers) {
    s += "<text class=\"stop-number\" x=\"" + Fmt("%.1f", n.x_px + n.radius_px + 2.0) + "\" y=\"" +
         Fmt("%.1f", n.y_px - 3.0) + "\" font-size=\"11\" font-weight=\"bold\" fill=\"#222\">" +
         n.label + "</text>\n";
  }
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
    h += ", " + Fmt("%.4g", d.duration_s / 60.0) + " min at " + Fmt("%.3g", o.speed_m_per_s) +
         " m/s (" + Fmt("%.4g", d.travel_s / 60.0) + " min flying, " +
         Fmt("%.4g", d.dwell_s / 60.0) + " min sampling)";
  }
  if (o.time_budget_s > 0.0) {
    h += "; time budget " + Fmt("%.4g", o.time_budget_s / 60.0) + " min (" +
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
  return internal::RenderHtmlPage(doc);
}

}  // namespace fastcal
