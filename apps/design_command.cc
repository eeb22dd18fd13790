// `fastcal design`: where to put the cabin, how many samples at each stop and in what
// order, for a calibration with a given spec to learn the most (design.h).
#include <gflags/gflags.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <sstream>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/design.h"
#include "fastcal/internal/quote.h"
#include "fastcal/version.h"

// Shared with the other commands.
DECLARE_string(joint_grid_deg);  // simulate's: the same grid of rotator angles

DEFINE_double(slow_error_percent, 2.0,
              "design: the sensors' slow error (% of the reading) where the spec estimates it.");
DEFINE_double(slow_error_kN, 1.0,
              "design: the sensors' slow error (kN) where the spec estimates sigma_kN.");
DEFINE_double(slow_error_time_s, 120.0,
              "design: the slow error's time constant (s) where the spec estimates it.");
DEFINE_double(max_extra_tilt_deg, 0.0, "design: largest tilt of z' off the focal law (deg).");
DEFINE_double(max_extra_yaw_deg, 0.0, "design: largest turn about z' off the focal law (deg).");
DEFINE_double(minutes, 0.0, "design: time budget of the survey (min); 0: none.");
// Shared with dynamics (dynamics_command.cc): the same band, the same default.
DEFINE_string(criterion, "A", "design: A (sum of variances) or D (log-determinant).");
DEFINE_string(parameters, "", "design: wanted parameters, comma-separated; default: see --help.");
DEFINE_double(hold_probability, 1e-4,
              "design: largest probability over the priors that a designed pose breaks a limit.");
DEFINE_double(range_prior_sigmas, 2.0,
              "design: plausible range of a parameter with a prior, in its sigmas.");
DEFINE_double(range_mass_centre_m, 0.25,
              "design: plausible range of a free mass centre without a prior (m per axis).");
DEFINE_double(range_offset_m, 0.05,
              "design: plausible range of free anchor and tower offsets without a prior (m).");
DEFINE_double(range_relative, 0.03,
              "design: plausible range of other free parameters without a prior (fraction).");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "design";
constexpr double kSecondsPerMinute = 60.0;

const char kHelp[] =
    R"(fastcal design: the calibration survey that determines the wanted parameters best.

Usage:
  fastcal design --spec=SPEC.yaml --samples=N --out=DIR [--model=MODEL.yaml]
                 [--max-extra-tilt-deg=A] [--max-extra-yaw-deg=B] [--criterion=A|D]
                 [--parameters=NAME,...] [--seed=1] [--speed-m-per-s=V] [--minutes=T]
                 [--joint-grid-deg=-15,0,15] [--slow-error-percent=2]
                 [--slow-error-time-s=120]

