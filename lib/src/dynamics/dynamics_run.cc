// A run in time and its summary (dynamics_run.h has the definitions: the minimum-jerk
// move, the quasi-static reference, the departures, the settle time).
#include "fastcal/dynamics_run.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/fail.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/units.h"

namespace fastcal {
namespace {

using internal::kNPerKn;
constexpr double kMmPerM = 1e3;
constexpr double kDegPerRad = 180.0 / M_PI;
// A lengths file: about 60 bytes a row; a day at 100 Hz is 0.5 GB, beyond any winch plan.
constexpr long long kMaxWinchTableBytes = 256LL << 20;
// The longest run (s): ten days, the wind's limit.
constexpr double kMaxDurationS = 10 * 86400.0;

using internal::Fail;

std::string Num(double v) { return internal::FormatDouble("%.10g", v); }

// Splits a CSV line on commas, trimming spaces and tabs.
std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) {
    const size_t a = field.find_first_not_of(" \t\r"), b = field.find_last_not_of(" \t\r");
    out.push_back(a == std::string::npos ? std::string() : field.substr(a, b - a + 1));
  }
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

// The pose of a move at time t (dynamics_run.h).
Pose MovePose(const DynamicsRunSpec& spec, double t) {
  return MinimumJerkPose(spec.start, spec.end, t / spec.move_s,
                         spec.focal_law ? &*spec.focal_law : nullptr);
}

std::string DescribePose(const Pose& p) {
  const Eigen::Vector3d rpy = RpyDegFromRotation(p.rotation);
  return "(" + Num(p.position_m.x()) + ", " + Num(p.position_m.y()) + ", " + Num(p.position_m.z()) +
         ") m, rpy (" + Num(rpy.x()) + ", " + Num(rpy.y()) + ", " + Num(rpy.z()) + ") deg";
}

// The winches' lengths of a run at time t: a move's by the exact statics (warm from the
// last call), a table's by linear interpolation, a decay's held.
class WinchPlan {
 public:
  WinchPlan(const CableRobot& robot, const DynamicsRunSpec& spec, const DynamicsOptions& options,
            const std::array<double, kNumCables>& start_s0)
      : robot_(robot), spec_(spec), start_s0_(start_s0) {
    statics_options_ = options.statics;
    statics_options_.warm_start = true;
  }

  bool At(double t, std::array<double, kNumCables>* s0, std::string* error) {
    switch (spec_.kind) {
      case DynamicsRunSpec::Kind::kFreeDecay:
        *s0 = start_s0_;
        return true;
      case DynamicsRunSpec::Kind::kLengths:
        *s0 = TableAt(t);
        return true;
      case DynamicsRunSpec::Kind::kMove:
        break;
    }
    const Pose pose = MovePose(spec_, std::min(t, spec_.move_s));
    if (SolveStatics(robot_, pose, statics_options_, &statics_) != StaticsStatus::kOk) {
      return Fail(error, "the statics cannot hold the move's pose at t = " + Num(t) + " s, " +
                             DescribePose(pose) + ": " + DescribeStatus(statics_));
    }
    for (int i = 0; i < kNumCables; ++i) (*s0)[i] = statics_.cables[i].unstretched_length_m;
    return true;
  }

 private:
  std::array<double, kNumCables> TableAt(double t) const {
    const WinchTable& table = spec_.lengths;
    if (t >= table.time_s.back()) return table.s0_m.back();
    const size_t k = static_cast<size_t>(
        std::upper_bound(table.time_s.begin(), table.time_s.end(), t) - table.time_s.begin());
    const size_t a = k == 0 ? 0 : k - 1;
    const double w = (t - table.time_s[a]) / (table.time_s[a + 1] - table.time_s[a]);
    std::array<double, kNumCables> out{};
    for (int i = 0; i < kNumCables; ++i) {
      out[i] = (1.0 - w) * table.s0_m[a][i] + w * table.s0_m[a + 1][i];
    }
    return out;
  }

