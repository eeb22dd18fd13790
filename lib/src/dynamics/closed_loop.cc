// The cabin in its control loop: the equations are closed_loop.h's opening.
#include "fastcal/closed_loop.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "fastcal/dynamics_run.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/units.h"

namespace fastcal {
namespace {

// The efficiency factor's kappa: exp(-(2 pi kappa 0.01 m / 0.1 m)^2) = 1 - 0.082 (10 mm
// RMS at 3 GHz loses 8.2%, Gan et al.).
constexpr double kEfficiencyKappa = 0.466;
constexpr double kSpeedOfLightMPerS = 299792458.0;
constexpr double kTwoPi = 6.283185307179586;

bool Positive(double v) { return std::isfinite(v) && v > 0.0; }
bool NonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

// The controller's state between cycles: the PID's sums, the winches' last command and
// rate, the warm start of the control cycle.
struct Controller {
  std::array<Eigen::Vector3d, 2> filtered = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  bool filter_started = false;
  Eigen::Vector3d integral = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_error = Eigen::Vector3d::Zero();
  bool has_last_error = false;
  std::array<double, kNumCables> s0{};
  std::array<double, kNumCables> rate{};
  bool saturated = false;  // a winch at its speed or acceleration limit last cycle
  ControlCycleResult cycle;
};

// The PID's correction for error e. The integral holds while a winch is at its limit
// (conditional integration: Astrom and Hagglund, "Advanced PID control", 2006, 3.5): what
// the winches cannot follow, during a slew, would otherwise wind it up and overshoot.
Eigen::Vector3d Pid(const LoopOptions& o, const Eigen::Vector3d& raw, Controller* c) {
  const double t = o.control_period_s;
  // Two first-order low-passes (started at the first error: no step into the loop).
  Eigen::Vector3d e = raw;
  if (o.error_filter_hz > 0.0) {
    const double alpha = 1.0 - std::exp(-kTwoPi * o.error_filter_hz * t);
    if (!c->filter_started) c->filtered = {raw, raw};
    c->filter_started = true;
    c->filtered[0] += alpha * (raw - c->filtered[0]);
    c->filtered[1] += alpha * (c->filtered[0] - c->filtered[1]);
    e = c->filtered[1];
  }
  if (!c->saturated) c->integral += e * t;
  const Eigen::Vector3d derivative =
      c->has_last_error ? Eigen::Vector3d((e - c->last_error) / t) : Eigen::Vector3d::Zero();
  c->last_error = e;
  c->has_last_error = true;
  return o.kp * e + o.ki_per_s * c->integral + o.kd_s * derivative;
}

// The winches toward `wanted` within their speed and acceleration over one period.
void MoveWinches(const LoopOptions& o, const std::array<double, kNumCables>& wanted,
                 Controller* c) {
  const double t = o.control_period_s;
  const double dv = o.max_winch_acceleration_m_per_s2 * t;
  c->saturated = false;
  for (int i = 0; i < kNumCables; ++i) {
    const double free = (wanted[i] - c->s0[i]) / t;
    double v = std::clamp(free, c->rate[i] - dv, c->rate[i] + dv);
    v = std::clamp(v, -o.max_winch_speed_m_per_s, o.max_winch_speed_m_per_s);
    c->saturated = c->saturated || v != free;
    c->rate[i] = v;
    c->s0[i] += v * t;
  }
}

// The path's clock at time t, with a minimum-jerk ease-in and ease-out of ramp_s around a
// path of `length_s` at full speed (closed_loop.h).
double PathClock(double t, double ramp_s, double length_s) {
  if (!(ramp_s > 0.0)) return t;
  const auto in = [](double u) { return u * u * u * u * (2.5 - 3.0 * u + u * u); };
  if (t < ramp_s) return ramp_s * in(std::max(0.0, t / ramp_s));
  if (t <= length_s) return t - 0.5 * ramp_s;
  const double u = std::min(1.0, (t - length_s) / ramp_s);
  return length_s - 0.5 * ramp_s + ramp_s * (u - in(u));
}

// The sample at the cycle's time: the cabin against the command.
LoopSample Sample(double time_s, const CableDynamics& plant, const Pose& command,
                  const Eigen::Vector3d& measured, const ControlCycleResult& plan,
                  const std::array<double, kNumCables>& s0) {
  LoopSample s;
  s.time_s = time_s;
  s.pose = plant.CabinPose();
  s.command = command;
  s.measured_m = measured;
  const Eigen::Vector3d d = s.pose.position_m - command.position_m;
  const Eigen::Vector3d axis = command.rotation.col(2);
  s.error_m = d.norm();
  s.axial_m = d.dot(axis);
  s.lateral_m = (d - s.axial_m * axis).norm();
  s.tension_n = plant.LowerTensionsN();
  for (int i = 0; i < kNumCables; ++i)
    s.planned_tension_n[i] = plan.statics.cables[i].lower_tension_n;
  s.s0_m = s0;
  return s;
}

LoopSummary Summarise(const std::vector<LoopSample>& samples, double from_s) {
  LoopSummary out;
  double e2 = 0.0, l2 = 0.0, a2 = 0.0, t2 = 0.0;
  const LoopSample* previous = nullptr;
  for (const LoopSample& s : samples) {
    if (previous != nullptr) {
      for (int i = 0; i < kNumCables; ++i)
        out.winch_travel_m += std::abs(s.s0_m[i] - previous->s0_m[i]);
    }
    previous = &s;
    if (s.time_s < from_s) continue;
    ++out.samples;
    e2 += s.error_m * s.error_m;
    l2 += s.lateral_m * s.lateral_m;
    a2 += s.axial_m * s.axial_m;
    out.error_peak_m = std::max(out.error_peak_m, s.error_m);
    out.lateral_peak_m = std::max(out.lateral_peak_m, s.lateral_m);
    out.axial_peak_m = std::max(out.axial_peak_m, std::abs(s.axial_m));
    for (int i = 0; i < kNumCables; ++i) {
      const double d = s.tension_n[i] - s.planned_tension_n[i];
      t2 += d * d;
      out.tension_error_peak_n = std::max(out.tension_error_peak_n, std::abs(d));
    }
  }
  if (out.samples > 0) {
    out.error_rms_m = std::sqrt(e2 / out.samples);
    out.lateral_rms_m = std::sqrt(l2 / out.samples);
    out.axial_rms_m = std::sqrt(a2 / out.samples);
    out.tension_error_rms_n = std::sqrt(t2 / (out.samples * kNumCables));
  }
  return out;
}

// One control cycle: the controller's winch lengths for the command at `time_s`, given
// the measurement, into c->s0 (the plant's unstretched lengths). False with *error.
bool Control(const CableRobot& truth, const CableRobot& controller, const LoopOptions& o,
             const Pose& command, const Eigen::Vector3d& error_m, double time_s, Controller* c,
             LoopSummary* summary, std::string* error) {
  const Eigen::Vector3d u = Pid(o, error_m, c);
  Pose aim = command;
  aim.position_m += u;
  StaticsOptions statics = o.statics;
  statics.warm_start = true;
  const ControlStatus status =
      ControlCycle(controller, aim, JointValues{}, o.limits, statics, &c->cycle);
  if (status == ControlStatus::kStaticsFailed) {
    *error = "at " + internal::FormatDouble("%.1f", time_s) +
             " s the controller's statics cannot solve the pose it aims at (" +
             internal::FormatDouble("%.3f", aim.position_m.x()) + ", " +
             internal::FormatDouble("%.3f", aim.position_m.y()) + ", " +
             internal::FormatDouble("%.3f", aim.position_m.z()) +
             " m): " + DescribeStatus(c->cycle.statics);
    return false;
  }
  if (status != ControlStatus::kOk && summary->limit_cycles++ == 0) {
    summary->first_limit = std::string(ControlStatusName(status)) + " at " +
                           internal::FormatDouble("%.1f", time_s) + " s";
  }
  std::array<double, kNumCables> wanted{};
  for (int i = 0; i < kNumCables; ++i) {
    wanted[i] = c->cycle.winch_length_m[i] - truth.cables[i].length_offset_m;
  }
  MoveWinches(o, wanted, c);
  return true;
}

}  // namespace

bool LoopOptions::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& what) {
    *error = what;
    return false;
  };
  if (!Positive(control_period_s)) return fail("control_period_s must be > 0");
  if (!NonNegative(kp) || !NonNegative(ki_per_s) || !NonNegative(kd_s)) {
    return fail("the PID's gains (kp, ki_per_s, kd_s) must be finite and >= 0");
  }
  if (!NonNegative(error_filter_hz)) return fail("error_filter_hz must be >= 0");
  if (!NonNegative(measurement_noise_m)) return fail("measurement_noise_m must be >= 0");
  if (!NonNegative(measurement_delay_s) || measurement_delay_s > 60.0) {
    return fail("measurement_delay_s must be in [0, 60] s");
  }
  if (!Positive(max_winch_speed_m_per_s)) return fail("max_winch_speed_m_per_s must be > 0");
  if (!Positive(max_winch_acceleration_m_per_s2)) {
    return fail("max_winch_acceleration_m_per_s2 must be > 0");
  }
  if (!NonNegative(summary_from_s)) return fail("summary_from_s must be >= 0");
  return limits.IsValid(error);
}

