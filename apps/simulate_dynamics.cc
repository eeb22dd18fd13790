// `fastcal simulate --dynamics`: the survey flown in time (dynamic_survey.h) instead of the
// cabin standing at each planned pose in its statics: the samples' poses, tensions, lengths
// and times come from the dynamics, then the same sensors' errors as any simulation.
#include <gflags/gflags.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/dynamic_survey.h"

DEFINE_bool(dynamics, false, "simulate: fly the survey in time (docs/cli.md, simulate).");
DEFINE_double(wait_s, 30.0, "simulate --dynamics: the wait after each move (s).");
DEFINE_double(min_move_s, 10.0, "simulate --dynamics: the shortest move (s).");
DEFINE_string(waits, "",
              "simulate --dynamics: a design.json whose stops' settle.wait_s are the waits "
              "after the moves (instead of --wait-s).");

namespace fastcal::cli {
namespace {

// The waits after the moves from a design.json (`fastcal design`): stops[k].settle.wait_s
// for k >= 1 (the first stop has no move before it). False with *error naming the file
// and what is missing.
bool WaitsFromDesign(const std::string& path, std::vector<double>* waits, std::string* error) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    *error = "--waits=" + path + ": " +
             (e.mark.line >= 0 ? "line " + std::to_string(e.mark.line + 1) + ": " : "") + e.msg;
    return false;
  }
  const YAML::Node stops = root["stops"];
  if (!stops || !stops.IsSequence() || stops.size() < 1) {
    *error = "--waits=" + path + ": no stops[] (a design.json that fastcal design wrote)";
    return false;
  }
  waits->clear();
  for (size_t k = 1; k < stops.size(); ++k) {
    const YAML::Node wait = stops[k]["settle"]["wait_s"];
    double value = 0.0;
    try {
      value = wait ? wait.as<double>() : -1.0;
    } catch (const YAML::Exception&) {
      value = -1.0;
    }
    if (!(value >= 0.0) || !std::isfinite(value)) {
      *error = "--waits=" + path + ": stops[" + std::to_string(k) +
               "].settle.wait_s is missing or not a number >= 0 (a design made with "
               "--speed-m-per-s has them)";
      return false;
    }
    waits->push_back(value);
  }
  return true;
}

}  // namespace

const std::set<std::string>& SimulateDynamicsFlags() {
  static const std::set<std::string> flags = {
      "dynamics", "wait-s",        "min-move-s",           "speed-m-per-s", "wind",  "waits",
      "segments", "damping-ratio", "turbulence-intensity", "gust-spectrum", "step-s"};
  return flags;
}

bool SurveyFlightFromFlags(const PoseStream& poses, SimulationOptions* options, std::string* note,
                           std::string* error) {
  SurveyFlightOptions o;
  if (FlagGiven("segments")) o.dynamics.segments = FLAGS_segments;
  o.dynamics.damping_ratio = FLAGS_damping_ratio;
  o.dynamics.max_step_s = FLAGS_step_s;
  if (!WindFromFlags(&o.dynamics.wind, error)) return false;
  if (FlagGiven("speed-m-per-s")) o.speed_m_per_s = FLAGS_speed_m_per_s;
  o.min_move_s = FLAGS_min_move_s;
  o.wait_s = FLAGS_wait_s;
  if (!FLAGS_waits.empty()) {
    if (FlagGiven("wait-s")) {
      *error = "give --wait-s (one wait) or --waits=design.json (each move's), not both";
      return false;
    }
    if (!WaitsFromDesign(FLAGS_waits, &o.move_waits_s, error)) return false;
    o.per_move_waits = true;
  }
  o.sample_interval_s = FLAGS_interval_s;
  if (!o.IsValid(error)) {
    *error = WithFlagNames(*error, {{"speed_m_per_s", "--speed-m-per-s"},
                                    {"min_move_s", "--min-move-s"},
                                    {"wait_s", "--wait-s"},
                                    {"sample_interval_s", "--interval-s"},
                                    {"segments", "--segments"},
                                    {"damping_ratio", "--damping-ratio"},
                                    {"max_step_s", "--step-s"},
                                    {"wind.mean_speed_m_per_s", "--wind (its speed)"},
                                    {"wind.turbulence_intensity", "--turbulence-intensity"}});
    return false;
  }
  // The flight needs every pose to size the wind's record: drawn from a copy.
  PoseStream copy = poses;
  std::vector<Pose> planned;
  planned.reserve(static_cast<size_t>(copy.count));
  for (long long n = 0; n < copy.count; ++n) planned.push_back(copy.next());
  double duration_s = 0.0;
  if (!MakeSurveyFlight(planned, o, &options->actual_source, &duration_s, error)) {
    if (o.per_move_waits) *error = "--waits=" + FLAGS_waits + ": " + *error;
    return false;
  }
  *note = "flown in time (--dynamics): " + FormatDouble(duration_s, 6) + " s, " +
          std::to_string(o.dynamics.segments) + " segments, wind " +
          FormatDouble(o.dynamics.wind.mean_speed_m_per_s, 3) + " m/s";
  return true;
}

}  // namespace fastcal::cli
