// The lumped-mass chains and the rigid cabin as one mechanical system: its state, the
// forces on every moving part and their tangents, and the solve of the bordered
// block-tridiagonal system both the time integration (dynamics.cc) and the chains' own
// statics need. The equations open chain_system.cc.
//
// Degrees of freedom: the body's translation of O' and a small rotation (global axes),
// then each cable's interior nodes 1..N-1 (3 each). Node 0 is the cable's lower end, on
// the body at its anchor (or fixed when the system has no body: a cable between two
// fixed points, for the checks); node N is the upper end at the tower, held. Every
// cable's N segments share the unstretched length s0/N, s0 the winch's paid-out length
// (a winch paying out spreads the length over the segments; dynamics.h says why).
#ifndef FASTCAL_SRC_DYNAMICS_CHAIN_SYSTEM_H_
#define FASTCAL_SRC_DYNAMICS_CHAIN_SYSTEM_H_

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <vector>

namespace fastcal::internal {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;

struct ChainCable {
  Eigen::Vector3d upper_m = Eigen::Vector3d::Zero();  // the tower end, global frame, held
  // The lower end: in the body frame when the system has a body, else global and held.
  Eigen::Vector3d lower_m = Eigen::Vector3d::Zero();
  double ea_n = 0.0;
  double density_kg_per_m = 0.0;  // per unstretched length
  // Kelvin-Voigt internal damping: a segment's tension gains tau EA d(strain)/dt.
  double damping_time_s = 0.0;
  double drag_diameter_m = 0.0;
};

struct ChainBody {
  double mass_kg = 0.0;
  Eigen::Vector3d mass_centre_m = Eigen::Vector3d::Zero();  // body frame, from O'
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about the mass centre, body frame
  double drag_area_m2 = 0.0;                                // C_d A, acting at O'
};

struct ChainModel {
  std::vector<ChainCable> cables;
  int segments = 40;
  bool has_body = true;
  ChainBody body;
  double gravity_m_per_s2 = -9.8;  // along z (negative: z up)
  double air_density_kg_per_m3 = 1.225;
  double cable_drag_coefficient = 1.2;  // on the velocity across a segment

  int interior() const { return segments - 1; }
  int Dofs() const { return (has_body ? 6 : 0) + 3 * interior() * static_cast<int>(cables.size()); }
};

struct ChainState {
  double time_s = 0.0;
  Eigen::Vector3d body_position_m = Eigen::Vector3d::Zero();  // O'
  Eigen::Matrix3d body_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d body_velocity_m_per_s = Eigen::Vector3d::Zero();            // of O'
  Eigen::Vector3d body_angular_velocity_rad_per_s = Eigen::Vector3d::Zero();  // global axes
  // Per cable, its interior nodes 1..N-1 as columns.
  std::vector<Eigen::Matrix3Xd> node_m, node_velocity_m_per_s;
  std::vector<double> s0_m, s0_rate_m_per_s;
};

// Accelerations (or any field over the degrees of freedom): the body's (a of O', angular
// acceleration), and each cable's interior nodes'.
struct ChainField {
  Vector6d body = Vector6d::Zero();
  std::vector<Eigen::Matrix3Xd> nodes;

