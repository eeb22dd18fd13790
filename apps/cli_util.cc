#include "cli_util.h"

#include <fcntl.h>
#include <gflags/gflags.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>

#include "common_flags.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/edit_distance.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/plausibility.h"
#include "fastcal/version.h"

namespace fastcal::cli {

bool WantsHelp(int argc, char** argv, int first) {
  for (int i = first; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help" || a == "-help" || a == "--helpfull") return true;
  }
  return false;
}

namespace {

// One spelling per unit, the data's (T1_kN, tension_sigma_percent); the old names stay
// accepted, with a note, so that scripts and the bundled datasets' headers still run.
const std::vector<std::pair<std::string, std::string>>& RenamedFlags() {
  static const std::vector<std::pair<std::string, std::string>> kRenamed = {
      {"min-tension-kn", "min-tension-kN"},
      {"max-tension-kn", "max-tension-kN"},
      {"sensor-bias-kn", "sensor-bias-kN"},
      {"sensor-bias-spread-kn", "sensor-bias-spread-kN"},
      {"tension-noise-kn", "tension-noise-kN"},
      {"tension-noise-pct", "tension-noise-percent"},
      {"outlier-scale-pct", "outlier-scale-percent"},
      {"density-mismatch-pct", "density-mismatch-percent"},
      {"tension-drift-pct", "tension-drift-percent"},
      {"tension-drift-kn", "tension-drift-kN"},
      {"sensor-rezero-kn", "sensor-rezero-kN"},
      {"sensor-gain-spread-pct", "sensor-gain-spread-percent"}};
  return kRenamed;
}

}  // namespace

std::string DeprecatedFlagName(const std::string& old_name) {
  for (const auto& [old, renamed] : RenamedFlags()) {
    if (old == old_name) return renamed;
  }
  return "";
}

using internal::EditDistance;

std::vector<std::string> ClosestNames(const std::string& name,
                                      const std::set<std::string>& allowed) {
  constexpr size_t kMaxShown = 3;
  // Within a third of the name's length (at least 2): "--tension-nosie-percent" finds its
  // flag, "--x" does not get a list of every short one.
  const size_t within = std::max<size_t>(2, name.size() / 3);
  std::vector<std::pair<size_t, std::string>> ranked;
  for (const std::string& flag : allowed) {
    size_t d = EditDistance(name, flag);
    // A slip in an old name ("--tension-nosie-pct") leads to the new one.
    for (const auto& [old, renamed] : RenamedFlags()) {
      if (renamed == flag) d = std::min(d, EditDistance(name, old));
    }
    // A flag the name is the start of ("--tension-noise" for --tension-noise-percent).
    const bool starts = name.size() >= 3 && flag.rfind(name, 0) == 0;
    if (d <= within || starts) ranked.emplace_back(starts ? std::min(d, within) : d, flag);
  }
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> out;
  for (size_t k = 0; k < ranked.size() && k < kMaxShown; ++k) out.push_back(ranked[k].second);
  return out;
}

bool CheckAndNormaliseFlags(int argc, char** argv, int first, const std::string& command,
                            const std::set<std::string>& allowed,
                            std::vector<std::string>* normalised, std::string* error,
                            std::vector<std::string>* notes) {
  normalised->assign(1, argv[0]);
  std::set<std::string> seen;
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.size() < 3 || arg[0] != '-') {
      *error = "unexpected argument " + internal::Quote(arg) +
               " (flags are --name=value; see fastcal " + command + " --help)";
      return false;
    }
    const size_t start = arg[1] == '-' ? 2 : 1;
    const size_t eq = arg.find('=');
    std::string name = arg.substr(start, eq == std::string::npos ? std::string::npos : eq - start);
    if (const std::string renamed = DeprecatedFlagName(name);
        !allowed.count(name) && !renamed.empty() && allowed.count(renamed)) {
      if (notes != nullptr) {
        notes->push_back("--" + name + " is deprecated; use --" + renamed +
                         " (units spelt as in the data: _kN, _percent)");
      }
      name = renamed;
    }
    std::string bare = name;
    if (!allowed.count(bare) && bare.rfind("no", 0) == 0 && allowed.count(bare.substr(2))) {
      bare = bare.substr(2);  // gflags' --noflag form of a boolean
    }
    std::string underscored = name;
    for (char& c : underscored) {
      if (c == '-') c = '_';
    }
    if (!allowed.count(bare)) {
      std::string guess;
      const std::vector<std::string> closest = ClosestNames(name, allowed);
      for (size_t k = 0; k < closest.size(); ++k) {
        guess += std::string(k == 0                   ? "; did you mean "
                             : k + 1 < closest.size() ? ", "
                                                      : " or ") +
                 "--" + closest[k];
      }
      *error = "unknown flag --" + internal::Escape(name.substr(0, internal::kMaxQuotedBytes)) +
               (guess.empty() ? "" : guess + "?") + " (see fastcal " + command + " --help)";
      return false;
    }
    if (!seen.insert(bare).second) {
      *error = "--" + bare + " given twice; give each flag once";
      return false;
    }
    // Check the value's type here: gflags would exit 1 with its own message.
    gflags::CommandLineFlagInfo info;
    if (eq == std::string::npos && gflags::GetCommandLineFlagInfo(underscored.c_str(), &info) &&
        info.type != "bool") {
      *error =
          "--" + name + " needs a value: --" + name + "=... (see fastcal " + command + " --help)";
      return false;
    }
    if (eq != std::string::npos && gflags::GetCommandLineFlagInfo(underscored.c_str(), &info)) {
      const std::string value = arg.substr(eq + 1);
      const char* begin = value.c_str();
      char* end = nullptr;
      bool ok = true;
      // The numbers of a flag are read as a file's are: whole decimal text (no hexadecimal,
      // no trailing junk), finite, and in the range of the flag's type (no truncation).
      if (info.type == "int32" || info.type == "int64") {
        errno = 0;
        const long long v = std::strtoll(begin, &end, 10);
        ok = !value.empty() && *end == '\0' && errno == 0 &&
             (info.type == "int64" || (v >= INT32_MIN && v <= INT32_MAX));
      } else if (info.type == "uint32" || info.type == "uint64") {
        errno = 0;
        const unsigned long long v = std::strtoull(begin, &end, 10);
        ok = !value.empty() && value[0] != '-' && *end == '\0' && errno == 0 &&
             (info.type == "uint64" || v <= UINT32_MAX);
      } else if (info.type == "double") {
        double v = 0.0;
        std::string why;
        ok = internal::ParseFiniteDecimal(value, &v, &why);
      } else if (info.type == "bool") {
        ok = value == "true" || value == "false" || value == "1" || value == "0";
      }
      if (!ok) {
        *error = "--" + name + ": " + internal::Quote(value) + " is not a valid " +
                 (info.type == "bool"     ? std::string("true/false")
                  : info.type == "double" ? std::string("finite decimal number")
                                          : std::string("whole number in range")) +
                 " (see fastcal " + command + " --help)";
        return false;
      }
    }
    normalised->push_back("--" + underscored +
                          (eq == std::string::npos ? std::string() : arg.substr(eq)));
  }
  return true;
}

