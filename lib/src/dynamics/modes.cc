// Natural frequencies and modes of the cabin on its six sagging cables (modes.h).
//
// Small undamped motions q about the static equilibrium: M q'' + K q = 0, so
// K phi = omega^2 M phi (a symmetric generalised eigenproblem; K is the Hessian of the
// potential energy, M that of the kinetic energy, both at the equilibrium).
//
// Cables: lumped-mass chains, the lumped-mass mooring model of MoorDyn (Hall and Goupee
// 2015, "Validation of a lumped-mass mooring line model with DeepCwind semisubmersible
// model test data", Ocean Eng. 104). Cable i of unstretched length s0 is cut into N
// segments of unstretched length l0 = s0/N; its N + 1 nodes sit on the exact elastic
// catenary of the statics (catenary.h, eqs. 11-13) at s = j l0. Node masses rho l0, half
// at the two ends (the tower's half is held, the anchor's moves with the cabin). Each
// segment is an elastic bar of energy (EA/2 l0)(l - l0)^2; its Hessian in the end-to-end
// vector d = l n is the tangent stiffness
//     K_seg = (EA/l0) n n^T + (T/l)(I - n n^T)
// (axial, and geometric: a taut segment resists turning by its tension T), with T the
// catenary's tension at the segment's middle, l its chord. No bending stiffness, no
// aerodynamics, no damping; the winches hold the top nodes.
//
// Cabin: a rigid body, mass m, inertia I_c about its mass centre (cabin frame), the mass
// centre at e = R r_e from O'. With q_c = (u, theta) (the translation of O' and a small
// rotation, global axes) the mass centre moves by u + theta x e, so the mass matrix at O'
// carries the offset:
//     M_c = [ m I        -m [e]x              ]
//           [ m [e]x     I_G - m [e]x [e]x     ],   I_G = R I_c R^T.
// A cable's anchor at r_i = R a_i moves by u + theta x r_i = T_i q_c, T_i = [I, -[r_i]x]:
// the anchor node is eliminated by this constraint (K and M of its segment and its half
// mass are carried to the cabin by T_i^T (.) T_i).
// Load stiffness: the forces f_j on the cabin (gravity W at e, each cable's -F_i at r_i)
// keep their directions while their points turn, p -> p + theta x p + (1/2) theta x
// (theta x p): the second-order term adds to the rotations' stiffness
//     K_theta_theta += sum_j [ (f_j . p_j) I - p_j f_j^T ],
// which is -d(moment)/d(theta) at fixed forces. Its antisymmetric part is half the net
// moment [sum p_j x f_j]x, zero at equilibrium: K is symmetrised, and what was removed is
// reported (ModesResult::stiffness_asymmetry). The first-order force changes as the
// anchors move come from the cables' own stiffness.
//
// Checks (tests/modes_test.cc): a taut string's f_n = (n / 2L) sqrt(T/mu); a sagging
// cable's first symmetric in-plane mode from Irvine's lambda^2 (Irvine and Caughey 1974,
// "The linear theory of free vibrations of a suspended cable", Proc. R. Soc. Lond. A 341;
// Irvine, "Cable Structures", 1981, ch. 3); without the cables' inertia the cabin on the
// stiffness of the statics (finite differences of the equilibrium at fixed lengths);
// convergence in N.
#include "fastcal/modes.h"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "dynamics/chain_statics.h"
#include "fastcal/cable.h"
#include "fastcal/catenary.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/model_plausibility.h"