  const CableRobot& robot_;
  const DynamicsRunSpec& spec_;
  std::array<double, kNumCables> start_s0_;
  StaticsOptions statics_options_;
  StaticsSolution statics_;
};

// Peaks and RMS of the departures over samples [first, end).
DynamicsDeparture Departure(const std::vector<DynamicsSample>& samples, size_t first) {
  DynamicsDeparture d;
  std::array<double, kNumCables> sum_kn{}, sum_percent{};
  double sum_position = 0.0;
  const size_t count = samples.size() > first ? samples.size() - first : 0;
  for (size_t k = first; k < samples.size(); ++k) {
    const DynamicsSample& s = samples[k];
    for (int i = 0; i < kNumCables; ++i) {
      const double kn = (s.tension_n[i] - s.quasi_static_tension_n[i]) / kNPerKn;
      const double percent = 100.0 * (s.tension_n[i] / s.quasi_static_tension_n[i] - 1.0);
      d.peak_kn[i] = std::max(d.peak_kn[i], std::abs(kn));
      d.peak_percent[i] = std::max(d.peak_percent[i], std::abs(percent));
      sum_kn[i] += kn * kn;
      sum_percent[i] += percent * percent;
    }
    const double mm = kMmPerM * (s.pose.position_m - s.quasi_static_pose.position_m).norm();
    d.peak_position_mm = std::max(d.peak_position_mm, mm);
    sum_position += mm * mm;
    d.peak_attitude_deg = std::max(
        d.peak_attitude_deg,
        kDegPerRad *
            Eigen::AngleAxisd(s.pose.rotation * s.quasi_static_pose.rotation.transpose()).angle());
  }
  if (count == 0) return d;
  for (int i = 0; i < kNumCables; ++i) {
    d.rms_kn[i] = std::sqrt(sum_kn[i] / count);
    d.rms_percent[i] = std::sqrt(sum_percent[i] / count);
    d.max_peak_kn = std::max(d.max_peak_kn, d.peak_kn[i]);
    d.max_rms_kn = std::max(d.max_rms_kn, d.rms_kn[i]);
    d.max_peak_percent = std::max(d.max_peak_percent, d.peak_percent[i]);
    d.max_rms_percent = std::max(d.max_rms_percent, d.rms_percent[i]);
  }
  d.rms_position_mm = std::sqrt(sum_position / count);
  return d;
}

size_t FirstAtOrAfter(const std::vector<DynamicsSample>& samples, double t) {
  return static_cast<size_t>(
      std::lower_bound(samples.begin(), samples.end(), t - 1e-9,
                       [](const DynamicsSample& s, double time) { return s.time_s < time; }) -
      samples.begin());
}

// The settle time from motion_end (dynamics_run.h); false when the last sample is
// outside the band.
bool SettleTime(const std::vector<DynamicsSample>& samples, double motion_end_s, double fraction,
                double* settle_s) {
  auto outside = [&](const DynamicsSample& s) {
    for (int i = 0; i < kNumCables; ++i) {
      if (std::abs(s.tension_n[i] - s.quasi_static_tension_n[i]) >
          fraction * s.quasi_static_tension_n[i]) {
        return true;
      }
    }
    return false;
  };
  if (samples.empty() || outside(samples.back())) {
    *settle_s = std::numeric_limits<double>::quiet_NaN();
    return false;
  }
  *settle_s = 0.0;
  for (size_t k = samples.size(); k-- > 0;) {
    if (samples[k].time_s < motion_end_s) break;
    if (outside(samples[k])) {
      *settle_s = samples[k + 1].time_s - motion_end_s;
      break;
    }
  }
  return true;
}

void WriteDeparture(const DynamicsDeparture& d, JsonWriter* j) {
  j->Key("peak_kN").Number(d.max_peak_kn);
  j->Key("rms_kN").Number(d.max_rms_kn);
  j->Key("peak_percent").Number(d.max_peak_percent);
  j->Key("rms_percent").Number(d.max_rms_percent);
  j->Key("peak_position_mm").Number(d.peak_position_mm);
  j->Key("rms_position_mm").Number(d.rms_position_mm);
  j->Key("peak_attitude_deg").Number(d.peak_attitude_deg);
  const std::pair<const char*, const std::array<double, kNumCables>*> per_cable[] = {
      {"cable_peak_kN", &d.peak_kn},
      {"cable_rms_kN", &d.rms_kn},
      {"cable_peak_percent", &d.peak_percent},
      {"cable_rms_percent", &d.rms_percent}};
  for (const auto& [name, values] : per_cable) j->Key(name).NumberArray(*values);
}

void WritePose(const Pose& p, JsonWriter* j) {
  const Eigen::Vector3d rpy = RpyDegFromRotation(p.rotation);
  j->BeginObject();
  j->Key("x_m").Number(p.position_m.x()).Key("y_m").Number(p.position_m.y());
  j->Key("z_m").Number(p.position_m.z());
  j->Key("roll_deg").Number(rpy.x()).Key("pitch_deg").Number(rpy.y());
  j->Key("yaw_deg").Number(rpy.z());
  j->EndObject();
}

const char* KindName(DynamicsRunSpec::Kind kind) {
  switch (kind) {
    case DynamicsRunSpec::Kind::kMove:
      return "move";
    case DynamicsRunSpec::Kind::kLengths:
      return "lengths";
    case DynamicsRunSpec::Kind::kFreeDecay:
      return "free_decay";
  }
  return "";
}

}  // namespace

