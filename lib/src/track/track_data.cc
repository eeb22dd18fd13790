// A track's data and directory (track.h, track_run.h): the files read into the window
// store, the state saved for an update (track_state.json), and the directory made whole
// at the end or put back as it was on failure.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <system_error>
#include <thread>

#include "fastcal/calibration.h"
#include "fastcal/evaluation.h"
#include "fastcal/file_digest.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/json.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/track_state.h"
#include "fastcal/internal/window_store.h"
#include "fastcal/sessions.h"
#include "fastcal/tension_scale.h"
#include "fastcal/time_text.h"
#include "track/track_run.h"
#include "util/yaml_document.h"

namespace fastcal::internal {

TrackRun::Lock::~Lock() {
  if (fd < 0) return;
  // Unlinked while held: a run that opened the file meanwhile finds, once it holds the
  // lock, that the name is no longer this file, and opens it anew (LockDirectory).
  ::unlink(path.c_str());
  ::close(fd);  // releases the flock
}

namespace {

namespace fs = std::filesystem;

constexpr char kStateFile[] = "track_state.json";
constexpr char kStateFormat[] = "fastcal-track-state-1";
// Samples read at once (as Samples, ~400 bytes each: 6.5 MB).
constexpr size_t kReadChunkSamples = 16384;
// Samples held in the store's buffers before they are appended to their files (160 bytes
// each: 10 MB).
constexpr size_t kMaxBufferedSamples = 1 << 16;
// Rows skipped (skip_invalid_rows) named in the notes at most.
constexpr size_t kMaxSkippedNamed = 5;

std::string FoldName(const std::string& label, int generation) {
  return "folds/" + label + ".g" + std::to_string(generation) + ".fold";
}

// ---------------------------------------------------------------------------------------
// The saved state.

std::string StateJson(const TrackRun& run) {
  JsonWriter j;
  j.BeginObject();
  j.Key("format").String(kStateFormat);
  j.Key("window").String(WindowSpecText(run.window));
  j.Key("generation").Int(run.generation);
  j.Key("model_yaml").String(run.model_yaml);
  j.Key("spec_yaml").String(run.spec_yaml);
  j.Key("columns").String(run.columns_text);
  j.Key("slow_error").BeginObject();
  j.Key("sigma_n").ExactNumber(run.slow.sigma_n);
  j.Key("sigma_percent").ExactNumber(run.slow.sigma_percent);
  j.Key("time_constant_s").ExactNumber(run.slow.time_constant_s);
  j.EndObject();
  j.Key("files").BeginArray();
  for (const TrackFile& f : run.files) {
    j.BeginObject();
    j.Key("path").String(f.path);
    j.Key("bytes").Int(f.bytes);
    j.Key("sha256").String(f.sha256);
    j.Key("samples").Int(f.samples);
    if (!f.content.empty()) j.Key("content").String(f.content);
    if (std::isfinite(f.first_s)) {
      j.Key("first_s").ExactNumber(f.first_s);
      j.Key("last_s").ExactNumber(f.last_s);
    }
    j.EndObject();
  }
  j.EndArray();
  // The events reported now, so that the next run can tell its new ones (is_new).
  j.Key("events").BeginArray();
  for (const TrackEvent& e : run.result->events) {
    j.BeginObject();
    j.Key("kind").String(e.kind);
    j.Key("cables").BeginArray();
    for (int c : e.cables) j.Int(c);
    j.EndArray();
    j.Key("time_low_s").ExactNumber(e.time_low_s);
    j.Key("time_high_s").ExactNumber(e.time_high_s);
    j.EndObject();
  }
  j.EndArray();
  j.Key("windows").BeginArray();
  for (const TrackWindowState& w : run.windows) {
    j.BeginObject();
    j.Key("label").String(w.label);
    j.Key("key").Int(w.key);
    j.Key("start_s").ExactNumber(w.start_s);
    j.Key("end_s").ExactNumber(w.end_s);
    j.Key("first_s").ExactNumber(w.first_s);
    j.Key("last_s").ExactNumber(w.last_s);
    j.Key("samples").Int(w.samples);
    j.Key("used").Bool(w.used);
    j.Key("fold").String(w.fold_file);
    j.Key("fold_sha256").String(w.fold_sha256);
    j.Key("store_bytes").Int(w.store_bytes);
    j.Key("store_sha256").String(w.store_sha256);
    j.Key("files").BeginArray();
    for (int f : w.files) j.Int(f);
    j.EndArray();
    j.EndObject();
  }
  j.EndArray();
  j.Key("shared").BeginArray();
  for (const SharedEntry& e : run.shared) {
    j.BeginObject();
    j.Key("name").String(run.layout.Column(run.layout.shared_columns[e.column]).name);
    j.Key("from_s").ExactNumber(std::isfinite(e.from_s) ? e.from_s : -1e308);
    j.Key("value_si").ExactNumber(e.value_si);
    if (e.inside) {
      j.Key("inside").Bool(true);
      j.Key("step_time_s").ExactNumber(e.step_time_s);
      j.Key("step_previous_s").ExactNumber(e.step_previous_s);
    }
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
  return j.str();
}

double Real(const YAML::Node& node) {
  double v = 0.0;
  if (!node || !node.IsScalar() || !ParseDouble(node.Scalar(), &v)) {
    throw YAML::Exception(node ? node.Mark() : YAML::Mark::null_mark(), "not a number");
  }
  return v;
}

long long Integer(const YAML::Node& node) { return static_cast<long long>(Real(node)); }

// A count or a size: a whole number from 0 to 2^53 (a review's "samples": -5 dropped a day
// silently, issue 37).
long long Count(const YAML::Node& node) {
  const double v = Real(node);
  if (!(v >= 0.0 && v <= 9007199254740992.0) || v != std::floor(v)) {
    throw YAML::Exception(node.Mark(), "not a count (a whole number >= 0)");
  }
  return static_cast<long long>(v);
}

std::string Text(const YAML::Node& node) {
  if (!node || !node.IsScalar()) {
    throw YAML::Exception(node ? node.Mark() : YAML::Mark::null_mark(), "not a string");
  }
  return node.Scalar();
}

// The saved state into `run` (files, windows, shared values, slow error). Throws
// YAML::Exception on a malformed file.
struct SavedState {
  std::string window, model_yaml, spec_yaml, columns;
  int generation = 0;
  SlowErrorProcess slow;
  std::vector<TrackFile> files;
  std::vector<TrackWindowState> windows;
  std::vector<std::pair<std::string, SharedEntry>> shared;  // by name
  std::vector<KnownEvent> events;  // reported by the run that saved it (none before 0.2)
};
// A window label as this program makes them (a date, "t123", a file's stem): names a
// store and a fold inside DIR, so one that could reach outside it is refused.
bool IsSafeLabel(const std::string& label) {
  if (label.empty() || label.size() > 200 || label[0] == '.') return false;
  return std::all_of(label.begin(), label.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ||
           c == ':' || c == '+' || c == ' ';
  });
}

// The entries of a JSON text outside its strings: each ',', '[' and '{'.
long long JsonEntries(const std::string& text) {
  long long entries = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"') {
      for (++i; i < text.size() && text[i] != '"'; ++i) {
        if (text[i] == '\\') ++i;
      }
    } else if (c == ',' || c == '[' || c == '{') {
      ++entries;
    }
  }
  return entries;
}