namespace fastcal {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// An eigenvalue below -this times the largest is a true negative stiffness (an unstable
// equilibrium), not rounding.
constexpr double kNegativeEigenvalueFraction = 1e-10;
// The dense solver (a check) holds K and M as n x n and takes O(n^3): at 4000 degrees of
// freedom (223 segments) 128 MB a matrix and seconds; beyond, it is refused.
constexpr int kMaxDenseDofs = 4000;

Eigen::Matrix3d Cross(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// How a node's displacement follows the degrees of freedom: v = map * q[dof .. dof + cols).
struct NodeMap {
  int dof = -1;  // -1: a fixed node
  Eigen::Matrix<double, 3, Eigen::Dynamic> map;
};
NodeMap FixedNode() { return NodeMap{}; }
NodeMap FreeNode(int dof) { return NodeMap{dof, Eigen::Matrix3d::Identity()}; }

// K and M as (row, column, value) entries, summed where they repeat: sparse (issue 57: dense,
// 1000 segments took 5 GB). Each cable is a chain, so its rows couple only its
// neighbouring nodes (a band of 3 nodes' width) and, at its anchor, the cabin's 6 dofs.
using Entries = std::vector<Eigen::Triplet<double>>;

// Adds block `b` at (row, col) to `entries`, skipping exact zeros.
template <typename Block>
void AddBlock(int row, int col, const Block& b, Entries* entries) {
  for (int c = 0; c < b.cols(); ++c) {
    for (int r = 0; r < b.rows(); ++r) {
      if (b(r, c) != 0.0) entries->emplace_back(row + r, col + c, b(r, c));
    }
  }
}

// Adds a segment's energy (1/2)(v_b - v_a)^T H (v_b - v_a) to K.
void AddSegment(const Eigen::Matrix3d& h, const NodeMap& a, const NodeMap& b, Entries* k) {
  const NodeMap* ends[2] = {&a, &b};
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) {
      const NodeMap& x = *ends[r];
      const NodeMap& y = *ends[c];
      if (x.dof < 0 || y.dof < 0) continue;
      const double sign = r == c ? 1.0 : -1.0;
      AddBlock(x.dof, y.dof, Eigen::MatrixXd(sign * x.map.transpose() * h * y.map), k);
    }
  }
}

// Adds a chain's stiffness and its moving nodes' masses. Interior node j (1..N-1) is free
// at first_dof + 3 (j - 1); the lower node follows `lower` and carries half a node's mass;
// the upper node is fixed.
void AddChain(const LumpedChain& chain, const NodeMap& lower, int first_dof, Entries* k,
              Entries* m) {
  const int segments = static_cast<int>(chain.tension_n.size());
  auto node = [&](int j) {
    if (j == 0) return lower;
    if (j == segments) return FixedNode();
    return FreeNode(first_dof + 3 * (j - 1));
  };
  for (int j = 0; j < segments; ++j) {
    const Eigen::Matrix3d h =
        Cable::SegmentStiffness(chain.nodes_m[j + 1] - chain.nodes_m[j], chain.tension_n[j],
                                chain.ea_n, chain.segment_length_m);
    AddSegment(h, node(j), node(j + 1), k);
  }
  for (int j = 1; j < segments; ++j) {
    for (int a = 0; a < 3; ++a) {
      const int dof = first_dof + 3 * (j - 1) + a;
      m->emplace_back(dof, dof, chain.node_mass_kg);
    }
  }
  if (lower.dof >= 0) {
    AddBlock(lower.dof, lower.dof,
             Eigen::MatrixXd(0.5 * chain.node_mass_kg * lower.map.transpose() * lower.map), m);
  }
}

// The n x n sparse matrix of `entries` (repeated entries summed).
Eigen::SparseMatrix<double> SparseOf(int n, const Entries& entries) {
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  return a;
}

// (K - sigma M)^-1 x by a sparse LDL^T: the shift-invert operator of Spectra's
// generalised solver (its interface: Scalar, rows, cols, set_shift, perform_op).
class ShiftInvertLdlt {
 public:
  using Scalar = double;
  ShiftInvertLdlt(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m)
      : k_(k), m_(m) {}
  Eigen::Index rows() const { return k_.rows(); }
  Eigen::Index cols() const { return k_.cols(); }
  void set_shift(double sigma) { ldlt_.compute(k_ - sigma * m_); }
  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<Eigen::VectorXd>(y_out, rows()) =
        ldlt_.solve(Eigen::Map<const Eigen::VectorXd>(x_in, rows()));
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& ldlt() const { return ldlt_; }

 private:
  const Eigen::SparseMatrix<double>& k_;
  const Eigen::SparseMatrix<double>& m_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
};

constexpr char kUnstable[] = "the equilibrium is unstable: its stiffness has ";

