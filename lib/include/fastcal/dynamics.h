// Dynamics in time: the cabin and its six sagging cables moving, with the winches paying
// out, structural damping and the wind's drag (docs/model.md, "Dynamics").
//
// The same discretisation as the modes (modes.h): each cable a lumped-mass chain of N
// segments (MoorDyn's model: Hall and Goupee 2015, Ocean Eng. 104), the cabin a rigid body
// with its mass, mass centre and inertia; here nonlinear in the geometry, a slack segment
// carrying no force, the segments damped in proportion to their strain rate, the air's
// drag on the cabin and the cables. The equations open lib/src/dynamics/chain_system.cc.
//
// Winches: each winch sets its cable's paid-out unstretched length s0(t), spread evenly
// over the N segments (l0 = s0/N; the node masses follow). Paying out at the tower only
// (the top segment growing, split when too long) would change N during a move; spread
// evenly, N stays, the chain's statics at any s0 is the quasi-static reference on the
// same mesh, and what differs, the momentum of cable running along itself at the
// winch's speed (< 0.2 m/s), is below a newton on 10^5 N tensions.
//
// Integrator: the generalised-alpha method of Chung and Hulbert (1993, J. Appl. Mech. 60),
// in the form of Arnold and Bruls (2007, Multibody Syst. Dyn. 18) that solves each step's
// equations of motion at its end (so the cabin's rotation updates as R <- exp([theta]x) R,
// with theta the step's rotation vector, and the forces are evaluated at one state), with a
// Newton iteration per step on the bordered block-tridiagonal tangent (each chain's
// blocks eliminated onto the cabin's six unknowns: O(N) per cable). Why: the axial waves
// of steel cables (1.4 km/s, 2.3 Hz and up to ~60 Hz at N = 40) against modes at
// 0.13-0.4 Hz make the problem stiff; an explicit scheme needs steps of a few ms
// (MoorDyn's limit dt < 2/omega_max), an unconditionally stable implicit one steps with
// the motion (20 ms by default). Second order; spectral_radius = 1 is the trapezoidal rule
// (Newmark's average acceleration: no numerical damping, the energy of a linear system
// conserved); below 1 it damps what the step cannot resolve (the axial waves) while
// leaving the 0.15 Hz modes' damping changed by ~1e-7.
//
// The start: at rest in the static equilibrium of the chains themselves, holding the
// unstretched lengths the exact statics give at the requested pose (found by Newton from
// the catenary's nodes): a fixed point of the equations in time. It lies within ~1 mm of
// the pose at N = 40 (the chains' polygons against the catenary's curve, O(1/N^2));
// DynamicsStart says by how much.
#ifndef FASTCAL_DYNAMICS_H_
#define FASTCAL_DYNAMICS_H_

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/modes.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"
#include "fastcal/wind.h"