Chooses N samples among candidate poses (the workspace grid of the focal-sphere cap at
the focal attitude law, and with --max-extra-tilt-deg / --max-extra-yaw-deg also tilted
up to A and turned up to B degrees off the law; each checked as `fastcal workspace`
checks a node) to minimise the predicted uncertainty of the wanted parameters, from the
calibration's own linearisation and noise model (the spec's noise, priors, free
nuisance parameters marginalised, consider parameters included), then orders the stops
into a short path (nearest neighbour + 2-opt). Deterministic for a given --seed (which
draws the random survey compared against).

  --spec=SPEC.yaml       the calibration spec the survey is for (docs/calibration.md)
  --samples=N            samples in the survey (>= the spec's free parameters)
  --out=DIR              new or empty directory: poses.csv, design.json, design.html
  --model=MODEL.yaml     default: the nominal FAST model
  --criterion=A          A: sum of the wanted variances; D: their log-determinant
  --parameters=...       wanted parameters, e.g. mass_centre_m.x,mass_centre_m.z;
                         default: the free parameters without a prior (those with a
                         prior are nuisance), or all free ones when all have priors
  --max-extra-tilt-deg=0 --max-extra-yaw-deg=0   attitudes off the focal law
  --speed-m-per-s=0      cabin speed between stops; gives the survey's duration
  --interval-s=1         time per sample (s)
  --minutes=0            time budget; needs --speed-m-per-s. Over it, the design drops
                         its least useful stops (their samples dwell at the others)
  --settle-fraction=0.005  with a speed: after each move (a minimum-jerk profile of
                         its length / speed), wait until every tension is within this
                         fraction of quasi-static, from the time-domain model (moves
                         that cannot leave the band are not simulated); the waits are
                         in the duration, outside the time budget; 0: no waits
Grid and limits, as fastcal workspace: --max-off-axis-deg=40 --off-axis-step-deg=1
  --azimuth-step-deg=5 --focal-radius=160 --focal-centre=0,0,300 --tilt-fraction=0.41
  --max-tension-kN=inf --max-strain=0.05 --max-length-ratio=1.5, and with the design's
  own margins (the optimum lies on the workspace's edge, where cables near slack sag by
  metres for a small error of the model): --min-tension-kN=50 --reflector-clearance=5

Slow sensor errors (docs/design.md): the predictions use the spec's whole noise model.
Where the spec has a slow error (noise.slow_error) each cable's readings are whitened in
flight order as the calibration whitens them, so a stop's samples, whose slow errors
agree, count for less than independent ones; a part the spec estimates is taken as
--slow-error-percent=2 (or --slow-error-kN=1 for sigma_kN) and --slow-error-time-s=120
(what the recommended spec found on realistic telemetry: say what your sensors do).

Moving parts (docs/design.md): with a model whose cabin has an A-B rotator
(cabin.moving_parts), its two angles are design variables: each candidate pose is offered
at every pair of --joint-grid-deg=-15,0,15 values (within the joints' ranges; other joints
at zero), and a stop is a pose with its angles, so the survey separates the rotator's
first moment from the fixed mass centre. --joint-grid-deg=0 holds the rotator at zero.
poses.csv then carries the joint columns and design.json each stop's joints; the circle
and the random survey compared with fly the rotator by the focal law.

Poses that hold (docs/design.md): a candidate must also hold over the plausible range of
the spec's statics parameters (free or considered; not the sensors'). A parameter with a
prior: with probability 1 - --hold-probability=1e-4 over the priors' joint distribution
(each pose breaks a limit in at most 1 of 10^4 plausible truths: first-order reliability,
then solved exactly at the design point). Free without a prior, at every value within +-
--range-mass-centre-m=0.25 (mass centre, per axis), --range-offset-m=0.05 (anchor and
tower offsets) or --range-relative=0.03 of its value (mass, densities, EA, attachments).
There the statics must be ok, every tension at least --min-tension-kN and every cable
--reflector-clearance clear of the reflector. --hold-probability=0: the priors too over
a box, +- --range-prior-sigmas=2 of each sigma at once (the corner rule; stricter, and
less efficient). The summary names what binds (the tightest stop, its cable and the
point); design.json has it per stop.

Outputs (written only when everything succeeded):
  poses.csv    x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg (and the joint columns), one row
               per sample in flight order: read by `fastcal simulate --poses` and
               `fastcal solve --poses`
  design.json  the stops, the path, and parameters[]: {name, sigma_total} predicted for
               the design, the paper's circle and a random survey of N samples
  design.html  the stops and path on the cap, the predicted sigmas side by side, what
               limits the design and what a better prior would buy
Every sigma is in its parameter's unit, the one its name carries (sensor_bias_kN: kN).
A summary on stdout (> design.txt keeps it); each stage's progress on stderr.

Example:
  fastcal design --spec=calibration_data/spec_realistic.yaml --samples=360 \
      --max-extra-tilt-deg=5 --max-extra-yaw-deg=10 --speed-m-per-s=0.5 --out=out/design
)";