bool LoopSpec::IsValid(std::string* error) const {
  if (!IsFinite(start) || (end && !IsFinite(*end))) {
    *error = "the loop's poses must be finite";
    return false;
  }
  if (!path.empty() || !path_time_s.empty()) {
    if (end) {
      *error = "give a slew's end or a path, not both";
      return false;
    }
    if (!NonNegative(path_ramp_s) || (!path_time_s.empty() && path_ramp_s > path_time_s.back())) {
      *error = "path_ramp_s must be >= 0 and at most the path's duration";
      return false;
    }
    if (path.size() != path_time_s.size() || path.size() < 2) {
      *error = "a path needs two or more poses, each with its time";
      return false;
    }
    for (size_t k = 0; k < path.size(); ++k) {
      const bool increasing = k == 0 ? path_time_s[0] == 0.0 : path_time_s[k] > path_time_s[k - 1];
      if (!IsFinite(path[k]) || !std::isfinite(path_time_s[k]) || !increasing) {
        *error = "path node " + std::to_string(k) +
                 ": its pose must be finite and the times increase from 0";
        return false;
      }
    }
  }
  if (end && !Positive(move_s)) {
    *error = "move_s must be > 0";
    return false;
  }
  if (!NonNegative(hold_s) || !(DurationS() > 0.0) || DurationS() > 86400.0 * 7) {
    *error = "hold_s must be >= 0 and the loop's duration in (0, 7 days]";
    return false;
  }
  return true;
}

