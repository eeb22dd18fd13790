// The track's pipeline (track.h): each stage is a function over one run's state
// (track_run.h), called in order by RunTrack.
#include "fastcal/track.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "fastcal/gross_errors.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/sessions.h"
#include "fastcal/time_text.h"
#include "track/track_run.h"

namespace fastcal {
namespace {

using internal::TrackRun;

constexpr double kSecondsPerDay = 86400.0;

bool InGroups(const ParameterSpec& p, const std::vector<std::string>& groups) {
  for (const std::string& g : groups) {
    if (g == ParameterGroupName(p.kind) || g == p.name) return true;
  }
  return false;
}

internal::TrackLayout Layout(const CalibrationSpec& spec) {
  internal::TrackLayout layout;
  layout.parameters = spec.parameters;
  for (size_t s = 0; s < spec.parameters.size(); ++s) {
    ParameterSpec& p = layout.parameters[s];
    if (!p.free && !p.IsConsider()) continue;
    FoldRole role = FoldRole::kConsider;
    if (p.free) role = InGroups(p, spec.separate_groups) ? FoldRole::kWindow : FoldRole::kShared;
    p.free = true;
    const int k = layout.size();
    layout.spec_index.push_back(static_cast<int>(s));
    layout.roles.push_back(role);
    (role == FoldRole::kWindow   ? layout.window_columns
     : role == FoldRole::kShared ? layout.shared_columns
                                 : layout.consider_columns)
        .push_back(k);
  }
  return layout;
}

TrackStatus Validate(TrackRun& run) {
  std::string why;
  if (!run.options.IsValid(&why)) return run.Fail(TrackStatus::kInvalidInput, why);
  if (!run.window.IsValid(&why)) return run.Fail(TrackStatus::kInvalidInput, "window: " + why);
  if (!run.model.IsValid(&why)) return run.Fail(TrackStatus::kInvalidInput, "model: " + why);
  if (!run.spec.IsValid(&why)) return run.Fail(TrackStatus::kInvalidInput, "spec: " + why);
  for (const ParameterSpec& p : run.spec.parameters) {
    if (!ParameterFitsModel(p, run.model, &why)) {
      return run.Fail(TrackStatus::kInvalidInput, "spec: " + why);
    }
  }
  if (run.model.HasAttachments() && run.spec.forward_model != StaticsMethod::kExact) {
    return run.Fail(TrackStatus::kInvalidInput,
                    "spec: forward_model: the model's cables carry attachments; use "
                    "forward_model: exact");
  }
  if (run.spec.separate_groups.empty()) {
    return run.Fail(TrackStatus::kInvalidInput,
                    "spec: a track needs the parameters it follows per window: name their "
                    "groups in sessions: {separate: [...]} (calibration_data/spec_track.yaml "
                    "follows the mass centre)");
  }
  if (run.spec.robust_loss != RobustLoss::kNone) {
    return run.Fail(TrackStatus::kInvalidInput,
                    std::string("spec: robust_loss: ") + RobustLossName(run.spec.robust_loss) +
                        " is calibrate's only; a track screens gross errors instead (use "
                        "robust_loss: none)");
  }
  run.layout = Layout(run.spec);
  if (run.layout.size() > internal::kMaxFreeParameters) {
    return run.Fail(TrackStatus::kInvalidInput, "spec: " + std::to_string(run.layout.size()) +
                                                    " free and consider parameters; at most " +
                                                    std::to_string(internal::kMaxFreeParameters) +
                                                    " are supported");
  }
  if (run.spec.holdout_fraction > 0.0) {
    run.result->notes.push_back(
        "the spec's hold-out is calibrate's only: a track fits every sample");
  }
  if (!run.spec.change_scan_groups.empty()) {
    run.result->notes.push_back(
        "the spec's change_scan is calibrate's only: a track tests changes between windows");
  }
  if (run.model.measured_frame.has_value()) {  // whose pose the data give (measured_frame.h)
    run.result->notes.push_back(
        "the data's poses are those of " +
        DescribeMeasuredFrame(&*run.model.measured_frame, run.model.moving_parts) +
        " (the model's cabin.measured_frame)");
  }
  run.model_yaml = CableRobotToYaml(run.model, "");
  run.spec_yaml = CalibrationSpecToYaml(run.spec);
  if (run.options.read.columns) {
    run.columns_text = run.options.read.columns->text;
    run.result->time_offset_s = run.options.read.columns->time.offset_s;
  }
  run.result->window = run.window;
  run.result->false_alarm = run.options.false_alarm;
  for (int k : run.layout.window_columns) {
    run.result->window_parameters.push_back(run.layout.Column(k).name);
    run.result->window_units.push_back(run.layout.Column(k).unit);
  }
  return TrackStatus::kOk;
}

TrackStatus Expand(TrackRun& run, const std::vector<std::string>& data) {
  return internal::ExpandDataPaths(data, &run.data_paths, run.error);
}

TrackStatus Threshold(TrackRun& run) {
  long long samples = 0;
  for (const internal::TrackWindowState& w : run.windows) samples += w.samples;
  run.gross_threshold_sigmas =
      ChooseGrossErrorThreshold(kNumCables * samples, run.spec.gross_error_threshold_sigmas).sigmas;
  return TrackStatus::kOk;
}

TrackStatus Points(TrackRun& run) {
  internal::InitialPoints(run);
  return TrackStatus::kOk;
}

TrackStatus Solve(TrackRun& run) { return internal::Iterate(run, true); }

}  // namespace

namespace internal {

std::string TrackTimeText(double time_s, int offset_s) {
  return IsUnixTime(time_s) ? IsoUnixTime(time_s, offset_s) : TimeValueText(time_s, TimeDisplay());
}

std::string WindowLabel(const WindowSpec& window, double start_s) {
  if (!IsUnixTime(start_s)) return "t" + FormatDouble("%.0f", start_s);
  // "2024-05-01 06:00:00", on the origin's clock.
  const std::string text = FormatUnixTime(start_s, window.label_offset_s);
  if (std::fmod(window.duration_s, kSecondsPerDay) == 0.0) return text.substr(0, 10);
  std::string label = text.substr(0, 10) + "T" + text.substr(11, 2) + text.substr(14, 2);
  if (text.substr(17, 2) != "00") label += text.substr(17, 2);
  if (window.label_offset_s == 0) return label + "Z";
  // "+0800": no ':' in a label (it names files).
  const int minutes = std::abs(window.label_offset_s) / 60;
  char zone[16];
  std::snprintf(zone, sizeof(zone), "%c%02d%02d", window.label_offset_s < 0 ? '-' : '+',
                minutes / 60, minutes % 60);
  return label + zone;
}

}  // namespace internal

bool WindowSpec::IsValid(std::string* error) const {
  if (kind == Kind::kFile) return true;
  if (std::isfinite(duration_s) && duration_s >= 1.0 && duration_s == std::floor(duration_s) &&
      duration_s <= kMaxWindowS) {
    return true;
  }
  *error = "duration_s must be a whole number of seconds from 1 to " +
           internal::FormatDouble("%.0f", kMaxWindowS) +
           " (a year: a window is a part of a season) (got " +
           internal::FormatDouble("%g", duration_s) + ")";
  return false;
}

namespace {

// "HH:MM" with a zone ("Z", "+08:00", "-0530"; none: UTC) into the boundary's offset from
// the epoch's alignment of windows of duration d, and the zone's offset. False for
// anything else.
bool ParseWindowOrigin(const std::string& text, double d, double* origin_s, int* zone_s) {
  // Two digits of `s` at `at`.
  const auto two = [](const std::string& s, size_t at, int* value) {
    if (at + 2 > s.size() || !std::isdigit(static_cast<unsigned char>(s[at])) ||
        !std::isdigit(static_cast<unsigned char>(s[at + 1]))) {
      return false;
    }
    *value = (s[at] - '0') * 10 + (s[at + 1] - '0');
    return true;
  };
  int hours = 0, minutes = 0;
  if (!two(text, 0, &hours) || text.size() < 5 || text[2] != ':' || !two(text, 3, &minutes) ||
      hours > 23 || minutes > 59) {
    return false;
  }
  std::string zone = text.substr(5);
  *zone_s = 0;
  if (!zone.empty() && zone != "Z") {
    if (zone.size() == 6 && zone[3] == ':') zone.erase(3, 1);  // "+08:00" -> "+0800"
    int zh = 0, zm = 0;
    if (zone.size() != 5 || (zone[0] != '+' && zone[0] != '-') || !two(zone, 1, &zh) ||
        !two(zone, 3, &zm) || zh > 14 || zm > 59) {
      return false;
    }
    *zone_s = (zone[0] == '-' ? -1 : 1) * (zh * 3600 + zm * 60);
  }
  const double local_s = hours * 3600.0 + minutes * 60.0 - *zone_s;
  *origin_s = local_s - d * std::floor(local_s / d);
  return true;
}

}  // namespace

bool ParseWindowSpec(const std::string& text_in, WindowSpec* window, std::string* error) {
  WindowSpec w;
  const size_t at = text_in.find('@');
  const std::string text = text_in.substr(0, at);
  if (at != std::string::npos && text == "file") {
    *error = "window '" + text_in + "': a window per file has no origin ('@')";
    return false;
  }
  if (text == "file") {
    w.kind = WindowSpec::Kind::kFile;
    *window = w;
    return true;
  }
  const auto bad = [&] {
    *error = "window '" + text +
             "': give a duration as a whole number and a unit (1d, 12h, 30m, 3600s) or 'file'";
    return false;
  };
  if (text.size() < 2) return bad();
  const char unit = text.back();
  const double scale = unit == 'd'   ? 86400.0
                       : unit == 'h' ? 3600.0
                       : unit == 'm' ? 60.0
                       : unit == 's' ? 1.0
                                     : 0.0;
  double count = 0.0;
  std::string why;
  if (scale == 0.0 ||
      !internal::ParseFiniteDecimal(text.substr(0, text.size() - 1), &count, &why) ||
      !(count > 0.0) || count != std::floor(count)) {
    return bad();
  }
  w.duration_s = count * scale;
  if (std::string why; !w.IsValid(&why)) {
    *error = "window '" + text_in + "': " + why;
    return false;
  }
  if (at != std::string::npos) {
    if (!ParseWindowOrigin(text_in.substr(at + 1), w.duration_s, &w.origin_s, &w.label_offset_s)) {
      *error = "window '" + text_in +
               "': the origin after '@' must be HH:MM with an optional zone (12:00+08:00, "
               "00:00Z)";
      return false;
    }
    w.has_origin = true;
  }
  *window = w;
  return true;
}

std::string WindowSpecText(const WindowSpec& window) {
  if (window.kind == WindowSpec::Kind::kFile) return "file";
  const double d = window.duration_s;
  std::string text = std::fmod(d, 86400.0) == 0.0  ? internal::FormatDouble("%.0fd", d / 86400.0)
                     : std::fmod(d, 3600.0) == 0.0 ? internal::FormatDouble("%.0fh", d / 3600.0)
                     : std::fmod(d, 60.0) == 0.0   ? internal::FormatDouble("%.0fm", d / 60.0)
                                                   : internal::FormatDouble("%.0fs", d);
  if (!window.has_origin) return text;
  // The origin on its own clock: (origin + zone) within the day.
  const double local = std::fmod(window.origin_s + window.label_offset_s + 86400.0 * 400, 86400.0);
  const int minutes_of_day = static_cast<int>(std::lround(local / 60.0)) % 1440;
  const int zone_minutes = std::abs(window.label_offset_s) / 60;
  char buf[32];
  if (window.label_offset_s == 0) {
    std::snprintf(buf, sizeof(buf), "@%02d:%02dZ", minutes_of_day / 60, minutes_of_day % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "@%02d:%02d%c%02d:%02d", minutes_of_day / 60,
                  minutes_of_day % 60, window.label_offset_s < 0 ? '-' : '+', zone_minutes / 60,
                  zone_minutes % 60);
  }
  return text + buf;
}

bool TrackOptions::IsValid(std::string* error) const {
  std::string why;
  if (threads < 1 || threads > kMaxCalibrationThreads)
    why = "threads must be 1 to " + std::to_string(kMaxCalibrationThreads) + ", got " +
          std::to_string(threads);
  else if (max_iterations < 1)
    why = "max_iterations must be >= 1";
  else if (first_fold_samples != 0 && first_fold_samples < min_window_samples)
    why = "first_fold_samples must be 0 (every sample) or at least min_window_samples (" +
          std::to_string(min_window_samples) + "), got " + std::to_string(first_fold_samples);
  else if (!(step_tolerance_sigmas > 0.0))
    why = "step_tolerance_sigmas must be > 0";
  else if (!(false_alarm > 0.0 && false_alarm < 0.5))
    why = "false_alarm must be in (0, 0.5)";
  else if (max_sensor_steps < 0)
    why = "max_sensor_steps must be >= 0";
  else if (min_window_samples < 1)
    why = "min_window_samples must be >= 1";
  else if (blocks < 2)
    why = "blocks must be >= 2";
  else if (slow_error_samples < 100)
    why = "slow_error_samples must be >= 100";
  if (why.empty()) return true;
  *error = "track options: " + why;
  return false;
}

bool IsTrackOutput(const std::string& name) {
  static const char* const kNames[] = {"track.csv",
                                       "events.json",
                                       "track.html",
                                       "track_state.json",
                                       "folds",
                                       "windows",
                                       internal::kCurrentModelFile};
  for (const char* n : kNames) {
    if (name == n) return true;
  }
  return name.rfind("model_calibrated@", 0) == 0 && name.size() > 22 &&
         name.compare(name.size() - 5, 5, ".yaml") == 0;
}

TrackStatus RunTrack(const CableRobot& model, const CalibrationSpec& spec,
                     const std::vector<std::string>& data, const WindowSpec& window,
                     const std::string& out_dir, const TrackOptions& options, TrackResult* result,
                     std::string* error) {
  *result = TrackResult();
  TrackRun run(model, spec, window, out_dir, options, result, error);
  using Stage = TrackStatus (*)(TrackRun&);
  struct NamedStage {
    const char* name;
    Stage stage;
  };
  const NamedStage stages[] = {{"validate", Validate},
                               {"prepare", internal::PrepareDirectory},
                               {"read", internal::ReadNewFiles},
                               {"threshold", Threshold},
                               {"points", Points},
                               {"solve", Solve},
                               {"sensor steps", internal::ScanSensorSteps},
                               {"consider", internal::FoldConsider},
                               {"uncertainty", internal::Uncertainties},
                               {"events", internal::FindParameterEvents},
                               {"models", internal::BuildModels},
                               {"outputs", internal::WriteOutputs},
                               {"state", internal::SaveState},
                               {"finish", internal::FinishDirectory}};
  for (const NamedStage& s : stages) {
    TrackStatus status = TrackStatus::kOk;
    // Up to the outputs: once they are written, the state and the directory's commit
    // follow, so that a stop there would leave more to roll back than it saves.
    const bool may_stop = std::string(s.name) != "state" && std::string(s.name) != "finish";
    if (may_stop && run.StopRequested()) {
      internal::RollBack(run);
      return run.Cancel();
    }
    if (std::string(s.name) == "prepare") {
      status = Expand(run, data);
      if (status == TrackStatus::kOk) status = s.stage(run);
    } else {
      status = s.stage(run);
    }
    if (status != TrackStatus::kOk) {
      internal::RollBack(run);
      return status;
    }
  }
  return TrackStatus::kOk;
}

}  // namespace fastcal
