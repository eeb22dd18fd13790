// Cabin trajectories (line, arc, focal-sphere grid, random workspace), poses from them,
// and the pose CSV reader (conventions: trajectory.h).
#include "fastcal/trajectory.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string_view>

#include "fastcal/cable_robot.h"
#include "fastcal/column_map.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/column_reading.h"
#include "fastcal/internal/csv.h"
#include "fastcal/internal/fail.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/plausibility.h"

namespace fastcal {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Tolerance, in degrees or in steps, when deciding whether an angle is a whole turn or a
// whole number of steps.
constexpr double kAngleTolerance = 1e-9;
// Most positions one trajectory builds (grid, line, arc, random): guards against a step
// or a count typed too large, which would exhaust memory (1e7 poses solve in ~15 s).
constexpr double kMaxGridPositions = 1e7;
constexpr int kMaxPositions = 10000000;

std::string TooMany(const std::string& what, int count) {
  return what + " must be at most " + std::to_string(kMaxPositions) + " (got " +
         std::to_string(count) + ")";
}

using internal::Fail;

std::string Num(double value) { return internal::FormatDouble("%g", value); }

bool IsPositiveFinite(double value) { return std::isfinite(value) && value > 0.0; }

// Validates a sphere given by centre and radius; `prefix` names the struct member.
bool CheckSphere(const FocalGridSpec& sphere, const std::string& prefix, std::string* error) {
  if (!sphere.focal_centre_m.allFinite()) {
    return Fail(error, prefix + "focal_centre_m must be finite");
  }
  if (!IsPositiveFinite(sphere.focal_radius_m)) {
    return Fail(error, prefix + "focal_radius_m must be > 0 and finite (got " +
                           Num(sphere.focal_radius_m) + ")");
  }
  return true;
}

// A stream's sample count: 1 to kMaxPositions.
bool CheckSamples(int samples, std::string* error) {
  if (samples > kMaxPositions) return Fail(error, TooMany("samples", samples));
  if (samples < 1) {
    return Fail(error, "samples must be >= 1 (got " + std::to_string(samples) + ")");
  }
  return true;
}

bool CheckMaxOffAxis(double max_off_axis_deg, std::string* error) {
  if (!(std::isfinite(max_off_axis_deg) && max_off_axis_deg >= 0.0 && max_off_axis_deg <= 90.0)) {
    return Fail(error, "max_off_axis_deg must be in [0, 90] (got " + Num(max_off_axis_deg) + ")");
  }
  return true;
}

// Point of the focal sphere at off-axis angle theta and azimuth phi, at distance
// `distance_m` from the centre.
Eigen::Vector3d OnSphere(const Eigen::Vector3d& centre_m, double distance_m, double cos_theta,
                         double sin_theta, double phi_rad) {
  return centre_m + distance_m * Eigen::Vector3d(sin_theta * std::cos(phi_rad),
                                                 sin_theta * std::sin(phi_rad), -cos_theta);
}

// Uniform in [0, 1) from the raw 64-bit output: the same on every standard library.
double Uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// The rest of a stream, as a vector (the *Positions functions). Always true.
bool Drain(PositionStream* stream, std::vector<Eigen::Vector3d>* positions) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(static_cast<size_t>(stream->count));
  for (long long k = 0; k < stream->count; ++k) out.push_back(stream->next());
  *positions = std::move(out);
  return true;
}

bool CheckPositions(const std::vector<Eigen::Vector3d>& positions, std::string* error) {
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!positions[i].allFinite()) {
      return Fail(error, "positions[" + std::to_string(i) + "] must be finite");
    }
  }
  return true;
}

// ---- CSV ----

std::string_view Trim(std::string_view s) {
  const size_t begin = s.find_first_not_of(" \t");
  if (begin == std::string_view::npos) return {};
  const size_t end = s.find_last_not_of(" \t");
  return s.substr(begin, end - begin + 1);
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      fields.push_back(Trim(line.substr(start)));
      return fields;
    }
    fields.push_back(Trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

// Parses a trimmed field as every fastcal file does (internal::ParseFiniteDecimal: decimal,
// '.' in every locale, finite); on failure *why says what is wrong with it.
bool ParseNumber(std::string_view field, double* value, std::string* why) {
  return internal::ParseFiniteDecimal(field, value, why);
}

enum Column { kX, kY, kZ, kRoll, kPitch, kYaw, kQw, kQx, kQy, kQz, kTime, kNumColumns };
constexpr std::array<const char*, kNumColumns> kColumnNames = {
    "x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg", "qw", "qx", "qy", "qz", "time_s"};

// The other columns of a measurement dataset (docs/data-format.md): accepted in a pose
// file and not used, so that a dataset doubles as a pose file.
std::vector<std::string> IgnoredDatasetColumns() {
  std::vector<std::string> names = {"planned_roll_deg", "planned_pitch_deg", "planned_yaw_deg"};
  for (int i = 1; i <= kNumCables; ++i) names.push_back("T" + std::to_string(i) + "_kN");
  for (int i = 1; i <= kNumCables; ++i) names.push_back("s0_" + std::to_string(i) + "_m");
  return names;
}

std::string AcceptedColumns() {
  std::string list;
  for (const char* name : kColumnNames) list += (list.empty() ? "" : ", ") + std::string(name);
  const std::string n = std::to_string(kNumCables);
  return list +
         "; and, not used, the dataset columns planned_roll_deg, planned_pitch_deg, "
         "planned_yaw_deg, T1_kN..T" +
         n + "_kN, s0_1_m..s0_" + n + "_m";
}

bool IsSkipped(std::string_view line) {
  const std::string_view trimmed = Trim(line);
  return trimmed.empty() || trimmed.front() == '#';
}

}  // namespace

