// The block-arrow least-squares problem of a track (internal/block_arrow.h).
#include "fastcal/internal/block_arrow.h"

#include <Eigen/Dense>

namespace fastcal::internal {
namespace {

// The inverse of a symmetric positive-definite matrix, or false.
bool InverseSpd(const Eigen::MatrixXd& m, Eigen::MatrixXd* inverse) {
  if (m.rows() == 0) {
    *inverse = Eigen::MatrixXd(0, 0);
    return true;
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(m);
  if (llt.info() != Eigen::Success) return false;
  *inverse = llt.solve(Eigen::MatrixXd::Identity(m.rows(), m.cols()));
  *inverse = 0.5 * (*inverse + inverse->transpose());
  return inverse->allFinite();
}

// P_w^T v: the local shared rows scattered into b's order (q rows).
Eigen::MatrixXd Scatter(const ArrowBlock& k, const Eigen::MatrixXd& local, int q) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(q, local.cols());
  for (int j = 0; j < k.m(); ++j) out.row(k.shared_index[j]) += local.row(j);
  return out;
}

}  // namespace

Eigen::MatrixXd ArrowSolver::B(int w) const {
  const ArrowBlock& k = problem_->blocks[w];
  return Scatter(k, k.h.block(k.p, 0, k.m(), k.p), problem_->q).transpose();
}

bool ArrowSolver::Solve(const ArrowProblem& problem) {
  problem_ = &problem;
  sandwich_ready_ = false;
  const int q = problem.q;
  const int windows = static_cast<int>(problem.blocks.size());
  a_inverse_.assign(windows, {});
  e_.assign(windows, {});
  a_.assign(windows, {});
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(q, q);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(q);
  std::vector<Eigen::VectorXd> y(windows);
  for (int w = 0; w < windows; ++w) {
    const ArrowBlock& k = problem.blocks[w];
    const int p = k.p, m = k.m();
    const Eigen::VectorXd kv = k.h * k.x0 - k.g;
    Eigen::MatrixXd a = k.h.topLeftCorner(p, p);
    a.diagonal() += k.prior_information;
    if (!InverseSpd(a, &a_inverse_[w])) return false;
    y[w] = kv.head(p) + k.prior_information.cwiseProduct(k.prior_mean);
    const Eigen::MatrixXd b = B(w);
    e_[w] = a_inverse_[w] * b;
    // D - sum B^T E and z - sum E^T y, window by window.
    s += Scatter(k, Scatter(k, k.h.bottomRightCorner(m, m), q).transpose(), q) -
         b.transpose() * e_[w];
    z += Scatter(k, kv.tail(m), q) - e_[w].transpose() * y[w];
  }
  const bool shared_priors = problem.shared_prior_information.size() == q;
  if (shared_priors) {
    s.diagonal() += problem.shared_prior_information;
    z += problem.shared_prior_information.cwiseProduct(problem.shared_prior_mean);
  }
  if (!InverseSpd(0.5 * (s + s.transpose()), &s_inverse_)) return false;
  b_ = s_inverse_ * z;
  chi_square_ = 0.0;
  for (int w = 0; w < windows; ++w) {
    const ArrowBlock& k = problem.blocks[w];
    a_[w] = a_inverse_[w] * y[w] - e_[w] * b_;
    const Eigen::VectorXd dx = LocalSolution(w) - k.x0;
    chi_square_ += k.c + 2.0 * k.g.dot(dx) + dx.dot(k.h * dx);
    const Eigen::VectorXd da = a_[w] - k.prior_mean;
    chi_square_ += da.dot(k.prior_information.cwiseProduct(da));
  }
  if (shared_priors) {
    const Eigen::VectorXd db = b_ - problem.shared_prior_mean;
    chi_square_ += db.dot(problem.shared_prior_information.cwiseProduct(db));
  }
  return b_.allFinite();
}

Eigen::VectorXd ArrowSolver::LocalSolution(int w) const {
  const ArrowBlock& k = problem_->blocks[w];
  Eigen::VectorXd x(k.p + k.m());
  x.head(k.p) = a_[w];
  for (int j = 0; j < k.m(); ++j) x[k.p + j] = b_[k.shared_index[j]];
  return x;
}

ArrowVector ArrowSolver::SolveFor(const ArrowVector& c) const {
  ArrowVector x;
  Eigen::MatrixXd rhs = c.b;
  for (int w = 0; w < windows(); ++w) rhs -= e_[w].transpose() * c.a[w];
  x.b = s_inverse_ * rhs;
  x.a.resize(windows());
  for (int w = 0; w < windows(); ++w) x.a[w] = a_inverse_[w] * c.a[w] - e_[w] * x.b;
  return x;
}

Eigen::MatrixXd ArrowSolver::QuadraticForm(const std::vector<int>& windows,
                                           const std::vector<Eigen::MatrixXd>& c_a,
                                           const Eigen::MatrixXd& c_b) const {
  eigen_assert(c_a.size() == windows.size());
  Eigen::MatrixXd r = c_b;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(c_b.cols(), c_b.cols());
  for (size_t i = 0; i < windows.size(); ++i) {
    const int w = windows[i];
    r -= e_[w].transpose() * c_a[i];
    out += c_a[i].transpose() * a_inverse_[w] * c_a[i];
  }
  out += r.transpose() * s_inverse_ * r;
  return out;
}

Eigen::MatrixXd ArrowSolver::QuadraticFormOfLocal(const std::vector<int>& windows,
                                                  const std::vector<Eigen::MatrixXd>& local) const {
  eigen_assert(local.size() == windows.size());
  const int q = problem_->q;
  std::vector<Eigen::MatrixXd> c_a;
  Eigen::MatrixXd c_b = Eigen::MatrixXd::Zero(q, local.empty() ? 0 : local.front().cols());
  for (size_t i = 0; i < windows.size(); ++i) {
    const ArrowBlock& k = problem_->blocks[windows[i]];
    c_a.push_back(local[i].topRows(k.p));
    c_b += Scatter(k, local[i].bottomRows(k.m()), q);
  }
  return QuadraticForm(windows, c_a, c_b);
}

Eigen::MatrixXd ArrowSolver::FormalAA(int w, int u) const {
  Eigen::MatrixXd out = e_[w] * s_inverse_ * e_[u].transpose();
  if (w == u) out += a_inverse_[w];
  return out;
}

Eigen::MatrixXd ArrowSolver::FormalAB(int w) const { return -e_[w] * s_inverse_; }

void ArrowSolver::FormSandwich() const {
  if (sandwich_ready_) return;
  const int q = problem_->q;
  Eigen::MatrixXd big_q = Eigen::MatrixXd::Zero(q, q);
  if (problem_->shared_prior_information.size() == q) {
    big_q.diagonal() += problem_->shared_prior_information;
  }
  t_.assign(windows(), {});
  for (int w = 0; w < windows(); ++w) {
    const ArrowBlock& k = problem_->blocks[w];
    Eigen::MatrixXd omega = k.scale * k.h;
    if (k.extra.size() > 0) omega += k.extra;
    omega.diagonal().head(k.p) += k.prior_information;
    // G_w^T = [E_w; -P_w] ((p + m) x q).
    Eigen::MatrixXd gt(k.p + k.m(), q);
    gt.topRows(k.p) = e_[w];
    gt.bottomRows(k.m()) = -Scatter(k, Eigen::MatrixXd::Identity(k.m(), k.m()), q).transpose();
    big_q += gt.transpose() * omega * gt;
    t_[w] = a_inverse_[w] * omega.topRows(k.p) * gt * s_inverse_;
  }
  sqs_ = s_inverse_ * big_q * s_inverse_;
  sandwich_ready_ = true;
}

Eigen::MatrixXd ArrowSolver::SandwichAA(int w, int u) const {
  FormSandwich();
  Eigen::MatrixXd out =
      t_[w] * e_[u].transpose() + e_[w] * t_[u].transpose() + e_[w] * sqs_ * e_[u].transpose();
  if (w == u) {
    const ArrowBlock& k = problem_->blocks[w];
    Eigen::MatrixXd omega_aa = k.scale * k.h.topLeftCorner(k.p, k.p);
    if (k.extra.size() > 0) omega_aa += k.extra.topLeftCorner(k.p, k.p);
    omega_aa.diagonal() += k.prior_information;
    out += a_inverse_[w] * omega_aa * a_inverse_[w];
  }
  return out;
}

Eigen::MatrixXd ArrowSolver::SandwichAB(int w) const {
  FormSandwich();
  return -t_[w] - e_[w] * sqs_;
}

Eigen::MatrixXd ArrowSolver::SandwichBB() const {
  FormSandwich();
  return sqs_;
}

}  // namespace fastcal::internal
