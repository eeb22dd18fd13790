// The calibration report's diagnostic sections (internal/report_sections.h): what the
// uncertainty is made of (uncertainty.h), which readings were gross errors
// (gross_errors.h), what would explain the misfit (the score test), how well each block
// of the data is predicted by the rest, and plots against the pose.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "fastcal/internal/report_sections.h"
#include "fastcal/internal/units.h"
#include "fastcal/svg_plot.h"

namespace fastcal::internal {
namespace {

// The focal centre of the off-axis angle and azimuth (docs/model.md, "Workspace").
const Eigen::Vector3d kFocalCentre_m(0.0, 0.0, 300.0);
// Rows at most in the report's tables of readings (summary.json has them all).
constexpr size_t kMaxReadingRows = 50;
constexpr size_t kMisfitRows = 10;
// Plot geometry (px); scatter series thinned to this many points (min/max per bucket).
constexpr int kScatterWidthPx = 540, kScatterHeightPx = 320;
constexpr int kMaxScatterPoints = 2000;
constexpr double kDotRadiusPx = 1.6, kDotOpacity = 0.5;
// Residual scatter against a pose axis: dots this faint under each cable's binned mean,
// in this many bins.
constexpr double kFaintDotOpacity = 0.25;
constexpr int kResidualBins = 24;

std::string Sigma(double v) { return Sig3(v); }

// "9 mm" for metres below 1 m, else the value and its unit.
std::string WithUnit(double v, const std::string& unit) {
  if (unit == "m" && std::abs(v) < 1.0) return Printf("%.2g", v * 1e3) + " mm";
  return Printf("%.2g", v) + (unit == "1" ? "" : " " + unit);
}

// A value of the misfit table, one unit per quantity (lengths always in mm, so that a
// column never has "1.6 m" beside "7.5e+02 mm"), 2 significant digits, no exponent
// between 0.001 and 1e6.
std::string MisfitValue(double v, const std::string& unit) {
  const bool length = unit == "m";
  const double shown = length ? v * 1e3 : v;
  const double magnitude = std::abs(shown);
  std::string text = Printf("%.2g", shown);
  if (magnitude >= 1e2 && magnitude < 1e6) {  // 2 significant digits, written out
    const double step = std::pow(10.0, std::floor(std::log10(magnitude)) - 1.0);
    text = Printf("%.0f", std::round(shown / step) * step);
  }
  return text + (length ? " mm" : unit == "1" ? "" : " " + unit);
}

std::vector<const ParameterEstimate*> FreeEstimates(const CalibrationResult& r) {
  std::vector<const ParameterEstimate*> free;
  for (const ParameterEstimate& p : r.parameters) {
    if (p.free) free.push_back(&p);
  }
  return free;
}

// ---------------------------------------------------------------------------------------
// The uncertainty budget.

Text BudgetIntro(const CalibrationResult& r) {
  const UncertaintyBudget& b = r.budget;
  Text t(
      "σ_total, the uncertainty to quote, is the root-sum-square of a statistical part and a "
      "systematic part. Statistical: the formal σ (the stated noise, independent samples) "
      "widened by what the data themselves show: by the misfit, √max(1, χ²/ν) = " +
      Sig3(b.misfit_factor) +
      " here, and by residuals correlated in time along the "
      "trajectory, measured from the data (long-run covariance of the fit's scores by "
      "overlapping batch means, corrected for what the fit absorbs). Systematic: parameters "
      "held fixed but given a prior (consider parameters), their prior σ propagated through "
      "the sensitivity of the estimates to them. docs/calibration.md gives the formulas.");
  return t;
}

std::string CorrelationSentence(const UncertaintyBudget& b) {
  if (b.samples == 0) return "";
  if (!b.correlated) {
    return "The residuals are not correlated in time (largest autocorrelation time " + Sig3(b.tau) +
           " samples, not significantly above 1): no widening for correlation.";
  }
  std::string s =
      "The residuals are correlated in time: the parameters' influence series have "
      "autocorrelation times up to " +
      Sig3(b.tau) + " samples, so the " + Int(b.samples) + " samples carry about " +
      Sig3(b.effective_samples) + " independent pieces of information (batch length " +
      Int(b.bandwidth) + ").";
  if (!b.correlation_reliable) {
    s += " Their memory is too long for these data to measure it fully (the fit absorbs most "
         "of a batch's slow error): the widening is a lower bound; longer or more varied data "
         "would tell.";
  }
  return s;
}

}  // namespace

PlotSeries ThinEvenly(const PlotSeries& series, int max_points, int* stride) {
  const size_t n = std::min(series.x.size(), series.y.size());
  const size_t k = max_points > 0 ? std::max<size_t>(1, (n + max_points - 1) / max_points) : 1;
  *stride = std::max(*stride, static_cast<int>(k));
  if (k == 1) return series;
  PlotSeries thinned = series;
  thinned.x.clear();
  thinned.y.clear();
  for (size_t t = 0; t < n; t += k) {
    thinned.x.push_back(series.x[t]);
    thinned.y.push_back(series.y[t]);
  }
  return thinned;
}

std::string EvenThinningNote(int num_samples, int stride) {
  if (stride <= 1) return "";
  return " Thinned for drawing: one point in " + Int(stride) + " of the " + Int(num_samples) +
         " samples, evenly (the statistics use them all).";
}

bool IsTrajectory(const Dataset& data) {
  const size_t n = data.samples.size();
  if (n < 3) return true;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Sample& s : data.samples) mean += s.pose.position_m;
  mean /= static_cast<double>(n);
  double spread2 = 0.0;
  for (const Sample& s : data.samples) spread2 += (s.pose.position_m - mean).squaredNorm();
  const double spread = std::sqrt(spread2 / n);
  std::vector<double> steps;
  steps.reserve(n - 1);
  for (size_t t = 1; t < n; ++t) {
    steps.push_back((data.samples[t].pose.position_m - data.samples[t - 1].pose.position_m).norm());
  }
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return IsTrajectory(static_cast<long long>(n), steps[steps.size() / 2], spread);
}

