// The calibration and evaluation report (report.h): the content is built once as a small
// document (headings, paragraphs, lists, tables, preformatted blocks, SVG figures) and then
// rendered as Markdown and as self-contained HTML (report_render.cc); summary.json is written
// directly with JsonWriter. Tensions are converted N -> kN here, at the edge, and only here.
#include "fastcal/report.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/paper_reference.h"
#include "fastcal/internal/report_document.h"
#include "fastcal/internal/report_sections.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/units.h"
#include "fastcal/svg_plot.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

// The report's document model and number formatting (internal/report_document.h).
using internal::Block;
using internal::CorrelationRows;
using internal::CorrelationUsable;
using internal::Document;
using internal::EstimateText;
using internal::Int;
using internal::Kn3;
using internal::NumHeldOut;
using internal::NumSamples;
using internal::Pct;
using internal::Printf;
using internal::RenderJson;
using internal::RmsAllCables;
using internal::Sig3;
using internal::Sig6;
using internal::Span;
using internal::Table;
using internal::Target;
using internal::Text;

using internal::kNPerKn;
// Defaults of CalibrationOptions, quoted in the text (the result does not carry them):
// taken from the struct, so that the text follows a change of them.
const double kDefaultPoorlyDeterminedRatio = CalibrationOptions().poorly_determined_ratio;
const double kDefaultUndeterminedRatio = CalibrationOptions().undetermined_ratio;
const double kDefaultStrongCorrelation = CalibrationOptions().strong_correlation;
// Plot geometry (px) and histogram bins.
constexpr int kCablePlotWidthPx = 540, kCablePlotHeightPx = 280;
constexpr int kWidePlotWidthPx = 1000, kWidePlotHeightPx = 320;
constexpr int kResidualBins = 40;
// Longer plot series are thinned (ThinMinMaxPerBucket): at most this many points each,
// about two per horizontal pixel of a cable plot; this bounds report.html's size.
constexpr int kMaxPlotPointsPerSeries = 2000;
// Measured tensions in the time plots: small translucent dots under the model lines
// (the held-out ones, sky blue, less translucent to stay visible on white).
constexpr double kMeasuredDotRadiusPx = 1.8, kMeasuredDotOpacity = 0.45, kHeldOutDotOpacity = 0.7;
// Gross errors on the tension plots: larger, opaque and red (no series' palette colour).
constexpr double kGrossDotRadiusPx = 3.5;
constexpr char kGrossErrorColour[] = "#C00000";
// How far beyond the other series' range (a fraction of it) a gross error is drawn at most.
constexpr double kGrossMargin = 0.08;

// ---------------------------------------------------------------------------------------
// Facts derived from the inputs, shared by the document and the JSON.

bool AnyHoldout(const ReportInputs& in) {
  for (const VariantEvaluation& v : in.variants) {
    if (v.holdout.samples > 0) return true;
  }
  return false;
}
bool IsHeldOut(const ReportInputs& in, size_t n) {
  return in.result && n < in.result->held_out.size() && in.result->held_out[n];
}
// Label of the samples a variant's `fit` statistics cover.
std::string FitSamplesLabel(const ReportInputs& in) {
  return in.result ? "fitted samples" : "all samples";
}

// Indices of the variants drawn in the time and residual plots: with a calibration the
// one before the calibrated model and the calibrated model, otherwise all.
std::vector<size_t> PlotVariants(const ReportInputs& in) {
  std::vector<size_t> out;
  const size_t n = in.variants.size();
  if (in.result && n >= 2) return {n - 2, n - 1};
  for (size_t i = 0; i < n; ++i) out.push_back(i);
  return out;
}
bool HasPredictions(const ReportInputs& in, const VariantEvaluation& v) {
  return in.data && !in.data->samples.empty() && v.predicted_n.size() == in.data->samples.size();
}

// The first and last time of the samples (inf, -inf for none).
std::pair<double, double> TimeRange(const ReportInputs& in) {
  if (in.sample_stream != nullptr) {
    return {in.sample_stream->time_min_s, in.sample_stream->time_max_s};
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Sample& s : in.data->samples) {
    lo = std::min(lo, s.time_s);
    hi = std::max(hi, s.time_s);
  }
  return {lo, hi};
}

std::string NoiseText(const CalibrationSpec& spec) {
  return "σ = √[(" + Printf("%.6g", spec.tension_sigma_n / kNPerKn) + " kN)² + (" +
         Printf("%.6g", spec.tension_sigma_percent) + " % of the predicted reading)²]";
}

// One-line meaning of the reduced chi-square.
std::string ChiSquareMeaning(const CalibrationResult& r) {
  const double chi = r.reduced_chi_square;
  if (!std::isfinite(chi)) return "not available.";
  const ChiSquareBand band = ReducedChiSquareBand(r);
  const int dof = band.degrees_of_freedom;
  const std::string sigmas = Printf("%g", kChiSquareBandSigmas);
  const std::string expected =
      dof > 0
          ? " (expected 1 ± " + sigmas + "·√(2/ν) = 1 ± " + Sig3(band.half_width) + ": within " +
                sigmas + " standard deviations of χ²/ν for a correct noise model, ν = " + Int(dof) +
                " degrees of freedom)"
          : "";
  if (band.within) {
    return "about 1: the residuals scatter as the noise model says" + expected + ".";
  }
  if (chi > 1.0) {
    return "above 1: model error the free parameters cannot absorb, or noise underestimated" +
           expected + ". σ_total below is scaled by at least √(χ²/ν) = " + Sig3(std::sqrt(chi)) +
           "; the formal σ is for the stated noise.";
  }
  return "below 1: the noise is overestimated (the residuals are smaller than the stated "
         "σ)" +
         expected + "; the ±1σ uncertainties below are then pessimistic.";
}

// ---------------------------------------------------------------------------------------
// Document sections.

Text FileText(const std::string& path, const std::string& digest, const char* absent) {
  Text t;
  if (path.empty()) return Text(absent);
  t.Code(path);
  if (!digest.empty()) t.Plain(" (SHA-256 ").Code(digest).Plain(")");
  return t;
}

