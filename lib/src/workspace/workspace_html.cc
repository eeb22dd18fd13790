// The workspace map as a self-contained HTML page (workspace.h): summary, limits, counts
// per reason and layer, and one polar map of the cap per layer (svg_plot.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include "fastcal/internal/units.h"
#include "fastcal/svg_plot.h"
#include "fastcal/workspace.h"

namespace fastcal {
namespace {

using internal::kNPerKn;

std::string Num(double value, int digits) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, value);
  return buf;
}

// The reasons a node can have, in the order of the tables and legends, with their mark.
struct ReasonStyle {
  const char* code;   // WorkspaceNodeCode
  const char* label;  // legend and table text
  MarkShape shape;
  bool filled = false;  // dark: below the minimum (▼) is not read as above the maximum (△)
};
constexpr std::array<ReasonStyle, 7> kReasons = {{
    {"below_min_tension", "a cable below the minimum tension", MarkShape::kTriangleDown, true},
    {"above_max_tension", "a cable above the maximum tension", MarkShape::kTriangleUp},
    {"no_equilibrium", "no equilibrium: the cables cannot hold the cabin", MarkShape::kCross},
    {"sagging_cable", "a cable longer than the model's range (s0/k)", MarkShape::kCircle},
    {"overstretched_cable", "a cable strained beyond the model's range", MarkShape::kSquare},
    {"reflector_contact", "a cable through (or too near) the reflector", MarkShape::kDiamond},
    {"", "another solver failure (message in the CSV)", MarkShape::kPlus},
}};

// Index into kReasons of a node that is not feasible.
int ReasonIndex(const WorkspaceNode& node) {
  const std::string code = WorkspaceNodeCode(node);
  for (size_t k = 0; k + 1 < kReasons.size(); ++k) {
    if (code == kReasons[k].code) return static_cast<int>(k);
  }
  return static_cast<int>(kReasons.size()) - 1;
}

std::string LayerName(double offset_m, double radius_m) {
  if (offset_m == 0.0) return "on the focal sphere (R = " + Num(radius_m, 6) + " m)";
  return Num(std::abs(offset_m), 6) + " m " +
         (offset_m < 0.0 ? "inside the sphere, toward its centre" : "outside the sphere") +
         " (R = " + Num(radius_m + offset_m, 6) + " m)";
}

std::string TensionRangeKn(double lo_n, double hi_n) {
  return Num(lo_n / kNPerKn, 4) + " to " + Num(hi_n / kNPerKn, 4) + " kN";
}

std::string LimitKn(double limit_n) {
  return std::isfinite(limit_n) ? Num(limit_n / kNPerKn, 6) + " kN" : "none";
}

// The polar map of one layer: cells centred on the nodes, one grid step wide, coloured on
// the scale [lo_kn, hi_kn] that all layers share.
std::string LayerMap(const WorkspaceMap& map, const CableRobot& robot, double offset_m,
                     double lo_kn, double hi_kn) {
  const FocalGridSpec& grid = map.options.grid;
  std::vector<const WorkspaceNode*> nodes;
  for (const WorkspaceNode& n : map.nodes) {
    if (n.radial_offset_m == offset_m) nodes.push_back(&n);
  }
  const double num_azimuths = std::ceil(360.0 / grid.azimuth_step_deg - 1e-9);
  const double half_ring = 0.5 * grid.off_axis_step_deg;
  const double half_azimuth = 0.5 * std::min(grid.azimuth_step_deg, 360.0 / num_azimuths);
  std::array<int, kReasons.size()> counts{};
  std::vector<PolarCell> cells;
  for (const WorkspaceNode* n : nodes) {
    PolarCell c;
    const bool axis = n->off_axis_deg < 1e-9;
    c.radius_lo = std::max(0.0, n->off_axis_deg - half_ring);
    c.radius_hi = n->off_axis_deg + half_ring;
    c.angle_lo_deg = axis ? 0.0 : n->azimuth_deg - half_azimuth;
    c.angle_hi_deg = axis ? 360.0 : n->azimuth_deg + half_azimuth;
    const bool solved = n->status == StaticsStatus::kOk;
    c.value = solved ? n->min_tension_n / kNPerKn : std::nan("");
    std::string tip = "off-axis " + Num(n->off_axis_deg, 4) + "\u00b0, azimuth " +
                      Num(n->azimuth_deg, 4) + "\u00b0: ";
    if (n->verdict == WorkspaceVerdict::kFeasible) {
      tip += "feasible";
    } else {
      const int k = ReasonIndex(*n);
      ++counts[k];
      c.mark = k;
      tip += n->reason;
    }
    if (solved) {
      tip += "; tensions " + TensionRangeKn(n->min_tension_n, n->max_tension_n) + " (lowest " +
             "cable " + std::to_string(n->min_tension_cable + 1) + ", highest cable " +
             std::to_string(n->max_tension_cable + 1) + ")";
    }
    c.tooltip = tip;
    cells.push_back(c);
  }
  PolarMapOptions o;
  o.plot.title = LayerName(offset_m, grid.focal_radius_m);
  o.plot.width_px = 640;
  o.plot.height_px = 780;
  o.value_lo = lo_kn;
  o.value_hi = hi_kn;
  // The colour is the smallest tension: its limit goes on the colour bar, so that what is
  // below it reads off the scale.
  const double min_kn = map.options.min_tension_n / kNPerKn;
  if (min_kn > 0.0) o.value_marks.push_back({min_kn, "minimum " + Num(min_kn, 4) + " kN"});
  o.radius_label = "off-axis angle [deg] about the focal centre";
  o.value_label = "smallest lower-end cable tension [kN] (grey: no equilibrium in range)";
  o.radius_max = grid.max_off_axis_deg + half_ring;
  // Every reason keeps its mark index; only those present are in the legend.
  for (size_t k = 0; k < kReasons.size(); ++k) {
    o.marks.push_back({counts[k] > 0
                           ? std::string(kReasons[k].label) + " (" + std::to_string(counts[k]) + ")"
                           : "",
                       kReasons[k].shape, kReasons[k].filled});
  }
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d d = robot.cables[i].tower_top_m - grid.focal_centre_m;
    o.rim_labels.push_back({std::atan2(d.y(), d.x()) * 180.0 / M_PI, "T" + std::to_string(i + 1)});
  }
  return SvgPolarMap(cells, o);
}