double MinimumJerk(double u) {
  if (!(u > 0.0)) return 0.0;
  if (u >= 1.0) return 1.0;
  return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

Pose MinimumJerkPose(const Pose& from, const Pose& to, double u, const FocalAttitudeLaw* law) {
  const double s = MinimumJerk(u);
  Pose p;
  p.position_m = from.position_m + s * (to.position_m - from.position_m);
  if (law != nullptr) {
    p.rotation = FocalAttitude(p.position_m, *law);
  } else {
    const Eigen::AngleAxisd turn(to.rotation * from.rotation.transpose());
    p.rotation = Eigen::AngleAxisd(s * turn.angle(), turn.axis()) * from.rotation;
  }
  return p;
}

bool ParseWinchTable(const std::string& text, const std::string& source_name, WinchTable* table,
                     std::string* error) {
  std::istringstream in(text);
  std::string line;
  long line_number = 0;
  std::array<int, kNumCables + 1> index;
  index.fill(-1);
  bool has_header = false;
  size_t header_fields = 0;
  WinchTable out;
  const char* names[kNumCables + 1] = {"time_s", "s0_1_m", "s0_2_m", "s0_3_m",
                                       "s0_4_m", "s0_5_m", "s0_6_m"};
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string where = source_name + ":" + std::to_string(line_number) + ": ";
    const std::vector<std::string> fields = Fields(line);
    if (!has_header) {
      for (size_t f = 0; f < fields.size(); ++f) {
        for (int c = 0; c <= kNumCables; ++c) {
          if (fields[f] != names[c]) continue;
          if (index[c] >= 0) return Fail(error, where + "column '" + names[c] + "' twice");
          index[c] = static_cast<int>(f);
        }
      }
      for (int c = 0; c <= kNumCables; ++c) {
        if (index[c] < 0) {
          return Fail(error, where + "no column '" + names[c] +
                                 "' in the header (a lengths file has time_s and s0_1_m .. "
                                 "s0_6_m)");
        }
      }
      header_fields = fields.size();
      has_header = true;
      continue;
    }
    if (fields.size() != header_fields) {
      return Fail(error, where + std::to_string(fields.size()) + " fields, the header has " +
                             std::to_string(header_fields));
    }
    std::array<double, kNumCables + 1> v{};
    for (int c = 0; c <= kNumCables; ++c) {
      std::string why;
      if (!internal::ParseFiniteDecimal(fields[index[c]], &v[c], &why)) {
        return Fail(error, where + "column '" + names[c] + "': " + why);
      }
      if (c > 0 && !(v[c] > 0.0)) {
        return Fail(error, where + "column '" + names[c] + "': a length must be > 0 (got " +
                               Num(v[c]) + ")");
      }
    }
    if (out.time_s.empty() && v[0] != 0.0) {
      return Fail(error, where + "column 'time_s': the first row is the start, at 0 s (got " +
                             Num(v[0]) + ")");
    }
    if (!out.time_s.empty() && !(v[0] > out.time_s.back())) {
      return Fail(error, where + "column 'time_s': times must increase (" + Num(v[0]) +
                             " s after " + Num(out.time_s.back()) + " s)");
    }
    if (v[0] > kMaxDurationS) {
      return Fail(error, where + "column 'time_s': beyond ten days (" + Num(v[0]) + " s)");
    }
    out.time_s.push_back(v[0]);
    std::array<double, kNumCables> s0{};
    std::copy(v.begin() + 1, v.end(), s0.begin());
    out.s0_m.push_back(s0);
  }
  if (!has_header) return Fail(error, source_name + ": no header line (empty file)");
  if (out.time_s.empty()) return Fail(error, source_name + ": no data rows");
  *table = std::move(out);
  return true;
}