void AddProvenance(const ReportInputs& in, Document* doc) {
  doc->Heading(2, "Provenance");
  Table t;
  t.header = {"Item", "Value"};
  t.right_align = {false, false};
  auto row = [&t](const Text& key, const Text& value) { t.rows.push_back({key, value}); };
  row("Model", FileText(in.model_path, in.model_digest, "nominal FAST model (built in)"));
  if (in.spec || !in.spec_path.empty()) {
    row("Calibration spec", FileText(in.spec_path, in.spec_digest, "given in code"));
  }
  Text data = FileText(in.data_path, in.data_digest, "given in code");
  if (!in.columns_path.empty()) {
    data.Plain(", read through the column map ").Code(in.columns_path);
    if (!in.columns_digest.empty()) data.Plain(" (SHA-256 ").Code(in.columns_digest).Plain(")");
  }
  if (in.data) {
    const Dataset& d = *in.data;
    data.Plain(": " + Int(NumSamples(in)) + " samples");
    if (NumSamples(in) > 0) {
      const auto [lo, hi] = TimeRange(in);
      data.Plain(", " + TimeRangeText(lo, hi, TimeDisplayFor(lo, d.time_offset_s)));
    }
    data.Plain(d.attitude_as_quaternion ? ", attitude as quaternion" : ", attitude as angles");
    if (d.has_planned_attitude) data.Plain(", with planned attitude");
    if (!d.skipped.empty())
      data.Plain(", " + Int(static_cast<long long>(d.skipped.size())) +
                 (d.skipped.size() == 1 ? " row" : " rows") +
                 " skipped: malformed, or a pose the model cannot solve (listed at the end)");
  } else {
    data.Plain(" (no dataset given)");
  }
  row("Data", data);
  if (!in.simulated_provenance.empty()) {
    Text header("simulated: ");
    size_t start = 0;
    while (start < in.simulated_provenance.size()) {
      const size_t end =
          std::min(in.simulated_provenance.find('\n', start), in.simulated_provenance.size());
      header.Plain(start == 0 ? "" : "; ").Code(in.simulated_provenance.substr(start, end - start));
      start = end + 1;
    }
    row("Data's header", header);
  }
  if (const CableRobot* model = in.initial_model != nullptr ? in.initial_model
                                : in.result != nullptr      ? &in.result->calibrated
                                                            : nullptr) {
    // Whose pose x_m..z_m and the attitude give (measured_frame.h): the cabin's own, or
    // the model's cabin.measured_frame, through which every statics call goes.
    const MeasuredFrame* frame = model->measured_frame ? &*model->measured_frame : nullptr;
    row("Data's poses", "x_m, y_m, z_m and the attitude are those of " +
                            DescribeMeasuredFrame(frame, model->moving_parts) +
                            (frame ? "" : "; a model declares another with cabin.measured_frame"));
  }
  row("Software",
      Text("fastcal ")
          .Plain(in.software_version.empty() ? "(version unknown)" : in.software_version));
  row("Command line",
      in.command_line.empty() ? Text("(not recorded)") : Text().Code(in.command_line));
  row("Run (UTC)", in.run_utc.empty() ? "(not recorded)" : in.run_utc);
  if (in.spec) {
    const CalibrationSpec& s = *in.spec;
    row("Forward model (in the fit)", Text().Code(StaticsMethodName(s.forward_model)));
    if (in.result && s.forward_model == StaticsMethod::kExact) {
      row("Forward model error vs exact", "none: the fit's forward model is exact");
    } else if (in.result) {
      row("Forward model error vs exact",
          Text("max " + Pct(in.result->forward_model_max_rel_error) + " %, RMS " +
               Pct(in.result->forward_model_rms_rel_error) +
               " % of the exact tension over the dataset poses (initial parameters); noise " +
               Printf("%.6g", s.tension_sigma_percent) + " %"));
    }
  }
  row("Evaluation statics",
      in.evaluation_method.empty() ? Text("(not recorded)") : Text().Code(in.evaluation_method));
  if (in.spec) {
    const CalibrationSpec& s = *in.spec;
    row("Noise model", NoiseText(s));
    row("Robust loss", s.robust_loss == RobustLoss::kNone
                           ? Text("none (least squares)")
                           : Text(std::string(RobustLossName(s.robust_loss)) + ", scale " +
                                  Sig6(s.robust_loss_scale) + " σ"));
    row("Attitude in the fit", s.use_planned_attitude ? "planned" : "measured");
    row("Gross errors", s.detect_gross_errors
                            ? "readings more than " + Sig3(s.gross_error_threshold_sigmas) +
                                  " robust σ from the model (more on a long dataset, see Gross "
                                  "errors) are kept out; refused above " +
                                  Sig3(100.0 * s.max_gross_error_fraction) + " % of them"
                            : std::string("not screened"));
    Text holdout("none: every sample is fitted");
    if (s.holdout_fraction > 0.0) {
      holdout =
          Text(Sig6(s.holdout_fraction) + " of the samples as whole contiguous blocks (of " +
               Int(s.holdout_blocks) + "), chosen with seed " + std::to_string(s.holdout_seed));
      if (in.result) holdout.Plain(": " + Int(NumHeldOut(in)) + " samples held out of the fit");
    }
    row("Hold-out", holdout);
    row("Cross-validation", Int(s.cross_validation_blocks) + " contiguous blocks");
    row("Ceres options", "max " + Int(s.max_iterations) + " iterations; function, gradient, " +
                             "parameter tolerance " + Sig3(s.function_tolerance) + ", " +
                             Sig3(s.gradient_tolerance) + ", " + Sig3(s.parameter_tolerance) +
                             "; " + Int(s.num_threads) + " threads");
  }
  if (in.result) row("Solve time", Printf("%.3g", in.result->seconds) + " s");
  doc->AddTable(std::move(t));
}

std::string RmsAllText(const VariantEvaluation& v, bool holdout) {
  const CableErrorStats& s = holdout ? v.holdout : v.fit;
  return Kn3(RmsAllCables(s.rms_n)) + " kN";
}

void AddEvaluationSummary(const ReportInputs& in, Document* doc) {
  doc->Heading(2, "Summary");
  Text t("Model tensions (statics: " +
         (in.evaluation_method.empty() ? std::string("?") : in.evaluation_method) +
         ", with the model's sensor gain and bias) against the " + Int(NumSamples(in)) +
         " measured samples. RMS of model - measured over all six cables: ");
  if (in.variants.empty()) t.Plain("no variant was evaluated.");
  for (size_t i = 0; i < in.variants.size(); ++i) {
    t.Plain(i ? "; " : "").Plain(in.variants[i].name + " ").Bold(RmsAllText(in.variants[i], false));
    if (i + 1 == in.variants.size()) t.Plain(".");
  }
  doc->Paragraph(t);
}

// The verdict's first paragraph and the notes a reader needs beside it.
void AddVerdictLead(const CalibrationResult& r, Document* doc) {
  // The verdict's colour says at a glance whether to use the result: green sound, blue
  // sound with pessimistic sigmas, amber usable with the misfit in sigma_total, red not
  // to be used as it stands.
  const char* lead = "Good fit:";
  internal::Tone tone = internal::Tone::kGood;
  switch (r.verdict) {
    case FitVerdict::kOk:
      break;
    case FitVerdict::kNoiseOverstated:
      lead = "Noise overstated:";
      tone = internal::Tone::kInfo;
      break;
    case FitVerdict::kMisfit:
      lead = "Misfit, scaled into the uncertainties:";
      tone = internal::Tone::kCaution;
      break;
    case FitVerdict::kFailed:
      lead = "The fit failed:";
      tone = internal::Tone::kBad;
      break;
    case FitVerdict::kModelIncomplete:
      lead = "Model incomplete:";
      tone = internal::Tone::kBad;
      break;
  }
  doc->Banner(tone, Text().Bold(lead).Plain(" " + r.verdict_text + "."));
  std::vector<Text> notes;
  if (!r.gross_errors.empty()) {
    notes.push_back(Int(static_cast<long long>(r.gross_errors.size())) +
                    (r.gross_errors.size() == 1 ? " reading was flagged as a gross error"
                                                : " readings were flagged as gross errors") +
                    " and kept out of the fit (see Gross errors and worst readings).");
  }
  for (const std::string& note : r.notes) notes.push_back(note + ".");
  if (!r.misfit_ranking.empty() && r.misfit_ranking.front().significant) {
    notes.push_back(Text("The misfit is best explained by freeing ")
                        .Code(r.misfit_ranking.front().name)
                        .Plain(" (see What would explain the misfit)."));
  }
  doc->List(std::move(notes));
}

void AddVerdict(const ReportInputs& in, Document* doc) {
  if (!in.result) {
    AddEvaluationSummary(in, doc);
    return;
  }
  const CalibrationResult& r = *in.result;
  doc->Heading(2, "Verdict");
  AddVerdictLead(r, doc);
  Text t;
  if (r.converged) {
    t.Bold("Converged");
  } else {
    t.Bold("Did not converge");
  }
  t.Plain(" (termination: ")
      .Code(r.termination.empty() ? "unknown" : r.termination)
      .Plain(") after " + Int(r.iterations) + " iterations; cost " + Sig6(r.initial_cost) + " → " +
             Sig6(r.final_cost) + ".");
  if (!r.converged) {
    t.Plain(" The estimates below are the last iterate: do not use them as they are.");
  }
  doc->Paragraph(t);
  doc->Paragraph(Text("Reduced chi-square χ²/ν = ")
                     .Bold(Printf("%.4g", r.reduced_chi_square))
                     .Plain(" over " + Int(r.num_residuals) + " residuals and " + Int(r.num_free) +
                            " free parameters: " + ChiSquareMeaning(r)));
  const int total = NumSamples(in);
  Text samples("Samples: " + Int(r.num_fit_samples) + " fitted, " + Int(NumHeldOut(in)) +
               " held out (" + Int(total) + " in the dataset).");
  const size_t n = in.variants.size();
  if (n >= 2) {
    const VariantEvaluation& before = in.variants[n - 2];
    const VariantEvaluation& after = in.variants[n - 1];
    samples
        .Plain(" RMS of model - measured over all cables, fitted samples: " + before.name + " " +
               RmsAllText(before, false) + " → " + after.name + " ")
        .Bold(RmsAllText(after, false));
    if (after.holdout.samples > 0) {
      samples.Plain("; held-out samples: " + RmsAllText(before, true) + " → ")
          .Bold(RmsAllText(after, true));
    }
    samples.Plain(".");
  }
  doc->Paragraph(samples);
  if (!r.covariance_ok) {
    doc->Paragraph(Text()
                       .Bold("The covariance could not be computed:")
                       .Plain(" the estimates have no uncertainties and no correlations."));
  }
  const size_t weak = r.after.undetermined.size() + r.after.poorly_determined.size() +
                      r.data_only.undetermined.size() + r.data_only.poorly_determined.size();
  if (weak > 0) {
    doc->Paragraph("Identifiability: " + Int(static_cast<long long>(weak)) +
                   " direction(s) in parameter space are poorly determined or held only by a "
                   "prior; see Identifiability below.");
  }
}

