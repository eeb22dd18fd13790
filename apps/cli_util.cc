#include "cli_util.h"

#include <gflags/gflags.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/number_text.h"

namespace fastcal::cli {

bool WantsHelp(int argc, char** argv, int first) {
  for (int i = first; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help" || a == "-help" || a == "--helpfull") return true;
  }
  return false;
}

bool CheckAndNormaliseFlags(int argc, char** argv, int first, const std::string& command,
                            const std::set<std::string>& allowed,
                            std::vector<std::string>* normalised, std::string* error) {
  normalised->assign(1, argv[0]);
  std::set<std::string> seen;
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.size() < 3 || arg[0] != '-') {
      *error = "unexpected argument '" + arg + "' (flags are --name=value; see fastcal " + command +
               " --help)";
      return false;
    }
    const size_t start = arg[1] == '-' ? 2 : 1;
    const size_t eq = arg.find('=');
    std::string name = arg.substr(start, eq == std::string::npos ? std::string::npos : eq - start);
    std::string bare = name;
    if (!allowed.count(bare) && bare.rfind("no", 0) == 0 && allowed.count(bare.substr(2))) {
      bare = bare.substr(2);  // gflags' --noflag form of a boolean
    }
    std::string underscored = name;
    for (char& c : underscored) {
      if (c == '-') c = '_';
    }
    if (!allowed.count(bare)) {
      *error = "unknown flag --" + name + " (see fastcal " + command + " --help)";
      return false;
    }
    if (!seen.insert(bare).second) {
      *error = "--" + bare + " given twice; give each flag once";
      return false;
    }
    // Check the value's type here: gflags would exit 1 with its own message.
    gflags::CommandLineFlagInfo info;
    if (eq != std::string::npos && gflags::GetCommandLineFlagInfo(underscored.c_str(), &info)) {
      const std::string value = arg.substr(eq + 1);
      const char* begin = value.c_str();
      char* end = nullptr;
      bool ok = true;
      if (info.type == "int32" || info.type == "int64") {
        std::strtoll(begin, &end, 10);
        ok = !value.empty() && *end == '\0';
      } else if (info.type == "uint32" || info.type == "uint64") {
        std::strtoull(begin, &end, 10);
        ok = !value.empty() && value[0] != '-' && *end == '\0';
      } else if (info.type == "double") {
        const double v = std::strtod(begin, &end);
        ok = !value.empty() && *end == '\0' && std::isfinite(v);
      } else if (info.type == "bool") {
        ok = value == "true" || value == "false" || value == "1" || value == "0";
      }
      if (!ok) {
        *error = "--" + name + ": '" + value + "' is not a valid " +
                 (info.type == "bool"     ? std::string("true/false")
                  : info.type == "double" ? std::string("finite number")
                                          : std::string("whole number")) +
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
  std::vector<std::string> args;
  std::string error;
  if (!CheckAndNormaliseFlags(argc, argv, 2, command, allowed, &args, &error)) {
    PrintError(command, error);
    *exit_code = kExitUsage;
    return false;
  }
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

bool CheckCanWrite(const std::string& path, bool force, std::string* error) {
  if (path.empty() || path == "-") return true;
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::is_directory(status)) {
    *error = path + ": is a directory (give a file name)";
    return false;
  }
  if (std::filesystem::exists(status) && !force) {
    *error = path + ": exists; not overwritten (add --force to replace it, or choose another name)";
    return false;
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec)) {
    *error = path + ": cannot write: directory '" + parent.string() + "' does not exist";
    return false;
  }
  return true;
}

bool CheckOutputDirectory(const std::string& dir, std::string* error) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(dir, ec);
  if (!std::filesystem::exists(status)) return true;
  if (!std::filesystem::is_directory(status)) {
    *error = dir + ": is a file, not a directory (--out names a new or empty directory)";
    return false;
  }
  if (!std::filesystem::is_empty(dir, ec)) {
    *error = dir + ": exists and is not an empty directory (choose a new --out)";
    return false;
  }
  return true;
}

bool ParseNumberItem(const std::string& item, double* value) {
  const size_t begin = item.find_first_not_of(" \t");
  if (begin == std::string::npos) return false;
  const size_t end = item.find_last_not_of(" \t");
  return internal::ParseDouble(std::string_view(item).substr(begin, end + 1 - begin), value);
}

namespace {
bool ParseList(const std::string& name, const std::string& text, int n, double* out,
               std::string* error) {
  std::stringstream ss(text);
  std::string item;
  int count = 0;
  while (std::getline(ss, item, ',')) {
    if (count >= n) break;
    double v = 0.0;
    if (!ParseNumberItem(item, &v)) {
      *error = "--" + name + ": '" + item + "' is not a number";
      return false;
    }
    if (!std::isfinite(v)) {
      *error = "--" + name + ": '" + item + "' is not finite";
      return false;
    }
    out[count++] = v;
  }
  if (count != n || ss.rdbuf()->in_avail() > 0 || (!text.empty() && text.back() == ',')) {
    *error = "--" + name + " needs " + std::to_string(n) + " comma-separated numbers, got '" +
             text + "'";
    return false;
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

bool WriteOutput(const std::string& path, const std::string& content, std::string* error) {
  if (path.empty() || path == "-") {
    std::cout << content << std::flush;
    return true;
  }
  return internal::WriteFileAtomically(path, content, error);
}

bool WriteOutputsTogether(const std::vector<std::pair<std::string, std::string>>& files,
                          std::string* error) {
  const std::string suffix = ".tmp." + std::to_string(::getpid());
  std::vector<std::string> written;
  auto undo = [&written] {
    for (const std::string& path : written) std::remove(path.c_str());
  };
  for (const auto& [path, content] : files) {
    if (!internal::WriteFileAtomically(path + suffix, content, error)) {
      undo();
      return false;
    }
    written.push_back(path + suffix);
  }
  for (const auto& [path, content] : files) {
    if (std::rename((path + suffix).c_str(), path.c_str()) != 0) {
      undo();
      *error = path + ": cannot rename the temporary file into place";
      return false;
    }
  }
  return true;
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

std::string FormatDouble(double value, int significant_digits) {
  if (value == 0.0) return "0";  // no "-0" in tables
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*g", significant_digits, value);
  return buf;
}

}  // namespace fastcal::cli
