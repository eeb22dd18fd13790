// The calibration pipeline (calibration.h): each stage is a function over one run's state
// (Run), called in order by Calibrate. The least-squares problem and its identifiability
// are here; the linearisation at the solution is calibration_linearisation.cc, the budget
// and the score test uncertainty.cc, the gross-error screen gross_errors.cc.
#include "fastcal/calibration.h"

#include <ceres/ceres.h>
#include <sys/resource.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "fastcal/gross_errors.h"
#include "fastcal/internal/calibration_evaluation.h"
#include "fastcal/internal/calibration_linearisation.h"
#include "fastcal/internal/calibration_slow_error.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/folded_cost.h"
#include "fastcal/internal/identifiability.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/model_plausibility.h"

namespace fastcal {
namespace {

using internal::Analyse;
using internal::CalibrationModel;
using internal::JacobianR;
using internal::MaxSigma;

// Samples (evenly spaced) on which the forward model is compared with exact.
constexpr size_t kForwardErrorSamples = 2000;
// A parameter with at least this weight in a weak direction gets a note.
constexpr double kNoteWeight = 0.3;
constexpr double kNPerKn = 1e3;
// Relative cost decrease at which pass 1 (weights from the initial model) stops; 10^-4
// of the cost saves a Jacobian and a cost evaluation of every sample (2 s at 10^6
// samples) and leaves pass 2 a start well inside its first step.
constexpr double kFirstPassFunctionTolerance = 1e-4;
// Chance that noise alone makes some candidate of the misfit ranking "significant".
constexpr double kMisfitFamilyError = 0.01;

// The process's CPU time so far (s, user and system, all threads) and peak resident
// memory (MB); 0 where getrusage does not say.
struct Usage {
  double cpu_s = 0.0, peak_mb = 0.0;
};
Usage ProcessUsage() {
  rusage usage;
  if (getrusage(RUSAGE_SELF, &usage) != 0) return {};
  const auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  return {seconds(usage.ru_utime) + seconds(usage.ru_stime), usage.ru_maxrss / 1024.0};
}

// x with P(chi-square(1 dof) > x) = tail: the square of the two-sided normal quantile.
double ChiSquare1Quantile(double tail) {
  const double z = TwoSidedNormalQuantile(tail);
  return z * z;
}

// ---------------------------------------------------------------------------------------
// The state of one calibration, passed from stage to stage.

// The model's readings at some parameters, for every dataset sample.
struct Prediction {
  std::vector<std::array<double, kNumCables>> reading_n;  // gain T + bias
  std::vector<std::array<double, kNumCables>> sigma_n;    // whitening sigma from the reading
  std::vector<std::array<double, kNumCables>> whitened;   // (reading - measured) / sigma
  internal::CompactStarts starts;                          // the statics there (warm starts)
};

struct Run {
  Run(const CableRobot& m, const CalibrationSpec& s, const Dataset& d, const CalibrationOptions& o,
      CalibrationResult* r, std::string* e)
      : model(m), spec(s), data(d), options(o), result(r), error(e) {}

  const CableRobot& model;
  const CalibrationSpec& spec;
  const Dataset& data;
  const CalibrationOptions& options;
  CalibrationResult* result;
  std::string* error;

  std::unique_ptr<CalibrationModel> cm;
  int n = 0;                  // free parameters
  int num_priors = 0;         // of the free parameters
  std::vector<int> fit;       // fitted samples (dataset indices, file order)
  std::vector<bool> is_fit;   // per dataset sample
  std::vector<double> theta;  // free parameters, SI
  StaticsOptions statics;
  std::unique_ptr<ceres::LossFunction> loss;  // a copy for the diagnostics (or null)
  Prediction at;                              // at the current theta
  // The weights and exclusions of the current problem, per fitted sample / dataset sample.
  std::vector<std::array<double, kNumCables>> sigma_n;
  ReadingMask excluded;
  // The slow sensor error the current problem whitens by (inactive: white noise only),
  // and per fitted sample each reading's sigma_slow / sigma_white (sample_rows.h).
  SlowErrorProcess slow;
  std::vector<std::array<double, kNumCables>> slow_rho;
  std::unique_ptr<ceres::Problem> problem;
  // At the solution: the candidates of the misfit ranking (and consider parameters),
  // the linearisation, and the normal matrix with the priors.
  std::vector<ParameterSpec> candidates;
  std::vector<double> candidate_value_si;
  internal::Linearisation lin;
  Eigen::MatrixXd information;