// The lowest `count` eigenpairs by shift-invert Lanczos about 0 (Spectra; K is positive
// definite at a stable equilibrium, which K's LDL^T tells by Sylvester's law of inertia:
// as many negative eigenvalues as negative pivots). False when the Lanczos iteration
// needs more vectors than the problem has (the caller then solves it densely).
bool SolveLowestLanczos(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m,
                        int count, Eigen::VectorXd* lambda, Eigen::MatrixXd* phi,
                        std::string* error) {
  ShiftInvertLdlt op(k, m);
  Spectra::SparseSymMatProd<double> mop(m);
  const int ncv = std::min<int>(static_cast<int>(k.rows()), std::max(2 * count + 1, count + 20));
  Spectra::SymGEigsShiftSolver<ShiftInvertLdlt, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, mop, count, ncv, 0.0);
  if (op.ldlt().info() != Eigen::Success) {
    *error = "the stiffness matrix is singular: the equilibrium is marginally stable";
    return false;
  }
  const int negative = static_cast<int>((op.ldlt().vectorD().array() < 0.0).count());
  if (negative > 0) {
    *error = kUnstable + std::to_string(negative) + " negative eigenvalue(s)";
    return false;
  }
  solver.init();
  try {
    // Spectra throws where its tridiagonal eigensolver fails (issue 57: an inertia of
    // 1e300 kg m^2 ended the command in std::terminate); the model's ranges now keep such
    // matrices out, and what remains is a failure with its reason, not an exception.
    solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12, Spectra::SortRule::SmallestAlge);
  } catch (const std::runtime_error& e) {
    *error = std::string("the Lanczos iteration for the lowest modes failed: ") + e.what();
    return false;
  }
  if (solver.info() != Spectra::CompInfo::Successful) {
    *error = "the Lanczos iteration for the lowest modes did not converge";
    return false;
  }
  *lambda = solver.eigenvalues().cwiseMax(0.0);
  *phi = solver.eigenvectors();
  for (int i = 0; i < phi->cols(); ++i) {
    phi->col(i) /= std::sqrt(phi->col(i).dot(m * phi->col(i)));
  }
  return true;
}

// All eigenpairs densely (Eigen), the lowest `count` kept.
bool SolveLowestDense(const Eigen::MatrixXd& k, const Eigen::MatrixXd& m, int count,
                      Eigen::VectorXd* lambda, Eigen::MatrixXd* phi, std::string* error) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      k, m, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (solver.info() != Eigen::Success) {
    *error = "the eigenproblem K phi = omega^2 M phi did not converge";
    return false;
  }
  const int n = std::min<int>(count, static_cast<int>(k.rows()));
  const double largest = solver.eigenvalues().cwiseAbs().maxCoeff();
  if (solver.eigenvalues()[0] < -kNegativeEigenvalueFraction * largest) {
    *error = kUnstable + std::string("a negative eigenvalue (") +
             std::to_string(solver.eigenvalues()[0]) + " s^-2)";
    return false;
  }
  *lambda = solver.eigenvalues().head(n).cwiseMax(0.0);
  *phi = solver.eigenvectors().leftCols(n);
  return true;
}

// The lowest `count` eigenpairs of K phi = lambda M phi, ascending, phi^T M phi = 1.
bool SolveLowest(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m,
                 int count, ModesOptions::Solver solver, Eigen::VectorXd* lambda,
                 Eigen::MatrixXd* phi, std::string* error) {
  // Lanczos needs count + 1 < n; below ~kMinLanczosDofs dense costs less anyway.
  constexpr int kMinLanczosDofs = 120;
  const int n = static_cast<int>(k.rows());
  if (solver == ModesOptions::Solver::kDense && n > kMaxDenseDofs) {
    *error = "solver: dense is a check for at most " + std::to_string(kMaxDenseDofs) +
             " degrees of freedom (this problem has " + std::to_string(n) + ")";
    return false;
  }
  if (solver == ModesOptions::Solver::kDense || n < kMinLanczosDofs || 2 * count + 1 > n) {
    return SolveLowestDense(Eigen::MatrixXd(k), Eigen::MatrixXd(m), count, lambda, phi, error);
  }
  return SolveLowestLanczos(k, m, count, lambda, phi, error);
}

// The cabin's mass matrix at O', (u, theta) in global axes (the file's opening).
Eigen::Matrix<double, 6, 6> CabinMass(const CableRobot& robot, const Eigen::Matrix3d& rotation) {
  const double m = robot.cabin_mass_kg;
  const Eigen::Matrix3d e = Cross(rotation * robot.mass_centre_cabin_m);
  const Eigen::Matrix3d inertia = rotation * robot.cabin_inertia_kg_m2 * rotation.transpose();
  Eigen::Matrix<double, 6, 6> mass;
  mass << m * Eigen::Matrix3d::Identity(), -m * e, m * e, inertia - m * e * e;
  return mass;
}