// From this many alike fixed parameters of one group on, the Estimates table shows them as
// one row.
constexpr size_t kCollapsedFrom = 4;

// The number of parameters from `first` on that are fixed, of the group of `first`
// ("tower_offset_m" of "tower_offset_m[2].z") and alike in every column of the table.
size_t AlikeFixedRun(const std::vector<ParameterEstimate>& all, size_t first) {
  const auto group = [](const std::string& name) {
    return name.substr(0, name.find_first_of("[.@"));
  };
  const ParameterEstimate& a = all[first];
  size_t n = 0;
  for (size_t k = first; k < all.size(); ++k, ++n) {
    const ParameterEstimate& b = all[k];
    const bool same = !b.free && group(b.name) == group(a.name) && b.unit == a.unit &&
                      b.initial == a.initial && b.estimate == a.estimate &&
                      b.consider == a.consider && b.sigma_total == a.sigma_total &&
                      b.has_prior == a.has_prior && b.prior_mean == a.prior_mean &&
                      b.prior_sigma == a.prior_sigma && b.note.empty() && b.moved_by.empty();
    if (!same) break;
  }
  return n;
}

void AddEstimates(const CalibrationResult& r, Document* doc) {
  doc->Heading(2, "Estimates");
  doc->Paragraph(
      "± σ_total: the uncertainty to quote (see Uncertainty budget); formal σ: for the "
      "stated noise and independent samples only. Priors are Gaussian, mean ± σ. Sensor "
      "biases are in kN, like the spec. Fixed parameters keep their initial value; a "
      "consider parameter (fixed, with a prior) shows its prior σ. Four or more alike "
      "fixed parameters of one group are one row (summary.json lists each).");
  Table t;
  t.header = {"Parameter", "Unit",     "Initial", "Estimate", "± σ_total",
              "formal σ",  "widening", "Prior",   "Note"};
  t.right_align = {false, false, true, true, true, true, true, true, false};
  for (size_t k = 0; k < r.parameters.size(); ++k) {
    const ParameterEstimate& p = r.parameters[k];
    // A run of fixed parameters of one group that are all alike (tower_offset_m: 18 zeros
    // with one consider prior) is one row, not a screenful of identical ones.
    const size_t alike = AlikeFixedRun(r.parameters, k);
    if (alike >= kCollapsedFrom) {
      const ParameterEstimate& last = r.parameters[k + alike - 1];
      t.rows.push_back({Text().Code(p.name).Plain(" … ").Code(last.name).Plain(
                            " (" + Int(static_cast<long long>(alike)) + ", all alike)"),
                        p.unit, Sig6(p.initial), Text(Sig6(p.estimate)),
                        p.consider ? Sig3(p.sigma_total) + " (consider)" : "fixed", "", "",
                        p.has_prior ? Sig6(p.prior_mean) + " ± " + Sig3(p.prior_sigma) : "-", ""});
      k += alike - 1;
      continue;
    }
    std::string total = "fixed", formal = "", widening = "";
    if (p.consider) total = Sig3(p.sigma_total) + " (consider)";
    if (p.free) {
      total = r.covariance_ok ? Sig3(p.sigma_total) : "n/a";
      formal = r.covariance_ok ? Sig3(p.sigma) : "n/a";
      widening = r.covariance_ok ? "× " + Printf("%.3g", p.widening) : "";
    }
    const std::string prior = p.has_prior ? Sig6(p.prior_mean) + " ± " + Sig3(p.prior_sigma) : "-";
    Text note(p.note);
    if (!p.moved_by.empty()) {
      note = Text()
                 .Bold("Not sound:")
                 .Plain(p.moved_by.rfind("prior of ", 0) == 0 ? " releasing the " : " freeing ")
                 .Code(p.moved_by)
                 .Plain(" would move it by " + Sig3(p.moved_by_shift) + " " + p.unit + " (" +
                        Printf("%.1f", p.moved_by_sigmas) + " σ_total)" +
                        (p.note.empty() ? "" : "; " + p.note));
    }
    t.rows.push_back(
        {Text().Code(p.name), p.unit, Sig6(p.initial),
         p.free ? Text().Bold(EstimateText(p.estimate, r.covariance_ok ? p.sigma_total : 0.0))
                : Text(Sig6(p.estimate)),
         p.free ? Text().Bold(total) : Text(total), formal, widening, prior, note});
  }
  if (t.rows.empty()) {
    doc->Paragraph("The spec names no parameter.");
    return;
  }
  doc->AddTable(std::move(t));
}

std::string RatioText(double ratio) { return "s/s1 = " + Printf("%.2g", ratio); }

// The singular-value ratios before, after, and of the data alone, side by side.
void AddSingularValueTable(const CalibrationResult& r, Document* doc) {
  const size_t rows =
      std::max({r.before.singular_value_ratios.size(), r.after.singular_value_ratios.size(),
                r.data_only.singular_value_ratios.size()});
  if (rows == 0) return;
  Table t;
  t.header = {"k", "s/s1 before (with priors)", "s/s1 after (with priors)",
              "s/s1 after (data alone)"};
  t.right_align = {true, true, true, true};
  auto cell = [](const std::vector<double>& v, size_t k) -> Text {
    return k < v.size() ? Text(Printf("%.3g", v[k])) : Text("-");
  };
  for (size_t k = 0; k < rows; ++k) {
    t.rows.push_back({Int(static_cast<long long>(k + 1)), cell(r.before.singular_value_ratios, k),
                      cell(r.after.singular_value_ratios, k),
                      cell(r.data_only.singular_value_ratios, k)});
  }
  doc->AddTable(std::move(t));
}

// The undetermined and poorly determined directions, or that there are none.
void AddWeakDirections(const CalibrationResult& r, Document* doc) {
  // One item per direction: lead, the direction, its ratio in parentheses, the tail.
  std::vector<Text> items;
  auto add = [&items](const std::vector<ParameterDirection>& directions, const Text& lead,
                      const std::string& open, const std::string& tail) {
    for (const ParameterDirection& d : directions) {
      items.push_back(
          Text(lead).Code(d.Describe()).Plain(open + RatioText(d.singular_value_ratio) + tail));
    }
  };
  add(r.before.undetermined, "Before solving, undetermined: ", " (", ").");
  add(r.before.poorly_determined, "Before solving, poorly determined: ", " (", ").");
  add(r.after.undetermined, Text().Bold("Undetermined").Plain(" at the solution: "), " (",
      "): the data and priors cannot fix this combination.");
  add(r.after.poorly_determined, Text().Bold("Poorly determined").Plain(" at the solution: "), " (",
      "): its estimate is uncertain; see the ±1σ column.");
  add(r.data_only.undetermined, "The data alone cannot determine ", " (", "); the prior holds it.");
  add(r.data_only.poorly_determined, "The data alone determine ", " only poorly (",
      "); the prior helps fix it.");
  const bool nothing_weak = r.after.undetermined.empty() && r.after.poorly_determined.empty() &&
                            r.data_only.undetermined.empty() &&
                            r.data_only.poorly_determined.empty();
  if (nothing_weak) {
    int prior_set = 0;
    for (const ParameterEstimate& p : r.parameters) {
      prior_set += p.note.find("set mostly by its prior") != std::string::npos;
    }
    doc->Paragraph(
        prior_set == 0
            ? "Nothing is poorly determined: every free parameter is fixed by the data alone, "
              "without help from a prior."
            : "No combination of parameters is poorly determined by the data alone, but " +
                  Int(prior_set) +
                  " estimate(s) are set mostly by their prior (see Estimates): the data "
                  "inform them less than the prior does.");
  }
  doc->List(std::move(items));
}