  Pose PoseOf(const Sample& s) const {
    Pose pose = s.pose;
    if (spec.use_planned_attitude) pose.rotation = s.planned_rotation;
    return pose;
  }
  const ParameterSpec& Free(int k) const { return spec.parameters[cm->spec_index(k)]; }
  // The current prediction, the fitted samples and their exclusions.
  internal::PredictionView View() const {
    internal::PredictionView v;
    v.data = &data;
    v.reading_n = &at.reading_n;
    v.sigma_n = &at.sigma_n;
    v.fit = &fit;
    v.excluded = &excluded;
    return v;
  }
  // The fitted samples with the current weights, warm starts and exclusions.
  internal::FittedSamples Samples() const {
    internal::FittedSamples s;
    s.model = cm.get();
    s.data = &data;
    s.fit = &fit;
    s.sigma_n = &sigma_n;
    s.starts = &at.starts;
    s.excluded = &excluded;
    s.use_planned_attitude = spec.use_planned_attitude;
    s.statics = statics;
    s.slow_error = slow;
    s.slow_rho = &slow_rho;
    return s;
  }
  CalibrationStatus Fail(CalibrationStatus status, const std::string& why) const {
    *error = why;
    return status;
  }
};

class ProgressCallback : public ceres::IterationCallback {
 public:
  explicit ProgressCallback(const std::function<void(const std::string&)>& f) : f_(f) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    using internal::FormatDouble;
    std::string iteration = std::to_string(s.iteration);
    iteration.insert(0, iteration.size() < 3 ? 3 - iteration.size() : 0, ' ');
    f_("iter " + iteration + "  cost " + FormatDouble("%.6e", s.cost) + "  decrease " +
       FormatDouble("%+.3e", s.cost_change) + "  |gradient| " +
       FormatDouble("%.3e", s.gradient_max_norm) + "  |step| " + FormatDouble("%.3e", s.step_norm) +
       "  " + (s.step_is_successful ? "" : "(rejected)"));
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::function<void(const std::string&)> f_;
};

std::string Fixed(const char* format, double v) { return internal::FormatDouble(format, v); }

std::string RatioText(double ratio) { return internal::FormatDouble("%.1e", ratio); }

// " kg/m" after a value; nothing for a dimensionless one ("+-0.0879", not "+-0.0879 1").
std::string UnitAfter(const std::string& unit) { return unit == "1" ? "" : " " + unit; }

std::unique_ptr<ceres::LossFunction> MakeLoss(const CalibrationSpec& spec) {
  if (spec.robust_loss == RobustLoss::kHuber) {
    return std::make_unique<ceres::HuberLoss>(spec.robust_loss_scale);
  }
  if (spec.robust_loss == RobustLoss::kCauchy) {
    return std::make_unique<ceres::CauchyLoss>(spec.robust_loss_scale);
  }
  return nullptr;
}

int CountExcluded(const Run& run) {
  int count = 0;
  if (run.excluded.empty()) return 0;
  for (int t : run.fit) {
    for (bool e : run.excluded[t]) count += e;
  }
  return count;
}

// ---------------------------------------------------------------------------------------
// Stage: validate the inputs and choose the fitted samples.

CalibrationStatus ValidateInputs(Run& run) {
  std::string why;
  if (!run.model.IsValid(&why)) return run.Fail(CalibrationStatus::kInvalidInput, "model: " + why);
  if (!run.spec.IsValid(&why)) return run.Fail(CalibrationStatus::kInvalidInput, "spec: " + why);
  for (const ParameterSpec& p : run.spec.parameters) {
    if (!ParameterFitsModel(p, run.model, &why)) {
      return run.Fail(CalibrationStatus::kInvalidInput, "spec: " + why);
    }
  }
  if (run.model.HasAttachments() && run.spec.forward_model != StaticsMethod::kExact) {
    return run.Fail(CalibrationStatus::kInvalidInput,
                    std::string("spec: forward_model: ") +
                        StaticsMethodName(run.spec.forward_model) +
                        " models uniform cables, but the model's cables carry attachments; "
                        "use forward_model: exact");
  }
  if (run.spec.use_planned_attitude && !run.data.has_planned_attitude) {
    return run.Fail(CalibrationStatus::kInvalidInput,
                    run.data.path +
                        ": the spec fits with the planned attitude but the dataset has no "
                        "planned_roll_deg, planned_pitch_deg, planned_yaw_deg columns");
  }
  run.cm = std::make_unique<CalibrationModel>(run.model, run.spec);
  run.n = run.cm->num_free();
  CalibrationResult& r = *run.result;
  r.num_free = run.n;
  for (int k = 0; k < run.n; ++k) r.free_names.push_back(run.Free(k).name);
  if (run.n == 0) {
    return run.Fail(CalibrationStatus::kInvalidInput,
                    "spec: no parameter is free (set free: true on what to estimate)");
  }
  if (run.n > internal::kMaxFreeParameters) {
    return run.Fail(CalibrationStatus::kInvalidInput,
                    "spec: " + std::to_string(run.n) + " free parameters; at most " +
                        std::to_string(internal::kMaxFreeParameters) + " are supported");
  }
  const int num_samples = static_cast<int>(run.data.samples.size());
  r.held_out = HoldoutMask(num_samples, run.spec.holdout_fraction, run.spec.holdout_seed,
                           run.spec.holdout_blocks);
  run.is_fit.assign(num_samples, false);
  for (int s = 0; s < num_samples; ++s) {
    if (r.held_out[s]) continue;
    run.fit.push_back(s);
    run.is_fit[s] = true;
  }
  r.num_fit_samples = static_cast<int>(run.fit.size());
  for (int k = 0; k < run.n; ++k) run.num_priors += run.Free(k).has_prior;
  r.num_residuals = kNumCables * r.num_fit_samples + run.num_priors;
  if (run.fit.empty()) return run.Fail(CalibrationStatus::kInvalidInput, "no samples to fit");
  if (r.num_residuals <= run.n) {
    return run.Fail(CalibrationStatus::kInvalidInput,
                    "only " + std::to_string(run.fit.size()) + " fitted samples (" +
                        std::to_string(r.num_residuals) + " residuals) for " +
                        std::to_string(run.n) +
                        " free parameters: add data, fix parameters or lower the hold-out "
                        "fraction");
  }
  run.theta = run.cm->InitialTheta();
  run.statics = ModelFitStaticsOptions(run.spec.forward_model);
  run.slow = run.spec.slow_error.Initial();
  r.slow_error.enabled = run.spec.slow_error.enabled;
  r.slow_error.process = run.slow;
  run.loss = MakeLoss(run.spec);
  return CalibrationStatus::kOk;
}

// ---------------------------------------------------------------------------------------
// Stage: the forward model's own error against exact on the dataset poses (initial model).

CalibrationStatus MeasureForwardModelError(Run& run) {
  StaticsParameters<double> p;
  std::array<double, kNumCables> gain, bias, t_model, t_exact;
  run.cm->Assemble(run.theta.data(), &p, &gain, &bias);
  StaticsOptions exact = run.statics;
  exact.method = StaticsMethod::kExact;
  double sum2 = 0.0;
  int count = 0;
  CalibrationResult& r = *run.result;
  // A diagnostic: evenly spaced samples suffice on a large dataset.
  const size_t stride = std::max<size_t>(1, run.data.samples.size() / kForwardErrorSamples);
  for (size_t index = 0; index < run.data.samples.size(); index += stride) {
    const Sample& s = run.data.samples[index];
    const Pose pose = run.PoseOf(s);
    if (ModelLowerTensions(p, pose, run.statics, &t_model) != StaticsStatus::kOk ||
        ModelLowerTensions(p, pose, exact, &t_exact) != StaticsStatus::kOk) {
      StaticsSolution sol;
      SolveStatics(run.cm->ToRobot(run.theta.data()), pose, exact, &sol);
      return run.Fail(CalibrationStatus::kInfeasible,
                      SampleWhere(run.data, s) +
                          ": the initial model cannot solve this pose: " + DescribeStatus(sol));
    }
    for (int i = 0; i < kNumCables; ++i) {
      const double e = std::abs(t_model[i] / t_exact[i] - 1.0);
      r.forward_model_max_rel_error = std::max(r.forward_model_max_rel_error, e);
      sum2 += e * e;
      ++count;
    }
  }
  r.forward_model_rms_rel_error = std::sqrt(sum2 / std::max(count, 1));
  return CalibrationStatus::kOk;
}

// ---------------------------------------------------------------------------------------
// Stage: the model's readings at theta for every sample, their weights and residuals.
// Why weights from the predicted and not the measured reading: weights from the measured
// reading correlate with the noise itself (a low reading weighs more), which biased the
// fit (3% noise moved the density by 0.8%, 9 sigma on 3000 samples). The prediction
// depends on the parameters, hence the passes (iteratively reweighted least squares).

CalibrationStatus Predict(Run& run) {
  // One model per session (a single one without sessions).
  const size_t sessions = std::max<size_t>(1, run.data.session_labels.size());
  std::vector<StaticsParameters<double>> session_params(sessions);
  std::vector<std::array<double, kNumCables>> session_gain(sessions), session_bias(sessions);
  for (size_t k = 0; k < sessions; ++k) {
    run.cm->Assemble(run.theta.data(), &session_params[k], &session_gain[k], &session_bias[k],
                     static_cast<int>(k));
  }
  const int num_samples = static_cast<int>(run.data.samples.size());
  Prediction& at = run.at;
  at.reading_n.resize(num_samples);
  at.sigma_n.resize(num_samples);
  at.whitened.resize(num_samples);
  // Each sample starts from its statics at the previous parameters, when there are any.
  if (at.starts.method() != run.statics.method ||
      at.starts.size() != static_cast<size_t>(num_samples)) {
    at.starts = internal::CompactStarts(run.statics.method);
    at.starts.Reset(num_samples);
  }
  StaticsOptions options = run.statics;
  options.warm_start = true;
  const auto solve = [&](int t, StaticsSolution* solution) {
    const Sample& sample = run.data.samples[t];
    at.starts.At(t).Restore(run.PoseOf(sample), options.method, solution);
    return SolveStaticsWithParameters(session_params[sample.session], run.PoseOf(sample), options,
                                      solution);
  };
  const int failed =
      internal::ForEachChunk(num_samples, run.spec.num_threads, [&](int begin, int end) {
        StaticsSolution solution;
        for (int t = begin; t < end; ++t) {
          const Sample& sample = run.data.samples[t];
          if (solve(t, &solution) != StaticsStatus::kOk) return t;
          at.starts.Set(t, solution);
          const std::array<double, kNumCables>& gain = session_gain[sample.session];
          const std::array<double, kNumCables>& bias = session_bias[sample.session];
          for (int i = 0; i < kNumCables; ++i) {
            at.reading_n[t][i] = gain[i] * solution.cables[i].lower_tension_n + bias[i];
          }
          at.sigma_n[t] = internal::TensionSigmas(at.reading_n[t], run.spec.tension_sigma_n,
                                                  run.spec.tension_sigma_percent);
          for (int i = 0; i < kNumCables; ++i) {
            at.whitened[t][i] = (at.reading_n[t][i] - sample.tension_n[i]) / at.sigma_n[t][i];
          }
        }
        return -1;
      });
  if (failed >= 0) {
    StaticsSolution solution;  // the first failure again, for its message
    solve(failed, &solution);
    return run.Fail(CalibrationStatus::kInfeasible,
                    SampleWhere(run.data, run.data.samples[failed]) +
                        ": the model cannot solve this pose: " + DescribeStatus(solution));
  }
  return CalibrationStatus::kOk;
}

// The screen's threshold: the spec's as a floor, raised with the number of readings
// screened (all samples') so that noise alone names none (gross_errors.h).
GrossErrorThreshold ScreenThreshold(const Run& run) {
  return ChooseGrossErrorThreshold(static_cast<long long>(kNumCables) * run.data.samples.size(),
                                   run.spec.gross_error_threshold_sigmas);
}

// Stage helper: the gross errors at the current prediction, judged by the fitted samples.
ReadingMask ScreenReadings(Run& run) {
  if (!run.spec.detect_gross_errors) return {};
  GrossErrorScreen screen =
      ScreenGrossErrors(run.at.whitened, run.is_fit, ScreenThreshold(run).sigmas);
  GrossErrorSummary& g = run.result->gross_error_summary;
  for (int i = 0; i < kNumCables; ++i) {
    g.centre[i] = screen.cables[i].centre;
    g.scale[i] = screen.cables[i].scale;
  }
  g.fitted_readings = screen.judged;
  g.fitted_flagged = screen.count;
  return std::move(screen.flagged);
}

// ---------------------------------------------------------------------------------------
// Stage: the least-squares problem with the current weights, exclusions and warm starts:
// the data term folded into one block (folded_cost.h; it refers to run's arrays, which
// stay unchanged while the problem lives; the robust loss is applied inside it), and one
// block per prior (Ceres owns the cost objects).

void BuildProblem(Run& run) {
  run.problem.reset();
  run.problem = std::make_unique<ceres::Problem>();
  run.sigma_n.resize(run.fit.size());
  for (size_t j = 0; j < run.fit.size(); ++j) run.sigma_n[j] = run.at.sigma_n[run.fit[j]];
  run.slow_rho = internal::SlowErrorRatios(run.slow, run.View());
  run.problem->AddResidualBlock(
      new internal::FoldedTensionCost(run.Samples(), run.loss.get(), run.spec.num_threads), nullptr,
      run.theta.data());
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (p.has_prior) {
      run.problem->AddResidualBlock(
          new internal::PriorCost(run.n, k, p.prior_mean_si, p.prior_sigma_si), nullptr,
          run.theta.data());
    }
  }
}

// ---------------------------------------------------------------------------------------
// Stage: refuse a free set the data and priors cannot determine (before solving).

std::string DescribeRefusal(const Run& run) {
  const Identifiability& before = run.result->before;
  std::ostringstream refuse;
  if (!before.undetermined.empty()) {
    refuse << "no reading changes along these combinations of parameters (exact degeneracy):\n";
    for (const ParameterDirection& d : before.undetermined) {
      refuse << "  - " << d.Describe() << "   (singular value ratio "
             << RatioText(d.singular_value_ratio) << ")\n";
    }
    return refuse.str();
  }
  bool any = false;
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    const double limit = MaxSigma(p, run.theta[k], run.options);
    const double sigma = before.sigma_si[k];
    if (!(sigma > limit)) continue;
    if (!any) refuse << "these would be determined only to (1 sigma, from the stated noise):\n";
    any = true;
    refuse << "  - " << p.name << ": +-" << Fixed("%.3g", sigma / p.to_si) << UnitAfter(p.unit)
           << " (determined means +-" << Fixed("%.3g", limit / p.to_si) << UnitAfter(p.unit)
           << " or better)";
    // What it cannot be told apart from, where the correlation says so.
    constexpr double kNamedCorrelation = 0.5;
    if (k < static_cast<int>(before.partner.size()) && before.partner[k] >= 0 &&
        std::abs(before.partner_correlation[k]) >= kNamedCorrelation) {
      refuse << "; correlation " << Fixed("%+.2f", before.partner_correlation[k]) << " with "
             << run.Free(before.partner[k]).name;
    }
    refuse << "\n";
  }
  if (!any) return "";
  if (!before.poorly_determined.empty()) refuse << "the weakest directions in parameter space:\n";
  for (const ParameterDirection& d : before.poorly_determined) {
    refuse << "  - " << d.Describe() << "   (singular value ratio "
           << RatioText(d.singular_value_ratio) << ")\n";
  }
  return refuse.str();
}