bool ReadWinchTable(const std::string& path, WinchTable* table, std::string* error) {
  std::string text, message;
  if (!internal::ReadRegularFile(path, kMaxWinchTableBytes, "lengths", &text, &message)) {
    return Fail(error, message);
  }
  return ParseWinchTable(text, path, table, error);
}

bool DynamicsRunSpec::IsValid(std::string* error) const {
  if (!IsFinite(start)) return Fail(error, "start: must be finite");
  const std::pair<const char*, double> positive[] = {{"hold_s", hold_s + 1.0},
                                                     {"rate_hz", rate_hz},
                                                     {"settle_fraction", settle_fraction},
                                                     {"residual_window_s", residual_window_s}};
  for (const auto& [name, value] : positive) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      return Fail(error, std::string(name) + ": must be finite and > 0" +
                             (std::string(name) == "hold_s" ? " (or 0)" : ""));
    }
  }
  if (!(hold_s >= 0.0)) return Fail(error, "hold_s: must be >= 0");
  if (rate_hz > 1000.0) return Fail(error, "rate_hz: at most 1000");
  if (!(summary_from_s >= 0.0) || !std::isfinite(summary_from_s)) {
    return Fail(error, "summary_from_s: must be finite and >= 0");
  }
  switch (kind) {
    case Kind::kMove:
      if (!IsFinite(end)) return Fail(error, "end: must be finite");
      if (!(move_s > 0.0) || !std::isfinite(move_s)) {
        return Fail(error, "move_s: must be finite and > 0");
      }
      break;
    case Kind::kLengths:
      if (lengths.time_s.empty() || lengths.time_s.size() != lengths.s0_m.size()) {
        return Fail(error, "lengths: no rows");
      }
      break;
    case Kind::kFreeDecay:
      if (!offset_m.allFinite() || !rotation_deg.allFinite()) {
        return Fail(error, "offset_m, rotation_deg: must be finite");
      }
      if (rotation_deg.norm() > 10.0 || offset_m.norm() > 10.0) {
        return Fail(error,
                    "offset_m, rotation_deg: a free decay's displacement is at most 10 m "
                    "and 10 deg");
      }
      break;
  }
  if (!(DurationS() * rate_hz >= 1.0)) {
    return Fail(error, "the record must hold at least two samples (a longer hold_s or rate_hz)");
  }
  if (DurationS() > kMaxDurationS) return Fail(error, "the record is longer than ten days");
  return true;
}

double DynamicsRunSpec::MotionEndS() const {
  switch (kind) {
    case Kind::kMove:
      return move_s;
    case Kind::kLengths:
      return lengths.time_s.empty() ? 0.0 : lengths.time_s.back();
    case Kind::kFreeDecay:
      return 0.0;
  }
  return 0.0;
}

double DynamicsRunSpec::DurationS() const { return MotionEndS() + hold_s; }