void ParseFlags(const std::vector<std::string>& args) {
  std::vector<char*> ptrs;
  for (const std::string& a : args) ptrs.push_back(const_cast<char*>(a.c_str()));
  int n = static_cast<int>(ptrs.size());
  char** p = ptrs.data();
  gflags::ParseCommandLineFlags(&n, &p, /*remove_flags=*/true);
}

bool StartCommand(int argc, char** argv, const std::string& command, const char* help,
                  const std::set<std::string>& allowed, int* exit_code) {
  if (WantsHelp(argc, argv, 2)) {
    std::cout << help;
    *exit_code = 0;
    return false;
  }
  for (int i = 2; i < argc; ++i) {  // `fastcal CMD --version`, as `fastcal --version`
    if (std::string(argv[i]) == "--version") {
      std::cout << "fastcal " << FASTCAL_VERSION << "\n";
      *exit_code = 0;
      return false;
    }
  }
  std::vector<std::string> args, notes;
  std::string error;
  if (!CheckAndNormaliseFlags(argc, argv, 2, command, allowed, &args, &error, &notes)) {
    PrintError(command, error);
    *exit_code = kExitUsage;
    return false;
  }
  for (const std::string& note : notes) PrintError(command, "note: " + note);
  ParseFlags(args);
  return true;
}

