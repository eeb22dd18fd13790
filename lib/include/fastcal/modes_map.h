// The vibrations over the workspace: the modes (modes.h) at every node of a grid on the
// focal-sphere cap at the focal attitude law, reduced to the figures a map shows: the
// lowest frequency, the first cabin-dominated mode, and where each of the cabin's six
// motions lives (the mode holding the most of it). CSV and an HTML map, as the workspace
// map draws tensions (workspace.h).
#ifndef FASTCAL_MODES_MAP_H_
#define FASTCAL_MODES_MAP_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/modes.h"
#include "fastcal/pose.h"
#include "fastcal/trajectory.h"

namespace fastcal {

struct ModesMapOptions {
  // The cap: 40 deg, rings every 5 deg, azimuths every 15 deg: 193 nodes.
  FocalGridSpec grid;
  FocalAttitudeLaw attitude_law;
  // At each node (its `modes` lowest are searched for the cabin's motions).
  ModesOptions modes;

  bool IsValid(std::string* error) const;
};

// The cabin's six motions in the order of the shares: translation of its mass centre
// along x, y, z, rotation about x, y, z (global axes).
inline constexpr int kCabinMotions = 6;

struct ModesMapNode {
  double off_axis_deg = 0.0;
  double azimuth_deg = 0.0;
  Pose pose;
  bool ok = false;     // false: no modes here (no equilibrium, unstable), `reason` says why
  std::string reason;  // "" when ok
  double lowest_hz = 0.0;
  double lowest_cabin_share = 0.0;
  // The first mode whose kinetic energy is over half the cabin's (1-based), and its
  // frequency; 0 and 0 when none of the computed modes is.
  int first_cabin_mode = 0;
  double first_cabin_hz = 0.0;
  // For each cabin motion, the computed mode holding the largest share of it: its
  // frequency and that share.
  std::array<double, kCabinMotions> motion_hz{};
  std::array<double, kCabinMotions> motion_share{};
};

struct ModesMap {
  ModesMapOptions options;
  std::vector<ModesMapNode> nodes;  // the grid's order: the axis, then ring by ring
};

// The modes at every node. A node without modes is recorded with its reason, not an
// error; false with *error only for invalid options or model.
bool ComputeModesMap(const CableRobot& robot, const ModesMapOptions& options, ModesMap* map,
                     std::string* error);

// One row per node: off_axis_deg, azimuth_deg, x_m, y_m, z_m, roll_deg, pitch_deg,
// yaw_deg, status (ok or no_modes), lowest_hz, lowest_cabin_share, first_cabin_mode,
// first_cabin_hz (empty when none), x_hz, x_share, y_hz, ..., rz_hz, rz_share, message.
std::string ModesMapCsv(const ModesMap& map);

// A self-contained page: the grid and the model, and polar maps of the lowest frequency,
// the first cabin-dominated one and the cabin's vertical (z) mode.
std::string ModesMapHtml(const ModesMap& map, const CableRobot& robot,
                         const std::string& model_name, const std::string& provenance);

}  // namespace fastcal

#endif  // FASTCAL_MODES_MAP_H_