bool LinePositionStream(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m, int nodes,
                        PositionStream* stream, std::string* error) {
  if (stream == nullptr) return Fail(error, "positions must not be null");
  if (nodes < 2) return Fail(error, "nodes must be >= 2 (got " + std::to_string(nodes) + ")");
  if (nodes > kMaxPositions) return Fail(error, TooMany("nodes", nodes));
  if (!from_m.allFinite()) return Fail(error, "from_m must be finite");
  if (!to_m.allFinite()) return Fail(error, "to_m must be finite");
  stream->count = nodes;
  stream->next = [from_m, to_m, nodes, k = 0]() mutable {
    const double t = static_cast<double>(k++) / (nodes - 1);  // t = 1 exactly at the end
    return Eigen::Vector3d((1.0 - t) * from_m + t * to_m);
  };
  return true;
}

bool LinePositions(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m, int nodes,
                   std::vector<Eigen::Vector3d>* positions, std::string* error) {
  if (positions == nullptr) return Fail(error, "positions must not be null");
  PositionStream stream;
  return LinePositionStream(from_m, to_m, nodes, &stream, error) && Drain(&stream, positions);
}

bool ArcPositionStream(const ArcSpec& spec, PositionStream* stream, std::string* error) {
  if (stream == nullptr) return Fail(error, "positions must not be null");
  if (!spec.centre_m.allFinite()) return Fail(error, "centre_m must be finite");
  if (!IsPositiveFinite(spec.radius_m)) {
    return Fail(error, "radius_m must be > 0 and finite (got " + Num(spec.radius_m) + ")");
  }
  if (!std::isfinite(spec.start_deg)) return Fail(error, "start_deg must be finite");
  if (!std::isfinite(spec.end_deg)) return Fail(error, "end_deg must be finite");
  if (spec.nodes > kMaxPositions) return Fail(error, TooMany("nodes", spec.nodes));
  if (spec.nodes < 2) {
    return Fail(error, "nodes must be >= 2 (got " + std::to_string(spec.nodes) + ")");
  }
  const double span_deg = spec.end_deg - spec.start_deg;
  if (span_deg == 0.0) return Fail(error, "end_deg must differ from start_deg");
  const bool full_turn = std::abs(std::abs(span_deg) - 360.0) <= kAngleTolerance;
  if (std::abs(span_deg) > 360.0 && !full_turn) {
    return Fail(error,
                "|end_deg - start_deg| must be <= 360 (got " + Num(std::abs(span_deg)) + ")");
  }
  // A full turn divides into `nodes` steps so the end node (= start) is left out.
  const int steps = full_turn ? spec.nodes : spec.nodes - 1;
  stream->count = spec.nodes;
  stream->next = [spec, span_deg, steps, k = 0]() mutable {
    const double angle_rad = (spec.start_deg + span_deg * k++ / steps) * kDegToRad;
    return Eigen::Vector3d(spec.centre_m + spec.radius_m * Eigen::Vector3d(std::cos(angle_rad),
                                                                           std::sin(angle_rad),
                                                                           0.0));
  };
  return true;
}

bool ArcPositions(const ArcSpec& spec, std::vector<Eigen::Vector3d>* positions,
                  std::string* error) {
  if (positions == nullptr) return Fail(error, "positions must not be null");
  PositionStream stream;
  return ArcPositionStream(spec, &stream, error) && Drain(&stream, positions);
}

ArcSpec PaperCircleArc() {
  ArcSpec circle;
  circle.centre_m = Eigen::Vector3d(0.0, 0.0, 156.73);
  circle.radius_m = 71.11;
  circle.start_deg = 0.0;
  circle.end_deg = 360.0;
  circle.nodes = 360;
  return circle;
}

void PaperCircleMatcher::Add(const Eigen::Vector3d& position_m) {
  static const ArcSpec circle = PaperCircleArc();
  const Eigen::Vector3d d = position_m - circle.centre_m;
  const double off_m = std::hypot(d.x(), d.y()) - circle.radius_m;
  all_near_ = all_near_ && std::abs(off_m) <= kToleranceM && std::abs(d.z()) <= kToleranceM;
  const double azimuth_deg = std::atan2(d.y(), d.x()) * 180.0 / M_PI;  // (-180, 180]
  const int sector = static_cast<int>(std::floor((azimuth_deg + 180.0) / (360.0 / kSectors)));
  visited_[std::clamp(sector, 0, kSectors - 1)] = true;
  ++count_;
}

bool PaperCircleMatcher::Matches() const {
  return count_ > 0 && all_near_ &&
         std::all_of(visited_.begin(), visited_.end(), [](bool v) { return v; });
}