bool RunDynamics(const CableRobot& robot, const DynamicsRunSpec& spec,
                 const DynamicsOptions& options, DynamicsRunResult* result, std::string* error,
                 const std::function<void(double, double)>& progress) {
  const auto clock_start = std::chrono::steady_clock::now();
  *result = DynamicsRunResult();
  if (!spec.IsValid(error) || !options.IsValid(error)) return false;
  result->spec = spec;
  result->options = options;
  const double duration = spec.DurationS();
  if (spec.kind == DynamicsRunSpec::Kind::kMove) {
    StaticsSolution end;
    if (SolveStatics(robot, spec.end, options.statics, &end) != StaticsStatus::kOk) {
      return Fail(error, "the statics cannot hold the end pose " + DescribePose(spec.end) + ": " +
                             DescribeStatus(end));
    }
  }
  std::unique_ptr<CableDynamics> dynamics =
      CableDynamics::Create(robot, spec.start, options, duration, error);
  if (!dynamics) return false;
  if (spec.kind == DynamicsRunSpec::Kind::kLengths &&
      !dynamics->StartAt(spec.lengths.s0_m.front(), error)) {
    return false;
  }
  if (spec.kind == DynamicsRunSpec::Kind::kFreeDecay &&
      !dynamics->Displace(spec.offset_m, spec.rotation_deg / kDegPerRad, error)) {
    return false;
  }
  result->start = dynamics->start();
  WinchPlan plan(robot, spec, options, dynamics->UnstretchedLengthsM());
  const double interval = 1.0 / spec.rate_hz;
  const long samples = static_cast<long>(std::floor(duration * spec.rate_hz + 1e-9));
  const int substeps =
      std::max(1, static_cast<int>(std::ceil(interval / options.max_step_s - 1e-9)));
  std::array<double, kNumCables> s0{};
  auto record = [&](double t) {
    DynamicsSample s;
    s.time_s = t;
    s.pose = dynamics->CabinPose();
    s.tension_n = dynamics->LowerTensionsN();
    s.s0_m = dynamics->UnstretchedLengthsM();
    s.wind_speed_m_per_s = dynamics->WindSpeed(t);
    QuasiStaticState qs;
    if (!dynamics->QuasiStatic(s.s0_m, &qs, error)) {
      *error = "t = " + Num(t) + " s: " + *error;
      return false;
    }
    s.quasi_static_pose = qs.pose;
    s.quasi_static_tension_n = qs.lower_tension_n;
    result->samples.push_back(s);
    return true;
  };
  result->samples.reserve(samples + 1);
  if (!record(0.0)) return false;
  for (long k = 1; k <= samples; ++k) {
    const double t0 = (k - 1) * interval;
    for (int j = 1; j <= substeps; ++j) {
      const double t = j == substeps ? k * interval : t0 + j * interval / substeps;
      if (!plan.At(t, &s0, error) || !dynamics->Advance(t, s0, error)) return false;
    }
    if (!record(k * interval)) return false;
    if (progress && k % 600 == 0) progress(k * interval, duration);
  }
  result->motion_end_s = spec.MotionEndS();
  result->departure =
      Departure(result->samples, FirstAtOrAfter(result->samples, spec.summary_from_s));
  result->residual = Departure(
      result->samples,
      FirstAtOrAfter(result->samples, result->samples.back().time_s - spec.residual_window_s));
  result->settled =
      SettleTime(result->samples, result->motion_end_s, spec.settle_fraction, &result->settle_s);
  result->stats = dynamics->stats();
  result->seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return true;
}

std::string DynamicsCsv(const DynamicsRunResult& result) {
  std::string out = "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg";
  for (int i = 1; i <= kNumCables; ++i) out += ",T" + std::to_string(i) + "_kN";
  out += ",x_qs_m,y_qs_m,z_qs_m,roll_qs_deg,pitch_qs_deg,yaw_qs_deg";
  for (int i = 1; i <= kNumCables; ++i) out += ",T" + std::to_string(i) + "_qs_kN";
  for (int i = 1; i <= kNumCables; ++i) out += ",s0_" + std::to_string(i) + "_m";
  out += ",wind_m_per_s\n";
  auto num = [](double v, const char* format) {
    return internal::WithoutNegativeZero(internal::FormatDouble(format, v));
  };
  auto pose = [&](const Pose& p) {
    const Eigen::Vector3d rpy = RpyDegFromRotation(p.rotation);
    std::string s;
    for (int k = 0; k < 3; ++k) s += "," + num(p.position_m[k], "%.6f");
    for (int k = 0; k < 3; ++k) s += "," + num(rpy[k], "%.7f");
    return s;
  };
  for (const DynamicsSample& s : result.samples) {
    out += num(s.time_s, "%.6g") + pose(s.pose);
    for (double t : s.tension_n) out += "," + num(t / kNPerKn, "%.6f");
    out += pose(s.quasi_static_pose);
    for (double t : s.quasi_static_tension_n) out += "," + num(t / kNPerKn, "%.6f");
    for (double l : s.s0_m) out += "," + num(l, "%.6f");
    out += "," + num(s.wind_speed_m_per_s, "%.4f") + "\n";
  }
  return out;
}