namespace fastcal {

struct DynamicsOptions {
  // Segments per cable (>= 2): as modes.h. At 40 the 10 lowest frequencies are within 0.03%
  // of the converged ones (docs/model.md, "Vibrations").
  int segments = 40;
  // Structural damping: the damping ratio of the lowest mode at the start (FAST's lowest
  // measured, 0.004), reached by one strain-rate coefficient tau shared by the cables
  // (segment tension += tau EA d(strain)/dt, tau = 2 zeta omega_1 / (phi_1^T K_axial phi_1)
  // for the M-normalised lowest mode phi_1; refused when that mode puts under 1e-4 of its
  // strain energy into the cables' stretch: FAST's puts 6.7%). 0: undamped.
  double damping_ratio = 0.004;
  // Or per cable, when given (6 values in [0, 1)): cable i's own damping ratio in its first
  // axial mode between fixed ends, tau_i = 2 zeta_i / omega_i,
  // omega_i = (pi / s0_i) sqrt(EA_i / rho_i); damping_ratio is then not used.
  std::vector<double> cable_damping_ratio;
  // The largest integration step (s, > 0); steps are equal within each Advance.
  double max_step_s = 0.02;
  // Generalised-alpha's spectral radius at infinite frequency, in [0, 1]: 1 the
  // trapezoidal rule (conserves a linear system's energy: the energy check), 0.9 by
  // default (damps the unresolved axial waves; a 0.15 Hz mode at 20 ms loses ~1e-7 of its
  // damping ratio).
  double spectral_radius = 0.9;
  // Newton per step: converged when the correction of every displacement is below this
  // (m, or rad for the cabin's rotation), within max_newton_iterations; otherwise the
  // step is halved, at most max_step_halvings times.
  double newton_tolerance_m = 1e-9;
  int max_newton_iterations = 16;
  int max_step_halvings = 8;
  // Aerodynamic drag (0.5 rho C_d A |u| u on the air's relative velocity u): the cabin's
  // C_d A (m^2; FAST's cabin is ~13 m across and ~5 m high: 50 m^2 assumes C_d ~ 0.8,
  // acting at O'), the cables' drag diameter (m; the steel strand is 14 mm, but the cables
  // carry the feed's power and signal lines: 0.1 m assumed) and coefficient (1.2, a
  // circular cylinder's across the flow).
  double air_density_kg_per_m3 = 1.225;
  double cabin_drag_area_m2 = 50.0;
  double cable_drag_diameter_m = 0.1;
  double cable_drag_coefficient = 1.2;
  WindOptions wind;
  // The exact statics of the start pose (and of a move's poses): their unstretched
  // lengths are what the winches hold.
  StaticsOptions statics;

  bool IsValid(std::string* error) const;
};

// The start, and how it stands against the exact statics of the requested pose.
struct DynamicsStart {
  StaticsSolution statics;         // exact, at the requested pose
  Pose equilibrium;                // where the chains hold the cabin at those lengths
  double position_offset_m = 0.0;  // |equilibrium - pose| of O'
  double attitude_offset_deg = 0.0;
  // Largest |T_chain - T_exact| / T_exact over the cables (lower ends).
  double tension_offset = 0.0;
  // The chains' own lowest modes at the equilibrium (undamped, Hz), and each one's
  // damping ratio from the strain-rate damping (first order in the damping).
  std::vector<double> frequency_hz;
  std::vector<double> damping_ratio;
  // Each cable's strain-rate damping time tau (s).
  std::array<double, kNumCables> damping_time_s{};
};

// Energies relative to the start's equilibrium (J): kinetic, elastic (the segments'
// (EA/2 l0)(l - l0)^2 while taut) and gravitational.
struct DynamicsEnergy {
  double kinetic_j = 0.0;
  double elastic_j = 0.0;
  double gravity_j = 0.0;
  double Total() const { return kinetic_j + elastic_j + gravity_j; }
};

// The integrator's work so far.
struct DynamicsStats {
  long long steps = 0;
  long long newton_iterations = 0;
  long long factorisations = 0;
  long long halvings = 0;
  long long slack_segment_steps = 0;  // segment-steps ending slack
};

// The pose and tensions where the chains hang at rest at given lengths.
struct QuasiStaticState {
  Pose pose;
  std::array<double, kNumCables> lower_tension_n{};
};

class CableDynamics {
 public:
  ~CableDynamics();
  CableDynamics(const CableDynamics&) = delete;
  CableDynamics& operator=(const CableDynamics&) = delete;

  // The robot at rest at its start (the file's opening). `duration_s` bounds the wind's
  // record. False with *error: invalid options or model, a model whose cables carry
  // attachments (not described yet), a pose the statics cannot hold (their account), or
  // chains whose equilibrium cannot be found from the catenary's.
  static std::unique_ptr<CableDynamics> Create(const CableRobot& robot, const Pose& pose,
                                               const DynamicsOptions& options, double duration_s,
                                               std::string* error);

  // The start of a free decay: the cabin moved from its equilibrium by `offset_m` and
  // turned by `rotation_rad` (a rotation vector, global axes), held while the chains
  // settle statically onto it, then everything at rest. Only at time 0.
  bool Displace(const Eigen::Vector3d& offset_m, const Eigen::Vector3d& rotation_rad,
                std::string* error);

