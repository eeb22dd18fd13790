// The forward (direct geometrico-static) problem's equations and their analytic Jacobian,
// shared by the solver (locate.cc), the measured-pose fit (locate_fit.cc) and the tests.
// docs/model.md, "Forward statics"; Kozak, Zhou and Wang (2006, IEEE T-RO 22) for the
// elastic catenary cable robot; Briot and Merlet on the stability of sagging-cable robots.
//
// Unknowns (24): the pose x = (r_p, R) and each cable's lower-end force F_i (global axes,
// applied ON the cable by the cabin, as in statics.h). The attitude moves by a rotation
// vector in the global frame, R <- exp([dtheta]x) R, so dx = (dr_p, dtheta).
// Equations (24), with the unstretched lengths s0_i given:
//   closure      c_i = E_i(F_i; s0_i) - (B_i - r_p - r_i),   r_i = R a_i         (3 per cable)
//                E(F; s0) = (-h L, Z),  h = (Fx, Fy)/Fl,  Fl = |(Fx, Fy)|,
//                (L, Z) = span and rise of the catenary (or chain) at (Fl, Fz, s0)
//   equilibrium  q = (sum(-F_i) + W,  sum r_i x (-F_i) + e x W) = 0,  e = R r_e     (6)
// Jacobian (catenary.h's partials, chained):
//   dc_i/dF_i = D_i, symmetric: in the basis (h, h_perp, z)
//                [-dL/dFl, 0, -dL/dFz; 0, -L/Fl, 0; dZ/dFl, 0, dZ/dFz]  (dZ/dFl = -dL/dFz)
//   dc_i/dr_p = I,  dc_i/dtheta = -[r_i]x,   i.e. dc_i/dx = P_i = (I, -[r_i]x)
//   dc_i/ds0_i = g_i = (-h dL/ds0, dZ/ds0)
//   dq/dF_i = -P_i^T = -(I; [r_i]x),   dq/dx = S = (0, 0; 0, -sum [F_i]x [r_i]x + [W]x [e]x)
// Newton eliminates the forces cable by cable (D_i is 3x3):
//   K dx = -q - sum P_i^T D_i^-1 c_i,   K = S + sum P_i^T D_i^-1 P_i,
//   dF_i = -D_i^-1 (c_i + P_i dx).
// K is the derivative of the cabin's net wrench along the cables' closures with the lengths
// held: minus the Hessian of the potential energy (the cables' elastic and gravitational
// energy and the cabin's weight), symmetric at an equilibrium. The equilibrium is stable
// where -K is positive definite (Briot and Merlet). The pose's sensitivity to the lengths
// follows from the same blocks: G dS0 + K dx = 0 with G = (P_i^T D_i^-1 g_i)_i, so
//   dx/ds0 = -K^-1 G,   dF_i/ds0 = -D_i^-1 (P_i dx/ds0 + g_i e_i^T),
// and at fixed pose (the inverse problem) ds0/dx = -G^-1 K.
#ifndef FASTCAL_INTERNAL_FORWARD_STATICS_H_
#define FASTCAL_INTERNAL_FORWARD_STATICS_H_

#include <Eigen/Core>
#include <array>

#include "fastcal/cable_robot.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"

