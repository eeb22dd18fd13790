// End-to-end tests of telemetry as it comes (issue 26): --columns on every command that
// reads telemetry, fastcal import, .xlsx refused with the ways in, absolute times shown
// as dates, --sessions-at (docs/cli.md, docs/data-format.md "Column maps").
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "cli_fixture.h"
#include "fastcal/dataset.h"
#include "fastcal/file_digest.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;
using test::CommandResult;
using test::Fastcal;
using test::ReadFile;
using test::Source;

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "'" << text.substr(0, 3000) << "' does not contain '" << part << "'";
}

class CliColumnsTest : public test::CliTest {
 protected:
  std::string Data(const std::string& name) const { return Source() + "/calibration_data/" + name; }
};

TEST_F(CliColumnsTest, ImportWritesTheCanonicalFileWithItsProvenance) {
  const std::string map = Data("fast_export.columns.yaml"), data = Data("fast_export.csv");
  const std::string out = Path("survey.csv");
  const CommandResult r = Fastcal("import --columns=" + map + " --data=" + data + " --out=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "1441 samples from"));
  EXPECT_TRUE(Contains(r.output, "2024-05-01 20:00:00 to 20:48:00 UTC+08:00"));
  const std::string text = ReadFile(out);
  std::string digest, error;
  ASSERT_TRUE(FileSha256(data, &digest, &error)) << error;
  EXPECT_TRUE(Contains(text, "# export " + data + " (sha256 " + digest + ")"));
  ASSERT_TRUE(FileSha256(map, &digest, &error)) << error;
  EXPECT_TRUE(Contains(text, "# column map " + map + " (sha256 " + digest + "):"));
  EXPECT_TRUE(Contains(text, "#   | time: {column: SysTime, format: iso8601, zone: \"+08:00\"}"));
  EXPECT_TRUE(Contains(text, "\ntime_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,planned_roll_deg"));
  // The canonical file holds the very numbers of the survey the export came from.
  Dataset imported, survey;
  ASSERT_TRUE(ReadDataset(out, {}, &imported, &error)) << error;
  ASSERT_TRUE(ReadDataset(Data("realistic_survey.csv"), {}, &survey, &error)) << error;
  ASSERT_EQ(imported.samples.size(), survey.samples.size());
  for (size_t k = 0; k < survey.samples.size(); ++k) {
    ASSERT_EQ(imported.samples[k].time_s - 1714564800.0, survey.samples[k].time_s);
    ASSERT_EQ(imported.samples[k].tension_n, survey.samples[k].tension_n);
    ASSERT_EQ(imported.samples[k].pose.position_m, survey.samples[k].pose.position_m);
    ASSERT_EQ(imported.samples[k].unstretched_length_m, survey.samples[k].unstretched_length_m);
  }
  // Not over an existing file without --force; with it, replaced.
  CommandResult again = Fastcal("import --columns=" + map + " --data=" + data + " --out=" + out);
  EXPECT_EQ(again.code, 2);
  EXPECT_TRUE(Contains(again.output, "exists; not overwritten"));
  again = Fastcal("import --columns=" + map + " --data=" + data + " --out=" + out + " --force");
  EXPECT_EQ(again.code, 0) << again.output;
  // Missing flags.
  EXPECT_EQ(Fastcal("import --data=" + data + " --out=" + Path("x.csv")).code, 2);
}

TEST_F(CliColumnsTest, ImportErrorsNameTheMapsKeyOrTheExportsColumnAndLeaveNoFile) {
  Write("map.yaml",
        "format: fastcal-columns-1\ntime: {column: t}\ncolumns:\n  x_m: {column: X, unit: ft}\n");
  CommandResult r = Fastcal("import --columns=" + Path("map.yaml") +
                            " --data=" + Data("fast_export.csv") + " --out=" + Path("out.csv"));
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "map.yaml:4: columns.x_m.unit: unknown unit 'ft' for a length"));
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  // A bad value on line 20 of the export: its source column and fastcal name.
  std::string text = ReadFile(Data("fast_export.csv"));
  size_t line_start = 0;
  for (int line = 1; line < 20; ++line) line_start = text.find('\n', line_start) + 1;
  const size_t field = text.find(';', line_start) + 1;  // SDP_PhaPos_X
  text.replace(field, text.find(';', field) - field, "12,3,4");
  Write("export.csv", text);
  r = Fastcal("import --columns=" + Data("fast_export.columns.yaml") +
              " --data=" + Path("export.csv") + " --out=" + Path("out.csv"));
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "export.csv:20: column 'SDP_PhaPos_X' (x_m, mm): '12,3,4'"));
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".import-"), std::string::npos);
  }
}

