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

#include "calibration/calibration_run.h"
#include "fastcal/gross_errors.h"
#include "fastcal/internal/calibration_evaluation.h"
#include "fastcal/internal/calibration_linearisation.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/calibration_slow_error.h"
#include "fastcal/internal/decrement_stop.h"
#include "fastcal/internal/folded_cost.h"
#include "fastcal/internal/identifiability.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/model_plausibility.h"
#include "fastcal/tension_scale.h"

namespace fastcal {

int internal::CountExcluded(const Run& run) {
  int count = 0;
  for (const ReadingMask* mask : {&run.excluded, &run.length_excluded}) {
    if (mask->empty()) continue;
    for (int t : run.fit) {
      for (bool e : (*mask)[t]) count += e;
    }
  }
  return count;
}

ReadingResidual internal::ReadingAt(const Run& run, int t, int i) {
  ReadingResidual g;
  const Sample& s = run.data.samples[t];
  g.sample = t;
  g.line = s.line;
  g.held_out = !run.is_fit[t];
  g.length = i >= kNumCables;
  const int c = i % kNumCables;
  g.cable = c + 1;
  if (g.length) {
    g.measured_m = s.unstretched_length_m[c];
    g.predicted_m = run.at.length_m[t][c];
    g.residual_sigma = run.at.length_whitened[t][c];
    return g;
  }
  g.measured_n = s.tension_n[c];
  g.predicted_n = run.at.reading_n[t][c];
  g.residual_sigma = run.at.whitened[t][c];
  return g;
}

bool internal::ReadingExcluded(const Run& run, int t, int i) {
  const ReadingMask& mask = i < kNumCables ? run.excluded : run.length_excluded;
  return !mask.empty() && mask[t][i % kNumCables];
}

double internal::ReadingWhitened(const Run& run, int t, int i) {
  return i < kNumCables ? run.at.whitened[t][i] : run.at.length_whitened[t][i - kNumCables];
}

namespace {

using namespace internal;  // the run's state and stages (calibration_run.h)
using internal::Analyse;
using internal::CalibrationModel;
using internal::JacobianR;
using internal::MaxSigma;

// Samples (evenly spaced) on which the forward model is compared with exact.
constexpr size_t kForwardErrorSamples = 2000;
// Relative cost decrease at which pass 1 (weights from the initial model) stops; 10^-4
// of the cost saves a Jacobian and a cost evaluation of every sample (2 s at 10^6
// samples) and leaves pass 2 a start well inside its first step.
constexpr double kFirstPassFunctionTolerance = 1e-4;
// Initial trust-region radius of pass 2 and later (Ceres's default 1e4; its maximum 1e16).
constexpr double kLaterPassTrustRegionRadius = 1e12;

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

// ---------------------------------------------------------------------------------------
// The state of one calibration, passed from stage to stage.

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

// Ceres asks after each iteration whether to go on: CalibrationOptions::should_stop.
class StopCallback : public ceres::IterationCallback {
 public:
  explicit StopCallback(const std::function<bool()>& should_stop) : should_stop_(should_stop) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    stopped_ = stopped_ || should_stop_();
    return stopped_ ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
  bool stopped() const { return stopped_; }

