// `fastcal track`: the mass centre and the sensors through a season of telemetry, one
// window (a day by default) at a time, as one joint fit (track.h). Flags -> options ->
// library; the summary on stdout, progress on stderr.
#include <gflags/gflags.h>

#include <algorithm>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "columns_flag.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/time_text.h"
#include "fastcal/track.h"

DEFINE_string(window, "1d", "track: window length (1d, 12h, 30m, 3600s) or 'file'.");
DEFINE_string(window_origin, "",
              "track: where the windows' boundaries fall, HH:MM with a zone (12:00+08:00).");
DEFINE_int32(threads, 2, "track: windows folded at once.");
DEFINE_bool(refold, false, "track: on an update, refold every window at the new point.");
DEFINE_bool(keep_overlapping, false,
            "track: fold files whose time spans overlap (refused otherwise: the same "
            "instants given twice).");
DEFINE_int64(min_window_samples, 100, "track: windows with fewer samples are left out.");
DEFINE_bool(exit_new_events, false,
            "track: exit with status 3 when the run reports an event the previous one did not.");
DEFINE_double(false_alarm, 0.01,
              "track: chance that noise alone reports any event of a kind over the track.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "track";
// Windows listed on stdout in full up to this many; beyond, the first and last few.
constexpr size_t kMaxListedWindows = 40;
constexpr size_t kListedEnds = 10;

const char kHelp[] =
    R"(fastcal track: the mass centre and the sensors through a season of telemetry.

Usage:
  fastcal track --spec=SPEC.yaml --data=DIR_OR_FILES --out=DIR [--window=1d] [--model=MODEL.yaml]
                [--columns=MAP.yaml]

  --spec=FILE         the calibration spec; its sessions.separate groups are fitted per
                      window, every other free parameter once for all windows
                      (calibration_data/spec_track.yaml follows the mass centre per day,
                      with the cables and sensors shared)
  --data=DIR_OR_FILES telemetry files (docs/data-format.md) with Unix or ISO 8601 times,
                      in any order: a directory (its *.csv files), or FILE.csv,FILE.csv,...
                      (one file of relative times, from its own start, is windowed on its
                      own time line; two need --window=file)
  --out=DIR           the track: a new or empty directory, or a track built before, which
                      is then updated with the files it does not hold yet (the old windows'
                      folds are kept: only windows that gained samples are folded); one run
                      at a time, however DIR is spelled (its lock .DIR.lock beside it, gone
                      when the run ends)
  --window=1d         windows: a calendar day in UTC (1d), another duration aligned to
                      1970-01-01T00:00Z (12h, 30m, 3600s, 7d, at most 366d), or 'file' (one
                      per file)
  --window-origin=HH:MM+ZZ:ZZ  the windows' boundaries at this time of day on that clock
                      (12:00+08:00: local noon in Beijing, a night's observing one window;
                      labels are then dates on that clock); an update must keep it
  --model=FILE        starting model (docs/model-format.md); default the nominal FAST model
  --columns=MAP.yaml  read every data file as exported, through a column map (ISO 8601
                      times, units, delimiters: docs/data-format.md, "Column maps"); an
                      update must use the same map
  --threads=2         windows folded at once
  --min-window-samples=100  windows with fewer samples are left out (and named)
  --false-alarm=0.01  each kind of event: the chance that noise alone reports any over
                      the whole track (Bonferroni over its tests)
  --exit-new-events   exit with status 3 (the track written) when an event is new: not
                      reported by the track's previous run (events.json: each event's
                      "new", "new_events"); every event of a track built afresh is new
  --refold            on an update, refold every window at the new point (and re-estimate
                      the slow error), as a fresh track would
  --force             build the track afresh from the data, whatever DIR holds (needed
                      when DIR holds a track of another model, spec or windowing, of
                      files that changed, or a damaged one)
  --keep-overlapping  fold files whose time spans overlap (refused otherwise: the same
                      instants given twice would be folded twice)
  --skip-invalid-rows skip malformed rows (named on stderr) instead of failing
  --quiet             no progress on stderr

Each window is folded at a linearisation point into its information over its own
parameters and the shared ones (whitened by the slow sensor error, gross errors screened);
the shared parameters come from the Schur complement of all windows, each window's from
back-substitution, Gauss-Newton until every step is below 5% of its sigma. Each estimate
has sigma_total: the joint fit's covariance widened per window by its misfit and by
residuals still correlated in time, plus the consider parameters' part.