bool FlagGiven(const std::string& name) {
  std::string underscored = name;
  for (char& c : underscored) {
    if (c == '-') c = '_';
  }
  return !gflags::GetCommandLineFlagInfoOrDie(underscored.c_str()).is_default;
}

bool CheckFlagsApply(const std::vector<FlagScope>& scopes, const std::string& mode,
                     std::string* error) {
  for (const FlagScope& scope : scopes) {
    if (scope.applies || !FlagGiven(scope.flag)) continue;
    *error = "--" + scope.flag + " applies to " + scope.belongs_to + ", not to " + mode;
    return false;
  }
  return true;
}

std::string ModelName(const std::string& model_path) {
  return model_path.empty() ? "nominal FAST" : model_path;
}

bool LoadModelFlag(const std::string& flag, const std::string& path, CableRobot* robot,
                   std::string* error) {
  *robot = CableRobot::NominalFast();
  if (path.empty() || LoadCableRobot(path, robot, error)) return true;
  *error = WithFlagNames(*error, {{"the model file", "--" + flag}});
  return false;
}

namespace {
bool IsNameChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
}  // namespace

std::string WithFlagNames(const std::string& message,
                          const std::vector<std::pair<std::string, std::string>>& field_to_flag) {
  std::string out;
  size_t i = 0;
  while (i < message.size()) {
    bool replaced = false;
    // A name starts here only if the previous character does not continue a name
    // ("sphere.radius_m" is one name, "x.y" too, but "(radius_m" starts one).
    const bool at_start = i == 0 || !(IsNameChar(message[i - 1]) || message[i - 1] == '.');
    if (at_start) {
      for (const auto& [field, flag] : field_to_flag) {
        if (message.compare(i, field.size(), field) != 0) continue;
        const size_t end = i + field.size();
        const bool name_goes_on =
            end < message.size() &&
            (IsNameChar(message[end]) || message[end] == '[' ||
             (message[end] == '.' && end + 1 < message.size() && IsNameChar(message[end + 1])));
        if (name_goes_on) continue;
        out += flag;
        i = end;
        replaced = true;
        break;
      }
    }
    if (!replaced) out += message[i++];
  }
  return out;
}

namespace {

// Whether a new file (or directory) can be made in `dir`: makes a uniquely named probe
// and removes it. Asking access(2) is not enough: root passes it on /proc and on a
// read-only mount. False with "cannot create a file in '<dir>': <why>".
bool CanCreateIn(const std::filesystem::path& dir, bool directory, std::string* why) {
  const std::filesystem::path probe = dir / (".fastcal-write-probe." + std::to_string(::getpid()));
  const std::string shown = dir.empty() ? "." : dir.string();
  if (directory ? ::mkdir(probe.c_str(), 0700) == 0 : [&] {
        const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        return fd >= 0 && ::close(fd) == 0;
      }()) {
    directory ? ::rmdir(probe.c_str()) : ::unlink(probe.c_str());
    return true;
  }
  *why = std::string("cannot create a ") + (directory ? "directory" : "file") + " in '" +
         internal::Escape(shown) + "': " + std::strerror(errno);
  return false;
}

}  // namespace

bool CheckCanWrite(const std::string& flag, const std::string& path, bool force,
                   std::string* error) {
  if (path.empty() || path == "-") return true;
  // What killed runs left beside it first (internal::RemoveStaleTemporaries).
  internal::RemoveStaleTemporaries(path);
  const std::string where = "--" + flag + "=" + internal::Escape(path) + ": ";
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::is_directory(status)) {
    *error = where + "is a directory (give a file name)";
    return false;
  }
  // The output is written beside the path and renamed over it: that would replace a
  // device, a pipe or a link (with --force, /dev/null itself) instead of writing to it.
  const std::filesystem::file_status link = std::filesystem::symlink_status(path, ec);
  if (std::filesystem::exists(link) && !std::filesystem::is_regular_file(link)) {
    *error = where + "is not a regular file (a " +
             (std::filesystem::is_symlink(link) ? "symbolic link" : "device, pipe or socket") +
             "): not replaced; give a new file name (--" + flag +
             "=- writes to standard output where the command allows it)";
    return false;
  }
  if (std::filesystem::exists(status) && !force) {
    *error = where + "exists; not overwritten (add --force to replace it, or choose another name)";
    return false;
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec)) {
    *error = where + "cannot write: directory '" + internal::Escape(parent.string()) +
             "' does not exist";
    return false;
  }
  std::string why;
  if (!CanCreateIn(parent.empty() ? std::filesystem::path(".") : parent, false, &why)) {
    *error = where + "cannot write: " + why;
    return false;
  }
  return true;
}

