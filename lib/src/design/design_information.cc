// A survey design's information and criterion (internal/design_information.h; formulas in
// design.h). The Jacobian comes from the calibration's own residual, TensionResidual
// through TensionCost, with the consider parameters freed so that one Jet pass gives
// both [J_x J_c]: the same derivatives the calibration's budget uses. With the winches'
// lengths in the spec (noise.length_sigma_m) each pose has twelve rows, the six tensions'
// and the six lengths' (calibration_model.h), each whitened by its sigma.
#include "fastcal/internal/design_information.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/slow_error_filter.h"
#include "fastcal/statics.h"

namespace fastcal::internal {
namespace {

// A factor S (n x m, m the wanted parameters) of the criterion's weight on P, W = S S^T:
// A: diag(weights) on the wanted parameters, so S = sqrt(weight) on the diagonal; D: P_w^-1
// embedded, so S = its Cholesky factor in the wanted rows.
bool CriterionFactor(const DesignProblem& pr, const Eigen::MatrixXd& total, Eigen::MatrixXd* s) {
  const int n = pr.n;
  const int m = static_cast<int>(pr.wanted.size());
  s->setZero(n, m);
  if (pr.criterion == DesignCriterion::kA) {
    for (int a = 0; a < m; ++a) {
      (*s)(pr.wanted[a], a) = std::sqrt(std::max(pr.wanted_weight[pr.wanted[a]], 0.0));
    }
    return true;
  }
  Eigen::MatrixXd block(m, m);
  for (int a = 0; a < m; ++a) {
    for (int b = 0; b < m; ++b) block(a, b) = total(pr.wanted[a], pr.wanted[b]);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(block);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::LLT<Eigen::MatrixXd> inverse(llt.solve(Eigen::MatrixXd::Identity(m, m)));
  if (inverse.info() != Eigen::Success) return false;
  const Eigen::MatrixXd l = inverse.matrixL();
  for (int a = 0; a < m; ++a) s->row(pr.wanted[a]) = l.row(a);
  return true;
}

}  // namespace

bool SetUpDesignProblem(const CalibrationSpec& spec, DesignProblem* problem, std::string* error) {
  DesignProblem& pr = *problem;
  pr = DesignProblem();
  for (size_t j = 0; j < spec.parameters.size(); ++j) {
    const ParameterSpec& p = spec.parameters[j];
    if (p.free) pr.free_spec.push_back(static_cast<int>(j));
    if (p.IsConsider()) pr.consider_spec.push_back(static_cast<int>(j));
  }
  pr.n = static_cast<int>(pr.free_spec.size());
  pr.q = static_cast<int>(pr.consider_spec.size());
  if (pr.n == 0) {
    *error = "the spec frees no parameter: there is nothing to calibrate, so nothing to design for";
    return false;
  }
  if (pr.n + pr.q > kMaxFreeParameters) {
    *error = "the spec has " + std::to_string(pr.n) + " free and " + std::to_string(pr.q) +
             " consider parameters; the design handles at most " +
             std::to_string(kMaxFreeParameters) + " together";
    return false;
  }
  pr.prior_information = Eigen::VectorXd::Zero(pr.n);
  for (int k = 0; k < pr.n; ++k) {
    const ParameterSpec& p = spec.parameters[pr.free_spec[k]];
    if (p.has_prior) pr.prior_information[k] = 1.0 / (p.prior_sigma_si * p.prior_sigma_si);
  }
  pr.consider_variance.resize(pr.q);
  for (int c = 0; c < pr.q; ++c) {
    const ParameterSpec& p = spec.parameters[pr.consider_spec[c]];
    pr.consider_variance[c] = p.prior_sigma_si * p.prior_sigma_si;
    const std::string group = ParameterGroupName(p.kind);
    int g = 0;
    while (g < static_cast<int>(pr.consider_groups.size()) && pr.consider_groups[g] != group) ++g;
    if (g == static_cast<int>(pr.consider_groups.size())) pr.consider_groups.push_back(group);
    pr.consider_group.push_back(g);
  }
  pr.rows = spec.UsesLengths() ? kMaxReadings : kNumCables;
  pr.x_rows.resize(0, pr.n);
  pr.z_rows.resize(0, pr.q);
  pr.wanted_weight = Eigen::VectorXd::Zero(pr.n);
  return true;
}

bool AddPoseRows(const CableRobot& robot, const CalibrationSpec& spec,
                 const std::vector<Pose>& poses, const std::vector<JointValues>& joints,
                 DesignProblem* problem, std::string* error) {
  DesignProblem& pr = *problem;
  // The consider parameters freed: one Jet pass differentiates against both kinds.
  CalibrationSpec both = spec;
  for (int j : pr.consider_spec) both.parameters[j].free = true;
  const CalibrationModel model(robot, both);
  const std::vector<double> theta = model.InitialTheta();
  std::vector<int> column(model.num_free());  // x columns first, then z (+ n)
  {
    int x = 0, z = 0;
    for (int k = 0; k < model.num_free(); ++k) {
      column[k] = spec.parameters[model.spec_index(k)].free ? x++ : pr.n + z++;
    }
  }
  TensionResidual f{&model,        Pose(), {}, {}, ModelFitStaticsOptions(spec.forward_model),
                    CompactStart()};
  f.sigma_n.fill(1.0);                             // residual = reading; whitened below
  if (spec.UsesLengths()) f.length_sigma_m = 1.0;  // residual = s0 + offset; likewise
  const int rows = pr.rows;
  const int first = static_cast<int>(pr.x_rows.rows());
  const int total_rows = first + rows * static_cast<int>(poses.size());
  pr.x_rows.conservativeResize(total_rows, pr.n);
  pr.z_rows.conservativeResize(total_rows, pr.q);
  pr.reading.conservativeResize(total_rows);
  pr.white_sigma.conservativeResize(total_rows);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jac(rows,
                                                                             model.num_free());
  std::array<double, kMaxReadings> reading{};
  for (size_t t = 0; t < poses.size(); ++t) {
    if (!joints.empty()) f.joints = joints[t];
    // The residual reads the data's pose (the measured frame's): the cabin's through it.
    f.pose = robot.MeasuredPose(poses[t], f.joints);
    const TensionCost cost(f);
    const double* parameters[1] = {theta.data()};
    double* jacobians[1] = {jac.data()};
    if (!cost.Evaluate(parameters, reading.data(), jacobians)) {
      const Eigen::Vector3d& p = poses[t].position_m;
      *error = "pose " + std::to_string(t + 1) + " at (" + std::to_string(p[0]) + ", " +
               std::to_string(p[1]) + ", " + std::to_string(p[2]) +
               ") m: the statics of the spec's initial model fail there";
      pr.x_rows.conservativeResize(first, pr.n);
      pr.z_rows.conservativeResize(first, pr.q);
      pr.reading.conservativeResize(first);
      pr.white_sigma.conservativeResize(first);
      return false;
    }
    std::array<double, kNumCables> tension{};
    std::copy(reading.begin(), reading.begin() + kNumCables, tension.begin());
    const std::array<double, kNumCables> sigma =
        TensionSigmas(tension, spec.tension_sigma_n, spec.tension_sigma_percent);
    for (int i = 0; i < rows; ++i) {
      const int row = first + rows * static_cast<int>(t) + i;
      const double sigma_i = i < kNumCables ? sigma[i] : spec.length_sigma_m;
      pr.reading[row] = reading[i];
      pr.white_sigma[row] = sigma_i;
      for (int k = 0; k < model.num_free(); ++k) {
        const double v = jac(i, k) / sigma_i;
        if (column[k] < pr.n) {
          pr.x_rows(row, column[k]) = v;
        } else {
          pr.z_rows(row, column[k] - pr.n) = v;
        }
      }
    }
  }
  return true;
}

void WhitenInTimeOrder(const SlowErrorProcess& process, const std::vector<double>& times_s,
                       DesignProblem* problem) {
  DesignProblem& pr = *problem;
  const int columns = pr.n + pr.q;
  ReadingWhitener whitener(process, columns);
  if (!whitener.active()) return;
  std::vector<double> rows(static_cast<size_t>(kNumCables) * columns);
  std::array<double, kNumCables> rho{};
  for (int t = 0; t < pr.candidates() && t < static_cast<int>(times_s.size()); ++t) {
    const int first = pr.rows * t;  // the tension rows come first (AddPoseRows)
    for (int i = 0; i < kNumCables; ++i) {
      rho[i] = process.SigmaN(std::abs(pr.reading[first + i])) / pr.white_sigma[first + i];
      for (int k = 0; k < pr.n; ++k) rows[i * columns + k] = pr.x_rows(first + i, k);
      for (int c = 0; c < pr.q; ++c) rows[i * columns + pr.n + c] = pr.z_rows(first + i, c);
    }
    whitener.WhitenOnly(times_s[t], 0, rho.data(), nullptr, rows.data());
    for (int i = 0; i < kNumCables; ++i) {
      for (int k = 0; k < pr.n; ++k) pr.x_rows(first + i, k) = rows[i * columns + k];
      for (int c = 0; c < pr.q; ++c) pr.z_rows(first + i, c) = rows[i * columns + pr.n + c];
    }
  }
}

DesignSums SumsOf(const DesignProblem& pr, const Eigen::VectorXd& weights) {
  DesignSums s;
  s.m = Eigen::MatrixXd::Zero(pr.n, pr.n);
  s.c = Eigen::MatrixXd::Zero(pr.n, pr.q);
  for (int k = 0; k < pr.candidates(); ++k) {
    if (!(weights[k] > 0.0)) continue;
    const auto x = pr.x_rows.middleRows(pr.rows * k, pr.rows);
    s.m.noalias() += weights[k] * (x.transpose() * x);
    if (pr.q > 0)
      s.c.noalias() += weights[k] * (x.transpose() * pr.z_rows.middleRows(pr.rows * k, pr.rows));
  }
  return s;
}

DesignSums SumsOfCandidate(const DesignProblem& pr, int k) {
  const auto x = pr.x_rows.middleRows(pr.rows * k, pr.rows);
  DesignSums s;
  s.m = x.transpose() * x;
  s.c = x.transpose() * pr.z_rows.middleRows(pr.rows * k, pr.rows);
  return s;
}

bool CovarianceOf(const DesignProblem& pr, const DesignSums& sums, DesignCovariance* out) {
  Eigen::MatrixXd m = sums.m;
  m.diagonal() += pr.prior_information;
  const Eigen::LLT<Eigen::MatrixXd> llt(m);
  if (llt.info() != Eigen::Success) return false;
  out->k = llt.solve(Eigen::MatrixXd::Identity(pr.n, pr.n));
  // An information matrix that is positive definite only by rounding: refuse, as the
  // calibration's identifiability check would (its 1e-8 singular-value ratio, squared).
  const Eigen::VectorXd scale = m.diagonal().cwiseSqrt();
  const Eigen::MatrixXd normalised = scale.asDiagonal() * out->k * scale.asDiagonal();
  if (!(normalised.diagonal().maxCoeff() < 1e16) || !out->k.allFinite()) return false;
  const Eigen::MatrixXd kc = out->k * sums.c;
  out->total = out->k + kc * pr.consider_variance.asDiagonal() * kc.transpose();
  return true;
}

double CriterionOf(const DesignProblem& pr, const DesignSums& sums) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  DesignCovariance cov;
  if (!CovarianceOf(pr, sums, &cov)) return kInfinity;
  if (pr.criterion == DesignCriterion::kA) {
    double f = 0.0;
    for (int j : pr.wanted) f += pr.wanted_weight[j] * cov.total(j, j);
    return f;
  }
  const int m = static_cast<int>(pr.wanted.size());
  Eigen::MatrixXd block(m, m);
  for (int a = 0; a < m; ++a) {
    for (int b = 0; b < m; ++b) block(a, b) = cov.total(pr.wanted[a], pr.wanted[b]);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(block);
  if (llt.info() != Eigen::Success) return kInfinity;
  return 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
}

bool CriterionGradient(const DesignProblem& pr, const DesignSums& sums, Eigen::VectorXd* gradient) {
  DesignCovariance cov;
  if (!CovarianceOf(pr, sums, &cov)) return false;
  Eigen::MatrixXd factor;
  if (!CriterionFactor(pr, cov.total, &factor)) return false;
  // With W = S S^T, G and H are of rank <= 2m and m (m wanted parameters, often 3 of
  // 21): for a row x (free columns) and z (consider columns), with u = x K S,
  // v = x Q S and p = z Sigma_c C^T K S (Q = K C Sigma_c C^T K),
  //   -x G x^T + 2 z H x^T = -(u.u + 2 u.v) + 2 p.u = -u.(u + 2 v - 2 p),
  // three products with n x m and q x m matrices per row instead of n x n and q x n.
  const Eigen::MatrixXd& k = cov.k;
  const Eigen::MatrixXd kc = k * sums.c;
  const int m = static_cast<int>(factor.cols());
  const Eigen::MatrixXd p = pr.consider_variance.asDiagonal() * (kc.transpose() * factor);
  Eigen::MatrixXd ab(pr.n, 2 * m);  // [K S, K S + 2 Q S]: x's rows read once for both
  ab.leftCols(m) = k * factor;
  ab.rightCols(m) = ab.leftCols(m) + 2.0 * (kc * p);
  const Eigen::MatrixXd e = -2.0 * p;
  // Per candidate: the sum over its rows. In chunks, so that the temporaries stay
  // small, the chunks shared by two threads (the gradient is most of a design's time).
  constexpr int kChunkCandidates = 512;
  constexpr int kThreads = 2;
  gradient->resize(pr.candidates());
  const int chunks = (pr.candidates() + kChunkCandidates - 1) / kChunkCandidates;
  auto work = [&](int first_chunk) {
    Eigen::MatrixXd uy;  // [u, u + 2 v - 2 p]
    for (int chunk = first_chunk; chunk < chunks; chunk += kThreads) {
      const int c0 = chunk * kChunkCandidates;
      const int count = std::min(kChunkCandidates, pr.candidates() - c0);
      uy.noalias() = pr.x_rows.middleRows(pr.rows * c0, pr.rows * count) * ab;
      if (pr.q > 0) {
        uy.rightCols(m).noalias() += pr.z_rows.middleRows(pr.rows * c0, pr.rows * count) * e;
      }
      const Eigen::VectorXd per_row =
          -(uy.leftCols(m).cwiseProduct(uy.rightCols(m))).rowwise().sum();
      for (int c = 0; c < count; ++c) {
        (*gradient)[c0 + c] = per_row.segment(pr.rows * c, pr.rows).sum();
      }
    }
  };
  if (chunks < kThreads) {
    work(0);
    return true;
  }
  // Thread w takes chunks w, w + kThreads, ...; the strides of threads the system refused
  // (OnThreads: a process limit is not an abort) are taken here afterwards.
  for (int w = internal::OnThreads(kThreads, work); w < kThreads; ++w) work(w);
  return true;
}

}  // namespace fastcal::internal