Events (events.json), each kind at a 1% false-alarm rate over the whole track, on one
time line: a change may happen between two windows or inside one.
  sensor     a sensor's bias stepped (re-zeroed): found by a score scan over cables and
             window boundaries, fitted per stretch, then placed at its most likely time
             (overnight, or inside the day before or after; a window with the step
             inside gets its own value), so that it does not read as a mass-centre move
  parameter  a per-window group (the mass centre) changed: each candidate time, between
             windows or between blocks of one (about 1/32 of it), tested with all the
             data before and after it; several found in turn; beyond the group's wander
             from window to window (estimated with the steps found taken out, and
             stated: a mass centre that moves about is not a string of steps)
Dating: a change between windows lies between the last sample before it and the first
after ("between A and B"); one inside a window at its most likely block, with its
likelihood interval (inside the window, at TIME, from LOW to HIGH; events.json: time,
after, time_low, time_high). Times in the column map's zone (UTC without a map).

Outputs in DIR:
  track.csv               one row per window: window_start, window_end (ISO 8601 in
                          the column map's zone, UTC without a map), samples, NAME,
                          NAME_sigma_total per per-window parameter, each sensor's
                          offset, chi2/nu, widening, gross errors, window label
  events.json             the events: time, after, time_low, time_high, kind, parameters
                          {shift, sigma_total}, cables, statistic, p_value (family-wise)
  model_calibrated.yaml   the current model, at a stable path: the event-free stretch
                          of the latest window (its windows averaged), as below
  model_calibrated@W.yaml the latest window's model, and one per event-free stretch
                          (@FIRST_to_LAST); a window with a move inside its telemetry in
                          its two parts (@W_before, @W_after; track.csv's rows too)
  track.html              the per-window parameters with bars, the sensors, the events
  track_state.json, folds/, windows/   the track's state for an update (docs/calibration.md,
                          "Tracking: files"); windows/ holds each window's samples (160 bytes
                          a sample)

Exit codes: 0 the track was written, 1 the fit failed (a pose the model cannot solve,
parameters undetermined), 2 bad input, 3 the track was written and holds new events
(with --exit-new-events only). Python: fastcal.track (also on a Dask cluster).

Example:
  fastcal simulate --trajectory=random --samples=18000 --days=10 --interval-s=2 \
      --start=2024-05-01T20:00:00Z --mass-centre-step=2024-05-05T20:00:00Z:0.05,0,0 \
      --sensor-step=2024-05-08T20:00:00Z:3:5 --out=season.csv
  fastcal track --spec=calibration_data/spec_track.yaml --data=season.csv --out=track
)";

std::vector<std::string> SplitPaths(const std::string& text) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

std::string Estimate(const TrackEstimate& e, const std::string& unit) {
  return internal::FormatDouble("%.6g", e.value) + " +- " +
         internal::FormatDouble("%.2g", e.sigma_total) + (unit == "1" ? "" : " " + unit);
}

// Lines of a sentence on the console at most (the header, the slow error, notes: whole in
// track.html and events.json).
constexpr size_t kSentenceLines = 4;

// The summary's stages: the head (windows, samples, convergence, slow error), the shared
// parameters, the per-window table, and the events.
std::string SummaryHead(const TrackResult& r) {
  const auto count = [](long long n, const char* one, const char* many) {
    return internal::Counted(n, one, many);
  };
  std::ostringstream head;
  head << "fastcal track: " << count(static_cast<long long>(r.windows.size()), "window", "windows")
       << " of " << WindowSpecText(r.window);
  if (r.windows.size() > 1) {
    head << " (" << r.windows.front().label << " to " << r.windows.back().label << ")";
  } else if (r.windows.size() == 1) {
    head << " (" << r.windows.front().label << ")";
  }
  head << ", " << count(r.samples, "sample", "samples") << " from "
       << count(static_cast<long long>(r.files.size()), "file", "files") << "; "
       << DescribeGaussNewton(r) << ", " << count(r.folds, "fold", "folds")
       << (r.updated ? " (an update)" : "") << "; chi2/nu "
       << internal::FormatDouble("%.3f", r.reduced_chi_square);
  std::string s = Wrapped(head.str(), "", "  ", kSentenceLines, "track.html");
  if (r.slow_error.enabled) {
    s += Wrapped(DescribeSlowError(r.slow_error), "", "  ", kSentenceLines, "track.html");
  }
  return s;
}