CalibrationStatus CheckIdentifiability(Run& run) {
  Eigen::MatrixXd r;
  if (!JacobianR(run.problem.get(), run.spec.num_threads, &r)) {
    return run.Fail(CalibrationStatus::kInfeasible,
                    "the initial model cannot be evaluated on every sample");
  }
  run.result->before = Analyse(r, run.result->free_names, run.options);
  const std::string refusal = DescribeRefusal(run);
  if (refusal.empty()) return CalibrationStatus::kOk;
  return run.Fail(CalibrationStatus::kUndetermined,
                  std::string("the data") + (run.num_priors ? " and priors" : "") +
                      " cannot determine the free parameters; " + refusal +
                      "Fix one of the parameters named (free: false), give it a prior "
                      "(prior: {mean: ..., sigma: ...}), or add data that separates them "
                      "(other positions, zenith angles, attitudes).");
}

// ---------------------------------------------------------------------------------------
// Stage: solve, then reweight from the prediction and re-judge the gross errors, until
// the gross errors settle (at least two passes: the second has weights from the first).

ceres::Solver::Options SolverOptions(const Run& run, ProgressCallback* callback) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.num_threads = run.spec.num_threads;
  so.max_num_iterations = run.spec.max_iterations;
  so.function_tolerance = run.spec.function_tolerance;
  so.gradient_tolerance = run.spec.gradient_tolerance;
  so.parameter_tolerance = run.spec.parameter_tolerance;
  so.minimizer_progress_to_stdout = false;
  so.logging_type = ceres::SILENT;
  if (callback != nullptr) {
    so.callbacks.push_back(callback);
    so.update_state_every_iteration = false;
  }
  return so;
}