bool CheckOutputDirectory(const std::string& flag, const std::string& dir, std::string* error,
                          const std::vector<std::string>* replaceable) {
  const std::string where = "--" + flag + "=" + internal::Escape(dir) + ": ";
  // What killed runs left beside it first: their temporary directories removed, and a
  // previous result a --force run had moved aside put back (internal::RemoveStaleTemporaries).
  internal::RemoveStaleTemporaries(ResolveOutputPath(dir).string());
  std::error_code ec;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(dir, ec)) &&
      !std::filesystem::exists(dir, ec)) {
    *error = where + "is a symbolic link to nothing (give a directory)";
    return false;
  }
  const std::filesystem::file_status status = std::filesystem::status(dir, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_directory(status)) {
    *error = where + "is a file, not a directory (--" + flag + " names a new or empty directory)";
    return false;
  }
  if (std::filesystem::exists(status) && !std::filesystem::is_empty(dir, ec)) {
    if (replaceable == nullptr) {
      *error = where + "exists and is not an empty directory (choose a new --" + flag +
               ", or --force to replace a previous run's results)";
      return false;
    }
    // --force replaces a previous run's results, never anything else. An entry "A*B"
    // stands for the names that start with A and end with B (a session's model).
    const auto is_result = [&](const std::string& name) {
      for (const std::string& r : *replaceable) {
        const size_t star = r.find('*');
        if (star == std::string::npos
                ? name == r
                : name.size() >= r.size() - 1 && name.compare(0, star, r, 0, star) == 0 &&
                      name.compare(name.size() - (r.size() - star - 1), std::string::npos, r,
                                   star + 1) == 0) {
          return true;
        }
      }
      return false;
    };
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (!is_result(name) || !entry.is_regular_file(ec)) {
        *error = where + "holds '" + internal::Escape(name) +
                 "', which is not a fastcal result: --force replaces only a previous run's "
                 "results (choose a new --" +
                 flag + ")";
        return false;
      }
    }
  }
  // The results are built in a sibling of `dir` and renamed into place, and missing
  // parents are created: the nearest existing ancestor must take a new directory.
  std::filesystem::path ancestor = std::filesystem::absolute(dir, ec).parent_path();
  while (!ancestor.empty() && !std::filesystem::exists(ancestor, ec) &&
         ancestor != ancestor.root_path()) {
    ancestor = ancestor.parent_path();
  }
  if (!std::filesystem::is_directory(ancestor, ec)) {
    *error =
        where + "cannot write: '" + internal::Escape(ancestor.string()) + "' is not a directory";
    return false;
  }
  std::string why;
  if (!CanCreateIn(ancestor, true, &why)) {
    *error = where + "cannot write: " + why;
    return false;
  }
  return true;
}

std::filesystem::path ResolveOutputPath(const std::string& dir) {
  std::string text = dir;
  while (text.size() > 1 && text.back() == '/') text.pop_back();
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(text, ec);
  if (ec) return std::filesystem::path(text).lexically_normal();
  std::filesystem::path resolved = std::filesystem::weakly_canonical(absolute, ec);
  if (ec) resolved = absolute.lexically_normal();
  // lexically_normal keeps a trailing separator ("a/b/" for "a/b/."): drop it.
  if (!resolved.has_filename() && resolved.has_parent_path() && resolved != resolved.root_path()) {
    resolved = resolved.parent_path();
  }
  return resolved;
}

bool ParseNumberItem(const std::string& item, double* value, std::string* why) {
  const size_t begin = item.find_first_not_of(" \t");
  const size_t end = item.find_last_not_of(" \t");
  const std::string_view trimmed = begin == std::string::npos
                                       ? std::string_view()
                                       : std::string_view(item).substr(begin, end + 1 - begin);
  return internal::ParseFiniteDecimal(trimmed, value, why);
}