// More entries than any track's state holds (a year of hourly files and daily windows is
// ~10^5): each costs yaml-cpp ~0.5 kB, and 16 MiB of "[]," took 2.7 GB (issue 37).
constexpr long long kMaxStateEntries = 250000;

// A file of the state.
TrackFile ParseFile(const YAML::Node& f) {
  TrackFile file;
  file.path = Text(f["path"]);
  file.bytes = Count(f["bytes"]);
  file.sha256 = Text(f["sha256"]);
  file.samples = Count(f["samples"]);
  if (f["content"]) file.content = Text(f["content"]);
  if (f["first_s"]) {
    file.first_s = Real(f["first_s"]);
    file.last_s = Real(f["last_s"]);
  }
  return file;
}

// A window of the state: its label one the track writes (no path outside DIR), its times
// as the track writes them (issue 37: a start_s of 1e400 was written to track.csv as inf):
// finite, within data's plausible times, in order.
TrackWindowState ParseWindow(const YAML::Node& n) {
  TrackWindowState w;
  w.label = Text(n["label"]);
  w.key = Integer(n["key"]);
  w.start_s = Real(n["start_s"]);
  w.end_s = Real(n["end_s"]);
  w.first_s = Real(n["first_s"]);
  w.last_s = Real(n["last_s"]);
  w.samples = Count(n["samples"]);
  w.used = Text(n["used"]) == "true";
  w.fold_file = Text(n["fold"]);
  if (!IsSafeLabel(w.label) ||
      (!w.fold_file.empty() && w.fold_file.rfind("folds/" + w.label + ".g", 0) != 0)) {
    throw YAML::Exception(n["label"].Mark(), "window label or fold '" + w.label +
                                                 "' is not one this program "
                                                 "writes (a path outside the track?)");
  }
  if (n["fold_sha256"]) w.fold_sha256 = Text(n["fold_sha256"]);
  if (n["store_bytes"]) w.store_bytes = Count(n["store_bytes"]);
  if (n["store_sha256"]) w.store_sha256 = Text(n["store_sha256"]);
  for (const YAML::Node& f : n["files"]) w.files.push_back(static_cast<int>(Integer(f)));
  const auto plausible = [](double t) {
    return std::isfinite(t) && std::abs(t) <= kUnixTimeUntilS;  // year 10000 (time_text.h)
  };
  if (!plausible(w.start_s) || !plausible(w.end_s) || w.start_s > w.end_s ||
      (w.samples > 0 && (!plausible(w.first_s) || !plausible(w.last_s) || w.first_s > w.last_s))) {
    throw YAML::Exception(n["start_s"].Mark(), "window " + w.label + "'s times are not a window's");
  }
  w.dirty = false;
  return w;
}

// A shared value of the state, by its column's name.
std::pair<std::string, SharedEntry> ParseShared(const YAML::Node& e) {
  SharedEntry entry;
  entry.from_s = Real(e["from_s"]);
  if (entry.from_s <= -1e308) entry.from_s = -std::numeric_limits<double>::infinity();
  entry.value_si = Real(e["value_si"]);
  if (e["inside"] && Text(e["inside"]) == "true") {
    entry.inside = true;
    entry.step_time_s = Real(e["step_time_s"]);
    entry.step_previous_s = Real(e["step_previous_s"]);
  }
  return {Text(e["name"]), entry};
}

SavedState ParseState(const std::string& text) {
  if (const long long entries = JsonEntries(text); entries > kMaxStateEntries) {
    YAML::Mark start;
    start.line = 0;
    throw YAML::Exception(start, std::to_string(entries) + " entries, more than any track's " +
                                     "state holds (" + std::to_string(kMaxStateEntries) +
                                     "): a damaged state; --force rebuilds the track from the "
                                     "data");
  }
  // The nesting guard of every YAML reader (16 MiB of '[' took 3.9 GB through YAML::Load).
  const YAML::Node root = LoadYamlDocuments(text).first;
  if (Text(root["format"]) != kStateFormat) {
    throw YAML::Exception(root["format"].Mark(), "not a " + std::string(kStateFormat));
  }
  SavedState s;
  s.window = Text(root["window"]);
  s.generation = static_cast<int>(Integer(root["generation"]));
  s.model_yaml = Text(root["model_yaml"]);
  s.spec_yaml = Text(root["spec_yaml"]);
  s.columns = Text(root["columns"]);
  s.slow.sigma_n = Real(root["slow_error"]["sigma_n"]);
  s.slow.sigma_percent = Real(root["slow_error"]["sigma_percent"]);
  s.slow.time_constant_s = Real(root["slow_error"]["time_constant_s"]);
  for (const YAML::Node& f : root["files"]) s.files.push_back(ParseFile(f));
  for (const YAML::Node& n : root["windows"]) s.windows.push_back(ParseWindow(n));
  for (const YAML::Node& e : root["shared"]) s.shared.push_back(ParseShared(e));
  for (const YAML::Node& e : root["events"]) {
    KnownEvent k;
    k.kind = Text(e["kind"]);
    for (const YAML::Node& c : e["cables"]) k.cables.push_back(static_cast<int>(Integer(c)));
    k.time_low_s = Real(e["time_low_s"]);
    k.time_high_s = Real(e["time_high_s"]);
    s.events.push_back(k);
  }
  return s;
}

// A file of the track given now at another path (from another directory, or moved) is
// the same file when its content is: its bytes and SHA-256. Its path becomes the one
// given, so that it is not read again.
void RelocateFiles(const TrackRun& run, SavedState* s) {
  for (TrackFile& f : s->files) {
    if (std::find(run.data_paths.begin(), run.data_paths.end(), f.path) != run.data_paths.end()) {
      continue;
    }
    for (const std::string& given : run.data_paths) {
      const bool taken = std::any_of(s->files.begin(), s->files.end(),
                                     [&](const TrackFile& g) { return g.path == given; });
      std::error_code ec;
      const auto bytes = fs::file_size(given, ec);
      std::string digest, why;
      if (taken || ec || static_cast<long long>(bytes) != f.bytes ||
          !FileSha256(given, &digest, &why) || digest != f.sha256) {
        continue;
      }
      f.path = given;
      break;
    }
  }
}

// The saved state's check against this run's inputs: "" when it may be updated.
std::string Mismatch(const TrackRun& run, const SavedState& s) {
  if (s.model_yaml != run.model_yaml) return "another model";
  if (s.spec_yaml != run.spec_yaml) return "another spec";
  if (s.window != WindowSpecText(run.window)) return "windows of " + s.window;
  if (s.columns != run.columns_text) {
    return s.columns.empty() ? "files read without a column map"
                             : "files read through another column map";
  }
  for (const TrackFile& f : s.files) {
    if (std::find(run.data_paths.begin(), run.data_paths.end(), f.path) == run.data_paths.end()) {
      return "data of " + f.path + ", not given now";
    }
    std::error_code ec;
    const auto bytes = fs::file_size(f.path, ec);
    std::string digest, why;
    if (ec || static_cast<long long>(bytes) != f.bytes || !FileSha256(f.path, &digest, &why) ||
        digest != f.sha256) {
      return "data of " + f.path + " as it was (the file changed since)";
    }
  }
  return "";
}