std::string PassNote(int pass, int excluded) {
  std::string s = "pass " + std::to_string(pass) + ": weights from pass " +
                  std::to_string(pass - 1) + "'s prediction";
  if (excluded > 0) {
    s += ", " + std::to_string(excluded) + (excluded == 1 ? " reading" : " readings") +
         " kept out as gross errors";
  }
  return s;
}

// Relative change of the slow error's amplitude and time constant within which a new
// estimate leaves the process the fit used as it is (the passes stop).
constexpr double kSlowErrorSettled = 0.05;
// Fitted samples the slow error's estimate uses at most (contiguous runs beyond).
constexpr int kSlowErrorEstimateSamples = 100000;

bool Settled(double before, double after) {
  return std::abs(after - before) <= kSlowErrorSettled * std::max(std::abs(before), 1e-300);
}

// Stage helper, after each pass's prediction: the slow error re-estimated from the
// residuals over their white sigma (when the spec estimates a part), and those residuals
// whitened by the process for the screen. True when the process the pass used stands
// (nothing estimated, or the new estimate within kSlowErrorSettled of it).
// On the last pass (`may_change` false) the process stays what the fit used.
bool ReestimateSlowError(Run& run, bool may_change) {
  SlowErrorReport& report = run.result->slow_error;
  bool settled = true;
  if (run.spec.slow_error.estimates_any()) {
    const SlowErrorReport estimate = internal::EstimateSlowError(
        internal::SlowErrorInputs(run.spec, run.View(), kSlowErrorEstimateSamples));
    const SlowErrorProcess& used = run.slow;
    const SlowErrorProcess& next = estimate.process;
    const bool floor = estimate.amplitude_at_floor && report.amplitude_at_floor;
    settled = used.IsActive() &&
              ((Settled(used.sigma_percent, next.sigma_percent) &&
                Settled(used.sigma_n, next.sigma_n) &&
                Settled(used.time_constant_s, next.time_constant_s)) ||
               floor);
    const int passes = report.passes + 1;
    report = estimate;
    report.passes = passes;
    if (!settled && may_change) run.slow = next;
    report.process = run.slow;
  }
  internal::WhitenPrediction(run.slow, run.View(), &run.at.whitened);
  return settled;
}

CalibrationStatus SolveAndReweight(Run& run) {
  CalibrationResult& r = *run.result;
  std::unique_ptr<ProgressCallback> callback;
  if (run.options.progress) callback = std::make_unique<ProgressCallback>(run.options.progress);
  const ceres::Solver::Options so = SolverOptions(run, callback.get());
  // Pass 1's weights are the initial model's, themselves off by its error: solving with
  // them beyond kFirstPassFunctionTolerance only polishes a point pass 2 moves from. Pass
  // 2 and later, with the weights of the pass before, meet the spec's tolerances.
  ceres::Solver::Options first = so;
  first.function_tolerance = std::max(so.function_tolerance, kFirstPassFunctionTolerance);
  ceres::Solver::Summary summary;
  std::string brief, full;
  int iterations = 0;
  for (int pass = 1; pass <= std::max(2, run.options.max_passes); ++pass) {
    if (pass > 1) {
      BuildProblem(run);
      if (run.options.progress) run.options.progress(PassNote(pass, CountExcluded(run)) + ":");
    }
    ceres::Solve(pass == 1 ? first : so, run.problem.get(), &summary);
    iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    if (pass == 1) r.initial_cost = summary.initial_cost;  // at the initial parameters
    const std::string label = pass == 1 ? "pass 1 (weights from the initial model)"
                                        : "pass " + std::to_string(pass) + " (weights from pass " +
                                              std::to_string(pass - 1) + ")";
    brief += (brief.empty() ? "" : "\n") + label + ": " + summary.BriefReport();
    full += (full.empty() ? "" : "\n") + label + "\n" + summary.FullReport();
    if (!summary.IsSolutionUsable()) break;
    const CalibrationStatus status = Predict(run);
    if (status != CalibrationStatus::kOk) return status;
    const bool slow_settled =
        ReestimateSlowError(run, pass < std::max(2, run.options.max_passes));
    ReadingMask screened = ScreenReadings(run);
    if (pass >= 2 && screened == run.excluded && slow_settled) break;
    if (pass == std::max(2, run.options.max_passes)) {
      r.gross_error_summary.settled = false;
      break;
    }
    run.excluded = std::move(screened);
  }
  r.ceres_brief_report = brief;
  r.ceres_full_report = full;
  r.final_cost = summary.final_cost;
  r.iterations = iterations;  // as Ceres counts them in its BriefReport, every pass
  r.converged = summary.termination_type == ceres::CONVERGENCE;
  r.termination = ceres::TerminationTypeToString(summary.termination_type);
  if (!summary.IsSolutionUsable()) {
    return run.Fail(CalibrationStatus::kSolverFailed, "the solver failed: " + summary.message);
  }
  const int excluded = CountExcluded(run);
  r.num_residuals = kNumCables * r.num_fit_samples - excluded + run.num_priors;
  r.reduced_chi_square = 2.0 * summary.final_cost / (r.num_residuals - run.n);
  return CalibrationStatus::kOk;
}

