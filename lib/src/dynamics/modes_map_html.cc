// The HTML page of the modes over the cap (modes_map.h): polar maps drawn as the
// workspace's (workspace_html.cc), one per figure.
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/internal/number_text.h"
#include "fastcal/modes_map.h"
#include "fastcal/svg_plot.h"

namespace fastcal {
namespace {

std::string Num(double value, int digits) {
  return internal::FormatDouble("%." + std::to_string(digits) + "g", value);
}

// One polar map of the cap: each node a cell one grid step wide, coloured by `value` (NaN:
// grey), with `tip` on hover.
std::string CapMap(const ModesMap& map, const CableRobot& robot, const std::string& title,
                   const std::string& value_label,
                   const std::function<double(const ModesMapNode&)>& value) {
  const FocalGridSpec& grid = map.options.grid;
  const double num_azimuths = std::ceil(360.0 / grid.azimuth_step_deg - 1e-9);
  const double half_ring = 0.5 * grid.off_axis_step_deg;
  const double half_azimuth = 0.5 * std::min(grid.azimuth_step_deg, 360.0 / num_azimuths);
  std::vector<PolarCell> cells;
  for (const ModesMapNode& n : map.nodes) {
    PolarCell c;
    const bool axis = n.off_axis_deg < 1e-9;
    c.radius_lo = std::max(0.0, n.off_axis_deg - half_ring);
    c.radius_hi = n.off_axis_deg + half_ring;
    c.angle_lo_deg = axis ? 0.0 : n.azimuth_deg - half_azimuth;
    c.angle_hi_deg = axis ? 360.0 : n.azimuth_deg + half_azimuth;
    c.value = n.ok ? value(n) : std::nan("");
    c.tooltip =
        "off-axis " + Num(n.off_axis_deg, 4) + "\u00b0, azimuth " + Num(n.azimuth_deg, 4) +
        "\u00b0: " +
        (n.ok ? "lowest " + Num(n.lowest_hz, 5) + " Hz (cabin " +
                    Num(100 * n.lowest_cabin_share, 3) + "%), first cabin-dominated " +
                    (n.first_cabin_mode > 0 ? Num(n.first_cabin_hz, 5) + " Hz"
                                            : std::string("none")) +
                    ", vertical " + Num(n.motion_hz[2], 5) + " Hz (" +
                    Num(100 * n.motion_share[2], 3) + "% of its energy vertical" +
                    (n.motion_share[2] < 0.5 ? ": under half, no single vertical mode" : "") + ")"
              : n.reason);
    cells.push_back(c);
  }
  PolarMapOptions o;
  o.plot.title = title;
  o.plot.width_px = 520;
  o.plot.height_px = 640;
  o.radius_label = "off-axis angle [deg] about the focal centre";
  o.value_label = value_label;
  o.radius_max = grid.max_off_axis_deg + half_ring;
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d d = robot.cables[i].tower_top_m - grid.focal_centre_m;
    o.rim_labels.push_back({std::atan2(d.y(), d.x()) * 180.0 / M_PI, "T" + std::to_string(i + 1)});
  }
  return SvgPolarMap(cells, o);
}

constexpr char kCss[] = R"(
body { margin: 0; background: #f3f4f6; color: #1c1e22; font: 14px/1.5 Helvetica, Arial, sans-serif; }
main { max-width: 1700px; margin: 0 auto; padding: 20px 28px 40px; background: #fff; }
h1 { font-size: 24px; margin: 6px 0 2px; }
h2 { font-size: 18px; margin: 26px 0 8px; border-bottom: 2px solid #d8dce1; }
p { max-width: 960px; }
.maps { display: flex; flex-wrap: wrap; gap: 8px 20px; }
.maps svg { max-width: 100%; height: auto; }
.prov { color: #555; font-size: 12px; overflow-wrap: anywhere; }
)";

}  // namespace

std::string ModesMapHtml(const ModesMap& map, const CableRobot& robot,
                         const std::string& model_name, const std::string& provenance) {
  const ModesMapOptions& o = map.options;
  int ok = 0;
  for (const ModesMapNode& n : map.nodes) ok += n.ok;
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>Natural frequencies of the FAST cable robot over the cap</title>\n<style>" +
      std::string(kCss) +
      "</style>\n</head>\n<body>\n<main>\n<h1>Natural frequencies over the cap</h1>\n";
  h += "<p><b>" + std::to_string(ok) + " of " + std::to_string(map.nodes.size()) +
       " nodes</b> with modes: the system linearised about the exact equilibrium at each node "
       "(docs/model.md, \"Vibrations\"), each cable a chain of " +
       std::to_string(o.modes.segments) + " segments, the " + std::to_string(o.modes.modes) +
       " lowest modes searched. Model: " + XmlEscape(model_name) +
       ". Attitude: the focal law, tilt fraction " + Num(o.attitude_law.tilt_fraction, 6) +
       ". Grid: the focal-sphere cap up to " + Num(o.grid.max_off_axis_deg, 6) +
       " deg off axis, rings every " + Num(o.grid.off_axis_step_deg, 6) + " deg, azimuths every " +
       Num(o.grid.azimuth_step_deg, 6) + " deg, sphere radius " + Num(o.grid.focal_radius_m, 6) +
       " m.</p>\n";
  h += "<h2>Maps</h2>\n<p>Seen from above, x toward tower 1 (T1) to the right, y up; each "
       "cell a grid node, the rings its off-axis angle. Left: the lowest frequency. Middle: "
       "the first mode in which the cabin holds over half the kinetic energy (grey: none "
       "among the modes searched). Right: the mode with the most vertical motion of the "
       "cabin (its bounce). Hover over a cell for its numbers; the CSV has every cabin "
       "motion's mode.</p>\n";
  // Issue 59: where no mode is mostly vertical, the right map's mode changes between
  // neighbouring nodes; say how often.
  int split = 0;
  for (const ModesMapNode& n : map.nodes) split += n.ok && n.motion_share[2] < 0.5;
  if (split > 0) {
    h += "<p>At " + std::to_string(split) + " of " + std::to_string(ok) +
         " nodes no mode holds over half its kinetic energy in the cabin's vertical motion: the "
         "bounce is shared by neighbouring modes, and the right map shows the one with the "
         "largest share (z_share in the CSV), which can change from node to node.</p>\n";
  }
  h += "<div class=\"maps\">\n";
  h += CapMap(map, robot, "Lowest frequency", "f [Hz]",
              [](const ModesMapNode& n) { return n.lowest_hz; }) +
       "\n";
  h += CapMap(map, robot, "First cabin-dominated mode", "f [Hz] (grey: none)",
              [](const ModesMapNode& n) {
                return n.first_cabin_mode > 0 ? n.first_cabin_hz : std::nan("");
              }) +
       "\n";
  h += CapMap(map, robot, "The cabin's vertical mode", "f [Hz]",
              [](const ModesMapNode& n) { return n.motion_hz[2]; }) +
       "\n";
  h += "</div>\n<p class=\"prov\">" + XmlEscape(provenance) + "</p>\n</main>\n</body>\n</html>\n";
  return h;
}

}  // namespace fastcal