bool IsTrajectory(long long n, double median_step_m, double spread_m) {
  return n < 3 || median_step_m <= kTrajectoryStepFraction * spread_m;
}

double OffAxisDeg(const Eigen::Vector3d& position_m) {
  const Eigen::Vector3d d = position_m - kFocalCentre_m;
  return std::atan2(std::hypot(d.x(), d.y()), -d.z()) * 180.0 / M_PI;
}

double AzimuthDeg(const Eigen::Vector3d& position_m) {
  const double a = std::atan2(position_m.y(), position_m.x()) * 180.0 / M_PI;
  return a < 0.0 ? a + 360.0 : a;
}

void AddUncertaintyBudget(const CalibrationResult& r, Document* doc) {
  doc->Heading(2, "Uncertainty budget");
  if (!r.covariance_ok) {
    doc->Paragraph("Not available: the covariance could not be computed.");
    return;
  }
  const UncertaintyBudget& b = r.budget;
  doc->Paragraph(BudgetIntro(r));
  Table t;
  t.caption = "Parts of σ_total per free parameter, in the parameter's unit";
  t.header = {"Parameter", "Unit", "formal σ", "misfit ×", "correlation ×", "statistical σ"};
  t.right_align = {false, false, true, true, true, true};
  for (const std::string& g : b.consider_groups) {
    t.header.push_back(Text("systematic: ").Code(g));
    t.right_align.push_back(true);
  }
  t.header.push_back("systematic σ");
  t.header.push_back(Text().Bold("σ_total"));
  t.right_align.insert(t.right_align.end(), {true, true});
  for (const ParameterEstimate* p : FreeEstimates(r)) {
    const double misfit = b.misfit_factor;
    std::vector<Text> row = {Text().Code(p->name),
                             p->unit,
                             Sigma(p->sigma),
                             Printf("%.3g", misfit),
                             Printf("%.3g", p->widening / misfit),
                             Sigma(p->sigma_statistical)};
    for (size_t g = 0; g < b.consider_groups.size(); ++g) {
      row.push_back(g < p->systematic_by_group.size() ? Sigma(p->systematic_by_group[g]) : "-");
    }
    row.push_back(Sigma(p->sigma_systematic));
    row.push_back(Text().Bold(Sigma(p->sigma_total)));
    t.rows.push_back(std::move(row));
  }
  doc->AddTable(std::move(t));
  doc->Paragraph(CorrelationSentence(b));
  std::vector<Text> groups;
  for (size_t g = 0; g < b.consider_groups.size(); ++g) {
    Text item = Text().Code(b.consider_groups[g]).Plain(": ");
    bool first = true;
    for (const ParameterEstimate* p : FreeEstimates(r)) {
      if (g >= p->systematic_by_group.size()) continue;
      item.Plain(std::string(first ? "" : ", ") + WithUnit(p->systematic_by_group[g], p->unit) +
                 " on ")
          .Code(p->name);
      first = false;
    }
    groups.push_back(std::move(item));
  }
  if (!groups.empty()) {
    doc->Paragraph("What each group of consider parameters adds (1σ of its prior):");
    doc->List(std::move(groups));
  } else {
    doc->Paragraph(
        "No consider parameters: the systematic part is 0. A parameter held fixed but known "
        "only to a tolerance (a sensor's gain, a tower's survey) belongs in the spec as "
        "free: false with a prior; the misfit ranking below shows which ones the data point "
        "at.");
  }
}

