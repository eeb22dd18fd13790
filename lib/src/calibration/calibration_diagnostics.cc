// The calibration's linearisation at its solution, uncertainty budget, sensor-step test,
// change scan and diagnostics (misfit ranking, block cross-validation, worst readings):
// stages over one run's state (calibration_run.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <sstream>

#include "calibration/calibration_run.h"
#include "fastcal/change_scan.h"
#include "fastcal/internal/identifiability.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/parameter_plausibility.h"
#include "fastcal/sensor_steps.h"
#include "fastcal/sessions.h"
#include "fastcal/uncertainty.h"

namespace fastcal::internal {
namespace {

// ---------------------------------------------------------------------------------------
// Stage: the uncertainty budget, from the problem linearised at the solution.

// The fixed parameters the model has, as the score test's candidates: every parameter a
// spec can name (AllModelParameters) but the free ones; a consider parameter keeps its
// prior and value (*value_si: the value it is held at).
std::vector<ParameterSpec> Candidates(const Run& run, std::vector<double>* value_si) {
  std::vector<ParameterSpec> out;
  value_si->clear();
  for (ParameterSpec c : AllModelParameters(run.model)) {
    // Without lengths in the fit an encoder's offset moves no reading.
    if (c.kind == ParameterKind::kLengthOffset && !run.spec.UsesLengths()) continue;
    bool free = false;
    for (const ParameterSpec& p : run.spec.parameters) {
      if (!SameParameter(p, c)) continue;
      free = p.free;
      c.has_prior = p.has_prior;
      c.prior_mean_si = p.prior_mean_si;
      c.prior_sigma_si = p.prior_sigma_si;
      c.has_initial = p.has_initial;
      c.initial_si = p.initial_si;
    }
    if (free) continue;
    value_si->push_back(c.has_initial ? c.initial_si : run.cm->BaseValue(c));
    out.push_back(c);
  }
  return out;
}

// Sum of the prior residuals squared at theta.
double PriorChiSquare(const Run& run) {
  double chi = 0.0;
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (!p.has_prior) continue;
    const double z = (run.theta[k] - p.prior_mean_si) / p.prior_sigma_si;
    chi += z * z;
  }
  return chi;
}

// The linearisation's inputs at the current solution (without candidates). The per-sample
// Jacobians are kept only for the change scan (calibration_linearisation.h).
internal::LinearisationInputs LinearisationInputsOf(const Run& run) {
  internal::LinearisationInputs in;
  in.samples = run.Samples();
  in.theta = run.theta.data();
  in.loss = run.loss.get();
  in.cross_validation_blocks = run.spec.cross_validation_blocks;
  in.num_threads = run.spec.num_threads;
  in.max_candidate_samples = run.options.max_candidate_samples;
  in.keep_jacobians = !run.spec.change_scan_groups.empty();
  return in;
}

// The budget's inputs. The linearisation's per-sample scores and Jacobians are moved
// in, not copied (~130 MB at 10^6 samples): ReturnSeries gives them back. Without kept
// Jacobians, the budget has them replayed from the linearisation's inputs.
BudgetInputs MakeBudgetInputs(const Run& run, internal::Linearisation& lin,
                              const std::vector<ParameterSpec>& candidates) {
  BudgetInputs in;
  in.num_threads = internal::MachineThreads(run.spec.num_threads);
  in.prior_information = Eigen::VectorXd::Zero(run.n);
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (p.has_prior) in.prior_information[k] = 1.0 / (p.prior_sigma_si * p.prior_sigma_si);
  }
  in.information = lin.information;
  if (run.loss != nullptr) {
    // The exact Hessian of the robust cost, when it stays positive definite (a
    // redescending loss can make it indefinite: then Gauss-Newton's, as the fit used).
    const Eigen::MatrixXd exact = lin.information + lin.loss_curvature;
    const Eigen::LLT<Eigen::MatrixXd> llt(exact +
                                          Eigen::MatrixXd(in.prior_information.asDiagonal()));
    if (llt.info() == Eigen::Success) in.information = exact;
  }
  in.information.diagonal() += in.prior_information;
  in.scores = std::move(lin.scores);
  in.jacobians = std::move(lin.jacobians);
  if (in.jacobians.rows() == 0) {
    in.jacobian_replay = [&run](const std::function<void(int, const float*)>& visit) {
      return internal::ReplayFreeJacobians(LinearisationInputsOf(run), visit);
    };
  }
  in.rows_per_sample = run.Readings();
  in.num_residuals = run.result->num_residuals;
  in.chi_square = lin.raw_chi_square + PriorChiSquare(run);
  in.robust_loss = run.loss != nullptr;
  in.misfit_threshold = 1.0 + ReducedChiSquareBand(*run.result).half_width;
  std::vector<int> consider;
  for (size_t j = 0; j < candidates.size(); ++j) {
    if (candidates[j].has_prior) consider.push_back(static_cast<int>(j));
  }
  in.consider_cross.resize(run.n, static_cast<int>(consider.size()));
  in.consider_sigma.resize(static_cast<int>(consider.size()));
  for (size_t c = 0; c < consider.size(); ++c) {
    const ParameterSpec& p = candidates[consider[c]];
    in.consider_cross.col(static_cast<int>(c)) = lin.cross.col(consider[c]);
    in.consider_sigma[static_cast<int>(c)] = p.prior_sigma_si;
    const std::string group = ParameterGroupName(p.kind);
    const auto it = std::find(in.consider_groups.begin(), in.consider_groups.end(), group);
    in.consider_group.push_back(static_cast<int>(it - in.consider_groups.begin()));
    if (it == in.consider_groups.end()) in.consider_groups.push_back(group);
  }
  return in;
}

