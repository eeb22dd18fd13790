// End-to-end tests of what a new user trips on (issue 30), each as the user meets it:
// flag names (units spelt as the data's, the old names deprecated, "did you mean"), the
// paper's circle and a plot in `solve`, every status in `solve --help`, `design`'s units
// and streams, `calibrate`'s one screen (units per row, width, the change found whole),
// the paper's Table 6 beside the RMS table, and the README's tour writing under out/.
#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"
#include "fastcal/statics.h"

namespace {

using fastcal::test::CliTest;
using fastcal::test::CommandResult;
using fastcal::test::Fastcal;
using fastcal::test::ReadFile;
using fastcal::test::Shell;
using fastcal::test::Source;

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The lines of `text` longer than `width` columns (code points), for the failure message;
// "wrote DIR/{...}" holds the --out path, which is the user's.
std::string LinesLongerThan(const std::string& text, size_t width) {
  std::istringstream in(text);
  std::string long_lines;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("wrote ", 0) == 0) continue;
    const size_t columns = std::count_if(line.begin(), line.end(), [](char c) {
      return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    });
    if (columns > width) long_lines += line + "\n";
  }
  return long_lines;
}

// `fastcal args` with stdout and stderr apart.
struct Streams {
  int code = -1;
  std::string out, err;
};

class UsabilityTest : public CliTest {
 protected:
  Streams Run(const std::string& args) {
    Streams s;
    // In a subshell: Shell adds its own 2>&1 after the command line.
    s.code = Shell("(" + fastcal::test::Bin() + " " + args + " > " + Path("stdout.txt") + " 2> " +
                   Path("stderr.txt") + ")")
                 .code;
    s.out = ReadFile(Path("stdout.txt"));
    s.err = ReadFile(Path("stderr.txt"));
    return s;
  }
};

// One spelling per unit, the data's: --min-tension-kN as T1_kN, --tension-noise-percent
// as tension_sigma_percent; the old names work, with a note naming the new one.
TEST_F(UsabilityTest, FlagsSpellUnitsAsTheDataAndTheOldNamesStillWork) {
  const std::string grid = "workspace --off-axis-step-deg=5 --azimuth-step-deg=30 ";
  const Streams now = Run(grid + "--min-tension-kN=130 --max-tension-kN=300");
  ASSERT_EQ(now.code, 0) << now.err;
  EXPECT_FALSE(Has(now.err, "deprecated")) << now.err;
  const Streams old = Run(grid + "--min-tension-kn=130 --max-tension-kn=300");
  ASSERT_EQ(old.code, 0) << old.err;
  EXPECT_EQ(old.out, now.out);  // the same map
  EXPECT_TRUE(Has(old.err, "note: --min-tension-kn is deprecated; use --min-tension-kN"))
      << old.err;
  EXPECT_TRUE(Has(old.err, "--max-tension-kn is deprecated; use --max-tension-kN")) << old.err;
  // An old and a new name are one flag given twice.
  const CommandResult twice = Fastcal(grid + "--min-tension-kn=130 --min-tension-kN=140");
  EXPECT_EQ(twice.code, 2);
  EXPECT_TRUE(Has(twice.output, "--min-tension-kN given twice")) << twice.output;
  const std::string sim = "simulate --nodes=4 --seed=3 --out=";
  const Streams a = Run(sim + Path("a.csv") + " --tension-noise-percent=2 --sensor-bias-kN=1.5");
  const Streams b = Run(sim + Path("b.csv") + " --tension-noise-pct=2 --sensor-bias-kn=1.5");
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_TRUE(Has(b.err, "--tension-noise-pct is deprecated; use --tension-noise-percent"));
  const auto rows = [](const std::string& csv) { return csv.substr(csv.find("\ntime_s")); };
  EXPECT_EQ(rows(ReadFile(Path("a.csv"))), rows(ReadFile(Path("b.csv"))));
  // The help texts use the new names (simulate's names the former ones once, as such).
  for (const char* command : {"simulate", "workspace", "design"}) {
    const std::string help = Fastcal(std::string(command) + " --help").output;
    EXPECT_FALSE(std::regex_search(help, std::regex("--[a-z-]+-(kn|pct)="))) << command << "\n"
                                                                             << help;
  }
}

