// The signal handler's clean-up (internal/atomic_file.h, issue 37): what it removes with
// system calls only, so that Ctrl-C in the middle of writing leaves nothing half-written.
#include "fastcal/internal/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fastcal::internal {
namespace {

namespace fs = std::filesystem;

std::string Scratch(const std::string& name) {
  const std::string dir =
      ::testing::TempDir() + "/atomic_file_test_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicFileTest, SignalCleanUpRemovesTemporariesAndStagingDirectories) {
  const std::string dir = Scratch("signal");
  // A staging directory being filled: many files (more than one getdents buffer's worth),
  // one of them half-written, and an empty subdirectory.
  const std::string staging = dir + "/.out.tmp." + std::to_string(::getpid());
  fs::create_directories(staging + "/empty");
  constexpr int kFiles = 600;
  for (int k = 0; k < kFiles; ++k) {
    std::ofstream(staging + "/file_with_a_long_name_" + std::to_string(k) + ".csv") << "x";
  }
  std::ofstream(staging + "/residuals.csv") << "time_s,cable,half a ro";
  // A new track's staging directory: its stores in subdirectories, two levels down too.
  fs::create_directories(staging + "/windows/deeper");
  std::ofstream(staging + "/windows/2024-05-01.samples") << "records";
  std::ofstream(staging + "/windows/deeper/x") << "x";
  RegisterTemporaryDirectory(staging);
  // A temporary file named for a result, and a result already published (kept).
  const std::string temporary = TemporaryNameFor(dir + "/data.csv");
  std::ofstream(temporary) << "partial";
  std::ofstream(dir + "/published.csv") << "done";

  RemoveTemporariesOnSignal();
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(temporary));
  EXPECT_TRUE(fs::exists(dir + "/published.csv"));
  // Registered directories that no longer exist (published meanwhile) are no error.
  RemoveTemporariesOnSignal();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fastcal::internal