std::string SharedLines(const TrackResult& r) {
  std::ostringstream s;
  s << "\nShared parameters (sigma_total):\n";
  for (const TrackShared& p : r.shared) {
    s << "  " << p.name << " = " << Estimate(p.estimate, p.unit);
    if (!(p.from_window == 0 && p.to_window + 1 == static_cast<int>(r.windows.size()))) {
      s << "   (windows " << r.windows[p.from_window].label << " to "
        << r.windows[p.to_window].label << ")";
    }
    s << "\n";
  }
  return s.str();
}

// The per-window table: each estimate's value right-aligned in its column and its
// sigma_total after it, so that the digits line up.
std::string WindowLines(const TrackResult& r) {
  std::vector<size_t> listed;
  for (size_t w = 0; w < r.windows.size(); ++w) {
    if (r.windows.size() > kMaxListedWindows && w == kListedEnds)
      w = r.windows.size() - kListedEnds;
    listed.push_back(w);
  }
  const size_t n = r.window_parameters.size();
  std::vector<size_t> value_width(n, 0), sigma_width(n, 0);
  size_t label_width = std::string("window").size();
  const auto value = [&](size_t w, size_t k) {
    return internal::FormatDouble("%.6g", r.windows[w].estimates[k].value);
  };
  const auto sigma = [&](size_t w, size_t k) {
    return internal::FormatDouble("%.2g", r.windows[w].estimates[k].sigma_total);
  };
  for (size_t w : listed) {
    label_width = std::max(label_width, r.windows[w].label.size());
    for (size_t k = 0; k < n; ++k) {
      value_width[k] = std::max(value_width[k], value(w, k).size());
      sigma_width[k] = std::max(sigma_width[k], sigma(w, k).size());
    }
  }
  const auto pad = [](const std::string& text, size_t width, bool right) {
    const std::string fill(width > text.size() ? width - text.size() : 0, ' ');
    return right ? fill + text : text + fill;
  };
  std::vector<std::string> cells(n);
  std::ostringstream s;
  s << "\nPer window (track.csv):\n  " << pad("window", label_width, false);
  for (size_t k = 0; k < n; ++k) {
    const std::string unit = r.window_units[k] == "1" ? "" : " " + r.window_units[k];
    const size_t width = value_width[k] + 4 + sigma_width[k] + unit.size();
    s << "  " << (k + 1 < n ? pad(r.window_parameters[k], width, false) : r.window_parameters[k]);
  }
  s << "\n";
  for (size_t i = 0; i < listed.size(); ++i) {
    const size_t w = listed[i];
    if (i > 0 && w != listed[i - 1] + 1) {
      s << "  ... (" << w - listed[i - 1] - 1 << " more)\n";
    }
    s << "  " << pad(r.windows[w].label, label_width, false);
    for (size_t k = 0; k < n; ++k) {
      const std::string unit = r.window_units[k] == "1" ? "" : " " + r.window_units[k];
      s << "  " << pad(value(w, k), value_width[k], true) << " +- "
        << pad(sigma(w, k), sigma_width[k], false) << unit;
    }
    s << "\n";
  }
  return s.str();
}

std::string EventLine(const TrackResult& r, const TrackEvent& e) {
  std::ostringstream line;  // wrapped at the console's width below
  line << (e.is_new && r.updated ? "new " : "") << e.kind;
  if (!e.cables.empty()) {
    line << " (cable";
    for (int c : e.cables) line << " " << c;
    line << ")";
  }
  line << " " << DescribeEventTime(r, e) << ":";
  for (const TrackEventParameter& p : e.parameters) {
    line << " " << p.name << " " << internal::FormatDouble("%+.4g", p.shift) << " +- "
         << internal::FormatDouble("%.2g", p.sigma_total) << (p.unit == "1" ? "" : " " + p.unit)
         << ";";
  }
  line << " p = " << internal::FormatDouble("%.2g", e.p_value);
  return Wrapped(line.str(), "  " + r.windows[e.window].label + "  ", "      ", 8, "events.json");
}

std::string EventLines(const TrackResult& r) {
  std::ostringstream s;
  s << "\nEvents (events.json; each kind at a "
    << internal::FormatDouble("%g", 100.0 * r.false_alarm)
    << "% false-alarm rate over the track): " << r.events.size();
  if (r.updated) s << " (" << r.NewEvents() << " new since the previous run)";
  s << "\n";
  for (const TrackWander& w : r.wander) {
    const std::string text = DescribeWander(w);
    if (!text.empty()) s << Wrapped("(" + text + ")", "  ", "   ", kSentenceLines, "track.html");
  }
  for (const TrackEvent& e : r.events) s << EventLine(r, e);
  return s.str();
}