// A misspelt flag is refused with the command's closest flags: an edit away, a case
// away, the start of one, or a slip in a former name.
TEST_F(UsabilityTest, AMisspeltFlagGetsDidYouMean) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"solve --position=0,0,140 --trajectori=line", "did you mean --trajectory?"},
      {"solve --position=0,0,140 --method=aas --aas-max-eror=0.1", "did you mean --aas-max-error?"},
      {"workspace --Min-Tension-KN=5", "did you mean --min-tension-kN"},
      {"simulate --out=x.csv --tension-nosie-pct=3", "did you mean --tension-noise-percent"},
      {"calibrate --sepc=s.yaml", "did you mean --spec?"},
  };
  for (const auto& [args, expected] : cases) {
    const CommandResult r = Fastcal(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_TRUE(Has(r.output, "unknown flag")) << r.output;
    EXPECT_TRUE(Has(r.output, expected)) << args << "\n" << r.output;
  }
  // Nothing close: no guess.
  const CommandResult far = Fastcal("solve --position=0,0,140 --zzzzzzzzzz=1");
  EXPECT_TRUE(Has(far.output, "unknown flag --zzzzzzzzzz (see fastcal solve --help)"))
      << far.output;
}

// A misspelt command gets the closest command, every command among them (issue 59:
// `fastcal trak` suggests track; `fastcal dynamcs` suggested nothing, dynamics missing
// from the list).
TEST_F(UsabilityTest, AMisspeltCommandGetsDidYouMean) {
  for (const auto& [command, expected] :
       std::vector<std::pair<std::string, std::string>>{{"trak", "did you mean track?"},
                                                        {"dynamcs", "did you mean dynamics?"},
                                                        {"mode", "did you mean modes?"}}) {
    const CommandResult r = Fastcal(command);
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_TRUE(Has(r.output, "unknown command '" + command + "'; " + expected)) << r.output;
  }
}

// solve --help names every status the library can give, from the library's own list.
TEST_F(UsabilityTest, SolveHelpListsEveryStatus) {
  const std::string help = Fastcal("solve --help").output;
  for (int s = 0; s <= static_cast<int>(fastcal::kLastStaticsStatus); ++s) {
    const std::string name = fastcal::StaticsStatusName(static_cast<fastcal::StaticsStatus>(s));
    EXPECT_TRUE(std::regex_search(help, std::regex("[ ,]" + name + "[,\n]"))) << name;
  }
  EXPECT_EQ(LinesLongerThan(help, 100), "");
}