void FillCorrelation(Run& run) {
  CalibrationResult& r = *run.result;
  const int n = run.n;
  const Eigen::MatrixXd& cov = r.budget.total;
  r.correlation = Eigen::MatrixXd::Identity(n, n);
  if (!r.covariance_ok) return;
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      const double d = std::sqrt(cov(a, a) * cov(b, b));
      r.correlation(a, b) = d > 0 ? cov(a, b) / d : (a == b ? 1.0 : 0.0);
      if (b > a && std::abs(r.correlation(a, b)) >= run.options.strong_correlation) {
        r.strong_correlations.push_back(r.free_names[a] + " ~ " + r.free_names[b] + ": " +
                                        Fixed("%+.3f", r.correlation(a, b)));
      }
    }
  }
}

CalibrationStatus Linearise(Run& run, const std::vector<ParameterSpec>& candidates,
                            internal::Linearisation* lin) {
  internal::LinearisationInputs in = LinearisationInputsOf(run);
  in.candidates = candidates;
  std::string why;
  if (!internal::Linearise(in, lin, &why)) return run.Fail(CalibrationStatus::kSolverFailed, why);
  return CalibrationStatus::kOk;
}

// The identifiability at the solution, from the linearisation's R factor: of the data
// alone, and with the priors' rows folded in.
void AnalyseAtSolution(Run& run, const internal::Linearisation& lin) {
  CalibrationResult& r = *run.result;
  Eigen::MatrixXd priors = Eigen::MatrixXd::Zero(run.n, run.n);
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (p.has_prior) priors(k, k) = 1.0 / p.prior_sigma_si;
  }
  r.data_only = Analyse(lin.r_factor, r.free_names, run.options);
  r.after = Analyse(internal::FoldRows(lin.r_factor, priors), r.free_names, run.options);
}

// ---------------------------------------------------------------------------------------
// Stage: diagnostics: what would explain the misfit, block cross-validation, the
// residuals' memory, the worst readings.