  // The start of one mode's free decay: everything moved from the equilibrium along the
  // `mode`-th lowest mode's shape (1-based, at most DynamicsStart::frequency_hz.size()),
  // scaled so that O' moves by `amplitude_m` (or, for a mode that barely moves the cabin,
  // its largest node by ten times that), at rest. Only at time 0.
  bool DisplaceAlongMode(int mode, double amplitude_m, std::string* error);

  // The start moved to the chains' equilibrium at lengths `s0_m` (found from the current
  // start), at rest: where a table of winch lengths begins. Only at time 0.
  bool StartAt(const std::array<double, kNumCables>& s0_m, std::string* error);

  // Integrates to `time_s` (> time_s()) with each winch's length going linearly from its
  // current value to `s0_m` there, in equal steps of at most max_step_s. False with *error
  // (the time named) when a step fails to converge after every halving.
  bool Advance(double time_s, const std::array<double, kNumCables>& s0_m, std::string* error);

  double time_s() const;
  Pose CabinPose() const;
  // The velocity of O' and the angular velocity (global axes).
  Eigen::Vector3d CabinVelocity() const;
  Eigen::Vector3d CabinAngularVelocity() const;
  // The force each cable pulls the cabin with at its anchor, in magnitude: what the
  // cabin-side sensor reads (its lowest segment's tension plus its half node's weight and
  // inertia).
  std::array<double, kNumCables> LowerTensionsN() const;
  std::array<double, kNumCables> UnstretchedLengthsM() const;
  // Each cable's nodes 0 (the anchor) .. N (the tower), global frame.
  Eigen::Matrix3Xd CableNodes(int cable) const;
  DynamicsEnergy Energy() const;
  const DynamicsStart& start() const;
  const DynamicsStats& stats() const;
  const DynamicsOptions& options() const;
  // The along-wind speed at time_s (m/s).
  double WindSpeed(double time_s) const;

  // Where the chains hang at rest, with no wind, at lengths `s0_m`: the quasi-static
  // reference. Warm-started from the last call (or the start). False with *error when
  // Newton fails (no equilibrium near the last).
  bool QuasiStatic(const std::array<double, kNumCables>& s0_m, QuasiStaticState* state,
                   std::string* error);

 private:
  struct Impl;
  explicit CableDynamics(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// One cable between two fixed points (modes.h's FixedCable), its static equilibrium
// disturbed by a sine of `harmonic` half-waves (node j moved by amplitude sin(n pi j / N))
// out of the cable's plane (kTransverse) or along its chord (kAxial), released at rest: the
// checks against the string's f_n = (n / 2L) sqrt(T / mu) and the bar's
// f_n = (n / 2 s0) sqrt(EA / rho).
struct FixedCableRelease {
  enum class Kind { kTransverse, kAxial };
  Kind kind = Kind::kTransverse;
  int harmonic = 1;
  double amplitude_m = 0.01;
};

struct FixedCableRecord {
  double sample_interval_s = 0.0;
  // The node at the first antinode (j = N / 2n, rounded), its displacement from the
  // equilibrium along the release's direction, and the lower end's tension, per sample.
  int probe_node = 0;
  std::vector<double> displacement_m;
  std::vector<double> lower_tension_n;
  DynamicsEnergy energy_start, energy_end;
};

// False with *error on invalid input (as ComputeFixedCableModes) or a failed step. The
// options' drag applies, and their damping as the cable's own: damping_ratio (or
// cable_damping_ratio[0]) is its first axial mode's (a straight cable's lowest modes do
// not stretch it); wind and statics do not apply.
bool SimulateFixedCable(const FixedCable& cable, const DynamicsOptions& options,
                        const FixedCableRelease& release, double duration_s,
                        double sample_interval_s, FixedCableRecord* record, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_DYNAMICS_H_
