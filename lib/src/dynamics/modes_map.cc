// The modes over the focal-sphere cap (modes_map.h): ComputeModes at each grid node,
// reduced to the figures of a map, and their CSV.
#include "fastcal/modes_map.h"

#include <sstream>
#include <string>
#include <vector>

#include "fastcal/internal/csv.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

std::string Num(double value) {
  return value == 0.0 ? std::string("0") : internal::FormatDouble("%.10g", value);
}

// The figures of one node from its modes (ascending).
void Summarise(const ModesResult& result, ModesMapNode* node) {
  const Mode& lowest = result.modes.front();
  node->lowest_hz = lowest.frequency_hz;
  node->lowest_cabin_share = lowest.CabinShare();
  for (size_t i = 0; i < result.modes.size(); ++i) {
    const Mode& m = result.modes[i];
    if (node->first_cabin_mode == 0 && m.CabinShare() > 0.5) {
      node->first_cabin_mode = static_cast<int>(i) + 1;
      node->first_cabin_hz = m.frequency_hz;
    }
    for (int k = 0; k < kCabinMotions; ++k) {
      const double share = k < 3 ? m.cabin_translation_share[k] : m.cabin_rotation_share[k - 3];
      if (share > node->motion_share[k]) {
        node->motion_share[k] = share;
        node->motion_hz[k] = m.frequency_hz;
      }
    }
  }
}

}  // namespace

bool ModesMapOptions::IsValid(std::string* error) const {
  std::vector<Eigen::Vector3d> positions;
  std::string why;
  if (!FocalSpherePositions(grid, &positions, &why)) {
    *error = "grid." + why;
    return false;
  }
  if (!attitude_law.focal_centre_m.allFinite() ||
      !(attitude_law.tilt_fraction >= 0.0 && attitude_law.tilt_fraction <= 1.0)) {
    *error = "attitude_law.tilt_fraction must be in [0, 1] and its centre finite";
    return false;
  }
  if (!modes.IsValid(&why)) {
    *error = "modes." + why;
    return false;
  }
  return true;
}

bool ComputeModesMap(const CableRobot& robot, const ModesMapOptions& options, ModesMap* map,
                     std::string* error) {
  if (!options.IsValid(error)) return false;
  if (!robot.IsValid(error)) {
    *error = "model: " + *error;
    return false;
  }
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  if (!FocalSpherePositions(options.grid, &positions, error) ||
      !PosesWithAttitudeLaw(positions, options.attitude_law, &poses, error)) {
    return false;
  }
  ModesMap out;
  out.options = options;
  for (const Pose& pose : poses) {
    ModesMapNode node;
    node.pose = pose;
    FocalGridAngles(pose.position_m, options.grid.focal_centre_m, &node.off_axis_deg,
                    &node.azimuth_deg);
    ModesResult result;
    node.ok =
        ComputeModes(robot, pose, options.modes, &result, &node.reason) && !result.modes.empty();
    if (node.ok) {
      node.reason.clear();
      Summarise(result, &node);
    }
    out.nodes.push_back(node);
  }
  *map = std::move(out);
  return true;
}

std::string ModesMapCsv(const ModesMap& map) {
  const char* kMotions[] = {"x", "y", "z", "rx", "ry", "rz"};
  std::ostringstream out;
  out << "off_axis_deg,azimuth_deg,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,status,lowest_hz,"
         "lowest_cabin_share,first_cabin_mode,first_cabin_hz";
  for (const char* m : kMotions) out << "," << m << "_hz," << m << "_share";
  out << ",message\n";
  for (const ModesMapNode& n : map.nodes) {
    const Eigen::Vector3d rpy = RpyDegFromRotation(n.pose.rotation);
    out << Num(n.off_axis_deg) << "," << Num(n.azimuth_deg);
    for (int k = 0; k < 3; ++k) out << "," << Num(n.pose.position_m[k]);
    for (int k = 0; k < 3; ++k) out << "," << Num(rpy[k]);
    out << "," << (n.ok ? "ok" : "no_modes");
    if (n.ok) {
      const bool cabin = n.first_cabin_mode > 0;
      out << "," << Num(n.lowest_hz) << "," << Num(n.lowest_cabin_share) << ","
          << (cabin ? std::to_string(n.first_cabin_mode) : std::string()) << ","
          << (cabin ? Num(n.first_cabin_hz) : std::string());
      for (int k = 0; k < kCabinMotions; ++k) {
        out << "," << Num(n.motion_hz[k]) << "," << Num(n.motion_share[k]);
      }
    } else {
      out << std::string(4 + 2 * kCabinMotions, ',');
    }
    out << "," << internal::QuotedCsvField(n.reason) << "\n";
  }
  return out.str();
}

}  // namespace fastcal