namespace {

// A table of readings (line, cable, measured, predicted, whitened residual; held out
// only when one is), the first kMaxReadingRows of them.
void AddReadingsTable(const std::vector<ReadingResidual>& list, const Text& caption,
                      Document* doc) {
  Table t;
  t.caption = caption;
  // With lengths in the fit a reading is a tension (kN) or a length (m, marked).
  const bool lengths =
      std::any_of(list.begin(), list.end(), [](const auto& e) { return e.length; });
  t.header = {"Line",
              "Cable",
              lengths ? "Measured [kN, or m]" : "Measured [kN]",
              lengths ? "Predicted [kN, or m]" : "Predicted [kN]",
              "(model - measured) / σ",
              "Held out"};
  t.right_align = {true, true, true, true, true, false};
  bool any_held_out = false;
  for (size_t k = 0; k < std::min(list.size(), kMaxReadingRows); ++k) {
    const ReadingResidual& e = list[k];
    any_held_out = any_held_out || e.held_out;
    t.rows.push_back({Int(e.line), e.length ? Int(e.cable) + " (length)" : Int(e.cable),
                      e.length ? Printf("%.4f m", e.measured_m) : Kn3(e.measured_n),
                      e.length ? Printf("%.4f m", e.predicted_m) : Kn3(e.predicted_n),
                      Printf("%+.1f", e.residual_sigma), e.held_out ? "yes" : ""});
  }
  if (!any_held_out) {  // an empty column is not drawn
    t.header.pop_back();
    t.right_align.pop_back();
    for (std::vector<Text>& row : t.rows) row.pop_back();
  }
  doc->AddTable(std::move(t));
  if (list.size() > kMaxReadingRows) {
    doc->Paragraph("... and " + Int(static_cast<long long>(list.size() - kMaxReadingRows)) +
                   " more, all in summary.json.");
  }
}

// The screen per cable: readings flagged, median and robust scale of the residuals.
void AddPerCableScreen(const std::array<int, kNumCables>& counts,
                       const std::array<RobustScale, kNumCables>& scales, Document* doc,
                       bool lengths = false) {
  Table s;
  s.caption = lengths ? "Per cable, lengths" : "Per cable";
  s.header = lengths ? std::vector<Text>{"", "L1", "L2", "L3", "L4", "L5", "L6"}
                     : std::vector<Text>{"", "T1", "T2", "T3", "T4", "T5", "T6"};
  s.right_align = {false, true, true, true, true, true, true};
  std::vector<Text> count = {"gross errors"}, centre = {"median residual [σ]"},
                    scale = {"robust scale [σ]"};
  for (int i = 0; i < kNumCables; ++i) {
    count.push_back(Int(counts[i]));
    centre.push_back(Printf("%+.2f", scales[i].centre));
    scale.push_back(Printf("%.2f", scales[i].scale));
  }
  s.rows = {count, centre, scale};
  doc->AddTable(std::move(s));
}

}  // namespace

void AddGrossErrors(const ReportInputs& in, Document* doc) {
  const CalibrationResult& r = *in.result;
  const GrossErrorSummary& g = r.gross_error_summary;
  doc->Heading(2, "Gross errors and worst readings");
  if (!g.enabled) {
    doc->Paragraph(Text("Not screened (").Code("gross_errors: {detect: false}").Plain(")."));
  } else {
    doc->Paragraph(
        "A reading more than " + Sig3(g.threshold_sigmas) +
        " robust σ from the model (the median and 1.4826 × MAD of its cable's whitened "
        "residuals, at least the stated noise) is a gross error: kept out of the fit and of "
        "the statistics, and re-judged after every pass so that gross errors cannot hide "
        "each other. " +
        Int(static_cast<long long>(r.gross_errors.size())) +
        (r.gross_errors.size() == 1 ? " reading was" : " readings were") + " flagged. Threshold " +
        DescribeGrossErrorThreshold(g.threshold) + ".");
    std::array<RobustScale, kNumCables> scales;
    for (int i = 0; i < kNumCables; ++i) scales[i] = {g.centre[i], g.scale[i]};
    AddPerCableScreen(g.count, scales, doc);
    if (r.lengths.used) {  // screened on their own scales: a slipped encoder is one
      for (int i = 0; i < kNumCables; ++i) scales[i] = {g.length_centre[i], g.length_scale[i]};
      AddPerCableScreen(g.length_count, scales, doc, /*lengths=*/true);
    }
  }
  if (!r.gross_errors.empty())
    AddReadingsTable(r.gross_errors, "Gross errors (line in the data file)", doc);
  if (!r.worst_readings.empty()) {
    AddReadingsTable(r.worst_readings, "The worst fitted readings (largest |model - measured| / σ)",
                     doc);
  }
}