void FocalGridAngles(const Eigen::Vector3d& position_m, const Eigen::Vector3d& centre_m,
                     double* off_axis_deg, double* azimuth_deg) {
  const Eigen::Vector3d d = position_m - centre_m;
  *off_axis_deg = std::atan2(d.head<2>().norm(), -d.z()) * 180.0 / M_PI;
  *azimuth_deg = d.head<2>().norm() > 0.0 ? std::atan2(d.y(), d.x()) * 180.0 / M_PI : 0.0;
  if (*azimuth_deg < 0.0) *azimuth_deg += 360.0;
  if (*azimuth_deg >= 360.0 - 1e-9) *azimuth_deg = 0.0;
}

bool FocalSpherePositions(const FocalGridSpec& spec, std::vector<Eigen::Vector3d>* positions,
                          std::string* error) {
  if (positions == nullptr) return Fail(error, "positions must not be null");
  if (!CheckMaxOffAxis(spec.max_off_axis_deg, error)) return false;
  if (!IsPositiveFinite(spec.off_axis_step_deg)) {
    return Fail(error, "off_axis_step_deg must be > 0 and finite (got " +
                           Num(spec.off_axis_step_deg) + ")");
  }
  if (!(IsPositiveFinite(spec.azimuth_step_deg) && spec.azimuth_step_deg <= 360.0)) {
    return Fail(error,
                "azimuth_step_deg must be in (0, 360] (got " + Num(spec.azimuth_step_deg) + ")");
  }
  if (!CheckSphere(spec, "", error)) return false;

  // Rings theta_k = k step <= max; azimuths phi_j = j step < 360, both up to a tolerance.
  const double rings = std::floor(spec.max_off_axis_deg / spec.off_axis_step_deg + kAngleTolerance);
  const double azimuths = std::ceil(360.0 / spec.azimuth_step_deg - kAngleTolerance);
  if (1.0 + rings * azimuths > kMaxGridPositions) {
    return Fail(error, "off_axis_step_deg and azimuth_step_deg give " +
                           Num(1.0 + rings * azimuths) + " positions (limit " +
                           Num(kMaxGridPositions) + ")");
  }
  const int num_rings = static_cast<int>(rings);
  const int num_azimuths = static_cast<int>(azimuths);
  std::vector<Eigen::Vector3d> out;
  out.reserve(1 + num_rings * num_azimuths);
  out.push_back(OnSphere(spec.focal_centre_m, spec.focal_radius_m, 1.0, 0.0, 0.0));
  for (int k = 1; k <= num_rings; ++k) {
    const double theta_rad =
        std::min(k * spec.off_axis_step_deg, spec.max_off_axis_deg) * kDegToRad;
    const double cos_theta = std::cos(theta_rad);
    const double sin_theta = std::sin(theta_rad);
    for (int j = 0; j < num_azimuths; ++j) {
      out.push_back(OnSphere(spec.focal_centre_m, spec.focal_radius_m, cos_theta, sin_theta,
                             j * spec.azimuth_step_deg * kDegToRad));
    }
  }
  *positions = std::move(out);
  return true;
}

bool RandomWorkspacePositionStream(const RandomWorkspaceSpec& spec, PositionStream* stream,
                                   std::string* error) {
  if (stream == nullptr) return Fail(error, "positions must not be null");
  if (!CheckSamples(spec.samples, error) || !CheckMaxOffAxis(spec.max_off_axis_deg, error)) {
    return false;
  }
  if (!CheckSphere(spec.sphere, "sphere.", error)) return false;
  if (!(std::isfinite(spec.radial_spread_m) && spec.radial_spread_m >= 0.0 &&
        spec.radial_spread_m < spec.sphere.focal_radius_m)) {
    return Fail(error, "radial_spread_m must be in [0, sphere.focal_radius_m) (got " +
                           Num(spec.radial_spread_m) + ")");
  }
  const double cos_max = std::cos(spec.max_off_axis_deg * kDegToRad);
  stream->count = spec.samples;
  stream->next = [spec, cos_max, rng = std::mt19937_64(spec.seed)]() mutable {
    // Uniform cos(theta) and azimuth give a uniform density over the cap's area.
    const double cos_theta = 1.0 - Uniform01(rng) * (1.0 - cos_max);
    const double phi_rad = 2.0 * M_PI * Uniform01(rng);
    const double offset_m = spec.radial_spread_m * (2.0 * Uniform01(rng) - 1.0);
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    return OnSphere(spec.sphere.focal_centre_m, spec.sphere.focal_radius_m + offset_m, cos_theta,
                    sin_theta, phi_rad);
  };
  return true;
}

namespace {

// A sidereal day (s): the sky turns once about the celestial pole.
constexpr double kSiderealDayS = 86164.0905;
// Draws of a source whose path stays on the cap for min_track_s, at most.
constexpr int kMaxSourceDraws = 100;

// The sources a SourceTrackSpec tracks, one sample at a time.
class SourceTracker {
 public:
  explicit SourceTracker(const SourceTrackSpec& spec)
      : spec_(spec),
        rng_(spec.seed),
        cos_max_(std::cos(spec.max_off_axis_deg * kDegToRad)),
        pole_(0.0, std::cos(spec.latitude_deg * kDegToRad),
              std::sin(spec.latitude_deg * kDegToRad)),
        step_(Eigen::AngleAxisd(2.0 * M_PI * spec.interval_s / kSiderealDayS, pole_)) {}