namespace {
bool ParseList(const std::string& name, const std::string& text, int n, double* out,
               std::string* error) {
  // Every item counts, an empty last one too: "0,0,140,5" and "0,0,140," are not 3 numbers.
  std::vector<std::string> items(1);
  for (char ch : text) {
    if (ch == ',') {
      items.emplace_back();
    } else {
      items.back() += ch;
    }
  }
  if (static_cast<int>(items.size()) != n) {
    *error = "--" + name + " needs " + std::to_string(n) + " comma-separated numbers, got " +
             internal::Quote(text);
    return false;
  }
  for (int k = 0; k < n; ++k) {
    std::string why;
    if (!ParseNumberItem(items[k], &out[k], &why)) {
      *error = "--" + name + ": " + why;
      return false;
    }
  }
  return true;
}
}  // namespace

bool ParseVector3(const std::string& name, const std::string& text, Eigen::Vector3d* v,
                  std::string* error) {
  return ParseList(name, text, 3, v->data(), error);
}

bool ParseVector4(const std::string& name, const std::string& text, Eigen::Vector4d* v,
                  std::string* error) {
  return ParseList(name, text, 4, v->data(), error);
}

bool ParseSix(const std::string& name, const std::string& text, std::array<double, 6>* v,
              std::string* error) {
  return ParseList(name, text, 6, v->data(), error);
}

bool ParsePosition(const std::string& name, const std::string& text, Eigen::Vector3d* position_m,
                   std::string* error) {
  if (!ParseVector3(name, text, position_m, error)) return false;
  std::string why;
  if (CheckPosition(*position_m, PlausibilityLimits(), &why)) return true;
  *error = "--" + name + "=" + internal::Escape(text) + ": " + why;
  return false;
}

bool ParseRpyDeg(const std::string& name, const std::string& text, Eigen::Vector3d* rpy_deg,
                 std::string* error) {
  if (!ParseVector3(name, text, rpy_deg, error)) return false;
  const char* names[] = {"roll", "pitch", "yaw"};
  for (int k = 0; k < 3; ++k) {
    std::string why;
    if (!CheckAngleDeg((*rpy_deg)[k], PlausibilityLimits(), &why)) {
      *error = "--" + name + "=" + internal::Escape(text) + ": " + names[k] + " " + why;
      return false;
    }
  }
  return true;
}

bool WriteOutput(const std::string& path, const std::string& content, std::string* error,
                 bool replace) {
  if (path.empty() || path == "-") {
    // Checked here, to stop at once; FinishStandardOutput checks again at exit.
    std::cout.write(content.data(), static_cast<std::streamsize>(content.size()));
    std::cout.flush();
    if (StdoutError() != 0 || !std::cout.good()) {
      *error = std::string("cannot write to standard output: ") +
               std::strerror(StdoutError() != 0 ? StdoutError() : EIO) +
               " (what it received is incomplete)";
      return false;
    }
    return true;
  }
  return internal::WriteFileAtomically(path, content, error, replace);
}

ResultStream::~ResultStream() {
  if (spill_ != nullptr) std::fclose(spill_);
}

bool ResultStream::Open(const std::string& path, std::string* error) {
  to_stdout_ = path.empty() || path == "-";
  return to_stdout_ || file_.Open(path, error);
}

bool ResultStream::Spill(std::string* error) {
  if (spill_ == nullptr) {
    const char* tmpdir = std::getenv("TMPDIR");
    spill_directory_ = tmpdir != nullptr && *tmpdir != '\0' ? tmpdir : "/tmp";
    int err = 0;
    spill_ = internal::OpenUnnamedFile(spill_directory_, &err);
    if (spill_ == nullptr) {
      *error = "cannot create a temporary file in " + internal::Escape(spill_directory_) +
               " for the output beyond " + std::to_string(kHeldBytes >> 20) +
               " MiB (TMPDIR names another directory): " + std::strerror(err);
      return false;
    }
  }
  if (std::fwrite(held_.data(), 1, held_.size(), spill_) != held_.size()) {
    *error = "cannot write the temporary file in " + internal::Escape(spill_directory_) +
             " that holds the output (TMPDIR names another directory): " + std::strerror(errno);
    return false;
  }
  held_.clear();
  return true;
}