TEST_F(CliColumnsTest, EveryCommandThatReadsTelemetryTakesTheMap) {
  const std::string columns = " --columns=" + Data("fast_export.columns.yaml");
  // evaluate: through the map, the table of the canonical survey, times as dates.
  const CommandResult mapped =
      Fastcal("evaluate --data=" + Data("fast_export.csv") + columns + " --out=" + Path("eval"));
  ASSERT_EQ(mapped.code, 0) << mapped.output;
  const CommandResult canonical = Fastcal("evaluate --data=" + Data("realistic_survey.csv"));
  ASSERT_EQ(canonical.code, 0) << canonical.output;
  const std::string table = "RMS model - measured (kN)";
  EXPECT_EQ(mapped.output.substr(mapped.output.find(table), 400),
            canonical.output.substr(canonical.output.find(table), 400));
  const std::string md = ReadFile(Path("eval/report.md"));
  EXPECT_TRUE(Contains(md, "2024-05-01 20:00:00 to 20:48:00 UTC+08:00"));
  EXPECT_TRUE(Contains(md, "read through the column map"));
  EXPECT_EQ(md.find("1.71456e+09"), std::string::npos);
  const std::string html = ReadFile(Path("eval/report.html"));
  EXPECT_TRUE(Contains(html, "time on 2024-05-01 (UTC+08:00)"));
  EXPECT_TRUE(Contains(html, ">20:10<"));
  EXPECT_EQ(html.find("1.7145"), std::string::npos);
  const std::string json = ReadFile(Path("eval/summary.json"));
  EXPECT_TRUE(Contains(json, "\"time_first\": \"2024-05-01T20:00:00+08:00\""));
  EXPECT_TRUE(Contains(json, "\"columns\": {"));
  // calibrate: the same estimates as from the canonical survey (only the lines differ: the
  // export has one line less above its rows).
  const std::string spec = " --quiet --spec=" + Data("spec_realistic.yaml");
  const CommandResult fit_mapped =
      Fastcal("calibrate" + spec + columns + " --data=" + Data("fast_export.csv") +
              " --out=" + Path("fit1"));
  ASSERT_EQ(fit_mapped.code, 0) << fit_mapped.output;
  const CommandResult fit = Fastcal("calibrate" + spec + " --data=" + Data("realistic_survey.csv") +
                                    " --out=" + Path("fit2"));
  ASSERT_EQ(fit.code, 0) << fit.output;
  const auto estimates = [](const std::string& out) {
    const size_t from = out.find("free parameter");
    return out.substr(from, out.find("gross errors") - from);
  };
  EXPECT_EQ(estimates(fit_mapped.output), estimates(fit.output));
  EXPECT_TRUE(Contains(ReadFile(Path("fit1/model_calibrated.yaml")),
                       "# read through the column map " + Data("fast_export.columns.yaml")));
  // solve --poses and simulate --poses.
  CommandResult r = Fastcal("solve --poses=" + Data("fast_export.csv") + columns +
                            " --output=" + Path("solved.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  r = Fastcal("simulate --poses=" + Data("fast_export.csv") + columns +
              " --out=" + Path("simulated.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  // --columns without --poses is refused.
  r = Fastcal("solve --position=0,0,140" + columns);
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "--columns applies to --poses"));
  // An .xlsx: the Python route and xlsx2csv named.
  Write("export.xlsx", std::string("PK\x03\x04", 4) + "a workbook");
  r = Fastcal("evaluate --data=" + Path("export.xlsx"));
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "a spreadsheet, not CSV text"));
  EXPECT_TRUE(Contains(r.output, "fastcal.read_dataset("));
  EXPECT_TRUE(Contains(r.output, "xlsx2csv"));
  r = Fastcal("import --columns=" + Data("fast_export.columns.yaml") +
              " --data=" + Path("export.xlsx") + " --out=" + Path("x.csv"));
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "xlsx2csv"));
}