  void Resize(const ChainModel& model);
  void SetZero();
  double MaxAbs() const;  // NaN when any entry is not finite
  // this += scale * other
  void AddScaled(double scale, const ChainField& other);
};

// The body with its cables' lower half-segments (their half node masses ride on it): its
// mass matrix at O' in global axes, the velocity terms of its equations, where its mass
// centre is.
struct CompositeBody {
  double mass_kg = 0.0;
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();   // from O', global axes
  Matrix6d mass = Matrix6d::Zero();                     // [m I, -m [c]x; m [c]x, I_O]
  Eigen::Matrix3d inertia_o = Eigen::Matrix3d::Zero();  // about O', global axes
};
CompositeBody Composite(const ChainModel& model, const ChainState& state);

// Forces, with tangents on request. The tangents are those of the elastic and damping
// forces (and the body's load stiffness); drag and the body's velocity terms enter the
// residual only (their derivatives are ~1e-4 of the masses' at the steps used).
struct ChainForces {
  // On each interior node: the segments' pulls, its weight and its drag.
  std::vector<Eigen::Matrix3Xd> node_force_n;
  // On the composite body: [force; moment about O'] from the cables' lowest segments,
  // the weight of the body and of the half nodes it carries, and the cabin's drag.
  Vector6d body_force = Vector6d::Zero();
  // Per cable and segment (0 at the lower end): the unit chord toward the upper end, the
  // chord's length, the tension (elastic plus damping; 0 when slack).
  std::vector<Eigen::Matrix3Xd> unit;
  std::vector<Eigen::VectorXd> length_m, tension_n;
  // Per cable: where its lower end is (global) and the force it pulls the body with
  // there (its lowest segment's pull plus its half node's weight and inertia, when the
  // body's acceleration is given to LowerEndForces).
  std::vector<Eigen::Vector3d> lower_end_m;
  // Tangents per cable and segment: K = (EA/l0) n n^T + (T/l)(I - n n^T) and the
  // damping's C = (tau EA / l0) n n^T (both zero when slack).
  std::vector<std::vector<Eigen::Matrix3d>> stiffness, damping;
  Eigen::Matrix3d load_stiffness = Eigen::Matrix3d::Zero();  // the body's rotations
  int slack_segments = 0;
};

// The forces in `state` with a uniform wind `wind_m_per_s` (global). `tangents` also fills
// the tangents.
void EvaluateForces(const ChainModel& model, const ChainState& state,
                    const Eigen::Vector3d& wind_m_per_s, bool tangents, ChainForces* forces);

// The force each cable's lower end pulls the body with: its lowest segment's tension
// along its chord plus its half node's weight less its mass times the anchor's
// acceleration (`body_acceleration`: a of O' and the angular acceleration; zero for the
// statics).
std::vector<Eigen::Vector3d> LowerEndForces(const ChainModel& model, const ChainState& state,
                                            const ChainForces& forces,
                                            const Vector6d& body_acceleration);

// The velocity terms of the body's equations at O': [m w x (w x c); w x (I_O w)].
Vector6d BodyVelocityTerms(const CompositeBody& body, const Eigen::Vector3d& angular_velocity);

// The matrix a_m M + a_c C + a_k K of the system (with the body's mass at O' and its
// load stiffness), factored by eliminating each cable's block-tridiagonal chain from the
// tower down onto its first interior node and then onto the body's six unknowns (a
// Schur complement), and solved for any right-hand side. Each pivot block is 3x3 (its
// inverse kept), the body's 6x6 Schur complement by LU: O(N) per cable.
class BorderedSolver {
 public:
  // False when a pivot is singular (a chain with no stiffness and no mass: a statics
  // with a slack segment). `body_held`: the body's unknowns fixed at zero (the chains
  // alone, each onto its held lower end).
  bool Factor(const ChainModel& model, const ChainState& state, const CompositeBody& body,
              const ChainForces& forces, double a_m, double a_c, double a_k,
              bool body_held = false);
  // x = S^-1 rhs.
  void Solve(const ChainField& rhs, ChainField* x) const;

 private:
  const ChainModel* model_ = nullptr;
  bool body_free_ = true;
  // Per cable: the inverted pivots P_j^-1 (j = 1..N-1 at index j - 1), the off-diagonal
  // blocks B_j between nodes j and j + 1, and E, node 1's coupling to the body.
  std::vector<std::vector<Eigen::Matrix3d>> pivot_inverse_, off_;
  std::vector<Matrix36d> coupling_;
  Eigen::PartialPivLU<Matrix6d> body_lu_;
  mutable std::vector<Eigen::Matrix3Xd> reduced_;  // the reduced right-hand sides
};

// The state moved by `dx` (body: translation of O' and a rotation vector applied on the
// left, R <- exp([dtheta]x) R; nodes: displacements).
void Displace(const ChainField& dx, ChainState* state);

// The linearised system at `state` as sparse matrices over the degrees of freedom
// (body first, then each cable's interior nodes): the stiffness K (symmetrised) and the
// mass M. Tangents must be in `forces`.
void AssembleLinearised(const ChainModel& model, const ChainState& state, const ChainForces& forces,
                        Eigen::SparseMatrix<double>* stiffness, Eigen::SparseMatrix<double>* mass);

// The system's energy: kinetic; elastic (the segments' (EA/2 l0)(l - l0)^2 while taut)
// and gravitational, each as its change from `reference`.
struct ChainEnergy {
  double kinetic_j = 0.0;
  double elastic_j = 0.0;
  double gravity_j = 0.0;
  double Total() const { return kinetic_j + elastic_j + gravity_j; }
};
ChainEnergy Energy(const ChainModel& model, const ChainState& state, const ChainState& reference);

// A cable's lower end (global).
Eigen::Vector3d LowerEnd(const ChainModel& model, const ChainState& state, int cable);

}  // namespace fastcal::internal

#endif  // FASTCAL_SRC_DYNAMICS_CHAIN_SYSTEM_H_