bool ResultStream::Write(std::string_view text, std::string* error) {
  if (!to_stdout_) return file_.Write(text, error);
  // Reserved once: growing by doubling would hold up to twice kHeldBytes.
  if (held_.capacity() < kHeldBytes) held_.reserve(kHeldBytes + (size_t{4} << 20));
  held_.append(text);
  return held_.size() < kHeldBytes || Spill(error);
}

bool ResultStream::Finish(bool replace, std::string* error) {
  if (!to_stdout_) return file_.Commit(replace, error);
  if (spill_ == nullptr) return WriteOutput("-", held_, error);
  if (!Spill(error)) return false;
  std::rewind(spill_);
  std::string chunk(size_t{1} << 20, '\0');
  while (true) {
    const size_t n = std::fread(chunk.data(), 1, chunk.size(), spill_);
    if (n == 0) break;
    if (!WriteOutput("-", chunk.substr(0, n), error)) return false;
  }
  if (std::ferror(spill_) != 0) {
    *error = "cannot read back the temporary file in " + internal::Escape(spill_directory_) +
             " that holds the output: " + std::strerror(errno);
    return false;
  }
  return true;
}

bool WriteOutputsTogether(const std::vector<std::pair<std::string, std::string>>& files,
                          bool replace, std::string* error) {
  std::vector<std::unique_ptr<internal::AtomicFileWriter>> writers;
  for (const auto& [path, content] : files) {
    writers.push_back(std::make_unique<internal::AtomicFileWriter>());
    if (!writers.back()->Open(path, error) || !writers.back()->Write(content, error) ||
        !writers.back()->Sync(error)) {
      return false;
    }
  }
  // Every file is complete in its temporary: now the renames (a failure there, another
  // process taking a name meanwhile, leaves the ones before it in place).
  for (auto& writer : writers) {
    if (!writer->Commit(replace, error)) return false;
  }
  return true;
}

namespace {

// std::cout's buffer (InstallCheckedStdout): file descriptor 1 through write(2), each
// write checked, the first error kept.
class CheckedStdout : public std::streambuf {
 public:
  CheckedStdout() { setp(buffer_, buffer_ + sizeof(buffer_)); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!Drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (n <= epptr() - pptr()) {
      std::memcpy(pptr(), s, static_cast<size_t>(n));
      pbump(static_cast<int>(n));
      return n;
    }
    return Drain() && Write(s, static_cast<size_t>(n)) ? n : 0;
  }
  int sync() override { return Drain() ? 0 : -1; }

 private:
  bool Drain() {
    const bool ok = Write(pbase(), static_cast<size_t>(pptr() - pbase()));
    setp(buffer_, buffer_ + sizeof(buffer_));
    return ok;
  }
  bool Write(const char* data, size_t size) {
    while (error_ == 0 && size > 0) {
      const ssize_t n = ::write(STDOUT_FILENO, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        error_ = n < 0 ? errno : EIO;
        break;
      }
      data += n;
      size -= static_cast<size_t>(n);
    }
    return error_ == 0;
  }

  char buffer_[1 << 16];
  int error_ = 0;
};

// Never destroyed: std::cout is flushed by the library's own static destructors after
// ours have run (libstdc++'s ios_base::Init in a shared library), and must still have a
// buffer then (ASan found the destroyed one).
CheckedStdout& StdoutBuffer() {
  static CheckedStdout* const buffer = new CheckedStdout;
  return *buffer;
}

}  // namespace

void InstallCheckedStdout() { std::cout.rdbuf(&StdoutBuffer()); }

int StdoutError() { return StdoutBuffer().error(); }

int FinishStandardOutput(const std::string& command, int exit_code) {
  std::cout.flush();
  int why = StdoutError();
  if (why == 0 && !std::cout.good()) why = EIO;
  // Closing reports what a network file system defers to close; nothing writes after it.
  if (why == 0 && ::close(STDOUT_FILENO) != 0 && errno != EBADF) why = errno;
  if (why == 0) return exit_code;
  PrintError(command, std::string("cannot write to standard output: ") + std::strerror(why) +
                          " (what it received is incomplete)");
  return exit_code != 0 ? exit_code : kExitFailure;
}

