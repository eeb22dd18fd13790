// The calibration linearised at its solution (internal/calibration_linearisation.h).
#include "fastcal/internal/calibration_linearisation.h"

#include <algorithm>
#include <thread>

#include "fastcal/internal/calibration_model.h"

namespace fastcal::internal {
namespace {

bool IsPerCableGroup(ParameterKind kind) {
  return kind == ParameterKind::kLinearDensity || kind == ParameterKind::kEa ||
         kind == ParameterKind::kSensorGain || kind == ParameterKind::kSensorBias;
}

// Whether basis parameter `b` is part of parameter `p`: itself, or one cable of a
// per-cable group's common parameter.
bool Covers(const ParameterSpec& p, const ParameterSpec& b) {
  return SameParameter(p, b) || (p.kind == b.kind && IsPerCableGroup(p.kind) && p.index < 0);
}

// What one thread adds up over its share of the samples.
struct Sums {
  Eigen::MatrixXd information, cross;
  Eigen::VectorXd self, gradient;
  double chi_square = 0.0;
  int readings = 0;
  std::vector<FoldSums> folds;

  Sums(int n, int q, int blocks)
      : information(Eigen::MatrixXd::Zero(n, n)),
        cross(Eigen::MatrixXd::Zero(n, q)),
        self(Eigen::VectorXd::Zero(q)),
        gradient(Eigen::VectorXd::Zero(q)),
        folds(blocks) {
    for (FoldSums& f : folds) {
      f.information = Eigen::MatrixXd::Zero(n, n);
      f.gradient = Eigen::VectorXd::Zero(n);
      for (int i = 0; i < kNumCables; ++i) {
        f.cross_n2[i] = Eigen::VectorXd::Zero(n);
        f.normal_n2[i] = Eigen::MatrixXd::Zero(n, n);
      }
    }
  }