  Eigen::Vector3d Next() {
    const int day = spec_.days > 0
                        ? static_cast<int>(static_cast<long long>(n_) * spec_.days / spec_.samples)
                        : 0;
    if (n_ == 0 || day != day_ || left_ <= 0 || source_.z() < cos_max_) NewSource();
    day_ = day;
    ++n_;
    --left_;
    const Eigen::Vector3d feed =
        spec_.sphere.focal_centre_m - spec_.sphere.focal_radius_m * source_;
    source_ = step_ * source_;
    return feed;
  }

 private:
  // Samples the source at s stays on the cap from now (at most `limit`).
  long long OnCap(Eigen::Vector3d s, long long limit) const {
    long long k = 0;
    for (; k < limit && s.z() >= cos_max_; ++k) s = step_ * s;
    return k;
  }
  void NewSource() {
    const long long shortest =
        std::max(1LL, static_cast<long long>(std::ceil(spec_.min_track_s / spec_.interval_s)));
    for (int draw = 0; draw < kMaxSourceDraws; ++draw) {
      const double cos_theta = 1.0 - Uniform01(rng_) * (1.0 - cos_max_);
      const double phi = 2.0 * M_PI * Uniform01(rng_);
      const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
      source_ = Eigen::Vector3d(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
      if (OnCap(source_, shortest) >= shortest) break;
    }
    const double track_s =
        spec_.min_track_s + (spec_.max_track_s - spec_.min_track_s) * Uniform01(rng_);
    left_ = std::max(1LL, static_cast<long long>(std::llround(track_s / spec_.interval_s)));
  }

  SourceTrackSpec spec_;
  std::mt19937_64 rng_;
  double cos_max_;
  Eigen::Vector3d pole_;
  Eigen::Matrix3d step_;
  Eigen::Vector3d source_ = Eigen::Vector3d::UnitZ();
  long long n_ = 0, left_ = 0;
  int day_ = 0;
};

}  // namespace

bool SourceTrackPositionStream(const SourceTrackSpec& spec, PositionStream* stream,
                               std::string* error) {
  if (stream == nullptr) return Fail(error, "positions must not be null");
  if (!CheckSamples(spec.samples, error) || !CheckMaxOffAxis(spec.max_off_axis_deg, error)) {
    return false;
  }
  if (!(spec.max_off_axis_deg > 0.0 && spec.max_off_axis_deg < 90.0)) {
    return Fail(error, "max_off_axis_deg must be in (0, 90) for source tracks (got " +
                           Num(spec.max_off_axis_deg) + ")");
  }
  if (!CheckSphere(spec.sphere, "sphere.", error)) return false;
  if (!(std::isfinite(spec.interval_s) && spec.interval_s > 0.0)) {
    return Fail(error, "interval_s must be > 0 (got " + Num(spec.interval_s) + ")");
  }
  if (!(std::isfinite(spec.min_track_s) && std::isfinite(spec.max_track_s) &&
        spec.min_track_s > 0.0 && spec.max_track_s >= spec.min_track_s)) {
    return Fail(error, "min_track_s and max_track_s must satisfy 0 < min <= max (got " +
                           Num(spec.min_track_s) + ", " + Num(spec.max_track_s) + ")");
  }
  if (!(std::abs(spec.latitude_deg) <= 90.0)) {
    return Fail(error, "latitude_deg must be in [-90, 90] (got " + Num(spec.latitude_deg) + ")");
  }
  if (spec.days < 0 || spec.days > spec.samples) {
    return Fail(error, "days must be in [0, samples] (got " + std::to_string(spec.days) + ")");
  }
  stream->count = spec.samples;
  // Held by value: a copy of the stream starts where the original stands (the CLI checks
  // every node on a copy).
  stream->next = [tracker = SourceTracker(spec)]() mutable { return tracker.Next(); };
  return true;
}

bool RandomWorkspacePositions(const RandomWorkspaceSpec& spec,
                              std::vector<Eigen::Vector3d>* positions, std::string* error) {
  if (positions == nullptr) return Fail(error, "positions must not be null");
  PositionStream stream;
  return RandomWorkspacePositionStream(spec, &stream, error) && Drain(&stream, positions);
}

bool RandomPosesAroundFocalLaw(const RandomPoseSpec& spec, std::vector<Pose>* poses,
                               std::string* error) {
  if (poses == nullptr) return Fail(error, "poses must not be null");
  if (!(spec.min_extra_rotation_deg >= 0.0) ||
      !(spec.max_extra_rotation_deg >= spec.min_extra_rotation_deg) ||
      !std::isfinite(spec.max_extra_rotation_deg)) {
    return Fail(error,
                "min_extra_rotation_deg and max_extra_rotation_deg must satisfy 0 <= min "
                "<= max, finite (got " +
                    Num(spec.min_extra_rotation_deg) + ", " + Num(spec.max_extra_rotation_deg) +
                    ")");
  }
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> out;
  if (!RandomWorkspacePositions(spec.positions, &positions, error) ||
      !PosesWithAttitudeLaw(positions, spec.law, &out, error)) {
    return false;
  }
  std::mt19937_64 rng(spec.positions.seed + 1);
  const double span_deg = spec.max_extra_rotation_deg - spec.min_extra_rotation_deg;
  for (Pose& p : out) {
    const double amplitude_deg = spec.min_extra_rotation_deg + span_deg * Uniform01(rng);
    double rpy_deg[3];
    for (double& a : rpy_deg) a = amplitude_deg * (2.0 * Uniform01(rng) - 1.0);
    p.rotation = p.rotation * RotationFromRpyDeg(rpy_deg[0], rpy_deg[1], rpy_deg[2]);
  }
  *poses = std::move(out);
  return true;
}

RandomPoseSpec EdgeSweepSpec(int samples, std::uint64_t seed) {
  RandomPoseSpec spec;
  spec.positions.samples = samples;
  spec.positions.max_off_axis_deg = 45.0;
  spec.positions.radial_spread_m = 5.0;
  spec.positions.seed = seed;
  return spec;
}

bool PosesWithAttitudeLaw(const std::vector<Eigen::Vector3d>& positions,
                          const FocalAttitudeLaw& law, std::vector<Pose>* poses,
                          std::string* error) {
  if (poses == nullptr) return Fail(error, "poses must not be null");
  if (!(law.tilt_fraction >= 0.0 && law.tilt_fraction <= 1.0)) {
    return Fail(error, "law.tilt_fraction must be in [0, 1] (got " + Num(law.tilt_fraction) + ")");
  }
  if (!law.focal_centre_m.allFinite()) return Fail(error, "law.focal_centre_m must be finite");
  if (!CheckPositions(positions, error)) return false;
  std::vector<Pose> out(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!(positions[i].z() < law.focal_centre_m.z())) {
      return Fail(error, "positions[" + std::to_string(i) +
                             "] must be below law.focal_centre_m (z_m " + Num(positions[i].z()) +
                             " >= " + Num(law.focal_centre_m.z()) + ")");
    }
    out[i].position_m = positions[i];
    out[i].rotation = FocalAttitude(positions[i], law);
  }
  *poses = std::move(out);
  return true;
}

