// The identifiability of a calibration's free set from the R factor of its whitened
// Jacobian (internal/identifiability.h): with R = U S V^T (columns scaled to unit norm
// first, so that units do not matter), var_j = sum_k (V_jk / s_k)^2 / scale_j^2, the
// correlations from V diag(1/s^2) V^T, and the directions of small s_k / s_1.
#include "fastcal/internal/identifiability.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "fastcal/internal/calibration_linearisation.h"

namespace fastcal::internal {
namespace {

// Rows of the Jacobian folded into its R factor at a time.
constexpr int kQrChunkRows = 1024;
// Weights below this are left out of a direction's description.
constexpr double kDirectionWeightFloor = 0.1;

}  // namespace

// The largest sigma with which a parameter counts as determined (CalibrationOptions).
double MaxSigma(const ParameterSpec& p, double initial, const CalibrationOptions& o) {
  return MaxSigmaOf(p.kind, initial, p.has_prior ? p.prior_sigma_si : 0.0, o);
}

// Upper-triangular R with R^T R = J^T J, folded from the CRS Jacobian chunk by chunk so
// a tall Jacobian never has to be dense in memory, and without squaring its condition.
Eigen::MatrixXd RFactor(const ceres::CRSMatrix& j) {
  const int n = j.num_cols;
  Eigen::MatrixXd r(0, n);
  for (int start = 0; start < j.num_rows; start += kQrChunkRows) {
    const int rows = std::min(kQrChunkRows, j.num_rows - start);
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(rows, n);
    for (int i = 0; i < rows; ++i) {
      for (int p = j.rows[start + i]; p < j.rows[start + i + 1]; ++p) m(i, j.cols[p]) = j.values[p];
    }
    r = FoldRows(r, m);
  }
  return r.rows() == n ? r : Eigen::MatrixXd(Eigen::MatrixXd::Zero(n, n));
}

Identifiability Analyse(const Eigen::MatrixXd& r, const std::vector<std::string>& names,
                        const CalibrationOptions& options) {
  Identifiability out;
  const int n = static_cast<int>(r.cols());
  Eigen::VectorXd scale(n);
  for (int c = 0; c < n; ++c) {
    const double norm = r.col(c).norm();
    scale[c] = norm > 0.0 ? norm : 1.0;  // a parameter with no effect stays a null column
  }
  const Eigen::MatrixXd scaled = r * scale.cwiseInverse().asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  const double s_max = s.size() > 0 ? s[0] : 0.0;
  // var_j = sum_k (V_jk / s_k)^2 / scale_j^2.
  out.sigma_si.assign(n, 0.0);
  for (int j = 0; j < n; ++j) {
    double var = 0.0;
    for (int k = 0; k < s.size(); ++k) {
      const double vjk = svd.matrixV()(j, k);
      var += s[k] > 0.0 ? vjk * vjk / (s[k] * s[k]) : std::numeric_limits<double>::infinity();
    }
    out.sigma_si[j] = std::sqrt(var) / scale[j];
  }
  // Correlations (scale-free): C = V diag(1/s^2) V^T in the scaled parameters.
  out.partner.assign(n, -1);
  out.partner_correlation.assign(n, 0.0);
  if (s.size() == n && n > 1 && s[n - 1] > 0.0) {
    const Eigen::MatrixXd vs = svd.matrixV() * s.cwiseInverse().asDiagonal();
    const Eigen::MatrixXd c = vs * vs.transpose();
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        if (k == j) continue;
        const double rho = c(j, k) / std::sqrt(c(j, j) * c(k, k));
        if (std::abs(rho) > std::abs(out.partner_correlation[j])) {
          out.partner[j] = k;
          out.partner_correlation[j] = rho;
        }
      }
    }
  }
  for (int k = 0; k < s.size(); ++k) {
    const double ratio = s_max > 0.0 ? s[k] / s_max : 0.0;
    out.singular_value_ratios.push_back(ratio);
    if (ratio >= options.poorly_determined_ratio) continue;
    ParameterDirection d;
    d.singular_value_ratio = ratio;
    Eigen::VectorXd v = svd.matrixV().col(k);
    // Sign convention: the largest weight positive.
    Eigen::Index big;
    v.cwiseAbs().maxCoeff(&big);
    if (v[big] < 0) v = -v;
    std::vector<std::pair<std::string, double>> w;
    for (int c = 0; c < n; ++c) {
      if (std::abs(v[c]) >= kDirectionWeightFloor) w.emplace_back(names[c], v[c]);
    }
    std::sort(w.begin(), w.end(),
              [](const auto& a, const auto& b) { return std::abs(a.second) > std::abs(b.second); });
    d.weights = w;
    (ratio < options.undetermined_ratio ? out.undetermined : out.poorly_determined).push_back(d);
  }
  return out;
}

// R factor of the whitened Jacobian (data and prior rows) at the current parameters.
// On one Ceres thread, as the solver (calibration.cc): the data term is one block that
// folds the samples on the spec's threads itself, so Ceres's threads had only the priors
// to share out. And Ceres 2.1's ParallelFor is not safe when memory runs out: a task left
// in its pool after the caller's bad_alloc ran an empty std::function when the problem
// was destroyed, and the process aborted (under `ulimit -v`, about 1 run in 50) instead
// of saying "out of memory".
bool JacobianR(ceres::Problem* problem, Eigen::MatrixXd* r) {
  ceres::Problem::EvaluateOptions eo;
  eo.num_threads = 1;
  ceres::CRSMatrix j;
  const bool evaluated = problem->Evaluate(eo, nullptr, nullptr, nullptr, &j);
  if (!evaluated) return false;
  *r = RFactor(j);
  return true;
}

}  // namespace fastcal::internal