void AddLengths(const CalibrationResult& r, Document* doc) {
  const LengthEvaluation& l = r.lengths;
  if (!l.used) return;
  doc->Heading(2, "Lengths");
  doc->Paragraph(
      "The winches' lengths (s0_<i>_m) as measurements, σ = " + Printf("%.3g", l.sigma_m * 1e3) +
      " mm each: model (its unstretched length at the sample's pose, exact statics, plus the "
      "encoder's offset length_offset_m) minus measured, per cable, in mm; gross errors left "
      "out.");
  Table t;
  t.caption = "Model - measured length [mm]";
  t.header = {"", "Samples", "L1", "L2", "L3", "L4", "L5", "L6"};
  t.right_align = {false, true, true, true, true, true, true, true};
  const auto add = [&](const std::string& name, const LengthResidualStats& s,
                       std::array<double, kNumCables> LengthResidualStats::*member) {
    if (s.samples == 0) return;
    std::vector<Text> row = {name, Int(s.samples)};
    // Below half the last digit: 0, not "-0.00".
    for (double v : s.*member) row.push_back(Printf("%.2f", std::abs(v) < 5e-6 ? 0.0 : v * 1e3));
    t.rows.push_back(std::move(row));
  };
  add("RMS, initial model", l.initial, &LengthResidualStats::rms_m);
  add("RMS, calibrated model", l.calibrated, &LengthResidualStats::rms_m);
  add("mean, calibrated model", l.calibrated, &LengthResidualStats::mean_m);
  add("largest |.|, calibrated model", l.calibrated, &LengthResidualStats::max_abs_m);
  add("RMS, initial model, held out", l.initial_holdout, &LengthResidualStats::rms_m);
  add("RMS, calibrated model, held out", l.calibrated_holdout, &LengthResidualStats::rms_m);
  doc->AddTable(std::move(t));
}

void AddEvaluationGrossErrors(const ReportInputs& in, Document* doc) {
  if (in.evaluation_screen == nullptr) return;
  const EvaluationScreen& e = *in.evaluation_screen;
  doc->Heading(2, "Gross errors");
  doc->Paragraph(
      "The readings screened as calibrate screens them, against the predictions of \"" + e.variant +
      "\": a reading more than the threshold in robust σ (the median and 1.4826 × MAD of "
      "its cable's residuals whitened by the default noise model, 3 % of the reading, at "
      "least that noise) is a gross error, named here and left out of the rows \"... - "
      "gross errors\" of the RMS table. " +
      Int(e.count) + (e.count == 1 ? " reading was" : " readings were") + " flagged. Threshold " +
      DescribeGrossErrorThreshold(e.threshold) + ".");
  std::array<int, kNumCables> counts{};
  for (int i = 0; i < kNumCables; ++i) counts[i] = static_cast<int>(e.count_per_cable[i]);
  AddPerCableScreen(counts, e.cables, doc);
  if (!e.gross_errors.empty()) {
    const bool all = static_cast<long long>(e.gross_errors.size()) == e.count;
    AddReadingsTable(e.gross_errors,
                     all ? Text("Gross errors (line in the data file)")
                         : Text("Gross errors (line in the data file; the first " +
                                Int(static_cast<long long>(e.gross_errors.size())) + " of " +
                                Int(e.count) + ")"),
                     doc);
  }
}

void AddMisfitRanking(const CalibrationResult& r, Document* doc) {
  doc->Heading(2, "What would explain the misfit");
  doc->Paragraph(
      "For every parameter held fixed (each group's common value and each cable's, every "
      "offset axis), the chi-square decrease expected from freeing it, from a score test "
      "at the solution (no refit; exact for a linear model), and what freeing it would do. "
      "Significant: its score is larger than the residuals' own noise (their long-run "
      "variance, so time-correlated residuals do not count as evidence) would make the "
      "largest of these, the statistic above " +
      Sig3(r.misfit_threshold) +
      " (chi-square of 1 degree of freedom, 1% for the family). Significant or not, a "
      "single circle of poses often cannot tell some candidates apart (a gain from an "
      "anchor offset): they are where to look, not a diagnosis. Freed, moves: the change "
      "of the parameter itself, one Gauss-Newton step (\"beyond the linear range\" when "
      "that would leave its plausible range); moves most: the estimate it would shift most, "
      "in units of that estimate's σ_total. Only the significant candidates are listed.");
  if (r.misfit_ranking.empty()) {
    doc->Paragraph("No candidate: every parameter is free or spanned by the free ones.");
    return;
  }
  // Only the significant candidates are tabled: on a good fit a list of shifts "(6.5 σ)"
  // read as evidence of what is noise. The whole ranking is in summary.json.
  if (!r.misfit_ranking.front().significant) {
    // The candidate nearest to significance: the largest statistic (the ranking is by
    // expected decrease, which time-correlated residuals inflate).
    const MisfitCandidate& top =
        *std::max_element(r.misfit_ranking.begin(), r.misfit_ranking.end(),
                          [](const MisfitCandidate& a, const MisfitCandidate& b) {
                            return a.statistic < b.statistic;
                          });
    doc->Paragraph(Text("No fixed parameter explains the misfit beyond the residuals' own noise: "
                        "the largest statistic, " +
                        Sig3(top.statistic) + " (from freeing ")
                       .Code(top.name)
                       .Plain("; expected χ² decrease " + Sig3(top.expected_decrease) +
                              "), is below the threshold " + Sig3(r.misfit_threshold) + ". All " +
                              Int(static_cast<long long>(r.misfit_ranking.size())) +
                              " candidates are in summary.json (misfit_ranking)."));
    return;
  }
  Text lead;
  lead.Bold("The misfit is best explained by freeing:").Plain(" ");
  for (size_t k = 0; k < std::min<size_t>(3, r.misfit_ranking.size()); ++k) {
    const MisfitCandidate& c = r.misfit_ranking[k];
    if (!c.significant) break;
    lead.Plain(k ? ", " : "").Code(c.name).Plain(" (about " + Sig3(c.expected_decrease) + ")");
  }
  lead.Plain(
      ". Free it (with a prior if the data alone cannot hold it) or give it a "
      "consider prior, and calibrate again.");
  doc->Paragraph(lead);
  const std::vector<const ParameterEstimate*> free = FreeEstimates(r);
  Table t;
  // Short headers: the table fits a 900 px window (the paragraph above explains them).
  t.header = {"#", "Parameter", "Expected χ² decrease", "Statistic", "Freed, moves", "Moves most"};
  t.right_align = {true, false, true, true, true, false};
  size_t shown = 0;
  for (; shown < std::min(kMisfitRows, r.misfit_ranking.size()); ++shown) {
    const MisfitCandidate& c = r.misfit_ranking[shown];
    if (!c.significant) break;
    Text moved("-");
    double most = 0.0;
    for (size_t j = 0; !c.beyond_linear_range && j < free.size() && j < c.shifts.size(); ++j) {
      const double sigmas =
          free[j]->sigma_total > 0 ? std::abs(c.shifts[j]) / free[j]->sigma_total : 0.0;
      if (sigmas <= most) continue;
      most = sigmas;
      moved = Text()
                  .Code(free[j]->name)
                  .Plain(" " + MisfitValue(c.shifts[j], free[j]->unit) + " = " +
                         Printf("%.2g", sigmas) + " σ_total");
    }
    t.rows.push_back(
        {Int(static_cast<long long>(shown + 1)), Text().Code(c.name), Sig3(c.expected_decrease),
         Sig3(c.statistic),
         c.beyond_linear_range ? "beyond the linear range" : MisfitValue(c.change, c.unit), moved});
  }
  doc->AddTable(std::move(t));
  const size_t rest = r.misfit_ranking.size() - shown;
  if (rest > 0) {
    doc->Paragraph(Int(static_cast<long long>(rest)) + " more candidate" + (rest == 1 ? "" : "s") +
                   (shown < kMisfitRows ? " (not significant)" : "") +
                   " in summary.json (misfit_ranking).");
  }
}

