// Design of a calibration survey (optimal experimental design): which poses, how many
// samples at each, and in what order to fly them, so that a calibration with a given spec
// determines the wanted parameters best.
//
// Information of a candidate pose i (docs/design.md; Fedorov 1972, Atkinson, Donev and
// Tobias 2007 ch. 9-12): J_i = [J_x,i  J_c,i], the whitened Jacobian (6 rows: the six
// readings over the spec's noise sigma at the initial model's predicted reading) with
// respect to the n free parameters x and the q consider parameters c, from the very
// residual the calibration fits (internal/calibration_model.h, TensionResidual). A design
// with n_i samples at candidate i has
//
//   M = sum_i n_i J_x,i^T J_x,i + Lambda       (Lambda: the free parameters' priors)
//   C = sum_i n_i J_x,i^T J_c,i
//   P_total = M^-1 + M^-1 C diag(sigma_c^2) C^T M^-1
//
// the calibration's uncertainty budget (uncertainty.h) for white residuals at the stated
// noise (misfit factor 1, no correlation widening): nuisance parameters marginalised (the
// wanted block of the full inverse), priors as information, consider parameters' part
// included. Criterion on the wanted block P_w: A-optimal tr(P_w) (each variance divided
// by its reference value when the wanted parameters' units differ), D-optimal
// log det(P_w). Its gradient in n_i is
//
//   df/dn_i = -tr(J_x,i G J_x,i^T) + 2 tr(J_c,i H J_x,i^T),
//   G = K W K + K W Q + Q W K,  H = Sigma_c C^T K W K,  K = M^-1,  Q = K C Sigma_c C^T K
//
// with W the criterion's weight on P (A: diag of the wanted weights; D: P_w^-1 embedded).
// Optimisation: Frank-Wolfe (the vertex-direction method of Fedorov and Wynn, with a
// line search) on the approximate design's weights, rounded to N samples, then a
// Fedorov exchange of single samples (the best gradient's additions against the
// smallest losses' removals, each swap judged by the exact criterion) until no swap
// improves it. Deterministic; the seed draws only the random survey compared against.
//
// Candidates: the workspace grid of the focal-sphere cap (workspace.h) at the focal
// attitude law, and with max_extra_tilt_deg A > 0 also each attitude tilted by A about
// tilt_directions horizontal cabin axes, and with max_extra_yaw_deg B > 0 turned by +-B
// about the cabin's z' axis: R = R_law Rtilt(A, phi) Rz(psi). Every candidate is judged
// as `fastcal workspace` judges a node: statics ok (model range, reflector clearance)
// and every lower-end tension within the limits.
//
// Poses that hold over the plausible range (docs/design.md): the optimum lies on the
// feasible set's edge, where a cable near slack sags by metres for a small error of the
// model, so a candidate must also hold off the spec's initial values: each statics
// parameter of the spec (free or considered; not the sensors' gains and biases, which
// change readings, not forces) by +- range_prior_sigmas of its prior's sigma, or, free
// without a prior, +- its kind's margin (range_*). From each parameter's effect on the six
// tensions (one solve per parameter at +delta) the corner of that box where each cable's
// tension is lowest is solved exactly; at the nominal point and at every such corner the
// statics must be ok and the tensions and clearance within the workspace's limits
// (min_tension_n is the margin kept there). What binds each stop is reported.
//
// Slow sensor errors (docs/design.md): the predictions whiten each cable's rows in flight
// order by the spec's slow error (PredictionSlowError; internal/slow_error_filter.h, as the
// calibration whitens its readings), so that samples whose errors are correlated count
// for what they are worth; the optimisation above weighs the candidates' samples as white.
//
// Moving parts (docs/design.md, "Moving parts"): with a model whose cabin has an A-B
// rotator (joint_plan.h), the rotator's two angles are design variables. Each candidate
// pose is offered at every point of the grid joint_grid_deg x joint_grid_deg (within the
// joints' ranges; other joints at zero), each point a candidate of its own judged over
// the plausible range at its mass centre c(q): at one pose the angles vary independently
// of the cabin's tilt, which separates the rotator's first moment from the fixed mass
// centre (methods.md). A stop is a pose and a joint point; stops at one pose are flown
// one after another. The paper's circle and the random survey, compared with, fly the
// rotator by the focal law (joint_plan.h), as observing does.
//
// A time budget: flying the stops in order takes path_length / speed plus N samples
// times the sample interval. When that is over the budget the design drops its least
// useful stops one at a time (their samples go to the others: dwell) until it fits.
#ifndef FASTCAL_DESIGN_H_
#define FASTCAL_DESIGN_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/move_settle.h"
#include "fastcal/moving_parts.h"
#include "fastcal/pose.h"
#include "fastcal/trajectory.h"
#include "fastcal/uncertainty.h"
#include "fastcal/workspace.h"