double LoopSpec::DurationS() const {
  if (!path.empty()) return path_time_s.back() + path_ramp_s + hold_s;
  return (end ? move_s : 0.0) + hold_s;
}

Pose LoopSpec::CommandAt(double time_s) const {
  Pose command = start;
  if (!path.empty()) {
    time_s = PathClock(time_s, path_ramp_s, path_time_s.back());
    // The segment [k, k + 1] holding time_s (the last one after the path's end).
    size_t k = static_cast<size_t>(
        std::upper_bound(path_time_s.begin(), path_time_s.end(), time_s) - path_time_s.begin());
    k = std::min(k == 0 ? 0 : k - 1, path.size() - 2);
    const size_t next = k + 1;
    const double u =
        std::clamp((time_s - path_time_s[k]) / (path_time_s[next] - path_time_s[k]), 0.0, 1.0);
    command.position_m = (1.0 - u) * path[k].position_m + u * path[next].position_m;
    const Eigen::Quaterniond a(path[k].rotation), b(path[next].rotation);
    command.rotation = a.slerp(u, b).toRotationMatrix();
    if (focal_law) command.rotation = FocalAttitude(command.position_m, *focal_law);
  } else if (end) {
    command = MinimumJerkPose(start, *end, time_s / move_s, focal_law ? &*focal_law : nullptr);
  } else if (focal_law) {
    command.rotation = FocalAttitude(start.position_m, *focal_law);
  }
  return command;
}