void AddCrossValidation(const CalibrationResult& r, Document* doc) {
  const CrossValidation& cv = r.cross_validation;
  if (cv.folds_used == 0) return;
  Table t;
  t.caption = Text("Block cross-validation (" + Int(cv.folds_used) + " of " + Int(cv.blocks) +
                   " blocks): RMS of model - measured [kN]");
  t.header = {"", "T1", "T2", "T3", "T4", "T5", "T6"};
  t.right_align = {false, true, true, true, true, true, true};
  std::vector<Text> fit = {"calibrated, fitted"},
                    held = {Text().Bold("calibrated, cross-validated")};
  for (int i = 0; i < kNumCables; ++i) {
    fit.push_back(Kn3(cv.fit_rms_n[i]));
    held.push_back(Kn3(cv.rms_n[i]));
  }
  t.rows = {fit, held};
  doc->AddTable(std::move(t));
  doc->Paragraph(
      "The fitted samples cut into " + Int(cv.blocks) +
      " contiguous blocks, each predicted by the fit without it: one Gauss-Newton step from "
      "the full fit (exact for a linear model). Contiguous blocks, not single samples: a sample of "
      "a slow trajectory "
      "is predicted by its neighbours. Cross-validated RMS well above the fitted one means "
      "the fit follows the data where it should not (too many free parameters, or slow "
      "errors it absorbs).");
}

// The mean of a scatter's y in kResidualBins equal bins of x over [lo, hi], as a line
// through the bins' centres (an empty bin is a gap), named as the scatter.
PlotSeries BinnedMean(const PlotSeries& dots, double lo, double hi) {
  std::vector<double> sum(kResidualBins, 0.0);
  std::vector<int> count(kResidualBins, 0);
  const double width = (hi - lo) / kResidualBins;
  for (size_t n = 0; n < dots.x.size() && n < dots.y.size(); ++n) {
    const int b = std::clamp(static_cast<int>((dots.x[n] - lo) / width), 0, kResidualBins - 1);
    sum[b] += dots.y[n];
    ++count[b];
  }
  PlotSeries line{dots.name + " (binned mean)", {}, {}};
  for (int b = 0; b < kResidualBins; ++b) {
    line.x.push_back(lo + (b + 0.5) * width);
    line.y.push_back(count[b] > 0 ? sum[b] / count[b] : NAN);
  }
  return line;
}

