// The FAST cable robot's model parameters: geometry and physical constants.
//
// Geometry (docs/model.md, paper eqs. 1-2): tower tops B_i in the global frame O-xyz
// (x toward tower B1, z up); cabin anchor points in the cabin frame O'-x'y'z'. Cable i
// runs from anchor point anchor_index[i] on the cabin up to tower i. The nominal FAST
// layout is
//   B_i = (r_b cos(pi (i-1)/3), r_b sin(pi (i-1)/3), H),             r_b = 300 m, H = 270 m
//   A_j = r_a (cos(pi/6 + 2 pi j/3), sin(pi/6 + 2 pi j/3), 0),       r_a = 7.5 m, j = 0,1,2
// with cables 1,2 on A_0, 3,4 on A_1 and 5,6 on A_2. The geometry is data: a real
// installation loads its own coordinates from YAML (docs/model-format.md).
//
// Physical parameters (paper Table 1): EA = 1.6e11 Pa * 1.541e-4 m^2 = 2.4656e7 N and the
// unstretched linear density 11.718 kg/m, per cable; cabin mass 30000 kg with its mass
// centre at (0, 0, 0.5) m in the cabin frame; g = -9.8 m/s^2 (negative: z is up).
#ifndef FASTCAL_CABLE_ROBOT_H_
#define FASTCAL_CABLE_ROBOT_H_

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "fastcal/cable_attachment.h"
#include "fastcal/measured_frame.h"
#include "fastcal/moving_parts.h"
#include "fastcal/pose.h"

namespace fastcal {

// FAST has six cables and six degrees of freedom; fixed-size arrays keep the per-pose
// solvers free of allocation.
inline constexpr int kNumCables = 6;

struct CableProperties {
  // Upper end of the cable (tower top, pulley exit), global frame.
  Eigen::Vector3d tower_top_m = Eigen::Vector3d::Zero();
  // Index into CableRobot::anchor_points_cabin_m of the cabin point the cable is tied to.
  int anchor_index = 0;
  // Axial stiffness E*A of the unstretched cross-section.
  double ea_n = 2.4656e7;
  // Mass per unit unstretched length.
  double linear_density_kg_per_m = 11.718;
  // The cable's cabin-side tension sensor: measured = gain * lower-end tension + bias.
  // Identity by default; a calibration may estimate them (YAML keys sensor_gain and
  // sensor_bias_kN, optional).
  double sensor_gain = 1.0;
  double sensor_bias_n = 0.0;
  // The winch's length encoder: measured length = unstretched length s0 + this offset
  // (its zero). 0 by default; a calibration with lengths may estimate it (YAML key
  // length_offset_m, optional).
  double length_offset_m = 0.0;
  // Sensors, connectors and hung lines the cable carries (cable_attachment.h), in the
  // model file's order; none for a uniform cable. At most kMaxAttachmentsPerCable.
  std::vector<CableAttachment> attachments;

  // What this cable's sensor reads when the cable's lower-end tension is `tension_n`
  // (e.g. StaticsSolution's lower_tension_n, which is the true tension).
  double SensorReadingN(double tension_n) const { return sensor_gain * tension_n + sensor_bias_n; }
  // What this cable's encoder reads when its unstretched length is `length_m`.
  double EncoderReadingM(double length_m) const { return length_m + length_offset_m; }
};

// The reflector: the lower cap of a sphere, within a circle of diameter aperture_m seen
// from above (FAST: radius 300 m about (0, 0, 300) m, aperture 500 m; design notes). Only
// used to check that no cable's lowest point passes through it
// (StaticsOptions::min_reflector_clearance_m).
struct Reflector {
  Eigen::Vector3d centre_m = Eigen::Vector3d(0.0, 0.0, 300.0);  // sphere centre, global frame
  double radius_m = 300.0;
  double aperture_m = 500.0;  // in (0, 2 radius_m]
};

struct CableRobot {
  // Cabin anchor points in the cabin frame (several cables may share one).
  std::vector<Eigen::Vector3d> anchor_points_cabin_m;
  std::array<CableProperties, kNumCables> cables;
  double cabin_mass_kg = 30000.0;
  // Mass centre of the cabin in the cabin frame, with every moving part's joints at zero.
  Eigen::Vector3d mass_centre_cabin_m = Eigen::Vector3d(0.0, 0.0, 0.5);
  // The rotator, the Stewart platform: parts whose joints move the mass centre
  // (moving_parts.h); none by default, and then the mass centre is fixed.
  MovingParts moving_parts;
  // Whose pose the data's x_m..z_m and attitude give (measured_frame.h; YAML
  // cabin.measured_frame): a point of a moving part's frame (FAST's feed on the Stewart
  // platform), or of the cabin's. None (the default): the cabin's own frame, and every
  // pose of the data is the cabin's as it stands.
  std::optional<MeasuredFrame> measured_frame;
  // The cabin's inertia tensor about its mass centre, cabin frame (kg m^2; YAML
  // cabin.inertia_kg_m2). Only the vibrations (modes.h) use it. The default is assumed,
  // not measured: diag(3.5e5, 3.5e5, 5.0e5), about a 30 t cabin of ~13 m diameter.
  Eigen::Matrix3d cabin_inertia_kg_m2 = Eigen::Vector3d(3.5e5, 3.5e5, 5.0e5).asDiagonal();
  // Gravitational acceleration along z (negative: z is up).
  double gravity_m_per_s2 = -9.8;
  // Optional model data: FAST's reflector in NominalFast(), none in a default-constructed
  // robot. Without it no cable is checked against the reflector.
  std::optional<Reflector> reflector;