// Strongly correlated pairs, and the correlation matrix (a table in Markdown, a heatmap
// in HTML).
void AddCorrelations(const CalibrationResult& r, bool with_plots, Document* doc) {
  if (!r.strong_correlations.empty()) {
    std::vector<Text> pairs;
    for (const std::string& c : r.strong_correlations) pairs.push_back(Text().Code(c));
    doc->Paragraph("Strongly correlated pairs of estimates (|correlation| above " +
                   Sig3(kDefaultStrongCorrelation) +
                   " by default): the data fix their combination better than each one.");
    doc->List(std::move(pairs));
  } else if (r.covariance_ok) {
    doc->Paragraph("No pair of estimates is strongly correlated (|correlation| above " +
                   Sig3(kDefaultStrongCorrelation) + " by default).");
  }
  if (!CorrelationUsable(r)) return;
  const std::vector<std::vector<double>> m = CorrelationRows(r);
  Table t;
  t.caption = "Correlation of the estimates";
  t.header.push_back("");
  t.right_align.push_back(false);
  for (const std::string& name : r.free_names) {
    t.header.push_back(Text().Code(name));
    t.right_align.push_back(true);
  }
  for (size_t i = 0; i < m.size(); ++i) {
    std::vector<Text> row = {Text().Code(r.free_names[i])};
    for (double v : m[i]) row.push_back(Printf("%+.2f", v));
    t.rows.push_back(std::move(row));
  }
  doc->AddTable(std::move(t), Target::kMarkdownOnly);
  if (with_plots) {
    const int n = static_cast<int>(r.free_names.size());
    PlotOptions o;
    o.title = "Correlation of the estimates";
    o.width_px = std::clamp(260 + 56 * n, 420, kWidePlotWidthPx);
    o.height_px = std::clamp(200 + 44 * n, 320, 1400);
    doc->Figure({SvgMatrixHeatmap(r.free_names, m, o)},
                "Correlation of the free parameters' estimates (1: move together, -1: "
                "opposite, 0: independent).");
  }
}

void AddIdentifiability(const CalibrationResult& r, bool with_plots, Document* doc) {
  doc->Heading(2, "Identifiability");
  doc->Paragraph(
      "Singular values s of the whitened Jacobian (data and prior rows) with unit-norm "
      "columns, relative to the largest (s/s1). A small ratio is a combination of parameters "
      "the measurements barely change: below " +
      Sig3(kDefaultPoorlyDeterminedRatio) + " it is reported as poorly determined, below " +
      Sig3(kDefaultUndeterminedRatio) +
      " as undetermined (default thresholds). \"Data alone\" leaves the priors out.");
  AddSingularValueTable(r, doc);
  AddWeakDirections(r, doc);
  AddCorrelations(r, with_plots, doc);
}

// Which rows a statistics table has: each variant's statistics on the fitted (or all)
// samples, on the held-out samples, or both (then suffixed "(fit)" and "(held out)").
enum class StatsRows { kFit, kHeldOut, kFitAndHeldOut };

// One statistics table: a row per variant and kind of samples; variants without held-out
// samples have no held-out row.
Table StatsTable(const ReportInputs& in, const Text& caption,
                 const std::array<double, kNumCables> CableErrorStats::*member, bool kn,
                 StatsRows rows, const char* format) {
  Table t;
  t.caption = caption;
  t.header = {"Variant", "Samples"};
  t.right_align = {false, true};
  for (int i = 1; i <= kNumCables; ++i) {
    t.header.push_back("T" + Int(i));
    t.right_align.push_back(true);
  }
  const bool all_column = member == &CableErrorStats::rms_n;
  if (all_column) {
    t.header.push_back("all");
    t.right_align.push_back(true);
  }
  const bool both = rows == StatsRows::kFitAndHeldOut;
  auto add_rows = [&](bool holdout, const std::string& suffix) {
    for (size_t k = 0; k < in.variants.size(); ++k) {
      const VariantEvaluation& v = in.variants[k];
      const CableErrorStats& s = holdout ? v.holdout : v.fit;
      if (holdout && s.samples == 0) continue;
      std::vector<Text> row = {
          Text().Swatch(PlotSeriesColour(static_cast<int>(k))).Plain(v.name + suffix),
          Int(s.samples)};
      for (double x : s.*member) row.push_back(kn ? Kn3(x) : Printf(format, x));
      if (all_column) row.push_back(Text().Bold(Kn3(RmsAllCables(s.rms_n))));
      t.rows.push_back(std::move(row));
    }
  };
  if (rows != StatsRows::kHeldOut) add_rows(false, both ? " (fit)" : "");
  if (rows != StatsRows::kFit) add_rows(true, both ? " (held out)" : "");
  return t;
}

std::string BarChart(const ReportInputs& in, bool holdout) {
  std::vector<BarGroup> groups;
  for (int i = 0; i < kNumCables; ++i) {
    BarGroup g;
    g.label = "T" + Int(i + 1);
    for (const VariantEvaluation& v : in.variants) {
      const CableErrorStats& s = holdout ? v.holdout : v.fit;
      g.values.push_back(s.samples > 0 ? s.rms_n[i] / kNPerKn
                                       : std::numeric_limits<double>::quiet_NaN());
    }
    groups.push_back(std::move(g));
  }
  std::vector<std::string> names;
  for (const VariantEvaluation& v : in.variants) names.push_back(v.name);
  PlotOptions o;
  o.title = std::string("RMS of model - measured per cable, ") +
            (holdout ? "held-out samples" : FitSamplesLabel(in));
  o.y_label = "RMS [kN]";
  o.width_px = kWidePlotWidthPx;
  o.height_px = kWidePlotHeightPx;
  return SvgGroupedBars(groups, names, o);
}

ReportSampleStream SamplesOf(const ReportInputs& in);

// Whether the samples fly the paper's measured circle (PaperCircleMatcher): then its
// Table 6 goes beside this one. A replay of the samples, held or streamed.
bool FliesPaperCircle(const ReportInputs& in) {
  if (in.data == nullptr || NumSamples(in) == 0) return false;
  PaperCircleMatcher matcher;
  std::string ignored;
  const bool read = SamplesOf(in).replay(
      [&matcher](const ReportSample& s) { matcher.Add(s.position_m); }, &ignored);
  return read && matcher.Matches();
}

// The paper's published RMS (its Table 6, real telemetry of FAST on that circle), each
// row beside the variant of this report it corresponds to.
void AddPaperTable6(bool simulated, Document* doc) {
  Table t;
  t.caption = simulated ? "The paper's Table 6, the same circle on the real telescope (these "
                          "data are simulated): RMS [kN]"
                        : "The paper's Table 6, the same circle on the telescope: RMS [kN]";
  t.header = {"", "as this report's", "T1", "T2", "T3", "T4", "T5", "T6"};
  t.right_align = {false, false, true, true, true, true, true, true};
  for (const internal::PaperRmsRow& row : internal::kPaperTable6) {
    std::vector<Text> cells = {Text(row.label), Text(row.corresponds_to)};
    for (double v : row.rms_kn) cells.push_back(Printf("%.3f", v));
    t.rows.push_back(cells);
  }
  doc->AddTable(std::move(t));
  doc->Paragraph(
      "These data fly the paper's measured circle (radius 71.11 m about (0, 0, 156.73) m), "
      "so its published RMS is shown for comparison. The paper's come from the real "
      "telescope's sensors under PID control, with the AAS statics and the mass centre moved "
      "by hand to about (0.22, 0.11, 0.5) m; sensor error about 3%.");
  if (simulated) {
    doc->Paragraph(Text()
                       .Bold("These data are simulated")
                       .Plain(" (made by fastcal simulate, see the top of this report): their "
                              "RMS is the noise the simulation was given, not the telescope's. "
                              "A smaller RMS here than the paper's is no improvement over its "
                              "calibration; only the same measurement on the telescope can "
                              "show one."));
  }
}