// The window stores as the state records them (issue 37): a store longer than its
// committed length holds an interrupted run's samples, cut off (they are read again with
// their file); a shorter one, or a file index out of range, is a damaged track; stores
// of windows the state does not know are an interrupted run's, removed.
bool CheckStores(TrackRun& run) {
  std::error_code ec;
  for (const TrackWindowState& w : run.windows) {
    for (int f : w.files) {
      if (f < 0 || f >= static_cast<int>(run.files.size())) {
        *run.error = run.Path(kStateFile) + ": window " + w.label + " names file " +
                     std::to_string(f) + " of " + std::to_string(run.files.size()) +
                     ": a damaged state; --force rebuilds the track from the data";
        return false;
      }
    }
    const std::string store = run.Path("windows/" + w.StoreName());
    if (w.store_bytes < 0) continue;  // a state of an older version: not recorded
    const auto size = fs::exists(store, ec) ? static_cast<long long>(fs::file_size(store, ec)) : 0;
    if (ec || size < w.store_bytes) {
      *run.error = store + ": " + std::to_string(size) + " bytes where the state records " +
                   std::to_string(w.store_bytes) +
                   ": the track's samples are damaged; --force rebuilds it from the data";
      return false;
    }
    if (size > w.store_bytes) {
      fs::resize_file(store, static_cast<std::uintmax_t>(w.store_bytes), ec);
      if (ec) {
        *run.error = store + ": cannot cut back an interrupted run's samples: " + ec.message();
        return false;
      }
      run.result->notes.push_back("repaired " + w.StoreName() + ": " +
                                  std::to_string(size - w.store_bytes) +
                                  " bytes an interrupted run appended were removed (their "
                                  "files are read again)");
    }
  }
  for (const fs::directory_entry& e : fs::directory_iterator(run.Path("windows"), ec)) {
    const std::string name = e.path().filename().string();
    if (std::none_of(run.windows.begin(), run.windows.end(),
                     [&](const TrackWindowState& w) { return w.StoreName() == name; })) {
      fs::remove(e.path(), ec);
      run.result->notes.push_back("repaired: " + name + " of an interrupted run removed");
    }
  }
  return true;
}

// Each window's fold, checked against the state's SHA-256 (a fold copied from another
// window or run, or edited, is refused by name) and read. With --refold a bad fold is
// dropped instead: the window is folded again from its store.
bool LoadFolds(TrackRun& run) {
  for (TrackWindowState& w : run.windows) {
    if (w.fold_file.empty()) continue;
    const std::string path = run.Path(w.fold_file);
    std::string digest, why;
    bool ok = true;
    if (!w.fold_sha256.empty() && (!FileSha256(path, &digest, &why) || digest != w.fold_sha256)) {
      why = path + ": " +
            (why.empty() ? "not the fold this track wrote (its SHA-256 differs "
                           "from track_state.json's)"
                         : why);
      ok = false;
    }
    if (ok && !LoadFold(run, &w, &why)) ok = false;
    // Whitened by the process the state records (issue 37: the state's slow error edited
    // by hand shifted every estimate, exit 0).
    const SlowErrorProcess& p = w.fold.slow_error;
    if (ok && (p.sigma_n != run.slow.sigma_n || p.sigma_percent != run.slow.sigma_percent ||
               p.time_constant_s != run.slow.time_constant_s)) {
      why = path + ": whitened by another slow error than track_state.json records";
      ok = false;
    }
    // A fold of another window passes its digest only with a forged state: its own label
    // and count still tell.
    if (ok && (w.fold.label != w.label || w.fold.samples != w.samples)) {
      why = path + ": the fold of window '" + w.fold.label + "' (" +
            std::to_string(w.fold.samples) + " samples), not of " + w.label + " (" +
            std::to_string(w.samples) + ")";
      ok = false;
    }
    if (!ok) {
      if (!run.options.refold_all) {
        *run.error = why +
                     "; --refold folds the window again from its samples (--force rebuilds "
                     "the track from the data)";
        return false;
      }
      run.result->notes.push_back("refolded " + w.label + ": " + why);
      w.fold_file.clear();
      w.fold_sha256.clear();
      w.has_fold = false;
      w.dirty = true;
      continue;
    }
    w.has_fold = true;
    w.theta = w.fold.theta_si;
  }
  return true;
}

bool DamagedState(TrackRun& run, const std::string& why) {
  *run.error = run.Path(kStateFile) + ": " + why +
               ": a damaged state; --force rebuilds the track from the data";
  return false;
}

// "" when the shared values are as the track writes them: each column's first from the
// start of time (-inf), the others' starts in order, none twice, every value finite (issue
// 37: a shared entry duplicated by hand crashed the next run, SIGSEGV or abort).
std::string SharedEntriesProblem(const TrackRun& run) {
  if (run.shared.empty()) return "";  // none saved: every column from the model's values
  for (size_t j = 0; j < run.layout.shared_columns.size(); ++j) {
    std::vector<double> starts;
    for (const SharedEntry& e : run.shared) {
      if (e.column != static_cast<int>(j)) continue;
      if (!std::isfinite(e.value_si)) return "a shared value that is not finite";
      if (e.inside && !(std::isfinite(e.step_time_s) && std::isfinite(e.step_previous_s))) {
        return "a shared value's step time that is not finite";
      }
      starts.push_back(e.from_s);
    }
    const std::string name = run.layout.Column(run.layout.shared_columns[j]).name;
    std::sort(starts.begin(), starts.end());
    if (starts.empty() || starts.front() != -std::numeric_limits<double>::infinity()) {
      return "no shared value of " + name + " from the start";
    }
    if (std::adjacent_find(starts.begin(), starts.end()) != starts.end()) {
      return "two shared values of " + name + " from one time";
    }
  }
  return "";
}

// "" when the windows are as the track writes them for its window spec (issue 37: a key,
// start or end edited by hand merged a day's samples into another window or showed one
// day's data under another date, exit 0): each a duration window's key, its bounds and
// its label from the key, or a file window's key its file; no key twice; the windows'
// samples those of the files.
std::string WindowsProblem(const TrackRun& run, const SavedState& s) {
  std::set<long long> keys;
  long long in_windows = 0, in_files = 0;
  for (const TrackWindowState& w : s.windows) {
    if (!keys.insert(w.key).second) return "two windows of key " + std::to_string(w.key);
    in_windows += w.samples;
    if (run.window.kind == WindowSpec::Kind::kFile) {
      if (w.key < 0 || w.key >= static_cast<long long>(s.files.size()) ||
          w.files != std::vector<int>{static_cast<int>(w.key)}) {
        return "window " + w.label + " is not its file's";
      }
      continue;
    }
    const double d = run.window.duration_s;
    const double start_s = static_cast<double>(w.key) * d + run.window.origin_s;
    if (w.start_s != start_s || w.end_s != start_s + d ||
        w.label != WindowLabel(run.window, start_s) ||
        (w.samples > 0 && (w.first_s < w.start_s || w.last_s >= w.end_s))) {
      return "window " + w.label + " is not the window of key " + std::to_string(w.key);
    }
  }
  // Each file with samples has them in a window (issue 37: a state's windows emptied by
  // hand made an update drop every earlier day, exit 0).
  for (size_t f = 0; f < s.files.size(); ++f) {
    in_files += s.files[f].samples;
    if (s.files[f].samples == 0) continue;
    const bool held = std::any_of(s.windows.begin(), s.windows.end(), [&](const auto& w) {
      return std::find(w.files.begin(), w.files.end(), static_cast<int>(f)) != w.files.end();
    });
    if (!held) {
      return "file " + s.files[f].path + "'s " + std::to_string(s.files[f].samples) +
             " samples are in no window";
    }
  }
  if (in_windows != in_files) {
    return "its windows hold " + std::to_string(in_windows) + " samples, its files " +
           std::to_string(in_files);
  }
  return "";
}

