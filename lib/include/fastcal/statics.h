// Statics of one cabin pose: the six cable forces, tensions and unstretched lengths.
//
// Unknowns per cable: the horizontal force Fl_i > 0, the vertical force Fz_i and the
// unstretched length s0_i (the force on cable i at its lower end is
// F_i = (-X_i/L_i Fl_i, -Y_i/L_i Fl_i, Fz_i), eqs. 17-18). Equations: each cable's two
// catenary end conditions (catenary.h) and the cabin's equilibrium in vector form
// (docs/model.md; note the corrected sign of the mass-centre term, not paper eq. 24):
//     sum_i (-F_i) + W = 0,   sum_i r_i x (-F_i) + e x W = 0,
// r_i = R a_i, e = R r_e, W = (0, 0, m g). With Fz_i = a_i Fl_i + b_i the six equilibrium
// rows are linear in Fl (paper eqs. 26-30, rows 4-5 corrected):
//     sum ux_i Fl_i = 0,  sum uy_i Fl_i = 0,  sum a_i Fl_i = m g - sum b_i,
//     sum (ry_i a_i + rz_i uy_i) Fl_i = ey m g - sum ry_i b_i,
//     sum (rx_i a_i + rz_i ux_i) Fl_i = ex m g - sum rx_i b_i,
//     sum (ry_i ux_i - rx_i uy_i) Fl_i = 0,                        (u = (X, Y)/L)
//
// Methods:
//  kExact      (default) Newton on all 18 unknowns: each catenary is linearised in
//              (Fl, Fz, s0), ds0 eliminated, leaving the same 6x6 system. It starts from
//              AAS (or the previous solution, warm); where that start fails (AAS gives a
//              cable Fl <= 0, Newton leaves Fl > 0, s0 > 0 or does not converge, or the
//              solution is outside the model's range) it follows the equilibrium from the
//              robot's home pose to `pose` (continuation in small steps, each a few Newton
//              iterations), which finds it wherever it is connected to the home pose, and
//              tells "no equilibrium" from an equilibrium outside the model's range.
//  kAas        the paper's: a_i, b_i from the secant through the catenary solutions at
//              s0 = 0.99 k_i and 1.01 k_i; one 6x6 solve. s0_i by one solve per cable.
//  kAasRefined AAS, then up to max_refinement_steps times: put each cable on its exact Fz(Fl)
//              curve at the current Fl_i, re-linearise with the tangent (implicit derivative
//              along the family of lengths) and solve the 6x6 system again, until its error
//              estimate is below refined_relative_tolerance. Each step is a Newton step on
//              the reduced system.
//
// No solution is ok without a check (docs/model.md, "Checking every solution"): the end
// conditions of every catenary are evaluated at the returned (Fl, Fz, s0) (their residual
// is end_residual_m), the first-order tension error they imply is propagated through the
// equilibrium (error_estimate; computed the same way for every method), and the
// equilibrium residuals are computed from the returned forces. exact needs
// error_estimate <= exact_relative_tolerance, aas-refined <= refined_relative_tolerance,
// aas <= aas_max_relative_error. Then the model's range (max_strain, max_length_ratio)
// and the reflector's clearance are checked.
//
// Nothing here allocates and nothing throws: an infeasible pose comes back as a status.
#ifndef FASTCAL_STATICS_H_
#define FASTCAL_STATICS_H_

#include <Eigen/Core>
#include <array>
#include <string>

#include "fastcal/cable_robot.h"
#include "fastcal/catenary.h"
#include "fastcal/pose.h"