// Counts per reason (rows) and layer (columns), with the feasible tension range.
std::string CountsTable(const WorkspaceMap& map) {
  std::string h = "<table>\n<thead><tr><th></th>";
  for (double offset_m : map.layers_m) {
    h += "<th>" + XmlEscape(LayerName(offset_m, map.options.grid.focal_radius_m)) + "</th>";
  }
  h += "</tr></thead>\n<tbody>\n";
  auto row = [&](const std::string& label, auto cell) {
    h += "<tr><th>" + XmlEscape(label) + "</th>";
    for (double offset_m : map.layers_m) h += "<td class=\"num\">" + cell(offset_m) + "</td>";
    h += "</tr>\n";
  };
  auto count = [&](double offset_m, auto keep) {
    int n = 0;
    for (const WorkspaceNode& node : map.nodes) n += node.radial_offset_m == offset_m && keep(node);
    return n;
  };
  row("nodes", [&](double m) { return std::to_string(count(m, [](auto&) { return true; })); });
  row("feasible", [&](double m) {
    return std::to_string(
        count(m, [](const WorkspaceNode& n) { return n.verdict == WorkspaceVerdict::kFeasible; }));
  });
  for (size_t k = 0; k < kReasons.size(); ++k) {
    const bool any = std::any_of(map.nodes.begin(), map.nodes.end(), [&](const WorkspaceNode& n) {
      return n.verdict != WorkspaceVerdict::kFeasible && ReasonIndex(n) == static_cast<int>(k);
    });
    if (!any) continue;
    row(kReasons[k].label, [&](double m) {
      return std::to_string(count(m, [&](const WorkspaceNode& n) {
        return n.verdict != WorkspaceVerdict::kFeasible && ReasonIndex(n) == static_cast<int>(k);
      }));
    });
  }
  row("tensions where feasible", [&](double m) {
    double lo = HUGE_VAL, hi = 0.0;
    for (const WorkspaceNode& n : map.nodes) {
      if (n.radial_offset_m != m || n.verdict != WorkspaceVerdict::kFeasible) continue;
      lo = std::min(lo, n.min_tension_n);
      hi = std::max(hi, n.max_tension_n);
    }
    return hi > 0.0 ? TensionRangeKn(lo, hi) : std::string("-");
  });
  return h + "</tbody>\n</table>\n";
}