bool LoadSavedState(TrackRun& run, bool* use) {
  // --force builds the track afresh from the data whatever DIR holds: another model's
  // track, or a damaged one (a corrupt fold or state, a store from elsewhere), which is
  // then never read (issue 37: a corrupt fold could not be cleared by --force).
  if (run.options.force) {
    *use = false;
    return true;
  }
  std::string text;
  if (!ReadRegularFile(run.Path(kStateFile), 16LL << 20, "track state", &text, run.error)) {
    return false;
  }
  SavedState s;
  try {
    s = ParseState(text);
  } catch (const YAML::Exception& e) {
    *run.error = run.Path(kStateFile) + ": line " + std::to_string(e.mark.line + 1) + ": " + e.msg;
    return false;
  }
  RelocateFiles(run, &s);
  const std::string mismatch = Mismatch(run, s);
  if (!mismatch.empty()) {
    *run.error = run.out + " holds a track of " + mismatch +
                 ": give a new --out, or --force to build it afresh";
    return false;
  }
  if (const std::string why = WindowsProblem(run, s); !why.empty()) return DamagedState(run, why);
  run.generation = s.generation + 1;
  run.slow = s.slow;
  run.previous_events = std::move(s.events);
  run.files = std::move(s.files);
  run.windows = std::move(s.windows);
  if (!CheckStores(run) || !LoadFolds(run)) return false;
  for (const auto& [name, entry] : s.shared) {
    bool known = false;
    for (size_t j = 0; j < run.layout.shared_columns.size(); ++j) {
      if (run.layout.Column(run.layout.shared_columns[j]).name != name) continue;
      SharedEntry e = entry;
      e.column = static_cast<int>(j);
      run.shared.push_back(e);
      known = true;
    }
    if (!known) return DamagedState(run, "a shared value of '" + name + "', not a column");
  }
  if (const std::string why = SharedEntriesProblem(run); !why.empty()) {
    return DamagedState(run, why);
  }
  *use = true;
  return true;
}

bool IsEmptyDirectory(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec) && fs::directory_iterator(path, ec) == fs::directory_iterator();
}

// ---------------------------------------------------------------------------------------
// Reading files into the store.

struct Router {
  TrackRun& run;
  std::map<long long, int> window_of_key;  // into run.windows
  std::map<int, std::vector<StoredSample>> buffers;
  size_t buffered = 0;
  int relative_file = -1;  // the file (index) whose times are relative, if one is

  explicit Router(TrackRun& r) : run(r) {
    for (size_t w = 0; w < run.windows.size(); ++w)
      window_of_key[run.windows[w].key] = static_cast<int>(w);
    // A file of relative times already in the track (an update adds to it): a new one
    // would share its windows (issue 37: an update joined two in window t0).
    for (size_t f = 0; f < run.files.size(); ++f) {
      if (!std::isnan(run.files[f].first_s) && !IsUnixTime(run.files[f].first_s)) {
        relative_file = static_cast<int>(f);
      }
    }
    for (const TrackWindowState& w : run.windows) {
      if (!IsUnixTime(w.start_s) && !w.files.empty() && relative_file < 0) {
        relative_file = w.files.front();
      }
    }
  }

  int WindowFor(long long key, double start_s, double end_s, const std::string& label) {
    const auto it = window_of_key.find(key);
    if (it != window_of_key.end()) return it->second;
    TrackWindowState w;
    w.key = key;
    w.label = label;
    w.start_s = start_s;
    w.end_s = end_s;
    w.first_s = std::numeric_limits<double>::infinity();
    w.last_s = -std::numeric_limits<double>::infinity();
    run.windows.push_back(std::move(w));
    return window_of_key[key] = static_cast<int>(run.windows.size() - 1);
  }

  bool Flush() {
    for (auto& [w, samples] : buffers) {
      if (samples.empty()) continue;
      const std::string path = run.Path("windows/" + run.windows[w].StoreName());
      std::error_code ec;
      const auto size = fs::exists(path, ec) ? static_cast<long long>(fs::file_size(path, ec)) : -1;
      if (run.update && std::none_of(run.appended.begin(), run.appended.end(),
                                     [&](const auto& a) { return a.first == path; })) {
        run.appended.push_back({path, size});
      }
      if (!AppendStoredSamples(path, samples, run.model.moving_parts.num_joints(), run.error)) {
        return false;
      }
    }
    // Freed, not cleared: a cleared buffer keeps its capacity, and every window's buffer
    // holding a window's worth was 1.5 GB at 10^7 samples in 100 windows.
    buffers.clear();
    buffered = 0;
    return true;
  }
};

// One sample into its window's buffer.
bool Route(Router& router, const Sample& s, int file_index, const std::string& stem) {
  TrackRun& run = router.run;
  int w = 0;
  if (run.window.kind == WindowSpec::Kind::kFile) {
    w = router.WindowFor(file_index, s.time_s, s.time_s, stem);
  } else {
    const double d = run.window.duration_s;
    const double o = run.window.origin_s;
    const double k = std::floor((s.time_s - o) / d);
    // The label only for a new window (formatting it was 5% of reading a season).
    const auto known = router.window_of_key.find(static_cast<long long>(k));
    w = known != router.window_of_key.end()
            ? known->second
            : router.WindowFor(static_cast<long long>(k), k * d + o, (k + 1.0) * d + o,
                               WindowLabel(run.window, k * d + o));
  }
  TrackWindowState& win = run.windows[w];
  win.first_s = std::min(win.first_s, s.time_s);
  win.last_s = std::max(win.last_s, s.time_s);
  if (run.window.kind == WindowSpec::Kind::kFile) {
    win.start_s = win.first_s;
    win.end_s = win.last_s;
  }
  ++win.samples;
  win.dirty = true;
  if (std::find(win.files.begin(), win.files.end(), file_index) == win.files.end()) {
    win.files.push_back(file_index);
  }
  router.buffers[w].push_back(ToStored(s, file_index, run.spec.use_planned_attitude));
  return ++router.buffered < kMaxBufferedSamples || router.Flush();
}