namespace fastcal {

enum class StaticsMethod { kAas, kAasRefined, kExact };
const char* StaticsMethodName(StaticsMethod method);  // "aas", "aas-refined", "exact"
bool ParseStaticsMethod(const std::string& name, StaticsMethod* method);

struct StaticsOptions {
  // exact by default: right wherever it answers, and as fast as aas-refined (docs/model.md).
  StaticsMethod method = StaticsMethod::kExact;
  // Secant lengths of AAS as fractions of the chord length k (paper: 0.99 and 1.01).
  double secant_low_fraction = 0.99;
  double secant_high_fraction = 1.01;
  // kAasRefined: its steps stop once error_estimate <= refined_relative_tolerance; after
  // max_refinement_steps (>= 1) without that, the status is kNotConverged. On the
  // workspace cap one step reaches ~1e-7, so 1e-6 costs one step there; where cables sag
  // (s0/k > ~1.02) it takes more.
  double refined_relative_tolerance = 1e-6;
  int max_refinement_steps = 8;
  // kAas: ok only when its error estimate is at most this. AAS's own error is up to 0.65%
  // on the workspace cap +-3 m and grows fast as a cable sags (docs/model.md).
  double aas_max_relative_error = 1e-2;
  // kExact: converged when error_estimate <= this (its floor, set by rounding, is ~1e-14).
  double exact_relative_tolerance = 1e-12;
  // kExact: Newton iterations from one start (warm or AAS) before it falls back to the
  // continuation from the home pose; from AAS it needs 2 on the workspace cap.
  int exact_max_iterations = 12;
  // kExact: Newton iterations allowed for the continuation (its path steps together); the
  // bound on a solve's cost where the start fails (docs/model.md gives the measured cost).
  int exact_max_continuation_iterations = 300;
  // kExact only: tolerance of the per-cable solves that build its AAS start (the secants
  // then end at their cold start's evaluation, the s0 solves after one Newton step). The
  // start is then ~1e-5 from AAS, itself ~1e-3 from the solution, so Newton needs the
  // same number of steps and the result is unchanged.
  double exact_start_catenary_tolerance = 1e-4;
  // aas and aas-refined: tolerance of the twelve secant solves (the looser of this and
  // catenary.relative_tolerance). The secants only define AAS's straight lines, whose own
  // error is ~1e-3; at 1e-6 each solve ends after one Newton step instead of two, and the
  // AAS forces differ from fully converged secants' by at most 2.9e-7 relative over the
  // workspace cap (s0 by 2 um; tests/statics_test.cc). Warm-started, a start may meet the
  // tolerance as it is and end without a step: then by up to ~1.2e-5 (2000 random
  // 15-node paths; 7e-6 before the secant starts were extrapolated along the path).
  double aas_secant_tolerance = 1e-6;
  // aas and aas-refined: tolerance of the per-cable solves for s0 at the AAS horizontal
  // forces (the looser of this and catenary.relative_tolerance). They start from a
  // model-corrected guess ~1e-5 off, so at 1e-8 one Newton step ends them, leaving s0
  // within ~1e-8 relative (3 um on a 300 m cable).
  double aas_length_tolerance = 1e-8;
  // kAas only: solve each cable's curve point at AAS's Fl (one 2x2 Newton per cable),
  // for s0 and the check's exact Fz miss. Off (forces only: a fit's inner loop,
  // ModelFitStaticsOptions), s0 and the Fz miss come from the model-corrected guess of
  // that point (6.7e-5 in s0, 1.4e-5 of the tension in Fz over the workspace cap) and
  // d(L, Z)/dFz from the secant solves, with no catenary evaluation: the same forces, but
  // a rougher check, since aas's own Fz miss is only a few N there: error estimate 0.76
  // to 1.10 times the solved one, end residual 1.06 to 1.71 times (tests/statics_test.cc).
  bool compute_unstretched_lengths = true;
  // Limits of the model's range, checked on every solution. A cable whose tension
  // exceeds max_strain EA (or whose s0 <= 0) is refused as kOverstretchedCable: a linear
  // elastic bar stretched by several percent is no steel cable. One whose unstretched
  // length exceeds max_length_ratio times its chord is refused as kSaggingCable: it hangs
  // in a deep loop, far outside FAST's cable lengths (s0 in [0.95 k, 1.05 k]).
  // Over the workspace cap +-3 m the highest strain is 1.41% and s0/k lies in
  // [0.986, 1.004] (nominal FAST, all three methods). 5% leaves room for a calibration's
  // trial parameters on measured poses (at 3% a fit on poses near the limit stalled),
  // and still refuses the nonsense it is for (7.7% and more, s0 <= 0).
  double max_strain = 0.05;
  double max_length_ratio = 1.5;
  // With a reflector in the model (CableRobot::reflector): a cable whose lowest point is
  // closer to the reflector's surface than this (m; below it: negative clearance) is
  // refused as kReflectorContact. 0 refuses touching and passing through it.
  double min_reflector_clearance_m = 0.0;
  // Start from the solution already in *solution (when its status is ok), e.g. the
  // previous node of a trajectory: the secant solves and the exact Newton start there.
  // A warm start that fails is retried cold.
  bool warm_start = false;
  // The per-cable Newton solves. Their tolerance is looser than a lone solve's default
  // (1e-12): inside the statics each result starts a Newton iteration (exact), is
  // followed by one (aas-refined), or feeds a method whose own error is ~1e-3 (aas), so
  // tighter buys no accuracy and costs an evaluation per solve.
  CatenarySolverOptions catenary = {/*relative_tolerance=*/1e-10};