// -d(moment about O')/d(theta) of the forces on the cabin held fixed while their points
// turn: gravity at the mass centre and each cable's pull at its anchor. Not symmetric off
// equilibrium (its antisymmetric part is half the net moment).
Eigen::Matrix3d LoadStiffness(const CableRobot& robot, const Pose& pose,
                              const StaticsSolution& statics) {
  auto term = [](const Eigen::Vector3d& force, const Eigen::Vector3d& point) {
    return Eigen::Matrix3d(force.dot(point) * Eigen::Matrix3d::Identity() -
                           point * force.transpose());
  };
  const Eigen::Vector3d weight_n(0.0, 0.0, robot.cabin_mass_kg * robot.gravity_m_per_s2);
  Eigen::Matrix3d k = term(weight_n, pose.rotation * robot.mass_centre_cabin_m);
  for (int i = 0; i < kNumCables; ++i) {
    k += term(-statics.cables[i].force_n, pose.rotation * robot.AnchorOfCable(i));
  }
  return k;
}

// K and M of the whole system, and what the modes' energies need.
struct Assembly {
  Eigen::SparseMatrix<double> k, m;
  std::array<LumpedChain, kNumCables> chains;
  std::array<NodeMap, kNumCables> anchors;  // each cable's lower node: T_i on the cabin's dofs
  std::array<int, kNumCables> first_dof{};  // each cable's first interior node
  double asymmetry = 0.0;
};

bool Assemble(const CableRobot& robot, const Pose& pose, const StaticsSolution& statics,
              int segments, Assembly* a, std::string* error) {
  const int per_cable = 3 * (segments - 1);
  const int dofs = 6 + kNumCables * per_cable;
  Entries k, m;
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = robot.cables[i];
    const CableSolution& s = statics.cables[i];
    const Eigen::Vector3d r = pose.rotation * robot.AnchorOfCable(i);
    const Eigen::Vector3d lower = pose.position_m + r;
    if (!Cable::Of(c).Lumped(lower, c.tower_top_m, s.horizontal_force_n, s.force_n.z(),
                             s.unstretched_length_m, robot.gravity_m_per_s2, segments,
                             &a->chains[i], error)) {
      *error = "cable " + std::to_string(i + 1) + ": " + *error;
      return false;
    }
    a->anchors[i].dof = 0;
    a->anchors[i].map.resize(3, 6);
    a->anchors[i].map << Eigen::Matrix3d::Identity(), -Cross(r);
    a->first_dof[i] = 6 + i * per_cable;
    AddChain(a->chains[i], a->anchors[i], a->first_dof[i], &k, &m);
  }
  AddBlock(0, 0, CabinMass(robot, pose.rotation), &m);
  AddBlock(3, 3, LoadStiffness(robot, pose, statics), &k);
  a->k = SparseOf(dofs, k);
  a->m = SparseOf(dofs, m);
  const Eigen::SparseMatrix<double> transpose = a->k.transpose();
  const double largest = a->k.coeffs().cwiseAbs().maxCoeff();
  const Eigen::SparseMatrix<double> antisymmetric = a->k - transpose;
  a->asymmetry =
      antisymmetric.nonZeros() == 0 ? 0.0 : antisymmetric.coeffs().cwiseAbs().maxCoeff() / largest;
  a->k = 0.5 * (a->k + transpose);
  return true;
}

// The stiffness at the cabin's dofs with the cables' interior nodes condensed out
// (Guyan): K_cc - sum_i K_ci K_ii^-1 K_ic, each cable's block on its own.
Eigen::Matrix<double, 6, 6> CondensedStiffness(const Assembly& a, int per_cable) {
  Eigen::Matrix<double, 6, 6> k = Eigen::MatrixXd(a.k.topLeftCorner(6, 6));
  for (int i = 0; i < kNumCables; ++i) {
    const int f = a.first_dof[i];
    const Eigen::MatrixXd kci = a.k.block(0, f, 6, per_cable);
    const Eigen::SparseMatrix<double> block = a.k.block(f, f, per_cable, per_cable);
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> kii(block);
    const Eigen::MatrixXd kic = kci.transpose();
    k -= kci * kii.solve(kic);
  }
  return 0.5 * (k + k.transpose());
}