// The file's chunks, read and parsed on a thread of their own one chunk ahead of the
// caller, who routes the chunk before meanwhile: reading a season was 70% on one thread
// (parsing is threaded, but each chunk's routing, conversion and the stores' writes
// waited for it, and it for them). Where the system refuses the thread, read in turn.
class ChunksAhead {
 public:
  explicit ChunksAhead(DatasetChunkReader* reader) : reader_(reader) {
    try {
      thread_ = std::thread([this] { Produce(); });
    } catch (const std::system_error&) {  // refused: read on the caller's thread (Next)
    } catch (const std::bad_alloc&) {
    }
  }
  ChunksAhead(const ChunksAhead&) = delete;
  ChunksAhead& operator=(const ChunksAhead&) = delete;
  ~ChunksAhead() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }

  // The next chunk, as DatasetChunkReader::Next gives it (its exceptions rethrown here).
  bool Next(Dataset* chunk, bool* done, std::string* error) {
    if (!thread_.joinable()) return reader_->Next(kReadChunkSamples, chunk, done, error);
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return ready_; });
    Chunk c = std::move(next_);
    ready_ = false;
    // The caller's chunk before, back to the reader to be filled again: a new one (6 MB
    // of samples) was faulted in for every chunk.
    spare_ = std::move(*chunk);
    lock.unlock();
    changed_.notify_all();
    if (c.thrown) std::rethrow_exception(c.thrown);
    *chunk = std::move(c.data);
    *done = c.done;
    if (!c.ok) *error = c.error;
    return c.ok;
  }

 private:
  struct Chunk {
    Dataset data;
    bool ok = false, done = false;
    std::string error;
    std::exception_ptr thrown;
  };

  void Produce() {
    for (;;) {
      Chunk c;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        c.data = std::move(spare_);
      }
      try {
        c.ok = reader_->Next(kReadChunkSamples, &c.data, &c.done, &c.error);
      } catch (...) {
        c.thrown = std::current_exception();
      }
      const bool last = !c.ok || c.done;
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return !ready_ || stop_; });
      if (stop_) return;
      next_ = std::move(c);
      ready_ = true;
      lock.unlock();
      changed_.notify_all();
      if (last) return;
    }
  }

  DatasetChunkReader* reader_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable changed_;
  Chunk next_;          // read, not yet taken
  Dataset spare_;       // a chunk the caller is done with, to be filled again
  bool ready_ = false;  // next_ holds a chunk
  bool stop_ = false;   // the caller is gone
};

// A file's SHA-256 computed on a thread of its own (on the caller's, in Get, where the
// system refuses the thread).
class DigestAhead {
 public:
  explicit DigestAhead(std::string path) : path_(std::move(path)) {
    try {
      thread_ = std::thread([this] {
        try {
          ok_ = FileSha256(path_, &sha256_, &error_);
        } catch (...) {  // out of memory: the caller's (Get), not the process's end
          thrown_ = std::current_exception();
        }
      });
    } catch (const std::system_error&) {  // refused: computed in Get
    } catch (const std::bad_alloc&) {
    }
  }
  DigestAhead(const DigestAhead&) = delete;
  DigestAhead& operator=(const DigestAhead&) = delete;
  ~DigestAhead() {
    if (thread_.joinable()) thread_.join();
  }

  bool Get(std::string* sha256, std::string* error) {
    if (thread_.joinable()) {
      thread_.join();
      if (thrown_) std::rethrow_exception(thrown_);
    } else if (!ok_) {
      ok_ = FileSha256(path_, &sha256_, &error_);
    }
    if (!ok_) *error = error_;
    *sha256 = sha256_;
    return ok_;
  }

 private:
  std::string path_, sha256_, error_;
  bool ok_ = false;
  std::exception_ptr thrown_;
  std::thread thread_;
};

// A file's readings without their times (issue 57: a day re-sent with its times shifted
// by 8 h, a Beijing-time re-export, passed the SHA-256 and repeated-row checks, which
// include the time, and was folded twice; shifted by 9 days it made a false event at
// p = 3e-84): every sample's position, attitude as read, planned attitude, tensions,
// lengths and joints, in order, mixed into two 64-bit lanes (a multiply and xor-shift per
// value, each lane its own constants). Not a cryptographic digest: it tells the same
// readings sent again, which no one forges; telemetry's noise makes two real files'
// readings differ in the first row.
class ContentWithoutTime {
 public:
  void Add(const Sample& s, int joints) {
    for (int k = 0; k < 3; ++k) Mix(s.pose.position_m[k]);
    for (int k = 0; k < 3; ++k) Mix(s.measured_rpy_deg[k]);
    for (int k = 0; k < 4; ++k) Mix(s.measured_quaternion_wxyz[k]);
    if (s.has_planned_attitude) {
      for (int k = 0; k < 3; ++k) Mix(s.planned_rpy_deg[k]);
    }
    for (double t : s.tension_n) Mix(t);
    if (s.has_unstretched_lengths) {
      for (double l : s.unstretched_length_m) Mix(l);
    }
    for (int j = 0; j < joints; ++j) Mix(s.joint[j]);
  }
  std::string Hex() const {
    char text[33];
    std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(Final(a_)),
                  static_cast<unsigned long long>(Final(b_)));
    return text;
  }

 private:
  void Mix(double value) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));
    a_ = (a_ ^ bits) * 0x9E3779B97F4A7C15ULL;
    a_ ^= a_ >> 32;
    b_ = (b_ + bits) * 0xC2B2AE3D27D4EB4FULL;
    b_ ^= b_ >> 29;
  }
  static std::uint64_t Final(std::uint64_t h) {  // splitmix64's finaliser
    h ^= h >> 30;
    h *= 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 27;
    h *= 0x94D049BB133111EBULL;
    return h ^ (h >> 31);
  }
  std::uint64_t a_ = 0x243F6A8885A308D3ULL, b_ = 0x13198A2E03707344ULL;
};

// The samples of file `index` (`path`) into the store, and its span and count into *file.
bool ReadSamples(Router& router, const std::string& path, int index, const std::string& stem,
                 TrackFile* file, std::string* error) {
  TrackRun& run = router.run;
  DatasetReadOptions read = run.options.read;
  SetJointColumns(run.model.moving_parts, &read);
  read.threads = std::max(read.threads, run.options.threads);
  DatasetChunkReader reader;
  if (!reader.Open(path, read, error)) return false;
  ChunksAhead ahead(&reader);
  Dataset chunk;
  ContentWithoutTime content;
  const int joints = run.model.moving_parts.num_joints();
  bool done = false;
  bool scale_checked = false;
  while (!done) {
    if (!ahead.Next(&chunk, &done, error)) return false;
    // The tensions' unit, on the file's first chunk (a slip is in every row), as calibrate
    // checks a survey (issue 37: a map's kN read as N made track fail with "cannot solve
    // this pose", naming no unit).
    if (!scale_checked && !chunk.samples.empty()) {
      chunk.path = path;
      if (!CheckTensionScale(chunk, run.model, error)) return false;
      scale_checked = true;
    }
    if (run.spec.use_planned_attitude && !chunk.samples.empty() && !chunk.has_planned_attitude) {
      *error = path +
               ": the spec fits with the planned attitude but the file has no "
               "planned_roll_deg, planned_pitch_deg, planned_yaw_deg columns";
      return false;
    }
    if (read.skip_invalid_rows && !chunk.samples.empty()) {
      // As calibrate --skip-invalid-rows: a pose the track's start cannot solve (near the
      // workspace's edge the measured attitude's error can loop a cable the cabin held taut)
      // goes the way of a malformed row, named in the notes; without the flag the fold
      // refuses it, naming it and why.
      chunk.path = path;
      run.unsolvable_skipped += SkipUnsolvableSamples(
          InitialCalibrationModel(run.model, run.spec), "the initial model",
          {run.spec.use_planned_attitude ? AttitudeSource::kPlanned : AttitudeSource::kMeasured},
          {run.spec.forward_model}, &chunk);
    }
    for (const std::string& skipped : chunk.skipped) {
      if (run.files_skipped.size() < kMaxSkippedNamed) run.files_skipped.push_back(skipped);
    }
    for (const Sample& s : chunk.samples) {
      // Relative times (seconds from a file's own start) of two files on one time line of
      // windows would merge unrelated days (a 10 cm move hidden): one file's relative
      // times are its own line, two need a window each (issue 37).
      if (run.window.kind != WindowSpec::Kind::kFile && !IsUnixTime(s.time_s)) {
        if (router.relative_file >= 0 && router.relative_file != index) {
          *error = path + ": relative times (" + FormatDouble("%g", s.time_s) +
                   " s, not Unix times) as in " + run.files[router.relative_file].path +
                   ": two such files cannot share windows of time; give --window=file (a "
                   "window per file), or files with Unix or ISO 8601 times";
          return false;
        }
        router.relative_file = index;
      }
      if (!Route(router, s, index, stem)) return false;
      content.Add(s, joints);
      file->first_s = std::isnan(file->first_s) ? s.time_s : std::min(file->first_s, s.time_s);
      file->last_s = std::isnan(file->last_s) ? s.time_s : std::max(file->last_s, s.time_s);
    }
    file->samples += static_cast<long long>(chunk.samples.size());
  }
  if (file->samples > 0) file->content = content.Hex();
  return true;
}

