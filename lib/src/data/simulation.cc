// Synthetic telemetry from a truth model: attitude control error, pose and tension sensor
// noise, outliers, sensor gain and bias, per-cable density mismatch, length-encoder offsets
// and noise (model: simulation.h).
#include "fastcal/simulation.h"

#include <cmath>
#include <exception>
#include <random>

#include "fastcal/internal/fail.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/units.h"

namespace fastcal {
namespace {

using internal::kNPerKn;
// Redraws allowed for one reading or density before giving up: the noise must be absurd
// for one draw in a thousand to be acceptable.
constexpr int kMaxRedraws = 1000;

// Independent generator per error source, so each sigma affects only its own numbers.
enum Stream : std::uint64_t {
  kDensityStream = 0,
  kAttitudeControlStream,
  kAttitudeMeasurementStream,
  kPositionStream,
  kTensionNoiseStream,
  kOutlierStream,
  kTensionDriftStream,
  kMassCentreDriftStream,
  kSensorSpreadStream,
  kSensorRezeroStream,
  kLengthOffsetStream,
  kLengthNoiseStream,
};

using internal::Fail;

std::string Num(double value) { return internal::FormatDouble("%.10g", value); }

// SplitMix64 finaliser: spreads (seed, stream) over the generator's seed space.
std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Uniform and standard normal numbers from the raw 64-bit output of std::mt19937_64, the
// same with every standard library (std distributions are not).
class Random {
 public:
  Random(std::uint64_t seed, Stream stream) : engine_(MixSeed(seed, stream)) {}

  // Uniform in [0, 1).
  double Uniform01() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  // Standard normal, Box-Muller (pairs; the second value is kept for the next call).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - Uniform01();  // (0, 1]: log is finite
    const double u2 = Uniform01();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