// Each candidate's score statistic against the residuals' own noise: the long-run
// variance (overlapping batch means at the budget's bandwidth, in the candidate pass's
// sample spacing) of its score projected off the free parameters,
// g~_t = J_c,t^T r_t - (M^-1 J_x^T J_c)^T s_t. White, well-fitting residuals give
// g^2 / A; correlated or misfitting ones a proportionally larger variance.
Eigen::VectorXd ScoreStatistics(const Run& run, const internal::Linearisation& lin,
                                const Eigen::MatrixXd& information) {
  const int rows = static_cast<int>(lin.candidate_rows.size());
  const int q = static_cast<int>(lin.cross.cols());
  Eigen::VectorXd statistic = Eigen::VectorXd::Zero(q);
  if (rows == 0) return statistic;
  const Eigen::MatrixXd projection = information.ldlt().solve(lin.cross) / lin.candidate_scale;
  Eigen::MatrixXd projected = lin.candidate_scores;
  for (int k = 0; k < rows; ++k) {
    projected.row(k) -= lin.candidate_free_scores.row(k) * projection;
  }
  const UncertaintyBudget& b = run.result->budget;
  const double stride = static_cast<double>(run.fit.size()) / rows;
  const int bandwidth =
      b.correlated ? std::max(1, static_cast<int>(std::lround(b.bandwidth / stride))) : 1;
  const Eigen::VectorXd sum = projected.colwise().sum().transpose();
  const Eigen::RowVectorXd mean = projected.colwise().mean();
  projected.rowwise() -= mean;  // the signal's constant part is not noise
  for (int j = 0; j < q; ++j) {
    const double variance = LongRunCovarianceOfSum(projected.col(j), bandwidth)(0, 0);
    statistic[j] = variance > 0.0 ? sum[j] * sum[j] / variance : 0.0;
  }
  return statistic;
}

// The free parameters' priors as candidates of the misfit ranking ("prior of NAME"): what
// releasing prior k (the others kept) would do. At the solution the data's gradient is
// -Lambda_k d e_k (d = estimate - prior mean), so one Newton step without the prior moves
// the estimates by (M - Lambda_k e_k e_k^T)^-1 Lambda_k d e_k. Its statistic is the
// prior's normalised residual, d^2 / (sigma_k^2 - P_kk) (the data's share of the
// disagreement's variance, P = M^-1), against the noise the residuals have (divided by
// the parameter's widening squared); its expected decrease that of the data's
// chi-square, d^2 P_kk / (sigma_k^2 (sigma_k^2 - P_kk)). A prior the data barely inform
// (P_kk > 99% of sigma_k^2) cannot disagree with them and is left out, as is one the
// data cannot do without (M singular without it).
void RankPriors(const Run& run, const Eigen::MatrixXd& information,
                std::vector<MisfitCandidate>* ranking) {
  constexpr double kMinDataShare = 0.01;
  if (run.loss != nullptr) return;  // M^-1 is then not the covariance (a sandwich)
  const Eigen::MatrixXd covariance =
      information.ldlt().solve(Eigen::MatrixXd::Identity(run.n, run.n));
  const UncertaintyBudget& b = run.result->budget;
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (!p.has_prior) continue;
    const double prior_var = p.prior_sigma_si * p.prior_sigma_si;
    const double data_var = prior_var - covariance(k, k);
    if (!(data_var > kMinDataShare * prior_var)) continue;
    Eigen::MatrixXd without = information;
    without(k, k) -= 1.0 / prior_var;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(without);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) continue;
    const double d = run.theta[k] - p.prior_mean_si;
    Eigen::VectorXd unit = Eigen::VectorXd::Zero(run.n);
    unit[k] = d / prior_var;
    const Eigen::VectorXd shift = ldlt.solve(unit);
    if (!shift.allFinite()) continue;
    // The data's share of d is widened like a data-only estimate would be: by the misfit
    // factor and the autocorrelation time of the parameter's influence series. (Its
    // posterior widening is diluted by the prior, which is not widened.)
    double widening2 = 1.0;
    if (k < static_cast<int>(b.parameters.size())) {
      const ParameterBudget& pb = b.parameters[k];
      widening2 = std::max({1.0, pb.widening * pb.widening,
                            b.misfit_factor * b.misfit_factor * std::max(1.0, pb.tau)});
    }
    MisfitCandidate m;
    m.name = "prior of " + p.name;
    m.unit = p.unit;
    m.expected_decrease = d * d * covariance(k, k) / (prior_var * data_var);
    m.statistic = d * d / data_var / widening2;
    m.change = shift[k] / p.to_si;
    for (int j = 0; j < run.n; ++j) m.shifts.push_back(shift[j] / run.Free(j).to_si);
    ranking->push_back(std::move(m));
  }
}

