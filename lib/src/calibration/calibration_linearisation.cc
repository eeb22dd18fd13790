// The calibration linearised at its solution (internal/calibration_linearisation.h).
#include "fastcal/internal/calibration_linearisation.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <thread>

#include "fastcal/internal/folded_cost.h"
#include "fastcal/internal/gram_fold.h"
#include "fastcal/internal/row_fold.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/sample_rows.h"
#include "fastcal/internal/slow_error_estimate.h"

namespace fastcal::internal {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// A sample's residuals: its readings (FittedSamples::readings), six or twelve.
using SampleResiduals = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxReadings, 1>;

// Whether basis parameter `b` is part of parameter `p`: itself, or one cable of a
// per-cable group's common parameter.
bool Covers(const ParameterSpec& p, const ParameterSpec& b) {
  return SameParameter(p, b) || (p.kind == b.kind && IsPerCableCapable(p.kind) && p.index < 0);
}

// The robust loss's IRLS weight sqrt(rho'(|r|^2)) of a sample's residuals (1 without a
// loss); `curvature` (may be null) receives 2 rho'' for the loss's exact Hessian
// rho' J^T J + 2 rho'' (J^T r)(J^T r)^T (0 without a loss).
double LossWeight(const ceres::LossFunction* loss, const SampleResiduals& r,
                  double* curvature = nullptr) {
  if (curvature != nullptr) *curvature = 0.0;
  if (loss == nullptr) return 1.0;
  double rho[3];
  loss->Evaluate(r.squaredNorm(), rho);
  if (curvature != nullptr) *curvature = 2.0 * rho[2];
  return std::sqrt(std::max(rho[1], 0.0));
}

// Sample t's residuals and n-column Jacobian from `rows`.
void RowsOf(const SampleRows& rows, int t, SampleResiduals* r, RowMatrix* j) {
  const int n = rows.columns - 1;
  const double* values = rows.Of(t);
  r->resize(rows.readings);
  j->resize(rows.readings, n);
  for (int i = 0; i < rows.readings; ++i) {
    for (int k = 0; k < n; ++k) (*j)(i, k) = values[i * rows.columns + k];
    (*r)[i] = values[i * rows.columns + n];
  }
}

// ---------------------------------------------------------------------------------------
// The free pass.

struct FreeSums {
  Eigen::MatrixXd information, curvature;
  RowFold fold;  // of the weighted rows: the R factor
  double chi_square = 0.0, raw_chi_square = 0.0;
  int readings = 0;
  std::vector<FoldSums> folds;
  std::vector<Eigen::MatrixXd> session_information;  // with two or more sessions
  std::vector<Eigen::VectorXd> session_gradient;

  FreeSums(int n, int blocks, int sessions)
      : information(Eigen::MatrixXd::Zero(n, n)),
        curvature(Eigen::MatrixXd::Zero(n, n)),
        fold(n),
        folds(blocks) {
    for (int s = 0; sessions > 1 && s < sessions; ++s) {
      session_information.push_back(Eigen::MatrixXd::Zero(n, n));
      session_gradient.push_back(Eigen::VectorXd::Zero(n));
    }
    for (FoldSums& f : folds) {
      f.information = Eigen::MatrixXd::Zero(n, n);
      f.gradient = Eigen::VectorXd::Zero(n);
      for (int i = 0; i < kNumCables; ++i) {
        f.cross_n2[i] = Eigen::VectorXd::Zero(n);
        f.normal_n2[i] = Eigen::MatrixXd::Zero(n, n);
      }
    }
  }

  // Each reading's rows over its own columns first (ReadingColumns without the residual's)
  // where they are zero elsewhere: a third of the flops of the full width (issue 41).
  std::optional<GroupedRowFold> grouped;

  void AddRows(const RowMatrix& rows) {
    if (!grouped) {
      fold.Add(rows.data(), static_cast<int>(rows.rows()));
      return;
    }
    for (int i = 0; i < rows.rows(); ++i) grouped->Add(i, rows.row(i).data());
  }
  void Flush() {
    if (grouped) {
      grouped->FlushInto(&fold);
    } else {
      fold.Flush();
    }
  }