constexpr char kCss[] = R"(
body { margin: 0; background: #f3f4f6; color: #1c1e22; font: 14px/1.5 Helvetica, Arial, sans-serif; }
main { max-width: 1420px; margin: 0 auto; padding: 20px 28px 40px; background: #fff; }
h1 { font-size: 24px; margin: 6px 0 2px; }
h2 { font-size: 18px; margin: 26px 0 8px; border-bottom: 2px solid #d8dce1; }
p, li { max-width: 960px; }
table { border-collapse: collapse; margin: 6px 0 14px; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #d8dce1; padding: 3px 9px; text-align: left; }
thead th, tbody th { background: #eef0f3; font-weight: 600; }
td.num { text-align: right; white-space: nowrap; }
.maps { display: flex; flex-wrap: wrap; gap: 8px 20px; }
.maps svg { max-width: 100%; height: auto; }
.prov { color: #555; font-size: 12px; overflow-wrap: anywhere; }
)";

}  // namespace

std::string WorkspaceHtml(const WorkspaceMap& map, const CableRobot& robot,
                          const std::string& model_name, const std::string& provenance) {
  const WorkspaceOptions& o = map.options;
  const StaticsOptions& s = o.statics;
  const int feasible = static_cast<int>(std::count_if(
      map.nodes.begin(), map.nodes.end(),
      [](const WorkspaceNode& n) { return n.verdict == WorkspaceVerdict::kFeasible; }));
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>Feasible workspace of the FAST cable robot</title>\n<style>" +
      std::string(kCss) + "</style>\n</head>\n<body>\n<main>\n<h1>Feasible workspace</h1>\n";
  h += "<p><b>" + std::to_string(feasible) + " of " + std::to_string(map.nodes.size()) +
       " nodes feasible</b>: the statics (" + StaticsMethodName(s.method) +
       ") hold the cabin there within the model's range and every cable's lower-end tension "
       "is within the limits below. Model: " +
       XmlEscape(model_name) + ". Attitude: the focal law, tilt fraction " +
       Num(o.attitude_law.tilt_fraction, 6) + ", focal centre (" +
       Num(o.attitude_law.focal_centre_m.x(), 6) + ", " +
       Num(o.attitude_law.focal_centre_m.y(), 6) + ", " +
       Num(o.attitude_law.focal_centre_m.z(), 6) + ") m.</p>\n";
  h += "<h2>Grid and limits</h2>\n<table>\n<tbody>\n";
  auto limit = [&h](const std::string& name, const std::string& value) {
    h += "<tr><th>" + XmlEscape(name) + "</th><td>" + XmlEscape(value) + "</td></tr>\n";
  };
  limit("grid", "focal-sphere cap up to " + Num(o.grid.max_off_axis_deg, 6) +
                    " deg off axis, rings every " + Num(o.grid.off_axis_step_deg, 6) +
                    " deg, azimuths every " + Num(o.grid.azimuth_step_deg, 6) +
                    " deg, sphere radius " + Num(o.grid.focal_radius_m, 6) + " m");
  limit("minimum lower-end tension", LimitKn(o.min_tension_n));
  limit("maximum lower-end tension", LimitKn(o.max_tension_n));
  limit("model range: strain (tension / EA)", "at most " + Num(100.0 * s.max_strain, 6) + "%");
  limit("model range: unstretched length / chord", "at most " + Num(s.max_length_ratio, 6));
  limit("reflector clearance", robot.reflector.has_value()
                                   ? "at least " + Num(s.min_reflector_clearance_m, 6) + " m"
                                   : std::string("not checked: the model has no reflector"));
  h += "</tbody>\n</table>\n<h2>Nodes by reason</h2>\n" + CountsTable(map);
  h += "<h2>Maps</h2>\n<p>Seen from above, x toward tower 1 (T1) to the right, y up; each "
       "cell is a grid node, the rings its off-axis angle. Colour: the smallest of the six "
       "lower-end tensions, the minimum tension marked on its colour bar; grey: no "
       "equilibrium within the model's range. A mark says why a node is not feasible "
       "(legend under each map: a dark ▼ below the minimum tension, a white △ above the "
       "maximum); hover over a cell for its numbers. "
       "The CSV has the same per node, with the cable and the message.</p>\n<div "
       "class=\"maps\">\n";
  double lo_kn = HUGE_VAL, hi_kn = -HUGE_VAL;
  for (const WorkspaceNode& n : map.nodes) {
    if (n.status != StaticsStatus::kOk) continue;
    lo_kn = std::min(lo_kn, n.min_tension_n / kNPerKn);
    hi_kn = std::max(hi_kn, n.min_tension_n / kNPerKn);
  }
  for (double offset_m : map.layers_m) h += LayerMap(map, robot, offset_m, lo_kn, hi_kn) + "\n";
  h += "</div>\n<p class=\"prov\">" + XmlEscape(provenance) + "</p>\n</main>\n</body>\n</html>\n";
  return h;
}

}  // namespace fastcal