void AddDiagnosticPlots(const ReportInputs& in, Document* doc) {
  const CalibrationResult& r = *in.result;
  if (in.variants.empty() || !in.data) return;
  const VariantEvaluation& v = in.variants.back();
  const Dataset& d = *in.data;
  if (v.predicted_n.size() != d.samples.size()) return;
  std::vector<PlotSeries> zenith(kNumCables), azimuth(kNumCables), versus(kNumCables + 1);
  int excluded = 0, stride = 1;
  double lo = INFINITY, hi = -INFINITY;
  for (int i = 0; i < kNumCables; ++i) {
    for (PlotSeries* s : {&zenith[i], &azimuth[i], &versus[i]}) {
      s->name = "T" + Int(i + 1);
      s->markers_only = true;
      s->marker_radius_px = kDotRadiusPx;
      s->opacity = kDotOpacity;
    }
    const auto drawn = [&](size_t n) { return !(n < r.excluded.size() && r.excluded[n][i]); };
    size_t points = 0;
    for (size_t n = 0; n < d.samples.size(); ++n) points += drawn(n);
    excluded += static_cast<int>(d.samples.size() - points);
    // ThinEvenly's points, taken as they come: every k-th drawn sample (at 10^6 samples
    // the whole series first held 100 MB for a moment).
    const size_t k = std::max<size_t>(1, (points + kMaxScatterPoints - 1) / kMaxScatterPoints);
    stride = std::max(stride, static_cast<int>(k));
    size_t index = 0;
    for (size_t n = 0; n < d.samples.size(); ++n) {
      if (!drawn(n)) continue;
      const Sample& s = d.samples[n];
      lo = std::min(lo, s.tension_n[i] / kNPerKn);
      hi = std::max(hi, s.tension_n[i] / kNPerKn);
      if (index++ % k != 0) continue;
      const double residual_kn = (v.predicted_n[n][i] - s.tension_n[i]) / kNPerKn;
      zenith[i].x.push_back(OffAxisDeg(s.pose.position_m));
      zenith[i].y.push_back(residual_kn);
      azimuth[i].x.push_back(AzimuthDeg(s.pose.position_m));
      azimuth[i].y.push_back(residual_kn);
      versus[i].x.push_back(s.tension_n[i] / kNPerKn);
      versus[i].y.push_back(v.predicted_n[n][i] / kNPerKn);
    }
  }
  versus[kNumCables] = PlotSeries{"predicted = measured", {lo, hi}, {lo, hi}, true, false};
  PlotOptions o;
  o.width_px = kScatterWidthPx;
  o.height_px = kScatterHeightPx;
  o.y_label = "model - measured [kN]";
  // A pose axis the trajectory barely moves along (a circle keeps its off-axis angle,
  // 26.39-26.41 deg) would show the residuals' scatter stretched over rounding: left
  // out, and the caption says why.
  constexpr double kFlatAxisDeg = 1.0;
  std::vector<std::string> plots;
  std::string flat;
  auto against = [&](std::vector<PlotSeries> series, const std::string& title,
                     const std::string& axis) {
    double axis_lo = INFINITY, axis_hi = -INFINITY;
    for (const PlotSeries& p : series) {
      for (double x : p.x) {
        axis_lo = std::min(axis_lo, x);
        axis_hi = std::max(axis_hi, x);
      }
    }
    if (axis_hi - axis_lo < kFlatAxisDeg) {
      flat += " Not drawn against the " + axis + ": the data span only " + Printf("%.4g", axis_lo) +
              " to " + Printf("%.4g", axis_hi) + " deg of it.";
      return;
    }
    // Six cables' dots lie on each other: each cable's binned mean is drawn over them as
    // a line in its colour (cables 4-6 dashed), the dots fainter and out of the legend.
    for (int i = 0; i < kNumCables; ++i) {
      series.push_back(BinnedMean(series[i], axis_lo, axis_hi));
      series.back().colour = PlotSeriesColour(i);
      series.back().dashed = i >= kNumCables / 2;
      series[i].name.clear();
      series[i].opacity = kFaintDotOpacity;
    }
    o.title = "Residual against " + title;
    o.x_label = axis + " [deg]";
    plots.push_back(SvgLinePlot(series, o));
  };
  against(zenith, "off-axis angle", "off-axis angle from the focal centre");
  against(azimuth, "azimuth", "azimuth");
  o.title = "Predicted against measured";
  o.x_label = "measured [kN]";
  o.y_label = "predicted by the calibrated model [kN]";
  plots.push_back(SvgLinePlot(versus, o));
  doc->Figure(plots,
              "The calibrated model's residuals per cable against where the cabin was (off-axis "
              "angle and azimuth seen from the focal centre): faint dots, and each cable's mean "
              "in " +
                  Int(kResidualBins) +
                  " bins as a line in its colour (cables 4-6 dashed). A trend or a wave is model "
                  "error that depends on the pose, not noise. Last: predicted against measured "
                  "tension, with the diagonal." +
                  flat +
                  (excluded > 0 ? " " + Int(excluded) + " gross errors are not drawn." : "") +
                  EvenThinningNote(static_cast<int>(d.samples.size()), stride));
}

