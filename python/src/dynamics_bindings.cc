// The dynamics in time (dynamics_run.h) on numpy arrays: a start pose, what the winches do
// (a move, a table of lengths, or nothing after a displacement) and the model's options
// in; the record's columns (as `fastcal dynamics` writes them) and its summary JSON out.
// The closed loop (closed_loop.h): the same start (and a slew's end), the controller's
// options in; the record as `fastcal loop` writes it and its summary JSON out.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "bindings.h"
#include "fastcal/closed_loop.h"
#include "fastcal/dynamics_run.h"

namespace fastcal::python {
namespace {

// The record's columns, named as the command line's CSV (docs/cli.md, "dynamics").
py::dict RecordColumns(const DynamicsRunResult& r) {
  const py::ssize_t n = static_cast<py::ssize_t>(r.samples.size());
  DoubleArray time = NewArray({n}), pose = NewArray({n, 6}), tension = NewArray({n, 6}),
              qs_pose = NewArray({n, 6}), qs_tension = NewArray({n, 6}), s0 = NewArray({n, 6}),
              wind = NewArray({n});
  for (py::ssize_t k = 0; k < n; ++k) {
    const DynamicsSample& s = r.samples[static_cast<size_t>(k)];
    time.mutable_at(k) = s.time_s;
    wind.mutable_at(k) = s.wind_speed_m_per_s;
    const Eigen::Vector3d rpy = RpyDegFromRotation(s.pose.rotation);
    const Eigen::Vector3d qs_rpy = RpyDegFromRotation(s.quasi_static_pose.rotation);
    for (int j = 0; j < 3; ++j) {
      pose.mutable_at(k, j) = s.pose.position_m[j];
      pose.mutable_at(k, 3 + j) = rpy[j];
      qs_pose.mutable_at(k, j) = s.quasi_static_pose.position_m[j];
      qs_pose.mutable_at(k, 3 + j) = qs_rpy[j];
    }
    for (int i = 0; i < kNumCables; ++i) {
      tension.mutable_at(k, i) = s.tension_n[i] / kNPerKn;
      qs_tension.mutable_at(k, i) = s.quasi_static_tension_n[i] / kNPerKn;
      s0.mutable_at(k, i) = s.s0_m[i];
    }
  }
  py::dict out;
  out["time_s"] = time;
  out["pose"] = pose;
  out["tension_kN"] = tension;
  out["quasi_static_pose"] = qs_pose;
  out["quasi_static_tension_kN"] = qs_tension;
  out["s0_m"] = s0;
  out["wind_m_per_s"] = wind;
  out["summary_json"] = DynamicsSummaryJson(r);
  return out;
}

// The focal law from its centre ((1, 3)) and tilt fraction; InputError for a wrong shape.
FocalAttitudeLaw FocalLawOf(const DoubleArray& focal_centre_m, double tilt_fraction) {
  FocalAttitudeLaw law;
  law.tilt_fraction = tilt_fraction;
  CheckRows(focal_centre_m, 3, "focal_centre");
  law.focal_centre_m =
      Eigen::Vector3d(focal_centre_m.at(0, 0), focal_centre_m.at(0, 1), focal_centre_m.at(0, 2));
  return law;
}

// What the winches do (a "move", "lengths" or a "decay") into `spec`; InputError for a
// wrong shape.
void WinchesFromArguments(const std::string& kind, const DoubleArray& end_m,
                          const std::string& end_kind, const DoubleArray& end_attitude, bool focal,
                          const DoubleArray& focal_centre_m, double tilt_fraction, double move_s,
                          const DoubleArray& lengths_time_s, const DoubleArray& lengths_s0_m,
                          const DoubleArray& offset, DynamicsRunSpec* spec_out) {
  DynamicsRunSpec& spec = *spec_out;
  if (kind == "move") {
    spec.kind = DynamicsRunSpec::Kind::kMove;
    spec.move_s = move_s;
    // "same": the start's attitude throughout (as the command line without --to-rpy).
    spec.end = PosesFromArrays(end_m, end_kind == "same" ? "none" : end_kind, end_attitude)[0];
    if (end_kind == "same") spec.end.rotation = spec.start.rotation;
    if (focal) spec.focal_law = FocalLawOf(focal_centre_m, tilt_fraction);
  } else if (kind == "lengths") {
    spec.kind = DynamicsRunSpec::Kind::kLengths;
    CheckRows(lengths_s0_m, kNumCables, "lengths (s0_1_m .. s0_6_m)");
    const py::ssize_t rows = lengths_s0_m.shape(0);
    if (lengths_time_s.ndim() != 1 || lengths_time_s.shape(0) != rows) {
      throw InputError("lengths: time_s must have one value per row");
    }
    for (py::ssize_t k = 0; k < rows; ++k) {
      spec.lengths.time_s.push_back(lengths_time_s.at(k));
      std::array<double, kNumCables> s0{};
      for (int i = 0; i < kNumCables; ++i) s0[i] = lengths_s0_m.at(k, i);
      spec.lengths.s0_m.push_back(s0);
    }
  } else {
    spec.kind = DynamicsRunSpec::Kind::kFreeDecay;
    CheckRows(offset, 6, "initial_offset");
    spec.offset_m = Eigen::Vector3d(offset.at(0, 0), offset.at(0, 1), offset.at(0, 2));
    spec.rotation_deg = Eigen::Vector3d(offset.at(0, 3), offset.at(0, 4), offset.at(0, 5));
  }
}

// The loop's options from the arguments; InputError for invalid ones.
LoopOptions LoopOptionsOf(double kp, double ki, double kd, double filter_hz, double period_s,
                          double noise_m, double delay_s, double max_speed, double max_acceleration,
                          double summary_from_s, std::uint64_t seed) {
  LoopOptions o;
  o.kp = kp;
  o.ki_per_s = ki;
  o.kd_s = kd;
  o.error_filter_hz = filter_hz;
  o.control_period_s = period_s;
  o.measurement_noise_m = noise_m;
  o.measurement_delay_s = delay_s;
  o.max_winch_speed_m_per_s = max_speed;
  o.max_winch_acceleration_m_per_s2 = max_acceleration;
  o.summary_from_s = summary_from_s;
  o.seed = seed;
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  return o;
}

DynamicsOptions PlantOptions(int segments, double damping_ratio, double step_s, double wind_speed,
                             double wind_direction_deg, const std::string& gust_spectrum,
                             double intensity, std::uint64_t seed) {
  DynamicsOptions options;
  options.segments = segments;
  options.damping_ratio = damping_ratio;
  options.max_step_s = step_s;
  options.wind.mean_speed_m_per_s = wind_speed;
  options.wind.direction_deg = wind_direction_deg;
  options.wind.turbulence_intensity = intensity;
  options.wind.seed = seed;
  if (!ParseGustSpectrum(gust_spectrum, &options.wind.spectrum)) {
    throw InputError("gust_spectrum must be 'kaimal' or 'davenport', got '" + gust_spectrum + "'");
  }
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  return options;
}

// fastcal.loop.
void BindLoop(py::module_& m) {
  m.def(
      "loop",
      [](const CableRobot& truth_argument, const CableRobot& controller_argument,
         const DoubleArray& start_m, const std::string& attitude_kind, const DoubleArray& attitude,
         bool has_end, const DoubleArray& end_m, const std::string& end_kind,
         const DoubleArray& end_attitude, bool focal, const DoubleArray& focal_centre_m,
         double tilt_fraction, double move_s, double hold_s, double kp, double ki, double kd,
         double filter_hz, double period_s, double noise_m, double delay_s, double max_speed,
         double max_acceleration, double summary_from_s, int segments, double damping_ratio,
         double step_s, double wind_speed, double wind_direction_deg,
         const std::string& gust_spectrum, double intensity, std::uint64_t seed,
         double frequency_hz) {
        // Copies with the GIL held (issue 37): another thread may change the models.
        const CableRobot truth = truth_argument;
        const CableRobot controller = controller_argument;
        ValidateModel(truth);
        ValidateModel(controller);
        const std::vector<Pose> start = PosesFromArrays(start_m, attitude_kind, attitude);
        if (start.size() != 1) throw InputError("loop takes one start pose");
        LoopSpec spec;
        spec.start = start[0];
        spec.hold_s = hold_s;
        if (focal) spec.focal_law = FocalLawOf(focal_centre_m, tilt_fraction);
        if (has_end) {
          spec.move_s = move_s;
          Pose end =
              PosesFromArrays(end_m, end_kind == "same" ? "none" : end_kind, end_attitude)[0];
          if (end_kind == "same") end.rotation = spec.start.rotation;
          if (focal) end.rotation = FocalAttitude(end.position_m, *spec.focal_law);
          spec.end = end;
        }
        if (!(frequency_hz > 0.0) || !std::isfinite(frequency_hz)) {
          throw InputError("frequency_ghz must be > 0");
        }
        const LoopOptions options =
            LoopOptionsOf(kp, ki, kd, filter_hz, period_s, noise_m, delay_s, max_speed,
                          max_acceleration, summary_from_s, seed);
        const DynamicsOptions plant =
            PlantOptions(segments, damping_ratio, step_s, wind_speed, wind_direction_deg,
                         gust_spectrum, intensity, seed);
        std::string error;
        if (!spec.IsValid(&error)) throw InputError(error);
        LoopResult result;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = RunLoop(truth, controller, spec, options, plant, &result, &error);
        }
        if (!ok) throw std::runtime_error(error);
        py::dict out;
        out["csv"] = LoopCsv(result);
        out["summary_json"] = LoopSummaryJson(result, frequency_hz);
        return out;
      },
      py::arg("truth"), py::arg("controller"), py::arg("start_m"), py::arg("attitude_kind"),
      py::arg("attitude"), py::arg("has_end"), py::arg("end_m"), py::arg("end_kind"),
      py::arg("end_attitude"), py::arg("focal"), py::arg("focal_centre_m"),
      py::arg("tilt_fraction"), py::arg("move_s"), py::arg("hold_s"), py::arg("kp"), py::arg("ki"),
      py::arg("kd"), py::arg("filter_hz"), py::arg("period_s"), py::arg("noise_m"),
      py::arg("delay_s"), py::arg("max_speed"), py::arg("max_acceleration"),
      py::arg("summary_from_s"), py::arg("segments"), py::arg("damping_ratio"), py::arg("step_s"),
      py::arg("wind_speed"), py::arg("wind_direction_deg"), py::arg("gust_spectrum"),
      py::arg("intensity"), py::arg("seed"), py::arg("frequency_hz"));
}

// fastcal.dynamics.
void BindDynamicsRun(py::module_& m) {
  m.def(
      "dynamics",
      [](const CableRobot& model_argument, const DoubleArray& start_m,
         const std::string& attitude_kind, const DoubleArray& attitude, const std::string& kind,
         const DoubleArray& end_m, const std::string& end_kind, const DoubleArray& end_attitude,
         bool focal, const DoubleArray& focal_centre_m, double tilt_fraction, double move_s,
         const DoubleArray& lengths_time_s, const DoubleArray& lengths_s0_m,
         const DoubleArray& offset, double hold_s, double rate_hz, double settle_fraction,
         int segments, double damping_ratio, double step_s, double wind_speed,
         double wind_direction_deg, const std::string& gust_spectrum, double intensity,
         std::uint64_t seed) {
        const CableRobot robot = model_argument;  // a copy with the GIL held (issue 37)
        ValidateModel(robot);
        const std::vector<Pose> start = PosesFromArrays(start_m, attitude_kind, attitude);
        if (start.size() != 1) throw InputError("dynamics takes one start pose");
        DynamicsRunSpec spec;
        spec.start = start[0];
        spec.hold_s = hold_s;
        spec.rate_hz = rate_hz;
        spec.settle_fraction = settle_fraction;
        WinchesFromArguments(kind, end_m, end_kind, end_attitude, focal, focal_centre_m,
                             tilt_fraction, move_s, lengths_time_s, lengths_s0_m, offset, &spec);
        const DynamicsOptions options =
            PlantOptions(segments, damping_ratio, step_s, wind_speed, wind_direction_deg,
                         gust_spectrum, intensity, seed);
        std::string error;
        if (!spec.IsValid(&error)) throw InputError(error);
        DynamicsRunResult result;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = RunDynamics(robot, spec, options, &result, &error);
        }
        if (!ok) throw std::runtime_error(error);
        return RecordColumns(result);
      },
      py::arg("model"), py::arg("start_m"), py::arg("attitude_kind"), py::arg("attitude"),
      py::arg("kind"), py::arg("end_m"), py::arg("end_kind"), py::arg("end_attitude"),
      py::arg("focal"), py::arg("focal_centre_m"), py::arg("tilt_fraction"), py::arg("move_s"),
      py::arg("lengths_time_s"), py::arg("lengths_s0_m"), py::arg("offset"), py::arg("hold_s"),
      py::arg("rate_hz"), py::arg("settle_fraction"), py::arg("segments"), py::arg("damping_ratio"),
      py::arg("step_s"), py::arg("wind_speed"), py::arg("wind_direction_deg"),
      py::arg("gust_spectrum"), py::arg("intensity"), py::arg("seed"));
}

}  // namespace

void BindDynamics(py::module_& m) {
  BindLoop(m);
  BindDynamicsRun(m);
}

}  // namespace fastcal::python