void AddRmsTables(const ReportInputs& in, bool with_plots, Document* doc) {
  doc->Heading(2, "Model against measurement");
  const std::string method = in.evaluation_method.empty() ? "?" : in.evaluation_method;
  doc->Paragraph(Text("Model minus measured lower-end tension per cable (the paper's Table 6), "
                      "model tensions from the ")
                     .Code(method)
                     .Plain(" statics with the model's sensor gain and bias. \"all\": RMS over "
                            "the six cables."));
  if (in.variants.empty()) {
    doc->Paragraph("No model variant was evaluated.");
    return;
  }
  const int fit_n = in.variants.front().fit.samples;
  doc->AddTable(StatsTable(
      in, "RMS of model - measured [kN], " + FitSamplesLabel(in) + " (n = " + Int(fit_n) + ")",
      &CableErrorStats::rms_n, true, StatsRows::kFit, nullptr));
  if (FliesPaperCircle(in)) AddPaperTable6(!in.simulated_provenance.empty(), doc);
  const bool holdout = AnyHoldout(in);
  if (holdout) {
    int n = 0;
    for (const VariantEvaluation& v : in.variants)
      n = v.holdout.samples > 0 ? v.holdout.samples : n;
    doc->AddTable(StatsTable(
        in,
        "RMS of model - measured [kN], held-out samples (n = " + Int(n) + "; not used in the fit)",
        &CableErrorStats::rms_n, true, StatsRows::kHeldOut, nullptr));
  }
  if (with_plots) {
    std::vector<std::string> svgs = {BarChart(in, false)};
    if (holdout) svgs.push_back(BarChart(in, true));
    doc->Figure(std::move(svgs), "RMS of model - measured per cable for each variant [kN].");
  }
  const StatsRows rows = holdout ? StatsRows::kFitAndHeldOut : StatsRows::kFit;
  doc->AddTable(StatsTable(in, "RMS of 100 (model - measured) / model [%]",
                           &CableErrorStats::rms_percent, false, rows, "%.2f"));
  doc->AddTable(StatsTable(in, "Mean of model - measured (bias) [kN]", &CableErrorStats::mean_n,
                           true, rows, nullptr));
  doc->AddTable(StatsTable(in, "Largest |model - measured| [kN]", &CableErrorStats::max_abs_n, true,
                           rows, nullptr));
}

// Puts `item` at index `slot` of `v`, padding with empty (unnamed, pointless) series: the
// charts colour a series by its index, and a variant keeps its colour (its index in the
// RMS table, PlotSeriesColour) in every chart.
template <typename Series>
void PutAt(std::vector<Series>* v, size_t slot, Series item) {
  if (v->size() <= slot) v->resize(slot + 1);
  (*v)[slot] = std::move(item);
}

// Colour slots of the measured tensions: black, and sky blue for held-out samples, after
// the variants' slots.
size_t MeasuredSlot(const ReportInputs& in) { return std::max<size_t>(6, in.variants.size() + 1); }
size_t HeldOutSlot(const ReportInputs& in) {
  return in.variants.size() <= 5 ? 5 : in.variants.size();
}

// Says in a figure caption that its series were thinned (buckets > 0), and how.
std::string ThinningNote(int num_samples, int buckets) {
  if (buckets <= 0) return "";
  return " Thinned for drawing (min/max per bucket): each series of more than " +
         Int(kMaxPlotPointsPerSeries) + " points is cut into " + Int(buckets) +
         " buckets of consecutive samples (about " + Int((num_samples + buckets - 1) / buckets) +
         " per bucket for all " + Int(num_samples) +
         " samples) and only each bucket's lowest and highest value are plotted, so peaks "
         "and outliers stay visible. The tables and statistics use all samples.";
}

// The samples the plots draw, as a stream: in.sample_stream, or data->samples with the
// variants' predictions, the gross errors (calibrate's or evaluate's screen) and the
// held-out flags. Both are drawn by one code path, in two replays.
ReportSampleStream SamplesOf(const ReportInputs& in) {
  if (in.sample_stream != nullptr) return *in.sample_stream;
  ReportSampleStream out;
  const Dataset& d = *in.data;
  out.samples = static_cast<long long>(d.samples.size());
  std::tie(out.time_min_s, out.time_max_s) = TimeRange(in);
  out.is_trajectory = internal::IsTrajectory(d);
  for (const VariantEvaluation& v : in.variants)
    out.has_predictions.push_back(HasPredictions(in, v));
  const ReadingMask* gross = in.result              ? &in.result->excluded
                             : in.evaluation_screen ? &in.evaluation_screen->excluded
                                                    : nullptr;
  out.replay = [&in, &d, gross, has = out.has_predictions](
                   const std::function<void(const ReportSample&)>& visit, std::string*) {
    std::vector<std::array<double, kNumCables>> predicted(in.variants.size());
    ReportSample r;
    r.predicted_n = predicted.data();
    for (size_t n = 0; n < d.samples.size(); ++n) {
      r.time_s = d.samples[n].time_s;
      r.position_m = d.samples[n].pose.position_m;
      r.measured_n = d.samples[n].tension_n;
      for (size_t k = 0; k < predicted.size(); ++k) {
        if (has[k]) predicted[k] = in.variants[k].predicted_n[n];
      }
      for (int i = 0; i < kNumCables; ++i) {
        r.gross[i] = gross != nullptr && n < gross->size() && (*gross)[n][i];
      }
      r.held_out = IsHeldOut(in, n);
      visit(r);
    }
    return true;
  };
  return out;
}

// A series thinned as it is fed: min/max per bucket (ThinMinMaxPerBucket) along a
// trajectory, every k-th point (ThinEvenly) for unordered samples. Its length and whether
// it has a gap come from the first replay.
class SeriesThinner {
 public:
  SeriesThinner(PlotSeries style, size_t n, bool any_gap, bool even)
      : style_(std::move(style)),
        even_(even),
        stride_(std::max<size_t>(1, (n + kMaxPlotPointsPerSeries - 1) / kMaxPlotPointsPerSeries)),
        min_max_(n, any_gap, kMaxPlotPointsPerSeries) {}
  void Add(double x, double y) {
    if (!even_) return min_max_.Add(x, y);
    if (next_++ % stride_ != 0) return;
    style_.x.push_back(x);
    style_.y.push_back(y);
  }
  PlotSeries Finish() const { return even_ ? style_ : min_max_.Finish(style_); }
  // The stride (even) or the number of buckets (min/max, 0 when not thinned).
  int Thinning() const { return even_ ? static_cast<int>(stride_) : min_max_.buckets(); }

 private:
  PlotSeries style_;
  bool even_;
  size_t stride_, next_ = 0;
  MinMaxBucketThinner min_max_;
};

// A series' length and whether it has a non-finite point, from the first replay.
struct SeriesShape {
  size_t n = 0;
  bool any_gap = false;
  void Add(double x, double y) {
    ++n;
    any_gap = any_gap || !std::isfinite(x) || !std::isfinite(y);
  }
};

// What every time plot shares: the x axis, the variants drawn, and how.
struct TimePlots {
  const ReportInputs& in;
  ReportSampleStream samples;
  std::string x_label;
  bool use_time = false;
  TimeDisplay display;        // Unix times: a clock-time axis in the data's zone
  std::vector<size_t> shown;  // PlotVariants
  bool holdout = false;
  bool ordered = true;  // a trajectory: lines join the samples; else dots
  std::string not_drawn;