bool PosesWithIdentityAttitude(const std::vector<Eigen::Vector3d>& positions,
                               std::vector<Pose>* poses, std::string* error) {
  if (poses == nullptr) return Fail(error, "poses must not be null");
  if (!CheckPositions(positions, error)) return false;
  std::vector<Pose> out(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) out[i].position_m = positions[i];
  *poses = std::move(out);
  return true;
}

// Where each known column stands in a pose file, and which attitude it gives.
struct PoseColumns {
  std::array<int, kNumColumns> index;
  size_t num_fields = 0;
  bool has_rpy = false;
  bool has_quaternion = false;
  // Read through a column map (null: the canonical columns): the delimiter, each
  // column's conversion, and how messages name it.
  const ColumnMap* map = nullptr;
  char delimiter = ',';
  std::array<internal::ValueConversion, kNumColumns> conversion{};
  std::array<std::string, kNumColumns> label;
  std::string position_label = "columns 'x_m,y_m,z_m'";
  std::string quaternion_label = "columns 'qw,qx,qy,qz'";
  // The moving parts' joint columns asked for (null: none), and where each stands (-1:
  // absent; the file has all of them or none).
  const std::vector<std::string>* joint_names = nullptr;
  std::vector<int> joint_index;
  std::vector<internal::ValueConversion> joint_conversion;  // through a map, per joint
};

// A pose file gives every joint column the model names or none of them (the command's
// flag or law then sets the joints).
bool CheckJointColumnsPresent(const PoseColumns& columns, const std::string& where,
                              std::string* error) {
  std::string missing;
  int present = 0;
  for (size_t j = 0; j < columns.joint_index.size(); ++j) {
    if (columns.joint_index[j] >= 0) {
      ++present;
    } else {
      missing += (missing.empty() ? "" : ", ") + internal::Quote((*columns.joint_names)[j]);
    }
  }
  if (present == 0 || missing.empty()) return true;
  return Fail(error, where + "the file gives some of the moving parts' joint columns but not " +
                         missing + " (give every joint column of the model, or none)");
}