// solve flies the paper's measured circle as simulate does, and plots a trajectory.
TEST_F(UsabilityTest, SolveFliesThePapersCircleAndPlotsTheTensions) {
  const std::string csv = Path("c.csv"), html = Path("c.html");
  const Streams r =
      Run("solve --trajectory=circle --method=compare --output=" + csv + " --plot=" + html);
  ASSERT_EQ(r.code, 0) << r.err;
  std::istringstream rows(ReadFile(csv));
  int lines = 0;
  for (std::string line; std::getline(rows, line);) ++lines;
  EXPECT_EQ(lines, 361);  // header and 360 nodes
  // The page: both methods, the error plot, and the maxima the summary line prints.
  const std::string page = ReadFile(html);
  EXPECT_TRUE(Has(page, "<title>(a) Lower-end tensions, aas</title>"));
  EXPECT_TRUE(Has(page, "<title>(b) Lower-end tensions, exact</title>"));
  EXPECT_TRUE(Has(page, "<title>Relative error of aas against exact</title>"));
  EXPECT_TRUE(Has(page, "distance travelled [m]"));
  EXPECT_FALSE(Has(page, "<script"));
  std::smatch maxima;
  ASSERT_TRUE(std::regex_search(r.out, maxima, std::regex("per cable \\(%\\): ([0-9.]+)")))
      << r.out;
  EXPECT_TRUE(Has(page, "<td class=\"num\">" + maxima[1].str() + "</td>")) << maxima[1];
  EXPECT_TRUE(Has(r.out, "focal law")) << r.out;
  // --nodes applies to the circle; --radius does not.
  EXPECT_EQ(Fastcal("solve --trajectory=circle --nodes=12").code, 0);
  const CommandResult radius = Fastcal("solve --trajectory=circle --radius=50");
  EXPECT_EQ(radius.code, 2);
  EXPECT_TRUE(Has(radius.output, "--radius applies to --trajectory=arc")) << radius.output;
  // The plot: a grid's nodes in order; refused for one pose, on stdout, over the output,
  // and over an existing file without --force; written with a table on stdout.
  ASSERT_EQ(Fastcal("solve --trajectory=grid --plot=" + Path("g.html")).code, 0);
  EXPECT_TRUE(Has(ReadFile(Path("g.html")), ">node</text>"));
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"solve --position=0,0,140 --plot=" + Path("p.html"),
       "--plot applies to a --trajectory or --poses, not to a single --position"},
      {"solve --trajectory=line --plot=-", "--plot needs a file name"},
      {"solve --trajectory=line --output=" + csv + " --plot=" + csv + " --force",
       "--output and --plot name the same file"},
      {"solve --trajectory=line --plot=" + html, "--force"},
  };
  for (const auto& [args, expected] : refused) {
    const CommandResult bad = Fastcal(args);
    EXPECT_EQ(bad.code, 2) << args;
    EXPECT_TRUE(Has(bad.output, expected)) << args << "\n" << bad.output;
  }
  EXPECT_EQ(ReadFile(html), page);  // refused: left as it was
}

// design: every sigma in its parameter's unit (kN for sensor_bias_kN, never N under a kN
// name), the summary on stdout, the stages' progress on stderr.
TEST_F(UsabilityTest, DesignSpeaksInTheParametersUnitsOnTheRightStreams) {
  const Streams r = Run("design --spec=" + Source() +
                        "/calibration_data/spec_realistic.yaml --samples=40 "
                        "--off-axis-step-deg=5 --azimuth-step-deg=30 --parameters="
                        "mass_centre_m.x,sensor_bias_kN[1] --out=" +
                        Path("d"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "fastcal design: 40 samples at")) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("sensor_bias_kN\\[1\\] +kN +[0-9.]+ "))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("mass_centre_m\\.x +m +0\\.0[0-9]+ "))) << r.out;
  EXPECT_TRUE(Has(r.err, "fastcal design: approximate design")) << r.err;
  EXPECT_FALSE(Has(r.err, "predicted sigma_total")) << r.err;
  const std::string json = ReadFile(Path("d/design.json"));
  std::smatch bias;
  ASSERT_TRUE(std::regex_search(
      json, bias,
      std::regex("\"name\": \"sensor_bias_kN\\[1\\]\",\\s*\"unit\": \"kN\",\\s*\"sigma_total\": "
                 "([0-9.e+-]+)")))
      << json.substr(0, 3000);
  // The spec's prior is 2 kN: the design cannot be less certain than that; in N it read
  // 300 and more.
  EXPECT_GT(std::stod(bias[1]), 0.0);
  EXPECT_LE(std::stod(bias[1]), 2.0);
  const std::string page = ReadFile(Path("d/design.html"));
  EXPECT_TRUE(Has(page, "<circle class=\"start\"")) << "a start mark";
  EXPECT_TRUE(Has(page, "<text class=\"stop-number\"")) << "stop numbers";
  EXPECT_TRUE(Has(page, ".banner-bad")) << "the report's style sheet";
}

TEST_F(UsabilityTest, SimulateHelpSaysWhereTheSummaryGoes) {
  const std::string help = Fastcal("simulate --help").output;
  EXPECT_FALSE(Has(help, "summary on stderr")) << help;
  EXPECT_TRUE(Has(help, "summary of what was written on stdout")) << help;
  const Streams r = Run("simulate --nodes=3 --out=" + Path("s.csv"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "fastcal simulate: 3 samples")) << r.out;
}