// Data given twice (a copy, a hard link, a day re-sent; a .csv and its .csv.gz) would be
// folded twice: refused by content (issue 37). "" when `file` is no copy.
std::string CopyOf(const TrackRun& run, const TrackFile& file) {
  for (const TrackFile& f : run.files) {
    if (f.sha256 != file.sha256) continue;
    return file.path + ": the same data as " + f.path +
           (run.update ? ", already in the track" : ", given too") +
           " (SHA-256 of the content): each sample is folded once; drop one";
  }
  // The same readings at other times: a re-export in another zone, or re-stamped.
  for (const TrackFile& f : run.files) {
    if (file.content.empty() || f.content != file.content) continue;
    std::string shift;
    if (std::isfinite(f.first_s) && std::isfinite(file.first_s)) {
      const double hours = (file.first_s - f.first_s) / 3600.0;
      shift = ", its times shifted by " + FormatDouble("%+.6g", hours) + " h";
      if (std::abs(hours) >= 48.0) shift += " (" + FormatDouble("%+.4g", hours / 24.0) + " d)";
    }
    return file.path + ": the same readings as " + f.path +
           (run.update ? ", already in the track" : ", given too") + shift +
           " (a re-export in another time zone, or re-stamped?): each sample is folded once; "
           "drop one";
  }
  return "";
}

bool ReadFile(Router& router, const std::string& path, std::string* error) {
  TrackRun& run = router.run;
  TrackFile file;
  file.path = path;
  std::error_code ec;
  file.bytes = static_cast<long long>(fs::file_size(path, ec));
  const int index = static_cast<int>(run.files.size());
  const std::string stem = SessionLabelOfPath(path);
  if (run.window.kind == WindowSpec::Kind::kFile && !IsValidSessionLabel(stem)) {
    *error = path + ": with a window per file the file's name " + stem +
             " labels its window: letters, digits, '-' and '_' only";
    return false;
  }
  // The digest beside the reading (a pass of its own before it was a tenth of reading a
  // season): a copy's samples are in the store when it is found, and go with the run's
  // failure (a new track's directory removed, an update's stores cut back). A copy is
  // named whatever else its read met (two copies of a file of relative times would be
  // told to take a window each).
  DigestAhead digest(path);
  std::string read_error, digest_error;
  const bool read = ReadSamples(router, path, index, stem, &file, &read_error);
  if (!digest.Get(&file.sha256, &digest_error)) {
    *error = read ? digest_error : read_error;
    return false;
  }
  if (std::string copy = CopyOf(run, file); !copy.empty()) {
    *error = std::move(copy);
    return false;
  }
  if (!read) {
    *error = read_error;
    return false;
  }
  run.files.push_back(file);
  return true;
}

}  // namespace

bool ParseTrackStateText(const std::string& text, int* windows, std::string* error) {
  SavedState s;
  try {
    s = ParseState(text);
  } catch (const YAML::Exception& e) {
    *error = "line " + std::to_string(e.mark.line + 1) + ": " + e.msg;
    return false;
  }
  for (const TrackWindowState& w : s.windows) {
    for (int f : w.files) {
      if (f < 0 || f >= static_cast<int>(s.files.size())) {
        *error = "window " + w.label + " names a file out of range";
        return false;
      }
    }
  }
  *windows = static_cast<int>(s.windows.size());
  return true;
}

TrackStatus ExpandDataPaths(const std::vector<std::string>& given, std::vector<std::string>* out,
                            std::string* error) {
  out->clear();
  for (const std::string& path : given) {
    std::error_code ec;
    if (!fs::is_directory(path, ec)) {
      out->push_back(path);
      continue;
    }
    std::vector<std::string> csv;
    for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
      // *.csv and *.csv.gz in any case (FAST's exports say .CSV; months are kept
      // gzipped); hidden files (an editor's .x.csv, a sync tool's) are not data (issue 37).
      const std::string name = e.path().filename().string();
      std::string lower = name;
      for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      const auto ends = [&](const std::string& suffix) {
        return lower.size() > suffix.size() &&
               lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0;
      };
      if (e.is_regular_file() && (ends(".csv") || ends(".csv.gz")) && name[0] != '.') {
        csv.push_back(e.path().string());
      }
    }
    std::sort(csv.begin(), csv.end());
    if (csv.empty()) {
      *error = path + ": a directory without *.csv or *.csv.gz files";
      return TrackStatus::kInvalidInput;
    }
    out->insert(out->end(), csv.begin(), csv.end());
  }
  if (out->empty()) {
    *error = "no data files";
    return TrackStatus::kInvalidInput;
  }
  for (size_t a = 0; a < out->size(); ++a) {
    for (size_t b = a + 1; b < out->size(); ++b) {
      if (fs::weakly_canonical((*out)[a]) == fs::weakly_canonical((*out)[b])) {
        *error = (*out)[b] + ": given twice";
        return TrackStatus::kInvalidInput;
      }
    }
  }
  return TrackStatus::kOk;
}

// `out` with its own symbolic links followed (up to 40, as the kernel does; a dangling one
// to where it points), as a canonical path; `out` itself when it is no link. (A linked
// parent needs nothing: the lock file beside DIR is then the same file either way.)
std::string ResolvedTrackPath(const std::string& out) {
  std::error_code ec;
  fs::path p = fs::path(out);
  if (!fs::is_symlink(p, ec)) return out;
  for (int hop = 0; hop < 40 && fs::is_symlink(p, ec); ++hop) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) return out;
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  const fs::path resolved = fs::weakly_canonical(p, ec);
  return ec ? p.lexically_normal().string() : resolved.string();
}