  void Add(const FreeSums& o) {
    fold.Add(o.fold);
    information += o.information;
    curvature += o.curvature;
    chi_square += o.chi_square;
    raw_chi_square += o.raw_chi_square;
    readings += o.readings;
    for (size_t k = 0; k < session_information.size(); ++k) {
      session_information[k] += o.session_information[k];
      session_gradient[k] += o.session_gradient[k];
    }
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

// The cross-validation block sums of one sample that are not Gram matrices (those are
// summed over a run of samples, RunSums): the whitened rows r, j for the prediction, the
// rows as evaluated (r_raw: before the slow-error whitening; the same without it) in
// newtons for the RMS.
void AddToFold(const std::array<bool, kNumCables>& excluded,
               const std::array<double, kNumCables>& sigma_n, const SampleResiduals& r,
               const RowMatrix& j, const SampleResiduals& r_raw, const RowMatrix& j_raw,
               double weight, FoldSums* fold) {
  ++fold->samples;
  fold->gradient.noalias() += weight * weight * j.transpose() * r;
  for (int i = 0; i < kNumCables; ++i) {
    if (excluded[i]) continue;
    const double s = sigma_n[i];
    const double ri = s * r_raw[i];  // N
    ++fold->readings[i];
    fold->sse_n2[i] += ri * ri;
    fold->cross_n2[i].noalias() += ri * (s * j_raw.row(i).transpose());  // N^2 per unit
  }
}

// The Gram matrices of a run of consecutive samples in one cross-validation block and one
// session, summed a batch of rows at a time (gram_fold.h: a sample's rank-6 update and
// its six rank-1 updates were as costly as its statics, issue 41), then added into the
// total's, the session's and the block's lower triangles.
struct RunSums {
  GramFold information;                     // the weighted whitened rows
  std::array<GramFold, kNumCables> normal;  // sigma_i times each raw row i (N per unit)
  int block = -1, session = -1;

  explicit RunSums(int n) : information(n) {
    for (GramFold& g : normal) g = GramFold(n);
  }
  void Add(const RowMatrix& jw, const std::array<bool, kNumCables>& excluded,
           const std::array<double, kNumCables>& sigma_n, const RowMatrix& j_raw) {
    for (int i = 0; i < jw.rows(); ++i) information.Add(jw.row(i).data());
    thread_local Eigen::RowVectorXd ji;  // no allocation per reading
    for (int i = 0; i < kNumCables; ++i) {
      if (excluded[i]) continue;
      ji.noalias() = sigma_n[i] * j_raw.row(i);
      normal[i].Add(ji.data());
    }
  }
  void FlushInto(FreeSums* sums) {
    if (block < 0) return;
    information.Flush();
    const Eigen::MatrixXd& lower = information.lower();
    sums->information += lower;
    if (!sums->session_information.empty()) sums->session_information[session] += lower;
    FoldSums& fold = sums->folds[block];
    fold.information += lower;
    for (int i = 0; i < kNumCables; ++i) {
      normal[i].Flush();
      fold.normal_n2[i] += normal[i].lower();
      normal[i].Reset();
    }
    information.Reset();
    block = session = -1;
  }
};

// A matrix accumulated in its lower triangle, made whole.
void Symmetric(Eigen::MatrixXd* m) { m->triangularView<Eigen::StrictlyUpper>() = m->transpose(); }

// Each block's information and per-cable normal matrices, accumulated in their lower
// triangles, made whole.
void SymmetricNormals(std::vector<FoldSums>* folds) {
  for (FoldSums& f : *folds) {
    Symmetric(&f.information);
    for (Eigen::MatrixXd& m : f.normal_n2) Symmetric(&m);
  }
}

// A chunk of the free pass: its rows as evaluated (for the cross-validation's sums in
// newtons) and whitened, and its sums.
struct FreeChunk {
  FreeSums sums;
  SampleRows raw, rows;
};

// Fitted samples [begin, end) evaluated into chunk->rows; the first that fails, or -1.
int EvaluateFree(const LinearisationInputs& in, const ModelAtTheta& at, int begin, int end,
                 FreeChunk* chunk) {
  chunk->rows.Reset(begin, end, in.samples.model->num_free() + 1, in.samples.readings());
  for (int t = begin; t < end; ++t) {
    if (!EvaluateSampleRows(in.samples, t, at, t, &chunk->rows)) return t;
  }
  return -1;
}

// The whitened rows of fitted samples [begin, end) into `sums`.
void AccumulateFree(const LinearisationInputs& in, const std::vector<int>& candidate_row, int begin,
                    int end, Linearisation* out, FreeChunk* chunk) {
  const int n = in.samples.model->num_free();
  const int num_fit = in.samples.size();
  FreeSums* sums = &chunk->sums;
  // Workspaces kept across samples: no allocation per sample (issue 41).
  RowMatrix j, j_raw, j_weighted;
  SampleResiduals r, r_raw, r_weighted;
  Eigen::RowVectorXd score(n);
  RunSums run(n);
  for (int t = begin; t < end; ++t) {
    const std::array<bool, kNumCables> excluded = in.samples.Excluded(t);
    RowsOf(chunk->rows, t, &r, &j);
    RowsOf(chunk->raw, t, &r_raw, &j_raw);
    double curvature = 0.0;
    const double weight = LossWeight(in.loss, r, &curvature);
    if (weight != 1.0) {
      j_weighted = weight * j;
      r_weighted = weight * r;
    }
    const RowMatrix& jw = weight != 1.0 ? j_weighted : j;
    const SampleResiduals& rw = weight != 1.0 ? r_weighted : r;
    out->residuals.row(t) = r.transpose();
    score.noalias() = rw.transpose() * jw;
    out->scores.row(t) = score.cast<float>();
    if (candidate_row[t] >= 0) out->candidate_free_scores.row(candidate_row[t]) = score;
    if (in.keep_jacobians) {
      for (int i = 0; i < jw.rows(); ++i) {
        out->jacobians.row(t).segment(i * n, n) = jw.row(i).cast<float>();
      }
    }
    const int session = in.samples.data->samples[(*in.samples.fit)[t]].session;
    const int block = BlockOfSample(t, num_fit, static_cast<int>(sums->folds.size()));
    if (block != run.block || (!sums->session_information.empty() && session != run.session)) {
      run.FlushInto(sums);
      run.block = block;
      run.session = session;
    }
    run.Add(jw, excluded, (*in.samples.sigma_n)[t], j_raw);
    if (!sums->session_information.empty()) {
      sums->session_gradient[session].noalias() += jw.transpose() * rw;
    }
    if (curvature != 0.0) {
      const Eigen::VectorXd jr = j.transpose() * r;
      sums->curvature.noalias() += curvature * jr * jr.transpose();
    }
    sums->AddRows(jw);
    sums->chi_square += rw.squaredNorm();
    sums->raw_chi_square += r.squaredNorm();
    for (bool e : excluded) sums->readings += !e;
    if (in.samples.readings() > kNumCables) {
      const std::array<bool, kNumCables> length_excluded = in.samples.LengthExcluded(t);
      for (bool e : length_excluded) sums->readings += !e;
    }
    AddToFold(excluded, (*in.samples.sigma_n)[t], r, j, r_raw, j_raw, weight, &sums->folds[block]);
  }
  run.FlushInto(sums);
  sums->Flush();
}

// ---------------------------------------------------------------------------------------
// The candidate pass.

struct CandidatePass {
  const LinearisationInputs& in;
  // The basis at the calibrated model of each session (one without sessions), and each
  // assembled at its own values.
  std::vector<CalibrationModel> basis;
  std::vector<ModelAtTheta> basis_at;
  std::vector<std::vector<double>> theta;  // each basis's own values
  std::vector<std::vector<int>> free_columns, candidate_columns;
  std::vector<int> free_session;  // of each free parameter (ParameterSpec::session)
};

struct CandidateSums {
  Eigen::MatrixXd cross;
  Eigen::VectorXd self, gradient;
  Eigen::MatrixXd information;  // J_x^T J_x over the same samples
};

// Columns of `basis` (6 x K) summed into the parameters' columns.
Eigen::MatrixXd Combine(const RowMatrix& basis, const std::vector<std::vector<int>>& columns) {
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(basis.rows(), static_cast<int>(columns.size()));
  for (size_t k = 0; k < columns.size(); ++k) {
    for (int c : columns[k]) j.col(static_cast<int>(k)) += basis.col(c);
  }
  return j;
}

// A chunk of the candidate pass: the basis rows of its samples, and its sums.
struct CandidateChunk {
  CandidateSums sums;
  SampleRows rows;
};

int SessionOf(const CandidatePass& pass, int fitted_sample) {
  const FittedSamples& in = pass.in.samples;
  return in.data->samples[(*in.fit)[fitted_sample]].session;
}

// The basis rows of the candidate pass's samples [begin, end) (positions in `samples`);
// the first that fails (a fitted sample), or -1.
int EvaluateCandidates(const CandidatePass& pass, const std::vector<int>& samples, int begin,
                       int end, CandidateChunk* chunk) {
  chunk->rows.Reset(begin, end, pass.basis.front().num_free() + 1, pass.in.samples.readings());
  for (int k = begin; k < end; ++k) {
    const ModelAtTheta& at = pass.basis_at[SessionOf(pass, samples[k])];
    if (!EvaluateSampleRows(pass.in.samples, samples[k], at, k, &chunk->rows)) return samples[k];
  }
  return -1;
}

// The (whitened) basis rows of samples [begin, end) into the chunk's sums.
void AccumulateCandidates(const CandidatePass& pass, const std::vector<int>& samples, int begin,
                          int end, CandidateChunk* chunk, Eigen::MatrixXd* scores) {
  RowMatrix b;
  SampleResiduals r;
  CandidateSums* sums = &chunk->sums;
  for (int k = begin; k < end; ++k) {
    const int session = SessionOf(pass, samples[k]);
    RowsOf(chunk->rows, k, &r, &b);
    const double weight = LossWeight(pass.in.loss, r);
    Eigen::MatrixXd jx = weight * Combine(b, pass.free_columns);
    for (size_t c = 0; c < pass.free_session.size(); ++c) {
      // Another session's copy: no effect on this sample.
      if (pass.free_session[c] >= 0 && pass.free_session[c] != session) jx.col(c).setZero();
    }
    const Eigen::MatrixXd jc = weight * Combine(b, pass.candidate_columns);
    const Eigen::VectorXd g = weight * (jc.transpose() * r);
    sums->cross.noalias() += jx.transpose() * jc;
    sums->self += jc.colwise().squaredNorm().transpose();
    sums->gradient += g;
    sums->information.noalias() += jx.transpose() * jx;
    scores->row(k) = g.transpose();
  }
}

// Evenly spaced fitted samples, at most `budget` of them.
std::vector<int> CandidateSamples(int num_fit, int budget) {
  std::vector<int> samples;
  const int used = std::min(num_fit, std::max(1, budget));
  for (int k = 0; k < used; ++k) {
    samples.push_back(static_cast<int>(static_cast<long long>(k) * num_fit / used));
  }
  return samples;
}

std::string CannotSolve(const LinearisationInputs& in, int fitted_sample) {
  const Dataset& data = *in.samples.data;
  const Sample& s = data.samples[(*in.samples.fit)[fitted_sample]];
  return SampleWhere(data, s) + ": the calibrated model cannot solve this pose";
}

// The free pass; out->candidate_rows must be set (their scores are kept in double).
bool LineariseFree(const LinearisationInputs& in, Linearisation* out, std::string* error) {
  const int n = in.samples.model->num_free();
  const int num_fit = in.samples.size();
  const int blocks = std::clamp(in.cross_validation_blocks, 1, std::max(1, num_fit));
  out->scores = SampleScores::Zero(num_fit, n);
  std::vector<int> candidate_row(num_fit, -1);  // each fitted sample's candidate row, or -1
  for (size_t k = 0; k < out->candidate_rows.size(); ++k) candidate_row[out->candidate_rows[k]] = k;
  out->candidate_free_scores =
      Eigen::MatrixXd::Zero(static_cast<int>(out->candidate_rows.size()), n);
  const int readings = in.samples.readings();
  out->residuals = Eigen::MatrixXd::Zero(num_fit, readings);
  if (in.keep_jacobians) out->jacobians = SampleJacobians::Zero(num_fit, readings * n);
  const int sessions = static_cast<int>(in.samples.data->session_labels.size());
  FreeSums total(n, blocks, sessions);
  std::vector<std::vector<int>> reading_columns = ReadingColumns(in.samples, in.loss);
  for (std::vector<int>& c : reading_columns) c.pop_back();  // the residual's: not folded here
  const ModelAtTheta at(*in.samples.model, in.theta, in.samples.sessions());
  SampleRowWhitener whitener(in.samples, n + 1);
  const int failed = ReduceChunksInOrder<FreeChunk>(
      num_fit, in.num_threads,
      [&] {
        FreeChunk chunk{FreeSums(n, blocks, sessions), {}, {}};
        if (!reading_columns.empty()) chunk.sums.grouped.emplace(reading_columns, n);
        return chunk;
      },
      [&](int begin, int end, FreeChunk* chunk) { return EvaluateFree(in, at, begin, end, chunk); },
      [&](int, int, FreeChunk* chunk) {
        chunk->raw = chunk->rows;
        whitener.Whiten(&chunk->rows);
      },
      [&](int begin, int end, FreeChunk* chunk) {
        AccumulateFree(in, candidate_row, begin, end, out, chunk);
        return -1;
      },
      [&](FreeChunk& chunk) { total.Add(chunk.sums); });
  if (failed >= 0) {
    *error = CannotSolve(in, failed);
    return false;
  }
  Symmetric(&total.information);
  for (Eigen::MatrixXd& m : total.session_information) Symmetric(&m);
  out->information = std::move(total.information);
  out->loss_curvature = std::move(total.curvature);
  out->r_factor = total.fold.r();
  out->chi_square = total.chi_square;
  out->raw_chi_square = total.raw_chi_square;
  out->readings = total.readings;
  SymmetricNormals(&total.folds);
  out->folds = std::move(total.folds);
  out->session_information = std::move(total.session_information);
  out->session_gradient = std::move(total.session_gradient);
  return true;
}

bool LineariseCandidates(const LinearisationInputs& in, Linearisation* out, std::string* error) {
  const CalibrationModel& fitted = *in.samples.model;
  const int n = fitted.num_free();
  const int q = static_cast<int>(in.candidates.size());
  const CableRobot& model = fitted.robot();
  CalibrationSpec basis_spec;
  const bool lengths = in.samples.readings() > kNumCables;
  basis_spec.parameters = BasisParameters(model, lengths);
  CandidatePass pass{in, {}, {}, {}, {}, {}, {}};
  const int sessions = in.samples.sessions();
  pass.basis.reserve(sessions);  // basis_at refers to them
  pass.theta.reserve(sessions);
  for (int s = 0; s < sessions; ++s) {
    pass.basis.emplace_back(fitted.ToRobot(in.theta, s), basis_spec);
    pass.theta.push_back(pass.basis.back().InitialTheta());
    pass.basis_at.emplace_back(pass.basis.back(), pass.theta.back().data(), sessions);
  }
  for (int k = 0; k < n; ++k) {
    const ParameterSpec& p = fitted.spec().parameters[fitted.spec_index(k)];
    pass.free_columns.push_back(BasisColumns(p, model, lengths));
    pass.free_session.push_back(p.session);
  }
  for (const ParameterSpec& p : in.candidates) {
    pass.candidate_columns.push_back(BasisColumns(p, model, lengths));
  }
  const std::vector<int>& samples = out->candidate_rows;
  const auto zero = [&] {
    return CandidateSums{Eigen::MatrixXd::Zero(n, q), Eigen::VectorXd::Zero(q),
                         Eigen::VectorXd::Zero(q), Eigen::MatrixXd::Zero(n, n)};
  };
  CandidateSums total = zero();
  out->candidate_scores = Eigen::MatrixXd::Zero(static_cast<int>(samples.size()), q);
  SampleRowWhitener whitener(in.samples, pass.basis.front().num_free() + 1);
  const int failed = ReduceChunksInOrder<CandidateChunk>(
      static_cast<int>(samples.size()), in.num_threads,
      [&] {
        return CandidateChunk{zero(), {}};
      },
      [&](int begin, int end, CandidateChunk* chunk) {
        return EvaluateCandidates(pass, samples, begin, end, chunk);
      },
      [&](int, int, CandidateChunk* chunk) { whitener.Whiten(&chunk->rows, &samples); },
      [&](int begin, int end, CandidateChunk* chunk) {
        AccumulateCandidates(pass, samples, begin, end, chunk, &out->candidate_scores);
        return -1;
      },
      [&](const CandidateChunk& chunk) {
        const CandidateSums& sums = chunk.sums;
        total.cross += sums.cross;
        total.self += sums.self;
        total.gradient += sums.gradient;
        total.information += sums.information;
      });
  if (failed >= 0) {
    *error = CannotSolve(in, failed);
    return false;
  }
  const double scale = static_cast<double>(in.samples.size()) / std::max<size_t>(1, samples.size());
  out->cross = scale * total.cross;
  out->self = scale * total.self;
  out->gradient = scale * total.gradient;
  out->candidate_samples = static_cast<int>(samples.size());
  out->candidate_information = scale * total.information;
  out->candidate_scale = scale;
  return true;
}

}  // namespace

std::vector<ParameterSpec> BasisParameters(const CableRobot& model, bool lengths) {
  std::vector<ParameterSpec> basis;
  for (ParameterSpec p : AllModelParameters(model)) {
    if (IsPerCableCapable(p.kind) && p.index < 0) continue;
    if (p.kind == ParameterKind::kLengthOffset && !lengths) continue;
    p.free = true;
    basis.push_back(p);
  }
  return basis;
}

std::vector<int> BasisColumns(const ParameterSpec& p, const CableRobot& model, bool lengths) {
  const std::vector<ParameterSpec> basis = BasisParameters(model, lengths);
  std::vector<int> columns;
  for (size_t c = 0; c < basis.size(); ++c) {
    if (Covers(p, basis[c])) columns.push_back(static_cast<int>(c));
  }
  return columns;
}

namespace {

// The inputs of a pass through the fit's own model: at the prediction's theta its starts
// are taken as solved (compact_start.h, FittedSamples::starts_solved).
LinearisationInputs AtSolvedStarts(const LinearisationInputs& in) {
  LinearisationInputs out = in;
  const FittedSamples& s = in.samples;
  out.samples.starts_solved =
      s.starts != nullptr && s.starts->SolvedAt(s.model, in.theta, s.model->num_free());
  return out;
}

}  // namespace

bool Linearise(const LinearisationInputs& in, Linearisation* out, std::string* error) {
  *out = Linearisation();
  // The candidate pass's samples. With a slow error the whitening needs neighbours:
  // contiguous runs (each a series of its own) rather than single samples spread out.
  out->candidate_rows = in.samples.whitened()
                            ? SlowErrorEstimateSamples(in.samples.size(), in.max_candidate_samples)
                            : CandidateSamples(in.samples.size(), in.max_candidate_samples);
  // The candidates' pass goes through another model and solves.
  return LineariseFree(AtSolvedStarts(in), out, error) && LineariseCandidates(in, out, error);
}

bool ReplayFreeJacobians(const LinearisationInputs& given,
                         const std::function<void(int t, const float* jacobian)>& visit) {
  // The free pass's rows: from the same starts, taken as solved where it took them so.
  const LinearisationInputs in = AtSolvedStarts(given);
  const int n = in.samples.model->num_free();
  const ModelAtTheta at(*in.samples.model, in.theta, in.samples.sessions());
  SampleRowWhitener whitener(in.samples, n + 1);
  struct Chunk {
    SampleRows rows;
  };
  const int failed = ReduceChunksInOrder<Chunk>(
      in.samples.size(), in.num_threads, [] { return Chunk(); },
      [&](int begin, int end, Chunk* chunk) {
        chunk->rows.Reset(begin, end, n + 1, in.samples.readings());
        for (int t = begin; t < end; ++t) {
          if (!EvaluateSampleRows(in.samples, t, at, t, &chunk->rows)) return t;
        }
        return -1;
      },
      [&](int, int, Chunk* chunk) { whitener.Whiten(&chunk->rows); },
      [](int, int, Chunk*) { return -1; },
      [&](const Chunk& chunk) {
        // As AccumulateFree stores them: the rows weighted by the loss's, as floats.
        const int m = chunk.rows.readings;
        RowMatrix j;
        SampleResiduals r;
        std::vector<float> jw(m * n);
        for (int t = chunk.rows.begin; t < chunk.rows.end; ++t) {
          RowsOf(chunk.rows, t, &r, &j);
          const double weight = LossWeight(in.loss, r);
          const RowMatrix weighted = weight * j;
          for (int k = 0; k < m * n; ++k) jw[k] = static_cast<float>(weighted.data()[k]);
          visit(t, jw.data());
        }
      });
  return failed < 0;
}

}  // namespace fastcal::internal
