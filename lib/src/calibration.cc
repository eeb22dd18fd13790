// The calibration problem, its identifiability analysis and covariance (calibration.h).
#include "fastcal/calibration.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>

#include "fastcal/evaluation.h"
#include "fastcal/internal/calibration_model.h"

namespace fastcal {
namespace {

using internal::CalibrationModel;

// Rows of the Jacobian folded into its R factor at a time.
constexpr int kQrChunkRows = 1024;
// Samples (evenly spaced) on which the forward model is compared with exact.
constexpr size_t kForwardErrorSamples = 2000;
// A parameter with at least this weight in a weak direction gets a note.
constexpr double kNoteWeight = 0.3;
// Weights below this are left out of a direction's description.
constexpr double kDirectionWeightFloor = 0.1;

// The largest sigma with which a parameter counts as determined (CalibrationOptions).
double MaxSigma(const ParameterSpec& p, double initial, const CalibrationOptions& o) {
  switch (p.kind) {
    case ParameterKind::kMassCentre:
      return o.max_sigma_mass_centre_m;
    case ParameterKind::kCabinMass:
      return o.max_sigma_cabin_mass_fraction * std::abs(initial);
    case ParameterKind::kLinearDensity:
      return o.max_sigma_density_fraction * std::abs(initial);
    case ParameterKind::kEa:
      return o.max_sigma_ea_fraction * std::abs(initial);
    case ParameterKind::kAnchorOffset:
      return o.max_sigma_anchor_offset_m;
    case ParameterKind::kTowerOffset:
      return o.max_sigma_tower_offset_m;
    case ParameterKind::kSensorGain:
      return o.max_sigma_sensor_gain;
    case ParameterKind::kSensorBias:
      return o.max_sigma_sensor_bias_n;
  }
  return std::numeric_limits<double>::infinity();
}

class ProgressCallback : public ceres::IterationCallback {
 public:
  explicit ProgressCallback(const std::function<void(const std::string&)>& f) : f_(f) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    char line[200];
    std::snprintf(line, sizeof(line),
                  "iter %3d  cost %.6e  decrease %+.3e  |gradient| %.3e  |step| %.3e  %s",
                  s.iteration, s.cost, s.cost_change, s.gradient_max_norm, s.step_norm,
                  s.step_is_successful ? "" : "(rejected)");
    f_(line);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::function<void(const std::string&)> f_;
};

// Upper-triangular R with R^T R = J^T J, folded from the CRS Jacobian chunk by chunk so
// a tall Jacobian never has to be dense in memory, and without squaring its condition.
Eigen::MatrixXd RFactor(const ceres::CRSMatrix& j) {
  const int n = j.num_cols;
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n, n);
  for (int start = 0; start < j.num_rows; start += kQrChunkRows) {
    const int rows = std::min(kQrChunkRows, j.num_rows - start);
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + rows, n);
    m.topRows(n) = r;
    for (int i = 0; i < rows; ++i) {
      for (int p = j.rows[start + i]; p < j.rows[start + i + 1]; ++p) {
        m(n + i, j.cols[p]) = j.values[p];
      }
    }
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(m);
    r = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  }
  return r;
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

// R factors of the whitened Jacobian at the current parameters: of all rows, and of the
// first `data_rows` rows (the data blocks are added before the priors) when not null.
bool JacobianR(ceres::Problem* problem, int num_threads, int data_rows, Eigen::MatrixXd* r_all,
               Eigen::MatrixXd* r_data) {
  ceres::Problem::EvaluateOptions eo;
  eo.num_threads = num_threads;
  ceres::CRSMatrix j;
  if (!problem->Evaluate(eo, nullptr, nullptr, nullptr, &j)) return false;
  *r_all = RFactor(j);
  if (r_data != nullptr) {
    ceres::CRSMatrix d = j;
    d.num_rows = data_rows;
    d.rows.resize(data_rows + 1);
    d.cols.resize(d.rows.back());
    d.values.resize(d.rows.back());
    *r_data = RFactor(d);
  }
  return true;
}

}  // namespace

std::string ParameterDirection::Describe() const {
  std::ostringstream s;
  for (size_t i = 0; i < weights.size(); ++i) {
    char w[32];
    std::snprintf(w, sizeof(w), "%+.2f", weights[i].second);
    s << (i ? " ~ " : "") << weights[i].first << " (" << w << ")";
  }
  return s.str();
}