// Stage: a slow error the spec states in full, checked against the residuals of the fit
// (the maximum-likelihood process, and whether the stated one is rejected).
CalibrationStatus CheckStatedSlowError(Run& run) {
  if (!run.spec.slow_error.enabled || run.spec.slow_error.estimates_any()) {
    return CalibrationStatus::kOk;
  }
  run.result->slow_error = internal::EstimateSlowError(
      internal::SlowErrorInputs(run.spec, run.View(), kSlowErrorEstimateSamples));
  return CalibrationStatus::kOk;
}

// ---------------------------------------------------------------------------------------
// Stage: the gross errors, named; a dataset that is mostly gross errors is refused.

ReadingResidual ReadingAt(const Run& run, int t, int i) {
  ReadingResidual g;
  const Sample& s = run.data.samples[t];
  g.sample = t;
  g.line = s.line;
  g.cable = i + 1;
  g.measured_n = s.tension_n[i];
  g.predicted_n = run.at.reading_n[t][i];
  g.residual_sigma = run.at.whitened[t][i];
  g.held_out = !run.is_fit[t];
  return g;
}

// More than half of the fitted readings farther from the fit than the threshold in
// stated sigmas: the robust screen breaks down at half (a median inside the gross
// errors), so this is judged against the stated noise instead.
constexpr double kMostlyFarFraction = 0.5;

std::string MostlyGrossErrorsMessage(const Run& run, int flagged, int readings, const char* how,
                                     double limit) {
  return std::to_string(flagged) + " of the " + std::to_string(readings) + " fitted readings (" +
         Fixed("%.0f%%", 100.0 * flagged / std::max(1, readings)) + ") are " + how +
         ", more than the " + Fixed("%.0f%%", 100.0 * limit) +
         " allowed: the data are mostly not what the model predicts. Check the export (units, "
         "column order, a dead sensor), the model and the stated noise; ";
}

CalibrationStatus NameGrossErrors(Run& run) {
  CalibrationResult& r = *run.result;
  GrossErrorSummary& g = r.gross_error_summary;
  g.enabled = run.spec.detect_gross_errors;
  g.threshold = ScreenThreshold(run);
  g.threshold_sigmas = g.threshold.sigmas;
  g.fitted_readings = kNumCables * r.num_fit_samples;
  r.excluded = run.excluded;
  if (!g.enabled) return CalibrationStatus::kOk;
  for (size_t t = 0; t < run.excluded.size(); ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      if (!run.excluded[t][i]) continue;
      r.gross_errors.push_back(ReadingAt(run, static_cast<int>(t), i));
      ++g.count[i];
    }
  }
  g.fitted_flagged = CountExcluded(run);
  int far = 0;
  const ReadingResidual* first_far = nullptr;
  for (int t : run.fit) {
    for (int i = 0; i < kNumCables; ++i) {
      if (std::abs(run.at.whitened[t][i]) <= g.threshold_sigmas) continue;
      ++far;
      if (first_far == nullptr && r.gross_errors.empty()) {
        r.gross_errors.push_back(ReadingAt(run, t, i));  // named in the refusal only
        first_far = &r.gross_errors.back();
      }
    }
  }
  const std::string threshold = Fixed("%g", g.threshold_sigmas);
  std::string message;
  if (g.fitted_flagged > run.spec.max_gross_error_fraction * g.fitted_readings) {
    message = MostlyGrossErrorsMessage(
        run, g.fitted_flagged, g.fitted_readings,
        ("gross errors (more than " + threshold + " robust sigmas from the model)").c_str(),
        run.spec.max_gross_error_fraction);
  } else if (far > kMostlyFarFraction * g.fitted_readings) {
    message = MostlyGrossErrorsMessage(
        run, far, g.fitted_readings,
        ("farther than " + threshold + " stated sigmas from the best fit").c_str(),
        kMostlyFarFraction);
  } else {
    if (first_far != nullptr) r.gross_errors.clear();
    return CalibrationStatus::kOk;
  }
  const ReadingResidual& first = r.gross_errors.front();
  return run.Fail(CalibrationStatus::kMostlyGrossErrors,
                  message + "the first is " +
                      SampleWhere(run.data, run.data.samples[first.sample]) + " cable " +
                      std::to_string(first.cable));
}

// ---------------------------------------------------------------------------------------
// Stage: the uncertainty budget, from the problem linearised at the solution.