const std::set<std::string> kFlags = {"spec",
                                      "out",
                                      "model",
                                      "samples",
                                      "seed",
                                      "tilt-fraction",
                                      "focal-centre",
                                      "max-off-axis-deg",
                                      "off-axis-step-deg",
                                      "azimuth-step-deg",
                                      "focal-radius",
                                      "min-tension-kN",
                                      "max-tension-kN",
                                      "interval-s",
                                      "max-extra-tilt-deg",
                                      "max-extra-yaw-deg",
                                      "speed-m-per-s",
                                      "minutes",
                                      "settle-fraction",
                                      "criterion",
                                      "parameters",
                                      "max-strain",
                                      "max-length-ratio",
                                      "reflector-clearance",
                                      "range-prior-sigmas",
                                      "range-mass-centre-m",
                                      "range-offset-m",
                                      "range-relative",
                                      "joint-grid-deg",
                                      "slow-error-percent",
                                      "slow-error-kN",
                                      "slow-error-time-s",
                                      "hold-probability"};

bool SetOptionsFromFlags(DesignOptions* o, std::string* error) {
  // The candidates' grid and limits exactly as `fastcal workspace` reads them.
  if (!WorkspaceOptionsFromFlags(&o->workspace, error)) return false;
  // The design's margins unless given (design.h: the optimum lies on the edge).
  if (!FlagGiven("reflector-clearance")) {
    o->workspace.statics.min_reflector_clearance_m = kDesignReflectorClearanceM;
  }
  if (!FlagGiven("min-tension-kN")) o->workspace.min_tension_n = kDesignMinTensionN;
  if (!ParseNumberList("joint-grid-deg", FLAGS_joint_grid_deg, &o->joint_grid_deg, error)) {
    return false;
  }
  o->slow_error_percent = FLAGS_slow_error_percent;
  o->slow_error_kn = FLAGS_slow_error_kN;
  o->slow_error_time_s = FLAGS_slow_error_time_s;
  o->max_extra_tilt_deg = FLAGS_max_extra_tilt_deg;
  o->max_extra_yaw_deg = FLAGS_max_extra_yaw_deg;
  o->range_prior_sigmas = FLAGS_range_prior_sigmas;
  o->hold_probability = FLAGS_hold_probability;
  o->range_mass_centre_m = FLAGS_range_mass_centre_m;
  o->range_offset_m = FLAGS_range_offset_m;
  o->range_relative = FLAGS_range_relative;
  o->samples = FLAGS_samples;
  o->seed = FLAGS_seed;
  o->speed_m_per_s = FLAGS_speed_m_per_s;
  o->settle_after_moves = FLAGS_settle_fraction != 0.0;
  if (o->settle_after_moves) o->settle.fraction = FLAGS_settle_fraction;
  o->sample_interval_s = FLAGS_interval_s;
  if (!(FLAGS_minutes >= 0.0) || !std::isfinite(FLAGS_minutes)) {
    *error = "--minutes must be >= 0 and finite (got " + FormatDouble(FLAGS_minutes) + ")";
    return false;
  }
  o->time_budget_s = FLAGS_minutes * kSecondsPerMinute;
  if (FLAGS_criterion == "A" || FLAGS_criterion == "a") {
    o->criterion = DesignCriterion::kA;
  } else if (FLAGS_criterion == "D" || FLAGS_criterion == "d") {
    o->criterion = DesignCriterion::kD;
  } else {
    *error = "--criterion must be A or D, got " + internal::Quote(FLAGS_criterion);
    return false;
  }
  std::stringstream names(FLAGS_parameters);
  for (std::string name; std::getline(names, name, ',');) {
    if (!name.empty()) o->wanted.push_back(name);
  }
  if (o->IsValid(error)) return true;
  *error = WithFlagNames(WithTrajectoryFlagNames(*error),
                         {{"max_extra_tilt_deg", "--max-extra-tilt-deg"},
                          {"max_extra_yaw_deg", "--max-extra-yaw-deg"},
                          {"samples", "--samples"},
                          {"speed_m_per_s", "--speed-m-per-s"},
                          {"sample_interval_s", "--interval-s"},
                          {"time_budget_s", "--minutes"},
                          {"move settle options: fraction", "--settle-fraction"},
                          {"range_prior_sigmas", "--range-prior-sigmas"},
                          {"range_mass_centre_m", "--range-mass-centre-m"},
                          {"range_offset_m", "--range-offset-m"},
                          {"range_relative", "--range-relative"},
                          {"joint_grid_deg", "--joint-grid-deg"},
                          {"slow_error_percent", "--slow-error-percent"},
                          {"slow_error_kn", "--slow-error-kN"},
                          {"slow_error_time_s", "--slow-error-time-s"},
                          {"hold_probability", "--hold-probability"}});
  return false;
}

