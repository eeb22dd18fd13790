// The fuzz targets (tests/fuzz/fuzz_targets.h) replayed on every file of their seed corpus
// and of their regression folder, in the normal test suite: tests/fuzz/regressions/ keeps
// each input that ever hung or crashed a reader, so a reader that regresses fails here,
// without clang or libFuzzer. Each test limits its own process in time and (without a
// sanitizer) in memory, so that a hang fails within seconds instead of eating the machine.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "bounded_process.h"
#include "fuzz/fuzz_targets.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

using Target = void (*)(const uint8_t*, size_t);

// Every file under tests/fuzz/<kind>/<target>/, sorted.
std::vector<fs::path> Inputs(const std::string& target) {
  std::vector<fs::path> files;
  for (const char* kind : {"corpus", "regressions"}) {
    const fs::path dir = fs::path(FASTCAL_TEST_SOURCE_DIR) / "tests" / "fuzz" / kind / target;
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.is_regular_file()) files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

void Replay(const std::string& target, Target run, size_t min_files) {
  test::LimitThisProcess();
  const std::vector<fs::path> files = Inputs(target);
  EXPECT_GE(files.size(), min_files) << "the corpus of " << target << " is missing";
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());  // aborts on a violation
  }
}

// Seeds (the bundled data and the tests' files) and regressions per target; a few of each
// at least, so that an emptied folder does not pass unnoticed.
constexpr size_t kMinFiles = 3;

TEST(FuzzRegressionTest, DatasetCsv) { Replay("dataset_csv", fuzz::DatasetCsv, kMinFiles); }
TEST(FuzzRegressionTest, PoseCsv) { Replay("pose_csv", fuzz::PoseCsv, kMinFiles); }
TEST(FuzzRegressionTest, ModelYaml) { Replay("model_yaml", fuzz::ModelYaml, kMinFiles); }
TEST(FuzzRegressionTest, SpecYaml) { Replay("spec_yaml", fuzz::SpecYaml, kMinFiles); }
TEST(FuzzRegressionTest, WindowFold) { Replay("window_fold", fuzz::WindowFoldBytes, kMinFiles); }
TEST(FuzzRegressionTest, TrackState) { Replay("track_state", fuzz::TrackStateJson, kMinFiles); }
TEST(FuzzRegressionTest, VibrationRecord) {
  Replay("vibration_record", fuzz::VibrationRecordCsv, kMinFiles);
}

}  // namespace
}  // namespace fastcal
