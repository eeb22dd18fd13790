// End-to-end tests of `fastcal modes` (apps/modes_command.cc): the CSV and its summary,
// atomic output and --force, and bad input named by its flag with exit 2 (no output) or a
// pose without equilibrium with exit 1.
#include <algorithm>
#include <string>
#include <vector>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

// The zenith's modes: the 20 lowest, ascending, each row's shares summing to 1; the
// lowest at ~0.155 Hz, a cable-and-cabin sway pair (docs/model.md, "Vibrations").
TEST_F(CliTest, ModesWritesAscendingModesWithSharesSummingToOne) {
  CommandResult r = Fastcal("modes --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.output.find("--segments"), std::string::npos);
  const std::string csv = Path("modes.csv");
  const std::string args = "modes --position=0,0,140 --segments=16 --output=" + csv;
  r = Fastcal(args);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("20 lowest of 276 degrees of freedom"), std::string::npos) << r.output;
  std::istringstream lines(ReadFile(csv));
  std::string line;
  std::getline(lines, line);
  const std::vector<std::string> header = CsvFields(line);
  ASSERT_EQ(header.size(), 13u) << line;
  EXPECT_EQ(header[1], "frequency_hz");
  double previous_hz = 0.0;
  int rows = 0;
  while (std::getline(lines, line)) {
    const std::vector<std::string> f = CsvFields(line);
    ASSERT_EQ(f.size(), 13u) << line;
    const double hz = std::stod(f[1]);
    EXPECT_GE(hz, previous_hz) << line;
    previous_hz = hz;
    double sum = 0.0;
    for (int k = 3; k <= 9; ++k) sum += std::stod(f[k]);
    EXPECT_NEAR(sum, 1.0, 1e-9) << line;
    EXPECT_TRUE(f[12] == "cabin" || f[12] == "cable") << line;
    if (++rows == 1) {
      EXPECT_NEAR(hz, 0.155, 0.005) << line;
    }
  }
  EXPECT_EQ(rows, 20);
  r = Fastcal(args);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(Fastcal(args + " --force --modes=5 --attitude-law=focal").code, 0);
}

// --cap: a CSV row per node and the HTML map, written together; flags of one pose refused.
TEST_F(CliTest, ModesCapWritesCsvAndMap) {
  const std::string csv = Path("cap.csv"), html = Path("cap.html");
  const std::string args =
      "modes --cap --max-off-axis-deg=20 --off-axis-step-deg=10 --azimuth-step-deg=90 "
      "--segments=12 --output=" +
      csv + " --html=" + html;
  CommandResult r = Fastcal(args);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("9 of 9 nodes with modes"), std::string::npos) << r.output;
  const std::string text = ReadFile(csv);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 10);
  EXPECT_NE(ReadFile(html).find("<svg"), std::string::npos);
  RunBoundedAndExpect({"modes --cap --position=0,0,140", 2, "--position is for one pose"});
  RunBoundedAndExpect({"modes --position=0,0,140 --html=" + Path("x.html"), 2, "--cap"});
  RunBoundedAndExpect({"modes --cap --off-axis-step-deg=0", 2, "--off-axis-step-deg"});
}

TEST_F(CliTest, ModesNamesBadInput) {
  const std::string out = " --output=" + Path("never.csv");
  const std::vector<ExpectedRun> runs = {
      {"modes" + out, 2, "--position"},
      {"modes --position=0,0,140 --segments=1" + out, 2, "--segments"},
      {"modes --position=0,0,140 --modes=0" + out, 2, "--modes"},
      {"modes --position=0,0,140 --rpy=0,0,0 --attitude-law=focal" + out, 2, "at most one"},
      {"modes --position=0,0,140 --segmnets=10" + out, 2, "--segments"},
      {"modes --position=0,0,140 --model=" + Path("missing.yaml") + out, 2, "missing.yaml"},
      {"modes --position=0,0,268" + out, 1, "no equilibrium"},
  };
  for (const ExpectedRun& run : runs) RunBoundedAndExpect(run);
  EXPECT_FALSE(fs::exists(Path("never.csv")));
}

}  // namespace
}  // namespace fastcal::test
