// The chains' statics, lowest modes and damping (chain_statics.h).
//
// Statics: the forces f(x) of chain_system.cc at rest without wind; Newton x <- x + dx with
// K dx = f (K the tangent stiffness, with the body's load stiffness), each step halved
// until the largest force falls (a backtracking line search: far from the equilibrium a
// full step can slacken a segment).
//
// Modes: K phi = omega^2 M phi at the equilibrium (K symmetrised: its antisymmetric part,
// half the body's net moment, vanishes there), as modes.cc solves it for the catenary's
// nodes; here about the chains' own equilibrium, so that a free decay in time and these
// frequencies describe one system.
//
// Damping: the strain-rate damping's matrix is C = sum_i tau_i K_axial,i, K_axial,i the sum
// over cable i's segments of (EA/l0) n n^T. To first order in C a mode keeps its shape and
// gains the damping ratio zeta = phi^T C phi / (2 omega) (phi M-normalised), the
// Rayleigh quotient of C on the undamped mode.
#include "dynamics/chain_statics.h"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>

#include "fastcal/model_plausibility.h"

namespace fastcal::internal {
namespace {

// The largest force on any moving part (N; the body's moments over kMomentArmM).
constexpr double kMomentArmM = 10.0;
double LargestForce(const ChainForces& f, bool body_free) {
  double largest = 0.0;
  if (body_free) {
    largest = std::max(f.body_force.head<3>().cwiseAbs().maxCoeff(),
                       f.body_force.tail<3>().cwiseAbs().maxCoeff() / kMomentArmM);
  }
  for (const Eigen::Matrix3Xd& m : f.node_force_n) {
    if (m.size() > 0) largest = std::max(largest, m.cwiseAbs().maxCoeff());
  }
  return largest;
}

void ForcesAsField(const ChainForces& f, bool body_free, ChainField* field) {
  field->body = body_free ? f.body_force : Vector6d::Zero();
  for (size_t i = 0; i < field->nodes.size(); ++i) field->nodes[i] = f.node_force_n[i];
}

// (K - sigma M)^-1 x by a sparse LDL^T: Spectra's shift-invert operator.
class ShiftInvert {
 public:
  using Scalar = double;
  ShiftInvert(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m)
      : k_(k), m_(m) {}
  Eigen::Index rows() const { return k_.rows(); }
  Eigen::Index cols() const { return k_.cols(); }
  void set_shift(double sigma) { ldlt_.compute(k_ - sigma * m_); }
  void perform_op(const double* in, double* out) const {
    Eigen::Map<Eigen::VectorXd>(out, rows()) =
        ldlt_.solve(Eigen::Map<const Eigen::VectorXd>(in, rows()));
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& ldlt() const { return ldlt_; }

 private:
  const Eigen::SparseMatrix<double>& k_;
  const Eigen::SparseMatrix<double>& m_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
};

bool DenseModes(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m,
                int count, Eigen::VectorXd* omega2, Eigen::MatrixXd* shapes, std::string* error) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      Eigen::MatrixXd(k), Eigen::MatrixXd(m), Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (solver.info() != Eigen::Success || !(solver.eigenvalues()[0] > 0.0)) {
    *error = "the chains' equilibrium is not stable (K is not positive definite)";
    return false;
  }
  const int n = std::min<int>(count, static_cast<int>(k.rows()));
  *omega2 = solver.eigenvalues().head(n);
  *shapes = solver.eigenvectors().leftCols(n);
  return true;
}

}  // namespace

bool CheckChainInputs(const CableRobot& robot, const Pose& pose, const std::string& user,
                      std::string* error) {
  if (!CheckModel(robot, error)) {
    *error = "model: " + *error;
    return false;
  }
  if (robot.HasAttachments()) {
    *error = "model: the cables carry attachments, which " + user +
             " do not describe yet (a uniform cable's lumped masses only)";
    return false;
  }
  if (!IsFinite(pose)) {
    *error = "pose: must be finite";
    return false;
  }
  return true;
}

bool SolveChainStatics(const ChainModel& model, const ChainStaticsOptions& options,
                       ChainState* state, int* iterations, std::string* error) {
  const bool body_free = model.has_body && !options.body_held;
  state->body_velocity_m_per_s.setZero();
  state->body_angular_velocity_rad_per_s.setZero();
  for (Eigen::Matrix3Xd& v : state->node_velocity_m_per_s) v.setZero();
  std::fill(state->s0_rate_m_per_s.begin(), state->s0_rate_m_per_s.end(), 0.0);
  ChainForces forces, trial_forces;
  BorderedSolver solver;
  ChainField rhs, step;
  rhs.Resize(model);
  step.Resize(model);
  const Eigen::Vector3d still_air = Eigen::Vector3d::Zero();
  EvaluateForces(model, *state, still_air, true, &forces);
  double largest = LargestForce(forces, body_free);
  for (int it = 1; it <= options.max_iterations; ++it) {
    *iterations = it;
    if (!solver.Factor(model, *state, Composite(model, *state), forces, 0.0, 0.0, 1.0,
                       options.body_held)) {
      *error = "the chains' stiffness is singular (a slack cable?)";
      return false;
    }
    ForcesAsField(forces, body_free, &rhs);
    solver.Solve(rhs, &step);
    const double correction = step.MaxAbs();
    if (!std::isfinite(correction)) {
      *error = "the chains' statics diverged";
      return false;
    }
    // Backtracking: the largest of the full step's and the halved steps' that lowers the
    // largest force (or the last tried, should none: Newton's own step then goes on).
    double scale = 1.0;
    for (int halving = 0; halving < 12; ++halving, scale *= 0.5) {
      ChainState trial = *state;
      ChainField scaled = step;
      scaled.body *= scale;
      for (Eigen::Matrix3Xd& m : scaled.nodes) m *= scale;
      Displace(scaled, &trial);
      EvaluateForces(model, trial, still_air, true, &trial_forces);
      const double trial_largest = LargestForce(trial_forces, body_free);
      if (trial_largest < largest || halving == 11 || correction * scale < options.tolerance_m) {
        *state = trial;
        forces = trial_forces;
        largest = trial_largest;
        break;
      }
    }
    if (correction * scale < options.tolerance_m) return true;
  }
  *error = "the chains' statics did not converge in " + std::to_string(options.max_iterations) +
           " Newton iterations (largest force " + std::to_string(largest) + " N)";
  return false;
}

bool LowestModes(const ChainModel& model, const ChainState& state, int count,
                 Eigen::VectorXd* omega2, Eigen::MatrixXd* shapes, std::string* error) {
  ChainForces forces;
  EvaluateForces(model, state, Eigen::Vector3d::Zero(), true, &forces);
  Eigen::SparseMatrix<double> k, m;
  AssembleLinearised(model, state, forces, &k, &m);
  const int n = static_cast<int>(k.rows());
  // Below ~120 unknowns (or when Lanczos needs more vectors than there are) dense costs
  // no more.
  constexpr int kMinLanczosDofs = 120;
  if (n < kMinLanczosDofs || 2 * count + 1 > n)
    return DenseModes(k, m, count, omega2, shapes, error);
  ShiftInvert op(k, m);
  Spectra::SparseSymMatProd<double> mop(m);
  const int ncv = std::min(n, std::max(2 * count + 1, count + 20));
  Spectra::SymGEigsShiftSolver<ShiftInvert, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, mop, count, ncv, 0.0);
  if (op.ldlt().info() != Eigen::Success || (op.ldlt().vectorD().array() <= 0.0).any()) {
    *error = "the chains' equilibrium is not stable (K is not positive definite)";
    return false;
  }
  solver.init();
  solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12, Spectra::SortRule::SmallestAlge);
  if (solver.info() != Spectra::CompInfo::Successful) {
    *error = "the Lanczos iteration for the chains' lowest modes did not converge";
    return false;
  }
  *omega2 = solver.eigenvalues();
  *shapes = solver.eigenvectors();
  for (int i = 0; i < shapes->cols(); ++i) {
    shapes->col(i) /= std::sqrt(shapes->col(i).dot(m * shapes->col(i)));
  }
  return true;
}