// calibrate's one screen: a change found is printed whole, every line within 100
// columns, and each row in one unit, the one its parameter's name carries.
TEST_F(UsabilityTest, CalibrateConsoleShowsTheChangeWholeWithinAHundredColumns) {
  const std::string data = Path("step.csv");
  ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=500 --seed=3 "
                    "--mass-centre=0.2,0,0.5 --mass-centre-step=250:0.05,0,0.03 --out=" +
                    data)
                .code,
            0);
  std::string spec = ReadFile(Source() + "/calibration_data/spec_change_scan.yaml");
  spec = std::regex_replace(spec, std::regex("min_segment_samples: 50"), "min_segment_samples: 40");
  Write("scan.yaml", spec);
  const Streams r = Run("calibrate --quiet --spec=" + Path("scan.yaml") + " --data=" + data +
                        " --out=" + Path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  // The step at 250 s, found within the scan's resolution.
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  change scan: a change at t = 2[4-5][0-9] s "
                                                  "\\(line [0-9]+, p [0-9.e-]+\\): ")))
      << r.out;
  // Whole: its last words are on the screen, not "... (report.md)".
  EXPECT_TRUE(Has(r.out, "{separate:\n    [mass_centre_m]}") ||
              Has(r.out, "{separate: [mass_centre_m]}"))
      << r.out;
  EXPECT_EQ(LinesLongerThan(r.out, 100), "");
  // One unit per row: the formal sigma in m beside an estimate in m; a group's unit after
  // its sigmas.
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("\n  mass_centre_m\\.x +[-0-9.]+ \\+- [0-9.]+ m +[0-9.]+ m +x")))
      << r.out;
  EXPECT_FALSE(Has(r.out, " mm")) << r.out;
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("sensor_bias_kN\\[1\\.\\.6\\] +[-0-9.]+\\.\\.[-0-9.]+ \\+- "
                        "[0-9.]+\\.\\.[0-9.]+ kN ")))
      << r.out;
  EXPECT_TRUE(Has(r.out, "\n  the misfit is best explained") ||
              Has(r.out, "\n  no fixed parameter explains"))
      << r.out;
}

// A model-incomplete verdict marks rows NOT SOUND: the note goes below a row it would
// push past 100 columns.
TEST_F(UsabilityTest, NotSoundNotesKeepTheConsoleWithinAHundredColumns) {
  const std::string data = Path("built.csv");
  ASSERT_EQ(Fastcal("simulate --truth=" + Source() +
                    "/calibration_data/as_built.yaml --trajectory=random --samples=300 "
                    "--mass-centre=0.22,0.11,0.56 --seed=11 --out=" +
                    data)
                .code,
            0);
  const Streams r =
      Run("calibrate --quiet --spec=" + Source() +
          "/calibration_data/spec_realistic.yaml --data=" + data + " --out=" + Path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "verdict: model incomplete")) << r.out;
  EXPECT_TRUE(Has(r.out, "\n      NOT SOUND: ")) << r.out;
  EXPECT_EQ(LinesLongerThan(r.out, 100), "");
}