// The header of a pose file read through a column map: x, y, z, the attitude, the time
// and the model's joint columns as the map names them (its other entries are not read).
bool ParseMappedPoseHeader(const std::vector<std::string_view>& fields, const std::string& where,
                           const std::string& path, PoseColumns* columns, std::string* error) {
  const ColumnMap& map = *columns->map;
  std::vector<std::string> names;
  for (int c = 0; c < kTime; ++c) names.push_back(kColumnNames[c]);
  if (columns->joint_names != nullptr) {  // targets kTime + j
    names.insert(names.end(), columns->joint_names->begin(), columns->joint_names->end());
  }
  internal::MappedHeader mapped;
  if (!internal::ResolveMappedHeader(map, fields, names, where, path, &mapped, error)) return false;
  columns->joint_conversion.assign(columns->joint_index.size(), {});
  for (size_t j = 0; j < columns->joint_index.size(); ++j) {
    columns->joint_index[j] = mapped.field_of_target[kTime + j];
    if (const ColumnMapEntry* e = mapped.entry_of_target[kTime + j]; e != nullptr) {
      columns->joint_conversion[j] = internal::ConversionOf(e->name, e->unit);
    }
  }
  if (!CheckJointColumnsPresent(*columns, internal::ColumnsWhere(map), error)) return false;
  std::array<int, kNumColumns>& index = columns->index;
  index.fill(-1);
  columns->num_fields = fields.size();
  for (int c = 0; c < kTime; ++c) {
    index[c] = mapped.field_of_target[c];
    const ColumnMapEntry* e = mapped.entry_of_target[c];
    if (e == nullptr) continue;
    columns->conversion[c] = internal::ConversionOf(e->name, e->unit);
    columns->label[c] = "column " + internal::Quote(e->column) + " (" + e->name + ")";
  }
  index[kTime] = mapped.time_field;
  if (map.has_time) {
    columns->label[kTime] = "column " + internal::Quote(map.time.column) + " (time_s)";
  }
  const auto group = [&](int first, int count) {
    std::string sources, fastcal;
    for (int c = first; c < first + count; ++c) {
      const ColumnMapEntry* e = mapped.entry_of_target[c];
      sources += (c > first ? "," : "") + (e ? e->column : std::string("?"));
      fastcal += (c > first ? "," : "") + std::string(kColumnNames[c]);
    }
    return "columns " + internal::Quote(sources) + " (" + fastcal + ")";
  };
  columns->position_label = group(kX, 3);
  columns->quaternion_label = group(kQw, 4);
  columns->has_rpy = index[kRoll] >= 0 || index[kPitch] >= 0 || index[kYaw] >= 0;
  columns->has_quaternion =
      index[kQw] >= 0 || index[kQx] >= 0 || index[kQy] >= 0 || index[kQz] >= 0;
  const std::string map_where = internal::ColumnsWhere(map);
  if (columns->has_rpy && columns->has_quaternion) {
    return Fail(error,
                map_where + "both roll/pitch/yaw and quaternion (qw,qx,qy,qz); give one attitude");
  }
  std::vector<int> required = {kX, kY, kZ};
  if (columns->has_rpy) required.insert(required.end(), {kRoll, kPitch, kYaw});
  if (columns->has_quaternion) required.insert(required.end(), {kQw, kQx, kQy, kQz});
  for (int c : required) {
    if (index[c] < 0) {
      return Fail(error, map_where + "no entry for '" + std::string(kColumnNames[c]) +
                             "' (a pose file needs x_m, y_m, z_m and, if any, a whole attitude)");
    }
  }
  return true;
}

// The header line: known or ignored (dataset) columns, each once; x, y, z and at most one
// complete attitude group. `where` is "path:line: ".
bool ParsePoseHeader(const std::string& line, const std::vector<std::string_view>& fields,
                     const std::string& where, PoseColumns* columns, std::string* error) {
  const std::string separator_error = internal::WrongSeparatorMessage(line);
  if (!separator_error.empty()) return Fail(error, where + separator_error);
  std::array<int, kNumColumns>& index = columns->index;
  index.fill(-1);
  columns->num_fields = fields.size();
  const std::vector<std::string> ignored = IgnoredDatasetColumns();
  std::set<std::string_view> seen_ignored;
  for (size_t i = 0; i < fields.size(); ++i) {
    const std::string column = "column " + std::to_string(i + 1);
    if (fields[i].empty()) return Fail(error, where + column + ": empty column name");
    bool known = false;
    for (int c = 0; c < kNumColumns; ++c) {
      if (fields[i] != kColumnNames[c]) continue;
      if (index[c] >= 0) return Fail(error, where + "duplicate column '" + kColumnNames[c] + "'");
      index[c] = static_cast<int>(i);
      known = true;
    }
    for (const std::string& name : ignored) {
      if (fields[i] != name) continue;
      if (!seen_ignored.insert(fields[i]).second) {
        return Fail(error, where + "duplicate column '" + name + "'");
      }
      known = true;
    }
    for (size_t j = 0; columns->joint_names != nullptr && j < columns->joint_names->size(); ++j) {
      if (fields[i] != (*columns->joint_names)[j]) continue;
      if (columns->joint_index[j] >= 0) {
        return Fail(error, where + "duplicate column " + internal::Quote(fields[i]));
      }
      columns->joint_index[j] = static_cast<int>(i);
      known = true;
    }
    if (!known) {
      const auto ends_with = [&](std::string_view suffix) {
        return fields[i].size() > suffix.size() &&
               fields[i].substr(fields[i].size() - suffix.size()) == suffix;
      };
      const bool joint_like = ends_with("_deg") || ends_with("_m");
      return Fail(error, where + column + " " + internal::Quote(fields[i]) +
                             ": unknown column name (accepted: " + AcceptedColumns() + ")" +
                             (joint_like ? "; a moving part's joint column is read only with "
                                           "a model that names it (cabin.moving_parts)"
                                         : ""));
    }
  }
  if (!CheckJointColumnsPresent(*columns, where, error)) return false;
  columns->has_rpy = index[kRoll] >= 0 || index[kPitch] >= 0 || index[kYaw] >= 0;
  columns->has_quaternion =
      index[kQw] >= 0 || index[kQx] >= 0 || index[kQy] >= 0 || index[kQz] >= 0;
  if (columns->has_rpy && columns->has_quaternion) {
    return Fail(error, where +
                           "both roll/pitch/yaw and quaternion (qw,qx,qy,qz) columns; give "
                           "one attitude");
  }
  std::vector<int> required = {kX, kY, kZ};
  if (columns->has_rpy) required.insert(required.end(), {kRoll, kPitch, kYaw});
  if (columns->has_quaternion) required.insert(required.end(), {kQw, kQx, kQy, kQz});
  for (int c : required) {
    if (index[c] < 0) return Fail(error, where + "missing column '" + kColumnNames[c] + "'");
  }
  return true;
}