std::vector<double> AxialQuadratic(const ChainModel& model, const ChainState& state,
                                   const Eigen::VectorXd& phi) {
  ChainForces forces;
  EvaluateForces(model, state, Eigen::Vector3d::Zero(), false, &forces);
  const int n = model.segments, interior = model.interior(), first = model.has_body ? 6 : 0;
  std::vector<double> out(model.cables.size(), 0.0);
  for (size_t i = 0; i < model.cables.size(); ++i) {
    const double l0 = state.s0_m[i] / n;
    const int base = first + 3 * interior * static_cast<int>(i);
    auto node = [&](int j) -> Eigen::Vector3d {
      if (j == n) return Eigen::Vector3d::Zero();
      if (j > 0) return phi.segment<3>(base + 3 * (j - 1));
      if (!model.has_body) return Eigen::Vector3d::Zero();
      const Eigen::Vector3d r = state.body_rotation * model.cables[i].lower_m;
      return phi.head<3>() + phi.segment<3>(3).cross(r);
    };
    for (int k = 0; k < n; ++k) {
      if (!(forces.tension_n[i][k] > 0.0)) continue;
      const double stretch = forces.unit[i].col(k).dot(node(k + 1) - node(k));
      out[i] += model.cables[i].ea_n / l0 * stretch * stretch;
    }
  }
  return out;
}

}  // namespace fastcal::internal
