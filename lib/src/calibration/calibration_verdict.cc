// The calibration's parameter table, verdict and notes, and the model against the
// measurements before and after: stages over one run's state (calibration_run.h).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "calibration/calibration_run.h"
#include "fastcal/internal/calibration_evaluation.h"
#include "fastcal/internal/identifiability.h"
#include "fastcal/model_plausibility.h"
#include "fastcal/sensor_steps.h"
#include "fastcal/sessions.h"

namespace fastcal::internal {
namespace {

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

// The largest angle (deg) between the measured frame's axis `component` in the world,
// R_m e_j, over the fitted samples and its mean direction: how far the survey turns it.
// An offset along an axis the data never turn moves every sample's cabin by the same
// vector (measured_frame.h (4)), which the tensions see only through the cables'
// geometry, like a common shift of the towers.
double MeasuredAxisTurnDeg(const Run& run, int component) {
  const auto axis = [&](int t) -> Eigen::Vector3d {
    const Sample& s = run.data.samples[t];
    return (run.spec.use_planned_attitude ? s.planned_rotation : s.pose.rotation).col(component);
  };
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int t : run.fit) mean += axis(t);
  if (!(mean.norm() > 0.0)) return 180.0;
  mean.normalize();
  double smallest_cos = 1.0;
  for (int t : run.fit) smallest_cos = std::min(smallest_cos, mean.dot(axis(t)));
  constexpr double kDegPerRad = 57.29577951308232;
  return std::acos(std::clamp(smallest_cos, -1.0, 1.0)) * kDegPerRad;
}

// A measured frame's offset along an axis the survey turns by less than this (deg) is
// marked: the survey gives it only the constant shift of every cabin position.
constexpr double kUnturnedAxisDeg = 1.0;

std::string MeasuredOffsetNote(const Run& run, const ParameterSpec& p) {
  if (p.kind != ParameterKind::kMeasuredOffset || run.fit.empty()) return "";
  const double turn = MeasuredAxisTurnDeg(run, p.component);
  if (turn >= kUnturnedAxisDeg) return "";
  return "the data never turn this axis (by " + Fixed("%.2g", turn) +
         " deg at most): it shifts every cabin position alike, seen only through the cables' "
         "geometry";
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
    if (const std::string unturned = MeasuredOffsetNote(run, p); !unturned.empty()) {
      e.note = unturned + (e.note.empty() ? "" : "; " + e.note);
    }
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

// Model minus measured lengths per cable over the fitted samples (`held_out` false) or
// the held-out ones, the gross errors left out.
LengthResidualStats LengthStats(const Run& run,
                                const std::vector<std::array<double, kNumCables>>& model_m,
                                bool held_out) {
  LengthResidualStats s;
  std::array<double, kNumCables> sum{}, sum2{};
  std::array<int, kNumCables> count{};
  for (size_t t = 0; t < model_m.size(); ++t) {
    if (run.result->held_out[t] != held_out) continue;
    ++s.samples;
    for (int i = 0; i < kNumCables; ++i) {
      if (!run.length_excluded.empty() && run.length_excluded[t][i]) {
        ++s.excluded[i];
        continue;
      }
      const double d = model_m[t][i] - run.data.samples[t].unstretched_length_m[i];
      sum[i] += d;
      sum2[i] += d * d;
      s.max_abs_m[i] = std::max(s.max_abs_m[i], std::abs(d));
      ++count[i];
    }
  }
  for (int i = 0; i < kNumCables; ++i) {
    if (count[i] == 0) continue;
    s.mean_m[i] = sum[i] / count[i];
    s.rms_m[i] = std::sqrt(sum2[i] / count[i]);
  }
  return s;
}

void EvaluateLengths(Run& run) {
  LengthEvaluation& l = run.result->lengths;
  if (!run.spec.UsesLengths()) return;
  l.used = true;
  l.sigma_m = run.spec.length_sigma_m;
  l.initial = LengthStats(run, run.initial_length_m, false);
  l.calibrated = LengthStats(run, run.at.length_m, false);
  l.initial_holdout = LengthStats(run, run.initial_length_m, true);
  l.calibrated_holdout = LengthStats(run, run.at.length_m, true);
  run.initial_length_m = std::vector<std::array<double, kNumCables>>();
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Stage: the model against the measurements before and after (the paper's Table 6):
// the initial model at each attitude the data has and the calibrated one at the fit's,
// exact statics, gross errors left out; with lengths in the fit their residuals too.
CalibrationStatus Evaluate(Run& run) {
  CalibrationResult& r = *run.result;
  EvaluateLengths(run);
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
  inputs.initial_readings = &run.initial_reading_n;  // empty unless PredictAndScreen kept it
  inputs.initial_attitude =
      run.spec.use_planned_attitude ? AttitudeSource::kPlanned : AttitudeSource::kMeasured;
  std::string why;
  const bool ok =
      internal::EvaluateBeforeAndAfter(run.model, run.spec, run.data, r, inputs, &r.variants, &why);
  run.at = Prediction();
  run.initial_reading_n = std::vector<std::array<double, kNumCables>>();
  if (!ok) {
    return run.Fail(CalibrationStatus::kInfeasible, why);
  }
  return CalibrationStatus::kOk;
}

namespace {

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

}  // namespace

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

namespace {}  // namespace

// The sensor-step test's verdict beside the refit's own.
void AddSensorStepVerdict(CalibrationResult* r) {
  const std::string steps = SensorStepVerdict(r->sensor_steps);
  if (steps.empty()) return;
  r->verdict_text += "; " + steps;
}

namespace {}  // namespace
}  // namespace fastcal::internal