  bool IsValid(std::string* error) const;
};

// Options for fitting a model to measurements and for evaluating it there: `method` and
// every per-cable solve converged to catenary.relative_tolerance (AAS's looser secant and
// s0 solves off). With the loose ones, values and derivatives of an AAS model disagree at
// ~3e-7 relative, and Ceres took 17 iterations instead of 6 on 1e4 samples
// (tests/calibration_test.cc: AasForwardModelConvergesLikeExact). aas is accepted
// whatever its error estimate (aas_max_relative_error = infinity): in a fit its error is
// a bias that calibrate measures against exact and reports, and refusing the samples
// where a trial parameter set takes it over 1% made Ceres fail or crawl (a mass centre
// 0.5 m off takes it to 3% at the cap's edge; calibration_bench: 111 iterations, not 6).
// Its curve points are not solved (compute_unstretched_lengths off): the fit needs only
// the forces, and the solves made an aas calibration 20% slower (calibration_bench).
StaticsOptions ModelFitStaticsOptions(StaticsMethod method);

enum class StaticsStatus {
  kOk = 0,
  kInvalidInput,           // non-finite pose or parameters, or invalid options
  kVerticalCable,          // a chord is vertical: Fl's direction is undefined
  kNoEquilibrium,          // exact: no equilibrium with positive cable forces (Fl_i > 0)
  kSaggingCable,           // an equilibrium, but cable `cable` has s0/k = limit_value > limit
  kOverstretchedCable,     // an equilibrium, but cable `cable` has strain limit_value > limit
                           // (tension over max_strain EA), or s0 <= 0 (limit_value = s0/k)
  kReflectorContact,       // an equilibrium, but cable `cable`'s lowest point is closer to
                           // the reflector than limit (m): clearance limit_value
  kSingular,               // the 6x6 equilibrium matrix is singular
  kCatenaryFailed,         // a per-cable solve did not converge
  kNotConverged,           // exact or aas-refined did not reach its tolerance within its
                           // iteration limits: error estimate limit_value > limit
  kInaccurate,             // aas: error estimate limit_value > aas_max_relative_error, or
                           // (limit_value 0) AAS gave cable `cable` Fl <= 0
  kAttachmentBeyondCable,  // an equilibrium, but an attachment of cable `cable` starts at
                           // limit_value (m), at or beyond its unstretched length limit (m)
  kUnsupportedModel,       // aas, aas-refined: cable `cable` carries attachments, which the
                           // paper's secant lines do not describe (use exact)
};
// Short code for files and scripts: "ok", "invalid_input", "vertical_cable",
// "no_equilibrium", "sagging_cable", "overstretched_cable", "reflector_contact",
// "singular", "catenary_failed", "not_converged", "inaccurate", "attachment_beyond_cable",
// "unsupported_model".
const char* StaticsStatusName(StaticsStatus status);
// The enum's last status: every status is a value from kOk (0) to this one, which lists
// (solve --help, the Python module's STATUS_NAMES) run through. A new status goes last.
inline constexpr StaticsStatus kLastStaticsStatus = StaticsStatus::kUnsupportedModel;

// exact only: which equilibrium a solution is, where sagging cables let several hold one
// pose (docs/model.md, "Which equilibrium exact returns").
enum class EquilibriumBranch {
  kNone = 0,  // none returned (a failure before an equilibrium was found), or aas/aas-refined
  kTaut,      // the taut-cable equilibrium: its cables so nearly straight that it is proven
              // the only one that taut (StaticsSolution::taut_certificate < 1/2), whatever
              // the start that found it
  kFromHome,  // followed from the home pose; its cables sag too much for that proof, and
              // others may hold the pose (other_equilibrium says whether one was met)
};

struct CableSolution {
  // Force applied ON the cable at its lower end by the cabin, global frame (N). The
  // cabin feels -force_n.
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  double horizontal_force_n = 0.0;  // Fl
  // |force_n|, the true tension at the cabin end. The cabin-side sensor reads it through
  // its gain and bias: CableProperties::SensorReadingN (identity unless calibrated).
  double lower_tension_n = 0.0;
  double upper_tension_n = 0.0;       // at the tower end: sqrt(Fl^2 + (Fz + w s0)^2)
  double unstretched_length_m = 0.0;  // s0
  double chord_length_m = 0.0;        // k = |B_i - (R a_i + r_p)|
  // Distance between the upper end that (Fl, Fz, s0) reach (eqs. 14-16) and the tower top.
  double end_residual_m = 0.0;
  // AAS secant solutions at s0 = low/high fraction * k (kept for warm starts).
  CatenaryForces secant_low;
  CatenaryForces secant_high;
};

struct StaticsSolution {
  std::array<CableSolution, kNumCables> cables;
  StaticsStatus status = StaticsStatus::kInvalidInput;
  StaticsMethod method = StaticsMethod::kExact;  // the method that produced it
  int cable = -1;                                // 0-based cable concerned by a failure, else -1
  int outer_iterations = 0;     // refinement steps or exact Newton iterations (all starts)
  int catenary_iterations = 0;  // total per-cable Newton iterations
  bool continuation = false;    // exact followed the equilibrium from the home pose
  // exact: which equilibrium this is (also with a model-range status: of the equilibrium
  // whose range was checked), and its taut-cable certificate, sum_i |a_i - a_t,i| kappa_i
  // (or a bound of it; docs/model.md): below 1/2 for at most one equilibrium of a pose.
  EquilibriumBranch branch = EquilibriumBranch::kNone;
  double taut_certificate = 0.0;
  // exact: the solve met an equilibrium other than the one returned (its start from AAS
  // converged to it): several hold this pose. With kNoEquilibrium (or kNotConverged): the
  // home pose's branch does not reach the pose, yet an equilibrium exists there, reached
  // only through a fold (a jump of the cable lengths). Never set by a warm start's find:
  // the answer and this flag depend on the pose, not on the solve before.
  bool other_equilibrium = false;
  // |sum(-F_i) + W| and |sum r_i x (-F_i) + e x W| of the returned forces.
  double force_residual_n = 0.0;
  double moment_residual_nm = 0.0;
  // Largest CableSolution::end_residual_m: how far the returned state misses the end
  // conditions. 0 only to rounding for exact; aas misses them by construction.
  double end_residual_m = 0.0;
  // The method's own estimate of the largest relative error of the returned lower-end
  // tensions: the relative change of |F_i| that one Newton step from the returned state
  // would make, from the end conditions' residuals (first order in the error).
  double error_estimate = 0.0;
  // Smallest clearance of a cable from the reflector's surface (m; negative: the cable
  // passes through it), over the cables that could reach it: those that dip below their
  // cabin anchor (Fz > 0), or whose anchor lies below the reflector's rim. +infinity when
  // none could, or without a reflector in the model.
  double reflector_clearance_m = 0.0;
  // On failure, the number that decided it and the limit it broke (see StaticsStatus;
  // units as there), else 0.
  double limit_value = 0.0;
  double limit = 0.0;
  // Kept for warm starts (StaticsOptions::warm_start): the pose solved and, when this
  // solution was itself warm-started, the pose and each cable's (Fl, Fz, s0) of the one
  // before. exact starts the next pose from the two, extrapolated along the poses' path:
  // ~1e-4 from the solution on the paper's trajectories, against ~7e-3 for the last alone,
  // which saves a Newton step. aas and aas-refined extrapolate the starts of their secant
  // solves the same way, from the secants of the one before: along the paper's line 15-18
  // catenary evaluations a pose instead of 23 from the last secants alone. Only secants
  // that aas or aas-refined solved at their own pose count: previous_secant_* are zero
  // where the one before was exact's (it carries older secants, or loose ones of its
  // AAS start), and then the next solve starts from the last secants alone.
  Pose pose;
  bool has_previous = false;
  Pose previous_pose;
  std::array<std::array<double, 3>, kNumCables> previous_state{};
  std::array<CatenaryForces, kNumCables> previous_secant_low{}, previous_secant_high{};
};

// Solves the statics of `pose`. Returns solution->status: kInvalidInput also for options
// that StaticsOptions::IsValid refuses and for a robot whose anchor indices are out of
// range (a default-constructed CableRobot: start from NominalFast() or a YAML file). On
// failure the forces are zero (never NaN) and `cable`, limit_value and limit say why.
StaticsStatus SolveStatics(const CableRobot& robot, const Pose& pose, const StaticsOptions& options,
                           StaticsSolution* solution);
// The same with the cabin's moving parts at `joints` (Sample::joint: the model's joint
// order, the columns' units): the mass centre at c(q), moving_parts.h eq. (1). A robot
// without moving parts solves as above.
StaticsStatus SolveStatics(const CableRobot& robot, const Pose& pose, const JointValues& joints,
                           const StaticsOptions& options, StaticsSolution* solution);

// Short code for files of which equilibrium a solution is: "taut" (kTaut), "home"
// (kFromHome), "several" (either, with other_equilibrium), "unreachable" (no equilibrium
// from the home pose, but other_equilibrium), "" (none of these: no equilibrium found,
// or not exact).
const char* EquilibriumCode(const StaticsSolution& solution);

// A one-line human-readable account of a solution's status, naming the cable (1-based)
// and the numbers behind it.
std::string DescribeStatus(const StaticsSolution& solution);

}  // namespace fastcal

#include "fastcal/internal/statics_core.h"  // IWYU pragma: export

#endif  // FASTCAL_STATICS_H_