void RankMisfit(Run& run, const internal::Linearisation& lin,
                const std::vector<ParameterSpec>& candidates, const std::vector<double>& value_si,
                const Eigen::MatrixXd& information) {
  Eigen::VectorXd self = lin.self, gradient = lin.gradient;
  for (size_t j = 0; j < candidates.size(); ++j) {
    const ParameterSpec& c = candidates[j];
    if (!c.has_prior) continue;  // freed with its prior: its residual joins the fit
    const double w = 1.0 / (c.prior_sigma_si * c.prior_sigma_si);
    self[j] += w;
    gradient[j] += (value_si[j] - c.prior_mean_si) * w;
  }
  // Everything from the candidate pass's samples, so that the Schur complement's two
  // terms (a small difference for a candidate near the free parameters' span) come from
  // the same samples: its own J_x^T J_x (with the priors), and the candidates' gradient
  // projected off the free parameters' gradient over those samples, which is not 0 as
  // it is over all of them.
  Eigen::MatrixXd same_samples = lin.candidate_information;
  same_samples.diagonal() += information.diagonal() - lin.information.diagonal();
  Eigen::VectorXd free_gradient = Eigen::VectorXd::Zero(run.n);
  for (int k = 0; k < static_cast<int>(lin.candidate_rows.size()); ++k) {
    free_gradient += lin.candidate_free_scores.row(k).transpose();
  }
  free_gradient *= lin.candidate_scale;
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (p.has_prior) {
      free_gradient[k] += (run.theta[k] - p.prior_mean_si) / (p.prior_sigma_si * p.prior_sigma_si);
    }
  }
  gradient -= lin.cross.transpose() * same_samples.ldlt().solve(free_gradient);
  const Eigen::VectorXd decrease = ScoreTestDecrease(same_samples, lin.cross, self, gradient);
  const Eigen::VectorXd statistic = ScoreStatistics(run, lin, same_samples);
  const Eigen::MatrixXd inverse =
      information.ldlt().solve(Eigen::MatrixXd::Identity(information.rows(), information.cols()));
  CalibrationResult& r = *run.result;
  std::vector<MisfitCandidate>& ranking = r.misfit_ranking;
  for (size_t j = 0; j < candidates.size(); ++j) {
    if (!std::isfinite(decrease[j])) continue;
    const ParameterSpec& c = candidates[j];
    MisfitCandidate m;
    m.name = c.name;
    m.unit = c.unit;
    m.expected_decrease = decrease[j];
    m.statistic = statistic[j];
    // Freeing it, one Gauss-Newton step: dc = -g / A, d(theta) = M^-1 J_x^T J_c g / A,
    // with A = g^2 / decrease.
    const double a = gradient[j] * gradient[j] / decrease[j];
    const double step = a > 0.0 ? gradient[j] / a : 0.0;
    m.change = -step / c.to_si;
    m.beyond_linear_range =
        !CheckParameterValue(c.kind, value_si[j] - step, PlausibilityLimits(), nullptr);
    const Eigen::VectorXd shift = inverse * lin.cross.col(static_cast<int>(j)) * step;
    for (int k = 0; k < run.n; ++k) m.shifts.push_back(shift[k] / run.Free(k).to_si);
    ranking.push_back(std::move(m));
  }
  RankPriors(run, information, &ranking);
  std::stable_sort(ranking.begin(), ranking.end(), [](const auto& a, const auto& b) {
    return a.expected_decrease > b.expected_decrease;
  });
  r.misfit_threshold = ChiSquare1Quantile(kMisfitFamilyError / std::max<size_t>(1, ranking.size()));
  for (MisfitCandidate& c : ranking) c.significant = c.statistic > r.misfit_threshold;
}