namespace fastcal {

enum class DesignCriterion {
  kA,  // sum of the wanted parameters' variances
  kD,  // log-determinant of their covariance
};
const char* DesignCriterionName(DesignCriterion criterion);  // "A", "D"

// Default margins of a designed pose: every cable's lower-end tension (N) and its
// clearance from the reflector (m).
inline constexpr double kDesignMinTensionN = 50e3;
inline constexpr double kDesignReflectorClearanceM = 5.0;

struct DesignOptions {
  // Where the cabin may go: the workspace's grid (1 deg off axis up to 40 deg, every 5 deg
  // of azimuth: 2881 positions), its focal attitude law, tension limits (none by default)
  // and statics checks (reflector clearance, model range), as `fastcal workspace`. The
  // radial offset is not used (candidates are on the focal sphere). Two differences,
  // margins: every lower-end tension at least kDesignMinTensionN and every cable
  // kDesignReflectorClearanceM clear of the reflector. The optimum lies on the feasible
  // set's edge, and the information there comes from cables near slack, whose sag moves
  // by metres with a small error of the model: a design without them put a tilted pose
  // with cable 1 at 27 kN, which a truth 1.5% heavier per cable took 0.6 m into the
  // reflector; with 30 kN the simulation of a drawn truth still failed, with 50 kN none
  // of 10 did (docs/design.md).
  WorkspaceOptions workspace = [] {
    WorkspaceOptions w;
    w.min_tension_n = kDesignMinTensionN;
    w.statics.min_reflector_clearance_m = kDesignReflectorClearanceM;
    return w;
  }();
  // Largest extra tilt of z' off the focal law (deg, in [0, 30]); 0: the law alone.
  double max_extra_tilt_deg = 0.0;
  // Number of tilt directions, evenly spaced about z' (>= 1); used when tilting.
  int tilt_directions = 4;
  // Largest extra turn about z' off the law (deg, in [0, 90]); 0: none.
  double max_extra_yaw_deg = 0.0;
  // The plausible range every candidate must hold over (the file comment; docs/design.md):
  // a parameter with a prior +- range_prior_sigmas of its sigma (2: a 1.5% density prior
  // gives +-3%); free without a prior, +- range_mass_centre_m per axis of the mass centre
  // (0.25 m: the paper's own calibration moved it ~0.25 m from nominal), range_offset_m
  // (anchor and tower offsets, 0.05 m), or range_relative of the value (cabin mass,
  // densities, EA, attachments; 3%). All 0: the nominal point only, as before issue 29.
  double range_prior_sigmas = 2.0;
  // How the priors' part of the range is held: with hold_probability p > 0, each designed
  // pose breaks a limit (a tension, the reflector's clearance) with probability at most p
  // over the priors' joint distribution, to first order and checked exactly at the design
  // point (internal/design_range.h); every value within the margins (range_*) is held as
  // before. 0: the corner rule, each prior +- range_prior_sigmas at once (issue 29's).
  // 1e-4: one pose in 10^4 of plausible truths comes nearer its limit than the margin.
  double hold_probability = 1e-4;
  double range_mass_centre_m = 0.25;
  double range_offset_m = 0.05;
  double range_relative = 0.03;
  // With a rotator in the model (design.h, "Moving parts"): the values (deg) each of its
  // two angles may take at a stop; the grid's points outside a joint's range are left
  // out. Empty: the rotator at zero.
  std::vector<double> joint_grid_deg = {-15.0, 0.0, 15.0};
  // The slow sensor error the predictions assume where the spec estimates it
  // (noise.slow_error: estimate; slow_error.h): its amplitude in percent of the reading
  // (or in kN, for a spec that estimates sigma_kN) and its time constant (s). 2 % and
  // 120 s: what the recommended spec found on realistic simulated telemetry
  // (docs/calibration.md, "Slow sensor errors"); say what your sensors do. A part the spec
  // states is the spec's; a spec without a slow error predicts with white noise. The
  // optimisation itself weighs samples as white (docs/design.md); the predictions, of the
  // design and of the surveys compared with, whiten each cable's readings in flight order
  // as the calibration does.
  double slow_error_percent = 2.0;
  double slow_error_kn = 1.0;
  double slow_error_time_s = 120.0;
  // Samples in the survey (>= the number of free parameters).
  int samples = 360;
  DesignCriterion criterion = DesignCriterion::kA;
  // Names of the wanted parameters (free ones of the spec); empty: the free parameters
  // without a prior (those known beforehand only to a tolerance, given a prior, are the
  // nuisance), or every free parameter when all have priors.
  std::vector<std::string> wanted;
  // Seed of the random survey the design is compared with.
  std::uint64_t seed = 1;
  // Frank-Wolfe iterations on the approximate design, and exchange iterations after
  // rounding (each an accepted swap of one sample).
  int approximate_iterations = 300;
  int exchange_iterations = 2000;
  // Additions and removals tried per exchange iteration (the best by the gradient).
  int exchange_width = 8;
  // Path: cabin speed between stops (m/s; 0: no duration), time per sample (s, > 0),
  // time budget (s; 0: none, else needs a speed).
  double speed_m_per_s = 0.0;
  double sample_interval_s = 1.0;
  double time_budget_s = 0.0;
  // With a speed: the wait after each move until every tension is within
  // settle.fraction of quasi-static (move_settle.h: the time-domain model, each leg a
  // minimum-jerk move of its length / speed), added to the duration and the samples'
  // times. The time budget holds travel and dwell; the waits come on top (the console
  // says when they pass it). False: no waits.
  bool settle_after_moves = true;
  MoveSettleOptions settle;
  // The paper's measured circle, compared with: radius 71.11 m about (0, 0, 156.73) m,
  // N samples evenly spaced on one turn, attitude by the focal law.
  Eigen::Vector3d circle_centre_m = Eigen::Vector3d(0.0, 0.0, 156.73);
  double circle_radius_m = 71.11;
  // Called at the start of each stage (candidates, information, approximate design,
  // exchange, time budget, predictions) with a line saying what it does: a design takes
  // about 20 s on the default grid with extra attitudes. Empty: silent. The library never
  // prints; the command line puts these on stderr.
  std::function<void(const std::string&)> progress;
  // False with *error naming the field when an option is invalid.
  bool IsValid(std::string* error) const;
};

// One candidate pose.
struct DesignCandidate {
  Pose pose;
  double off_axis_deg = 0.0, azimuth_deg = 0.0;  // its grid node
  double extra_tilt_deg = 0.0;                   // 0 or max_extra_tilt_deg
  double tilt_direction_deg = 0.0;               // about z', from x'
  double extra_yaw_deg = 0.0;                    // 0 or +-max_extra_yaw_deg
  // The moving parts' joint values there (the model's joint order, the columns' units),
  // and the joint grid's point (-1: no rotator in the model).
  JointValues joints{};
  int joint_point = -1;
  // `pose` in the data's frame: the model's measured frame (measured_frame.h) at `joints`,
  // what the telemetry shows there and what poses.csv and design.json give; `pose` itself
  // for a model without one.
  Pose data_pose;
};

// The predicted uncertainty of a survey.
struct DesignPrediction {
  bool ok = false;  // false: the survey could not be predicted (`note` says why)
  std::string note;
  int samples = 0;
  double criterion = 0.0;
  // Per free parameter (spec order): the calibration's budget for white residuals.
  UncertaintyBudget budget;
  // Per free parameter: variance from the data's noise, from each prior group (free
  // parameters with a prior) and each consider group: they add up to sigma_total^2.
  std::vector<double> noise_variance;
  std::vector<std::string> parts;                  // prior and consider group names
  std::vector<std::vector<double>> part_variance;  // [part][free parameter]
};

// What a better prior would buy: a prior or consider group's sigma halved.
struct DesignPriorEffect {
  std::string group;
  bool consider = false;
  std::vector<double> sigma_total;  // of each wanted parameter with that prior halved
};

// A statics parameter of the spec and how far off its initial value the designed poses
// hold (DesignOptions::range_*).
struct DesignRangeParameter {
  std::string name;  // the spec's, e.g. "mass_centre_m.x"
  std::string unit;  // its unit in files (SI value = file value * to_si)
  double to_si = 1.0;
  double delta_si = 0.0;    // +- this (the corner rule; a margin under either rule)
  bool from_prior = false;  // range_prior_sigmas x its prior's sigma; else a range_* margin
  double sigma_si = 0.0;    // its prior's sigma (from_prior), held with hold_probability
};

// What binds a designed pose: its tightest limit over the plausible range.
struct DesignBinding {
  // "min_tension" (the margin), "max_tension", or "reflector_clearance"; empty: none
  // computed.
  std::string constraint;
  int cable = -1;      // 0-based: the lowest (or highest, or nearest) cable there
  double value = 0.0;  // the tension (N) or clearance (m) there
  double limit = 0.0;  // the limit it keeps (N or m)
  // Where in the range: each parameter's offset from its initial value (SI), parallel
  // to Design::range (0 everywhere: the nominal point).
  std::vector<double> corner_si;
};

struct DesignStop {
  int candidate = 0;  // index into Design::candidates
  int samples = 0;    // samples taken there (dwell = samples x sample interval)
  DesignBinding binding;
  // The wait before the first sample, after the move here (move_settle.h; 0 at the first
  // stop, without a speed or with settle_after_moves false).
  MoveSettle settle;
};

struct Design {
  DesignOptions options;
  std::vector<DesignCandidate> candidates;  // the feasible ones
  int rejected_candidates = 0;              // infeasible ones (rejected_off_nominal too)
  // The plausible range (DesignOptions::range_*), and how many candidates feasible at
  // the nominal point were left out because they do not hold over it.
  std::vector<DesignRangeParameter> range;
  int rejected_off_nominal = 0;
  std::vector<std::string> free_names;  // spec order
  std::vector<std::string> free_units;  // their units in files (the spec's)
  std::vector<double> free_to_si;       // SI value = file value * to_si
  std::vector<int> wanted;              // indices into free_names
  std::vector<DesignStop> stops;        // in flight order
  std::vector<Pose> poses;              // one per sample, in flight order (the cabin's)
  std::vector<Pose> data_poses;         // the same in the data's frame (DesignCandidate)
  // With moving parts: the model's joint columns, and each sample's joint values
  // (parallel to poses); both empty for a rigid cabin.
  std::vector<std::string> joint_columns;
  std::vector<JointValues> joints;
  double path_length_m = 0.0;
  double travel_s = 0.0, dwell_s = 0.0, duration_s = 0.0;  // 0 without a speed
  // The waits after moves (in duration_s), and the moves the dynamics could not run
  // (they wait 0; empty when none).
  double settle_s = 0.0;
  std::string settle_note;
  // Distinct stops the optimum had before the time budget dropped some (= stops.size()
  // without a budget).
  int unconstrained_stops = 0;
  DesignPrediction design, circle, random;
  // The slow sensor error the predictions assumed (PredictionSlowError; inactive: white).
  SlowErrorProcess slow_error;
  // The largest part of the wanted parameters' summed variance in the design:
  // "noise" or a group name, and its share of the sum.
  std::string limiting_part;
  double limiting_share = 0.0;
  std::vector<DesignPriorEffect> prior_effects;
};

// The slow error a design's predictions assume: the spec's, with the options' values for
// the parts it estimates; inactive for a spec without one.
SlowErrorProcess PredictionSlowError(const CalibrationSpec& spec, const DesignOptions& options);

// Designs the survey. False with *error for invalid options, a spec with nothing free,
// more free plus consider parameters than the calibration handles, fewer samples than
// free parameters, unknown wanted names, no feasible candidate, a design that cannot
// determine the parameters, or a time budget shorter than the samples alone take.
bool DesignSurvey(const CableRobot& robot, const CalibrationSpec& spec,
                  const DesignOptions& options, Design* design, std::string* error);

// The prediction for any survey (one sample per pose, flown options.sample_interval_s
// apart), with the design's criterion, wanted parameters and slow error. The poses are the
// data's (the model's measured frame's at the joints, as a poses.csv gives them). False
// with *error when the statics fail at a pose.
bool PredictSurvey(const CableRobot& robot, const CalibrationSpec& spec,
                   const DesignOptions& options, const std::vector<Pose>& poses,
                   DesignPrediction* prediction, std::string* error);
// The same with each pose's joint values (parallel to poses; empty: all zero).
bool PredictSurvey(const CableRobot& robot, const CalibrationSpec& spec,
                   const DesignOptions& options, const std::vector<Pose>& poses,
                   const std::vector<JointValues>& joints, DesignPrediction* prediction,
                   std::string* error);

// The design's outputs (design_output.cc), every pose in the data's frame (the model's
// measured frame; Design::data_poses). Poses, one row per sample in flight order:
// x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg (the format ReadPosesCsv reads), after
// '#' comment lines with `provenance`; with moving parts, then the joint columns.
std::string DesignPosesCsv(const Design& design, const std::string& provenance);
// design.json: options, stops, path, and for the design, the circle and the random
// survey `parameters[]: {name, unit, wanted, sigma_total, formal, systematic}`, the
// budget's parts, what limits the design and what a better prior would buy; each sigma in
// the parameter's spec unit (free_units: kN for sensor_bias_kN), never SI under a kN name.
std::string DesignJson(const Design& design, const std::string& provenance);
// Two lines for the console: the plausible range the poses hold over and what binds
// them (the tightest stop, the constraint, the cable and the numbers).
std::string DesignRangeSummary(const Design& design);
// A self-contained HTML page: the stops and the path on the cap seen from above (with
// the circle), the predicted sigma_total side by side, the limits and prior effects.
std::string DesignHtml(const Design& design, const CableRobot& robot,
                       const std::string& provenance);

}  // namespace fastcal

#endif  // FASTCAL_DESIGN_H_