TEST_F(CliColumnsTest, AbsoluteTimesReadAsDatesAndSessionsAtTakesTheScansAnswer) {
  // A circle of 240 nodes, the mass centre stepping by 8 cm in x at t = 120 s, its times
  // made Unix seconds (2024-05-01T20:00:00Z on).
  ASSERT_EQ(Fastcal("simulate --mass-centre=0.2,0,0.5 --nodes=240 --seed=5 "
                    "--mass-centre-step=120:0.08,0,0 --out=" +
                    Path("step.csv"))
                .code,
            0);
  Dataset data;
  std::string error;
  ASSERT_TRUE(ReadDataset(Path("step.csv"), {}, &data, &error)) << error;
  for (Sample& s : data.samples) s.time_s += 1714593600.0;
  ASSERT_TRUE(WriteDataset(Path("unix.csv"), data, "", &error)) << error;
  Write("scan.yaml",
        "parameters:\n  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}\n"
        "change_scan: {parameters: [mass_centre_m], min_segment_samples: 40}\n");
  CommandResult r = Fastcal("calibrate --quiet --spec=" + Path("scan.yaml") +
                            " --data=" + Path("unix.csv") + " --out=" + Path("scan"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "a change at 2024-05-01 20:0"));
  EXPECT_TRUE(Contains(r.output, " UTC (line "));
  EXPECT_EQ(r.output.find("e+09"), std::string::npos) << r.output;
  const std::string json = ReadFile(Path("scan/summary.json"));
  std::smatch m;
  ASSERT_TRUE(std::regex_search(json, m, std::regex("\"sessions_at\": \"([^\"]+)\""))) << json;
  const std::string sessions_at = m[1].str();
  EXPECT_TRUE(Contains(sessions_at, "2024-05-01T20:0"));
  EXPECT_TRUE(Contains(json, "\"time\": \"2024-05-01T20:0"));
  const std::string md = ReadFile(Path("scan/report.md"));
  EXPECT_TRUE(Contains(md, "2024-05-01 20:00:00 to 20:03:59 UTC"));
  EXPECT_TRUE(Contains(md, "--sessions-at=" + sessions_at));
  EXPECT_EQ(md.find("e+09"), std::string::npos);
  EXPECT_EQ(ReadFile(Path("scan/report.html")).find("1.7146"), std::string::npos);

  // The survey cut there, by the scan's summary.json and by the time itself: the same fit.
  Write("sessions.yaml",
        "parameters:\n  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}\n"
        "sessions: {separate: [mass_centre_m]}\n");
  r = Fastcal("calibrate --quiet --spec=" + Path("sessions.yaml") + " --data=" + Path("unix.csv") +
              " --sessions-at=" + Path("scan/summary.json") + " --out=" + Path("by_json"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "mass_centre_m.x"));
  EXPECT_TRUE(Contains(r.output, "s1 -> s2"));
  const CommandResult by_time =
      Fastcal("calibrate --quiet --spec=" + Path("sessions.yaml") + " --data=" + Path("unix.csv") +
              " --sessions-at=" + sessions_at + " --out=" + Path("by_time"));
  ASSERT_EQ(by_time.code, 0) << by_time.output;
  const std::string between = "between sessions";
  EXPECT_EQ(r.output.substr(r.output.find(between), 300),
            by_time.output.substr(by_time.output.find(between), 300));
  EXPECT_TRUE(fs::exists(Path("by_time/model_calibrated@s2.yaml")));
  // Import cuts the same way into a session column.
  Write("identity.yaml",
        "format: fastcal-columns-1\ntime: {column: time_s, format: unix_s}\ncolumns:\n"
        "  x_m: x_m\n  y_m: y_m\n  z_m: z_m\n  roll_deg: roll_deg\n  pitch_deg: pitch_deg\n"
        "  yaw_deg: yaw_deg\n  T1_kN: T1_kN\n  T2_kN: T2_kN\n  T3_kN: T3_kN\n  T4_kN: T4_kN\n"
        "  T5_kN: T5_kN\n  T6_kN: T6_kN\nunmapped: ignore\n");
  r = Fastcal("import --columns=" + Path("identity.yaml") + " --data=" + Path("unix.csv") +
              " --sessions-at=" + sessions_at + " --out=" + Path("cut.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "sessions: s1 ("));
  Dataset cut;
  ASSERT_TRUE(ReadDataset(Path("cut.csv"), {}, &cut, &error)) << error;
  EXPECT_EQ(cut.session_labels, (std::vector<std::string>{"s1", "s2"}));
  // Bad cuts.
  r = Fastcal("calibrate --quiet --spec=" + Path("sessions.yaml") + " --data=" + Path("unix.csv") +
              " --sessions-at=2030-01-01T00:00:00Z --out=" + Path("never"));
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "(session s2 would be empty)"));
  r = Fastcal("calibrate --quiet --spec=" + Path("sessions.yaml") + " --data=" + Path("unix.csv") +
              " --sessions-at=noon --out=" + Path("never"));
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "--sessions-at=noon: 'noon' is neither a time in seconds"));
  r = Fastcal("calibrate --quiet --spec=" + Path("sessions.yaml") + " --data=" + Path("unix.csv") +
              " --sessions-at=" + Path("by_time/summary.json") + " --out=" + Path("never"));
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "that calibration had no change scan"));
  EXPECT_FALSE(fs::exists(Path("never")));
}

}  // namespace
}  // namespace fastcal

