// `fastcal calibrate`: fit model parameters to a telemetry export and report (what it
// shares with evaluate: calibrate_common.h). Outputs go to a temporary directory that is
// renamed into place only when everything has been written.
#include <gflags/gflags.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>

#include "calibrate_common.h"
#include "cli_util.h"
#include "columns_flag.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/cable_robot.h"
#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/change_scan.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/evaluation_screen.h"
#include "fastcal/file_digest.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/quote.h"
#include "fastcal/internal/report_document.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/report.h"
#include "fastcal/sessions.h"
#include "fastcal/trajectory.h"
#include "fastcal/unsolvable_rows.h"
#include "fastcal/version.h"

DEFINE_bool(timings, false,
            "calibrate: print the wall time of reading, of each stage of the fit and of "
            "writing, on stderr.");

namespace fastcal::cli {
namespace {

namespace fs = std::filesystem;

const char kCalibrateHelp[] =
    R"(fastcal calibrate: estimate model parameters from measured cabin poses and cable tensions.

Usage:
  fastcal calibrate --spec=SPEC.yaml --data=DATA.csv --out=DIR [--model=MODEL.yaml] [--force]
                    [--columns=MAP.yaml] [--sessions-at=TIME,...]

  --model=FILE        starting model (docs/model-format.md); default the nominal FAST model
  --spec=FILE         which parameters are free, initial values, priors (a fixed
                      parameter with a prior is a consider parameter), noise model,
                      gross-error screen, robust loss, forward model, hold-out
                      (docs/calibration.md; calibration_data/spec_realistic.yaml is the
                      one recommended for real telemetry)
  --data=FILE         telemetry export: time_s, x_m,y_m,z_m, roll_deg,pitch_deg,yaw_deg (or
                      qw,qx,qy,qz), T1_kN..T6_kN, optional planned_*_deg, s0_*_m and
                      session (docs/data-format.md). --data=a.csv,b.csv: several
                      surveys, one session each, labelled by file name ("a", "b")
  --columns=MAP.yaml  read --data as exported, through a column map (format
                      fastcal-columns-1): source column names, units (mm, rad, N, tf...),
                      time stamps (unix_s, unix_ms, iso8601 with a zone), delimiter,
                      decimal comma, header line, unit row, extra channels
                      (docs/data-format.md, "Column maps"); an .xlsx: Python's
                      fastcal.read_dataset, or xlsx2csv first
  --sessions-at=TIME[,TIME...]  cut one survey into sessions s1, s2, ... at these times (a
                      sample at or after a time goes to the next): each a number in the
                      data's time_s or an ISO 8601 date and time (without a zone, the
                      column map's, else UTC); --sessions-at=DIR/summary.json takes the
                      changes a previous run's change scan found. With a spec that says
                      sessions: {separate: [...]} (calibration_data/spec_sessions.yaml)
  --out=DIR           output directory; must not exist or be empty. Written only when the
                      calibration succeeded: nothing is left behind on failure.
  --force             let --out be a previous run's results (only the files listed under
                      Outputs), replaced when the new ones are complete
  --residuals-every=K residuals.csv keeps one sample in K (default 1: every sample;
                      0: no residuals.csv). At 10^6 samples the full file is ~300 MB.
  --skip-invalid-rows skip rows that are malformed (a missing, non-numeric or non-finite
                      value, an implausible one...) or whose pose the initial model cannot
                      solve (e.g. outside the workspace), instead of failing; each is
                      listed with its line on stderr, in the report and in summary.json
  --quiet             no per-iteration solver progress
  --timings           after the run, the wall time of reading, of each stage of the
                      fit (with the cores it kept busy and the peak memory) and of
                      writing (stderr)

Before solving, the free set is checked: if the data (and priors) cannot determine it --
e.g. cabin mass together with a common sensor gain, or tower offsets from one circle --
the calibration is refused with the combination named and what to fix (exit 1).

Gross errors: a reading more than 5 robust sigmas from the model (the spec's
gross_errors.threshold_sigmas; more on a long dataset: the threshold at which Gaussian
noise has a 1% chance of naming any reading, 5.64 at 10^5 samples, 6.03 at 10^6) is kept
out of the fit and named by file line and cable; a dataset mostly made of them is
refused (exit 1).

Winch lengths: with noise: {length_sigma_m: ...} in the spec, the s0_1_m..s0_6_m columns
(the encoders' readings) are measurements too, six per sample beside the tensions, and
length_offset_m (each encoder's zero) may be free; a slipped encoder is a gross error of
a length ("line 812, length of cable 3"), and the console, report and summary.json give
model minus measured length per cable before and after (docs/calibration.md, "Lengths";
calibration_data/spec_lengths.yaml).

Each estimate comes with sigma_total, the uncertainty to quote: the formal sigma (stated
noise, independent samples) widened by the misfit and by residuals correlated in time,
plus what the consider parameters add. The console and report show its parts, the
gross errors, the fixed parameters whose freeing would explain most of the misfit, and
a block cross-validation RMS (docs/calibration.md).

Outputs in DIR:
  model_calibrated.yaml   the calibrated model (loads into fastcal solve and evaluate);
                          its comments list each estimate +- sigma_total, and open with
                          a warning if the fit failed
  report.html, report.md  verdict, estimates with sigma_total, uncertainty budget, gross
                          errors and worst readings, misfit ranking, identifiability, RMS
                          per cable before and after (the paper's Table 6), block
                          cross-validation, plots
  summary.json            the same, machine-readable (outliers: line, cable, reading,
                          measured_kN and predicted_kN or, for a length, measured_m and
                          predicted_m, residual_sigma; lengths), with provenance and the
                          UTC time
  model_calibrated@LABEL.yaml  with sessions: {separate: [...]} in the spec and data of
                          two or more sessions, the calibrated model of each session
                          (model_calibrated.yaml is the first's)
  residuals.csv           per sample: measured, nominal and calibrated tensions (kN)

Verdict, from the reduced chi-square against its band 1 +- 3 sqrt(2/nu) (nu: residuals
minus free parameters): ok; noise overstated (below; the sigmas are pessimistic);
misfit (above: scaled into sigma_total, a note ends stderr); failed (chi^2/nu above 25,
the residuals 5 times the stated noise, or no convergence: "warning: the fit failed"
ends stderr and model_calibrated.yaml opens with a warning); model incomplete (a fixed
parameter or a prior the data point at would move an estimate by more than 3 times its
uncertainty: "warning: model incomplete" ends stderr, the estimates concerned are marked
NOT SOUND; docs/calibration.md, "Model incomplete"). The exit code stays 0 for all five:
the outputs are written, as a record. A model whose cables carry attachments
(docs/model-format.md) needs forward_model: exact.

Streams: the one-screen summary (verdict, free estimates, gross errors, RMS table) on
stdout; progress, skipped rows, notes and warnings on stderr.

Exit codes: 0 the outputs were written (see the verdict), 1 the calibration failed or was
refused, a row's pose cannot be solved (without --skip-invalid-rows), or the machine
failed (out of memory, a full disk: the file named), 2 bad input.

Example (the bundled paper-like circle):
  fastcal calibrate --spec=calibration_data/spec_mass_centre_density.yaml \
    --data=calibration_data/circle_paper.csv --out=out/circle
)";

// The files calibrate (kCalibrateOutputs) and evaluate write into --out: what --force may
// replace there.
// "A*B": any name from A to B (a joint fit of sessions writes one model per session).
const std::vector<std::string> kCalibrateOutputs = {
    "model_calibrated.yaml", "model_calibrated@*.yaml", "report.html", "report.md", "summary.json",
    "residuals.csv"};

// With lengths in the fit: their RMS per cable before and after (mm), else "".
std::string LengthTable(const LengthEvaluation& l) {
  if (!l.used) return "";
  std::string s = "\n" + CableHeader("RMS model - measured length (mm)", "L");
  s += CableRow("initial model", l.initial.rms_m, 1e3);
  s += CableRow("calibrated model", l.calibrated.rms_m, 1e3);
  if (l.calibrated_holdout.samples > 0) {
    s += CableRow("calibrated model [hold-out]", l.calibrated_holdout.rms_m, 1e3);
  }
  return s;
}

PaperCircleMatcher PositionsOf(const Dataset& data) {
  PaperCircleMatcher matcher;
  for (const Sample& sample : data.samples) matcher.Add(sample.pose.position_m);
  return matcher;
}

// Threads that parse the data files (the same samples on any number): the machine FAST's
// tools run on has two cores, as the spec's default solver.threads.

bool LoadInputs(CableRobot* robot, Dataset* data, std::string* error) {
  std::vector<std::string> paths;
  if (!LoadModelAndDataPaths(robot, &paths, error)) return false;
  DatasetReadOptions read;
  read.skip_invalid_rows = FLAGS_skip_invalid_rows;
  read.threads = kReadThreads;
  SetJointColumns(robot->moving_parts, &read);
  if (!ColumnsFromFlag(&read.columns, error) || !ReadSessionDatasets(paths, read, data, error)) {
    return false;
  }
  // --sessions-at: one survey cut into sessions at times.
  std::vector<double> cuts;
  if (!SessionCutsFromFlag(*data, &cuts, error)) return false;
  if (cuts.empty()) return true;
  if (!CutSessionsAt(cuts, data, error)) {
    *error = "--sessions-at: " + *error;
    return false;
  }
  return true;
}

std::string BlameTheModel(const CableRobot& model, const std::string& model_name,
                          const Dataset& data, const std::vector<StaticsMethod>& methods) {
  return BlameText(
      DiagnoseUnsolvableRows(model, model_name, data,
                             {AttitudeSource::kPlanned, AttitudeSource::kMeasured}, methods),
      model_name);
}

// "0.192 +- 0.034 m": the estimate to the precision its sigma_total supports (a tiny
// estimate beside a large sigma is "0.000 +- 0.010", not "1.2e-09"); no unit for "1".
std::string ValueWithSigma(double estimate, double sigma, const std::string& unit) {
  const std::string shown_unit = unit == "1" ? "" : " " + unit;
  if (!(sigma > 0.0)) return internal::EstimateText(estimate, sigma) + shown_unit;
  return internal::EstimateText(estimate, sigma) + " +- " + internal::EstimateText(sigma, sigma) +
         shown_unit;
}

// The comment lines at the top of model_calibrated.yaml: provenance, a warning when the
// fit failed (the file is still written, as a record), and each free estimate with its
// sigma_total (the file's values have no room for uncertainties).
std::string CalibratedModelHeader(const CalibrationResult& result, const ReportInputs& report) {
  std::string header;
  if (result.verdict == FitVerdict::kFailed) {
    header += "WARNING: THIS CALIBRATION FAILED; DO NOT USE THIS MODEL.\n" + result.verdict_text +
              ".\n(report.md, Verdict)\n";
  } else if (result.verdict == FitVerdict::kModelIncomplete) {
    header += "WARNING: THE MODEL IS INCOMPLETE; ESTIMATES MARKED BELOW ARE NOT SOUND.\n" +
              result.verdict_text + ".\n(report.md, Verdict)\n";
  }
  header += "Calibrated by fastcal " + std::string(FASTCAL_VERSION) + " on " + report.run_utc +
            "\n" + report.command_line + "\ndata " + report.data_path + " (sha256 " +
            report.data_digest + ")" +
            (report.columns_path.empty() ? ""
                                         : "\nread through the column map " + report.columns_path +
                                               " (sha256 " + report.columns_digest + ")") +
            "\nverdict: " + FitVerdictName(result.verdict) +
            "\nestimates, +- sigma_total (the uncertainty to quote; report.md, Uncertainty "
            "budget):";
  for (const ParameterEstimate& p : result.parameters) {
    if (!p.free) continue;
    header += "\n  " + p.name + " = " + ValueWithSigma(p.estimate, p.sigma_total, p.unit);
    if (!p.moved_by.empty()) header += "  NOT SOUND: freeing " + p.moved_by + " would move it";
  }
  return header;
}

// The verdict as a last stderr line when it is not plain ok: a failed fit is a
// warning ("do not use"), a misfit scaled into the sigmas a note; "" when ok.
std::string ChiSquareWarning(const CalibrationResult& result) {
  switch (result.verdict) {
    case FitVerdict::kOk:
      return "";
    case FitVerdict::kFailed:
      return "fastcal calibrate: warning: the fit failed: " + result.verdict_text +
             " (report.md, Verdict)\n";
    case FitVerdict::kMisfit:
      return "fastcal calibrate: note: misfit scaled into sigma_total: " + result.verdict_text +
             " (report.md, Verdict)\n";
    case FitVerdict::kNoiseOverstated:
      return "fastcal calibrate: note: noise overstated: " + result.verdict_text + "\n";
    case FitVerdict::kModelIncomplete:
      return "fastcal calibrate: warning: model incomplete: " + result.verdict_text +
             " (report.md, Verdict)\n";
  }
  return "";
}

// "0.0012 m", "0.031 kg/m", "655 kg m": a sigma in the parameter's unit (the one its name
// carries, as its estimate beside it), 2 significant digits, and from 100 up in whole
// units as the estimate's "+- sigma" is (issue 59: "-310 +- 655 kg m" stood beside
// "6.6e+02 kg m").
std::string SigmaText(double sigma, const std::string& unit) {
  constexpr double kWholeFrom = 100.0;  // where %.2g turns to an exponent
  const std::string text = std::abs(sigma) >= kWholeFrom && std::isfinite(sigma)
                               ? internal::FormatDouble("%.0f", sigma)
                               : FormatDouble(sigma, 2);
  return text + (unit == "1" ? "" : " " + unit);
}

// Long notes are cut to kNoteLines lines on the console (the report has them whole).
constexpr size_t kNoteLines = 2;
constexpr size_t kEstimateRows = 14;

// Short flags of an estimate's note; the full notes are in the report.
std::string EstimateFlags(const ParameterEstimate& p) {
  std::string flags;
  // Model incomplete (calibration.h): the report says which candidate and by how much.
  if (!p.moved_by.empty()) {
    flags += "NOT SOUND: " + p.moved_by + " would move it " + FormatDouble(p.moved_by_sigmas, 2) +
             " sigma ";
  }
  if (p.note.find("set mostly by its prior") != std::string::npos) flags += "prior-dominated ";
  // A measured frame's offset along an axis the survey never turns (calibration_verdict.cc).
  if (p.note.find("the data never turn this axis") != std::string::npos)
    flags += "axis never turned ";
  if (p.note.find("not determined by the data alone") != std::string::npos) {
    flags += "data cannot determine ";
  } else if (p.note.find("poorly determined") != std::string::npos) {
    flags += "weak in data ";
  }
  return flags;
}

// A row of the estimates table with its note: after it when the row stays within
// kConsoleWidth, else on the next line, indented (a NOT SOUND note is 60 columns).
std::string WithNote(std::string row, std::string note) {
  while (!note.empty() && note.back() == ' ') note.pop_back();
  if (note.empty()) return row;
  if (row.size() + 2 + note.size() <= kConsoleWidth) return row + "  " + note;
  while (!row.empty() && row.back() == ' ') row.pop_back();
  std::string wrapped = Wrapped(note, "      ", "      ", kNoteLines);
  wrapped.pop_back();  // the rows are joined with newlines by the caller
  return row + "\n" + wrapped;
}

// The free estimates: value +- sigma_total, the formal sigma and the widening. A group of
// more than three per-cable or per-point parameters (sensor_gain[1..6]) is one row: the
// range of its estimates and of their sigma_total. At most kEstimateRows rows; the fixed
// and consider parameters and every part of the budget are in the report.
std::string EstimatesTable(const CalibrationResult& result) {
  constexpr size_t kGroupedFrom = 4;
  std::map<std::string, std::vector<const ParameterEstimate*>> groups;
  std::vector<std::string> order;
  for (const ParameterEstimate& p : result.parameters) {
    if (!p.free) continue;
    const std::string key = p.name.substr(0, p.name.find('['));
    if (!groups.count(key)) order.push_back(key);
    groups[key].push_back(&p);
  }
  std::vector<std::string> rows;
  char buf[240];
  // The name column: as wide as the longest name (moving_parts.rotator.first_moment_kg_m.x
  // is 40), at least 29, at most 44.
  int width = 29;
  for (const ParameterEstimate& p : result.parameters) {
    if (p.free) width = std::max(width, std::min(44, static_cast<int>(p.name.size())));
  }
  for (const std::string& key : order) {
    const std::vector<const ParameterEstimate*>& g = groups[key];
    if (g.size() < kGroupedFrom) {
      for (const ParameterEstimate* p : g) {
        std::snprintf(buf, sizeof(buf), "  %-*.*s %-31s %9s %8s", width, width, p->name.c_str(),
                      ValueWithSigma(p->estimate, p->sigma_total, p->unit).c_str(),
                      SigmaText(p->sigma, p->unit).c_str(),
                      ("x" + FormatDouble(p->widening, 2)).c_str());
        rows.push_back(WithNote(buf, EstimateFlags(*p)));
      }
      continue;
    }
    double lo = HUGE_VAL, hi = -HUGE_VAL, sigma_lo = HUGE_VAL, sigma_hi = 0.0, widest = 0.0;
    int marked = 0;
    std::string flags;
    for (const ParameterEstimate* p : g) {
      lo = std::min(lo, p->estimate);
      hi = std::max(hi, p->estimate);
      sigma_lo = std::min(sigma_lo, p->sigma_total);
      sigma_hi = std::max(sigma_hi, p->sigma_total);
      widest = std::max(widest, p->widening);
      if (flags.empty()) flags = EstimateFlags(*p);
      marked += !p->moved_by.empty();
    }
    if (marked > 0) {
      flags = "NOT SOUND: " + std::to_string(marked) + " of " + std::to_string(g.size()) +
              " (report.md) " +
              flags.substr(flags.rfind("NOT SOUND", 0) == 0 ? flags.find(" sigma ") + 7 : 0);
    }
    // "sensor_gain[1..6]": the first and the last index of the group.
    auto index_of = [](const std::string& name) {
      const size_t open = name.find('['), close = name.find(']');
      return name.substr(open + 1, close - open - 1);
    };
    const std::string label =
        key + "[" + index_of(g.front()->name) + ".." + index_of(g.back()->name) + "]";
    // The unit after the sigmas, as on a single row ("0.19 +- 0.03 m"): it is both's.
    const std::string unit = g.front()->unit == "1" ? "" : " " + g.front()->unit;
    const std::string range = FormatDouble(lo, 4) + ".." + FormatDouble(hi, 4) + " +- " +
                              FormatDouble(sigma_lo, 2) + ".." + FormatDouble(sigma_hi, 2) + unit;
    std::snprintf(buf, sizeof(buf), "  %-*.*s %-31s %9s %8s", width, width, label.c_str(),
                  range.c_str(), "", ("<= x" + FormatDouble(widest, 2)).c_str());
    rows.push_back(WithNote(buf, flags));
  }
  std::ostringstream s;
  std::snprintf(buf, sizeof(buf), "  %-*s %-31s %9s %8s  %s\n", width, "free parameter",
                "estimate +- sigma_total", "formal", "widening", "note");
  s << buf;
  for (size_t k = 0; k < rows.size() && k < kEstimateRows; ++k) {
    std::string row = rows[k];
    while (!row.empty() && row.back() == ' ') row.pop_back();
    s << row << "\n";
  }
  if (rows.size() > kEstimateRows) {
    s << "  ... " << rows.size() - kEstimateRows << " more rows (report.md, Estimates)\n";
  }
  return s.str();
}

// What each consider group adds to the estimates it matters most for, largest share of
// sigma_total first ("sensor_gain: 9 mm on mass_centre_m.x"); the report has them all.
std::string ConsiderLines(const CalibrationResult& result) {
  constexpr size_t kShown = 4;
  std::ostringstream s;
  const std::vector<std::string>& groups = result.budget.consider_groups;
  for (size_t g = 0; g < groups.size(); ++g) {
    std::vector<const ParameterEstimate*> on;
    for (const ParameterEstimate& p : result.parameters) {
      if (p.free && g < p.systematic_by_group.size() && p.sigma_total > 0) on.push_back(&p);
    }
    std::stable_sort(on.begin(), on.end(), [g](const auto* a, const auto* b) {
      return a->systematic_by_group[g] / a->sigma_total >
             b->systematic_by_group[g] / b->sigma_total;
    });
    std::string line;
    for (size_t k = 0; k < std::min(kShown, on.size()); ++k) {
      line += (k ? ", " : "") + SigmaText(on[k]->systematic_by_group[g], on[k]->unit) + " on " +
              on[k]->name;
    }
    if (on.size() > kShown) line += ", ...";
    s << Wrapped("systematic, from " + groups[g] + ": " + line, "  ", "    ", kNoteLines);
  }
  return s.str();
}

std::string GrossErrorLines(const CalibrationResult& result) {
  const GrossErrorSummary& g = result.gross_error_summary;
  if (!g.enabled) return "  gross errors: not screened (gross_errors.detect: false)\n";
  std::ostringstream s;
  const size_t count = result.gross_errors.size();
  s << "  gross errors (more than " << FormatDouble(g.threshold_sigmas, 3)
    << " robust sigmas from the model): " << count << (count == 1 ? " reading" : " readings")
    << ", kept out of the fit\n"
    << ThresholdLine("    ", g.threshold);
  s << ReadingLines(result.gross_errors, "    ");
  return s.str();
}

std::string MisfitLine(const CalibrationResult& result) {
  constexpr size_t kShown = 5;
  if (result.misfit_ranking.empty()) return "";
  const MisfitCandidate& top = result.misfit_ranking.front();
  if (!top.significant) {
    // As the report says it: the statistic nearest to significance against the threshold
    // (an expected decrease alone read as large on 10^6 samples, where the threshold is).
    const MisfitCandidate& nearest =
        *std::max_element(result.misfit_ranking.begin(), result.misfit_ranking.end(),
                          [](const MisfitCandidate& a, const MisfitCandidate& b) {
                            return a.statistic < b.statistic;
                          });
    return Wrapped(
        "no fixed parameter explains the misfit beyond the residuals' own noise: the largest "
        "statistic, " +
            FormatDouble(nearest.statistic, 3) + " (from freeing " + nearest.name +
            "), is below the threshold " + FormatDouble(result.misfit_threshold, 3),
        "  ", "    ", kNoteLines);
  }
  std::string line = "the misfit is best explained by freeing:";
  for (size_t k = 0; k < std::min(kShown, result.misfit_ranking.size()); ++k) {
    const MisfitCandidate& c = result.misfit_ranking[k];
    if (!c.significant) break;
    line += std::string(k ? ", " : " ") + c.name + " (about " +
            FormatDouble(c.expected_decrease, 3) + ")";
  }
  return Wrapped(line + " [expected chi-square decrease; each beyond the residuals' own noise]",
                 "  ", "    ", kNoteLines);
}

std::string CrossValidationLine(const CalibrationResult& result) {
  const CrossValidation& cv = result.cross_validation;
  if (cv.folds_used == 0) return "";
  return CableRow("calibrated, cross-validated (" + std::to_string(cv.folds_used) + " blocks)",
                  cv.rms_n, 1.0 / kNPerKn);
}

// A joint fit's differences between consecutive sessions ("" without sessions).
std::string SessionLines(const CalibrationResult& result) {
  if (result.session_differences.empty()) return "";
  std::ostringstream s;
  s << "\n  between sessions (later minus earlier, +- sigma_total from the full covariance):\n";
  char buf[200];
  for (const SessionDifference& d : result.session_differences) {
    std::snprintf(buf, sizeof(buf), "    %-24s %s -> %s  %+.4g +- %.3g %s  (%.1f sigma)\n",
                  d.name.c_str(), d.from.c_str(), d.to.c_str(), d.difference, d.sigma_total,
                  d.unit.c_str(), d.Sigmas());
    s << buf;
  }
  return s.str();
}

// Wall time of a command's phases.
class Stopwatch {
 public:
  // Seconds since the last lap (or construction).
  double Lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// --timings: read, the fit's stages (with the cores they kept busy), write (stderr), with
// the peak resident memory at the end of each stage.
std::string TimingLines(double read_s, double fit_s, double write_s,
                        const std::vector<CalibrationResult::Stage>& stages) {
  std::ostringstream s;
  char buf[160];
  s << "timings (wall; cores busy: CPU time / wall; peak resident memory so far):\n";
  const auto line = [&](const std::string& name, double seconds) {
    std::snprintf(buf, sizeof(buf), "  %-24s %8.3f s\n", name.c_str(), seconds);
    s << buf;
  };
  line("read inputs", read_s);
  line("fit", fit_s);
  for (const CalibrationResult::Stage& stage : stages) {
    std::snprintf(buf, sizeof(buf), "    %-22s %8.3f s  %4.1f  %6.0f MB\n", stage.name.c_str(),
                  stage.seconds, stage.seconds > 0.0 ? stage.cpu_seconds / stage.seconds : 0.0,
                  stage.peak_resident_mb);
    s << buf;
  }
  line("write outputs", write_s);
  return s.str();
}

// The verdict: its reason cut to a few lines (the report has it whole), then what the
// sessions, the change scan and the sensor-step test found, each whole on its own lines: a
// change found is the news of the run, never cut off behind the misfit's explanation.
std::string VerdictLines(const CalibrationResult& result) {
  constexpr size_t kFindingLines = 8;
  std::string reason = result.verdict_text;
  std::vector<std::string> findings;  // in the verdict's order: sessions, then the scan
  auto split_off = [&reason, &findings](const std::string& label, const std::string& part) {
    const std::string tail = "; " + part;
    if (reason.size() <= tail.size() ||
        reason.compare(reason.size() - tail.size(), tail.size(), tail) != 0) {
      return;
    }
    reason.resize(reason.size() - tail.size());
    findings.insert(findings.begin(), label + ": " + part);
  };
  // The verdict's parts in the reverse of their order (calibration_verdict.cc).
  if (const std::string steps = SensorStepVerdict(result.sensor_steps); !steps.empty()) {
    split_off("sensor steps", steps);
  }
  if (result.change_scan.enabled) split_off("change scan", ChangeScanVerdict(result.change_scan));
  if (!result.session_differences.empty()) {
    split_off("sessions", SessionVerdict(result.session_differences));
  }
  std::string out =
      Wrapped(std::string("verdict: ") + FitVerdictName(result.verdict) + ": " + reason, "", "  ",
              2 * kNoteLines);
  for (const std::string& f : findings) out += Wrapped(f, "  ", "    ", kFindingLines);
  return out;
}

std::string CalibrationConsole(const CalibrationResult& result, const Dataset& data,
                               const std::vector<VariantEvaluation>& variants) {
  std::ostringstream s;
  char buf[300];
  const ChiSquareBand band = ReducedChiSquareBand(result);
  std::snprintf(buf, sizeof(buf),
                "reduced chi-square %.3f (expected 1 +- %.3g) over %d residuals\n"
                "%d samples fitted, %d held out; %.2f s\n",
                result.reduced_chi_square, band.half_width, result.num_residuals,
                result.num_fit_samples,
                static_cast<int>(data.samples.size()) - result.num_fit_samples, result.seconds);
  s << buf << VerdictLines(result) << "\n"
    << EstimatesTable(result) << ConsiderLines(result) << SessionLines(result);
  for (const std::string& note : result.notes) s << Wrapped(note, "  ", "    ", kNoteLines);
  for (const ParameterDirection& d : result.data_only.undetermined) {
    s << Wrapped("the data alone cannot determine (a prior holds it): " + d.Describe(), "  ",
                 "    ", kNoteLines);
  }
  for (const ParameterDirection& d : result.data_only.poorly_determined) {
    s << Wrapped("weak direction in the data alone: " + d.Describe(), "  ", "    ", kNoteLines);
  }
  if (!result.strong_correlations.empty()) {
    std::string pairs;
    for (const std::string& c : result.strong_correlations)
      pairs += (pairs.empty() ? "" : "; ") + c;
    s << Wrapped("strongly correlated: " + pairs, "  ", "    ", kNoteLines);
  }
  s << GrossErrorLines(result) << MisfitLine(result) << "\n"
    << RmsTable(variants) << CrossValidationLine(result) << LengthTable(result.lengths)
    << PaperTable6Lines(PositionsOf(data), !SimulatedProvenance().empty()) << "\nwrote "
    << FLAGS_out << "/{model_calibrated.yaml, ";
  // One model a session when the spec separates parameters by session.
  for (size_t k = 0; k < result.session_models.size(); ++k) {
    s << "model_calibrated@" << result.session_labels[k] << ".yaml, ";
  }
  s << "report.html, report.md, summary.json"
    << (FLAGS_residuals_every > 0 ? ", residuals.csv" : "") << "}\n";
  return s.str();
}

}  // namespace

// --skip-invalid-rows for calibrate: what must solve are the "initial model" rows of the
// table (exact, every attitude the data has) and the fit's start, the spec's initial
// values (its forward model and exact, at the fit's attitude).
void SkipSamplesTheCalibrationCannotSolve(const CableRobot& model, const CalibrationSpec& spec,
                                          Dataset* data) {
  const AttitudeSource fit_attitude =
      spec.use_planned_attitude ? AttitudeSource::kPlanned : AttitudeSource::kMeasured;
  const std::string name = "the initial model";
  SkipUnsolvableSamples(model, name, {AttitudeSource::kPlanned, AttitudeSource::kMeasured},
                        {StaticsMethod::kExact}, data);
  SkipUnsolvableSamples(InitialCalibrationModel(model, spec), name, {fit_attitude},
                        {spec.forward_model, StaticsMethod::kExact}, data);
}

// calibrate's --out: the calibrated model (one per session too), residuals.csv (unless
// --residuals-every=0) and the report files. False, with the error printed, on failure.
bool WriteCalibrationOutputs(int argc, char** argv, const CableRobot& model,
                             const CalibrationSpec& spec, const Dataset& data,
                             const std::string& data_digest, CalibrationResult* calibration) {
  const CalibrationResult& result = *calibration;
  ReportInputs report = ReportProvenance(argc, argv, /*with_spec=*/true, &data_digest);
  report.initial_model = &model;
  report.spec = &spec;
  report.data = &data;
  report.result = &result;
  // Lent to the report, not copied (48 bytes a sample each); given back below.
  report.variants = std::move(calibration->variants);
  const std::vector<VariantEvaluation>& variants = report.variants;
  report.evaluation_method = "exact";
  report.out_dir = FLAGS_out;
  report.other_data_path = OtherDataset(FLAGS_data);

  std::vector<std::pair<std::string, std::string>> files = {
      {"model_calibrated.yaml",
       CableRobotToYaml(result.calibrated, CalibratedModelHeader(result, report))}};

  std::vector<std::string> outputs = kCalibrateOutputs;
  for (size_t s = 0; s < result.session_models.size(); ++s) {
    const std::string name = "model_calibrated@" + result.session_labels[s] + ".yaml";
    files.push_back({name, CableRobotToYaml(result.session_models[s],
                                            "session " + result.session_labels[s] + "\n" +
                                                CalibratedModelHeader(result, report))});
    outputs.push_back(name);  // --force may replace a previous run's
  }
  const bool written = WriteOutDirectory(
      "calibrate", files, report, outputs,
      [&](const std::string& dir, std::string* why) {
        return FLAGS_residuals_every <= 0 ||
               WriteResidualsFile(dir, data, variants, result.held_out, result.excluded,
                                  FLAGS_residuals_every, spec.num_threads, why);
      },
      /*more_beside_report=*/true);
  calibration->variants = std::move(report.variants);
  return written;
}

int RunCalibrate(int argc, char** argv) {
  const char* command = "calibrate";
  int exit_code = 0;
  if (!StartCommand(argc, argv, command, kCalibrateHelp,
                    {"model", "spec", "data", "out", "skip-invalid-rows", "quiet", "force",
                     "residuals-every", "timings", "columns", "sessions-at"},
                    &exit_code)) {
    return exit_code;
  }
  std::string error;
  if (FLAGS_spec.empty() || FLAGS_out.empty()) {
    PrintError(command,
               "--spec=FILE.yaml, --data=FILE.csv and --out=DIR are required (see "
               "fastcal calibrate --help)");
    return kExitUsage;
  }
  CableRobot model;
  Dataset data;
  CalibrationSpec spec;
  Stopwatch watch;
  // The data files' digest for the report, hashed beside the (one-core) read: ~0.4 s at
  // 10^6 samples that no longer adds to the run.
  std::future<std::string> data_digest = AsyncOrDeferred(DataDigest);
  if (!CheckResidualsEvery(&error) || !CheckOutFlag(kCalibrateOutputs, &error) ||
      !LoadInputs(&model, &data, &error) ||
      !LoadCalibrationSpec(FLAGS_spec, model, &spec, &error)) {
    PrintError(command, error);
    return kExitUsage;
  }
  const double read_s = watch.Lap();
  if (!FLAGS_sessions_at.empty() && spec.separate_groups.empty()) {
    std::cerr << "fastcal calibrate: note: --sessions-at cut the survey into "
              << data.session_labels.size()
              << " sessions, but the spec separates no parameter per session (sessions: "
                 "{separate: [mass_centre_m]}, as calibration_data/spec_sessions.yaml): they "
                 "are fitted as one\n";
  }
  const CableRobot initial = InitialCalibrationModel(model, spec);
  const std::vector<StaticsMethod> methods = {StaticsMethod::kExact, spec.forward_model};
  if (FLAGS_skip_invalid_rows) {
    if (const std::string blame = BlameTheModel(initial, "the initial model", data, methods);
        !blame.empty()) {
      PrintError(command, blame);
      return kExitFailure;
    }
    SkipSamplesTheCalibrationCannotSolve(model, spec, &data);
  }
  if (!ReportSkipped(command, data, &error)) {
    PrintError(command, error);
    return kExitFailure;
  }
  std::cerr << "fastcal calibrate: " << data.samples.size()
            << (data.samples.size() == 1 ? " sample from " : " samples from ")
            << internal::Escape(data.path) << SkippedNote(data) << ", model "
            << internal::Escape(ModelName(FLAGS_model)) << ", forward model "
            << StaticsMethodName(spec.forward_model) << "\n";
  CalibrationOptions options;
  if (!FLAGS_quiet)
    options.progress = [](const std::string& line) { std::cerr << "  " << line << "\n"; };
  CalibrationResult result;
  watch.Lap();
  const CalibrationStatus status = Calibrate(model, spec, data, options, &result, &error);
  const double fit_s = watch.Lap();
  if (status == CalibrationStatus::kInfeasible) {
    if (const std::string blame = BlameTheModel(initial, "the initial model", data, methods);
        !blame.empty()) {
      PrintError(command, blame);
      return kExitFailure;
    }
  }
  if (status != CalibrationStatus::kOk) {
    PrintError(command, error + (status == CalibrationStatus::kInfeasible ? SkipHint() : ""));
    return status == CalibrationStatus::kInvalidInput ? kExitUsage : kExitFailure;
  }

  if (!WriteCalibrationOutputs(argc, argv, model, spec, data, data_digest.get(), &result)) {
    return kExitFailure;  // checked before the fit: the machine's failure (a full disk)
  }
  if (FLAGS_timings) std::cerr << TimingLines(read_s, fit_s, watch.Lap(), result.stages);

  // Results on stdout, progress and diagnostics on stderr (docs/cli.md, "Output streams").
  if (!FLAGS_quiet) std::cerr << result.ceres_brief_report << "\n";
  std::cout << CalibrationConsole(result, data, result.variants) << std::flush;
  std::cerr << ChiSquareWarning(result);
  return 0;
}

}  // namespace fastcal::cli