void PrintError(const std::string& command, const std::string& message) {
  std::cerr << "fastcal " << command << ": " << message << std::endl;
}

std::string CommandLine(int argc, char** argv, const std::vector<std::string>& omit) {
  std::string s = "fastcal";
  for (int i = 1; i < argc; ++i) {
    std::string name = argv[i];
    name = name.substr(0, name.find('='));
    name.erase(0, name.find_first_not_of('-'));
    bool skip = false;
    for (const std::string& o : omit) skip = skip || name == o || name == "no" + o;
    if (!skip) s += std::string(" ") + argv[i];
  }
  return s;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::string FormatDouble(double value, int significant_digits) {
  if (value == 0.0) return "0";  // no "-0" in tables
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*g", significant_digits, value);
  return buf;
}

// Writes the given files into a fresh temporary sibling of `dir` (locked while this run
// writes it), syncs it, then publishes it as `dir` and syncs the parent; on any failure
// removes the temporary directory.
bool WriteDirectoryAtomically(const std::string& dir,
                              const std::vector<std::pair<std::string, std::string>>& files,
                              const std::function<bool(const std::string&, std::string*)>& extra,
                              const std::vector<std::string>* replaceable, std::string* error) {
  if (!CheckOutputDirectory("out", dir, error, replaceable)) return false;
  std::error_code ec;
  const std::filesystem::path target = ResolveOutputPath(dir);
  const std::filesystem::path parent =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::exists(parent, ec) && !std::filesystem::create_directories(parent, ec)) {
    *error = "--out=" + internal::Escape(dir) + ": cannot create its directory '" +
             internal::Escape(parent.string()) + "': " + ec.message();
    return false;
  }
  // What killed runs left beside it (their processes gone): removed, or put back.
  internal::RemoveStaleTemporaries(target.string());
  const std::filesystem::path tmp =
      parent / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()));
  std::filesystem::remove_all(tmp, ec);
  // Failures name the user's --out, not the temporary sibling.
  const std::string where = "--out=" + internal::Escape(dir) + ": ";
  if (!std::filesystem::create_directory(tmp, ec)) {
    *error =
        where + "cannot create the temporary directory '" + tmp.string() + "': " + ec.message();
    return false;
  }
  internal::TemporaryLock lock;
  lock.Lock(tmp.string());
  // Ctrl-C or SIGTERM while the files are written: the handler removes the staging
  // directory with what it holds (issue 37), not only the temporaries it named.
  internal::RegisterTemporaryDirectory(tmp.string());
  auto fail = [&](std::string why) {
    lock.Release();
    std::filesystem::remove_all(tmp, ec);
    for (size_t at = why.find(tmp.string()); at != std::string::npos;
         at = why.find(tmp.string(), at + dir.size())) {
      why.replace(at, tmp.string().size(), dir);
    }
    *error = why.rfind("--out=", 0) == 0 ? why : where + why;
    return false;
  };
  for (const auto& [name, content] : files) {
    std::string why;
    if (!WriteOutput((tmp / name).string(), content, &why)) return fail(why);
  }
  std::string why;
  if (extra && !extra(tmp.string(), &why)) return fail(why);
  int err = 0;
  if (!internal::SyncDirectory(tmp.string(), &err)) {
    return fail(std::string("cannot write: ") + std::strerror(err));
  }
  // --force: what is there at the moment of replacing must still be a previous run's
  // results only.
  std::function<bool(std::string*)> may_replace;
  if (replaceable != nullptr) {
    may_replace = [&](std::string* w) { return CheckOutputDirectory("out", dir, w, replaceable); };
  }
  if (!internal::PublishDirectory(tmp.string(), target.string(), may_replace, &why)) {
    return fail(why);
  }
  // The new name is durable only once the directory holding it is synced.
  if (!internal::SyncDirectory(parent.string(), &err)) {
    *error = where + "written, but its directory cannot be synced: " + std::strerror(err);
    return false;
  }
  return true;
}