// One data row: numbers, plausible angles and position, a unit quaternion; *time_s is
// set when the file has time_s.
bool ParsePoseRow(std::vector<std::string_view> fields, const std::string& where,
                  const PoseColumns& columns, const PlausibilityLimits& limits, Pose* pose,
                  double* time_s, JointValues* joints, std::string* error) {
  while (columns.map != nullptr && fields.size() > columns.num_fields && fields.back().empty()) {
    fields.pop_back();  // trailing delimiters
  }
  if (fields.size() != columns.num_fields) {
    return Fail(error, where + "expected " + std::to_string(columns.num_fields) +
                           " fields (as in the header), got " + std::to_string(fields.size()));
  }
  const std::array<int, kNumColumns>& index = columns.index;
  std::array<double, kNumColumns> values{};
  for (int c = 0; c < kNumColumns; ++c) {
    if (index[c] < 0) continue;
    std::string why;
    double file_value = 0.0;
    const bool read = columns.map == nullptr ? ParseNumber(fields[index[c]], &values[c], &why)
                      : c == kTime ? internal::ReadTimeField(fields[index[c]], columns.map->time,
                                                             columns.map->decimal, &values[c], &why)
                                   : internal::ReadConvertedNumber(
                                         fields[index[c]], columns.map->decimal,
                                         columns.conversion[c], &file_value, &values[c], &why);
    if (!read || (c >= kRoll && c <= kYaw && !CheckAngleDeg(values[c], limits, &why))) {
      return Fail(error, where + columns.label[c] + ": " + why);
    }
  }
  pose->position_m = Eigen::Vector3d(values[kX], values[kY], values[kZ]);
  if (std::string why; !CheckPosition(pose->position_m, limits, &why)) {
    return Fail(error, where + columns.position_label + ": " + why);
  }
  if (columns.has_rpy) {
    pose->rotation = RotationFromRpyDeg(values[kRoll], values[kPitch], values[kYaw]);
  } else if (columns.has_quaternion) {
    std::string why;
    if (!RotationFromQuaternion(values[kQw], values[kQx], values[kQy], values[kQz], &pose->rotation,
                                &why)) {
      return Fail(error, where + columns.quaternion_label + ": " + why);
    }
  }
  *time_s = values[kTime];
  joints->fill(0.0);
  for (size_t j = 0; j < columns.joint_index.size(); ++j) {
    if (columns.joint_index[j] < 0) continue;
    const std::string& name = (*columns.joint_names)[j];
    std::string why;
    double file_value = 0.0;
    const std::string_view field = fields[columns.joint_index[j]];
    const bool read = columns.map == nullptr
                          ? ParseNumber(field, &(*joints)[j], &why)
                          : internal::ReadConvertedNumber(field, columns.map->decimal,
                                                          columns.joint_conversion[j], &file_value,
                                                          &(*joints)[j], &why);
    if (!read || !PlausibleJointValue(name, (*joints)[j], &why)) {
      return Fail(error, where + "column " + internal::Quote(name) + ": " + why);
    }
  }
  return true;
}

