// The joint least-squares problem of many windows with per-window parameters a_w and
// shared ones b: normal equations of block-arrow shape, solved by the Schur complement
// on the shared part and back-substitution (Triggs, McLauchlan, Hartley and Fitzgibbon
// 2000, "Bundle adjustment - a modern synthesis", sect. 6; the structure Ceres's
// SPARSE_SCHUR exploits inside one process).
//
// Window w brings a quadratic model of its chi-square in its own variables x_w = (a_w, s_w),
// a_w its p parameters and s_w the m shared parameters it sees, s_w = P_w b (P_w picks
// entries of b: shared_index), folded at a point x0_w:
//   chi2_w(x) = c_w + 2 g_w^T (x - x0_w) + (x - x0_w)^T H_w (x - x0_w)
// (g = J^T r, H = J^T J of its whitened rows). With Gaussian priors on a_w (Lambda_a,
// mean mu_a) and on b (Lambda_b, mu_b) the normal equations are, with k_w = H_w x0_w - g_w,
//   A_w a_w + B_w b = y_w,         A_w = H_aa + Lambda_a,  B_w = H_as P_w,  y_w = k_a + Lambda_a
//   mu_a sum_w B_w^T a_w + D b = z,     D = sum_w P_w^T H_ss P_w + Lambda_b,     z = sum_w P_w^T
//   k_s + Lambda_b mu_b
// Eliminating each a_w (E_w = A_w^-1 B_w):
//   S b = z - sum_w E_w^T y_w,     S = D - sum_w B_w^T E_w,     a_w = A_w^-1 y_w - E_w b.
// The inverse of the whole normal matrix M has the blocks
//   (M^-1)_wu = delta_wu A_w^-1 + E_w S^-1 E_u^T,   (M^-1)_wb = -E_w S^-1,   (M^-1)_bb = S^-1
// and M X = C for C = (C_w per window, C_b) is X_b = S^-1 (C_b - sum_w E_w^T C_w),
// X_w = A_w^-1 C_w - E_w X_b: O(windows) work and memory for any number of windows.
// Where C is zero but in the windows of a set V, C^T M^-1 C needs only theirs:
//   C^T M^-1 C = sum_{w in V} C_w^T A_w^-1 C_w + R^T S^-1 R,   R = C_b - sum_{w in V} E_w^T C_w
// (O(|V|): the track's score tests ask it once per window and column, issue 41).
//
// Sandwich covariance (uncertainty.h: P = M^-1 (Omega + Lambda) M^-1) with window w's
// information scaled by f_w >= 1 (its misfit and time-correlation widening) and, where
// given, a covariance of its scores beyond the white one (a process its rows share, such
// as a wander of its own parameters inside the window: track_wander.cc),
// Omega_w = f_w H_w + X_w + diag(Lambda_a, 0): with G_w = [E_w^T, -P_w^T] (x_w's columns mapped
// to b), Q = sum_w G_w Omega_w G_w^T + Lambda_b and T_w = A_w^-1 (Omega_w)_{a.} G_w^T,
//   P_wu = delta_wu A_w^-1 (Omega_w)_aa A_w^-1 + T_w S^-1 E_u^T + E_w S^-1 T_u^T
//          + E_w S^-1 Q S^-1 E_u^T
//   P_wb = -T_w S^-1 - E_w S^-1 Q S^-1,   P_bb = S^-1 Q S^-1
// (all f_w = 1: P = M^-1). Every block costs O(1) once Q is formed.
#ifndef FASTCAL_INTERNAL_BLOCK_ARROW_H_
#define FASTCAL_INTERNAL_BLOCK_ARROW_H_

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <vector>

