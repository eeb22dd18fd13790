// The fixture of the end-to-end CLI tests (cli_test.cc, cli_usability_test.cc,
// cli_faults_test.cc): the fastcal binary run through the shell, its exit code and output,
// and a temporary directory per test. The binary comes from $FASTCAL_BIN (set by CTest).
#ifndef FASTCAL_TESTS_CLI_FIXTURE_H_
#define FASTCAL_TESTS_CLI_FIXTURE_H_

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "bounded_process.h"

namespace fastcal::test {

namespace fs = std::filesystem;

struct CommandResult {
  int code = -1;
  std::string output;  // stdout and stderr
};

inline std::string Bin() {
  const char* bin = (std::getenv("FASTCAL_BIN") ? std::getenv("FASTCAL_BIN") : FASTCAL_TEST_BIN);
  return bin ? bin : "";
}
inline std::string Source() {
  const char* dir = (std::getenv("FASTCAL_SOURCE_DIR") ? std::getenv("FASTCAL_SOURCE_DIR")
                                                       : FASTCAL_TEST_SOURCE_DIR);
  return dir ? dir : "";
}

inline CommandResult Shell(const std::string& command_line) {
  CommandResult r;
  const std::string command = command_line + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) r.output.append(buf, n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CommandResult Fastcal(const std::string& args) { return Shell(Bin() + " " + args); }

inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Splits one CSV line into fields as RFC 4180 readers do (pandas, Python's csv): a field in
// double quotes may hold commas, and "" inside it is one quote.
inline std::vector<std::string> CsvFields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t k = 0; k < line.size(); ++k) {
    const char c = line[k];
    if (quoted && c == '"' && k + 1 < line.size() && line[k + 1] == '"') {
      fields.back() += '"';
      ++k;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

// The estimate and sigma_total of parameter `name` in calibrate's console table
// ("  NAME   value +- sigma unit").
inline void ConsoleEstimate(const std::string& output, const std::string& name, double* value,
                            double* sigma) {
  const std::regex row("\n  " + std::regex_replace(name, std::regex(R"([.\[\]])"), R"(\$&)") +
                       R"( +(\S+) \+- (\S+))");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(output, m, row)) << name << "\n" << output;
  *value = std::stod(m[1]);
  *sigma = std::stod(m[2]);
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (Bin().empty() || Source().empty()) GTEST_SKIP() << "FASTCAL_BIN / FASTCAL_SOURCE_DIR unset";
    // The process id keeps two suites run at once (two checkouts on one machine) apart.
    dir_ = fs::path(::testing::TempDir()) /
           ("fastcal_cli_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
  }
  // A command line, its exit code and a text its output must contain.
  struct ExpectedRun {
    std::string args;
    int code;
    std::string expected;
  };
  // Runs `fastcal c.args` bounded (a regression of a limit must fail, not exhaust the
  // machine: 60 s, and 4 GB of address space except under a sanitizer, which reserves
  // terabytes) and checks its exit code and output; returns the result for more checks.
  CommandResult RunBoundedAndExpect(const ExpectedRun& c) const {
    const std::string limit =
        std::string(kUnderSanitizer ? "" : "ulimit -v 4000000; ") + "timeout 60 ";
    const CommandResult r = Shell(limit + Bin() + " " + c.args);
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.output.substr(0, 2000);
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args << "\n"
                                                            << r.output.substr(0, 2000);
    return r;
  }
  fs::path dir_;
};

}  // namespace fastcal::test

#endif  // FASTCAL_TESTS_CLI_FIXTURE_H_
