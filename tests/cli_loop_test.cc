// End-to-end tests of `fastcal loop` (apps/loop_command.cc): a controller's model with its
// mass centre 5 cm off, feed-forward alone, leaves the cabin ~11 mm off (the record and
// the summary agree), the PID takes it away; bad flags named with exit 2, nothing
// written by a failed run.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

// The nominal model with its mass centre moved by dx in the cabin's x, written to `path`.
std::string ShiftedModel(const std::string& path, double dx) {
  std::ifstream in(Source() + "/calibration_data/nominal_fast.yaml");
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  const std::string key = "mass_centre_m: [";
  const size_t at = text.find(key);
  EXPECT_NE(at, std::string::npos);
  const size_t comma = text.find(',', at);
  const double x = std::stod(text.substr(at + key.size(), comma - at - key.size()));
  text.replace(at + key.size(), comma - at - key.size(), std::to_string(x + dx));
  std::ofstream(path) << text;
  return path;
}

TEST_F(CliTest, LoopFeedForwardLeavesTheModelsErrorAndThePidTakesIt) {
  CommandResult r = Fastcal("loop --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.output.find("--controller-model"), std::string::npos);
  const std::string off = ShiftedModel(Path("off.yaml"), 0.05);
  const std::string base = "loop --truth=" + Source() +
                           "/calibration_data/nominal_fast.yaml --controller-model=" + off +
                           " --position=54.72,0,149.65 --attitude-law=focal --segments=16 ";
  const std::string csv = Path("ff.csv"), json = Path("ff.json");
  r = Fastcal(base + "--hold-s=10 --pid=0,0,0 --output=" + csv + " --summary=" + json);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("cabin - command"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("efficiency lost at 3 GHz"), std::string::npos) << r.output;
  std::istringstream lines(ReadFile(csv));
  std::string line;
  std::getline(lines, line);
  const std::vector<std::string> header = CsvFields(line);
  ASSERT_EQ(header.size(), 31u) << line;
  EXPECT_EQ(header[10], "error_mm");
  int rows = 0;
  std::vector<std::string> last;
  while (std::getline(lines, line)) {
    last = CsvFields(line);
    ++rows;
  }
  EXPECT_EQ(rows, 101);  // 10 s at 10 Hz, both ends
  // The 5 cm mass centre costs about 11 mm here (the statics' answer: closed_loop_test).
  const double error_mm = std::stod(last[10]);
  EXPECT_GT(error_mm, 8.0);
  EXPECT_LT(error_mm, 16.0);
  const std::string summary = ReadFile(json);
  EXPECT_NE(summary.find("\"format\": \"fastcal-loop-1\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"error_rms_mm\""), std::string::npos);
  // With the PID for three minutes, the last minute's error is under a millimetre.
  r = Fastcal(base + "--hold-s=180 --summary-from-s=120 --summary=" + Path("pid.json"));
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string pid = ReadFile(Path("pid.json"));
  const size_t at = pid.find("\"error_rms_mm\": ");
  ASSERT_NE(at, std::string::npos) << pid;
  EXPECT_LT(std::stod(pid.substr(at + 16)), 1.0) << pid;
}

// A path: solve's line at --path-speed, eased in and out, the record's command moving
// along it.
TEST_F(CliTest, LoopFollowsATrajectory) {
  const std::string csv = Path("line.csv");
  const CommandResult r =
      Fastcal("loop --truth=" + Source() +
              "/calibration_data/nominal_fast.yaml --trajectory=line --from=0,0,140 --to=1,0,140 "
              "--nodes=11 --path-speed=0.05 --path-ramp-s=5 --hold-s=2 --segments=8 --output=" +
              csv);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("a path of 11 nodes in 20 s"), std::string::npos) << r.output;
  std::istringstream lines(ReadFile(csv));
  std::string line;
  std::getline(lines, line);
  std::vector<std::string> first, last;
  int rows = 0;
  while (std::getline(lines, line)) {
    last = CsvFields(line);
    if (rows++ == 0) first = last;
  }
  EXPECT_EQ(rows, 271);             // 20 s + 5 s of easing + 2 s held, at 10 Hz
  EXPECT_EQ(first[4], "0.000000");  // x_cmd_m at the line's start
  EXPECT_EQ(last[4], "1.000000");   // and at its end
}

TEST_F(CliTest, LoopBadFlagsAreNamed) {
  const std::string truth = "--truth=" + Source() + "/calibration_data/nominal_fast.yaml ";
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"loop --position=0,0,140", "--truth=MODEL.yaml is required"},
      {"loop " + truth + "--position=0,0,140 --pid=1,2", "--pid=1,2: give KP,KI,KD"},
      {"loop " + truth + "--position=0,0,140 --move-s=3", "--move-s applies to --to"},
      {"loop " + truth + "--position=0,0,140 --control-period-s=0", "--control-period-s"},
      {"loop " + truth + "--position=0,0,140 --pid=-1,0,0", "--pid"},
      {"loop " + truth + "--position=0,0,140 --hold-s=0", "--hold-s"},
      {"loop " + truth + "--position=0,0,140 --frequency-ghz=0", "--frequency-ghz"},
      {"loop --truth=" + Path("missing.yaml") + " --position=0,0,140", "missing.yaml"},
      {"loop " + truth + "--trajectory=grid", "loop follows an arc, the circle or a line"},
      {"loop " + truth + "--trajectory=arc --position=0,0,140", "--position applies to a hold"},
      {"loop " + truth + "--trajectory=line --from=0,0,140 --to=1,0,140 --path-speed=0",
       "--path-speed"},
      {"loop " + truth + "--trajectory=line --from=0,0,140 --to=1,0,140 --path-ramp-s=1000",
       "--path-ramp-s"},
  };
  for (const Case& c : cases) {
    const CommandResult r = Fastcal(c.args + " --output=" + Path("x.csv"));
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(Path("x.csv"))) << c.args;
  }
}

}  // namespace
}  // namespace fastcal::test