  void Add(const Sums& o) {
    information += o.information;
    cross += o.cross;
    self += o.self;
    gradient += o.gradient;
    chi_square += o.chi_square;
    readings += o.readings;
    for (size_t k = 0; k < folds.size(); ++k) {
      FoldSums& f = folds[k];
      const FoldSums& g = o.folds[k];
      f.samples += g.samples;
      f.information += g.information;
      f.gradient += g.gradient;
      for (int i = 0; i < kNumCables; ++i) {
        f.readings[i] += g.readings[i];
        f.sse_n2[i] += g.sse_n2[i];
        f.cross_n2[i] += g.cross_n2[i];
        f.normal_n2[i] += g.normal_n2[i];
      }
    }
  }
};

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Columns of `basis` (6 x K) summed into the parameters' columns (6 x columns.size()).
Eigen::MatrixXd Combine(const RowMatrix& basis, const std::vector<std::vector<int>>& columns) {
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(basis.rows(), static_cast<int>(columns.size()));
  for (size_t k = 0; k < columns.size(); ++k) {
    for (int c : columns[k]) j.col(static_cast<int>(k)) += basis.col(c);
  }
  return j;
}

// The shared, read-only part of a pass.
struct Pass {
  const LinearisationInputs& in;
  CalibrationModel model;
  std::vector<double> theta;
  std::vector<std::vector<int>> free_columns, candidate_columns;
};

// Samples [begin, end) of the fitted ones into *sums and rows of *out; false with the
// failing fitted sample in *failed.
bool Accumulate(const Pass& pass, int begin, int end, Linearisation* out, Sums* sums, int* failed) {
  const LinearisationInputs& in = pass.in;
  const int k_basis = pass.model.num_free();
  const int num_fit = static_cast<int>(in.fit.size());
  RowMatrix basis(kNumCables, k_basis);
  for (int j = begin; j < end; ++j) {
    const Sample& sample = in.data->samples[in.fit[j]];
    TensionResidual f{&pass.model,      sample.pose,
                      sample.tension_n, in.sigma_n[j],
                      in.statics,       in.starts.empty() ? StaticsSolution() : in.starts[j]};
    if (in.use_planned_attitude) f.pose.rotation = sample.planned_rotation;
    if (!in.excluded.empty()) f.excluded = in.excluded[in.fit[j]];
    const TensionCost cost(f);
    Eigen::Matrix<double, kNumCables, 1> r;
    const double* parameters[1] = {pass.theta.data()};
    double* jacobians[1] = {basis.data()};
    if (!cost.Evaluate(parameters, r.data(), jacobians)) {
      *failed = j;
      return false;
    }
    for (int i = 0; i < kNumCables; ++i) {
      if (f.excluded[i]) basis.row(i).setZero();  // r_i is 0 already
    }
    const Eigen::MatrixXd jx_raw = Combine(basis, pass.free_columns);
    const Eigen::MatrixXd jc_raw = Combine(basis, pass.candidate_columns);
    double weight = 1.0;  // sqrt(rho'(|r|^2)): the robust loss's IRLS weight
    if (in.loss != nullptr) {
      double rho[3];
      in.loss->Evaluate(r.squaredNorm(), rho);
      weight = std::sqrt(std::max(rho[1], 0.0));
    }
    const Eigen::VectorXd rw = weight * r;
    const Eigen::MatrixXd jx = weight * jx_raw;
    const Eigen::MatrixXd jc = weight * jc_raw;
    out->residuals.row(j) = r.transpose();
    out->scores.row(j) = rw.transpose() * jx;
    sums->information.noalias() += jx.transpose() * jx;
    for (int i = 0; i < kNumCables; ++i) {
      out->jacobians.row(j).segment(i * jx.cols(), jx.cols()) = jx.row(i).cast<float>();
    }
    sums->cross.noalias() += jx.transpose() * jc;
    sums->self += jc.colwise().squaredNorm().transpose();
    sums->gradient.noalias() += jc.transpose() * rw;
    sums->chi_square += rw.squaredNorm();
    FoldSums& fold = sums->folds[BlockOfSample(j, num_fit, static_cast<int>(sums->folds.size()))];
    ++fold.samples;
    fold.information.noalias() += jx.transpose() * jx;
    fold.gradient.noalias() += jx.transpose() * rw;
    for (int i = 0; i < kNumCables; ++i) {
      if (f.excluded[i]) continue;
      ++sums->readings;
      const double s = in.sigma_n[j][i];
      const Eigen::VectorXd ji = s * jx_raw.row(i).transpose();  // N per parameter unit
      const double ri = s * r[i];                                // N
      ++fold.readings[i];
      fold.sse_n2[i] += ri * ri;
      fold.cross_n2[i] += ri * ji;
      fold.normal_n2[i].noalias() += ji * ji.transpose();
    }
  }
  return true;
}

}  // namespace

std::vector<ParameterSpec> BasisParameters(int num_anchor_points) {
  std::vector<ParameterSpec> basis;
  for (ParameterSpec p : AllModelParameters(num_anchor_points)) {
    if (IsPerCableGroup(p.kind) && p.index < 0) continue;
    p.free = true;
    basis.push_back(p);
  }
  return basis;
}

std::vector<int> BasisColumns(const ParameterSpec& p, int num_anchor_points) {
  const std::vector<ParameterSpec> basis = BasisParameters(num_anchor_points);
  std::vector<int> columns;
  for (size_t c = 0; c < basis.size(); ++c) {
    if (Covers(p, basis[c])) columns.push_back(static_cast<int>(c));
  }
  return columns;
}

bool Linearise(const LinearisationInputs& in, Linearisation* out, std::string* error) {
  const int num_anchor_points = static_cast<int>(in.at_solution.anchor_points_cabin_m.size());
  CalibrationSpec basis_spec;
  basis_spec.parameters = BasisParameters(num_anchor_points);
  Pass pass{in, CalibrationModel(in.at_solution, basis_spec), {}, {}, {}};
  pass.theta = pass.model.InitialTheta();
  for (const ParameterSpec& p : in.free) {
    pass.free_columns.push_back(BasisColumns(p, num_anchor_points));
  }
  for (const ParameterSpec& p : in.candidates) {
    pass.candidate_columns.push_back(BasisColumns(p, num_anchor_points));
  }
  const int n = static_cast<int>(in.free.size());
  const int q = static_cast<int>(in.candidates.size());
  const int num_fit = static_cast<int>(in.fit.size());
  const int blocks = std::clamp(in.cross_validation_blocks, 1, std::max(1, num_fit));
  *out = Linearisation();
  out->scores = Eigen::MatrixXd::Zero(num_fit, n);
  out->residuals = Eigen::MatrixXd::Zero(num_fit, kNumCables);
  out->jacobians = SampleJacobians::Zero(num_fit, kNumCables * n);

  const int threads = std::clamp(in.num_threads, 1, std::max(1, num_fit));
  std::vector<Sums> sums(threads, Sums(n, q, blocks));
  std::vector<int> failed(threads, -1);
  std::vector<std::thread> workers;
  for (int w = 0; w < threads; ++w) {
    const int begin = static_cast<int>(static_cast<long long>(num_fit) * w / threads);
    const int end = static_cast<int>(static_cast<long long>(num_fit) * (w + 1) / threads);
    workers.emplace_back(
        [&, w, begin, end] { Accumulate(pass, begin, end, out, &sums[w], &failed[w]); });
  }
  for (std::thread& t : workers) t.join();
  for (int w = 0; w < threads; ++w) {
    if (failed[w] >= 0) {
      const Sample& s = in.data->samples[in.fit[failed[w]]];
      *error = in.data->path + ":" + std::to_string(s.line) +
               ": the calibrated model cannot solve this pose";
      return false;
    }
    if (w > 0) sums[0].Add(sums[w]);
  }
  out->information = std::move(sums[0].information);
  out->cross = std::move(sums[0].cross);
  out->self = std::move(sums[0].self);
  out->gradient = std::move(sums[0].gradient);
  out->chi_square = sums[0].chi_square;
  out->readings = sums[0].readings;
  out->folds = std::move(sums[0].folds);
  return true;
}

}  // namespace fastcal::internal