  std::string ThinningNote(int thinning) const {
    return ordered ? ::fastcal::ThinningNote(NumSamples(in), thinning)
                   : internal::EvenThinningNote(NumSamples(in), thinning);
  }

  TimePlots(const ReportInputs& inputs)  // NOLINT: a view of the inputs
      : in(inputs), samples(SamplesOf(inputs)), shown(PlotVariants(inputs)) {
    // x: time_s, or the sample index when time does not vary.
    use_time = std::isfinite(samples.time_min_s) && std::isfinite(samples.time_max_s) &&
               samples.time_max_s > samples.time_min_s;
    display = TimeDisplayFor(samples.time_min_s, in.data ? in.data->time_offset_s : 0);
    x_label = !use_time          ? "sample index"
              : display.absolute ? TimeAxisLabel(samples.time_min_s, samples.time_max_s, display)
                                 : "t [s]";
    holdout = NumHeldOut(in) > 0;
    ordered = samples.is_trajectory;
    if ((in.result && !in.result->gross_errors.empty()) ||
        (in.evaluation_screen && in.evaluation_screen->count > 0)) {
      not_drawn =
          " Gross errors (kept out of the fit) are the red dots on the tension plots, at the "
          "plot's edge when they lie far beyond its range; their residuals are not drawn.";
    }
  }
  double X(const ReportSample& s, long long n) const {
    return use_time ? s.time_s : static_cast<double>(n);
  }
  bool Predicted(size_t k) const {
    return k < samples.has_predictions.size() && samples.has_predictions[k];
  }
  // With a calibration the "before" variant is dashed, the calibrated one solid.
  PlotSeries Model(const std::string& name, size_t k) const {
    PlotSeries p{name, {}, {}, in.result != nullptr && k + 1 < shown.size(), !ordered};
    p.marker_radius_px = kMeasuredDotRadiusPx;
    return p;
  }
};

// Every series of the time plots and the histogram, per cable: the models' tensions
// (index k of `shown`), the measured ones (fitted, held out), the models' residuals
// (gross errors a gap).
struct TimeSeries {
  std::array<std::vector<SeriesShape>, kNumCables> model_shape, residual_shape;
  std::array<SeriesShape, kNumCables> fitted_shape, held_shape, gross_shape;
  double residual_lo = std::numeric_limits<double>::infinity(), residual_hi = -residual_lo;
  // Per cable, the range of the models' and the kept readings' tensions: a gross error
  // beyond it (a 99999 kN spike) is drawn at its edge, so that it cannot flatten the plot.
  std::array<double, kNumCables> tension_lo, tension_hi;
  TimeSeries() {
    tension_lo.fill(std::numeric_limits<double>::infinity());
    tension_hi.fill(-std::numeric_limits<double>::infinity());
  }
  void Span(int i, double y) {
    if (!std::isfinite(y)) return;
    tension_lo[i] = std::min(tension_lo[i], y);
    tension_hi[i] = std::max(tension_hi[i], y);
  }
  double OnScale(int i, double y) const {
    const double margin = kGrossMargin * (tension_hi[i] - tension_lo[i]);
    if (!(tension_hi[i] >= tension_lo[i]) || !std::isfinite(y)) return y;
    return std::clamp(y, tension_lo[i] - margin, tension_hi[i] + margin);
  }
};

// The points of every time series, in replay order: of cable i, the tension and the
// residual of variant shown[k] (a gross error's residual NaN: a gap), and the measured
// tension of a fitted or a held-out sample, or of a gross error.
enum class PointKind { kModel, kResidual, kMeasured, kHeldOut, kGross };
using PointVisitor = std::function<void(PointKind kind, int i, size_t k, double x, double y)>;
bool ReplayPoints(const TimePlots& t, const PointVisitor& visit, std::string* error) {
  long long n = 0;
  return t.samples.replay(
      [&](const ReportSample& s) {
        const double x = t.X(s, n++);
        for (int i = 0; i < kNumCables; ++i) {
          for (size_t k = 0; k < t.shown.size(); ++k) {
            if (!t.Predicted(t.shown[k])) continue;
            const double predicted = s.predicted_n[t.shown[k]][i];
            visit(PointKind::kModel, i, k, x, predicted / kNPerKn);
            visit(PointKind::kResidual, i, k, x,
                  s.gross[i] ? NAN : (predicted - s.measured_n[i]) / kNPerKn);
          }
          const PointKind measured = s.gross[i]   ? PointKind::kGross
                                     : s.held_out ? PointKind::kHeldOut
                                                  : PointKind::kMeasured;
          visit(measured, i, 0, x, s.measured_n[i] / kNPerKn);
        }
      },
      error);
}

// First replay: the series' lengths and gaps, and the residuals' range.
bool ShapeSeries(const TimePlots& t, TimeSeries* ts, std::string* error) {
  for (int i = 0; i < kNumCables; ++i) {
    ts->model_shape[i].assign(t.shown.size(), {});
    ts->residual_shape[i].assign(t.shown.size(), {});
  }
  return ReplayPoints(
      t,
      [ts](PointKind kind, int i, size_t k, double x, double y) {
        switch (kind) {
          case PointKind::kModel:
            ts->Span(i, y);
            return ts->model_shape[i][k].Add(x, y);
          case PointKind::kResidual:
            ts->residual_shape[i][k].Add(x, y);
            if (!std::isfinite(y)) return;
            ts->residual_lo = std::min(ts->residual_lo, y);
            ts->residual_hi = std::max(ts->residual_hi, y);
            return;
          case PointKind::kMeasured:
            ts->Span(i, y);
            return ts->fitted_shape[i].Add(x, y);
          case PointKind::kHeldOut:
            ts->Span(i, y);
            return ts->held_shape[i].Add(x, y);
          case PointKind::kGross:
            return ts->gross_shape[i].Add(x, y);
        }
      },
      error);
}

PlotOptions CablePlotOptions(const std::string& title, const std::string& x_label,
                             const std::string& y_label) {
  PlotOptions o;
  o.title = title;
  o.x_label = x_label;
  o.y_label = y_label;
  o.width_px = kCablePlotWidthPx;
  o.height_px = kCablePlotHeightPx;
  return o;
}

// The figures of AddPlots, drawn from the second replay.
struct TimeFigures {
  std::vector<std::string> tension_svgs, residual_svgs;
  int tension_thinning = 0, residual_buckets = 0;
  std::string histogram_svg;  // empty: no variant has predictions
};