std::string DynamicsSummaryJson(const DynamicsRunResult& r) {
  JsonWriter j;
  j.BeginObject();
  j.Key("run").BeginObject();
  j.Key("kind").String(KindName(r.spec.kind));
  j.Key("start");
  WritePose(r.spec.start, &j);
  if (r.spec.kind == DynamicsRunSpec::Kind::kMove) {
    j.Key("end");
    WritePose(r.spec.end, &j);
    j.Key("move_s").Number(r.spec.move_s);
    j.Key("distance_m").Number((r.spec.end.position_m - r.spec.start.position_m).norm());
  }
  if (r.spec.kind == DynamicsRunSpec::Kind::kFreeDecay) {
    j.Key("offset_m").NumberArray(r.spec.offset_m);
    j.Key("rotation_deg").NumberArray(r.spec.rotation_deg);
  }
  j.Key("hold_s").Number(r.spec.hold_s);
  j.Key("duration_s").Number(r.spec.DurationS());
  j.Key("rate_hz").Number(r.spec.rate_hz);
  j.Key("segments").Int(r.options.segments);
  j.Key("damping_ratio").Number(r.options.damping_ratio);
  j.Key("max_step_s").Number(r.options.max_step_s);
  j.Key("spectral_radius").Number(r.options.spectral_radius);
  j.Key("wind").BeginObject();
  j.Key("mean_m_per_s").Number(r.options.wind.mean_speed_m_per_s);
  j.Key("direction_deg").Number(r.options.wind.direction_deg);
  j.Key("spectrum").String(GustSpectrumName(r.options.wind.spectrum));
  j.Key("turbulence_intensity").Number(r.options.wind.turbulence_intensity);
  j.Key("seed").Int(static_cast<long long>(r.options.wind.seed));
  j.EndObject();
  j.EndObject();
  j.Key("start").BeginObject();
  j.Key("equilibrium");
  WritePose(r.start.equilibrium, &j);
  j.Key("offset_from_exact_statics_mm").Number(kMmPerM * r.start.position_offset_m);
  j.Key("attitude_offset_deg").Number(r.start.attitude_offset_deg);
  j.Key("tension_offset_percent").Number(100.0 * r.start.tension_offset);
  j.Key("frequency_hz").NumberArray(r.start.frequency_hz);
  j.Key("damping_ratio").NumberArray(r.start.damping_ratio);
  j.Key("damping_time_s").NumberArray(r.start.damping_time_s);
  j.EndObject();
  j.Key("departure").BeginObject();
  j.Key("from_s").Number(r.spec.summary_from_s);
  WriteDeparture(r.departure, &j);
  j.EndObject();
  j.Key("residual").BeginObject();
  j.Key("window_s").Number(r.spec.residual_window_s);
  WriteDeparture(r.residual, &j);
  j.EndObject();
  j.Key("settle").BeginObject();
  j.Key("fraction").Number(r.spec.settle_fraction);
  j.Key("motion_end_s").Number(r.motion_end_s);
  j.Key("settled").Bool(r.settled);
  j.Key("settle_s").Number(r.settled ? r.settle_s : std::numeric_limits<double>::quiet_NaN());
  j.EndObject();
  j.Key("integrator").BeginObject();
  j.Key("steps").Int(r.stats.steps);
  j.Key("newton_iterations").Int(r.stats.newton_iterations);
  j.Key("factorisations").Int(r.stats.factorisations);
  j.Key("halvings").Int(r.stats.halvings);
  j.Key("slack_segment_steps").Int(r.stats.slack_segment_steps);
  j.Key("seconds").Number(r.seconds);
  j.EndObject();
  j.EndObject();
  return j.str();
}

}  // namespace fastcal