namespace {

// The slow sensor error: the process the fit whitened by and what the residuals say.
void JsonSlowError(const SlowErrorReport& s, JsonWriter* w) {
  w->Key("slow_error").BeginObject();
  w->Key("enabled").Bool(s.enabled);
  if (s.enabled) {
    w->Key("sigma_percent").Number(s.process.sigma_percent);
    w->Key("sigma_kN").Number(s.process.sigma_n / 1e3);
    w->Key("time_constant_s").Number(s.process.time_constant_s);
    w->Key("amplitude_estimated").Bool(s.amplitude_estimated);
    w->Key("amplitude_part").String(s.amplitude_in_percent ? "sigma_percent" : "sigma_kN");
    w->Key("amplitude_sigma").Number(s.amplitude_in_percent ? s.amplitude_sigma
                                                            : s.amplitude_sigma / 1e3);
    w->Key("amplitude_at_floor").Bool(s.amplitude_at_floor);
    w->Key("time_constant_estimated").Bool(s.time_constant_estimated);
    w->Key("time_constant_sigma_s").Number(s.time_constant_sigma_s);
    w->Key("time_constant_at_bound").Bool(s.time_constant_at_bound);
    w->Key("likelihood_ratio_vs_white").Number(s.likelihood_ratio_vs_white);
    w->Key("maximum_likelihood").BeginObject();
    w->Key("sigma_percent").Number(s.maximum_likelihood.sigma_percent);
    w->Key("sigma_kN").Number(s.maximum_likelihood.sigma_n / 1e3);
    w->Key("time_constant_s").Number(s.maximum_likelihood.time_constant_s);
    w->EndObject();
    w->Key("stated_likelihood_ratio").Number(s.stated_likelihood_ratio);
    w->Key("stated_p_value").Number(s.stated_p_value);
    w->Key("stated_contradicted").Bool(s.stated_contradicted);
    w->Key("series").Int(s.series);
    w->Key("samples_used").Int(s.samples_used);
    w->Key("passes").Int(s.passes);
  }
  w->EndObject();
}

void JsonVerdictAndBudget(const CalibrationResult& r, JsonWriter* w) {
  w->Key("verdict").BeginObject();
  w->Key("status").String(FitVerdictName(r.verdict));
  w->Key("text").String(r.verdict_text);
  w->Key("notes").BeginArray();
  for (const std::string& n : r.notes) w->String(n);
  w->EndArray();
  w->EndObject();

  const UncertaintyBudget& b = r.budget;
  w->Key("uncertainty_budget").BeginObject();
  w->Key("reduced_chi_square").Number(b.reduced_chi_square);
  w->Key("misfit_factor").Number(b.misfit_factor);
  w->Key("residuals_correlated").Bool(b.correlated);
  w->Key("autocorrelation_time_samples").Number(b.tau);
  w->Key("batch_length_samples").Int(b.bandwidth);
  w->Key("samples").Int(b.samples);
  w->Key("effective_samples").Number(b.effective_samples);
  w->Key("correlation_reliable").Bool(b.correlation_reliable);
  w->Key("consider_groups").BeginArray();
  for (const std::string& g : b.consider_groups) w->String(g);
  w->EndArray();
  w->EndObject();
  JsonSlowError(r.slow_error, w);
}

void JsonReadings(const char* key, const std::vector<ReadingResidual>& list, JsonWriter* w) {
  w->Key(key).BeginArray();
  for (const ReadingResidual& e : list) {
    w->BeginObject();
    w->Key("line").Int(e.line);
    w->Key("cable").Int(e.cable);
    if (e.length) {
      w->Key("measured_m").Number(e.measured_m);
      w->Key("predicted_m").Number(e.predicted_m);
    } else {
      w->Key("measured_kN").Number(e.measured_n / kNPerKn);
      w->Key("predicted_kN").Number(e.predicted_n / kNPerKn);
    }
    w->Key("residual_sigma").Number(e.residual_sigma);
    w->Key("held_out").Bool(e.held_out);
    w->Key("reading").String(e.length ? "length" : "tension");
    w->EndObject();
  }
  w->EndArray();
}

// Why the threshold is what it is: the spec's floor, the family-wise value for the
// readings screened, and which of the two decided.
void JsonGrossErrorThreshold(const GrossErrorThreshold& t, JsonWriter* w) {
  w->Key("threshold_floor_sigmas").Number(t.floor_sigmas);
  w->Key("threshold_family_wise_sigmas").Number(t.family_wise_sigmas);
  w->Key("family_false_alarm").Number(kGrossErrorFamilyFalseAlarm);
  w->Key("screened_readings").Int(t.readings);
  w->Key("threshold_rule").String(t.family_wise_decides() ? "family-wise" : "spec floor");
  w->Key("threshold_why").String(DescribeGrossErrorThreshold(t));
}

void JsonGrossErrors(const CalibrationResult& r, JsonWriter* w) {
  const GrossErrorSummary& g = r.gross_error_summary;
  w->Key("gross_errors").BeginObject();
  w->Key("detect").Bool(g.enabled);
  w->Key("threshold_sigmas").Number(g.threshold_sigmas);
  JsonGrossErrorThreshold(g.threshold, w);
  w->Key("count_per_cable").NumberArray(std::vector<double>(g.count.begin(), g.count.end()));
  w->Key("robust_centre_sigma").NumberArray(g.centre);
  w->Key("robust_scale_sigma").NumberArray(g.scale);
  w->Key("fitted_readings").Int(g.fitted_readings);
  w->Key("fitted_flagged").Int(g.fitted_flagged);
  w->Key("settled").Bool(g.settled);
  if (r.lengths.used) {
    w->Key("length_count_per_cable")
        .NumberArray(std::vector<double>(g.length_count.begin(), g.length_count.end()));
    w->Key("length_robust_centre_sigma").NumberArray(g.length_centre);
    w->Key("length_robust_scale_sigma").NumberArray(g.length_scale);
  }
  w->EndObject();
  JsonReadings("outliers", r.gross_errors, w);
  JsonReadings("worst_readings", r.worst_readings, w);
}

void JsonMisfitAndValidation(const CalibrationResult& r, JsonWriter* w) {
  w->Key("misfit_ranking").BeginArray();
  for (const MisfitCandidate& c : r.misfit_ranking) {
    w->BeginObject();
    w->Key("name").String(c.name);
    w->Key("expected_chi_square_decrease").Number(c.expected_decrease);
    w->Key("statistic").Number(c.statistic);
    w->Key("significant").Bool(c.significant);
    w->Key("change").Number(c.change);
    w->Key("beyond_linear_range").Bool(c.beyond_linear_range);
    w->Key("unit").String(c.unit);
    w->Key("shifts").BeginObject();
    size_t k = 0;
    for (const ParameterEstimate& e : r.parameters) {
      if (!e.free || k >= c.shifts.size()) continue;
      w->Key(e.name).Number(c.shifts[k++]);
    }
    w->EndObject();
    w->EndObject();
  }
  w->EndArray();
  w->Key("misfit_significance_threshold").Number(r.misfit_threshold);

  const CrossValidation& cv = r.cross_validation;
  w->Key("cross_validation").BeginObject();
  w->Key("blocks").Int(cv.blocks);
  w->Key("blocks_used").Int(cv.folds_used);
  std::vector<double> rms, fit;
  for (int i = 0; i < kNumCables; ++i) {
    rms.push_back(cv.rms_n[i] / kNPerKn);
    fit.push_back(cv.fit_rms_n[i] / kNPerKn);
  }
  w->Key("rms_kN").NumberArray(rms);
  w->Key("fit_rms_kN").NumberArray(fit);
  w->EndObject();
  w->Key("residual_autocorrelation_time_samples").NumberArray(r.residual_tau);
}

}  // namespace

