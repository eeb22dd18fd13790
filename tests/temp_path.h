// Temporary paths of a test that stay apart from every other test process's: ctest runs
// a fixture's tests as parallel processes, and two checkouts' suites may run at once on
// one machine (a fixed name let one process remove the directory another was writing).
#ifndef FASTCAL_TESTS_TEMP_PATH_H_
#define FASTCAL_TESTS_TEMP_PATH_H_

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

namespace fastcal::test {

// TempDir() + name + "_" + the process id (+ extension, e.g. ".csv").
inline std::string TempPath(const std::string& name, const std::string& extension = "") {
  std::string dir = ::testing::TempDir();
  if (!dir.empty() && dir.back() != '/') dir += '/';
  return dir + name + "_" + std::to_string(::getpid()) + extension;
}

}  // namespace fastcal::test

#endif  // FASTCAL_TESTS_TEMP_PATH_H_
