// Gzipped telemetry from the command line (issue 39): calibrate reads a .csv.gz as the
// plain file, track --data=DIR lists *.csv.gz beside *.csv, and a truncated .gz is refused
// by name with a non-zero exit and no output.
#include <string>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

class CliGzipTest : public CliTest {};

TEST_F(CliGzipTest, CalibrateAndTrackReadGzippedTelemetry) {
  ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=400 --seed=3 --days=2 "
                    "--interval-s=2 --start=2024-05-01T20:00:00Z --out=" +
                    Path("s.csv"))
                .code,
            0);
  ASSERT_EQ(Shell("cd " + Path("") + " && gzip -k s.csv && mkdir days && cp s.csv.gz days/").code,
            0);
  const std::string spec = Source() + "/calibration_data/spec_mass_centre.yaml";
  const CommandResult plain =
      Fastcal("calibrate --spec=" + spec + " --data=" + Path("s.csv") + " --out=" + Path("a"));
  const CommandResult gz =
      Fastcal("calibrate --spec=" + spec + " --data=" + Path("s.csv.gz") + " --out=" + Path("b"));
  ASSERT_EQ(plain.code, 0) << plain.output;
  ASSERT_EQ(gz.code, 0) << gz.output;
  // The same estimates: the calibrated models' mass centres agree to the digit.
  const auto centre = [](const std::string& yaml) {
    const size_t at = yaml.find("mass_centre_m:");
    return at == std::string::npos ? std::string("none") : yaml.substr(at, yaml.find('\n', at) - at);
  };
  EXPECT_EQ(centre(ReadFile(Path("a/model_calibrated.yaml"))),
            centre(ReadFile(Path("b/model_calibrated.yaml"))));
  EXPECT_NE(centre(ReadFile(Path("a/model_calibrated.yaml"))), "none");
  const CommandResult track = Fastcal("track --spec=" + Source() +
                                      "/calibration_data/spec_track.yaml --data=" +
                                      Path("days") + " --out=" + Path("t"));
  EXPECT_EQ(track.code, 0) << track.output;
  EXPECT_NE(track.output.find("s.csv.gz"), std::string::npos) << track.output;
  ASSERT_EQ(Shell("head -c 2000 " + Path("s.csv.gz") + " > " + Path("cut.csv.gz")).code, 0);
  const CommandResult cut =
      Fastcal("calibrate --spec=" + spec + " --data=" + Path("cut.csv.gz") + " --out=" + Path("c"));
  EXPECT_NE(cut.code, 0);
  EXPECT_NE(cut.output.find("cut.csv.gz: truncated gzip file"), std::string::npos) << cut.output;
  EXPECT_FALSE(fs::exists(Path("c/summary.json")));
}

}  // namespace
}  // namespace fastcal::test