// What noise the predictions assumed: white, or with the slow error.
std::string NoiseText(const Design& d) {
  const SlowErrorProcess& p = d.slow_error;
  if (!p.IsActive()) return "predicted with white noise (the spec has no slow error)";
  std::string amplitude = p.sigma_percent > 0.0 ? FormatDouble(p.sigma_percent, 3) + " %" : "";
  if (p.sigma_n > 0.0) {
    amplitude += (amplitude.empty() ? "" : " and ") + FormatDouble(p.sigma_n / 1e3, 3) + " kN";
  }
  return "predicted with a slow sensor error of " + amplitude + " over " +
         FormatDouble(p.time_constant_s, 3) + " s (whitened in flight order)";
}

// With moving parts: how many joint points the stops visit at how many poses.
std::string JointStopsText(const Design& d) {
  std::set<std::vector<double>> poses;
  std::set<int> points;
  for (const DesignStop& stop : d.stops) {
    const DesignCandidate& c = d.candidates[stop.candidate];
    const Eigen::Vector3d rpy = RpyDegFromRotation(c.pose.rotation);
    poses.insert({c.pose.position_m.x(), c.pose.position_m.y(), c.pose.position_m.z(), rpy[0],
                  rpy[1], rpy[2]});
    points.insert(c.joint_point);
  }
  if (points.size() == 1 && *points.begin() < 0) {
    return "moving parts: no rotator to design for (joints at zero)";
  }
  return "moving parts: " + std::to_string(d.stops.size()) + " stops at " +
         std::to_string(poses.size()) + " poses, " + std::to_string(points.size()) +
         " rotator angle pairs in all (design.json: stops[].joints)";
}

// The waits after the moves (move_settle.h), and whether they pass the time budget.
std::string SettleText(const Design& d) {
  int simulated = 0, unsettled = 0;
  const int moves = d.stops.empty() ? 0 : static_cast<int>(d.stops.size()) - 1;
  size_t longest = 0;
  for (size_t k = 0; k < d.stops.size(); ++k) {
    simulated += d.stops[k].settle.simulated;
    unsettled += !d.stops[k].settle.settled;
    if (d.stops[k].settle.wait_s > d.stops[longest].settle.wait_s) longest = k;
  }
  const double band = 100.0 * d.options.settle.fraction;
  std::string s = "waits after moves (every tension within " + FormatDouble(band, 3) +
                  "% of quasi-static): " + FormatDouble(d.settle_s / kSecondsPerMinute, 3) +
                  " min in all; " + std::to_string(simulated) + " of " + std::to_string(moves) +
                  " moves run in time" +
                  (simulated < moves ? " (the others too gentle to leave the band)" : "");
  if (d.settle_s > 0.0) {
    s += "; the longest " + FormatDouble(d.stops[longest].settle.wait_s, 3) + " s before stop " +
         std::to_string(longest + 1);
  }
  if (unsettled > 0) {
    s += "; " + std::to_string(unsettled) + " still outside after " +
         FormatDouble(d.options.settle.max_wait_s, 3) + " s (waited that long)";
  }
  if (!d.settle_note.empty()) s += "; " + d.settle_note;
  if (d.options.time_budget_s > 0.0 && d.duration_s > d.options.time_budget_s) {
    s += "; with them the survey takes " + FormatDouble(d.duration_s / kSecondsPerMinute, 3) +
         " min, over the " + FormatDouble(d.options.time_budget_s / kSecondsPerMinute, 3) +
         "-min budget (which holds travel and dwell)";
  }
  return s;
}