// A mode's energy shares (modes.h, Mode) from its shape phi (M-normalised) over the
// assembly's dofs; only the cabin's when `cables` is false (the Guyan model).
Mode DescribeMode(const CableRobot& robot, const Pose& pose, const Assembly& a, bool cables,
                  double lambda, const Eigen::VectorXd& phi) {
  Mode mode;
  mode.frequency_hz = std::sqrt(lambda) / kTwoPi;
  mode.cabin_shape = phi.head<6>();
  const Eigen::Vector3d u = phi.head<3>(), theta = phi.segment<3>(3);
  const Eigen::Vector3d v_centre = u + theta.cross(pose.rotation * robot.mass_centre_cabin_m);
  mode.cabin_translation_share = robot.cabin_mass_kg * v_centre.cwiseAbs2();
  const Eigen::Matrix3d inertia =
      pose.rotation * robot.cabin_inertia_kg_m2 * pose.rotation.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> root(inertia);
  mode.cabin_rotation_share = (root.operatorSqrt() * theta).cwiseAbs2();
  for (int i = 0; cables && i < kNumCables; ++i) {
    const LumpedChain& chain = a.chains[i];
    const int interior = static_cast<int>(chain.tension_n.size()) - 1;
    mode.cable_share[i] =
        0.5 * chain.node_mass_kg * (a.anchors[i].map * phi.head<6>()).squaredNorm() +
        chain.node_mass_kg * phi.segment(a.first_dof[i], 3 * interior).squaredNorm();
  }
  double total = mode.CabinShare();
  for (double s : mode.cable_share) total += s;
  mode.cabin_translation_share /= total;
  mode.cabin_rotation_share /= total;
  for (double& s : mode.cable_share) s /= total;
  mode.cables_share = 0.0;
  for (double s : mode.cable_share) mode.cables_share += s;
  mode.dominant_cable =
      static_cast<int>(std::max_element(mode.cable_share.begin(), mode.cable_share.end()) -
                       mode.cable_share.begin());
  return mode;
}

}  // namespace

bool ModesOptions::IsValid(std::string* error) const {
  if (segments < 2 || segments > 1000) {
    *error = "segments: must be in [2, 1000] (got " + std::to_string(segments) + ")";
    return false;
  }
  if (modes < 1 || modes > kMaxModes) {
    *error = "modes: must be in [1, " + std::to_string(kMaxModes) + "] (got " +
             std::to_string(modes) + ")";
    return false;
  }
  if (statics.method != StaticsMethod::kExact) {
    *error = "statics.method: must be exact (the chain's nodes lie on the exact catenary)";
    return false;
  }
  return statics.IsValid(error);
}

bool ComputeFixedCableModes(const FixedCable& cable, const ModesOptions& options,
                            std::vector<CableMode>* modes, std::string* error) {
  if (!options.IsValid(error)) return false;
  const double chord_m = std::hypot(cable.span_m, cable.rise_m);
  if (!(cable.span_m > 0.0) || !std::isfinite(chord_m) || !(cable.ea_n > 0.0) ||
      !(cable.linear_density_kg_per_m > 0.0) || !(cable.gravity_m_per_s2 < 0.0) ||
      !(cable.unstretched_length_m > 0.0) || !std::isfinite(cable.ea_n) ||
      !std::isfinite(cable.unstretched_length_m) || !std::isfinite(cable.gravity_m_per_s2) ||
      !std::isfinite(cable.linear_density_kg_per_m)) {
    *error = "cable: span, unstretched length, EA and density must be > 0 and finite, g < 0";
    return false;
  }
  const Cable bare(cable.ea_n, cable.linear_density_kg_per_m);
  CatenaryForces forces;
  int iterations = 0;
  if (bare.Forces(cable.span_m, cable.rise_m, cable.unstretched_length_m, cable.gravity_m_per_s2,
                  CatenarySolverOptions(), nullptr, &forces, &iterations) != CatenaryStatus::kOk) {
    *error = "cable: the catenary has no solution for this span, rise and length";
    return false;
  }
  const int n = options.segments;
  LumpedChain chain;
  if (!bare.Lumped(Eigen::Vector3d::Zero(), Eigen::Vector3d(cable.span_m, 0.0, cable.rise_m),
                   forces.fl_n, forces.fz_n, cable.unstretched_length_m, cable.gravity_m_per_s2, n,
                   &chain, error)) {
    return false;
  }
  const int dofs = 3 * (n - 1);
  Entries k, m;
  AddChain(chain, FixedNode(), 0, &k, &m);
  Eigen::VectorXd lambda;
  Eigen::MatrixXd phi;
  if (!SolveLowest(SparseOf(dofs, k), SparseOf(dofs, m), options.modes, options.solver, &lambda,
                   &phi, error)) {
    return false;
  }
  modes->assign(lambda.size(), CableMode());
  const int mid = n / 2;  // the node nearest mid-span (exactly at it for even N)
  for (int i = 0; i < lambda.size(); ++i) {
    CableMode& mode = (*modes)[i];
    mode.frequency_hz = std::sqrt(lambda[i]) / kTwoPi;
    double in_plane = 0.0, total = 0.0, largest_z = 0.0;
    for (int j = 1; j < n; ++j) {
      const Eigen::Vector3d v = phi.col(i).segment<3>(3 * (j - 1));
      in_plane += v.x() * v.x() + v.z() * v.z();
      total += v.squaredNorm();
      largest_z = std::max(largest_z, std::abs(v.z()));
    }
    mode.in_plane_share = in_plane / total;
    mode.midspan_vertical = largest_z > 0.0 ? phi(3 * (mid - 1) + 2, i) / largest_z : 0.0;
  }
  return true;
}

