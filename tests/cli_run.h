// Running the fastcal command line from an end-to-end test: the binary from $FASTCAL_BIN
// (set by CTest) or the build's, the sources from $FASTCAL_SOURCE_DIR, a command's exit
// code and its output (stdout and stderr together).
#ifndef FASTCAL_TESTS_CLI_RUN_H_
#define FASTCAL_TESTS_CLI_RUN_H_

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace fastcal::testing {

struct CommandResult {
  int code = -1;
  std::string output;  // stdout and stderr
};

inline std::string Bin() {
  const char* bin = std::getenv("FASTCAL_BIN") ? std::getenv("FASTCAL_BIN") : FASTCAL_TEST_BIN;
  return bin ? bin : "";
}

inline std::string Source() {
  const char* dir = std::getenv("FASTCAL_SOURCE_DIR") ? std::getenv("FASTCAL_SOURCE_DIR")
                                                      : FASTCAL_TEST_SOURCE_DIR;
  return dir ? dir : "";
}

inline CommandResult Shell(const std::string& command_line) {
  CommandResult r;
  FILE* pipe = popen((command_line + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) r.output.append(buf, n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CommandResult Fastcal(const std::string& args) { return Shell(Bin() + " " + args); }

inline std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace fastcal::testing

#endif  // FASTCAL_TESTS_CLI_RUN_H_
