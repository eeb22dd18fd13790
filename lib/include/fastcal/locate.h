// Forward statics: where the cabin hangs, given the six unstretched cable lengths the
// winches have paid out (the direct geometrico-static problem; docs/model.md, "Forward
// statics"), and the pose that best fits those lengths together with a measured attitude
// and measured tensions.
//
// With sagging cables the problem has no closed form. The pose (6) and each cable's
// lower-end force (3 x 6) are solved together from each cable's end-to-end closure (the
// catenary of catenary.h, or the chain of catenary_chain.h, with s0 given: 3 x 6) and the
// cabin's equilibrium (6): 24 equations, 24 unknowns, by Newton on the analytic Jacobian,
// the forces eliminated cable by cable (equations: fastcal/internal/forward_statics.h).
//
// Starts (Merlet 2019, 2020: several equilibria may exist; which one is found depends on
// where the search starts):
//   warm   the previous answer (LocateOptions::warm_start), moved to the new lengths by its
//          sensitivity dx/ds0 (first order): along a trajectory Newton then needs 2 steps;
//   cold   the continuation from the robot's home pose (the same as the inverse solver's,
//          statics.h), whose lengths the inverse statics give: the lengths are moved from
//          the home pose's to the given ones in steps, each point predicted along the path's
//          tangent and corrected by Newton. It finds the equilibrium the cabin reaches when
//          the winches move it from home, and reports no_equilibrium where that path ends
//          (a fold of the equilibria, or a cable going slack) before the given lengths.
//
// Every answer is checked as SolveStatics checks exact's (statics.h, "Checking every
// solution"): each cable's end conditions at the found forces and the given lengths, the
// error estimate, the equilibrium residuals, the model's range and the reflector; the
// checked StaticsSolution comes with the answer. Its stability is stated: the Hessian of
// the potential energy with the lengths held (Briot and Merlet), positive definite or not.
// Other equilibria near the answer are looked for by Newton from starts displaced along
// each of the Hessian's six modes; a local search, not a proof of uniqueness.
//
// Nothing here allocates per pose or throws: a failure is a status, with zero forces.
#ifndef FASTCAL_LOCATE_H_
#define FASTCAL_LOCATE_H_

#include <Eigen/Core>
#include <array>
#include <string>

#include "fastcal/cable_robot.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"

namespace fastcal {

enum class Stability {
  kUnknown = 0,  // no equilibrium to judge
  kStable,       // the potential's Hessian (lengths held) is positive definite
  kUnstable,     // it has a negative eigenvalue: a small push and the cabin moves away
  kMarginal,     // its smallest eigenvalue is zero to LocateOptions::marginal_stiffness_fraction:
                 // at a fold, where two equilibria meet
};
// "unknown", "stable", "unstable", "marginal".
const char* StabilityName(Stability stability);

struct LocateOptions {
  // Converged when the next Newton step would move the cabin's anchors by at most this (m):
  // the position's step and the rotation's times the cabin's size (its farthest anchor).
  // Rounding sets the floor at ~1e-13 m.
  double tolerance_m = 1e-10;
  // Newton iterations from one start (warm, a point of the continuation, a search start)
  // before it is given up.
  int max_iterations = 12;
  // Newton iterations the continuation from the home pose may take in all: the bound on a
  // cold solve's cost.
  int max_continuation_iterations = 400;
  // Start from the answer already in *solution (when its status is ok), moved to the new
  // lengths by its sensitivity. A warm start that fails is retried cold.
  bool warm_start = false;
  // An eigenvalue of the scaled Hessian (LocateSolution::stiffness) within this fraction of
  // the largest counts as zero: the equilibrium is marginal.
  double marginal_stiffness_fraction = 1e-9;
  // Other equilibria near the answer: Newton from starts this far from it (m, the anchors'
  // largest move) along each of the Hessian's six modes, both ways: 12 solves, each ended
  // after max_iterations. 0 searches none.
  double search_radius_m = 2.0;
  // Two equilibria closer than this (m, anchors' move) are the same one.
  double distinct_m = 1e-6;
  // The checks (exact_relative_tolerance), the model's range (max_strain,
  // max_length_ratio, min_reflector_clearance_m) and the per-cable solves (catenary) of
  // the inverse statics, which check every answer and give the continuation's start.
  StaticsOptions statics;

