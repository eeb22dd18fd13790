// The calibration report's diagnostic sections (report_diagnostics.cc), shared by the
// Markdown/HTML document and summary.json (report.cc): the uncertainty budget, the gross
// errors and worst readings, the misfit ranking, block cross-validation, and the plots
// that suit unordered data (residual against the pose's off-axis angle and azimuth,
// predicted against measured).
#ifndef FASTCAL_INTERNAL_REPORT_SECTIONS_H_
#define FASTCAL_INTERNAL_REPORT_SECTIONS_H_

#include "fastcal/calibration.h"
#include "fastcal/dataset.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/report_document.h"
#include "fastcal/report.h"
#include "fastcal/svg_plot.h"

namespace fastcal::internal {

// Whether the samples follow a trajectory (consecutive positions close against their
// spread: lines join them) or are an unordered set (dots only): the median step between
// consecutive positions below kTrajectoryStepFraction of the positions' RMS spread.
inline constexpr double kTrajectoryStepFraction = 0.2;
bool IsTrajectory(const Dataset& data);
// The same test from its numbers: n samples, the median step and the RMS spread.
bool IsTrajectory(long long n, double median_step_m, double spread_m);

// Every k-th point of a series with more than `max_points` (k the smallest that leaves
// at most max_points; *stride receives k, 1 if nothing was thinned). For data that are not
// a time series (scatter plots, unordered samples): min/max per bucket of consecutive
// samples would keep only each bucket's extremes of an unordered cloud and draw two
// false bands.
PlotSeries ThinEvenly(const PlotSeries& series, int max_points, int* stride);
// Says in a caption that series were thinned evenly (stride > 1).
std::string EvenThinningNote(int num_samples, int stride);

// Off-axis angle (deg, 0 at the bottom of the focal sphere) and azimuth (deg, [0, 360)
// from +x toward +y) of a position seen from the focal centre (0, 0, 300) m.
double OffAxisDeg(const Eigen::Vector3d& position_m);
double AzimuthDeg(const Eigen::Vector3d& position_m);

void AddUncertaintyBudget(const CalibrationResult& r, Document* doc);
void AddGrossErrors(const ReportInputs& in, Document* doc);
// With lengths in the fit: their residuals per cable before and after (nothing without).
void AddLengths(const CalibrationResult& r, Document* doc);
// evaluate's: the screen of the readings against the model (in.evaluation_screen).
void AddEvaluationGrossErrors(const ReportInputs& in, Document* doc);
void WriteEvaluationGrossErrorsJson(const ReportInputs& in, JsonWriter* w);
void AddMisfitRanking(const CalibrationResult& r, Document* doc);
void AddCrossValidation(const CalibrationResult& r, Document* doc);
void AddDiagnosticPlots(const ReportInputs& in, Document* doc);

// summary.json's keys for the same: verdict, uncertainty_budget, gross_errors, outliers,
// worst_readings, misfit_ranking, cross_validation, residual_autocorrelation_time, lengths
// (null without them).
void WriteDiagnosticsJson(const CalibrationResult& r, JsonWriter* w);

// The cabin's moving parts (report_moving_parts.cc): the calibrated first moments and
// masses in words, the largest shift of the mass centre over the joints' ranges, and its
// sweep per joint. Nothing for a model without moving parts.
void AddMovingParts(const ReportInputs& in, bool with_plots, Document* doc);

// A joint fit's sessions (report_sessions.cc): the separate parameters per session with
// sigma_total, the differences between consecutive sessions, and a plot per parameter.
// Nothing without sessions.
void AddSessions(const CalibrationResult& r, bool with_plots, Document* doc);
// summary.json's `sessions` (labels) and `session_differences` (empty without sessions).
void WriteSessionsJson(const CalibrationResult& r, JsonWriter* w);
// The change scan (report_sessions.cc): the changes found, the statistic over time with
// its threshold and the changes marked. Nothing without a scan.
void AddChangeScan(const CalibrationResult& r, bool with_plots, Document* doc);
// summary.json's `change_scan` (null without a scan) and `changes` (empty when none).
void WriteChangeScanJson(const CalibrationResult& r, JsonWriter* w);

// summary.json (report_json.cc), and the facts it shares with the document: the RMS over
// the six cables of per-cable RMS values, the dataset's samples and those held out.
std::string RenderJson(const ReportInputs& in);
double RmsAllCables(const std::array<double, kNumCables>& rms);
int NumSamples(const ReportInputs& in);
int NumHeldOut(const ReportInputs& in);
// The correlation matrix of the free estimates as rows, and whether it can be shown.
std::vector<std::vector<double>> CorrelationRows(const CalibrationResult& r);
bool CorrelationUsable(const CalibrationResult& r);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_REPORT_SECTIONS_H_