// On the paper's measured circle the paper's own Table 6 follows the RMS table; by the
// positions (a renamed copy gets it too), and only there.
TEST_F(UsabilityTest, ThePapersTable6IsBesideTheRmsTableOnItsCircle) {
  const std::string renamed = Path("flight_0412.csv");
  Write("flight_0412.csv", ReadFile(Source() + "/calibration_data/circle_paper.csv"));
  const Streams calibrated = Run(
      "calibrate --quiet --spec=" + Source() +
      "/calibration_data/spec_mass_centre_density.yaml --data=" + renamed + " --out=" + Path("c"));
  ASSERT_EQ(calibrated.code, 0) << calibrated.err;
  EXPECT_TRUE(
      std::regex_search(calibrated.out, std::regex("paper's Table 6: AAS +22\\.554 +17\\.517")))
      << calibrated.out;
  EXPECT_TRUE(Has(calibrated.out, "paper's Table 6: + corrected mass centre   20.060"))
      << calibrated.out;
  EXPECT_TRUE(Has(ReadFile(Path("c/report.md")),
                  "| AAS with actual attitudes | initial model, "
                  "measured attitude | 23.942 |"));
  // Issue 59: the file is the simulate's (its header says so): the report says so in its
  // first lines, and the console's Table 6 with the caveat.
  const std::string report = ReadFile(Path("c/report.md"));
  EXPECT_LT(report.find("**Simulated data.**"), report.find("## Provenance")) << report;
  EXPECT_TRUE(Has(calibrated.out, "THESE DATA\n  ARE SIMULATED (fastcal simulate)"))
      << calibrated.out;
  const Streams evaluated =
      Run("evaluate --model=" + Path("c/model_calibrated.yaml") + " --data=" + renamed);
  EXPECT_TRUE(Has(evaluated.out, "paper's Table 6: actual attitudes")) << evaluated.out;
  EXPECT_TRUE(Has(evaluated.out, "ARE SIMULATED")) << evaluated.out;
  // The same samples without the header: the paper's table as before, no caveat.
  std::string data = ReadFile(renamed);
  while (data.rfind("#", 0) == 0) data.erase(0, data.find('\n') + 1);
  Write("flight_0413.csv", data);
  const Streams plain = Run("evaluate --data=" + Path("flight_0413.csv"));
  EXPECT_TRUE(Has(plain.out, "the same circle on the telescope (the paper's published RMS, kN):"))
      << plain.out;
  EXPECT_FALSE(Has(plain.out, "SIMULATED")) << plain.out;
  // Another survey: no paper values.
  const Streams other =
      Run("evaluate --data=" + Source() + "/calibration_data/workspace_multi_zenith.csv");
  ASSERT_EQ(other.code, 0) << other.err;
  EXPECT_FALSE(Has(other.out, "Table 6")) << other.out;
}

// The README's tour writes every output under out/, none into the repository's top.
TEST_F(UsabilityTest, TheReadmeTourWritesUnderOut) {
  const std::string readme = ReadFile(Source() + "/README.md");
  const size_t start = readme.find("## A tour");
  ASSERT_NE(start, std::string::npos);
  // The tour's commands: its indented lines.
  std::istringstream lines(readme.substr(start, readme.find("\n## ", start + 1) - start));
  std::string tour;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("    ", 0) == 0) tour += line + "\n";
  }
  const std::regex output("(--(out|output|html|plot)=|> )([^ \\\\\n]+)");
  int outputs = 0;
  for (auto it = std::sregex_iterator(tour.begin(), tour.end(), output);
       it != std::sregex_iterator(); ++it) {
    ++outputs;
    EXPECT_EQ((*it)[3].str().rfind("out/", 0), 0u) << (*it)[0];
  }
  EXPECT_GE(outputs, 10);
  EXPECT_TRUE(Has(tour, "mkdir -p out"));
}

// Issue 59: the README's moving-parts example starts from a first moment of zero, not from
// calibration_data/moving_parts.yaml, which holds the truth it is meant to find.
TEST_F(UsabilityTest, TheReadmeMovingPartsExampleStartsFromZero) {
  const std::string readme = ReadFile(Source() + "/README.md");
  const size_t calibrate = readme.find("calibrate --spec=calibration_data/spec_moving_parts.yaml");
  ASSERT_NE(calibrate, std::string::npos);
  const std::string command =
      readme.substr(calibrate, readme.find("--out=", calibrate) - calibrate);
  const std::smatch model = [&command] {
    std::smatch m;
    std::regex_search(command, m, std::regex("--model=(\\S+)"));
    return m;
  }();
  ASSERT_FALSE(model.empty()) << command;
  EXPECT_NE(model[1].str(), "calibration_data/moving_parts.yaml") << command;
  // The start model is the truth with its first moment zeroed, made just before.
  EXPECT_TRUE(Has(readme.substr(0, calibrate),
                  "sed 's/\\[0, 0, -6000\\]/[0, 0, 0]/' calibration_data/moving_parts.yaml \\\n"
                  "        > " +
                      model[1].str()))
      << readme.substr(calibrate - 400, 400);
}

}  // namespace