// The track `out` names, however it is spelled: its links followed, then made absolute
// and canonical (issue 57: `--out=/p/t` and, from inside it, `--out=.` locked two
// different files, ./..lock and /p/.t.lock, and both runs wrote the track). "" with
// *error when it cannot be a track's directory: the root, or an existing non-directory.
std::string TrackDirectoryOf(const std::string& out, std::string* error) {
  std::error_code ec;
  fs::path p = fs::absolute(fs::path(ResolvedTrackPath(out)), ec);
  if (!ec) p = fs::weakly_canonical(p, ec);
  if (ec) p = fs::absolute(fs::path(out)).lexically_normal();
  if (p.filename().empty() && p.has_parent_path() && p.parent_path() != p) p = p.parent_path();
  if (p.filename().empty() || p == p.root_path()) {
    *error = out +
             ": the root directory cannot hold a track; give --out=DIR, a new or empty "
             "directory or a track";
    return "";
  }
  if (fs::exists(p, ec) && !fs::is_directory(p, ec)) {
    *error = out +
             ": not a directory (a track is a directory: give a new or empty one, or a "
             "track)";
    return "";
  }
  return p.string();
}

// Opens and locks `path` (created if missing) into *fd. A lock whose file was unlinked
// between the open and the lock (its holder released it) is no lock: opened again. False
// with errno's reason in *error, or with *busy when another process holds it.
bool LockFile(const std::string& path, int* fd, bool* busy, std::string* error) {
  constexpr int kMaxReopens = 100;  // each reopen means another run released it meanwhile
  *busy = false;
  for (int attempt = 0; attempt < kMaxReopens; ++attempt) {
    *fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (*fd < 0) {
      *error = std::strerror(errno);
      return false;
    }
    if (::flock(*fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(*fd);
      *fd = -1;
      *busy = true;
      return false;
    }
    struct stat held {
    }, named{};
    if (::fstat(*fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 &&
        held.st_dev == named.st_dev && held.st_ino == named.st_ino) {
      return true;
    }
    ::close(*fd);
    *fd = -1;
  }
  *error = "the lock file kept being replaced";
  return false;
}

// The exclusive lock on DIR for the run's life: a lock file beside DIR, ".NAME.lock"
// (beside it, so that a new track's DIR, made only at the end, is locked too), named from
// the resolved track (TrackDirectoryOf). A second run on the same DIR is refused at once,
// naming it. Leftover staging directories of runs that died (DIR.partial-PID) are removed
// once the lock is held: none is alive.
TrackStatus LockDirectory(TrackRun& run) {
  // One lock per track, however DIR is spelled: a symbolic link (even one to a DIR not yet
  // made), a linked parent, '.', '..' or a relative path (issue 37: two runs on `n` and on
  // `sym -> n` both ran, and one result was lost; issue 57: `.` from inside it).
  std::string why;
  const std::string resolved = TrackDirectoryOf(run.out, &why);
  if (resolved.empty()) return run.Fail(TrackStatus::kInvalidInput, why);
  run.out = resolved;
  const fs::path out(run.out);
  const fs::path parent = out.parent_path();
  const std::string lock = (parent / ("." + out.filename().string() + ".lock")).string();
  bool busy = false;
  if (!LockFile(lock, &run.lock.fd, &busy, &why)) {
    if (busy) {
      return run.Fail(TrackStatus::kFailed,
                      run.out + ": another fastcal track is running on it (" + lock +
                          " is locked): wait for it to finish, or give another --out");
    }
    return run.Fail(TrackStatus::kInvalidInput, lock + ": cannot create the track's lock: " + why);
  }
  run.lock.path = lock;
  std::error_code ec;
  const std::string partial = out.filename().string() + ".partial-";
  for (const fs::directory_entry& e : fs::directory_iterator(parent, ec)) {
    if (e.path().filename().string().rfind(partial, 0) == 0) fs::remove_all(e.path(), ec);
  }
  return TrackStatus::kOk;
}

namespace {

// What in track directory `dir` is not the track's (IsTrackOutput), as the message that
// refuses to replace it ("" when nothing).
std::string OtherFiles(const std::string& dir) {
  std::error_code ec;
  std::vector<std::string> other;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!IsTrackOutput(name)) other.push_back(name);
  }
  if (other.empty()) return "";
  std::sort(other.begin(), other.end());
  std::string list;
  for (size_t k = 0; k < other.size() && k < 3; ++k) list += (k ? ", " : "") + other[k];
  if (other.size() > 3) list += " and " + std::to_string(other.size() - 3) + " more";
  return "holds files that are not the track's (" + list +
         "): --force replaces a track, never anything else; move them, or give another --out";
}

}  // namespace