namespace fastcal::internal {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Lengths = std::array<double, kNumCables>;

// The forward problem's 24 unknowns.
struct ForwardState {
  Pose pose;
  std::array<Eigen::Vector3d, kNumCables> force_n;  // on cable i at its lower end, global
};

// Cable i's end point in 3-D and its partials (file comment): E, D = dE/dF (and its
// inverse), g = dE/ds0, with the tensions at both ends.
struct CableEnd3d {
  Eigen::Vector3d end_m;         // E: upper end relative to the lower end, global axes
  Eigen::Matrix3d d;             // dE/dF
  Eigen::Matrix3d d_inverse;     // (dE/dF)^-1
  Eigen::Vector3d de_ds0;        // dE/ds0
  double lower_tension_n = 0.0;  // |F|
  double upper_tension_n = 0.0;
};

// False (and *end untouched) where the horizontal force is not positive or D is singular.
bool CableEnd3dAt(const StaticsParameters<double>& p, int i, const Eigen::Vector3d& force_n,
                  double s0_m, CableEnd3d* end);

// The equations and their eliminated Newton system at one state (file comment).
struct ForwardLinearisation {
  std::array<CableEnd3d, kNumCables> ends;
  std::array<Eigen::Vector3d, kNumCables> r;          // R a_i
  std::array<Eigen::Vector3d, kNumCables> closure_m;  // c_i
  std::array<double, kNumCables> chord_m{};
  Vector6d wrench = Vector6d::Zero();     // q: net force (N) and moment about O' (N m) on the cabin
  Matrix6d stiffness = Matrix6d::Zero();  // K = dq/dx along the closures, lengths held
  Matrix6d length_coupling = Matrix6d::Zero();  // G: column i = P_i^T D_i^-1 g_i
  // Scaled squared residual: sum |c_i|^2 / k_i^2 + |q_f|^2 / W^2 + |q_m|^2 / (W rho)^2,
  // rho = the cabin's size (ForwardScales). Newton's direction descends it.
  double merit = 0.0;
};

// The sizes that make the residuals and steps comparable: the cabin's weight |m g| (N)
// and its size rho (m, the farthest anchor from O', at least 1 m), which turns a rotation
// into the anchors' move.
struct ForwardScales {
  double weight_n = 1.0;
  double size_m = 1.0;
};
ForwardScales MakeForwardScales(const StaticsParameters<double>& p);

// False where a cable's end cannot be evaluated (CableEnd3dAt).
bool LineariseForward(const StaticsParameters<double>& p, const ForwardScales& scales,
                      const Lengths& s0_m, const ForwardState& x, ForwardLinearisation* lin);

// The Newton step from a linearisation: dx (dr_p, dtheta) and each dF_i; false when K is
// singular (the step is not finite).
bool ForwardNewtonStep(const ForwardLinearisation& lin, Vector6d* dx,
                       std::array<Eigen::Vector3d, kNumCables>* dforce_n);

// Six zero forces (a std::array of Eigen vectors is not zeroed by `{}`).
std::array<Eigen::Vector3d, kNumCables> ZeroForces();

// The state moved by a fraction of a step.
ForwardState MoveState(const ForwardState& x, const Vector6d& dx,
                       const std::array<Eigen::Vector3d, kNumCables>& dforce_n, double fraction);

// |dr_p|^2 + rho^2 |dtheta|^2, square-rooted: how far a step moves the cabin's anchors, at most.
double StepSizeM(const Vector6d& dx, double size_m);

// The residuals (c_1, ..., c_6, q) and the 24 x 24 Jacobian d(residuals)/d(F_1, ..., F_6, dx),
// assembled from the same blocks as the Newton system (for the tests and docs/model.md).
Eigen::Matrix<double, 24, 1> ForwardResiduals(const ForwardLinearisation& lin);
Eigen::Matrix<double, 24, 24> ForwardJacobian(const StaticsParameters<double>& p,
                                              const ForwardState& x,
                                              const ForwardLinearisation& lin);

// dx/ds0 = -K^-1 G and dF/ds0 (rows 3i..3i+2: cable i) at a linearisation; false when K
// is singular.
bool LengthSensitivity(const ForwardLinearisation& lin, Matrix6d* pose_per_length,
                       Eigen::Matrix<double, 3 * kNumCables, kNumCables>* force_per_length);

// The per-cable forces that close each cable at `pose` with lengths s0 (one catenary solve
// per cable, catenary.h), horizontal along the chord: the start of a Newton solve from a
// pose alone. False where a cable cannot be closed (vertical chord, no convergence).
bool ClosedForcesAt(const StaticsParameters<double>& p, const Lengths& s0_m, const Pose& pose,
                    std::array<Eigen::Vector3d, kNumCables>* force_n);

// The rotation vector (global frame) that takes `from` to `to`: to = exp([v]x) from.
Eigen::Vector3d RotationDifference(const Eigen::Matrix3d& to, const Eigen::Matrix3d& from);
// Its derivative as `to` turns by exp([dtheta]x): the inverse left Jacobian of SO(3) at
// phi = RotationDifference(to, from),
//   J_l^-1(phi) = I - [phi]x/2 + (1/|phi|^2 - (1 + cos|phi|)/(2 |phi| sin|phi|)) [phi]x^2.
Eigen::Matrix3d InverseLeftJacobian(const Eigen::Vector3d& phi);

// [v]x, the cross-product matrix: [v]x u = v x u.
Eigen::Matrix3d Skew(const Eigen::Vector3d& v);

// The home pose the inverse statics' continuation (statics.cc) and the forward solver
// (locate.cc) start from: level (R = I), below the centroid of the tower tops by 130/300
// of their mean horizontal distance from it. For FAST that is K1 = (0, 0, 140) m (130 m
// below 270 m tower tops at 300 m), where all cables are taut.
Pose HomePose(const StaticsParameters<double>& p);

}  // namespace fastcal::internal

namespace fastcal {

struct LocateSolution;

// *solution as a failed Locate leaves it (locate.h): the lengths asked for, everything else
// zero, the identity pose; status untouched.
void ResetLocateSolution(const std::array<double, kNumCables>& unstretched_length_m,
                         LocateSolution* solution);

// Checks a state of the statics given from outside (each cable's Fl, Fz, s0 at `pose`: a
// forward solution) as SolveStatics checks exact's own (statics.cc): end residuals, error
// estimate at most options.exact_relative_tolerance (else kNotConverged), equilibrium
// residuals, model range, reflector. *solution is filled as SolveStatics fills it (method
// exact; no warm-start data), forces zero on failure.
StaticsStatus CheckStaticsState(const StaticsParameters<double>& p, const Pose& pose,
                                const std::array<internal::CableState<double>, kNumCables>& state,
                                const StaticsOptions& options, StaticsSolution* solution);

}  // namespace fastcal

#endif  // FASTCAL_INTERNAL_FORWARD_STATICS_H_