namespace fastcal::internal {

// One window's quadratic model, its variables ordered [a (p); s (m)].
struct ArrowBlock {
  int p = 0;                          // own parameters
  std::vector<int> shared_index;      // m entries: s_j = b[shared_index[j]]
  Eigen::MatrixXd h;                  // (p + m) x (p + m)
  Eigen::VectorXd g;                  // p + m
  Eigen::VectorXd x0;                 // p + m, the point it was folded at
  double c = 0.0;                     // chi-square at x0
  Eigen::VectorXd prior_information;  // p (diagonal; 0: no prior)
  Eigen::VectorXd prior_mean;         // p
  double scale = 1.0;                 // f_w of the sandwich (>= 1)
  // X_w of the sandwich ((p + m) x (p + m), the local order; empty: none): the covariance
  // of the window's scores beyond scale * h.
  Eigen::MatrixXd extra;
  int m() const { return static_cast<int>(shared_index.size()); }
};

struct ArrowProblem {
  int q = 0;  // shared parameters
  std::vector<ArrowBlock> blocks;
  Eigen::VectorXd shared_prior_information;  // q (0: no prior)
  Eigen::VectorXd shared_prior_mean;         // q
};

// A right-hand side (or several, as columns) split like the variables: one p x k matrix
// per window and one q x k matrix for b.
struct ArrowVector {
  std::vector<Eigen::MatrixXd> a;
  Eigen::MatrixXd b;
};

class ArrowSolver {
 public:
  // Factors the problem and solves it. False when some A_w or S is not positive
  // definite (a window's own parameters, or the shared ones, undetermined).
  bool Solve(const ArrowProblem& problem);

  int windows() const { return static_cast<int>(a_.size()); }
  const Eigen::VectorXd& a(int w) const { return a_[w]; }
  const Eigen::VectorXd& b() const { return b_; }
  // Predicted chi-square at the solution (the sum of the quadratic models, priors included).
  double ChiSquare() const { return chi_square_; }

  // M^-1 C.
  ArrowVector SolveFor(const ArrowVector& c) const;
  // C^T M^-1 C (k x k) for C zero but in windows[i]'s block (c_a[i], p x k) and in b's
  // (c_b, q x k): the same as from SolveFor, in O(windows.size()). Each window once
  // (c_a.size() == windows.size()); a window named twice would lose their cross term.
  Eigen::MatrixXd QuadraticForm(const std::vector<int>& windows,
                                const std::vector<Eigen::MatrixXd>& c_a,
                                const Eigen::MatrixXd& c_b) const;
  // The same for C given per window in its own variables' order [a; s] (local[i],
  // (p + m) x k, as ArrowBlock's): the s rows go to b by shared_index, summed over windows.
  Eigen::MatrixXd QuadraticFormOfLocal(const std::vector<int>& windows,
                                       const std::vector<Eigen::MatrixXd>& local) const;
  // Blocks of M^-1 (the formal covariance).
  Eigen::MatrixXd FormalAA(int w, int u) const;
  Eigen::MatrixXd FormalAB(int w) const;
  const Eigen::MatrixXd& FormalBB() const { return s_inverse_; }

  // Blocks of the sandwich covariance with each block's scale (see above).
  Eigen::MatrixXd SandwichAA(int w, int u) const;
  Eigen::MatrixXd SandwichAB(int w) const;
  Eigen::MatrixXd SandwichBB() const;

  // For the block's variables: the shared ones' entry in b (shared_index), and the
  // problem (kept by reference: it must outlive the solver's use).
  const ArrowProblem& problem() const { return *problem_; }
  // The blocks' scale or extra changed since the sandwich was formed: form it again on
  // next use.
  void ResetSandwich() const { sandwich_ready_ = false; }
  // E_w = A_w^-1 B_w (p x q) and A_w^-1.
  const Eigen::MatrixXd& E(int w) const { return e_[w]; }
  const Eigen::MatrixXd& AInverse(int w) const { return a_inverse_[w]; }
  // B_w = H_as P_w (p x q).
  Eigen::MatrixXd B(int w) const;
  // Window w's variables as a vector of its local order [a; s] at the solution.
  Eigen::VectorXd LocalSolution(int w) const;

 private:
  void FormSandwich() const;

  const ArrowProblem* problem_ = nullptr;
  std::vector<Eigen::MatrixXd> a_inverse_, e_;
  std::vector<Eigen::VectorXd> a_;
  Eigen::VectorXd b_;
  Eigen::MatrixXd s_inverse_;
  double chi_square_ = 0.0;
  // The sandwich's Q-dependent parts, formed on first use.
  mutable bool sandwich_ready_ = false;
  mutable std::vector<Eigen::MatrixXd> t_;  // T_w S^-1 (p x q)
  mutable Eigen::MatrixXd sqs_;             // S^-1 Q S^-1
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_BLOCK_ARROW_H_