namespace {

// The pose file read through `map` (null: the canonical columns).
bool ParsePosesCsvImpl(const std::string& text, const std::string& path, const ColumnMap* map,
                       const std::vector<std::string>* joint_names, std::vector<Pose>* poses,
                       std::vector<JointValues>* joints, std::vector<double>* times_s,
                       std::string* error) {
  if (poses == nullptr) return Fail(error, "poses must not be null");
  if (const std::string spreadsheet =
          internal::SpreadsheetMessage(path, std::string_view(text).substr(0, 8), false);
      !spreadsheet.empty()) {
    return Fail(error, spreadsheet);
  }
  const PlausibilityLimits limits;  // as for a dataset, by default
  PoseColumns columns;
  columns.map = map;
  columns.joint_names = joint_names;
  if (joint_names != nullptr) columns.joint_index.assign(joint_names->size(), -1);
  for (int c = 0; c < kNumColumns; ++c) {
    columns.label[c] = std::string("column '") + kColumnNames[c] + "'";
  }
  bool has_header = false;
  std::vector<Pose> out_poses;
  std::vector<JointValues> out_joints;
  std::vector<double> out_times;
  std::string line;
  long line_number = 0;
  long skip_until = 0;
  std::string_view rest(text);
  std::vector<std::string_view> fields;
  std::deque<std::string> scratch;
  while (!rest.empty()) {
    ++line_number;
    int breaks = 0;
    const size_t end = internal::RecordEnd(rest, 0, map != nullptr, &breaks);
    line.assign(rest.substr(0, end));
    rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
    const long record_line = line_number;
    line_number += breaks;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (record_line == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // BOM
    const std::string where = path + ":" + std::to_string(record_line) + ": ";
    if (map != nullptr && !has_header && map->header_line > 0) {
      if (record_line < map->header_line) continue;
      const size_t first = line.find_first_not_of(" \t");
      if (first != std::string::npos && line[first] == '#') line.erase(0, first + 1);
    } else if (IsSkipped(line) || record_line <= skip_until) {
      continue;
    } else if (map != nullptr && has_header &&
               line.find_first_not_of(std::string(1, columns.delimiter) + " \t\r\"") ==
                   std::string::npos) {
      continue;  // a spreadsheet's empty row (";;;;")
    }
    if (map != nullptr) {
      scratch.clear();
      std::string why;
      if (!has_header) {
        columns.delimiter =
            map->delimiter != 0 ? map->delimiter : internal::DetectDelimiter(line, map->decimal);
      }
      if (!internal::SplitRecord(line, columns.delimiter, &fields, &scratch, &why)) {
        return Fail(error, where + why);
      }
    } else {
      fields = SplitFields(line);
    }
    if (!has_header) {
      if (map != nullptr) {
        while (fields.size() > 1 && fields.back().empty()) fields.pop_back();
        if (!ParseMappedPoseHeader(fields, where, path, &columns, error)) return false;
        skip_until = record_line + map->skip_after_header;
      } else if (!ParsePoseHeader(line, fields, where, &columns, error)) {
        return false;
      }
      has_header = true;
      continue;
    }
    Pose pose;
    double time_s = 0.0;
    JointValues row_joints{};
    if (!ParsePoseRow(fields, where, columns, limits, &pose, &time_s, &row_joints, error)) {
      return false;
    }
    out_poses.push_back(pose);
    if (!columns.joint_index.empty() && columns.joint_index[0] >= 0) {
      out_joints.push_back(row_joints);
    }
    if (columns.index[kTime] >= 0) out_times.push_back(time_s);
  }
  if (!has_header) return Fail(error, path + ": no header line (empty file)");
  if (out_poses.empty()) return Fail(error, path + ": no data rows");

  *poses = std::move(out_poses);
  if (joints != nullptr) *joints = std::move(out_joints);
  if (times_s != nullptr) *times_s = std::move(out_times);
  return true;
}

bool ReadPosesCsvImpl(const std::string& path, const ColumnMap* map,
                      const std::vector<std::string>* joint_names, std::vector<Pose>* poses,
                      std::vector<JointValues>* joints, std::vector<double>* times_s,
                      std::string* error) {
  if (const std::string spreadsheet = internal::SpreadsheetMessage(path, "");
      !spreadsheet.empty()) {
    return Fail(error, spreadsheet);
  }
  std::string text, message;
  if (!internal::ReadRegularFile(path, kMaxPoseFileBytes, "pose", &text, &message)) {
    return Fail(error, message);
  }
  return ParsePosesCsvImpl(text, path, map, joint_names, poses, joints, times_s, error);
}

}  // namespace

bool ParsePosesCsv(const std::string& text, const std::string& path, std::vector<Pose>* poses,
                   std::vector<double>* times_s, std::string* error) {
  return ParsePosesCsvImpl(text, path, nullptr, nullptr, poses, nullptr, times_s, error);
}
bool ParsePosesCsv(const std::string& text, const std::string& source_name,
                   const ColumnMap& columns, std::vector<Pose>* poses, std::vector<double>* times_s,
                   std::string* error) {
  return ParsePosesCsvImpl(text, source_name, &columns, nullptr, poses, nullptr, times_s, error);
}
bool ParsePosesCsv(const std::string& text, const std::string& source_name,
                   const std::vector<std::string>& joint_columns, std::vector<Pose>* poses,
                   std::vector<JointValues>* joints, std::vector<double>* times_s,
                   std::string* error) {
  return ParsePosesCsvImpl(text, source_name, nullptr, &joint_columns, poses, joints, times_s,
                           error);
}
bool ReadPosesCsv(const std::string& path, std::vector<Pose>* poses, std::vector<double>* times_s,
                  std::string* error) {
  return ReadPosesCsvImpl(path, nullptr, nullptr, poses, nullptr, times_s, error);
}
bool ReadPosesCsv(const std::string& path, const ColumnMap& columns, std::vector<Pose>* poses,
                  std::vector<double>* times_s, std::string* error) {
  return ReadPosesCsvImpl(path, &columns, nullptr, poses, nullptr, times_s, error);
}
bool ReadPosesCsv(const std::string& path, const std::vector<std::string>& joint_columns,
                  std::vector<Pose>* poses, std::vector<JointValues>* joints,
                  std::vector<double>* times_s, std::string* error) {
  return ReadPosesCsvImpl(path, nullptr, &joint_columns, poses, joints, times_s, error);
}
bool ReadPosesCsv(const std::string& path, const ColumnMap& columns,
                  const std::vector<std::string>& joint_columns, std::vector<Pose>* poses,
                  std::vector<JointValues>* joints, std::vector<double>* times_s,
                  std::string* error) {
  return ReadPosesCsvImpl(path, &columns, &joint_columns, poses, joints, times_s, error);
}

}  // namespace fastcal