  bool IsValid(std::string* error) const;
};

// An equilibrium of the same lengths found near the answer.
struct OtherEquilibrium {
  Pose pose;
  double distance_m = 0.0;  // the anchors' largest move from the answer
  Stability stability = Stability::kUnknown;
  StaticsStatus status = StaticsStatus::kInvalidInput;  // its check: ok, or the range it breaks
};

// The fit of LocateFromMeasurements (with a measured attitude or tensions).
struct LocateFit {
  bool fitted = false;  // false: lengths alone, the exact forward solution
  int readings = 0;     // lengths, attitude components and tensions used
  int iterations = 0;   // Gauss-Newton steps
  double chi2 = 0.0;    // sum of the whitened residuals squared; readings - 6 degrees of freedom
  // Model minus measured, per cable (m; sensor readings in N) and the attitude (measured to
  // fitted rotation vector, rad, global axes); zero where not measured.
  std::array<double, kNumCables> length_residual_m{};
  std::array<double, kNumCables> tension_residual_n{};
  Eigen::Vector3d attitude_residual_rad = Eigen::Vector3d::Zero();
  // Of the answer's (r_p (m), rotation vector (rad, global axes)): for lengths alone
  // sigma_L^2 (dx/ds0)(dx/ds0)^T, for a fit (J^T J)^-1 of its whitened residuals; zero
  // from Locate (no noise model) and on failure.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

struct LocateSolution {
  StaticsStatus status = StaticsStatus::kInvalidInput;
  Pose pose;  // the answer (identity and zero on failure)
  // The statics at the answer: forces, tensions, lengths, and the checks behind the ok
  // (statics.h). On a failure of the model's range (sagging_cable, ...) its cable,
  // limit_value and limit say why.
  StaticsSolution statics;
  std::array<double, kNumCables> unstretched_length_m{};  // the lengths solved for
  int iterations = 0;         // Newton iterations, all starts and the search included
  bool continuation = false;  // the answer came from the continuation from the home pose
  // The size of the Newton step that would follow the answer: its error (m, anchors' move).
  double error_estimate_m = 0.0;
  // Stability: the Hessian of the potential energy with the lengths held, H = -dq/dx (q the
  // net wrench on the cabin, x = (r_p, rotation vector in the global frame)), rows and
  // columns of the rotation scaled by 1 / the cabin's size so that all are in N/m.
  Stability stability = Stability::kUnknown;
  int unstable_modes = 0;              // its negative eigenvalues
  double min_stiffness_n_per_m = 0.0;  // its smallest eigenvalue
  Eigen::Matrix<double, 6, 6> stiffness = Eigen::Matrix<double, 6, 6>::Zero();
  // How the pose moves with each length: d(r_p (m), rotation vector (rad))/d s0_j.
  Eigen::Matrix<double, 6, kNumCables> pose_per_length = Eigen::Matrix<double, 6, 6>::Zero();
  // The search for other equilibria (LocateOptions::search_radius_m).
  bool searched = false;
  int other_equilibria = 0;  // distinct ones found
  OtherEquilibrium nearest_other;
  LocateFit fit;
  // For the next warm start: each cable's lower-end force (global, on the cable) and
  // d(force)/d s0 (rows 3i..3i+2: cable i).
  std::array<Eigen::Vector3d, kNumCables> force_n{};
  Eigen::Matrix<double, 3 * kNumCables, kNumCables> force_per_length =
      Eigen::Matrix<double, 3 * kNumCables, kNumCables>::Zero();
};

// The pose at which the cabin hangs with unstretched lengths `unstretched_length_m` (the
// model's s0, m). Returns solution->status: ok, or invalid_input (a length not finite or
// <= 0, invalid options or model), no_equilibrium (the continuation from home ends before
// these lengths), not_converged (out of iterations), singular, vertical_cable, and the
// model-range statuses of the check (sagging_cable, overstretched_cable,
// reflector_contact, attachment_beyond_cable), whose equilibrium exists but lies outside
// the model's range. On failure the pose is the identity at the origin and the forces zero.
StaticsStatus Locate(const CableRobot& robot,
                     const std::array<double, kNumCables>& unstretched_length_m,
                     const LocateOptions& options, LocateSolution* solution);

// One line for people: the status with its cable and numbers, the stability, and other
// equilibria found.
std::string DescribeLocateStatus(const LocateSolution& solution);

// What was measured at one instant.
struct LocateMeasurement {
  // The lengths as the winches' encoders give them (m): the model's unstretched length
  // plus its length_offset_m (CableProperties::EncoderReadingM), which
  // LocateFromMeasurements removes.
  std::array<double, kNumCables> length_m{};
  bool has_attitude = false;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // measured attitude
  bool has_tensions = false;
  std::array<double, kNumCables> tension_n{};  // the sensors' readings (gain and bias apply)
};

// The measurements' standard deviations (the calibration spec's noise model for tensions).
struct LocateNoise {
  double length_sigma_m = 0.01;
  // sigma_i^2 = tension_sigma_n^2 + (tension_sigma_percent/100 * predicted reading_i)^2.
  double tension_sigma_n = 0.0;
  double tension_sigma_percent = 3.0;
  double attitude_sigma_deg = 0.05;  // per axis of the rotation vector

  bool IsValid(std::string* error) const;
};

// Lengths alone: Locate, with the covariance of the answer (solution->fit). With a measured
// attitude or tensions: the pose minimising the whitened residuals of all of them (Gauss-Newton
// from the lengths' answer; the model's lengths, tensions and their derivatives from the inverse
// statics at each trial pose), with solution->fit filled and the stability judged at the fitted
// pose's equilibrium.
StaticsStatus LocateFromMeasurements(const CableRobot& robot, const LocateMeasurement& measurement,
                                     const LocateNoise& noise, const LocateOptions& options,
                                     LocateSolution* solution);

// d(roll, pitch, yaw)/d(rotation vector, global axes) at `rotation` (deg/rad), to turn the
// covariance's attitude block into roll/pitch/yaw sigmas.
Eigen::Matrix3d RpyDegPerRotationVector(const Eigen::Matrix3d& rotation);

}  // namespace fastcal

#endif  // FASTCAL_LOCATE_H_