  // The nominal FAST layout and parameters of the paper's Table 1.
  static CableRobot NominalFast();

  // Anchor point of cable i in the cabin frame.
  const Eigen::Vector3d& AnchorOfCable(int i) const {
    return anchor_points_cabin_m[cables[i].anchor_index];
  }

  // The mass centre (cabin frame) at joint values `joints` (the model's joint order, SI):
  // mass_centre_cabin_m plus the parts' shift, eq. (1) of moving_parts.h.
  Eigen::Vector3d MassCentreAt(const JointValues& joints) const;

  // The cabin's pose from the data's (the measured frame's, measured_frame.h (3)-(4)) at
  // `joints` (the model's joint order, columns' units); the pose itself, bit for bit,
  // without a measured frame.
  Pose CabinPose(const Pose& measured, const JointValues& joints) const;
  // The data's pose (the measured frame's) from the cabin's at `joints`: the inverse.
  Pose MeasuredPose(const Pose& cabin, const JointValues& joints) const;

  // Whether any cable carries attachments (the statics then need exact: statics.h).
  bool HasAttachments() const {
    for (const CableProperties& c : cables) {
      if (!c.attachments.empty()) return true;
    }
    return false;
  }

  // Checks physical sense: EA > 0, density > 0, mass > 0, g < 0, finite coordinates,
  // a symmetric positive definite cabin inertia, a measured frame on a part of the model,
  // attachments valid (CableAttachment::IsValid) and at most kMaxAttachmentsPerCable,
  // a reflector (if any) with radius > 0 and aperture in (0, 2 radius], anchor indices in range, no
  // two tower tops coincident, no two distinct anchor points coincident. On failure returns false
  // and names the offending key in *error (YAML key path, e.g. "cables[2].ea_n").
  bool IsValid(std::string* error) const;
};

// Largest model file LoadCableRobot reads: a model is about 2 KiB.
inline constexpr long long kMaxModelFileBytes = 16LL << 20;  // 16 MiB

// Loads a model from YAML (format in docs/model-format.md). Keys that are absent take
// the nominal values, except that a file that gives `cables` must give all six. A file
// with no document (empty, or only comments and white space) is an error: the nominal
// model is CableRobot::NominalFast(), without a file.
// Unknown keys, wrong types and non-physical values are errors; *error then names the
// file, the key and (where yaml-cpp knows it) the line. Only a regular file of at most
// kMaxModelFileBytes is read (a device such as /dev/zero, a pipe or a larger file is
// refused before reading).
bool LoadCableRobot(const std::string& path, CableRobot* robot, std::string* error);
bool ParseCableRobotYaml(const std::string& text, const std::string& source_name, CableRobot* robot,
                         std::string* error);

// Writes the model as YAML in the same format LoadCableRobot reads; values are written
// with 17 significant digits so a save/load round trip is exact. `header_comment` (may be
// empty) is written as leading '#' lines.
std::string CableRobotToYaml(const CableRobot& robot, const std::string& header_comment);
// Writes atomically (temporary file, then rename): a failure leaves no partial file.
bool SaveCableRobot(const CableRobot& robot, const std::string& path,
                    const std::string& header_comment, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_CABLE_ROBOT_H_