// The equilibrium of `pose` by the exact statics, with its failure said in words.
bool SolveEquilibrium(const CableRobot& robot, const Pose& pose, const ModesOptions& options,
                      StaticsSolution* statics, std::string* error) {
  // For callers that built the model themselves, as a model file is checked.
  if (!internal::CheckChainInputs(robot, pose, "the modes", error)) return false;
  if (SolveStatics(robot, pose, options.statics, statics) != StaticsStatus::kOk) {
    *error = "no equilibrium to linearise about: " + DescribeStatus(*statics);
    return false;
  }
  return true;
}

bool ComputeModes(const CableRobot& robot, const Pose& pose, const ModesOptions& options,
                  ModesResult* result, std::string* error) {
  *result = ModesResult();
  if (!options.IsValid(error)) return false;
  if (!SolveEquilibrium(robot, pose, options, &result->statics, error)) return false;
  Assembly a;
  if (!Assemble(robot, pose, result->statics, options.segments, &a, error)) return false;
  result->stiffness_asymmetry = a.asymmetry;
  Eigen::VectorXd lambda;
  Eigen::MatrixXd phi;
  if (options.cable_inertia) {
    result->degrees_of_freedom = static_cast<int>(a.k.rows());
    if (!SolveLowest(a.k, a.m, options.modes, options.solver, &lambda, &phi, error)) return false;
  } else {
    result->degrees_of_freedom = 6;
    result->cabin_stiffness = CondensedStiffness(a, 3 * (options.segments - 1));
    const Eigen::MatrixXd mass = CabinMass(robot, pose.rotation);
    const Eigen::MatrixXd stiffness = result->cabin_stiffness;
    if (!SolveLowest(stiffness.sparseView(), mass.sparseView(), options.modes,
                     ModesOptions::Solver::kDense, &lambda, &phi, error)) {
      return false;
    }
  }
  for (int i = 0; i < lambda.size(); ++i) {
    result->modes.push_back(
        DescribeMode(robot, pose, a, options.cable_inertia, lambda[i], phi.col(i)));
  }
  return true;
}

std::string ModesCsv(const ModesResult& result) {
  auto num = [](double value) {
    return value == 0.0 ? std::string("0") : internal::FormatDouble("%.10g", value);
  };
  // A share below 1e-12 is rounding (a mode of the symmetric zenith pose has exactly none
  // of some motions): written as 0, not as 3e-25.
  auto share = [&](double value) {
    return std::abs(value) < 1e-12 ? std::string("0") : num(value);
  };
  std::ostringstream out;
  out << "mode,frequency_hz,period_s,share_x,share_y,share_z,share_rx,share_ry,share_rz,"
         "share_cables,dominant_cable,dominant_cable_share,kind\n";
  for (size_t i = 0; i < result.modes.size(); ++i) {
    const Mode& m = result.modes[i];
    out << i + 1 << "," << num(m.frequency_hz) << ","
        << (m.frequency_hz > 0.0 ? num(1.0 / m.frequency_hz) : std::string());
    for (int k = 0; k < 3; ++k) out << "," << share(m.cabin_translation_share[k]);
    for (int k = 0; k < 3; ++k) out << "," << share(m.cabin_rotation_share[k]);
    out << "," << share(m.cables_share) << "," << m.dominant_cable + 1 << ","
        << share(m.cable_share[m.dominant_cable]) << ","
        << (m.CabinShare() > 0.5 ? "cabin" : "cable") << "\n";
  }
  return out.str();
}

}  // namespace fastcal