// The result, on stdout: what was chosen, and the predicted sigma_total of each wanted
// parameter in its own unit (the one in its name: kN for sensor_bias_kN).
std::string Summary(const Design& d) {
  std::ostringstream s;
  s << "fastcal design: " << d.options.samples << " samples at " << d.stops.size() << " stops from "
    << d.candidates.size() << " feasible candidates (" << d.rejected_candidates
    << " infeasible); path " << FormatDouble(d.path_length_m, 5) << " m";
  if (d.options.speed_m_per_s > 0.0) {
    s << ", " << FormatDouble(d.duration_s / kSecondsPerMinute, 3) << " min";
  }
  // The name column as wide as the longest wanted name (a moving part's are long).
  int width = 28;
  for (int k : d.wanted) width = std::max(width, static_cast<int>(d.free_names[k].size()));
  char row[256];
  std::snprintf(row, sizeof(row), "\n  %-*s %-6s %11s %15s %14s", width + 2,
                "predicted sigma_total", "unit", "design", "paper's circle", "random survey");
  s << row;
  for (int k : d.wanted) {
    auto sig = [&d, k](const DesignPrediction& p) {
      return p.ok ? FormatDouble(p.budget.parameters[k].total / d.free_to_si[k], 4)
                  : std::string("n/a");
    };
    std::snprintf(row, sizeof(row), "\n    %-*s %-6s %11s %15s %14s", width,
                  d.free_names[k].c_str(), d.free_units[k] == "1" ? "" : d.free_units[k].c_str(),
                  sig(d.design).c_str(), sig(d.circle).c_str(), sig(d.random).c_str());
    s << row;
  }
  if (!d.joint_columns.empty()) s << "\n  " << JointStopsText(d);
  if (d.options.speed_m_per_s > 0.0 && d.options.settle_after_moves) s << "\n  " << SettleText(d);
  s << "\n  " << NoiseText(d);
  s << "\n  limited by " << d.limiting_part << " (" << FormatDouble(100.0 * d.limiting_share, 3)
    << "% of the wanted variance)";
  // Each finding wrapped to the console's width; design.html has the stops' detail.
  std::istringstream range(DesignRangeSummary(d));
  for (std::string line; std::getline(range, line);) {
    std::string wrapped = Wrapped(line, "  ", "    ", 4, "design.html");
    wrapped.pop_back();  // the final newline: lines here are joined by a leading one
    s << "\n" << wrapped;
  }
  return s.str();
}

}  // namespace

int RunDesign(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  std::string error;
  if (FLAGS_spec.empty() || FLAGS_out.empty() || !FlagGiven("samples")) {
    PrintError(kCommand,
               "--spec=SPEC.yaml, --samples=N and --out=DIR are required (see "
               "fastcal design --help)");
    return kExitUsage;
  }
  CableRobot robot;
  CalibrationSpec spec;
  DesignOptions options;
  // Progress on stderr: a design with extra attitudes takes about 20 s.
  options.progress = [](const std::string& stage) {
    std::cerr << "fastcal design: " << stage << std::endl;
  };
  if (!CheckOutputDirectory("out", FLAGS_out, &error) ||
      !LoadModelFlag("model", FLAGS_model, &robot, &error) ||
      !LoadCalibrationSpec(FLAGS_spec, robot, &spec, &error) ||
      !SetOptionsFromFlags(&options, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  Design design;
  if (!DesignSurvey(robot, spec, options, &design, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  const std::string provenance = CommandLine(argc, argv) + "\nfastcal " + FASTCAL_VERSION +
                                 ", model " + ModelName(FLAGS_model);
  if (!WriteDirectoryAtomically(FLAGS_out,
                                {{"poses.csv", DesignPosesCsv(design, provenance)},
                                 {"design.json", DesignJson(design, provenance)},
                                 {"design.html", DesignHtml(design, robot, provenance)}},
                                {}, nullptr, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  // The summary of what was written is the result: stdout (docs/cli.md, "Output streams").
  std::cout << Summary(design) << "\n";
  return 0;
}

}  // namespace fastcal::cli