// The fixed parameters the model has, as the score test's candidates: every parameter a
// spec can name (AllModelParameters) but the free ones; a consider parameter keeps its
// prior and value (*value_si: the value it is held at).
std::vector<ParameterSpec> Candidates(const Run& run, std::vector<double>* value_si) {
  std::vector<ParameterSpec> out;
  value_si->clear();
  for (ParameterSpec c : AllModelParameters(run.model)) {
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
  in.rows_per_sample = kNumCables;
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
    for (int i = 0; i < kNumCables && keep > 0; ++i) {
      if (!run.excluded.empty() && run.excluded[t][i]) continue;
      const Entry e{std::abs(run.at.whitened[t][i]), t, i};
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
  return CalibrationStatus::kOk;
}

// Stage: the problem linearised at the solution (one pass for the free parameters, one
// for the candidates).
CalibrationStatus LineariseAtSolution(Run& run) {
  run.problem.reset();
  run.candidates = Candidates(run, &run.candidate_value_si);
  return Linearise(run, run.candidates, &run.lin);
}

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
  scan.wanders = !scan.changes.empty() &&
                 (scan.changes.size() > 1 || scan.trend_statistic >= scan.best_step_statistic);
  return CalibrationStatus::kOk;
}

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

// ---------------------------------------------------------------------------------------
// Stage: the per-parameter table (every parameter the spec names).

// One short note per kind; the directions themselves are listed once in the
// identifiability section.
std::string IdentifiabilityNote(const CalibrationResult& r, const ParameterSpec& p,
                                const ParameterEstimate& e, const CalibrationOptions& o) {
  std::string note;
  auto add = [&](const std::string& text) { note += (note.empty() ? "" : "; ") + text; };
  if (p.has_prior && r.covariance_ok && e.sigma > o.prior_dominated_fraction * e.prior_sigma) {
    add("set mostly by its prior");
  }
  auto in_direction = [&](const std::vector<ParameterDirection>& dirs) {
    for (const ParameterDirection& d : dirs) {
      for (const auto& w : d.weights) {
        if (w.first == p.name && std::abs(w.second) >= kNoteWeight) return true;
      }
    }
    return false;
  };
  if (in_direction(r.data_only.undetermined)) {
    add("not determined by the data alone (held by a prior; see identifiability)");
  } else if (in_direction(r.data_only.poorly_determined)) {
    add("poorly determined by the data alone (see identifiability)");
  }
  return note;
}

void FillParameterTable(Run& run) {
  CalibrationResult& r = *run.result;
  std::vector<int> free_of_spec(run.spec.parameters.size(), -1);
  for (int k = 0; k < run.n; ++k) free_of_spec[run.cm->spec_index(k)] = k;
  const std::vector<double> initial = run.cm->InitialTheta();
  for (size_t j = 0; j < run.spec.parameters.size(); ++j) {
    const ParameterSpec& p = run.spec.parameters[j];
    ParameterEstimate e;
    e.name = p.name;
    e.unit = p.unit;
    e.free = p.free;
    e.consider = p.IsConsider();
    e.has_prior = p.has_prior;
    e.prior_mean = p.prior_mean_si / p.to_si;
    e.prior_sigma = p.prior_sigma_si / p.to_si;
    const int k = free_of_spec[j];
    if (k < 0) {
      e.initial = e.estimate = (p.has_initial ? p.initial_si : run.cm->BaseValue(p)) / p.to_si;
      if (e.consider) e.sigma_total = e.prior_sigma;
      r.parameters.push_back(e);
      continue;
    }
    e.initial = initial[k] / p.to_si;
    e.estimate = run.theta[k] / p.to_si;
    if (r.covariance_ok) {
      const ParameterBudget& b = r.budget.parameters[k];
      e.sigma = b.formal / p.to_si;
      e.sigma_statistical = b.statistical / p.to_si;
      e.sigma_systematic = b.systematic / p.to_si;
      e.sigma_total = b.total / p.to_si;
      e.widening = b.widening;
      e.tau = b.tau;
      for (double g : b.systematic_by_group) e.systematic_by_group.push_back(g / p.to_si);
    }
    e.note = IdentifiabilityNote(r, p, e, run.options);
    r.parameters.push_back(e);
  }
  r.calibrated = run.cm->ToRobot(run.theta.data());
}

// ---------------------------------------------------------------------------------------
// Stage: the verdict, and the notes a reader needs beside it.

void DecideVerdict(Run& run) {
  CalibrationResult& r = *run.result;
  const ChiSquareBand band = ReducedChiSquareBand(r);
  const double chi = r.reduced_chi_square;
  const std::string chi_text = "reduced chi-square " + Fixed("%.3g", chi);
  if (!r.converged || !std::isfinite(chi) || chi > run.options.failed_fit_reduced_chi_square) {
    r.verdict = FitVerdict::kFailed;
    r.verdict_text =
        !r.converged
            ? "the solver stopped without converging (" + r.termination +
                  "): do not use the estimates"
            : chi_text + " is above " + Fixed("%g", run.options.failed_fit_reduced_chi_square) +
                  " (residuals about " + Fixed("%.1f", std::sqrt(chi)) +
                  " times the stated noise): the model does not describe these data, or the "
                  "stated noise is far too small (noise in the spec); the linearised "
                  "uncertainties mean nothing then; do not use the estimates as they are";
  } else if (band.within || band.degrees_of_freedom <= 0) {
    r.verdict = FitVerdict::kOk;
    r.verdict_text =
        chi_text + " agrees with the stated noise (1 +- " + Fixed("%.3g", band.half_width) + ")";
  } else if (chi < 1.0) {
    r.verdict = FitVerdict::kNoiseOverstated;
    r.verdict_text = chi_text + " is below 1 - " + Fixed("%.3g", band.half_width) +
                     ": the residuals are smaller than the stated noise; the formal sigmas are "
                     "pessimistic and are not scaled down";
  } else {
    r.verdict = FitVerdict::kMisfit;
    r.verdict_text =
        chi_text + " is above 1 + " + Fixed("%.3g", band.half_width) + ": the residuals are " +
        Fixed("%.2f", std::sqrt(chi)) +
        " times the stated noise (model error the free parameters cannot absorb, or noise "
        "understated). The statistical uncertainties are scaled by at least that factor "
        "(sigma_total); the misfit ranking says which fixed parameter would explain most "
        "of it";
  }
}

// The misfit ranking's significant candidates against the free estimates: each estimate
// that one of them would move by more than incomplete_model_sigmas sigma_total is marked
// (the largest move), and the verdict becomes kModelIncomplete unless the fit failed.
void JudgeCompleteness(Run& run) {
  CalibrationResult& r = *run.result;
  if (r.verdict == FitVerdict::kFailed || !r.covariance_ok) return;
  const double limit = run.options.incomplete_model_sigmas;
  for (const MisfitCandidate& c : r.misfit_ranking) {
    // A change beyond the parameter's plausible range leaves the linearisation: its
    // shifts say nothing reliable (the ranking shows no shift for it either).
    if (!c.significant || c.beyond_linear_range) continue;
    size_t k = 0;
    for (ParameterEstimate& e : r.parameters) {
      if (!e.free) continue;
      const double shift = k < c.shifts.size() ? c.shifts[k] : 0.0;
      ++k;
      const double sigmas = e.sigma_total > 0 ? std::abs(shift) / e.sigma_total : 0.0;
      // Judged against the uncertainty the estimate would have with the candidate freed:
      // sigma_total widened by the shift's own uncertainty, shift^2 / statistic (the
      // candidate's change is known to 1/sqrt(statistic) of itself). Under the null the
      // ratio is below sqrt(statistic), so a candidate noise made significant rarely
      // passes; against sigma_total alone 2 of 20 realistic seeds did.
      const double after = std::sqrt(e.sigma_total * e.sigma_total +
                                     (c.statistic > 0 ? shift * shift / c.statistic : 0.0));
      const double sigmas_after = after > 0 ? std::abs(shift) / after : 0.0;
      if (!(sigmas_after > limit) || sigmas <= e.moved_by_sigmas) continue;
      e.moved_by = c.name;
      e.moved_by_shift = shift;
      e.moved_by_sigmas = sigmas;
    }
  }
  const ParameterEstimate* worst = nullptr;
  std::string marked;
  for (const ParameterEstimate& e : r.parameters) {
    if (e.moved_by.empty()) continue;
    marked += (marked.empty() ? "" : ", ") + e.name;
    if (worst == nullptr || e.moved_by_sigmas > worst->moved_by_sigmas) worst = &e;
  }
  if (worst == nullptr) return;
  r.verdict = FitVerdict::kModelIncomplete;
  // A prior's candidate is released, a fixed parameter's freed.
  const bool prior = worst->moved_by.rfind("prior of ", 0) == 0;
  r.verdict_text = (prior ? "releasing the " : "freeing ") + worst->moved_by +
                   ", which the data point at beyond their " + "noise, would move " + worst->name +
                   " by " + Fixed("%+.3g", worst->moved_by_shift) + " " + worst->unit + " (" +
                   Fixed("%.1f", worst->moved_by_sigmas) +
                   " sigma_total): the model lacks something the data show, and sigma_total " +
                   "cannot contain that error. Not sound as they stand: " + marked +
                   (prior ? ". Check the prior, or free what explains the data's disagreement"
                          : ". Free the candidate (with a prior)") +
                   ", or model what it stands for (a sensor's gain, cable attachments: "
                   "docs/calibration.md, \"Model incomplete\"); " +
                   r.verdict_text;
}

// What the misfit ranking's significant candidates would move, in sigma_total: sigma_total
// does not contain the error of a fixed parameter the data point at.
void NoteWhatTheMisfitWouldMove(CalibrationResult* r) {
  constexpr size_t kCandidates = 3;
  constexpr double kWorthSaying = 1.0;  // sigma_total
  size_t said = 0;
  for (const MisfitCandidate& c : r->misfit_ranking) {
    if (!c.significant || said == kCandidates) break;
    if (c.beyond_linear_range) continue;
    const ParameterEstimate* worst = nullptr;
    double worst_sigmas = 0.0, worst_shift = 0.0;
    size_t k = 0;
    for (const ParameterEstimate& e : r->parameters) {
      if (!e.free) continue;
      const double sigmas = e.sigma_total > 0 ? std::abs(c.shifts[k]) / e.sigma_total : 0.0;
      if (sigmas > worst_sigmas) {
        worst = &e;
        worst_sigmas = sigmas;
        worst_shift = c.shifts[k];
      }
      ++k;
    }
    ++said;
    if (worst == nullptr || worst_sigmas < kWorthSaying) continue;
    r->notes.push_back("freeing " + c.name + ", which the data point at, would move " +
                       worst->name + " by " + Fixed("%+.3g", worst_shift) + UnitAfter(worst->unit) +
                       " (" + Fixed("%.1f", worst_sigmas) +
                       " sigma_total): sigma_total does not include the error of a parameter "
                       "held fixed at a wrong value");
  }
}

void AddNotes(Run& run) {
  CalibrationResult& r = *run.result;
  const UncertaintyBudget& b = r.budget;
  for (const std::string& slow :
       {DescribeSlowError(r.slow_error), DescribeStatedSlowErrorCheck(r.slow_error)}) {
    if (!slow.empty()) r.notes.push_back(slow);
  }
  if (r.covariance_ok && b.correlation_measured && !b.correlated) {
    r.notes.push_back("residuals uncorrelated in time (largest autocorrelation time " +
                      Fixed("%.3g", b.tau) + " samples, not significantly above 1)");
  } else if (r.covariance_ok && b.correlated) {
    r.notes.push_back("residuals correlated in time: " + Fixed("%.3g", b.effective_samples) +
                      " effective independent samples of " + std::to_string(b.samples) +
                      " (autocorrelation time " + Fixed("%.3g", b.tau) + " samples, batch length " +
                      std::to_string(b.bandwidth) + ")" +
                      (b.correlation_reliable
                           ? ""
                           : "; the memory is too long for these data to measure, so the "
                             "widening is a lower bound"));
  }
  if (!r.gross_error_summary.settled) {
    r.notes.push_back("the set of gross errors still changed after " +
                      std::to_string(run.options.max_passes) + " passes");
  }
  std::string wider;
  for (const ParameterEstimate& e : r.parameters) {
    if (e.free && e.has_prior && e.sigma_total > e.prior_sigma) {
      wider += (wider.empty() ? "" : ", ") + e.name + " (" + Fixed("%.3g", e.sigma_total) +
               " against " + Fixed("%.3g", e.prior_sigma) + ")";
    }
    if (e.consider && std::abs(e.estimate - e.prior_mean) > 0.5 * e.prior_sigma) {
      r.notes.push_back(e.name + " is held at " + Fixed("%.6g", e.estimate) +
                        " but its prior's mean is " + Fixed("%.6g", e.prior_mean) +
                        ": the fit is conditional on a value the prior doubts");
    }
  }
  if (!wider.empty()) {
    r.notes.push_back("sigma_total exceeds the prior's sigma for " + wider +
                      ": the data, weighted by the stated noise but noisier than stated, pull "
                      "them further than their priors allow; stating the noise the residuals "
                      "show (or fewer free parameters) would give the priors their due weight");
  }
  NoteWhatTheMisfitWouldMove(&r);
}

// ---------------------------------------------------------------------------------------
// Stage: the model against the measurements before and after (the paper's Table 6):
// the initial model at each attitude the data has and the calibrated one at the fit's,
// exact statics, gross errors left out.
CalibrationStatus Evaluate(Run& run) {
  CalibrationResult& r = *run.result;
  if (!run.options.evaluate) return CalibrationStatus::kOk;
  // With exact statics the last prediction is the calibrated model's row already, and
  // its statics each sample's warm start for the other rows.
  internal::RmsTableInputs inputs;
  std::vector<std::array<double, kNumCables>> calibrated;
  if (run.spec.forward_model == StaticsMethod::kExact) {
    calibrated = std::move(run.at.reading_n);
    inputs.calibrated_readings = &calibrated;
    inputs.starts = &run.at.starts;
  }
  std::string why;
  const bool ok =
      internal::EvaluateBeforeAndAfter(run.model, run.spec, run.data, r, inputs, &r.variants, &why);
  run.at = Prediction();
  if (!ok) {
    return run.Fail(CalibrationStatus::kInfeasible, why);
  }
  return CalibrationStatus::kOk;
}

// A joint fit's per-session models, the differences between sessions and what they say
// (sessions.h); nothing without separate parameters.
void ConcludeSessions(Run& run) {
  CalibrationResult& r = *run.result;
  std::vector<ParameterSpec> free;
  for (int k = 0; k < run.n; ++k) free.push_back(run.Free(k));
  if (std::none_of(free.begin(), free.end(), [](const auto& p) { return p.session >= 0; })) {
    if (!run.spec.separate_groups.empty()) {
      r.notes.push_back("sessions.separate has no effect: the data have " +
                        std::to_string(run.data.session_labels.size()) +
                        " session labels (two or more are needed: a session column, or "
                        "--data=a.csv,b.csv)");
    }
    return;
  }
  r.session_labels = run.data.session_labels;
  for (size_t s = 0; s < r.session_labels.size(); ++s) {
    r.session_models.push_back(run.cm->ToRobot(run.theta.data(), static_cast<int>(s)));
  }
  r.session_differences = ConsecutiveSessionDifferences(
      free, run.theta, r.covariance_ok ? r.budget.total : Eigen::MatrixXd(), r.session_labels);
  r.verdict_text += "; " + SessionVerdict(r.session_differences);
}

// Stage: the per-parameter table, the verdict and its notes.
CalibrationStatus Conclude(Run& run) {
  FillParameterTable(run);
  DecideVerdict(run);
  JudgeCompleteness(run);
  AddNotes(run);
  ConcludeSessions(run);
  if (run.result->change_scan.enabled) {
    run.result->verdict_text += "; " + ChangeScanVerdict(run.result->change_scan);
  }
  return CalibrationStatus::kOk;
}

// Stage: the initial model's readings, screened for gross errors.
CalibrationStatus PredictAndScreen(Run& run) {
  const CalibrationStatus status = Predict(run);
  if (status != CalibrationStatus::kOk) return status;
  internal::WhitenPrediction(run.slow, run.View(), &run.at.whitened);
  run.excluded = ScreenReadings(run);
  return status;
}

// Stage: the problem with the initial weights, and the refusal of a free set the data
// and priors cannot determine.
CalibrationStatus BuildAndCheck(Run& run) {
  BuildProblem(run);
  return CheckIdentifiability(run);
}

// The sensor-step test's verdict beside the refit's own.
void AddSensorStepVerdict(CalibrationResult* r) {
  const std::string steps = SensorStepVerdict(r->sensor_steps);
  if (steps.empty()) return;
  r->verdict_text += "; " + steps;
}

CalibrationStatus RunPipeline(const CableRobot& model, const CalibrationSpec& spec,
                              const Dataset& data, const CalibrationOptions& options,
                              CalibrationResult* result, std::string* error) {
  // A joint fit of several sessions: the separate groups' copies (sessions.h).
  const CalibrationSpec joint = SeparateSessionParameters(spec, data.session_labels);
  Run run(model, joint, data, options, result, error);
  using Stage = CalibrationStatus (*)(Run&);
  struct NamedStage {
    const char* name;
    Stage stage;
  };
  const NamedStage stages[] = {{"validate", ValidateInputs},
                               {"forward model error", MeasureForwardModelError},
                               {"predict and screen", PredictAndScreen},
                               {"build and check", BuildAndCheck},
                               {"solve and reweight", SolveAndReweight},
                               {"slow error", CheckStatedSlowError},
                               {"name gross errors", NameGrossErrors},
                               {"worst readings", FindWorstReadings},
                               {"linearise", LineariseAtSolution},
                               {"uncertainty", EstimateUncertainty},
                               {"sensor steps", TestSensorStepsStage},
                               {"change scan", ScanChanges},
                               {"diagnose", Diagnose},
                               {"conclude", Conclude},
                               {"evaluate", Evaluate}};
  for (const NamedStage& s : stages) {
    const auto start = std::chrono::steady_clock::now();
    const Usage before = ProcessUsage();
    const CalibrationStatus status = s.stage(run);
    const Usage after = ProcessUsage();
    result->stages.push_back(
        {s.name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
         after.cpu_s - before.cpu_s, after.peak_mb});
    if (status != CalibrationStatus::kOk) return status;
  }
  return CalibrationStatus::kOk;
}

}  // namespace