// Each block predicted by the fit without it: theta + (M - M_k)^-1 J_k^T r_k, one
// Gauss-Newton step, exact for a linear model.
void CrossValidate(Run& run, const internal::Linearisation& lin,
                   const Eigen::MatrixXd& information) {
  CrossValidation& cv = run.result->cross_validation;
  cv.blocks = static_cast<int>(lin.folds.size());
  std::array<double, kNumCables> sse_cv{}, sse_fit{};
  std::array<int, kNumCables> readings{};
  for (const internal::FoldSums& f : lin.folds) {
    if (f.samples == 0) continue;
    const Eigen::LDLT<Eigen::MatrixXd> rest(information - f.information);
    if (rest.info() != Eigen::Success || !rest.isPositive()) continue;
    const Eigen::VectorXd step = rest.solve(f.gradient);
    if (!step.allFinite()) continue;
    ++cv.folds_used;
    for (int i = 0; i < kNumCables; ++i) {
      sse_cv[i] += f.sse_n2[i] + 2.0 * f.cross_n2[i].dot(step) + step.dot(f.normal_n2[i] * step);
      sse_fit[i] += f.sse_n2[i];
      readings[i] += f.readings[i];
    }
  }
  for (int i = 0; i < kNumCables; ++i) {
    if (readings[i] == 0) continue;
    cv.rms_n[i] = std::sqrt(std::max(sse_cv[i], 0.0) / readings[i]);
    cv.fit_rms_n[i] = std::sqrt(sse_fit[i] / readings[i]);
  }
}

}  // namespace

// The fitted readings farthest from the model in stated sigmas (options.worst_readings),
// through a bounded heap: memory independent of the number of samples. Ties go to the
// earlier reading. The last use of the prediction's weights and whitened residuals: they
// are freed (~100 MB at 10^6 samples) before the linearisation's per-sample arrays.
CalibrationStatus FindWorstReadings(Run& run) {
  struct Entry {
    double size;
    int t, i;
  };
  const auto worse = [](const Entry& a, const Entry& b) {
    if (a.size != b.size) return a.size > b.size;
    return a.t != b.t ? a.t < b.t : a.i < b.i;
  };
  const size_t keep = static_cast<size_t>(std::max(0, run.options.worst_readings));
  std::vector<Entry> heap;  // the best of the worst on top (a heap under `worse`)
  for (int t : run.fit) {
    for (int i = 0; i < run.Readings() && keep > 0; ++i) {
      if (ReadingExcluded(run, t, i)) continue;
      const Entry e{std::abs(ReadingWhitened(run, t, i)), t, i};
      if (heap.size() < keep) {
        heap.push_back(e);
        std::push_heap(heap.begin(), heap.end(), worse);
      } else if (worse(e, heap.front())) {
        std::pop_heap(heap.begin(), heap.end(), worse);
        heap.back() = e;
        std::push_heap(heap.begin(), heap.end(), worse);
      }
    }
  }
  std::sort(heap.begin(), heap.end(), worse);
  std::vector<ReadingResidual>& worst = run.result->worst_readings;
  worst.clear();
  for (const Entry& e : heap) worst.push_back(ReadingAt(run, e.t, e.i));
  run.at.whitened = std::vector<std::array<double, kNumCables>>();
  run.at.sigma_n = std::vector<std::array<double, kNumCables>>();
  run.at.length_whitened = std::vector<std::array<double, kNumCables>>();
  return CalibrationStatus::kOk;
}