  Eigen::Vector3d Normal3() {
    const double x = Normal();
    const double y = Normal();
    return Eigen::Vector3d(x, y, Normal());
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// A stationary AR(1) process (simulation.h): x_0 = s N(0, 1), then
// x_n = phi x_{n-1} + s sqrt(1 - phi^2) N(0, 1), phi = exp(-dt / tau), 0 for tau = 0.
class Ar1 {
 public:
  Ar1(double sigma, double time_s, double dt) : sigma_(sigma), time_s_(time_s), phi_(Phi(dt)) {}
  double Next(Random* rng) { return Step(rng, phi_); }
  // The next value `dt` after the last, not the sample interval (a gap between sessions).
  double NextAfter(Random* rng, double dt) { return Step(rng, Phi(dt)); }

 private:
  double Phi(double dt) const { return time_s_ > 0.0 ? std::exp(-dt / time_s_) : 0.0; }
  double Step(Random* rng, double phi) {
    const double xi = rng->Normal();
    x_ = first_ ? sigma_ * xi : phi * x_ + sigma_ * std::sqrt(1.0 - phi * phi) * xi;
    first_ = false;
    return x_;
  }
  double sigma_, time_s_, phi_;
  double x_ = 0.0;
  bool first_ = true;
};

// Three independent AR(1) processes, drawn x, y, z in turn.
class Ar1Vector {
 public:
  Ar1Vector(double sigma, double time_s, double dt)
      : x_{Ar1(sigma, time_s, dt), Ar1(sigma, time_s, dt), Ar1(sigma, time_s, dt)} {}
  Eigen::Vector3d Next(Random* rng) {
    const double a = x_[0].Next(rng);
    const double b = x_[1].Next(rng);
    return Eigen::Vector3d(a, b, x_[2].Next(rng));
  }
  Eigen::Vector3d NextAfter(Random* rng, double dt) {
    const double a = x_[0].NextAfter(rng, dt);
    const double b = x_[1].NextAfter(rng, dt);
    return Eigen::Vector3d(a, b, x_[2].NextAfter(rng, dt));
  }

 private:
  std::array<Ar1, 3> x_;
};

bool NonNegativeFinite(double v) { return std::isfinite(v) && v >= 0.0; }

// 1 + spread N(0, 1), redrawn while <= 0 (counted in *redrawn); false after kMaxRedraws.
bool PositiveFactor(double spread, Random* rng, int* redrawn, double* factor) {
  *factor = 0.0;
  for (int attempt = 0; !(*factor > 0.0); ++attempt) {
    if (attempt == kMaxRedraws) return false;
    if (attempt > 0) ++*redrawn;
    *factor = 1.0 + spread * rng->Normal();
  }
  return true;
}

// The truth model with what is drawn once: density mismatch, gain and bias spreads.
bool DrawTruthModel(const SimulationOptions& options, CableRobot* model, SimulationSummary* stats,
                    std::string* error) {
  Random density_rng(options.seed, kDensityStream);
  for (int i = 0; i < kNumCables; ++i) {
    double factor = 0.0;
    if (!PositiveFactor(options.density_mismatch_percent / 100.0, &density_rng, &stats->redrawn,
                        &factor)) {
      return Fail(error, "density_mismatch_percent " + Num(options.density_mismatch_percent) +
                             " keeps giving a density <= 0 for cable " + std::to_string(i + 1));
    }
    stats->density_factor[i] = factor;
    model->cables[i].linear_density_kg_per_m *= factor;
  }
  Random sensor_rng(options.seed, kSensorSpreadStream);
  for (int i = 0; i < kNumCables; ++i) {
    double factor = 0.0;
    if (!PositiveFactor(options.sensor_gain_spread_percent / 100.0, &sensor_rng, &stats->redrawn,
                        &factor)) {
      return Fail(error, "sensor_gain_spread_percent " + Num(options.sensor_gain_spread_percent) +
                             " keeps giving a gain <= 0 for cable " + std::to_string(i + 1));
    }
    model->cables[i].sensor_gain *= factor;
  }
  for (int i = 0; i < kNumCables; ++i) {
    model->cables[i].sensor_bias_n += options.sensor_bias_spread_kn * kNPerKn * sensor_rng.Normal();
  }
  Random length_rng(options.seed, kLengthOffsetStream);
  for (int i = 0; i < kNumCables; ++i) {
    model->cables[i].length_offset_m += options.length_offset_spread_m * length_rng.Normal();
    stats->length_offset_m[i] = model->cables[i].length_offset_m;
  }
  return true;
}

// Adding +0 turns -0 into +0 and changes nothing else: no "-0" angles in the CSV.
Eigen::Vector3d NoNegativeZero(const Eigen::Vector3d& v) { return (v.array() + 0.0).matrix(); }

std::string Vec(const Eigen::Vector3d& v) {
  return "(" + Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z()) + ")";
}

bool CheckInputs(const CableRobot& truth, const PoseStream& planned,
                 const SimulationOptions& options, std::string* error) {
  if (!options.IsValid(error)) return false;
  std::string why;
  if (!truth.IsValid(&why)) return Fail(error, "truth model: " + why);
  if (planned.count <= 0) return Fail(error, "no planned poses");
  if (options.actual_source && !truth.moving_parts.empty()) {
    return Fail(error, "actual_source: the truth model's moving parts are not simulated with it");
  }
  if (options.sessions > planned.count) {
    return Fail(error, std::to_string(options.sessions) + " sessions for " +
                           std::to_string(planned.count) + " poses: at most one per pose");
  }
  return true;
}

// The random processes along the run, one independent stream each (so that turning one
// on leaves the others' draws unchanged), and the sums of squares the summary reports.
struct Processes {
  explicit Processes(const SimulationOptions& o)
      : control_rng(o.seed, kAttitudeControlStream),
        attitude_rng(o.seed, kAttitudeMeasurementStream),
        position_rng(o.seed, kPositionStream),
        tension_rng(o.seed, kTensionNoiseStream),
        outlier_rng(o.seed, kOutlierStream),
        drift_rng(o.seed, kTensionDriftStream),
        mass_centre_rng(o.seed, kMassCentreDriftStream),
        rezero_rng(o.seed, kSensorRezeroStream),
        length_rng(o.seed, kLengthNoiseStream),
        control(o.attitude_control_sigma_deg, o.attitude_control_time_s, o.sample_interval_s),
        mass_centre_drift(o.mass_centre_drift_m, o.mass_centre_drift_time_s, o.sample_interval_s),
        tension_drift(kNumCables, Ar1(DriftSigma(o), o.tension_drift_time_s, o.sample_interval_s)) {
  }
  // The drift processes' sigma: the relative one (their values are fractions of the
  // reading), or 1 when only the absolute part is given (scaled by it), else 0.
  static double DriftSigma(const SimulationOptions& o) {
    if (o.tension_drift_percent > 0.0) return o.tension_drift_percent / 100.0;
    return o.tension_drift_kn > 0.0 ? 1.0 : 0.0;
  }
  Random control_rng, attitude_rng, position_rng, tension_rng, outlier_rng, drift_rng,
      mass_centre_rng, rezero_rng, length_rng;
  // The time since the previous sample (the interval, or more across a session gap).
  double dt = 0.0;
  // With mass_centre_drift_centred: the session's drift, drawn at its start (its mean
  // taken out), and the next sample's index in it.
  std::vector<Eigen::Vector3d> session_drift;
  size_t session_drift_next = 0;
  Ar1Vector control, mass_centre_drift;
  std::vector<Ar1> tension_drift;
  // Sums over the samples.
  Eigen::Vector3d mass_centre_sum = Eigen::Vector3d::Zero();
  double mass_centre_sq = 0.0, control_sq = 0.0, attitude_sq = 0.0, position_sq = 0.0;
  std::array<double, kNumCables> drift_sq{}, noise_sq{}, relative_sq{}, length_sq{};
};

// The actual pose of sample n (the planned one with the control error) and its statics
// with the model's mass centre drifted; *actual_rpy_deg for the measurement.
bool SolveActual(size_t n, const Pose& planned_pose, const Eigen::Vector3d& planned_rpy_deg,
                 const SimulationOptions& options, const Eigen::Vector3d& mass_centre_m,
                 const JointValues& joints, const StaticsOptions& statics, Processes* p,
                 CableRobot* model, Eigen::Vector3d* actual_rpy_deg, StaticsSolution* solution,
                 std::string* error) {
  const Eigen::Vector3d control_deg = p->control.NextAfter(&p->control_rng, p->dt);
  const Eigen::Vector3d drift_m = options.mass_centre_drift_centred
                                      ? p->session_drift[p->session_drift_next++]
                                      : p->mass_centre_drift.NextAfter(&p->mass_centre_rng, p->dt);
  model->mass_centre_cabin_m = mass_centre_m + drift_m;
  p->mass_centre_sum += model->mass_centre_cabin_m;
  p->mass_centre_sq += drift_m.squaredNorm();
  p->control_sq += control_deg.squaredNorm();
  *actual_rpy_deg = NoNegativeZero(planned_rpy_deg + control_deg);
  Pose actual;
  actual.position_m = planned_pose.position_m;
  actual.rotation =
      RotationFromRpyDeg((*actual_rpy_deg)[0], (*actual_rpy_deg)[1], (*actual_rpy_deg)[2]);
  if (SolveStatics(*model, actual, joints, statics, solution) == StaticsStatus::kOk) return true;
  std::string message =
      "node " + std::to_string(n) + " at position " + Vec(actual.position_m) + " m";
  if (options.attitude_control_sigma_deg > 0.0) {
    message += ", actual attitude rpy " + Vec(*actual_rpy_deg) + " deg";
  }
  return Fail(error, message + ": " + DescribeStatus(*solution) + " [truth model, method " +
                         StaticsMethodName(options.method) + "]");
}

// The actual state of sample n from options.actual_source: its time (and the time since
// the previous sample, for the slow processes), pose, and the tensions and lengths
// `solution` carries to MeasureTensions.
bool ActualFromSource(size_t n, const Pose& planned_pose, const SimulationOptions& options,
                      const CableRobot& model, double last_time_s, double* time_s, double* dt,
                      Eigen::Vector3d* position_m, Eigen::Vector3d* rpy_deg,
                      StaticsSolution* solution, std::string* error) {
  ActualSample a;
  if (!options.actual_source(static_cast<long long>(n), planned_pose, model, &a, error)) {
    return false;
  }
  *time_s = options.start_time_s + a.time_s;
  *dt = n == 0 ? options.sample_interval_s : std::max(*time_s - last_time_s, 0.0);
  *position_m = a.pose.position_m;
  *rpy_deg = NoNegativeZero(RpyDegFromRotation(a.pose.rotation));
  for (int i = 0; i < kNumCables; ++i) {
    solution->cables[i].lower_tension_n = a.lower_tension_n[i];
    solution->cables[i].unstretched_length_m = a.unstretched_length_m[i];
  }
  return true;
}

// The measured pose: the actual one with attitude and position noise.
void MeasurePose(const Eigen::Vector3d& position_m, const Eigen::Vector3d& actual_rpy_deg,
                 const SimulationOptions& options, Processes* p, Sample* s) {
  const Eigen::Vector3d attitude_noise_deg =
      options.attitude_measurement_sigma_deg * p->attitude_rng.Normal3();
  s->measured_rpy_deg = NoNegativeZero(actual_rpy_deg + attitude_noise_deg);
  s->pose.rotation =
      RotationFromRpyDeg(s->measured_rpy_deg[0], s->measured_rpy_deg[1], s->measured_rpy_deg[2]);
  const Eigen::Vector3d position_noise_m =
      options.position_measurement_sigma_m * p->position_rng.Normal3();
  s->pose.position_m = NoNegativeZero(position_m + position_noise_m);
  p->attitude_sq += attitude_noise_deg.squaredNorm();
  p->position_sq += position_noise_m.squaredNorm();
}

// Where the truth model declares a measured frame (measured_frame.h (1)-(2)), the pose
// sensors see that frame: the planned attitude and the actual position and attitude
// become its own, at the sample's joints. The cabin's are left as they are without one.
void ToDataFrame(const CableRobot& model, const Pose& planned_pose, Eigen::Vector3d* position_m,
                 Eigen::Vector3d* actual_rpy_deg, Sample* s) {
  if (!model.measured_frame.has_value()) return;
  const Pose planned = model.MeasuredPose(planned_pose, s->joint);
  s->planned_rpy_deg = NoNegativeZero(RpyDegFromRotation(planned.rotation));
  s->planned_rotation =
      RotationFromRpyDeg(s->planned_rpy_deg[0], s->planned_rpy_deg[1], s->planned_rpy_deg[2]);
  Pose actual;
  actual.position_m = *position_m;
  actual.rotation =
      RotationFromRpyDeg((*actual_rpy_deg)[0], (*actual_rpy_deg)[1], (*actual_rpy_deg)[2]);
  const Pose data = model.MeasuredPose(actual, s->joint);
  *position_m = data.position_m;
  *actual_rpy_deg = RpyDegFromRotation(data.rotation);
}

double SlowErrorN(const SimulationOptions& o, double reading_n, double drift) {
  if (!(o.tension_drift_kn > 0.0)) return reading_n * drift;
  const double relative = o.tension_drift_percent / 100.0;
  const double sigma_n = std::hypot(o.tension_drift_kn * kNPerKn, relative * reading_n);
  // drift = relative u, or u itself (sigma 1) without a relative part.
  return sigma_n * (relative > 0.0 ? drift / relative : drift);
}

// The six readings of sample n: the sensor's reading of the true tension, with the slow
// drift and the noise, or an outlier; the encoder's reading of s0 alongside (offset and
// noise).
bool MeasureTensions(size_t n, const CableRobot& model, const StaticsSolution& solution,
                     const SimulationOptions& options, Processes* p, SimulationSummary* stats,
                     Sample* s, std::string* error) {
  s->has_unstretched_lengths = true;
  for (int i = 0; i < kNumCables; ++i) {
    const double reading_n = model.cables[i].SensorReadingN(solution.cables[i].lower_tension_n);
    if (!(reading_n > 0.0)) {
      return Fail(error, "node " + std::to_string(n) + ", cable " + std::to_string(i + 1) +
                             ": sensor reading gain * tension + bias = " +
                             Num(reading_n / kNPerKn) + " kN is not > 0 (check the bias)");
    }
    const double drift = p->tension_drift[i].NextAfter(&p->drift_rng, p->dt);
    // The slow error in newtons: drift * reading when it is relative only (the same
    // numbers as before the absolute part existed), else sigma_e(reading) u with u the
    // standardised process and sigma_e^2 = abs^2 + (pct/100 reading)^2 (slow_error.h).
    const double slow_n = SlowErrorN(options, reading_n, drift);
    const double slow_relative = options.tension_drift_kn > 0.0 ? slow_n / reading_n : drift;
    p->drift_sq[i] += slow_relative * slow_relative;
    // Both draws are made for every reading, outlier or not, to keep streams aligned.
    const bool outlier = p->outlier_rng.Uniform01() < options.outlier_fraction;
    const double outlier_u = 2.0 * p->outlier_rng.Uniform01() - 1.0;
    double measured_n = 0.0;
    for (int attempt = 0; !(measured_n > 0.0); ++attempt) {
      if (attempt == kMaxRedraws) {
        return Fail(error, "node " + std::to_string(n) + ", cable " + std::to_string(i + 1) +
                               ": the tension noise keeps making the reading <= 0");
      }
      if (attempt > 0) ++stats->redrawn;
      const double relative = options.tension_noise_percent / 100.0 * p->tension_rng.Normal();
      const double absolute_n = options.tension_noise_kn * kNPerKn * p->tension_rng.Normal();
      measured_n = outlier ? reading_n * (1.0 + options.outlier_scale_percent / 100.0 * outlier_u)
                   : options.tension_drift_kn > 0.0
                       ? reading_n * (1.0 + relative) + slow_n + absolute_n
                       : reading_n * (1.0 + relative + drift) + absolute_n;
    }
    s->tension_n[i] = measured_n;
    const double length_noise_m = options.length_noise_m * p->length_rng.Normal();
    s->unstretched_length_m[i] =
        model.cables[i].EncoderReadingM(solution.cables[i].unstretched_length_m) + length_noise_m;
    p->length_sq[i] += length_noise_m * length_noise_m;
    if (!(s->unstretched_length_m[i] > 0.0)) {
      return Fail(error, "node " + std::to_string(n) + ", cable " + std::to_string(i + 1) +
                             ": the length reading s0 + offset + noise = " +
                             Num(s->unstretched_length_m[i]) + " m is not > 0");
    }
    stats->outliers[i] += outlier ? 1 : 0;
    p->noise_sq[i] += (measured_n - reading_n) * (measured_n - reading_n);
    p->relative_sq[i] += (measured_n / reading_n - 1.0) * (measured_n / reading_n - 1.0);
  }
  return true;
}

// The RMS figures of the summary from the sums over `count` samples.
void Summarise(const Processes& p, double count, SimulationSummary* stats) {
  for (int i = 0; i < kNumCables; ++i) {
    stats->tension_noise_rms_n[i] = std::sqrt(p.noise_sq[i] / count);
    stats->tension_noise_rms_relative[i] = std::sqrt(p.relative_sq[i] / count);
    stats->tension_drift_rms_relative[i] = std::sqrt(p.drift_sq[i] / count);
    stats->length_noise_rms_m[i] = std::sqrt(p.length_sq[i] / count);
  }
  stats->mass_centre_mean_m = p.mass_centre_sum / count;
  stats->mass_centre_drift_rms_m = std::sqrt(p.mass_centre_sq / (3.0 * count));
  stats->attitude_control_rms_deg = std::sqrt(p.control_sq / (3.0 * count));
  stats->attitude_measurement_rms_deg = std::sqrt(p.attitude_sq / (3.0 * count));
  stats->position_measurement_rms_m = std::sqrt(p.position_sq / (3.0 * count));
}

// With mass_centre_drift_centred, at the first sample of a session of `count` samples: its
// drift drawn (the process goes on from the session before, across the gap `gap_s`) and
// its mean over the session taken out.
void DrawSessionDrift(const SimulationOptions& options, long long count, double gap_s,
                      Processes* p) {
  p->session_drift.assign(static_cast<size_t>(count), Eigen::Vector3d::Zero());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (long long k = 0; k < count; ++k) {
    const double dt = k == 0 ? options.sample_interval_s + gap_s : options.sample_interval_s;
    p->session_drift[k] = p->mass_centre_drift.NextAfter(&p->mass_centre_rng, dt);
    mean += p->session_drift[k] / static_cast<double>(count);
  }
  for (Eigen::Vector3d& d : p->session_drift) d -= mean;
  p->session_drift_next = 0;
}

// The samples of session `session` of `sessions` over `count` (as SimulateImpl cuts them:
// sample n is in session floor(n sessions / count)).
long long SessionSamples(long long count, int sessions, int session) {
  const auto first = [&](int k) {
    return (static_cast<long long>(k) * count + sessions - 1) / sessions;
  };
  return first(session + 1) - first(session);
}

// The sum of the mass-centre steps at or before time t.
Eigen::Vector3d StepShiftAt(const SimulationOptions& options, double t) {
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (const MassCentreStep& step : options.mass_centre_steps) {
    if (step.time_s <= t) shift += step.shift_m;
  }
  return shift;
}

std::array<double, kNumCables> SensorBiases(const CableRobot& model) {
  std::array<double, kNumCables> bias{};
  for (int i = 0; i < kNumCables; ++i) bias[i] = model.cables[i].sensor_bias_n;
  return bias;
}

// A maintenance between sessions: each sensor re-zeroed, its bias moved by
// N(0, sensor_rezero_kn) (drawn whether or not the spread is 0, to keep streams aligned).
void ReZeroSensors(const SimulationOptions& options, int session, Processes* p, CableRobot* model,
                   SimulationSummary* stats) {
  for (int i = 0; i < kNumCables; ++i) {
    model->cables[i].sensor_bias_n += options.sensor_rezero_kn * kNPerKn * p->rezero_rng.Normal();
  }
  stats->session_bias_n.resize(session + 1, SensorBiases(*model));
}

// The single sensors re-zeroed at or before time t that were not yet.
void ApplySensorSteps(const SimulationOptions& options, double t, std::vector<bool>* applied,
                      CableRobot* model) {
  for (size_t k = 0; k < options.sensor_bias_steps.size(); ++k) {
    const SensorBiasStep& step = options.sensor_bias_steps[k];
    if ((*applied)[k] || step.time_s > t) continue;
    model->cables[step.cable].sensor_bias_n += step.shift_n;
    (*applied)[k] = true;
  }
}

// Stages: check the inputs, draw the truth model, then per planned pose the actual pose
// and its statics, the measured pose and the readings; last the summary.
bool SimulateImpl(const CableRobot& truth, PoseStream& planned, const SimulationOptions& options,
                  const SampleSink& sink, CableRobot* truth_used, SimulationSummary* summary,
                  std::string* error) {
  if (!CheckInputs(truth, planned, options, error)) return false;
  SimulationSummary stats;
  stats.samples = static_cast<int>(planned.count);
  CableRobot model = truth;
  if (!DrawTruthModel(options, &model, &stats, error)) return false;
  const Eigen::Vector3d mass_centre_m = model.mass_centre_cabin_m;
  Processes processes(options);

  // Synthetic truth: converged per-cable solves, as a fit uses, plus s0.
  StaticsOptions statics = ModelFitStaticsOptions(options.method);
  statics.compute_unstretched_lengths = true;
  // Consecutive nodes are usually close; a failed warm start is retried cold.
  statics.warm_start = true;
  StaticsSolution solution;
  const CableRobot first_session = model;  // the truth written out: the first session's
  stats.session_bias_n.push_back(SensorBiases(model));
  int session = 0;
  std::vector<bool> applied_sensor_steps(options.sensor_bias_steps.size(), false);
  JointPlan joint_plan;
  if (!JointPlan::Make(model.moving_parts, options.joints, &joint_plan, error)) return false;
  double last_time_s = 0.0;  // the previous sample's (an actual source's times are its own)

  for (size_t n = 0; n < static_cast<size_t>(planned.count); ++n) {
    const Pose planned_pose = planned.next();
    if (!IsFinite(planned_pose)) {
      return Fail(error, "planned pose of node " + std::to_string(n) + " is not finite");
    }
    Sample s;
    // Consecutive equal sessions, labelled "1" .. "N" (SimulatedDatasetLayout), each
    // session_gap_s after the previous one's end; the sensors re-zeroed at its start.
    if (options.sessions > 1) {
      s.session = static_cast<int>(static_cast<long long>(n) * options.sessions / planned.count);
    }
    const bool new_session = n > 0 && s.session != session;
    if (new_session) ReZeroSensors(options, s.session, &processes, &model, &stats);
    session = s.session;
    s.time_s = options.start_time_s + static_cast<double>(n) * options.sample_interval_s +
               session * options.session_gap_s;
    ApplySensorSteps(options, s.time_s, &applied_sensor_steps, &model);
    processes.dt = options.sample_interval_s + (new_session ? options.session_gap_s : 0.0);
    if (options.mass_centre_drift_centred && (n == 0 || new_session)) {
      DrawSessionDrift(options,
                       SessionSamples(planned.count, std::max(1, options.sessions), session),
                       n == 0 ? 0.0 : options.session_gap_s, &processes);
    }
    s.has_planned_attitude = true;
    s.planned_rpy_deg = NoNegativeZero(RpyDegFromRotation(planned_pose.rotation));
    s.planned_rotation =
        RotationFromRpyDeg(s.planned_rpy_deg[0], s.planned_rpy_deg[1], s.planned_rpy_deg[2]);
    if (!model.moving_parts.empty() &&
        !joint_plan.Next(static_cast<long long>(n), planned_pose, &s.joint, error)) {
      return false;
    }
    Eigen::Vector3d actual_rpy_deg;
    Eigen::Vector3d actual_position_m = planned_pose.position_m;
    if (options.actual_source) {
      if (!ActualFromSource(n, planned_pose, options, model, last_time_s, &s.time_s, &processes.dt,
                            &actual_position_m, &actual_rpy_deg, &solution, error)) {
        return false;
      }
    } else if (!SolveActual(n, planned_pose, s.planned_rpy_deg, options,
                            mass_centre_m + StepShiftAt(options, s.time_s), s.joint, statics,
                            &processes, &model, &actual_rpy_deg, &solution, error)) {
      return false;
    }
    ToDataFrame(model, planned_pose, &actual_position_m, &actual_rpy_deg, &s);
    MeasurePose(actual_position_m, actual_rpy_deg, options, &processes, &s);
    if (!MeasureTensions(n, model, solution, options, &processes, &stats, &s, error)) return false;
    last_time_s = s.time_s;
    if (!sink(s, error)) return false;
  }
  Summarise(processes, static_cast<double>(planned.count), &stats);
  for (int i = 0; i < kNumCables; ++i) {
    model.cables[i].sensor_bias_n = first_session.cables[i].sensor_bias_n;
  }
  model.mass_centre_cabin_m = mass_centre_m;  // the truth written out: the mean

  if (truth_used != nullptr) *truth_used = std::move(model);
  if (summary != nullptr) *summary = stats;
  return true;
}

}  // namespace

bool SimulationOptions::IsValid(std::string* error) const {
  const struct {
    const char* name;
    double value;
  } non_negative[] = {
      {"attitude_control_sigma_deg", attitude_control_sigma_deg},
      {"attitude_control_time_s", attitude_control_time_s},
      {"tension_drift_percent", tension_drift_percent},
      {"tension_drift_time_s", tension_drift_time_s},
      {"tension_drift_kn", tension_drift_kn},
      {"session_gap_s", session_gap_s},
      {"sensor_rezero_kn", sensor_rezero_kn},
      {"mass_centre_drift_m", mass_centre_drift_m},
      {"mass_centre_drift_time_s", mass_centre_drift_time_s},
      {"sensor_gain_spread_percent", sensor_gain_spread_percent},
      {"sensor_bias_spread_kn", sensor_bias_spread_kn},
      {"attitude_measurement_sigma_deg", attitude_measurement_sigma_deg},
      {"position_measurement_sigma_m", position_measurement_sigma_m},
      {"tension_noise_percent", tension_noise_percent},
      {"tension_noise_kn", tension_noise_kn},
      {"density_mismatch_percent", density_mismatch_percent},
      {"length_offset_spread_m", length_offset_spread_m},
      {"length_noise_m", length_noise_m},
  };
  for (const auto& f : non_negative) {
    if (!NonNegativeFinite(f.value)) {
      return Fail(error,
                  std::string(f.name) + " must be finite and >= 0 (got " + Num(f.value) + ")");
    }
  }
  if (!(outlier_fraction >= 0.0 && outlier_fraction <= 1.0)) {
    return Fail(error, "outlier_fraction must be in [0, 1] (got " + Num(outlier_fraction) + ")");
  }
  if (!(outlier_scale_percent >= 0.0 && outlier_scale_percent < 100.0)) {
    return Fail(error, "outlier_scale_percent must be in [0, 100) (got " +
                           Num(outlier_scale_percent) + ")");
  }
  for (const MassCentreStep& step : mass_centre_steps) {
    if (!std::isfinite(step.time_s) || !step.shift_m.allFinite()) {
      return Fail(error, "mass_centre_steps: a step's time and shift must be finite");
    }
  }
  for (const SensorBiasStep& step : sensor_bias_steps) {
    if (!std::isfinite(step.time_s) || !std::isfinite(step.shift_n) || step.cable < 0 ||
        step.cable >= kNumCables) {
      return Fail(error,
                  "sensor_bias_steps: a step needs a finite time and shift and a cable 0..5");
    }
  }
  if (!std::isfinite(start_time_s)) {
    return Fail(error, "start_time_s must be finite (got " + Num(start_time_s) + ")");
  }
  if (sessions < 1)
    return Fail(error, "sessions must be >= 1 (got " + std::to_string(sessions) + ")");
  if (!(std::isfinite(sample_interval_s) && sample_interval_s > 0.0)) {
    return Fail(error,
                "sample_interval_s must be finite and > 0 (got " + Num(sample_interval_s) + ")");
  }
  if (actual_source && (attitude_control_sigma_deg > 0.0 || mass_centre_drift_m > 0.0 ||
                        !mass_centre_steps.empty() || !sensor_bias_steps.empty() || sessions > 1)) {
    return Fail(error,
                "actual_source: the actual state and the times come from it, so no attitude "
                "control error, mass-centre drift or steps, sensor steps, and one session");
  }
  return true;
}

Dataset SimulatedDatasetLayout(int sessions, const std::vector<std::string>& joint_columns) {
  Dataset layout;
  layout.joint_columns = joint_columns;
  for (int k = 1; sessions > 1 && k <= sessions; ++k) {
    layout.session_labels.push_back(std::to_string(k));
  }
  layout.path = "simulation";
  layout.has_planned_attitude = true;
  layout.has_unstretched_lengths = true;
  layout.attitude_as_quaternion = false;
  return layout;
}

bool SimulateStream(const CableRobot& truth, PoseStream planned, const SimulationOptions& options,
                    const SampleSink& sink, CableRobot* truth_used, SimulationSummary* summary,
                    std::string* error) {
  std::string message;
  try {
    if (SimulateImpl(truth, planned, options, sink, truth_used, summary, &message)) return true;
  } catch (const std::exception& e) {
    message = std::string("simulation failed: ") + e.what();
  }
  return Fail(error, message);
}

bool SimulateStream(const CableRobot& truth, const std::vector<Pose>& planned,
                    const SimulationOptions& options, const SampleSink& sink,
                    CableRobot* truth_used, SimulationSummary* summary, std::string* error) {
  // Every pose checked before the first sample is handed over, as before streams.
  for (size_t n = 0; n < planned.size(); ++n) {
    if (!IsFinite(planned[n]) && options.IsValid(nullptr) && truth.IsValid(nullptr) &&
        static_cast<size_t>(options.sessions) <= planned.size()) {
      return Fail(error, "planned pose of node " + std::to_string(n) + " is not finite");
    }
  }
  PoseStream stream;
  stream.count = static_cast<long long>(planned.size());
  stream.next = [&planned, n = size_t{0}]() mutable { return planned[n++]; };
  return SimulateStream(truth, std::move(stream), options, sink, truth_used, summary, error);
}

bool Simulate(const CableRobot& truth, const std::vector<Pose>& planned,
              const SimulationOptions& options, Dataset* dataset, CableRobot* truth_used,
              SimulationSummary* summary, std::string* error) {
  Dataset out = SimulatedDatasetLayout(options.sessions, truth.moving_parts.JointColumns());
  out.samples.reserve(planned.size());
  const SampleSink keep = [&out](const Sample& s, std::string*) {
    out.samples.push_back(s);
    return true;
  };
  if (!SimulateStream(truth, planned, options, keep, truth_used, summary, error)) return false;
  if (dataset != nullptr) *dataset = std::move(out);
  return true;
}

}  // namespace fastcal
