// Cabin trajectories: sequences of cabin positions and poses to evaluate the statics on.
//
// The paper's section 4 scenarios (docs/model.md, "Reference values" and "Measured data"):
//   - straight line G1 (50, 0, 150) m -> G2 (-50, 0, 150) m, 101 nodes   LinePositions
//   - half circle of radius 50 m about (0, 0, 150) m, 0..180 deg, 101 nodes   ArcPositions
//   - measured full circle of radius 71.11 m about (0, 0, 156.73) m   PaperCircleArc
// and the workspace: the lower cap of the focal sphere (radius 160 m about (0, 0, 300) m)
// up to 40 deg off-axis, as a regular grid (FocalSpherePositions) or uniformly sampled
// with optional offsets off the sphere (RandomWorkspacePositions). Positions become poses
// with the focal attitude law (pose.h) or the neutral attitude; recorded poses are read
// from CSV (ReadPosesCsv).
//
// All positions are of the cabin-frame origin O' in the global frame O-xyz (z up), in
// metres; angles in the specs are in degrees. Every function validates its arguments and
// returns false with a message naming the offending parameter in *error (error may be
// null); the output is written only on success.
#ifndef FASTCAL_TRAJECTORY_H_
#define FASTCAL_TRAJECTORY_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/column_map.h"
#include "fastcal/moving_parts.h"
#include "fastcal/pose.h"

namespace fastcal {

// `nodes` evenly spaced points from `from_m` to `to_m`, both ends included (exactly).
// Requires 2 <= nodes <= 1e7 and finite end points; equal end points give a stationary sequence.
bool LinePositions(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m, int nodes,
                   std::vector<Eigen::Vector3d>* positions, std::string* error);

// Horizontal circle or arc at the height of its centre.
struct ArcSpec {
  // Centre of the circle, global frame.
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  // Radius, > 0.
  double radius_m = 0.0;
  // Polar angle of the first and last node, measured from +x toward +y (counter-clockwise
  // seen from above); end_deg < start_deg runs clockwise. 0 < |end_deg - start_deg| <= 360.
  double start_deg = 0.0;
  double end_deg = 360.0;
  // Number of nodes, 2 to 1e7.
  int nodes = 101;
};

// Nodes at angles evenly spaced from start_deg to end_deg, both ends included:
//   p_k = centre + radius (cos a_k, sin a_k, 0).
// A full turn (|end_deg - start_deg| = 360 within 1e-9 deg) does not repeat the start
// node at the end: the `nodes` points are distinct, spaced 360/nodes deg apart.
// Multiple turns are rejected (they would repeat points).
bool ArcPositions(const ArcSpec& spec, std::vector<Eigen::Vector3d>* positions, std::string* error);

// The paper's measured circle (its section 4 and Table 6; docs/model.md, "Measured data"):
// radius 71.11 m about (0, 0, 156.73) m, one full turn from +x, 360 nodes.
ArcSpec PaperCircleArc();

// Recognises the paper's measured circle in a dataset's positions, fed one at a time (a
// file too long to hold is streamed): they fly it when every one lies within
// kToleranceM of the circle (horizontal distance from its axis minus its radius, and
// height) and together they visit every 10-degree sector of the turn. By content, not by
// file name: the report then shows the paper's published Table 6 beside its own, for
// the bundled circle_paper.csv and for any other survey flown on that circle.
class PaperCircleMatcher {
 public:
  static constexpr double kToleranceM = 1.0;
  void Add(const Eigen::Vector3d& position_m);
  bool Matches() const;