namespace {}  // namespace

// Stage: the problem linearised at the solution (one pass for the free parameters, one
// for the candidates).
CalibrationStatus LineariseAtSolution(Run& run) {
  run.problem.reset();
  run.folded = nullptr;  // the problem owned it
  run.candidates = Candidates(run, &run.candidate_value_si);
  return Linearise(run, run.candidates, &run.lin);
}

namespace {}  // namespace

// Stage: identifiability at the solution, the least-squares chi-square, the budget.
CalibrationStatus EstimateUncertainty(Run& run) {
  CalibrationResult& r = *run.result;
  AnalyseAtSolution(run, run.lin);
  // The least-squares chi-square of the kept readings (with a robust loss, twice the
  // robust cost would be another number).
  r.reduced_chi_square =
      (run.lin.raw_chi_square + PriorChiSquare(run)) / std::max(1, r.num_residuals - run.n);
  BudgetInputs inputs = MakeBudgetInputs(run, run.lin, run.candidates);
  run.information = inputs.information;
  r.covariance_ok = ComputeUncertaintyBudget(inputs, &r.budget);
  run.lin.scores = std::move(inputs.scores);
  run.lin.jacobians = std::move(inputs.jacobians);
  FillCorrelation(run);
  return CalibrationStatus::kOk;
}

namespace {}  // namespace

// Stage: sensors re-zeroed between sessions (sensor_steps.h), from the linearisation's
// per-session sums.
CalibrationStatus TestSensorStepsStage(Run& run) {
  if (!run.result->covariance_ok) return CalibrationStatus::kOk;
  std::vector<ParameterSpec> free;
  for (int k = 0; k < run.n; ++k) free.push_back(run.Free(k));
  SensorStepInputs in;
  in.free = &free;
  in.information = &run.information;
  in.session_information = &run.lin.session_information;
  in.session_gradient = &run.lin.session_gradient;
  in.labels = &run.data.session_labels;
  in.widening = run.result->budget.misfit_factor;
  run.result->sensor_steps = TestSensorSteps(in);
  return CalibrationStatus::kOk;
}