std::string ParameterDirection::Describe() const {
  std::ostringstream s;
  for (size_t i = 0; i < weights.size(); ++i) {
    s << (i ? " ~ " : "") << weights[i].first << " ("
      << internal::FormatDouble("%+.2f", weights[i].second) << ")";
  }
  return s.str();
}

const char* FitVerdictName(FitVerdict verdict) {
  switch (verdict) {
    case FitVerdict::kOk:
      return "ok";
    case FitVerdict::kNoiseOverstated:
      return "noise overstated";
    case FitVerdict::kMisfit:
      return "misfit scaled";
    case FitVerdict::kFailed:
      return "failed";
    case FitVerdict::kModelIncomplete:
      return "model incomplete";
  }
  return "unknown";
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
  if (!CheckSessions(data, error)) return CalibrationStatus::kInvalidInput;
  CalibrationStatus status = RunPipeline(model, spec, data, options, result, error);
  // Sensors re-zeroed between sessions: fitted again with their biases per session.
  const SensorStepTest steps = result->sensor_steps;
  if (status == CalibrationStatus::kOk && options.separate_stepped_sensors &&
      !steps.separated.empty()) {
    if (options.progress) {
      options.progress("sensor offsets stepped between sessions: fitting again with their "
                       "biases per session");
    }
    CalibrationSpec refit = spec;
    for (const std::string& name : steps.separated) refit.separate_groups.push_back(name);
    std::vector<CalibrationResult::Stage> first_stages = result->stages;
    for (CalibrationResult::Stage& stage : first_stages) stage.name = "first fit: " + stage.name;
    *result = CalibrationResult();
    status = RunPipeline(model, refit, data, options, result, error);
    result->stages.insert(result->stages.begin(), first_stages.begin(), first_stages.end());
    result->sensor_steps = steps;
    if (status == CalibrationStatus::kOk) AddSensorStepVerdict(result);
  }
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return status;
}

}  // namespace fastcal