// Second replay: every series thinned as it goes, the residuals binned.
bool DrawTimeFigures(const TimePlots& t, const TimeSeries& ts, TimeFigures* f, std::string* error) {
  std::array<std::vector<SeriesThinner>, kNumCables> models, residuals;
  std::vector<SeriesThinner> fitted, held, gross;
  std::vector<std::string> histogram_names;
  bool any = false;
  for (int i = 0; i < kNumCables; ++i) {
    for (size_t k = 0; k < t.shown.size(); ++k) {
      const VariantEvaluation& v = t.in.variants[t.shown[k]];
      models[i].emplace_back(t.Model(v.name, k), ts.model_shape[i][k].n,
                             ts.model_shape[i][k].any_gap, !t.ordered);
      residuals[i].emplace_back(t.Model(v.name, k), ts.residual_shape[i][k].n,
                                ts.residual_shape[i][k].any_gap, false);
    }
    PlotSeries m{t.holdout ? "measured (fitted)" : "measured", {}, {}, false, true};
    PlotSeries h{"measured (held out)", {}, {}, false, true};
    m.marker_radius_px = h.marker_radius_px = kMeasuredDotRadiusPx;
    m.opacity = kMeasuredDotOpacity;
    h.opacity = kHeldOutDotOpacity;
    fitted.emplace_back(m, ts.fitted_shape[i].n, ts.fitted_shape[i].any_gap, !t.ordered);
    held.emplace_back(h, ts.held_shape[i].n, ts.held_shape[i].any_gap, !t.ordered);
    // Gross errors: large red dots over everything, so that a reading kept out is seen.
    PlotSeries g{"gross error", {}, {}, false, true};
    g.marker_radius_px = kGrossDotRadiusPx;
    g.colour = kGrossErrorColour;
    g.on_top = true;
    gross.emplace_back(g, ts.gross_shape[i].n, ts.gross_shape[i].any_gap, true);
  }
  for (size_t k : t.shown) {
    if (!t.Predicted(k)) continue;
    if (histogram_names.size() <= k) histogram_names.resize(k + 1);
    histogram_names[k] = t.in.variants[k].name;
    any = true;
  }
  HistogramBins histogram(histogram_names, ts.residual_lo, ts.residual_hi, kResidualBins);
  const bool ok = ReplayPoints(
      t,
      [&](PointKind kind, int i, size_t k, double x, double y) {
        switch (kind) {
          case PointKind::kModel:
            return models[i][k].Add(x, y);
          case PointKind::kResidual:
            residuals[i][k].Add(x, y);
            return histogram.Add(t.shown[k], y);  // a gap (NaN) is not counted
          case PointKind::kMeasured:
            return fitted[i].Add(x, y);
          case PointKind::kHeldOut:
            return held[i].Add(x, y);
          case PointKind::kGross:
            return gross[i].Add(x, ts.OnScale(i, y));
        }
      },
      error);
  if (!ok) return false;
  for (int i = 0; i < kNumCables; ++i) {
    std::vector<PlotSeries> series, residual_series;
    for (size_t k = 0; k < t.shown.size(); ++k) {
      if (!t.Predicted(t.shown[k])) continue;
      PutAt(&series, t.shown[k], models[i][k].Finish());
      f->tension_thinning = std::max(f->tension_thinning, models[i][k].Thinning());
      PutAt(&residual_series, t.shown[k], residuals[i][k].Finish());
      f->residual_buckets = std::max(f->residual_buckets, residuals[i][k].Thinning());
    }
    if (t.holdout) {
      PutAt(&series, HeldOutSlot(t.in), held[i].Finish());
      f->tension_thinning = std::max(f->tension_thinning, held[i].Thinning());
    }
    PutAt(&series, MeasuredSlot(t.in), fitted[i].Finish());
    f->tension_thinning = std::max(f->tension_thinning, fitted[i].Thinning());
    if (ts.gross_shape[i].n > 0) PutAt(&series, MeasuredSlot(t.in) + 1, gross[i].Finish());
    PlotOptions tension_options = CablePlotOptions("Cable " + Int(i + 1) + ": tension", t.x_label,
                                                   "T" + Int(i + 1) + " [kN]");
    PlotOptions residual_options = CablePlotOptions("Cable " + Int(i + 1) + ": model - measured",
                                                    t.x_label, "model - measured [kN]");
    for (PlotOptions* o : {&tension_options, &residual_options}) {
      o->x_unix_time = t.use_time && t.display.absolute;
      o->x_time_offset_s = t.display.offset_s;
    }
    f->tension_svgs.push_back(SvgLinePlot(series, tension_options));
    f->residual_svgs.push_back(SvgLinePlot(residual_series, residual_options));
  }
  if (any) {
    PlotOptions o;
    o.title = "Model - measured, all cables and samples";
    o.x_label = "model - measured [kN]";
    o.width_px = kWidePlotWidthPx;
    o.height_px = kWidePlotHeightPx;
    f->histogram_svg = histogram.Svg(o);
  }
  return true;
}

void AddPlots(const ReportInputs& in, Document* doc) {
  doc->Heading(2, "Plots");
  if (!in.data || NumSamples(in) == 0) {
    doc->Paragraph("No samples to plot.");
    return;
  }
  const TimePlots t(in);
  TimeSeries ts;
  TimeFigures f;
  std::string error;
  if (!ShapeSeries(t, &ts, &error) || !DrawTimeFigures(t, ts, &f, &error)) {
    doc->Paragraph("The samples could not be read back to plot them: " + error);
    return;
  }
  // Tension against time, one plot per cable: the measured tensions as small translucent
  // dots, drawn first, and the model over them.
  doc->Figure(std::move(f.tension_svgs),
              std::string("Measured lower-end tension (translucent dots, drawn underneath") +
                  (t.holdout ? "; held-out samples in light blue" : "") + ") and the model " +
                  (t.ordered ? "predictions (lines on top; dashed: before calibration)"
                             : "predictions (dots on top: the samples are not a trajectory, so "
                               "nothing joins them)") +
                  " against time, per cable [kN]." + t.not_drawn +
                  t.ThinningNote(f.tension_thinning));
  // Residual distribution, all cables and samples pooled.
  if (f.histogram_svg.empty()) {
    doc->Paragraph("No model predictions to plot residuals of.");
    return;
  }
  doc->Figure({f.histogram_svg},
              "Distribution of model - measured over all cables and all " + Int(NumSamples(in)) +
                  " samples [kN]: a calibrated model should centre on 0 with the width of the "
                  "sensor noise.");
  // Residual against time, one plot per cable.
  doc->Figure(std::move(f.residual_svgs),
              "Model - measured against time, per cable [kN]: a pattern that repeats with "
              "the pose is model error; what remains after calibration should look like noise." +
                  t.not_drawn + t.ThinningNote(f.residual_buckets));
  if (in.result) internal::AddDiagnosticPlots(in, doc);
}

// Each cable's attachments (cable_attachment.h) as the model describes them, and as
// calibrated where the spec estimated them; nothing for uniform cables.
void AddCablesAsBuilt(const ReportInputs& in, Document* doc) {
  const CableRobot* model = in.initial_model;
  const CableRobot* calibrated = in.result ? &in.result->calibrated : nullptr;
  const CableRobot* any = model != nullptr ? model : calibrated;
  if (any == nullptr || !any->HasAttachments()) return;
  doc->Heading(2, "Cables as built");
  doc->Paragraph(
      "What each cable carries besides its own weight, by unstretched arc length from its "
      "lower (cabin) end: point masses (sensor and connector assemblies, clamps) and added "
      "weight per length (hung lines). The tension sensor sits below all of them. The "
      "statics solve such a cable as a chain of catenary segments (docs/model.md).");
  Table t;
  t.header = {
      "Cable", "#", "What", "Where (m)", "Model", "Calibrated", "Added mass in the model (kg)"};
  t.right_align = {true, true, false, true, true, true, true};
  for (int i = 0; i < kNumCables; ++i) {
    const std::vector<CableAttachment>& on = any->cables[i].attachments;
    for (size_t j = 0; j < on.size(); ++j) {
      const CableAttachment& a = on[j];
      const bool point = a.kind == AttachmentKind::kPointMass;
      const std::string unit = point ? " kg" : " kg/m";
      std::string after = "-";
      if (calibrated != nullptr && j < calibrated->cables[i].attachments.size() &&
          calibrated->cables[i].attachments[j].Value() != a.Value()) {
        after = Sig6(calibrated->cables[i].attachments[j].Value()) + unit;
      }
      t.rows.push_back({Int(i + 1), Int(static_cast<long long>(j + 1)),
                        point ? "point mass" : "added density",
                        point ? Sig6(a.at_m) : Sig6(a.from_m) + " – " + Sig6(a.to_m),
                        Sig6(a.Value()) + unit, after, Sig6(a.TotalMassKg())});
    }
  }
  doc->AddTable(std::move(t));
}

void AddCalibratedModel(const ReportInputs& in, Document* doc) {
  doc->Heading(2, "The calibrated model");
  // The commands name this run's directory and a dataset the model was not fitted to:
  // evaluating on the fitted data again would only repeat the fit's own RMS.
  const std::string dir = in.out_dir.empty() ? "DIR" : in.out_dir;
  const std::string other = in.other_data_path.empty() ? "OTHER_DATA.csv" : in.other_data_path;
  doc->Paragraph(Text("The calibrated model is ")
                     .Code(dir + "/model_calibrated.yaml")
                     .Plain(", in the same format as the input model; parameters the spec does "
                            "not name keep their input values, and the estimated sensor gains and "
                            "biases are in it. Check it on data it was not fitted to (another "
                            "trajectory, another day: " +
                            std::string(in.other_data_path.empty()
                                            ? "OTHER_DATA.csv stands for such a file"
                                            : "here another file beside the fitted one") +
                            "), then use it like any model file:"));
  doc->Pre("",
           "fastcal evaluate --model=" + dir + "/model_calibrated.yaml --data=" + other +
               (in.columns_path.empty() ? "" : " --columns=" + in.columns_path) +
               "\nfastcal solve --model=" + dir +
               "/model_calibrated.yaml --position=0,0,140 --method=exact",
           false);
}

