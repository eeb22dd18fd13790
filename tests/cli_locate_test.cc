// End-to-end tests of `fastcal locate` (the pose from six winch lengths) and of winch
// lengths as calibration data, run as a user runs them: round trips with solve and
// simulate, sigmas from a spec, and bad input named. The binary comes from $FASTCAL_BIN.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"

namespace {

namespace fs = std::filesystem;
using fastcal::test::Bin;
using fastcal::test::CliTest;
using fastcal::test::CommandResult;
using fastcal::test::CsvFields;
using fastcal::test::Fastcal;
using fastcal::test::ReadFile;
using fastcal::test::Shell;
using fastcal::test::Source;

// The rows of a CSV text (comment lines skipped) as maps from the header's names
// (CsvFields: messages in quotes keep their commas).
std::vector<std::map<std::string, std::string>> CsvRows(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty()) {
      header = CsvFields(line);
      continue;
    }
    const std::vector<std::string> fields = CsvFields(line);
    std::map<std::string, std::string> row;
    for (size_t k = 0; k < header.size() && k < fields.size(); ++k) row[header[k]] = fields[k];
    rows.push_back(row);
  }
  return rows;
}

// locate gives back the pose whose lengths solve printed (10 significant digits of the
// lengths: the pose to ~1e-6 m), stable and alone.
TEST_F(CliTest, LocateInvertsSolve) {
  constexpr double kPositionTolM = 1e-5;
  CommandResult r = Fastcal("solve --position=42.65,33.73,149.52 --attitude-law=focal --output=" +
                            Path("k2.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto solved = CsvRows(ReadFile(Path("k2.csv")));
  ASSERT_EQ(solved.size(), 1u);
  std::string lengths;
  for (int i = 1; i <= 6; ++i) {
    lengths += (i > 1 ? "," : "") + solved[0].at("s0_" + std::to_string(i) + "_m");
  }
  r = Fastcal("locate --lengths=" + lengths + " --output=" + Path("located.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("lengths alone"), std::string::npos) << r.output;
  const auto located = CsvRows(ReadFile(Path("located.csv")));
  ASSERT_EQ(located.size(), 1u);
  EXPECT_EQ(located[0].at("status"), "ok");
  EXPECT_EQ(located[0].at("stability"), "stable");
  EXPECT_EQ(located[0].at("other_equilibria"), "0");
  EXPECT_NEAR(std::stod(located[0].at("x_m")), 42.65, kPositionTolM);
  EXPECT_NEAR(std::stod(located[0].at("y_m")), 33.73, kPositionTolM);
  EXPECT_NEAR(std::stod(located[0].at("z_m")), 149.52, kPositionTolM);
  for (int i = 1; i <= 6; ++i) {
    const std::string t = "T" + std::to_string(i) + "_kN";
    EXPECT_NEAR(std::stod(located[0].at(t)), std::stod(solved[0].at(t)), 1e-4) << t;
  }
}

// solve's own output is a lengths file: its rows located back to their poses (the rows
// solve could not solve left out and counted, the lines named as the file's), gzipped
// too; and an export whose length channels have other names is read through --columns.
TEST_F(CliTest, LocateReadsSolvesOutputAndAnExportThroughAMap) {
  constexpr double kRoundTripM = 1e-6;  // the forward statics' tolerance is far below
  Write("p.csv", "x_m,y_m,z_m\n0,0,150\n200,0,150\n10,5,148\n");
  CommandResult r = Fastcal("solve --poses=" + Path("p.csv") + " --keep-going --output=" +
                            Path("solved.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_EQ(Shell("gzip -k " + Path("solved.csv")).code, 0);
  r = Fastcal("locate --use=lengths --data=" + Path("solved.csv.gz") + " --output=" +
              Path("back.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("1 of 3 rows of " + Path("solved.csv.gz") + " left out"),
            std::string::npos)
      << r.output;
  const auto back = CsvRows(ReadFile(Path("back.csv")));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].at("line"), "4");  // the file's own line, past the row left out
  EXPECT_NEAR(std::stod(back[1].at("x_m")), 10.0, kRoundTripM);
  EXPECT_NEAR(std::stod(back[1].at("z_m")), 148.0, kRoundTripM);
  // An export: the lengths as L1..L6 in mm, through a map.
  const auto rows = CsvRows(ReadFile(Path("solved.csv")));
  std::string text = "t;X;Y;Z;L1;L2;L3;L4;L5;L6\n0;10;5;148";
  for (int i = 1; i <= 6; ++i) {
    text += ";" + std::to_string(1e3 * std::stod(rows[2].at("s0_" + std::to_string(i) + "_m")));
  }
  Write("export.csv", text + "\n");
  std::string map = "format: fastcal-columns-1\ntime: {column: t}\ncolumns:\n"
                    "  x_m: X\n  y_m: Y\n  z_m: Z\n";
  for (int i = 1; i <= 6; ++i) {
    map += "  s0_" + std::to_string(i) + "_m: {column: L" + std::to_string(i) + ", unit: mm}\n";
  }
  Write("map.yaml", map);
  r = Fastcal("locate --data=" + Path("export.csv") + " --columns=" + Path("map.yaml") +
              " --output=" + Path("mapped.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto mapped = CsvRows(ReadFile(Path("mapped.csv")));
  ASSERT_EQ(mapped.size(), 1u);
  EXPECT_NEAR(std::stod(mapped[0].at("y_m")), 5.0, 1e-3);  // lengths written to 1 um
}

// A dataset of simulate (it has s0 columns) is a lengths file: each row located, its
// position compared with the file's in the summary; with the measured attitude and
// tensions the fit uses 15 readings, with --use=lengths 6.
TEST_F(CliTest, LocateReadsASimulatedSurvey) {
  const std::string data = Path("survey.csv");
  CommandResult r = Fastcal("simulate --trajectory=random --samples=12 --seed=5 --out=" + data);
  ASSERT_EQ(r.code, 0) << r.output;
  r = Fastcal("locate --search-radius-m=0 --data=" + data + " --output=" + Path("fit.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("lengths, attitude, tensions fitted together"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("against the file's x_m,y_m,z_m: RMS"), std::string::npos) << r.output;
  auto rows = CsvRows(ReadFile(Path("fit.csv")));
  ASSERT_EQ(rows.size(), 12u);
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("readings"), "15");
    EXPECT_FALSE(row.at("line").empty());
  }
  r = Fastcal("locate --use=lengths --search-radius-m=0 --data=" + data +
              " --output=" + Path("lengths.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  rows = CsvRows(ReadFile(Path("lengths.csv")));
  ASSERT_EQ(rows.size(), 12u);
  EXPECT_EQ(rows[0].at("readings"), "6");
  EXPECT_EQ(rows[0].at("chi2"), "0");
}

// simulate's length readings carry the encoders' offsets (written into the truth model)
// and noise: locate with the truth model finds the cabin within millimetres, with the
// nominal model (offsets unknown) decimetres off.
TEST_F(CliTest, SimulatedEncoderLengthsLocateWithTheirTruthModel) {
  const std::string data = Path("enc.csv");
  CommandResult r = Fastcal(
      "simulate --trajectory=random --samples=20 --seed=4 --length-offset-spread-m=0.3 "
      "--length-noise-m=0.002 --out=" +
      data);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("length-encoder offsets (m):"), std::string::npos) << r.output;
  EXPECT_NE(ReadFile(Path("enc.truth.yaml")).find("length_offset_m: "), std::string::npos);
  const auto rms_of = [](const std::string& output) {
    const std::smatch m = [&] {
      std::smatch found;
      std::regex_search(output, found, std::regex("RMS ([0-9.e+-]+) m"));
      return found;
    }();
    return m.empty() ? -1.0 : std::stod(m[1]);
  };
  r = Fastcal("locate --use=lengths --search-radius-m=0 --model=" + Path("enc.truth.yaml") +
              " --data=" + data + " --output=" + Path("a.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_LT(rms_of(r.output), 0.01) << r.output;
  EXPECT_GE(rms_of(r.output), 0.0) << r.output;
  r = Fastcal("locate --use=lengths --search-radius-m=0 --data=" + data +
              " --output=" + Path("b.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_GT(rms_of(r.output), 0.1) << r.output;
  RunBoundedAndExpect({"simulate --length-noise-m=-1 --out=" + Path("x.csv"), 2,
                       "--length-noise-m must be finite and >= 0"});
}

// The fit with attitude and tensions: lengths read through encoders whose offsets the
// nominal model does not know disagree with the tensions and attitude, on every row; the
// truth model's lengths agree with them. The summary counts the rows that disagree.
TEST_F(CliTest, LocateSaysWhenTheMeasurementsDisagree) {
  const std::string data = Path("enc.csv");
  CommandResult r = Fastcal(
      "simulate --trajectory=random --samples=20 --seed=4 --length-offset-spread-m=0.3 "
      "--length-noise-m=0.005 --out=" +
      data);
  ASSERT_EQ(r.code, 0) << r.output;
  r = Fastcal("locate --search-radius-m=0 --data=" + data + " --output=" + Path("nominal.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("20 whose measurements disagree; first: row 0"), std::string::npos)
      << r.output;
  for (const auto& row : CsvRows(ReadFile(Path("nominal.csv")))) {
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_NE(row.at("message").find("the measurements disagree: chi2 "), std::string::npos);
    EXPECT_NE(row.at("message").find("over 9 degrees of freedom"), std::string::npos);
  }
  r = Fastcal("locate --search-radius-m=0 --model=" + Path("enc.truth.yaml") + " --data=" + data +
              " --output=" + Path("truth.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("disagree"), std::string::npos) << r.output;
}

// A calibration with the winches' lengths from the command line (docs/calibration.md,
// "Lengths"): the console's length table before and after, summary.json's lengths; a
// dataset without the s0 columns refused naming the file.
TEST_F(CliTest, CalibrateWithLengths) {
  const std::string spec = Source() + "/calibration_data/spec_lengths.yaml";
  const std::string data = Path("lengths.csv");
  CommandResult r = Fastcal("simulate --truth=" + Source() +
                            "/calibration_data/lengths.truth.yaml --trajectory=random "
                            "--samples=200 --radial-spread=3 --seed=21 --length-noise-m=0.005 "
                            "--out=" +
                            data);
  ASSERT_EQ(r.code, 0) << r.output;
  r = Fastcal("calibrate --quiet --spec=" + spec + " --data=" + data + " --out=" + Path("out"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("verdict: ok"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("RMS model - measured length (mm)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("length_offset_m[1..6]"), std::string::npos) << r.output;
  const std::string summary = ReadFile(Path("out") + "/summary.json");
  EXPECT_NE(summary.find("\"lengths\": {"), std::string::npos);
  EXPECT_NE(ReadFile(Path("out") + "/report.md").find("## Lengths"), std::string::npos);
  EXPECT_NE(ReadFile(Path("out") + "/model_calibrated.yaml").find("length_offset_m: "),
            std::string::npos);
  Write("no_lengths.csv",
        "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n"
        "0,0,0,140,0,0,0,160,160,160,160,160,160\n");
  RunBoundedAndExpect(
      {"calibrate --spec=" + spec + " --data=" + Path("no_lengths.csv") + " --out=" + Path("out2"),
       2, "no_lengths.csv: the spec fits the lengths (noise.length_sigma_m)"});
  EXPECT_FALSE(fs::exists(Path("out2") + "/summary.json"));
}

// --spec takes the sigmas from a calibration spec's noise: spec_lengths.yaml's 5 mm
// lengths halve the pose's sigma from lengths alone (default 1 cm); a flag overrides it.
TEST_F(CliTest, LocateTakesItsSigmasFromASpec) {
  constexpr double kRelTol = 1e-6;
  const std::string k1 = "--lengths=319.4245,319.4245,319.4245,319.4245,319.4245,319.4245";
  const std::string spec = " --spec=" + Source() + "/calibration_data/spec_lengths.yaml";
  const auto sigma_x = [&](const std::string& flags, const std::string& name) {
    const CommandResult r = Fastcal("locate " + k1 + flags + " --output=" + Path(name));
    EXPECT_EQ(r.code, 0) << r.output;
    const auto rows = CsvRows(ReadFile(Path(name)));
    return rows.size() == 1 ? std::stod(rows[0].at("sigma_x_m")) : -1.0;
  };
  const double by_default = sigma_x("", "a.csv");
  const double by_spec = sigma_x(spec, "b.csv");
  const double overridden = sigma_x(spec + " --length-sigma-m=0.01", "c.csv");
  EXPECT_GT(by_default, 0.0);
  EXPECT_NEAR(by_spec, 0.5 * by_default, kRelTol * by_default);
  EXPECT_NEAR(overridden, by_default, kRelTol * by_default);
  RunBoundedAndExpect(
      {"locate " + k1 + " --spec=" + Path("nosuch.yaml"), 2, "nosuch.yaml: cannot open"});
}

TEST_F(CliTest, LocateRefusesBadInputAndNamesIt) {
  const std::string k1 = "--lengths=319.4245,319.4245,319.4245,319.4245,319.4245,319.4245";
  Write("short.csv", "time_s,s0_1_m,s0_2_m\n0,300,300\n");
  Write("bad_value.csv",
        "s0_1_m,s0_2_m,s0_3_m,s0_4_m,s0_5_m,s0_6_m\n319,319,319,319,319,319\n319,319,x,319,319,"
        "319\n");
  for (const ExpectedRun& c : std::vector<ExpectedRun>{
           {"locate", 2, "give --lengths=L1,...,L6 or --data=FILE.csv"},
           {"locate --lengths=1,2,3", 2, "--lengths needs 6 comma-separated numbers"},
           {"locate --lengths=319,319,319,319,319,-1", 2,
            "cable 6: unstretched length must be > 0"},
           {"locate " + k1 + " --use=lengths,tension", 2, "--use: unknown measurement 'tension'"},
           {"locate " + k1 + " --use=attitude", 2, "--use must include lengths"},
           {"locate " + k1 + " --length-sigma-m=0", 2, "--length-sigma-m must be > 0"},
           {"locate " + k1 + " --search-radius-m=-1", 2, "--search-radius-m must be >= 0"},
           {"locate " + k1 + " --rpy=0,0,0 --quat=1,0,0,0", 2, "at most one of --rpy and --quat"},
           {"locate " + k1 + " --tensions-kN=1,2", 2, "--tensions-kN needs 6"},
           {"locate " + k1 + " --force", 2, "--force applies to --output=FILE"},
           {"locate --data=" + Path("short.csv"), 2, "short.csv:1: missing columns 's0_3_m', 's0_4_m', 's0_5_m', 's0_6_m'"},
           {"locate --data=" + Path("bad_value.csv"), 2,
            "bad_value.csv:3: column 's0_3_m': 'x' is not a number"},
           {"locate --data=" + Path("short.csv") + " " + k1, 2, "drop --lengths"},
       }) {
    RunBoundedAndExpect(c);
  }
}

// Lengths no equilibrium within the model's range holds: exit 1 naming the row, no output
// file; with --keep-going the row is written with its status, message and empty numbers.
TEST_F(CliTest, LocateFailedRowIsNamedOrKeptWithItsStatus) {
  Write("lengths.csv",
        "s0_1_m,s0_2_m,s0_3_m,s0_4_m,s0_5_m,s0_6_m\n"
        "319.4245,319.4245,319.4245,319.4245,319.4245,319.4245\n"
        "250,250,250,250,250,250\n");
  const std::string out = Path("out.csv");
  CommandResult r =
      RunBoundedAndExpect({"locate --data=" + Path("lengths.csv") + " --output=" + out, 1,
                           "row 1 (" + Path("lengths.csv") + " line 3)"});
  EXPECT_NE(r.output.find("stretched beyond"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  r = Fastcal("locate --keep-going --data=" + Path("lengths.csv") + " --output=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("1 failed"), std::string::npos) << r.output;
  const auto rows = CsvRows(ReadFile(out));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("status"), "ok");
  EXPECT_EQ(rows[1].at("status"), "overstretched_cable");
  EXPECT_EQ(rows[1].at("stability"), "unknown");
  EXPECT_EQ(rows[1].at("x_m"), "");
}

}  // namespace