namespace {

// A console note cut to its lines ends "... (report.md)" after a whole word of the note,
// never inside a number (the slow error's likelihood ratio 2.62e+03 once read "2.6"): the
// word before the mark stands whole in the report, which has every note in full.
TEST_F(UsabilityTest, ConsoleNotesAreCutAtAWord) {
  const Streams s = Run("calibrate --spec=" + Source() + "/calibration_data/spec_realistic.yaml" +
                        " --data=" + Source() + "/calibration_data/realistic_survey.csv" +
                        " --out=" + Path("out"));
  ASSERT_EQ(s.code, 0) << s.err;
  const std::string report = ReadFile(Path("out/report.md"));
  const std::string mark = " ... (report.md)";
  int cut = 0;
  std::istringstream lines(s.out);
  for (std::string line; std::getline(lines, line);) {
    const size_t at = line.find(mark);
    if (at == std::string::npos) continue;
    ++cut;
    const std::string before = line.substr(0, at);
    const std::string word = before.substr(before.find_last_of(' ') + 1);
    ASSERT_FALSE(word.empty()) << line;
    // Whole: followed in the report by a space or the end of a sentence, not more digits.
    const std::regex whole(
        "(^|[ (])" + std::regex_replace(word, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)") +
        R"(($|[ ;,)]))");
    EXPECT_TRUE(std::regex_search(report, whole)) << "cut inside a word: " << line;
  }
  EXPECT_GT(cut, 0) << "no note was cut; the test no longer tests the cut\n" << s.out;
}

}  // namespace

namespace fastcal::test {
namespace {

TEST_F(UsabilityTest, TrackRefusesAnAbsurdThreadCount) {
  // --threads=100000 was accepted (issue 37): the bound is calibrate's, 256.
  ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=50 --out=" + Path("s.csv")).code, 0);
  RunBoundedAndExpect({"track --spec=" + Source() + "/calibration_data/spec_track.yaml --data=" +
                           Path("s.csv") + " --out=" + Path("t") + " --threads=100000",
                       2, "--threads must be 1 to 256, got 100000"});
}

TEST_F(UsabilityTest, ADataDirectoryReadsCsvInAnyCaseAndNoHiddenFile) {
  // *.CSV was skipped and a hidden .x.csv read (issue 37).
  fs::create_directories(Path("days"));
  ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=300 --start=2024-05-01T20:00:00Z "
                    "--out=" +
                    Path("days/A.CSV"))
                .code,
            0);
  Write("days/.x.csv", "not a dataset\n");
  const CommandResult r = Fastcal("track --spec=" + Source() +
                                  "/calibration_data/spec_track.yaml --data=" + Path("days") +
                                  " --out=" + Path("t"));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("A.CSV"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find(".x.csv"), std::string::npos) << r.output;
}

TEST_F(UsabilityTest, TheTruthFileListsTheStepsAsTheHelpSays) {
  // simulate --help: "its header lists the steps"; it did not (issue 39).
  const CommandResult r = Fastcal(
      "simulate --trajectory=random --samples=50 --days=2 --start=2024-05-01T20:00:00Z "
      "--mass-centre-step=2024-05-02T20:00:00Z:0.05,0,0 "
      "--sensor-step=2024-05-02T21:00:00Z:3:5 --out=" +
      Path("s.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string truth = ReadFile(Path("s.truth.yaml"));
  EXPECT_NE(truth.find("# Mass centre step at 2024-05-02 20:00:00 UTC: (0.05, 0, 0) m"),
            std::string::npos)
      << truth;
  EXPECT_NE(truth.find("# Sensor step at 2024-05-02 21:00:00 UTC: cable 3's bias 5 kN"),
            std::string::npos)
      << truth;
}

}  // namespace
}  // namespace fastcal::test
