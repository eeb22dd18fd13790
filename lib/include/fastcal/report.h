// The calibration report: what a calibration (or an evaluation alone) found, written for
// the engineers who run the cable robot and the colleagues they pass it on to.
//
//   report.md     Markdown: provenance, verdict, estimates, identifiability, RMS tables
//   report.html   the same, self-contained (inline <style> and SVG plots; no scripts, no
//                 external resources): correlation heatmap, RMS per cable as grouped bars,
//                 measured and predicted tension per cable against time, residual histogram;
//                 time plots of long datasets are thinned (min/max per bucket, at most 2000
//                 points a series, said in the caption), so the file stays under ~1 MB; the
//                 tables, statistics and histogram use every sample
//   summary.json  the numbers, for scripts (units in the key names: _kN, _percent)
//
// Sections: provenance (inputs with SHA-256 digests, software version, command line, the
// run's UTC date and time, forward model and its error against the exact statics,
// evaluation method, noise model, robust loss, gross-error screen, hold-out and
// cross-validation blocks, Ceres options, rows skipped); verdict (CalibrationResult's:
// ok, noise overstated, misfit scaled into the uncertainties, or failed; termination,
// iterations, cost, reduced chi-square and what it means, notes); estimates with
// sigma_total, the formal sigma and priors; the uncertainty budget (formal, widening,
// systematic per consider group); gross errors and the worst readings; what would explain
// the misfit (score test); identifiability (singular-value ratios, poorly determined and
// data-only directions, strong correlations); RMS of model - measured per cable (the
// paper's Table 6) for each variant on the fitted and the held-out samples, and block
// cross-validation, with the paper's published Table 6 beside when the data fly its
// measured circle (PaperCircleMatcher, trajectory.h: by the positions, not the file name); plots
// (per-cable tension and residual against time, joined by lines only for a trajectory; residual
// against off-axis angle and azimuth; predicted against measured; residual histogram; RMS bars;
// correlation heatmap); how to use the calibrated model; the Ceres full report. The only date is
// ReportInputs::run_utc, which the caller gives: the same inputs give the same bytes.
//
// Tensions are in kN in every table, plot and JSON key (the library is SI inside).
#ifndef FASTCAL_REPORT_H_
#define FASTCAL_REPORT_H_

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/evaluation_screen.h"
#include "fastcal/evaluation_stream.h"

namespace fastcal {

// A sample as the report's plots see it.
struct ReportSample {
  double time_s = 0.0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // measured
  std::array<double, kNumCables> measured_n{};
  // predicted_n[k]: the predicted readings of ReportInputs::variants[k], for each k with
  // ReportSampleStream::has_predictions[k].
  const std::array<double, kNumCables>* predicted_n = nullptr;
  std::array<bool, kNumCables> gross{};  // gross errors: red dots, their residuals not drawn
  bool held_out = false;
};

// The samples of an evaluation too long to hold (fastcal evaluate streams its file:
// evaluation_stream.h), replayed in order as often as the plots need (twice: the first
// replay finds the series' lengths and ranges, the second thins them), so that the
// report's memory is independent of their number. Everything drawn is what the samples
// held in ReportInputs::data with the variants' predicted_n would draw.
struct ReportSampleStream {
  long long samples = 0;
  double time_min_s = 0.0, time_max_s = 0.0;
  bool is_trajectory = true;          // internal::IsTrajectory of the samples
  std::vector<bool> has_predictions;  // per variant of ReportInputs::variants
  std::function<bool(const std::function<void(const ReportSample&)>& visit, std::string* error)>
      replay;
};

struct ReportInputs {
  // The input files as given on the command line; an empty model path means the built-in
  // nominal FAST model, an empty spec path an evaluation without calibration.
  std::string model_path, spec_path, data_path;
  // FileSha256 of each file (64 hex digits, as sha256sum prints them), filled by the
  // caller; empty if not known.
  std::string model_digest, spec_digest, data_digest;
  // The column map the data was read through (--columns, column_map.h) and its digest;
  // empty: the canonical format.
  std::string columns_path, columns_digest;
  std::string software_version;  // FASTCAL_VERSION (fastcal/version.h)
  std::string command_line;
  // When the run happened, UTC, e.g. "2026-11-22T15:04:05Z"; empty: not recorded.
  std::string run_utc;
  // The data file's provenance when `fastcal simulate` made it (its header comment, e.g.
  // "Simulated by fastcal 0.2.0\nfastcal simulate --seed=1 ...", lines joined by '\n');
  // empty: data not known to be simulated. The report then says so in its first lines,
  // and sets the paper's Table 6 beside its RMS only with that caveat (issue 59).
  std::string simulated_provenance;
  // Not owned; must outlive the calls. `data` is required. `spec` and `result` are null
  // for an evaluation-only report (`fastcal evaluate`); `initial_model` may be null.
  const CableRobot* initial_model = nullptr;
  const CalibrationSpec* spec = nullptr;
  const Dataset* data = nullptr;
  const CalibrationResult* result = nullptr;
  // The rows of the RMS table, in table order, e.g. "initial model, planned attitude",
  // "initial model, measured attitude", "calibrated model, measured attitude". With a
  // calibration result the last variant is the calibrated model and the one before it
  // the "before" the plots compare it with; without one, the plots show every variant.
  // predicted_n may be empty (then a variant is left out of the time and residual plots).
  std::vector<VariantEvaluation> variants;
  // Statics method of the evaluation, e.g. "exact".
  std::string evaluation_method;
  // For the calibrated model's "check it on other data" commands: the output directory
  // as given (--out; empty: "DIR"), and a dataset it was not fitted to, e.g. another
  // file beside the data (empty: "OTHER_DATA.csv", said to be one).
  std::string out_dir;
  std::string other_data_path;
  // For an evaluation-only report: the gross-error screen of the readings (not owned;
  // null: not screened).
  const EvaluationScreen* evaluation_screen = nullptr;
  // For an evaluation-only report of a file too long to hold: its samples (not owned).
  // `data` then holds the path, column flags and skipped rows only, and the variants'
  // predicted_n are empty. Null: data->samples are the samples.
  const ReportSampleStream* sample_stream = nullptr;
};

// The samples of a streamed evaluation for its report: replayed from its temporary file
// (`evaluation` must outlive the stream's use).
ReportSampleStream ReportSamplesOf(const StreamedEvaluation& evaluation);

// The report as Markdown, HTML and JSON. Each is deterministic (its only date is
// run_utc). They return
// an empty string only if memory runs out; missing inputs (no data, no variants) give a
// report that says what is missing.
std::string ReportMarkdown(const ReportInputs& inputs);
std::string ReportHtml(const ReportInputs& inputs);
std::string SummaryJson(const ReportInputs& inputs);

// Writes report.md, report.html and summary.json into `dir`, which must exist, each
// atomically (temporary file in `dir`, then rename). On any failure removes what it wrote,
// sets *error (naming the file and the reason) and returns false.
bool WriteReportFiles(const std::string& dir, const ReportInputs& inputs, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_REPORT_H_
