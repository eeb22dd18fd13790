// Vibrations: the natural frequencies and modes of the cabin and its six sagging cables,
// linearised about the exact static equilibrium of a pose (docs/model.md, "Vibrations").
//
// The six cables weigh about 22 t against the 30 t cabin, so the lowest modes couple
// cables and cabin: each cable is a lumped-mass chain (the mooring model of MoorDyn, Hall
// and Goupee 2015, Ocean Eng. 104), the cabin a rigid body, and the undamped small motions
// about the equilibrium solve the symmetric generalised eigenproblem K phi = omega^2 M phi.
// The equations, their assumptions and where they come from open lib/src/dynamics/modes.cc.
//
// Degrees of freedom: the cabin's translation u of O' and small rotation theta (global
// axes, rad), then each cable's N - 1 interior nodes (3 each): 6 + 18 (N - 1) in all. The
// top node is fixed at the tower (winches held); the bottom node moves with the cabin's
// anchor point, u_anchor = u + theta x r_i.
#ifndef FASTCAL_MODES_H_
#define FASTCAL_MODES_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"

namespace fastcal {

// The most modes ModesOptions may ask for: ten times the default. The Lanczos basis holds
// about twice as many vectors of every degree of freedom, and a problem with fewer
// degrees of freedom than twice the modes is solved densely.
inline constexpr int kMaxModes = 200;

struct ModesOptions {
  // Segments per cable (N >= 2). The lumped chain's frequencies fall short of the
  // converged ones by ~C/N^2: at 48 the 10 lowest of the nominal FAST model are within
  // 0.021% and the 20 lowest within 0.071% of the converged values, at the zenith and 40
  // deg off axis (at 24: 0.085% and 0.28%; docs/model.md, "Vibrations", the table), in
  // ~20 ms a pose.
  int segments = 48;
  // How many of the lowest modes to return, 1 to kMaxModes; fewer when the model has fewer
  // degrees of freedom.
  int modes = 20;
  // false: the cables' inertia is ignored (their weight still shapes the equilibrium and
  // their stiffness): the cabin alone on the cables' static stiffness, the interior nodes
  // condensed out (Guyan; exact in this limit). Six modes at most. A check of the cabin's
  // mass matrix and load stiffness against the statics (tests/modes_test.cc).
  bool cable_inertia = true;
  // How the eigenproblem is solved: shift-invert Lanczos for the lowest modes (Spectra,
  // on a sparse LDL^T of K; the default), or densely (Eigen, all modes, O(n^3): a check).
  // Problems of fewer than ~120 degrees of freedom are solved densely either way.
  enum class Solver { kShiftInvertLanczos, kDense };
  Solver solver = Solver::kShiftInvertLanczos;
  // The equilibrium about which the system is linearised: exact by default (the only
  // method whose forces close every catenary; aas and aas-refined are refused).
  StaticsOptions statics;

  bool IsValid(std::string* error) const;
};

// One mode. The shares split its kinetic energy (they sum to 1): the cabin's as the
// translation of its mass centre along x, y, z and its rotation about the global axes
// x, y, z through the mass centre (the rotation's energy theta^T I theta split as the
// squares of I^(1/2) theta, which for an inertia diagonal in the global axes is I_kk
// theta_k^2), and each cable's (its moving nodes, and the half segment at its anchor).
struct Mode {
  double frequency_hz = 0.0;
  Eigen::Vector3d cabin_translation_share = Eigen::Vector3d::Zero();
  Eigen::Vector3d cabin_rotation_share = Eigen::Vector3d::Zero();
  std::array<double, kNumCables> cable_share{};
  double cables_share = 0.0;  // the sum of cable_share
  int dominant_cable = 0;     // 0-based: the cable with the largest share
  // The cabin's part of the mode shape, (u (m), theta (rad)) in global axes, scaled so
  // that phi^T M phi = 1 kg m^2 over the whole system (the sign is arbitrary).
  Eigen::Matrix<double, 6, 1> cabin_shape = Eigen::Matrix<double, 6, 1>::Zero();

  double CabinShare() const { return cabin_translation_share.sum() + cabin_rotation_share.sum(); }
};

struct ModesResult {
  // The equilibrium linearised about (its forces, tensions and lengths).
  StaticsSolution statics;
  // Ascending in frequency.
  std::vector<Mode> modes;
  int degrees_of_freedom = 0;  // of the eigenproblem solved
  // max |K - K^T| / max |K| before K was symmetrised: the load stiffness's antisymmetric
  // part is half the net moment on the cabin, so this is the equilibrium's residual.
  double stiffness_asymmetry = 0.0;
  // cable_inertia = false: the cabin's 6x6 stiffness at O' (N/m, N, N m/rad; rows and
  // columns (u, theta)), the cables condensed out; zero otherwise.
  Eigen::Matrix<double, 6, 6> cabin_stiffness = Eigen::Matrix<double, 6, 6>::Zero();
};

// The modes at `pose`. False with the reason in *error: invalid options or model, a
// model whose cables carry attachments (not supported yet), a pose the statics cannot
// hold (their status and account), or an unstable equilibrium (a negative eigenvalue).
bool ComputeModes(const CableRobot& robot, const Pose& pose, const ModesOptions& options,
                  ModesResult* result, std::string* error);

// The modes as CSV, one row per mode, ascending (docs/cli.md, "modes"): mode (1-based),
// frequency_hz, period_s, the kinetic energy's shares share_x, share_y, share_z (the
// cabin's translation), share_rx, share_ry, share_rz (its rotation), share_cables,
// dominant_cable (1-based), dominant_cable_share, and kind: "cabin" when the cabin holds
// more than half the energy, else "cable".
std::string ModesCsv(const ModesResult& result);

// One uniform elastic cable hanging between two fixed points, its lower end at the origin
// and its upper end `span_m` along x and `rise_m` up: the isolated cable of Irvine and
// Caughey's theory, for the checks. The cable plane is x-z.
struct FixedCable {
  double span_m = 0.0;
  double rise_m = 0.0;
  double unstretched_length_m = 0.0;
  double ea_n = 0.0;
  double linear_density_kg_per_m = 0.0;  // unstretched
  double gravity_m_per_s2 = -9.8;        // negative: z up
};

struct CableMode {
  double frequency_hz = 0.0;
  // Share of the kinetic energy in the cable's plane (x, z); the rest is out of it (y).
  double in_plane_share = 0.0;
  // Of the in-plane modes: the vertical displacement at mid-span, over its largest
  // magnitude; ~0 for an antisymmetric mode of a level cable, and near +-1 for a
  // symmetric one.
  double midspan_vertical = 0.0;
};

// The lowest `options.modes` modes of `cable` with `options.segments` segments (the
// options' statics and cable_inertia do not apply). False with *error on invalid input or
// when the catenary cannot be solved.
bool ComputeFixedCableModes(const FixedCable& cable, const ModesOptions& options,
                            std::vector<CableMode>* modes, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_MODES_H_