namespace fastcal {
namespace {

// Issue 37: tensions in kN under a map's `unit: N` were read 1000x small and calibrate
// exited 0 with gains of 0.001. The whole file's tensions against the cabin's weight
// now refuse it, naming the slip.
TEST_F(CliColumnsTest, TensionsReadInTheWrongUnitAreRefused) {
  ASSERT_EQ(
      Fastcal("simulate --trajectory=random --samples=200 --seed=2 --out=" + Path("s.csv")).code,
      0);
  std::string map = "format: fastcal-columns-1\ntime: time_s\nunmapped: ignore\ncolumns:\n";
  for (const char* name : {"x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"}) {
    map += std::string("  ") + name + ": " + name + "\n";
  }
  for (int i = 1; i <= 6; ++i) {
    const std::string t = "T" + std::to_string(i) + "_kN";
    map += "  " + t + ": {column: " + t + ", unit: N}\n";
  }
  Write("map.yaml", map);
  const test::CommandResult r =
      Fastcal("calibrate --spec=" + Source() + "/calibration_data/spec_realistic.yaml --data=" +
              Path("s.csv") + " --columns=" + Path("map.yaml") + " --out=" + Path("cal"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("read 1000x small? (tensions in kN where the column map says N)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(Path("cal")));
  // evaluate checks it too (it gave an RMS of 99.9% and exit 0).
  const test::CommandResult e = Fastcal("evaluate --data=" + Path("s.csv") +
                                        " --columns=" + Path("map.yaml") + " --out=" + Path("ev"));
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_NE(e.output.find("read 1000x small"), std::string::npos) << e.output;
  EXPECT_FALSE(fs::exists(Path("ev")));
  // One column alone under `unit: N` (sensor_gain[3] = 0.001, exit 0): the cable named.
  Write("one.yaml",
        std::regex_replace(map, std::regex("T([1245-6])_kN, unit: N"), "T$1_kN, unit: kN"));
  const test::CommandResult one =
      Fastcal("calibrate --spec=" + Source() + "/calibration_data/spec_realistic.yaml --data=" +
              Path("s.csv") + " --columns=" + Path("one.yaml") + " --out=" + Path("cal"));
  EXPECT_EQ(one.code, 2) << one.output;
  EXPECT_NE(one.output.find("cable 3's tensions"), std::string::npos) << one.output;
  EXPECT_FALSE(fs::exists(Path("cal")));
  // Issue 57, 12: import, where the map's units are known, wrote both (1000x small, exit 0),
  // and only calibrate refused the imported file. It refuses them itself, writing nothing.
  for (const char* map_name : {"map.yaml", "one.yaml"}) {
    const test::CommandResult imported =
        Fastcal("import --columns=" + Path(map_name) + " --data=" + Path("s.csv") +
                " --out=" + Path("imported.csv"));
    EXPECT_EQ(imported.code, 2) << imported.output;
    EXPECT_NE(imported.output.find(std::string(map_name) == "map.yaml"
                                       ? "read 1000x small? (tensions in kN where the column "
                                         "map says N)"
                                       : "cable 3's tensions"),
              std::string::npos)
        << imported.output;
    EXPECT_FALSE(fs::exists(Path("imported.csv")));
  }
}

}  // namespace
}  // namespace fastcal

namespace fastcal {
namespace {

// Issue 37: a file whose times never advance (every sample at one time_s) gave the slow
// sensor error any value at all, fitted silently; a spec with noise.slow_error refuses it.
TEST_F(CliColumnsTest, TimesThatNeverAdvanceAreRefusedForASlowError) {
  ASSERT_EQ(
      Fastcal("simulate --trajectory=random --samples=200 --seed=3 --out=" + Path("s.csv")).code,
      0);
  ASSERT_EQ(test::Shell("awk -F, 'BEGIN{OFS=\",\"} /^#/ {print; next} $1 != \"time_s\" {$1 = 0} "
                        "{print}' " +
                        Path("s.csv") + " > " + Path("still.csv"))
                .code,
            0);
  const std::string spec = Source() + "/calibration_data/spec_realistic.yaml";
  const test::CommandResult r =
      Fastcal("calibrate --spec=" + spec + " --data=" + Path("still.csv") + " --out=" + Path("c"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("every sample has time_s = 0"), std::string::npos) << r.output;
  // The same file with its times calibrates.
  EXPECT_EQ(
      Fastcal("calibrate --spec=" + spec + " --data=" + Path("s.csv") + " --out=" + Path("d")).code,
      0);
}

}  // namespace
}  // namespace fastcal
