// Temporary paths of a test that stay apart from every other test process's: ctest runs
// a fixture's tests as parallel processes, and two checkouts' suites may run at once on
// one machine (a fixed name let one process remove the directory another was writing).
#ifndef FASTCAL_TESTS_TEMP_PATH_H_
#define FASTCAL_TESTS_TEMP_PATH_H_

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>

namespace fastcal::test {

// The paths handed out, removed (files or whole directories) when the test program
// exits, whether its tests passed or not: the suite left ~6 MB a run in /tmp (a track
// test's season). FASTCAL_KEEP_TEST_FILES=1 keeps them for a look. Only by the process
// that handed them out: a death test's child exits too.
class TempPaths {
 public:
  static TempPaths& Get() {
    static TempPaths paths;
    return paths;
  }
  void Add(const std::string& path) {
    std::lock_guard<std::mutex> lock(mutex_);
    paths_.insert(path);
  }
  ~TempPaths() {
    if (std::getenv("FASTCAL_KEEP_TEST_FILES") != nullptr || ::getpid() != owner_) return;
    for (const std::string& p : paths_) {
      std::error_code ec;
      std::filesystem::remove_all(p, ec);
    }
  }

 private:
  std::mutex mutex_;
  std::set<std::string> paths_;
  pid_t owner_ = ::getpid();
};

// TempDir() + name + "_" + the process id (+ extension, e.g. ".csv"); removed at exit.
inline std::string TempPath(const std::string& name, const std::string& extension = "") {
  std::string dir = ::testing::TempDir();
  if (!dir.empty() && dir.back() != '/') dir += '/';
  const std::string path = dir + name + "_" + std::to_string(::getpid()) + extension;
  TempPaths::Get().Add(path);
  return path;
}

}  // namespace fastcal::test

#endif  // FASTCAL_TESTS_TEMP_PATH_H_