bool RunLoop(const CableRobot& truth, const CableRobot& controller, const LoopSpec& spec,
             const LoopOptions& options, const DynamicsOptions& dynamics, LoopResult* result,
             std::string* error) {
  const auto clock_start = std::chrono::steady_clock::now();
  *result = LoopResult();
  result->spec = spec;
  result->options = options;
  if (!spec.IsValid(error) || !options.IsValid(error)) return false;
  const double period = options.control_period_s;
  const int cycles = static_cast<int>(std::ceil(spec.DurationS() / period - 1e-9));
  const int delay = static_cast<int>(std::lround(options.measurement_delay_s / period));
  // The plant starts at rest where the truth hangs at the lengths the controller commands
  // for the start: a model's error is there from the first cycle.
  std::unique_ptr<CableDynamics> plant =
      CableDynamics::Create(truth, spec.CommandAt(0.0), dynamics, spec.DurationS(), error);
  if (!plant) return false;
  Controller c;
  LoopSummary& summary = result->summary;
  if (!Control(truth, controller, options, spec.CommandAt(0.0), Eigen::Vector3d::Zero(), 0.0, &c,
               &summary, error)) {
    return false;
  }
  for (int i = 0; i < kNumCables; ++i) {
    c.s0[i] = c.cycle.winch_length_m[i] - truth.cables[i].length_offset_m;
  }
  c.integral.setZero();
  c.has_last_error = false;
  c.filter_started = false;
  if (!plant->StartAt(c.s0, error)) return false;
  result->start = plant->start();
  std::mt19937_64 random(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<Eigen::Vector3d> positions;  // the cabin at each cycle, for the delay
  positions.reserve(static_cast<size_t>(cycles) + 1);
  result->samples.reserve(static_cast<size_t>(cycles) + 1);
  for (int k = 0; k <= cycles; ++k) {
    const double t = k * period;
    positions.push_back(plant->CabinPose().position_m);
    const int seen = std::max(0, k - delay);
    Eigen::Vector3d measured = positions[seen];
    for (int a = 0; a < 3; ++a) measured[a] += options.measurement_noise_m * noise(random);
    const Pose command = spec.CommandAt(t);
    result->samples.push_back(Sample(t, *plant, command, measured, c.cycle, c.s0));
    if (k == cycles) break;
    const Eigen::Vector3d e = spec.CommandAt(seen * period).position_m - measured;
    // The winches reach this cycle's lengths at the period's end: the feed-forward solves
    // the command there (a controller knows its trajectory a period ahead; solved for now,
    // the cabin lagged it by the path's speed times the period, 9.5 mm at 0.1 m/s).
    if (!Control(truth, controller, options, spec.CommandAt(t + period), e, t, &c, &summary,
                 error) ||
        !plant->Advance(t + period, c.s0, error)) {
      return false;
    }
  }
  const int limit_cycles = summary.limit_cycles;
  const std::string first_limit = summary.first_limit;
  summary = Summarise(result->samples, options.summary_from_s);
  summary.limit_cycles = limit_cycles;
  summary.first_limit = first_limit;
  result->stats = plant->stats();
  result->seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return true;
}

double FeedEfficiencyLoss(double lateral_rms_m, double frequency_hz) {
  const double wavelength_m = kSpeedOfLightMPerS / frequency_hz;
  const double x = kTwoPi * kEfficiencyKappa * lateral_rms_m / wavelength_m;
  return 1.0 - std::exp(-x * x);
}

std::string LoopCsv(const LoopResult& result) {
  std::string out =
      "time_s,x_m,y_m,z_m,x_cmd_m,y_cmd_m,z_cmd_m,x_meas_m,y_meas_m,z_meas_m,error_mm,"
      "lateral_mm,axial_mm";
  for (int i = 1; i <= kNumCables; ++i) out += ",T" + std::to_string(i) + "_kN";
  for (int i = 1; i <= kNumCables; ++i) out += ",T" + std::to_string(i) + "_plan_kN";
  for (int i = 1; i <= kNumCables; ++i) out += ",s0_" + std::to_string(i) + "_m";
  out += "\n";
  const auto num = [](double v, const char* format) {
    return internal::WithoutNegativeZero(internal::FormatDouble(format, v));
  };
  for (const LoopSample& s : result.samples) {
    out += num(s.time_s, "%.6g");
    for (const Eigen::Vector3d& v : {s.pose.position_m, s.command.position_m, s.measured_m}) {
      for (int a = 0; a < 3; ++a) out += "," + num(v[a], "%.6f");
    }
    out += "," + num(s.error_m * 1e3, "%.4f") + "," + num(s.lateral_m * 1e3, "%.4f") + "," +
           num(s.axial_m * 1e3, "%.4f");
    for (double t : s.tension_n) out += "," + num(t / internal::kNPerKn, "%.6f");
    for (double t : s.planned_tension_n) out += "," + num(t / internal::kNPerKn, "%.6f");
    for (double l : s.s0_m) out += "," + num(l, "%.6f");
    out += "\n";
  }
  return out;
}

std::string LoopSummaryJson(const LoopResult& r, double frequency_hz) {
  const LoopSummary& s = r.summary;
  JsonWriter j;
  j.BeginObject();
  j.Key("format").String("fastcal-loop-1");
  j.Key("duration_s").Number(r.spec.DurationS());
  j.Key("samples").Int(s.samples);
  j.Key("summary_from_s").Number(r.options.summary_from_s);
  j.Key("error_rms_mm").Number(s.error_rms_m * 1e3);
  j.Key("error_peak_mm").Number(s.error_peak_m * 1e3);
  j.Key("lateral_rms_mm").Number(s.lateral_rms_m * 1e3);
  j.Key("lateral_peak_mm").Number(s.lateral_peak_m * 1e3);
  j.Key("axial_rms_mm").Number(s.axial_rms_m * 1e3);
  j.Key("axial_peak_mm").Number(s.axial_peak_m * 1e3);
  j.Key("tension_error_rms_kN").Number(s.tension_error_rms_n / internal::kNPerKn);
  j.Key("tension_error_peak_kN").Number(s.tension_error_peak_n / internal::kNPerKn);
  j.Key("winch_travel_m").Number(s.winch_travel_m);
  j.Key("limit_cycles").Int(s.limit_cycles);
  j.Key("first_limit").String(s.first_limit);
  j.Key("efficiency").BeginObject();
  j.Key("frequency_hz").Number(frequency_hz);
  j.Key("loss").Number(FeedEfficiencyLoss(s.lateral_rms_m, frequency_hz));
  j.Key("formula").String(
      "1 - exp(-(2 pi 0.466 lateral_rms / wavelength)^2): 10 mm RMS loses 8.2% at 3 GHz "
      "(Gan et al.)");
  j.EndObject();
  j.Key("controller").BeginObject();
  j.Key("control_period_s").Number(r.options.control_period_s);
  j.Key("kp").Number(r.options.kp);
  j.Key("ki_per_s").Number(r.options.ki_per_s);
  j.Key("kd_s").Number(r.options.kd_s);
  j.Key("error_filter_hz").Number(r.options.error_filter_hz);
  j.Key("measurement_noise_m").Number(r.options.measurement_noise_m);
  j.Key("measurement_delay_s").Number(r.options.measurement_delay_s);
  j.Key("max_winch_speed_m_per_s").Number(r.options.max_winch_speed_m_per_s);
  j.Key("max_winch_acceleration_m_per_s2").Number(r.options.max_winch_acceleration_m_per_s2);
  j.EndObject();
  j.Key("plant_start_offset_mm").Number(r.start.position_offset_m * 1e3);
  j.Key("steps").Int(r.stats.steps);
  j.Key("seconds").Number(r.seconds);
  j.EndObject();
  return j.str();
}

}  // namespace fastcal
