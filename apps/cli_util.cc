#include "cli_util.h"

#include <gflags/gflags.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

#include "fastcal/internal/atomic_file.h"

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

namespace {
bool ParseList(const std::string& name, const std::string& text, int n, double* out,
               std::string* error) {
  std::stringstream ss(text);
  std::string item;
  int count = 0;
  while (std::getline(ss, item, ',')) {
    if (count >= n) break;
    const char* begin = item.c_str();
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    while (end != nullptr && (*end == ' ' || *end == '\t')) ++end;
    if (end == begin || *end != '\0') {
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

void PrintError(const std::string& command, const std::string& message) {
  std::cerr << "fastcal " << command << ": " << message << std::endl;
}

std::string FormatDouble(double value, int significant_digits) {
  if (value == 0.0) return "0";  // no "-0" in tables
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*g", significant_digits, value);
  return buf;
}

}  // namespace fastcal::cli