 private:
  std::function<bool()> should_stop_;
  bool stopped_ = false;
};

constexpr char kCancelledMessage[] = "stopped on request (CalibrationOptions::should_stop)";

std::unique_ptr<ceres::LossFunction> MakeLoss(const CalibrationSpec& spec) {
  if (spec.robust_loss == RobustLoss::kHuber) {
    return std::make_unique<ceres::HuberLoss>(spec.robust_loss_scale);
  }
  if (spec.robust_loss == RobustLoss::kCauchy) {
    return std::make_unique<ceres::CauchyLoss>(spec.robust_loss_scale);
  }
  return nullptr;
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
  if (!CheckJointColumns(run.data, run.model.moving_parts, &why) ||
      !CheckTensionScale(run.data, run.model, &why)) {
    return run.Fail(CalibrationStatus::kInvalidInput, why);
  }
  if (run.spec.slow_error.enabled && run.data.samples.size() > 1) {
    // A slow error correlates readings by their times: times that never advance (every
    // sample at one time_s) make it any value at all, fitted silently before (issue 37).
    const auto [lo, hi] =
        std::minmax_element(run.data.samples.begin(), run.data.samples.end(),
                            [](const Sample& a, const Sample& b) { return a.time_s < b.time_s; });
    if (lo->time_s == hi->time_s) {
      return run.Fail(CalibrationStatus::kInvalidInput,
                      run.data.path + ": every sample has time_s = " +
                          internal::FormatDouble("%g", lo->time_s) +
                          ": the slow sensor error (spec noise.slow_error) correlates "
                          "readings by their times; give the samples' times, or drop "
                          "slow_error from the spec");
    }
  }
  if (run.spec.UsesLengths() && !run.data.has_unstretched_lengths) {
    return run.Fail(CalibrationStatus::kInvalidInput,
                    run.data.path +
                        ": the spec fits the lengths (noise.length_sigma_m) but the dataset has "
                        "no s0_1_m ... s0_6_m columns");
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
  r.num_residuals = run.Readings() * r.num_fit_samples + run.num_priors;
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
  Eigen::Vector3d measured_offset;
  run.cm->Assemble<double>(run.theta.data(), &p, &gain, &bias, 0, nullptr, &measured_offset);
  StaticsOptions exact = run.statics;
  exact.method = StaticsMethod::kExact;
  double sum2 = 0.0;
  int count = 0;
  CalibrationResult& r = *run.result;
  // A diagnostic: evenly spaced samples suffice on a large dataset.
  const size_t stride = std::max<size_t>(1, run.data.samples.size() / kForwardErrorSamples);
  for (size_t index = 0; index < run.data.samples.size(); index += stride) {
    const Sample& s = run.data.samples[index];
    const Pose pose = run.PoseOf(s, measured_offset);
    PartShifts shifts;
    run.cm->robot().moving_parts.ShiftsAt(s.joint, &shifts);
    const StaticsParameters<double> at = AtJoints(p, shifts);
    if (ModelLowerTensions(at, pose, run.statics, &t_model) != StaticsStatus::kOk ||
        ModelLowerTensions(at, pose, exact, &t_exact) != StaticsStatus::kOk) {
      StaticsSolution sol;
      SolveStatics(run.cm->ToRobot(run.theta.data()), pose, s.joint, exact, &sol);
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
  std::vector<std::array<double, kNumCables>> session_gain(sessions), session_bias(sessions),
      session_offset(sessions);
  std::vector<Eigen::Vector3d> session_measured_offset(sessions);
  for (size_t k = 0; k < sessions; ++k) {
    run.cm->Assemble(run.theta.data(), &session_params[k], &session_gain[k], &session_bias[k],
                     static_cast<int>(k), &session_offset[k], &session_measured_offset[k]);
  }
  const bool lengths = run.spec.UsesLengths();
  const int num_samples = static_cast<int>(run.data.samples.size());
  Prediction& at = run.at;
  at.reading_n.resize(num_samples);
  at.sigma_n.resize(num_samples);
  at.whitened.resize(num_samples);
  at.length_m.resize(lengths ? num_samples : 0);
  at.length_whitened.resize(lengths ? num_samples : 0);
  // Each sample starts from its statics at the previous parameters, when there are any.
  if (at.starts.method() != run.statics.method ||
      at.starts.size() != static_cast<size_t>(num_samples)) {
    at.starts = internal::CompactStarts(run.statics.method);
    at.starts.Reset(num_samples);
  }
  StaticsOptions options = run.statics;
  options.warm_start = true;
  // After a solve, the fit's last evaluation at theta has solved every fitted sample.
  const bool solved = run.folded != nullptr && run.folded->SolvedAt(run.theta.data());
  const auto solve = [&](int t, StaticsSolution* solution) {
    const Sample& sample = run.data.samples[t];
    const Pose pose = run.PoseOf(sample, session_measured_offset[sample.session]);
    at.starts.At(t).Restore(pose, options.method, solution);
    return SolveStaticsWithParameters(session_params[sample.session], run.cm->robot().moving_parts,
                                      sample.joint, pose, options, solution);
  };
  const int failed =
      internal::ForEachChunk(num_samples, run.spec.num_threads, [&](int begin, int end) {
        StaticsSolution solution;
        for (int t = begin; t < end; ++t) {
          const Sample& sample = run.data.samples[t];
          if (!solved || !run.is_fit[t]) {
            if (solve(t, &solution) != StaticsStatus::kOk) return t;
            at.starts.Set(t, solution);
            const std::array<double, kNumCables>& gain = session_gain[sample.session];
            const std::array<double, kNumCables>& bias = session_bias[sample.session];
            for (int i = 0; i < kNumCables; ++i) {
              at.reading_n[t][i] = gain[i] * solution.cables[i].lower_tension_n + bias[i];
            }
          }
          at.sigma_n[t] = internal::TensionSigmas(at.reading_n[t], run.spec.tension_sigma_n,
                                                  run.spec.tension_sigma_percent);
          for (int i = 0; i < kNumCables; ++i) {
            at.whitened[t][i] = (at.reading_n[t][i] - sample.tension_n[i]) / at.sigma_n[t][i];
          }
          for (int i = 0; i < kNumCables && lengths; ++i) {
            at.length_m[t][i] =
                solution.cables[i].unstretched_length_m + session_offset[sample.session][i];
            at.length_whitened[t][i] =
                (at.length_m[t][i] - sample.unstretched_length_m[i]) / run.spec.length_sigma_m;
          }
        }
        return -1;
      });
  if (failed >= 0) {
    at.starts.ForgetSolved();
    StaticsSolution solution;  // the first failure again, for its message
    solve(failed, &solution);
    return run.Fail(CalibrationStatus::kInfeasible,
                    SampleWhere(run.data, run.data.samples[failed]) +
                        ": the model cannot solve this pose: " + DescribeStatus(solution));
  }
  // Every sample's start is now its solution at theta (the fitted ones the fold's, when
  // `solved`): the next pass at theta need not solve them again.
  at.starts.MarkSolvedAt(run.cm.get(), run.theta.data(), run.n);
  return CalibrationStatus::kOk;
}

// The screen's threshold: the spec's as a floor, raised with the number of readings
// screened (all samples') so that noise alone names none (gross_errors.h).
GrossErrorThreshold ScreenThreshold(const Run& run) {
  return ChooseGrossErrorThreshold(static_cast<long long>(run.Readings()) * run.data.samples.size(),
                                   run.spec.gross_error_threshold_sigmas);
}

// Stage helper: the gross errors at the current prediction, judged by the fitted samples:
// the tensions' and, with lengths in the fit, the lengths' (*lengths; each reading
// against its own cable's robust scale).
ReadingMask ScreenReadings(Run& run, ReadingMask* lengths) {
  lengths->clear();
  if (!run.spec.detect_gross_errors) return {};
  const double threshold = ScreenThreshold(run).sigmas;
  GrossErrorScreen screen = ScreenGrossErrors(run.at.whitened, run.is_fit, threshold);
  GrossErrorSummary& g = run.result->gross_error_summary;
  for (int i = 0; i < kNumCables; ++i) {
    g.centre[i] = screen.cables[i].centre;
    g.scale[i] = screen.cables[i].scale;
  }
  g.fitted_readings = screen.judged;
  g.fitted_flagged = screen.count;
  if (run.spec.UsesLengths()) {
    GrossErrorScreen length_screen =
        ScreenGrossErrors(run.at.length_whitened, run.is_fit, threshold);
    for (int i = 0; i < kNumCables; ++i) {
      g.length_centre[i] = length_screen.cables[i].centre;
      g.length_scale[i] = length_screen.cables[i].scale;
    }
    g.fitted_readings += length_screen.judged;
    g.fitted_flagged += length_screen.count;
    *lengths = std::move(length_screen.flagged);
  }
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
  // The fit's last evaluation leaves the statics it solved where the next prediction
  // reads them (Predict): a pass of statics saved after every solve.
  internal::FittedSamples samples = run.Samples();
  samples.solved = {&run.at.reading_n, &run.at.starts};
  auto* folded = new internal::FoldedTensionCost(samples, run.loss.get(), run.spec.num_threads);
  run.folded = folded;
  run.problem->AddResidualBlock(folded, nullptr, run.theta.data());
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

// Why lengths and tensions together may not separate an encoder's offset from the rest,
// when a direction the data cannot determine involves one.
std::string LengthOffsetHint(const std::vector<ParameterDirection>& directions) {
  for (const ParameterDirection& d : directions) {
    for (const auto& [name, weight] : d.weights) {
      if (name.rfind(ParameterGroupName(ParameterKind::kLengthOffset), 0) != 0) continue;
      return "a length encoder's offset adds the same to every reading of its cable's length, "
             "so the lengths tell it from the cable's stretch (EA), sag (density) and "
             "geometry only where the tensions and poses vary over the survey.\n";
    }
  }
  return "";
}

// A free first moment without a prior whose component lies along one of its part's own
// revolute axes: seen only at second order in the angles (moving_parts.h), it needs one.
std::string FirstMomentHint(const Run& run) {
  std::string names;
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (p.kind != ParameterKind::kPartFirstMoment || p.has_prior) continue;
    const MovingPart& part = run.model.moving_parts.parts[p.index];
    for (const Joint& j : part.joints) {
      if (j.type == JointType::kRevolute && std::abs(j.axis[p.component]) > 0.5) {
        names += (names.empty() ? "" : ", ") + p.name;
        break;
      }
    }
  }
  if (names.empty()) return "";
  return "a first moment's component along its part's own rotation axis (" + names +
         ") moves the mass centre only at second order in the joint angles: give it a prior "
         "(e.g. first_moment_kg_m: {x: {free: true, prior: {mean: 0, sigma: 3000}}}).\n";
}

// A free offset of the measured frame without a prior: it moves only the cabin's
// position, which the tensions see through the cables' geometry alone (measured_frame.h).
std::string MeasuredOffsetHint(const Run& run) {
  std::string names;
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (p.kind == ParameterKind::kMeasuredOffset && !p.has_prior) {
      names += (names.empty() ? "" : ", ") + p.name;
    }
  }
  if (names.empty()) return "";
  return "the measured point's offset (" + names +
         ") moves only the cabin's position, which the tensions see through the cables' "
         "geometry alone (and the z offset trades against mass_centre_m.z where the cabin "
         "tilts with the pointing): give it a prior from the drawings (e.g. measured_frame: "
         "{offset_m: {z: {free: true, prior: {mean: -1.2, sigma: 0.5}}}}).\n";
}

std::string DescribeRefusal(const Run& run) {
  const Identifiability& before = run.result->before;
  std::ostringstream refuse;
  if (!before.undetermined.empty()) {
    refuse << "no reading changes along these combinations of parameters (exact degeneracy):\n";
    for (const ParameterDirection& d : before.undetermined) {
      refuse << "  - " << d.Describe() << "   (singular value ratio "
             << RatioText(d.singular_value_ratio) << ")\n";
    }
    refuse << LengthOffsetHint(before.undetermined) << FirstMomentHint(run)
           << MeasuredOffsetHint(run);
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
  refuse << LengthOffsetHint(before.poorly_determined) << FirstMomentHint(run)
         << MeasuredOffsetHint(run);
  return refuse.str();
}

CalibrationStatus CheckIdentifiability(Run& run) {
  Eigen::MatrixXd r;
  if (!JacobianR(run.problem.get(), &r)) {
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
  // One Ceres thread: the data term is one block that folds the samples on the spec's
  // threads itself; Ceres's threads would only sum the blocks' costs (the priors') in an
  // order that depends on their number, and the final cost's last bits with it.
  so.num_threads = 1;
  so.max_num_iterations = run.spec.max_iterations;
  so.function_tolerance = run.spec.function_tolerance;
  so.gradient_tolerance = run.spec.gradient_tolerance;
  so.parameter_tolerance = run.spec.parameter_tolerance;
  so.minimizer_progress_to_stdout = false;
  so.logging_type = ceres::SILENT;
  if (callback != nullptr) so.callbacks.push_back(callback);
  // The decrement stop (SolveAndReweight) reads theta at each iteration's end.
  so.update_state_every_iteration = true;
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

// Fitted samples the slow error's estimate uses at most (contiguous runs beyond).
constexpr int kSlowErrorEstimateSamples = 100000;

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
    settled = internal::AdoptSlowErrorEstimate(estimate, may_change, &run.slow, &report);
  }
  internal::WhitenPrediction(run.slow, run.View(), &run.at.whitened);
  return settled;
}

// The decrement stop of the current problem (decrement_stop.h): the data term's folded
// rows as the fold left them, and the priors.
internal::DecrementStop MakeDecrementStop(const Run& run, double function_tolerance) {
  std::vector<internal::DecrementPrior> priors;
  for (int k = 0; k < run.n; ++k) {
    const ParameterSpec& p = run.Free(k);
    if (p.has_prior) priors.push_back({k, p.prior_mean_si, p.prior_sigma_si});
  }
  const internal::FoldedTensionCost* folded = run.folded;
  return internal::DecrementStop(
      [folded](const double* theta, Eigen::MatrixXd* r_aug) {
        return folded->FoldedAt(theta, r_aug);
      },
      std::move(priors), run.theta.data(), function_tolerance);
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
  // Pass 2 and later start from the pass before's solution, where the Gauss-Newton step is
  // good: Levenberg-Marquardt's default damping (trust region 1e4) made them creep there in
  // 3-4 steps where 1-2 do (a Jacobian fold each: issue 28).
  ceres::Solver::Options later = so;
  later.initial_trust_region_radius = kLaterPassTrustRegionRadius;
  ceres::Solver::Summary summary;
  std::string brief, full;
  int iterations = 0;
  for (int pass = 1; pass <= std::max(2, run.options.max_passes); ++pass) {
    if (pass > 1) {
      BuildProblem(run);
      if (run.options.progress) run.options.progress(PassNote(pass, CountExcluded(run)) + ":");
    }
    ceres::Solver::Options options = pass == 1 ? first : later;
    internal::DecrementStop stop = MakeDecrementStop(run, options.function_tolerance);
    options.callbacks.push_back(&stop);
    std::unique_ptr<StopCallback> cancel;
    if (run.options.should_stop) {
      cancel = std::make_unique<StopCallback>(run.options.should_stop);
      options.callbacks.push_back(cancel.get());
    }
    ceres::Solve(options, run.problem.get(), &summary);
    if (cancel && cancel->stopped()) {
      return run.Fail(CalibrationStatus::kCancelled, kCancelledMessage);
    }
    if (stop.stopped()) {  // where Ceres would have stopped after one more cost evaluation
      summary.termination_type = ceres::CONVERGENCE;
      summary.message = stop.Reason();
    }
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
    const bool slow_settled = ReestimateSlowError(run, pass < std::max(2, run.options.max_passes));
    ReadingMask screened_lengths;
    ReadingMask screened = ScreenReadings(run, &screened_lengths);
    if (pass >= 2 && screened == run.excluded && screened_lengths == run.length_excluded &&
        slow_settled) {
      break;
    }
    if (pass == std::max(2, run.options.max_passes)) {
      r.gross_error_summary.settled = false;
      break;
    }
    run.excluded = std::move(screened);
    run.length_excluded = std::move(screened_lengths);
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
  r.num_residuals = run.Readings() * r.num_fit_samples - excluded + run.num_priors;
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
  g.fitted_readings = run.Readings() * r.num_fit_samples;
  r.excluded = run.excluded;
  r.length_excluded = run.length_excluded;
  if (!g.enabled) return CalibrationStatus::kOk;
  const int num_samples = static_cast<int>(run.data.samples.size());
  for (int t = 0; t < num_samples && !run.excluded.empty(); ++t) {
    for (int i = 0; i < run.Readings(); ++i) {
      if (!ReadingExcluded(run, t, i)) continue;
      r.gross_errors.push_back(ReadingAt(run, t, i));
      ++(i < kNumCables ? g.count[i] : g.length_count[i - kNumCables]);
    }
  }
  g.fitted_flagged = CountExcluded(run);
  int far = 0;
  const ReadingResidual* first_far = nullptr;
  for (int t : run.fit) {
    for (int i = 0; i < run.Readings(); ++i) {
      if (std::abs(ReadingWhitened(run, t, i)) <= g.threshold_sigmas) continue;
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
  return run.Fail(
      CalibrationStatus::kMostlyGrossErrors,
      message + "the first is " + SampleWhere(run.data, run.data.samples[first.sample]) +
          (first.length ? " length of cable " : " cable ") + std::to_string(first.cable));
}

// Whether the first prediction is the RMS table's initial-model row at the fit's attitude:
// the table's statics (exact) of the input model itself (no spec value in place of one of
// its parameters; Evaluate predicts with `run.model`).
bool PredictionIsInitialRow(const Run& run) {
  if (!run.options.evaluate || run.spec.forward_model != StaticsMethod::kExact) return false;
  return std::none_of(run.spec.parameters.begin(), run.spec.parameters.end(),
                      [](const ParameterSpec& p) { return p.has_initial; });
}

// Stage: the initial model's readings, screened for gross errors.
CalibrationStatus PredictAndScreen(Run& run) {
  const CalibrationStatus status = Predict(run);
  if (status != CalibrationStatus::kOk) return status;
  if (PredictionIsInitialRow(run)) run.initial_reading_n = run.at.reading_n;
  internal::WhitenPrediction(run.slow, run.View(), &run.at.whitened);
  run.excluded = ScreenReadings(run, &run.length_excluded);
  run.initial_length_m = run.at.length_m;
  return status;
}

// Stage: the problem with the initial weights, and the refusal of a free set the data
// and priors cannot determine.
CalibrationStatus BuildAndCheck(Run& run) {
  BuildProblem(run);
  return CheckIdentifiability(run);
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
    if (options.should_stop && options.should_stop()) {
      return run.Fail(CalibrationStatus::kCancelled, kCancelledMessage);
    }
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
      options.progress(
          "sensor offsets stepped between sessions: fitting again with their "
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