 private:
  static constexpr int kSectors = 36;
  long long count_ = 0;
  bool all_near_ = true;
  std::vector<bool> visited_ = std::vector<bool>(kSectors, false);
};

// Positions handed out one at a time, in order, for runs too long to hold (fastcal
// simulate at 10^6 samples: memory independent of their number). `next` gives position
// k on its k-th call, k = 0 .. count - 1, bit for bit the element k of the vector the
// matching *Positions function returns. A copy of the stream starts where the original
// stands (its generator state is copied), so a copy can be drained to check the
// positions before the original is used.
struct PositionStream {
  long long count = 0;
  std::function<Eigen::Vector3d()> next;
};

// Streams of LinePositions, ArcPositions and RandomWorkspacePositions: the same checks and
// messages, the same positions.
bool LinePositionStream(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m, int nodes,
                        PositionStream* stream, std::string* error);
bool ArcPositionStream(const ArcSpec& spec, PositionStream* stream, std::string* error);

// Regular grid on the lower cap of the focal sphere.
struct FocalGridSpec {
  // Largest off-axis angle theta (angle at the focal centre from the downward vertical),
  // in [0, 90].
  double max_off_axis_deg = 40.0;
  // Spacing of the off-axis rings, > 0.
  double off_axis_step_deg = 5.0;
  // Spacing of the azimuths on each ring, in (0, 360].
  double azimuth_step_deg = 15.0;
  // Centre and radius of the focal sphere, global frame.
  Eigen::Vector3d focal_centre_m = Eigen::Vector3d(0.0, 0.0, 300.0);
  double focal_radius_m = 160.0;
};

// Points C + R (sin(theta) cos(phi), sin(theta) sin(phi), -cos(theta)) with C, R the focal
// centre and radius, for theta = 0, step, 2 step, ... <= max_off_axis_deg (max included
// when it is a multiple of the step within 1e-9) and, for theta > 0, azimuths
// phi = 0, azimuth_step, ... < 360 deg measured from +x toward +y. The axis point
// (theta = 0) comes first and only once; then ring by ring, azimuth by azimuth.
// The defaults give 1 + 8 * 24 = 193 points.
bool FocalSpherePositions(const FocalGridSpec& spec, std::vector<Eigen::Vector3d>* positions,
                          std::string* error);
// Off-axis angle and azimuth (deg, azimuth in [0, 360)) of `position_m` about the focal
// centre: the grid's own coordinates, recovered from its positions.
void FocalGridAngles(const Eigen::Vector3d& position_m, const Eigen::Vector3d& centre_m,
                     double* off_axis_deg, double* azimuth_deg);

// Random positions spread uniformly over the area of the focal sphere's lower cap.
struct RandomWorkspaceSpec {
  // Number of positions, 1 to 1e7.
  int samples = 100;
  // Largest off-axis angle, in [0, 90]; sphere.max_off_axis_deg is not used.
  double max_off_axis_deg = 40.0;
  // Each position is moved along the sphere's outward normal (away from the centre, so
  // downward near the axis) by an offset uniform in [-spread, spread]. In [0, radius).
  double radial_spread_m = 0.0;
  // Only focal_centre_m and focal_radius_m are used.
  FocalGridSpec sphere;
  // Seed of the std::mt19937_64 generator: the same spec gives the same positions on
  // every platform (raw generator output is converted without std distributions).
  std::uint64_t seed = 0;
};

// Per sample: cos(theta) uniform in [cos(max_off_axis), 1], azimuth uniform in [0, 360),
// radial offset uniform in [-spread, spread] (drawn even when spread = 0, so the spread
// changes only the offsets, not the directions). Returns `samples` positions.
bool RandomWorkspacePositions(const RandomWorkspaceSpec& spec,
                              std::vector<Eigen::Vector3d>* positions, std::string* error);

bool RandomWorkspacePositionStream(const RandomWorkspaceSpec& spec, PositionStream* stream,
                                   std::string* error);

// Poses at `positions` with the attitude of the focal attitude law (FocalAttitude, pose.h).
// Positions must be finite and strictly below the focal centre (the law is defined for
// the lower half space only); the law's fields must be finite. Empty input is allowed.
bool PosesWithAttitudeLaw(const std::vector<Eigen::Vector3d>& positions,
                          const FocalAttitudeLaw& law, std::vector<Pose>* poses,
                          std::string* error);

// Random poses around the focal attitude law, for sweeps of the workspace's edge (issue 9's:
// 45 deg off axis, +-5 m, 2 to 5 deg): positions as RandomWorkspacePositions(positions),
// each attitude the focal law's times an extra rotation Rz(c) Ry(b) Rx(a), whose amplitude
// A is drawn per pose uniform in [min_extra_rotation_deg, max_extra_rotation_deg] and a, b,
// c uniform in [-A, A]. The rotations come from a second generator seeded with
// positions.seed + 1, so the positions are RandomWorkspacePositions' own; the same spec
// gives the same poses on every platform.
// Sources tracked across the sky at the sidereal rate, as the telescope observes: the
// feed follows each source's focal point on the focal sphere, F = C - R s(t), s the unit
// vector to the source, turning about the celestial pole p = (0, cos(lat), sin(lat)) (the
// y axis taken as north) at omega = 2 pi / 86164.0905 s^-1 (a sidereal day): 11.7 mm/s at
// R = 160 m on the equator, less toward the pole. Each source is drawn uniformly over the
// cap (cos(theta) and azimuth uniform) and tracked for a time uniform in [min_track_s,
// max_track_s], or until it leaves the cap (a source whose path leaves it sooner than
// min_track_s is drawn again, up to 100 times); then the next, at once (the slew between
// them is not sampled). With days > 0 the samples are cut into days as a season's
// sessions are (sample n is in day floor(n days / samples)) and each day starts a source.
struct SourceTrackSpec {
  int samples = 3600;                                 // 1 to 1e7
  double interval_s = 1.0;                            // between samples, > 0
  double min_track_s = 1200.0, max_track_s = 3600.0;  // 0 < min <= max
  double max_off_axis_deg = 40.0;                     // (0, 90)
  double latitude_deg = 25.647;                       // FAST's site; [-90, 90]
  int days = 0;                                       // >= 0
  FocalGridSpec sphere;                               // focal_centre_m and focal_radius_m
  std::uint64_t seed = 0;
};
bool SourceTrackPositionStream(const SourceTrackSpec& spec, PositionStream* stream,
                               std::string* error);

struct RandomPoseSpec {
  RandomWorkspaceSpec positions;
  FocalAttitudeLaw law;
  double min_extra_rotation_deg = 2.0;  // 0 <= min <= max, finite
  double max_extra_rotation_deg = 5.0;
};
bool RandomPosesAroundFocalLaw(const RandomPoseSpec& spec, std::vector<Pose>* poses,
                               std::string* error);

// The sweep of the workspace's edge of issue 9: `samples` poses up to 45 deg off axis,
// +-5 m off the focal sphere, extra rotations of 2 to 5 deg per axis, `seed`; the other
// fields at their defaults (the paper's focal law and sphere).
RandomPoseSpec EdgeSweepSpec(int samples, std::uint64_t seed);

// Poses at finite `positions` with the neutral attitude R = I.
bool PosesWithIdentityAttitude(const std::vector<Eigen::Vector3d>& positions,
                               std::vector<Pose>* poses, std::string* error);

// Reads cabin poses from a CSV file.
//
// Format: plain comma-separated values without quoting; lines that are blank or whose
// first non-blank character is '#' are skipped. The first other line is the header;
// columns are found by (case-sensitive) name in any order and fields are trimmed of
// spaces and tabs. Columns:
//   x_m, y_m, z_m               position of O' in the global frame, required
//   roll_deg, pitch_deg, yaw_deg   attitude, R = RotationFromRpyDeg(roll, pitch, yaw)
//   qw, qx, qy, qz              or attitude as a unit quaternion (RotationFromQuaternion)
//   time_s                      optional time stamp
// At most one attitude kind, complete; none means R = I. The other columns of a
// measurement dataset (planned_roll_deg, planned_pitch_deg, planned_yaw_deg, T1_kN..T6_kN,
// s0_1_m..s0_6_m; dataset.h) are accepted and not used, so a dataset CSV also serves as a
// pose file. Any other column name (a misspelt "roll" for "roll_deg" would otherwise turn
// the attitude silently into R = I), or an empty one, is an error naming the 1-based
// column number and listing the accepted names:
//   "<path>:<line>: column <n> '<name>': unknown column name (accepted: x_m, ...)".
// Every data row must have as many fields as the header; every used field must be a finite
// decimal number ('.' as the decimal point whatever the locale; no hexadecimal; the whole
// field consumed), and positions and angles within the default PlausibilityLimits
// (plausibility.h), as in a dataset. There must be at least one data row.
//
// Errors read "<path>:<line>: column '<name>': <what>" (line 1-based in the file).
// `times_s` may be null; otherwise it receives one time per pose, or is left empty when
// the file has no time_s column. Times are not checked for order.
// Only a regular file of at most kMaxPoseFileBytes is read (a device, pipe or larger file
// is refused before reading).
bool ReadPosesCsv(const std::string& path, std::vector<Pose>* poses, std::vector<double>* times_s,
                  std::string* error);
// Same, from the file's text; `source_name` stands for the file name in messages.
bool ParsePosesCsv(const std::string& text, const std::string& source_name,
                   std::vector<Pose>* poses, std::vector<double>* times_s, std::string* error);
// The same, an export read through a column map (column_map.h): x_m, y_m, z_m, the
// attitude (roll/pitch/yaw or the quaternion) and the time as the map names and converts
// them; its other entries (tensions, planned attitude) are not read. Messages name the
// source column and the fastcal name; a map without x, y, z names the map's key and line.
bool ReadPosesCsv(const std::string& path, const ColumnMap& columns, std::vector<Pose>* poses,
                  std::vector<double>* times_s, std::string* error);
bool ParsePosesCsv(const std::string& text, const std::string& source_name,
                   const ColumnMap& columns, std::vector<Pose>* poses, std::vector<double>* times_s,
                   std::string* error);

// The same with the moving parts' joint columns of a model (MovingParts::JointColumns(),
// in the columns' units, deg or m): the file gives all of them or none. *joints receives
// one JointValues per pose (the model's joint order) when it gives them, and is left empty
// when it gives none (the command's flag or law sets the joints then); some but not all is
// an error naming the missing ones. A value outside PlausibleJointValue is an error naming
// the column.
bool ReadPosesCsv(const std::string& path, const std::vector<std::string>& joint_columns,
                  std::vector<Pose>* poses, std::vector<JointValues>* joints,
                  std::vector<double>* times_s, std::string* error);
// The same through a column map, which names the joint columns as any quantity (in deg or
// rad, m, cm or mm): all of the model's joints or none.
bool ReadPosesCsv(const std::string& path, const ColumnMap& columns,
                  const std::vector<std::string>& joint_columns, std::vector<Pose>* poses,
                  std::vector<JointValues>* joints, std::vector<double>* times_s,
                  std::string* error);
bool ParsePosesCsv(const std::string& text, const std::string& source_name,
                   const std::vector<std::string>& joint_columns, std::vector<Pose>* poses,
                   std::vector<JointValues>* joints, std::vector<double>* times_s,
                   std::string* error);

// Largest pose file ReadPosesCsv reads, as for a dataset (DatasetReadOptions).
inline constexpr long long kMaxPoseFileBytes = 1LL << 30;  // 1 GiB

}  // namespace fastcal

#endif  // FASTCAL_TRAJECTORY_H_
