// The derivatives of exact's six lower-end tensions with respect to every statics
// parameter, by the implicit-function theorem at the converged solution (issue 28: the
// calibration's Jacobians were ceres::Jets 32 to 128 wide through a replayed Newton step).
//
// Unknowns per cable (Fl_i, Fz_i, s0_i); equations (statics.h): the end conditions
//   E_i = (span_i(Fl, Fz, s0; w_i, EA_i, chain_i) - L_i, rise_i(...) - Z_i) = 0
// and the six equilibrium rows G(Fl, Fz; u, r, e, m g) = 0. At a solution, a change dp of
// the parameters moves the unknowns by the solution of the same linear system Newton
// factors: d(span, rise)/d(Fl, Fz, s0) d(state) = -dE/dp dp, with ds0 eliminated by the
// normal n = (drise/ds0, -dspan/ds0) of each cable:
//   dFz_i = a_i dFl_i + db_i,   a_i = -(n . dE/dFl) / (n . dE/dFz),   db_i = -(n . c_i) / (n .
//   dE/dFz)
// with c_i = dE_i/dp dp (the end point's own parameters w, EA, chain values, and -dL, -dZ
// of the chord). The equilibrium rows then give the 6x6 system of the Newton step,
//   A dFl = h,   A = the matrix of statics.h's rows with Fz = a Fl + b,
//   h = d(right-hand side) - (dA0 Fl + dB Fz) - B db
// (dA0, dB: the rows' Fl and Fz coefficients moved by the geometry; B_i = (0, 0, 1, ry_i,
// rx_i, 0)), and the tension T_i = sqrt(Fl_i^2 + Fz_i^2) moves by
//   dT = K h + diag(Fz / T) db,   K = diag((Fl + a Fz) / T) A^-1.
// K is formed once per pose (one 6x6 factorisation); each parameter then costs a few
// multiply-adds. The geometry's derivatives: with c_i = B_i - (R a_i + p) the chord,
// dL = ux dc_x + uy dc_y, dZ = dc_z and (ux, uy) turns by phi = (uy dc_x - ux dc_y) / L,
// d(ux, uy) = phi (uy, -ux); r_i = R a_i, e = R r_e, W = m g.
//
// End-point derivatives: with respect to EA analytically (span = Fl s0 / EA + ...,
// rise = -(Fz + w s0 / 2) s0 / EA - ...), and with respect to w by Euler's relation: the
// end point is homogeneous of degree 0 in (Fl, Fz, w, EA) (scale every force and EA alike
// and the shape is the same), so w dX/dw = -(Fl dX/dFl + Fz dX/dFz + EA dX/dEA). A cable
// with attachments (catenary_chain.h) takes its w, EA and chain-value derivatives from a
// small ceres::Jet through the chain's end point.
//
// Exact only: aas and aas-refined are explicit sequences of solves whose derivatives are
// not those of an equilibrium (the calibration replays them in Jets: calibration_model.h).
#ifndef FASTCAL_INTERNAL_TENSION_GRADIENT_H_
#define FASTCAL_INTERNAL_TENSION_GRADIENT_H_

#include <Eigen/Core>
#include <array>

#include "fastcal/cable_attachment.h"
#include "fastcal/statics.h"

namespace fastcal::internal {

using Vector6d = Eigen::Matrix<double, kNumCables, 1>;
using Matrix63d = Eigen::Matrix<double, kNumCables, 3>;

// d tension / d parameter: entry (i) of each vector is cable i's lower-end tension's
// derivative (N per parameter unit), one vector per parameter of StaticsParameters.
struct TensionGradient {
  std::array<double, kNumCables> tension_n{};  // the solution's lower-end tensions
  // Only when asked for (ExactTensionGradient's `geometry`): left as they are otherwise.
  std::array<Matrix63d, kNumCables> tower_top_m;  // d T / d tower_top_m[c] (global axes)
  std::array<Matrix63d, kNumCables> anchor_m;     // d T / d anchor_cabin_m[c] (cabin axes)
  std::array<Vector6d, kNumCables> ea_n;
  std::array<Vector6d, kNumCables> linear_density_kg_per_m;
  // d T / d chain[c].value[j], for j < the cable's num_attachments.
  std::array<std::array<Vector6d, kMaxAttachmentsPerCable>, kNumCables> chain_value;
  Vector6d cabin_mass_kg;
  Matrix63d mass_centre_cabin_m;  // cabin axes
};

// The gradient at `solution`, an exact solution (status ok) of `p` at `pose`; the tower
// and anchor columns only with `geometry` (36 of the ~100 columns, a fifth of the cost).
// Returns kSingular where the equilibrium system cannot be factored (it was solved, so
// only at a pose the solver itself barely held), kVerticalCable as ComputeGeometry.
// With `tensions_from_state`, only each cable's state (Fl, Fz, s0) is read from
// `solution` (CompactStart::Restore's): gradient->tension_n are the lower end tensions
// evaluated there, by the end evaluation the solver's last check makes (so the same
// numbers as its solution's, for a state it converged to).
StaticsStatus ExactTensionGradient(const StaticsParameters<double>& p, const Pose& pose,
                                   const StaticsSolution& solution, double vertical_span_fraction,
                                   bool geometry, TensionGradient* gradient,
                                   bool tensions_from_state = false);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_TENSION_GRADIENT_H_