TrackStatus PrepareDirectory(TrackRun& run) {
  if (const TrackStatus locked = LockDirectory(run); locked != TrackStatus::kOk) return locked;
  // A track --force was replacing when a crash came between the fallback's two renames
  // (no RENAME_EXCHANGE): put back (internal::PublishDirectory).
  RemoveStaleTemporaries(run.out);
  std::error_code ec;
  const bool exists = fs::exists(run.out, ec);
  if (exists && !fs::is_directory(run.out, ec)) {
    return run.Fail(TrackStatus::kInvalidInput, run.out + ": not a directory");
  }
  if (exists && fs::exists(run.out + "/" + kStateFile, ec)) {
    // A symbolic link inside the track would read, truncate or delete files outside it
    // (a review's symlinked store was cut in half elsewhere, issue 37): none is followed.
    for (auto it = fs::recursive_directory_iterator(run.out, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (it->is_symlink(ec)) {
        return run.Fail(TrackStatus::kInvalidInput,
                        it->path().string() +
                            ": a symbolic link inside a track is refused (it would read or "
                            "write outside the track); replace it with the file or directory");
      }
    }
    if (run.options.force) {
      if (const std::string other = OtherFiles(run.out); !other.empty()) {
        return run.Fail(TrackStatus::kInvalidInput, run.out + ": " + other);
      }
    }
    run.dir = run.out;
    bool use = false;
    if (!LoadSavedState(run, &use)) return TrackStatus::kInvalidInput;
    run.update = use;
    if (use) return TrackStatus::kOk;
    run.files.clear();
    run.windows.clear();
    run.shared.clear();
  } else if (exists && !IsEmptyDirectory(run.out)) {
    return run.Fail(TrackStatus::kInvalidInput,
                    run.out +
                        " is not empty and holds no track (track_state.json): give a new "
                        "or empty directory");
  }
  // A new track: built beside DIR and moved into place at the end.
  run.dir = run.out + ".partial-" + std::to_string(::getpid());
  fs::remove_all(run.dir, ec);
  // Removed with what it holds when SIGINT or SIGTERM stops the run (a signal handler's
  // work: atomic_file.h; issue 37: a stopped new track left its window stores).
  internal::RegisterTemporaryDirectory(run.dir);
  if (!fs::create_directories(run.dir + "/windows", ec) ||
      !fs::create_directories(run.dir + "/folds", ec)) {
    return run.Fail(TrackStatus::kInvalidInput, run.dir + ": cannot create: " + ec.message());
  }
  run.generation = 1;
  return TrackStatus::kOk;
}

// Two files whose time spans overlap (issue 37: overlapping files were double-counted
// with a false sensor event): named, unless TrackOptions::keep_overlapping. Files of
// relative times have a line each (--window=file) and are not compared.
std::string Overlap(const TrackRun& run) {
  if (run.options.keep_overlapping || run.window.kind == WindowSpec::Kind::kFile) return "";
  for (size_t a = 0; a < run.files.size(); ++a) {
    for (size_t b = a + 1; b < run.files.size(); ++b) {
      const TrackFile& f = run.files[a];
      const TrackFile& g = run.files[b];
      if (!(f.first_s <= g.last_s && g.first_s <= f.last_s)) continue;  // NaN: unknown
      return g.path + " (" + TrackTimeText(g.first_s, 0) + " to " + TrackTimeText(g.last_s, 0) +
             ") overlaps " + f.path + " (" + TrackTimeText(f.first_s, 0) + " to " +
             TrackTimeText(f.last_s, 0) +
             ") in time: the same instants given twice would be folded twice; drop one, or "
             "give --keep-overlapping if both belong";
    }
  }
  return "";
}

TrackStatus ReadNewFiles(TrackRun& run) {
  Router router(run);
  int read = 0;
  for (const std::string& path : run.data_paths) {
    if (std::any_of(run.files.begin(), run.files.end(),
                    [&](const TrackFile& f) { return f.path == path; })) {
      continue;
    }
    if (run.StopRequested()) return run.Cancel();
    run.Progress("reading " + path);
    if (!ReadFile(router, path, run.error)) return TrackStatus::kInvalidInput;
    ++read;
  }
  if (!router.Flush()) return TrackStatus::kFailed;
  if (const std::string overlap = Overlap(run); !overlap.empty()) {
    return run.Fail(TrackStatus::kInvalidInput, overlap);
  }
  std::stable_sort(
      run.windows.begin(), run.windows.end(),
      [](const TrackWindowState& a, const TrackWindowState& b) { return a.start_s < b.start_s; });
  for (size_t a = 1; a < run.windows.size(); ++a) {
    for (size_t b = 0; b < a; ++b) {
      if (run.windows[a].label != run.windows[b].label) continue;
      return run.Fail(TrackStatus::kInvalidInput,
                      "two windows are labelled " + run.windows[a].label +
                          " (one per file: give the files distinct names)");
    }
  }
  for (const std::string& s : run.files_skipped) run.result->notes.push_back("skipped: " + s);
  if (run.unsolvable_skipped > 0) {
    run.result->notes.push_back(std::to_string(run.unsolvable_skipped) + " sample" +
                                (run.unsolvable_skipped == 1 ? "" : "s") +
                                " the initial model cannot solve left out (--skip-invalid-rows)");
  }
  if (run.update) {
    run.result->notes.push_back(std::to_string(read) + " new file" + (read == 1 ? "" : "s") +
                                " added to the track in " + run.out);
  }
  return TrackStatus::kOk;
}

bool LoadFold(const TrackRun& run, TrackWindowState* w, std::string* error) {
  std::string bytes;
  const std::string path = run.Path(w->fold_file);
  if (!ReadRegularFile(path, 1LL << 30, "fold", &bytes, error)) return false;
  return ParseWindowFold(bytes, path, &w->fold, error);
}

namespace {

// Each store's committed length (appends past it are an interrupted run's: CheckStores)
// and digest, hashed again only where this run appended; the stores on the run's threads
// (1.5 GB of them at 10^7 samples: a second on one core, issue 41). False with the first
// failure in window order.
bool DigestStores(TrackRun& run) {
  std::vector<int> to_hash;
  for (size_t k = 0; k < run.windows.size(); ++k) {
    TrackWindowState& w = run.windows[k];
    std::error_code ec;
    const std::string store = run.Path("windows/" + w.StoreName());
    const long long bytes =
        fs::exists(store, ec) ? static_cast<long long>(fs::file_size(store, ec)) : 0;
    if (bytes != w.store_bytes || w.store_sha256.empty()) {
      w.store_sha256.clear();
      if (bytes > 0) to_hash.push_back(static_cast<int>(k));
    }
    w.store_bytes = bytes;
  }
  std::vector<std::string> errors(to_hash.size());
  const int failed = internal::ForEachChunk(
      static_cast<int>(to_hash.size()), run.options.threads,
      [&](int begin, int end) {
        for (int i = begin; i < end; ++i) {
          TrackWindowState& w = run.windows[to_hash[i]];
          if (!FileSha256(run.Path("windows/" + w.StoreName()), &w.store_sha256, &errors[i])) {
            return i;
          }
        }
        return -1;
      },
      1);
  if (failed < 0) return true;
  *run.error = errors[failed];
  return false;
}

}  // namespace

TrackStatus SaveState(TrackRun& run) {
  for (TrackWindowState& w : run.windows) {
    if (!w.folded) continue;
    w.fold_file = FoldName(w.label, run.generation);
    // The residual run served this run's slow-error estimate; an update keeps the process.
    WindowFold kept = w.fold;
    kept.residuals.clear();
    if (!WriteFileAtomically(run.Path(w.fold_file), SerializeWindowFold(kept), run.error) ||
        !FileSha256(run.Path(w.fold_file), &w.fold_sha256, run.error)) {
      return TrackStatus::kFailed;
    }
  }
  if (!DigestStores(run)) return TrackStatus::kFailed;
  if (!WriteFileAtomically(run.Path(kStateFile), StateJson(run), run.error)) {
    return TrackStatus::kFailed;
  }
  return TrackStatus::kOk;
}

TrackStatus FinishDirectory(TrackRun& run) {
  std::error_code ec;
  if (run.update) {
    // Fold files no window uses any more.
    for (const fs::directory_entry& e : fs::directory_iterator(run.Path("folds"), ec)) {
      const std::string name = "folds/" + e.path().filename().string();
      if (std::none_of(run.windows.begin(), run.windows.end(),
                       [&](const TrackWindowState& w) { return w.fold_file == name; })) {
        fs::remove(e.path(), ec);
      }
    }
    return TrackStatus::kOk;
  }
  // A new track: synced where it was built, then put in place in one step as every
  // command's results are (internal::PublishDirectory): DIR empty or missing, or a track
  // --force replaces, swapped with it (RENAME_EXCHANGE); never a mix of the two.
  int err = 0;
  for (const char* sub : {"/windows", "/folds", ""}) {
    if (!SyncDirectory(run.dir + sub, &err)) {
      return run.Fail(TrackStatus::kFailed,
                      run.out + ": cannot write the track: " + std::strerror(err));
    }
  }
  std::function<bool(std::string*)> may_replace;
  if (run.options.force) {
    may_replace = [&run](std::string* why) {
      *why = OtherFiles(run.out);
      if (!why->empty()) *why = run.out + ": " + *why;
      return why->empty();
    };
  }
  std::string why;
  if (!PublishDirectory(run.dir, run.out, may_replace, &why)) {
    return run.Fail(TrackStatus::kFailed, why.rfind(run.out, 0) == 0 ? why : run.out + ": " + why);
  }
  if (!SyncDirectory(ParentDirectory(run.out), &err)) {
    return run.Fail(
        TrackStatus::kFailed,
        run.out + ": written, but its directory cannot be synced: " + std::strerror(err));
  }
  run.dir = run.out;
  return TrackStatus::kOk;
}

void RollBack(TrackRun& run) {
  std::error_code ec;
  if (run.dir.empty()) return;
  if (!run.update) {
    if (run.dir != run.out) fs::remove_all(run.dir, ec);
    return;
  }
  for (const auto& [path, size] : run.appended) {
    if (size < 0)
      fs::remove(path, ec);  // made by this run
    else
      fs::resize_file(path, size, ec);
  }
  const std::string suffix = ".g" + std::to_string(run.generation) + ".fold";
  for (const fs::directory_entry& e : fs::directory_iterator(run.Path("folds"), ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      fs::remove(e.path(), ec);
    }
  }
}

}  // namespace fastcal::internal