CableRobot InitialCalibrationModel(const CableRobot& model, const CalibrationSpec& spec) {
  const CalibrationModel cm(model, spec);
  return cm.ToRobot(cm.InitialTheta().data());
}

ChiSquareBand ReducedChiSquareBand(const CalibrationResult& result) {
  ChiSquareBand band;
  band.degrees_of_freedom = result.num_residuals - result.num_free;
  if (band.degrees_of_freedom <= 0) return band;
  band.half_width = kChiSquareBandSigmas * std::sqrt(2.0 / band.degrees_of_freedom);
  band.within = std::isfinite(result.reduced_chi_square) &&
                std::fabs(result.reduced_chi_square - 1.0) <= band.half_width;
  return band;
}

CalibrationStatus Calibrate(const CableRobot& model, const CalibrationSpec& spec,
                            const Dataset& data, const CalibrationOptions& options,
                            CalibrationResult* result, std::string* error) {
  const auto t0 = std::chrono::steady_clock::now();
  *result = CalibrationResult();
  std::string why;
  if (!model.IsValid(&why)) {
    *error = "model: " + why;
    return CalibrationStatus::kInvalidInput;
  }
  if (!spec.IsValid(&why)) {
    *error = "spec: " + why;
    return CalibrationStatus::kInvalidInput;
  }
  for (const ParameterSpec& p : spec.parameters) {
    if (p.kind == ParameterKind::kAnchorOffset &&
        p.index >= static_cast<int>(model.anchor_points_cabin_m.size())) {
      *error = "spec: " + p.name + ": the model has only " +
               std::to_string(model.anchor_points_cabin_m.size()) + " anchor points";
      return CalibrationStatus::kInvalidInput;
    }
  }
  if (spec.use_planned_attitude && !data.has_planned_attitude) {
    *error = data.path +
             ": the spec fits with the planned attitude but the dataset has no "
             "planned_roll_deg, planned_pitch_deg, planned_yaw_deg columns";
    return CalibrationStatus::kInvalidInput;
  }
  const CalibrationModel cm(model, spec);
  const int n = cm.num_free();
  result->num_free = n;
  for (int k = 0; k < n; ++k) result->free_names.push_back(spec.parameters[cm.spec_index(k)].name);
  if (n == 0) {
    *error = "spec: no parameter is free (set free: true on what to estimate)";
    return CalibrationStatus::kInvalidInput;
  }
  if (n > internal::kMaxFreeParameters) {
    *error = "spec: " + std::to_string(n) + " free parameters; at most " +
             std::to_string(internal::kMaxFreeParameters) + " are supported";
    return CalibrationStatus::kInvalidInput;
  }

  result->held_out =
      HoldoutMask(static_cast<int>(data.samples.size()), spec.holdout_fraction, spec.holdout_seed);
  std::vector<int> fit;
  for (size_t s = 0; s < data.samples.size(); ++s) {
    if (!result->held_out[s]) fit.push_back(static_cast<int>(s));
  }
  result->num_fit_samples = static_cast<int>(fit.size());
  int num_priors = 0;
  for (int k = 0; k < n; ++k) num_priors += spec.parameters[cm.spec_index(k)].has_prior;
  result->num_residuals = kNumCables * static_cast<int>(fit.size()) + num_priors;
  if (result->num_residuals <= n) {
    *error = "only " + std::to_string(fit.size()) + " fitted samples (" +
             std::to_string(result->num_residuals) + " residuals) for " + std::to_string(n) +
             " free parameters: add data, fix parameters or lower the hold-out fraction";
    return CalibrationStatus::kInvalidInput;
  }

  std::vector<double> theta = cm.InitialTheta();
  const StaticsOptions statics = ModelFitStaticsOptions(spec.forward_model);

  // The forward model's own error against exact on the dataset poses (initial model).
  {
    StaticsParameters<double> p;
    std::array<double, kNumCables> gain, bias, t_model, t_exact;
    cm.Assemble(theta.data(), &p, &gain, &bias);
    StaticsOptions exact = statics;
    exact.method = StaticsMethod::kExact;
    double sum2 = 0.0;
    int count = 0;
    // A diagnostic: evenly spaced samples suffice on a large dataset.
    const size_t stride = std::max<size_t>(1, data.samples.size() / kForwardErrorSamples);
    for (size_t index = 0; index < data.samples.size(); index += stride) {
      const Sample& s = data.samples[index];
      Pose pose = s.pose;
      if (spec.use_planned_attitude) pose.rotation = s.planned_rotation;
      if (ModelLowerTensions(p, pose, statics, &t_model) != StaticsStatus::kOk ||
          ModelLowerTensions(p, pose, exact, &t_exact) != StaticsStatus::kOk) {
        StaticsSolution sol;
        SolveStatics(cm.ToRobot(theta.data()), pose, exact, &sol);
        *error = data.path + ":" + std::to_string(s.line) +
                 ": the initial model cannot solve this pose: " + DescribeStatus(sol);
        return CalibrationStatus::kInfeasible;
      }
      for (int i = 0; i < kNumCables; ++i) {
        const double e = std::abs(t_model[i] / t_exact[i] - 1.0);
        result->forward_model_max_rel_error = std::max(result->forward_model_max_rel_error, e);
        sum2 += e * e;
        ++count;
      }
    }
    result->forward_model_rms_rel_error = std::sqrt(sum2 / std::max(count, 1));
  }

  // The weights: sigma of each reading from its *predicted* value at given parameters.
  // Taken from the measured value, as the noise model literally reads, they correlate
  // with the noise itself (a low reading weighs more), which biased the fit: 3% noise
  // moved the density by 0.8%, 9 sigma on 3000 samples. So the fit runs twice: weights
  // from the initial model, then from the first fit (iteratively reweighted least
  // squares; a third pass changes the estimates by far less than their sigma).
  // `starts` receives each sample's statics solution at those parameters (warm starts).
  auto predicted_sigmas = [&](const std::vector<double>& at,
                              std::vector<std::array<double, kNumCables>>* sigmas,
                              std::vector<StaticsSolution>* starts) {
    StaticsParameters<double> params;
    std::array<double, kNumCables> gain, bias;
    cm.Assemble(at.data(), &params, &gain, &bias);
    sigmas->assign(fit.size(), {});
    starts->assign(fit.size(), StaticsSolution());
    for (size_t j = 0; j < fit.size(); ++j) {
      const Sample& sample = data.samples[fit[j]];
      Pose pose = sample.pose;
      if (spec.use_planned_attitude) pose.rotation = sample.planned_rotation;
      std::array<double, kNumCables> reading = sample.tension_n;  // if the model fails
      if (SolveStaticsWithParameters(params, pose, statics, &(*starts)[j]) == StaticsStatus::kOk) {
        for (int i = 0; i < kNumCables; ++i) {
          reading[i] = gain[i] * (*starts)[j].cables[i].lower_tension_n + bias[i];
        }
      }
      (*sigmas)[j] =
          internal::TensionSigmas(reading, spec.tension_sigma_n, spec.tension_sigma_percent);
    }
  };
  std::vector<std::array<double, kNumCables>> sigmas;
  std::vector<StaticsSolution> starts;
  predicted_sigmas(theta, &sigmas, &starts);

  // The least-squares problem with the given weights and warm starts (Ceres owns the
  // cost and loss objects it is given).
  auto build_problem = [&](std::vector<ceres::ResidualBlockId>* blocks) {
    ceres::Problem::Options po;
    auto problem = std::make_unique<ceres::Problem>(po);
    ceres::LossFunction* loss = nullptr;
    if (spec.robust_loss == RobustLoss::kHuber) loss = new ceres::HuberLoss(spec.robust_loss_scale);
    if (spec.robust_loss == RobustLoss::kCauchy) {
      loss = new ceres::CauchyLoss(spec.robust_loss_scale);
    }
    blocks->clear();
    for (size_t j = 0; j < fit.size(); ++j) {
      const Sample& sample = data.samples[fit[j]];
      internal::TensionResidual f;
      f.model = &cm;
      f.pose = sample.pose;
      if (spec.use_planned_attitude) f.pose.rotation = sample.planned_rotation;
      f.measured_n = sample.tension_n;
      f.sigma_n = sigmas[j];
      f.statics = statics;
      f.start = starts[j];
      blocks->push_back(
          problem->AddResidualBlock(new internal::TensionCost(f), loss, theta.data()));
    }
    if (blocks->empty()) delete loss;
    starts = std::vector<StaticsSolution>();  // copied into the residuals: free ~70 MB/1e5
    for (int k = 0; k < n; ++k) {
      const ParameterSpec& p = spec.parameters[cm.spec_index(k)];
      if (p.has_prior) {
        problem->AddResidualBlock(new internal::PriorCost(n, k, p.prior_mean_si, p.prior_sigma_si),
                                  nullptr, theta.data());
      }
    }
    return problem;
  };
  std::vector<ceres::ResidualBlockId> data_blocks;
  std::unique_ptr<ceres::Problem> problem_owner = build_problem(&data_blocks);
  if (data_blocks.empty()) {
    *error = "no samples to fit";
    return CalibrationStatus::kInvalidInput;
  }
  ceres::Problem& problem_first = *problem_owner;
  Eigen::MatrixXd r, r_data;
  const int data_rows = kNumCables * static_cast<int>(data_blocks.size());
  if (!JacobianR(&problem_first, spec.num_threads, data_rows, &r, nullptr)) {
    *error = "the initial model cannot be evaluated on every sample";
    return CalibrationStatus::kInfeasible;
  }
  result->before = Analyse(r, result->free_names, options);
  std::ostringstream refuse;
  if (!result->before.undetermined.empty()) {
    refuse << "no reading changes along these combinations of parameters (exact degeneracy):\n";
    for (const ParameterDirection& d : result->before.undetermined) {
      char ratio[32];
      std::snprintf(ratio, sizeof(ratio), "%.1e", d.singular_value_ratio);
      refuse << "  - " << d.Describe() << "   (singular value ratio " << ratio << ")\n";
    }
  } else {
    bool any = false;
    for (int k = 0; k < n; ++k) {
      const ParameterSpec& p = spec.parameters[cm.spec_index(k)];
      const double limit = MaxSigma(p, theta[k], options);
      const double sigma = result->before.sigma_si[k];
      if (sigma > limit) {
        if (!any) {
          refuse << "these would be determined only to (1 sigma, from the stated noise):\n";
          any = true;
        }
        char line[200];
        std::snprintf(line, sizeof(line),
                      "  - %s: +-%.3g %s (determined means +-%.3g %s or better)\n", p.name.c_str(),
                      sigma / p.to_si, p.unit.c_str(), limit / p.to_si, p.unit.c_str());
        refuse << line;
      }
    }
    if (any) {
      if (!result->before.poorly_determined.empty()) {
        refuse << "the weakest directions in parameter space:\n";
      }
      for (const ParameterDirection& d : result->before.poorly_determined) {
        char ratio[32];
        std::snprintf(ratio, sizeof(ratio), "%.1e", d.singular_value_ratio);
        refuse << "  - " << d.Describe() << "   (singular value ratio " << ratio << ")\n";
      }
    }
  }
  if (!refuse.str().empty()) {
    *error = std::string("the data") + (num_priors ? " and priors" : "") +
             " cannot determine the free parameters; " + refuse.str() +
             "Fix one of the parameters named (free: false), give it a prior "
             "(prior: {mean: ..., sigma: ...}), or add data that separates them (other "
             "positions, zenith angles, attitudes).";
    return CalibrationStatus::kUndetermined;
  }

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.num_threads = spec.num_threads;
  so.max_num_iterations = spec.max_iterations;
  so.function_tolerance = spec.function_tolerance;
  so.gradient_tolerance = spec.gradient_tolerance;
  so.parameter_tolerance = spec.parameter_tolerance;
  so.minimizer_progress_to_stdout = false;
  so.logging_type = ceres::SILENT;
  std::unique_ptr<ProgressCallback> callback;
  if (options.progress) {
    callback = std::make_unique<ProgressCallback>(options.progress);
    so.callbacks.push_back(callback.get());
    so.update_state_every_iteration = false;
  }
  ceres::Solver::Summary summary;
  ceres::Solve(so, problem_owner.get(), &summary);
  int iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  const double first_initial_cost = summary.initial_cost;
  const std::string first_brief = summary.BriefReport(), first_full = summary.FullReport();
  const bool two_passes = summary.IsSolutionUsable();
  if (two_passes) {
    // Second pass: weights (and warm starts) from the first fit's prediction.
    predicted_sigmas(theta, &sigmas, &starts);
    problem_owner.reset();  // one problem in memory at a time (~300 MB at 1e5 samples)
    problem_owner = build_problem(&data_blocks);
    if (options.progress) options.progress("reweighted from the first fit's prediction:");
    ceres::Solve(so, problem_owner.get(), &summary);
    iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  }
  ceres::Problem& problem = *problem_owner;
  // Both passes, each with its own weights (so their costs do not compare across passes).
  result->ceres_brief_report = two_passes
                                   ? "pass 1 (weights from the initial model): " + first_brief +
                                         "\npass 2 (weights from pass 1): " + summary.BriefReport()
                                   : summary.BriefReport();
  result->ceres_full_report = two_passes ? "Pass 1, weights from the initial model\n" + first_full +
                                               "\nPass 2, weights from pass 1's prediction\n" +
                                               summary.FullReport()
                                         : summary.FullReport();
  result->initial_cost = first_initial_cost;  // pass 1's, at the initial parameters
  result->final_cost = summary.final_cost;
  // As Ceres counts them in its BriefReport, both passes.
  result->iterations = iterations;
  result->converged = summary.termination_type == ceres::CONVERGENCE;
  result->termination = ceres::TerminationTypeToString(summary.termination_type);
  if (!summary.IsSolutionUsable()) {
    *error = "the solver failed: " + summary.message;
    return CalibrationStatus::kSolverFailed;
  }
  const int dof = result->num_residuals - n;
  result->reduced_chi_square = 2.0 * summary.final_cost / dof;

  if (JacobianR(&problem, spec.num_threads, data_rows, &r, &r_data)) {
    result->after = Analyse(r, result->free_names, options);
    result->data_only = Analyse(r_data, result->free_names, options);
  }

  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  {
    ceres::Covariance::Options co;
    co.algorithm_type = ceres::DENSE_SVD;
    co.num_threads = spec.num_threads;
    ceres::Covariance covariance(co);
    const std::vector<std::pair<const double*, const double*>> blocks = {
        {theta.data(), theta.data()}};
    if (covariance.Compute(blocks, &problem)) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> c(n, n);
      result->covariance_ok = covariance.GetCovarianceBlock(theta.data(), theta.data(), c.data());
      if (result->covariance_ok) cov = c;
    }
  }
  result->correlation = Eigen::MatrixXd::Identity(n, n);
  if (result->covariance_ok) {
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        const double d = std::sqrt(cov(a, a) * cov(b, b));
        result->correlation(a, b) = d > 0 ? cov(a, b) / d : (a == b ? 1.0 : 0.0);
        if (b > a && std::abs(result->correlation(a, b)) >= options.strong_correlation) {
          char c[32];
          std::snprintf(c, sizeof(c), "%+.3f", result->correlation(a, b));
          result->strong_correlations.push_back(result->free_names[a] + " ~ " +
                                                result->free_names[b] + ": " + c);
        }
      }
    }
  }

  // Per-parameter table (every parameter the spec names).
  std::vector<int> free_of_spec(spec.parameters.size(), -1);
  for (int k = 0; k < n; ++k) free_of_spec[cm.spec_index(k)] = k;
  const std::vector<double> initial = cm.InitialTheta();
  for (size_t j = 0; j < spec.parameters.size(); ++j) {
    const ParameterSpec& p = spec.parameters[j];
    ParameterEstimate e;
    e.name = p.name;
    e.unit = p.unit;
    e.free = p.free;
    e.has_prior = p.has_prior;
    e.prior_mean = p.prior_mean_si / p.to_si;
    e.prior_sigma = p.prior_sigma_si / p.to_si;
    const int k = free_of_spec[j];
    if (k >= 0) {
      e.initial = initial[k] / p.to_si;
      e.estimate = theta[k] / p.to_si;
      e.sigma = result->covariance_ok ? std::sqrt(std::max(cov(k, k), 0.0)) / p.to_si : 0.0;
      if (p.has_prior && result->covariance_ok &&
          e.sigma > options.prior_dominated_fraction * e.prior_sigma) {
        e.note = "set mostly by its prior";
      }
      // One short note per kind; the directions themselves are listed once in the
      // identifiability section.
      auto in_direction = [&](const std::vector<ParameterDirection>& dirs) {
        for (const ParameterDirection& d : dirs) {
          for (const auto& w : d.weights) {
            if (w.first == p.name && std::abs(w.second) >= kNoteWeight) return true;
          }
        }
        return false;
      };
      auto add = [&](const std::string& text) { e.note += (e.note.empty() ? "" : "; ") + text; };
      if (in_direction(result->data_only.undetermined)) {
        add("not determined by the data alone (held by a prior; see identifiability)");
      } else if (in_direction(result->data_only.poorly_determined)) {
        add("poorly determined by the data alone (see identifiability)");
      }
    } else {
      e.initial = e.estimate = (p.has_initial ? p.initial_si : cm.BaseValue(p)) / p.to_si;
    }
    result->parameters.push_back(e);
  }
  result->calibrated = cm.ToRobot(theta.data());
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return CalibrationStatus::kOk;
}

}  // namespace fastcal