void AddAppendices(const ReportInputs& in, Document* doc) {
  const bool spec = in.spec != nullptr;
  const bool ceres = in.result && !in.result->ceres_full_report.empty();
  const bool skipped = in.data && !in.data->skipped.empty();
  if (!spec && !ceres && !skipped) return;
  doc->Heading(2, "Details");
  if (spec) doc->Pre("Calibration spec as used (YAML)", CalibrationSpecToYaml(*in.spec), true);
  if (ceres) doc->Pre("Ceres full report", in.result->ceres_full_report, true);
  if (skipped) {
    std::string text;
    for (const std::string& s : in.data->skipped) text += s + "\n";
    doc->Pre("Skipped dataset rows (" + Int(static_cast<long long>(in.data->skipped.size())) + ")",
             text, true);
  }
}

// Issue 59: a report on data `fastcal simulate` made says so before anything else (the
// demo's calibrated RMS stood beside the paper's Table 6 with nothing saying the data were
// not the telescope's).
void AddSimulatedDataNote(const std::string& provenance, Document* doc) {
  std::string first = provenance.substr(0, provenance.find('\n'));
  doc->Paragraph(Text()
                     .Bold("Simulated data.")
                     .Plain(" The data file says it was made by fastcal simulate (")
                     .Code(first)
                     .Plain("; its header is under Provenance): the estimates and errors below "
                            "are those of a simulation with the noise its command gave, not of "
                            "the telescope."));
}

Document BuildDocument(const ReportInputs& in, bool with_plots) {
  Document doc;
  doc.title = in.result ? "fastcal calibration report" : "fastcal evaluation report";
  doc.Heading(1, doc.title);
  doc.Paragraph(in.result
                    ? "FAST feed-cabin cable robot: model parameters estimated from measured "
                      "poses and cable tensions, and the model checked against the measurements "
                      "before and after. Tensions in kN."
                    : "FAST feed-cabin cable robot: model tensions checked against measured cable "
                      "tensions. Tensions in kN.");
  if (!in.simulated_provenance.empty()) AddSimulatedDataNote(in.simulated_provenance, &doc);
  AddProvenance(in, &doc);
  AddVerdict(in, &doc);
  if (in.result) {
    AddEstimates(*in.result, &doc);
    AddCablesAsBuilt(in, &doc);
    internal::AddMovingParts(in, with_plots, &doc);
    internal::AddSessions(*in.result, with_plots, &doc);
    internal::AddChangeScan(*in.result, with_plots, &doc);
    internal::AddUncertaintyBudget(*in.result, &doc);
    internal::AddGrossErrors(in, &doc);
    internal::AddMisfitRanking(*in.result, &doc);
    AddIdentifiability(*in.result, with_plots, &doc);
  }
  if (!in.result) AddCablesAsBuilt(in, &doc);
  if (!in.result) internal::AddEvaluationGrossErrors(in, &doc);
  AddRmsTables(in, with_plots, &doc);
  if (in.result) internal::AddLengths(*in.result, &doc);
  if (in.result) internal::AddCrossValidation(*in.result, &doc);
  if (with_plots) {
    AddPlots(in, &doc);
  } else {
    doc.Heading(2, "Plots");
    doc.Paragraph(
        "The plots (tension and model - measured against time per cable, residual against "
        "off-axis angle and azimuth, predicted against measured, residual distribution, RMS "
        "per cable, correlation heatmap) are in report.html.");
  }
  if (in.result) AddCalibratedModel(in, &doc);
  AddAppendices(in, &doc);
  return doc;
}

}  // namespace

namespace {

// ---------------------------------------------------------------------------------------
// Files.

// Writes `content` to a new temporary file in the directory of `path`, flushes it to

}  // namespace

ReportSampleStream ReportSamplesOf(const StreamedEvaluation& evaluation) {
  ReportSampleStream out;
  out.samples = evaluation.samples();
  out.time_min_s = evaluation.time_min_s();
  out.time_max_s = evaluation.time_max_s();
  out.is_trajectory = internal::IsTrajectory(evaluation.samples(), evaluation.median_step_m(),
                                             evaluation.position_spread_m());
  out.has_predictions.assign(evaluation.variants().size(), false);
  for (int k = 0; k < evaluation.predicted_variants(); ++k) out.has_predictions[k] = true;
  out.replay = [&evaluation](const std::function<void(const ReportSample&)>& visit,
                             std::string* error) {
    return evaluation.ForEach(
        [&visit](const EvaluatedSample& s) {
          ReportSample r;
          r.time_s = s.time_s;
          r.position_m = s.position_m;
          r.measured_n = s.measured_n;
          r.predicted_n = s.predicted_n.data();
          r.gross = s.gross;
          visit(r);
        },
        error);
  };
  return out;
}

std::string ReportMarkdown(const ReportInputs& inputs) {
  try {
    return internal::RenderMarkdown(BuildDocument(inputs, false));
  } catch (const std::exception&) {
    return std::string();
  }
}

std::string ReportHtml(const ReportInputs& inputs) {
  try {
    return internal::RenderHtmlPage(BuildDocument(inputs, true));
  } catch (const std::exception&) {
    return std::string();
  }
}

std::string SummaryJson(const ReportInputs& inputs) {
  try {
    return RenderJson(inputs);
  } catch (const std::exception&) {
    return std::string();
  }
}

namespace {

// report.md, report.html and summary.json rendered, on the spec's threads when the samples
// are held in memory (issue 41: each replays every sample; report.html, the longest, ~0.9 s
// at 10^6, no longer waits for the other two). Pure renderings of `inputs`, so the same
// bytes on any number of threads. A streamed evaluation's samples are replayed from one
// temporary file, on one thread.
std::vector<std::pair<std::string, std::string>> RenderReportFiles(const ReportInputs& inputs) {
  using Render = std::string (*)(const ReportInputs&);
  // The longest first, so that two threads finish together.
  const Render renders[] = {ReportHtml, ReportMarkdown, SummaryJson};
  constexpr int kFiles = 3;
  std::vector<std::string> content(kFiles);
  const int threads =
      inputs.sample_stream != nullptr || inputs.spec == nullptr ? 1 : inputs.spec->num_threads;
  std::atomic<int> next{0};
  internal::OnThreads(std::clamp(threads, 1, kFiles), [&](int) {
    for (int k = next++; k < kFiles; k = next++) content[k] = renders[k](inputs);
  });
  // In the order the files have always been written.
  return {{"report.md", std::move(content[1])},
          {"report.html", std::move(content[0])},
          {"summary.json", std::move(content[2])}};
}

}  // namespace

bool WriteReportFiles(const std::string& dir, const ReportInputs& inputs, std::string* error) {
  std::string ignored;
  if (error == nullptr) error = &ignored;
  if (dir.empty()) {
    *error = "report: no output directory given";
    return false;
  }
  std::vector<std::string> written;
  try {
    const std::vector<std::pair<std::string, std::string>> files = RenderReportFiles(inputs);
    for (const auto& [name, content] : files) {
      if (content.empty()) {
        *error = name + ": could not be rendered (out of memory)";
        break;
      }
      const std::string path = dir + (dir.back() == '/' ? "" : "/") + name;
      if (!internal::WriteFileAtomically(path, content, error)) break;
      written.push_back(path);
    }
    if (written.size() == files.size()) return true;
  } catch (const std::exception& e) {
    *error = std::string("report: ") + e.what();
  }
  for (const std::string& path : written) ::unlink(path.c_str());
  return false;
}

}  // namespace fastcal