std::string Summary(const TrackResult& r, const std::string& out) {
  std::string s = SummaryHead(r) + SharedLines(r) + WindowLines(r) + EventLines(r);
  for (const std::string& n : r.notes) {
    s += Wrapped("Note: " + n, "", "  ", kSentenceLines, "track.html");
  }
  return s + "\nWritten to " + out + ": track.csv, events.json, track.html, " +
         (r.current_model >= 0 ? "model_calibrated.yaml (the current model), " : "") +
         std::to_string(r.models.size()) + " model_calibrated@*.yaml\n";
}

}  // namespace

int RunTrack(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp,
                    {"model", "spec", "data", "out", "window", "window-origin", "threads", "refold",
                     "force", "keep-overlapping", "quiet", "skip-invalid-rows", "exit-new-events",
                     "min-window-samples", "false-alarm", "columns"},
                    &exit_code)) {
    return exit_code;
  }
  std::string error;
  const auto usage = [&](const std::string& message) {
    PrintError(kCommand, message);
    return kExitUsage;
  };
  if (FLAGS_spec.empty()) return usage("--spec=SPEC.yaml is required");
  if (FLAGS_data.empty()) return usage("--data=DIR_OR_FILES is required");
  if (FLAGS_out.empty()) return usage("--out=DIR is required");
  WindowSpec window;
  std::string window_text = FLAGS_window;
  if (!FLAGS_window_origin.empty()) {
    if (window_text.find('@') != std::string::npos) {
      return usage("--window-origin: --window=" + FLAGS_window + " already has an origin");
    }
    window_text += "@" + FLAGS_window_origin;
  }
  if (!ParseWindowSpec(window_text, &window, &error)) return usage("--" + error);
  CableRobot model;
  if (!LoadModelFlag("model", FLAGS_model, &model, &error)) return usage(error);
  CalibrationSpec spec;
  if (!LoadCalibrationSpec(FLAGS_spec, model, &spec, &error)) return usage(error);
  const std::vector<std::string> data = SplitPaths(FLAGS_data);
  if (std::find(data.begin(), data.end(), "") != data.end()) {
    return usage("--data=" + internal::Quote(FLAGS_data) +
                 " has an empty file name (a stray comma?)");
  }
  TrackOptions options;
  options.threads = FLAGS_threads;
  options.refold_all = FLAGS_refold;
  options.keep_overlapping = FLAGS_keep_overlapping;
  options.force = FLAGS_force;
  options.min_window_samples = FLAGS_min_window_samples;
  // A subsample never smaller than a window the track keeps (TrackOptions::IsValid): a
  // --min-window-samples above the default subsample raises it, not refused.
  options.first_fold_samples =
      std::max<long long>(options.first_fold_samples, options.min_window_samples);
  options.false_alarm = FLAGS_false_alarm;
  options.read.skip_invalid_rows = FLAGS_skip_invalid_rows;
  if (!ColumnsFromFlag(&options.read.columns, &error)) return usage(error);
  if (!FLAGS_quiet) {
    // Wrapped at the console's width, never cut (nothing else holds these lines).
    options.progress = [](const std::string& line) {
      std::cerr << Wrapped(line, "  ", "      ", std::numeric_limits<size_t>::max());
    };
  }
  if (!options.IsValid(&error)) {
    return usage(WithFlagNames(error, {{"threads", "--threads"},
                                       {"false_alarm", "--false-alarm"},
                                       {"min_window_samples", "--min-window-samples"}}));
  }
  TrackResult result;
  const TrackStatus status =
      fastcal::RunTrack(model, spec, data, window, FLAGS_out, options, &result, &error);
  if (status != TrackStatus::kOk) {
    PrintError(kCommand, error);
    return status == TrackStatus::kInvalidInput ? kExitUsage : kExitFailure;
  }
  std::cout << Summary(result, FLAGS_out);
  // An operator's script learns from the status alone that something changed.
  constexpr int kExitNewEvents = 3;
  return FLAGS_exit_new_events && result.NewEvents() > 0 ? kExitNewEvents : 0;
}

}  // namespace fastcal::cli