// Stage: the scan for a step of the spec's change_scan groups within the survey
// (change_scan.h), on the linearisation and with the budget's widening.
CalibrationStatus ScanChanges(Run& run) {
  CalibrationResult& r = *run.result;
  ChangeScanResult& scan = r.change_scan;
  if (run.spec.change_scan_groups.empty()) return CalibrationStatus::kOk;
  scan.enabled = true;
  scan.groups = run.spec.change_scan_groups;
  scan.significance = run.spec.change_scan_significance;
  scan.min_segment = run.spec.change_scan_min_segment;
  scan.replicates = run.options.change_scan_replicates;
  ChangeScanInputs in;
  in.residuals = &run.lin.residuals;
  in.jacobians = &run.lin.jacobians;
  in.rows_per_sample = run.Readings();
  in.num_free = run.n;
  in.prior_information = Eigen::VectorXd::Zero(run.n);
  in.prior_gradient = Eigen::VectorXd::Zero(run.n);
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    const std::string group = ParameterGroupName(p.kind);
    if (std::count(scan.groups.begin(), scan.groups.end(), group) != 0 ||
        std::count(scan.groups.begin(), scan.groups.end(), p.name) != 0) {
      if (p.session >= 0) {
        return run.Fail(CalibrationStatus::kInvalidInput,
                        "spec: change_scan and sessions.separate both name " + group +
                            ": scan each session on its own, or scan another group");
      }
      in.scanned.push_back(k);
      scan.parameters.push_back(p.name);
      scan.units.push_back(p.unit);
    }
    if (!p.has_prior) continue;
    in.prior_information[k] = 1.0 / (p.prior_sigma_si * p.prior_sigma_si);
    in.prior_gradient[k] = (run.theta[k] - p.prior_mean_si) * in.prior_information[k];
  }
  in.bandwidth = r.covariance_ok && r.budget.correlated ? r.budget.bandwidth : 1;
  in.min_segment = run.spec.change_scan_min_segment;
  in.significance = run.spec.change_scan_significance;
  in.max_changes = run.spec.change_scan_max_changes;
  in.replicates = run.options.change_scan_replicates;
  in.seed = run.options.change_scan_seed;
  ChangeScanOutput out;
  std::string why;
  if (!ScanForChanges(in, &out, &why)) return run.Fail(CalibrationStatus::kSolverFailed, why);
  scan.threshold = out.threshold;
  scan.widening = out.widening;
  for (size_t j = 1; j < run.fit.size(); ++j) {
    const Sample& now = run.data.samples[run.fit[j]];
    if (now.time_s >= run.data.samples[run.fit[j - 1]].time_s) continue;
    r.notes.push_back(
        "the change scan takes the rows in file order as time order, but time_s "
        "decreases at " +
        SampleWhere(run.data, now) +
        ": sort the export by time for the scan's times to mean anything");
    break;
  }
  scan.unit_samples = out.unit_samples;
  scan.time_display = TimeDisplayOf(run.data);
  for (size_t k = 0; k < out.splits.size(); ++k) {
    scan.time_s.push_back(run.data.samples[run.fit[out.splits[k]]].time_s);
    scan.statistic.push_back(out.statistic[k]);
  }
  for (const DetectedChange& c : out.changes) {
    FoundChange f;
    f.sample = run.fit[c.split];
    f.time_s = run.data.samples[f.sample].time_s;
    f.line = run.data.samples[f.sample].line;
    f.statistic = c.statistic;
    f.p_value = c.p_value;
    for (size_t j = 0; j < in.scanned.size(); ++j) {
      const double to_si = run.Free(in.scanned[j]).to_si;
      f.shift.push_back(c.shift[j] / to_si);
      f.shift_sigma.push_back(c.shift_sigma[j] / to_si);
    }
    scan.changes.push_back(std::move(f));
  }
  scan.trend_statistic = out.trend_statistic;
  scan.trend_p_value = out.trend_p_value;
  scan.best_step_statistic = out.best_step_statistic;
  for (int j = 0; j < out.trend_shift.size(); ++j) {
    const double to_si = run.Free(in.scanned[j]).to_si;
    scan.trend_shift.push_back(out.trend_shift[j] / to_si);
    scan.trend_shift_sigma.push_back(out.trend_shift_sigma[j] / to_si);
  }
  SetChangeTimeAndWandering(static_cast<int>(in.scanned.size()), &scan);
  return CalibrationStatus::kOk;
}

namespace {}  // namespace

// Stage: what would explain the misfit, block cross-validation, the residuals' memory,
// the worst readings.
CalibrationStatus Diagnose(Run& run) {
  CalibrationResult& r = *run.result;
  RankMisfit(run, run.lin, run.candidates, run.candidate_value_si, run.information);
  CrossValidate(run, run.lin, run.information);
  for (int i = 0; i < kNumCables; ++i) {
    r.residual_tau[i] = IntegratedAutocorrelationTime(run.lin.residuals.col(i)).tau;
  }
  // The linearisation's per-sample series and the last pass's weights are not needed
  // beyond here: ~300 MB at 10^6 samples, freed before the RMS table's predictions.
  run.lin = internal::Linearisation();
  run.sigma_n = std::vector<std::array<double, kNumCables>>();
  run.slow_rho = std::vector<std::array<double, kNumCables>>();
  return CalibrationStatus::kOk;
}

namespace {}  // namespace
}  // namespace fastcal::internal