bool CheckRecordOutputs(const std::string& name, const std::string& path, std::string* error) {
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  if (FLAGS_force && !to_file && path.empty()) {
    *error = "--force applies to --output=FILE or --" + name + "=FILE";
    return false;
  }
  if (path == "-") {
    *error = "--" + name + "=-: only the record goes to stdout; give this file a name";
    return false;
  }
  if (to_file && !path.empty() && ResolveOutputPath(FLAGS_output) == ResolveOutputPath(path)) {
    *error = "--output and --" + name + " name the same file; give two names";
    return false;
  }
  return (!to_file || CheckCanWrite("output", FLAGS_output, FLAGS_force, error)) &&
         (path.empty() || CheckCanWrite(name, path, FLAGS_force, error));
}

bool WriteRecordOutputs(const std::string& record, const std::string& path,
                        const std::string& content, std::string* error) {
  const bool to_file = !FLAGS_output.empty() && FLAGS_output != "-";
  std::vector<std::pair<std::string, std::string>> files;
  if (to_file) files.push_back({FLAGS_output, record});
  if (!path.empty()) files.push_back({path, content});
  return WriteOutputsTogether(files, FLAGS_force, error) &&
         (to_file || WriteOutput("-", record, error));
}

std::string Wrapped(const std::string& text, const std::string& first_indent,
                    const std::string& indent, size_t max_lines, const std::string& full_text_in) {
  std::istringstream words(text);
  std::vector<std::string> lines = {first_indent};
  std::string word;
  while (words >> word) {
    std::string& line = lines.back();
    const bool starts = line.size() == (lines.size() == 1 ? first_indent : indent).size();
    if (!starts && line.size() + 1 + word.size() > kConsoleWidth) {
      lines.push_back(indent + word);
    } else {
      line += (starts ? "" : " ") + word;
    }
  }
  const std::string cut = " ... (" + full_text_in + ")";
  if (lines.size() > max_lines) {
    lines.resize(max_lines);
    std::string& last = lines.back();
    // Whole words dropped until the mark fits: a number cut in the middle would misread.
    while (last.size() + cut.size() > kConsoleWidth) {
      const size_t space = last.find_last_of(' ');
      if (space == std::string::npos || space <= indent.size()) {
        last.resize(kConsoleWidth - cut.size());
        break;
      }
      last.resize(space);
    }
    last += cut;
  }
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

bool ParseNumberList(const std::string& flag, const std::string& text, std::vector<double>* values,
                     std::string* error) {
  values->clear();
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    double v = 0.0;
    std::string why;
    if (!ParseNumberItem(item, &v, &why)) {
      *error = "--" + flag + ": " + why;
      return false;
    }
    values->push_back(v);
  }
  if (!text.empty() && text.back() == ',') {
    *error = "--" + flag + ": an empty value after the last comma";
    return false;
  }
  return true;
}

bool MassCentreAtJointsFlag(const std::string& text, CableRobot* robot, std::string* error,
                            JointValues* joints_out) {
  const MovingParts& parts = robot->moving_parts;
  if (text.empty()) return true;
  std::string names;
  for (const std::string& c : parts.JointColumns()) names += (names.empty() ? "" : ",") + c;
  if (parts.empty()) {
    *error = "--joints: the model has no moving parts (cabin.moving_parts, --model=MODEL.yaml)";
    return false;
  }
  std::vector<double> values;
  if (!ParseNumberList("joints", text, &values, error)) return false;
  if (values.size() != static_cast<size_t>(parts.num_joints())) {
    *error = "--joints needs " + std::to_string(parts.num_joints()) + " values (" + names +
             "), got " + internal::Quote(text);
    return false;
  }
  JointValues joints{};
  const auto all = parts.Joints();
  for (size_t j = 0; j < values.size(); ++j) {
    const Joint& joint = *all[j].second;
    std::string why;
    if (!CheckJointValue(joint, values[j], &why)) {
      *error = "--joints: " + joint.column + ": " + why;
      return false;
    }
    joints[j] = values[j];
  }
  robot->mass_centre_cabin_m = robot->MassCentreAt(joints);
  robot->moving_parts.parts.clear();
  // Its part is gone with the parts: the caller converts poses with the model as loaded.
  robot->measured_frame.reset();
  if (joints_out != nullptr) *joints_out = joints;
  return true;
}

}  // namespace fastcal::cli