void WriteEvaluationGrossErrorsJson(const ReportInputs& in, JsonWriter* w) {
  if (in.evaluation_screen == nullptr) return;
  const EvaluationScreen& e = *in.evaluation_screen;
  w->Key("gross_errors").BeginObject();
  w->Key("detect").Bool(true);
  w->Key("variant").String(e.variant);
  w->Key("threshold_sigmas").Number(e.threshold.sigmas);
  JsonGrossErrorThreshold(e.threshold, w);
  std::vector<double> counts(e.count_per_cable.begin(), e.count_per_cable.end()), centre, scale;
  for (const RobustScale& c : e.cables) {
    centre.push_back(c.centre);
    scale.push_back(c.scale);
  }
  w->Key("count_per_cable").NumberArray(counts);
  w->Key("robust_centre_sigma").NumberArray(centre);
  w->Key("robust_scale_sigma").NumberArray(scale);
  w->EndObject();
  JsonReadings("outliers", e.gross_errors, w);
}

void JsonLengthStats(const char* key, const LengthResidualStats& s, JsonWriter* w) {
  w->Key(key);
  if (s.samples == 0) {
    w->Null();
    return;
  }
  w->BeginObject();
  w->Key("samples").Int(s.samples);
  w->Key("excluded").NumberArray(std::vector<double>(s.excluded.begin(), s.excluded.end()));
  w->Key("mean_m").NumberArray(s.mean_m);
  w->Key("rms_m").NumberArray(s.rms_m);
  w->Key("max_abs_m").NumberArray(s.max_abs_m);
  w->EndObject();
}

void WriteDiagnosticsJson(const CalibrationResult& r, JsonWriter* w) {
  JsonVerdictAndBudget(r, w);
  JsonGrossErrors(r, w);
  JsonMisfitAndValidation(r, w);
  w->Key("lengths");
  if (!r.lengths.used) {
    w->Null();
    return;
  }
  w->BeginObject();
  w->Key("sigma_m").Number(r.lengths.sigma_m);
  JsonLengthStats("initial", r.lengths.initial, w);
  JsonLengthStats("calibrated", r.lengths.calibrated, w);
  JsonLengthStats("initial_holdout", r.lengths.initial_holdout, w);
  JsonLengthStats("calibrated_holdout", r.lengths.calibrated_holdout, w);
  w->EndObject();
}

}  // namespace fastcal::internal
