// `fastcal simulate --dynamics`: the survey flown in time (dynamic_survey.h) instead of the
// cabin standing at each planned pose in its statics: the samples' poses, tensions, lengths
// and times come from the dynamics, then the same sensors' errors as any simulation.
#include <gflags/gflags.h>

#include <cmath>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/dynamic_survey.h"

DEFINE_bool(dynamics, false, "simulate: fly the survey in time (docs/cli.md, simulate).");
DEFINE_double(wait_s, 30.0, "simulate --dynamics: the wait after each move (s).");
DEFINE_double(min_move_s, 10.0, "simulate --dynamics: the shortest move (s).");

namespace fastcal::cli {

const std::set<std::string>& SimulateDynamicsFlags() {
  static const std::set<std::string> flags = {
      "dynamics", "wait-s",        "min-move-s",           "speed-m-per-s", "wind",
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
  if (!MakeSurveyFlight(planned, o, &options->actual_source, &duration_s, error)) return false;
  *note = "flown in time (--dynamics): " + FormatDouble(duration_s, 6) + " s, " +
          std::to_string(o.dynamics.segments) + " segments, wind " +
          FormatDouble(o.dynamics.wind.mean_speed_m_per_s, 3) + " m/s";
  return true;
}

}  // namespace fastcal::cli
