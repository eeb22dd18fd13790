// End-to-end tests of the fastcal command line as a user runs it: exit codes, messages
// that name the file, line, column or flag, no output left behind on failure, and the
// calibrate -> evaluate round trip. The binary comes from $FASTCAL_BIN (set by CTest).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int code = -1;
  std::string output;  // stdout and stderr
};

std::string Bin() {
  const char* bin = (std::getenv("FASTCAL_BIN") ? std::getenv("FASTCAL_BIN") : FASTCAL_TEST_BIN);
  return bin ? bin : "";
}
std::string Source() {
  const char* dir = (std::getenv("FASTCAL_SOURCE_DIR") ? std::getenv("FASTCAL_SOURCE_DIR")
                                                       : FASTCAL_TEST_SOURCE_DIR);
  return dir ? dir : "";
}

CommandResult Fastcal(const std::string& args) {
  CommandResult r;
  const std::string command = Bin() + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) r.output.append(buf, n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (Bin().empty() || Source().empty()) GTEST_SKIP() << "FASTCAL_BIN / FASTCAL_SOURCE_DIR unset";
    dir_ = fs::path(::testing::TempDir()) /
           ("fastcal_cli_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
  }
  fs::path dir_;
};

TEST_F(CliTest, SolveK1CompareMatchesPaper) {
  const CommandResult r = Fastcal("solve --position=0,0,140 --method=compare");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("T1_aas_kN"), std::string::npos);
  EXPECT_NE(r.output.find("158.98"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("159.167"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("-0.117"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("us/pose"), std::string::npos);
}

TEST_F(CliTest, SolveJsonAndTrajectoryToFile) {
  const std::string out = Path("arc.json");
  const CommandResult r = Fastcal(
      "solve --trajectory=arc --attitude-law=focal --method=exact --format=json --output=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("\"lower_tension_kN\""), std::string::npos);
  EXPECT_EQ(text.str().find("nan"), std::string::npos);
}

TEST_F(CliTest, SolveBadInputExitsNonZeroAndNamesTheProblem) {
  CommandResult r = Fastcal("solve --positon=0,0,140");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("unknown flag --positon"), std::string::npos) << r.output;
  r = Fastcal("solve --position=0,nan,140");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--position"), std::string::npos) << r.output;
  r = Fastcal("solve --position=0,0,140 --method=fast");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--method"), std::string::npos) << r.output;
  r = Fastcal("solve --position=0,0,140 --quat=1,1,0,0");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("unit"), std::string::npos) << r.output;
  // A pose the cables cannot hold: exit 1, the cable named, no output file.
  const std::string out = Path("never.csv");
  r = Fastcal("solve --position=330,0,150 --output=" + out);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("slack"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // Malformed model YAML: file and line named.
  Write("bad.yaml", "cabin:\n  mass_kg: heavy\n");
  r = Fastcal("solve --position=0,0,140 --model=" + Path("bad.yaml"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("bad.yaml:2"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cabin.mass_kg"), std::string::npos) << r.output;
  r = Fastcal("solve --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.output.find("--attitude-law"), std::string::npos);
  r = Fastcal("frobnicate");
  EXPECT_EQ(r.code, 2);
}

// Simulate a small circle, calibrate it, and check the calibrated model reproduces the
// reported RMS through evaluate.
TEST_F(CliTest, SimulateCalibrateEvaluateRoundTrip) {
  const std::string data = Path("circle.csv");
  CommandResult r =
      Fastcal("simulate --mass-centre=0.22,0.11,0.5 --nodes=48 --seed=3 --out=" + data);
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_TRUE(fs::exists(data));
  ASSERT_TRUE(fs::exists(Path("circle.truth.yaml")));
  const std::string out = Path("cal");
  r = Fastcal("calibrate --quiet --spec=" + Source() +
              "/calibration_data/spec_mass_centre_density.yaml --data=" + data + " --out=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* f :
       {"model_calibrated.yaml", "report.html", "report.md", "summary.json", "residuals.csv"}) {
    EXPECT_TRUE(fs::exists(fs::path(out) / f)) << f;
  }
  const std::regex row("calibrated model, measured attitude\\s+([0-9. ]+)");
  std::smatch cal;
  ASSERT_TRUE(std::regex_search(r.output, cal, row)) << r.output;
  const std::string calibrated_rms = cal[1].str();
  r = Fastcal("evaluate --model=" + out + "/model_calibrated.yaml --data=" + data);
  ASSERT_EQ(r.code, 0) << r.output;
  const std::regex eval_row("model, measured attitude\\s+([0-9. ]+)");
  std::smatch ev;
  ASSERT_TRUE(std::regex_search(r.output, ev, eval_row)) << r.output;
  EXPECT_EQ(std::regex_replace(calibrated_rms, std::regex("\\s+"), " "),
            std::regex_replace(ev[1].str(), std::regex("\\s+"), " "));
  // The output directory is not overwritten.
  r = Fastcal("calibrate --quiet --spec=" + Source() +
              "/calibration_data/spec_mass_centre_density.yaml --data=" + data + " --out=" + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("not an empty directory"), std::string::npos) << r.output;
}

TEST_F(CliTest, CalibrateBadInputLeavesNoOutput) {
  const std::string spec = Source() + "/calibration_data/spec_mass_centre_density.yaml";
  const std::string out = Path("never");
  // Text in a number: file, line and column named.
  Write("bad.csv",
        "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n"
        "0,0,0,150,0,0,0,150,150,150,150,150,150\n"
        "1,0,0,150,0,0,0,150,150,abc,150,150,150\n");
  CommandResult r =
      Fastcal("calibrate --spec=" + spec + " --data=" + Path("bad.csv") + " --out=" + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("bad.csv:3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("T3_kN"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // A missing tension column.
  Write("short.csv",
        "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN\n");
  r = Fastcal("calibrate --spec=" + spec + " --data=" + Path("short.csv") + " --out=" + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("T6_kN"), std::string::npos) << r.output;
  // NaN.
  Write("nan.csv",
        "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n"
        "0,0,0,150,0,0,nan,150,150,150,150,150,150\n");
  r = Fastcal("calibrate --spec=" + spec + " --data=" + Path("nan.csv") + " --out=" + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("yaw_deg"), std::string::npos) << r.output;
  // Unknown parameter name in the spec.
  Write("spec.yaml", "parameters:\n  mass_center_m:\n    x: {free: true}\n");
  const std::string data = Source() + "/calibration_data/circle_paper.csv";
  r = Fastcal("calibrate --spec=" + Path("spec.yaml") + " --data=" + data + " --out=" + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("spec.yaml:2"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("mass_center_m"), std::string::npos) << r.output;
  // A free set the data cannot determine: refused before solving, exit 1.
  Write("degenerate.yaml",
        "parameters:\n  cabin_mass_kg: {free: true}\n  linear_density_kg_per_m: {free: true}\n"
        "  ea_n: {free: true}\n  sensor_gain: {free: true}\n");
  r = Fastcal("calibrate --spec=" + Path("degenerate.yaml") + " --data=" + data + " --out=" + out);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("cannot determine"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("sensor_gain"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // Nothing else was left next to it either (no temporary directory).
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir_))
    entries += e.path().filename().string()[0] == '.';
  EXPECT_EQ(entries, 0);
}

}  // namespace
