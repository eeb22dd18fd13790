// Where the telemetry measures, from the command line (issue 58): solve with a measured
// frame against the plain model at the cabin's pose derived by hand (a frame on the cabin
// and one on the rotated platform), a survey with a 2 m lever arm and the rotator
// following the pointing calibrated to its truth with the offset estimated, locate's two
// poses, the bundled FAST export read as the feed's, and the refusals a user meets.
#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

class CliMeasuredFrameTest : public CliTest {
 protected:
  // The fields of the first data row of a CSV output (after the header), by column name.
  static double Column(const std::string& csv, const std::string& name) {
    const size_t end_header = csv.find('\n');
    const std::vector<std::string> header = CsvFields(csv.substr(0, end_header));
    const size_t end_row = csv.find('\n', end_header + 1);
    const std::vector<std::string> row =
        CsvFields(csv.substr(end_header + 1, end_row - end_header - 1));
    for (size_t k = 0; k < header.size(); ++k) {
      if (header[k] == name && k < row.size()) return std::stod(row[k]);
    }
    ADD_FAILURE() << "no column " << name << " in\n" << csv.substr(0, 500);
    return 0.0;
  }
  std::string FeedModel() const { return Source() + "/calibration_data/fast_feed.yaml"; }
  // fast_feed.yaml without its measured frame: the data's pose taken as the cabin's.
  std::string PlainFeedModel() {
    std::string text = ReadFile(FeedModel());
    text = text.substr(0, text.find("  measured_frame:"));
    Write("plain.yaml", text);
    return Path("plain.yaml");
  }
};

TEST_F(CliMeasuredFrameTest, SolveGivesThePlainModelsTensionsAtTheCabinPoseDerivedByHand) {
  // solve writes 10 significant digits.
  constexpr double kRelTol = 1e-8;
  struct Case {
    std::string framed, plain, given, hand, joints;
    double cabin[3];
  };
  // A point 2 m below the anchor plane, the cabin rolled 10 deg:
  //   p_c = m - R_m d = (10, 5, 150) + 2 (0, -sin 10, cos 10).
  Write("cabin_frame.yaml",
        "format: fastcal-model-1\ncabin:\n  measured_frame: {part: cabin, offset_m: [0, 0, -2]}\n");
  const double y = 5 - 2 * 0.17364817766693033, z = 150 + 2 * 0.984807753012208;
  // fast_feed.yaml: the platform rolled 10 deg with the rotator at a = 10 deg, so the cabin
  // is level: p_c = m - R_c t - R_m d = (0, 0, 140) + (0, 0, 0.8) + 1.2 (0, -sin 10, cos 10).
  const double feed_y = -1.2 * 0.17364817766693033, feed_z = 140.8 + 1.2 * 0.984807753012208;
  char hand_cabin[128], hand_feed[128];
  std::snprintf(hand_cabin, sizeof(hand_cabin), "10,%.17g,%.17g --rpy=10,0,0", y, z);
  std::snprintf(hand_feed, sizeof(hand_feed), "0,%.17g,%.17g --rpy=0,0,0", feed_y, feed_z);
  const std::vector<Case> cases = {
      {Path("cabin_frame.yaml"), "", "10,5,150 --rpy=10,0,0", hand_cabin, "", {10, y, z}},
      {FeedModel(),
       PlainFeedModel(),
       "0,0,140 --rpy=10,0,0",
       hand_feed,
       " --joints=10,0,0,0,0",
       {0, feed_y, feed_z}},
  };
  for (const Case& c : cases) {
    const CommandResult framed =
        Fastcal("solve --model=" + c.framed + " --position=" + c.given + c.joints);
    ASSERT_EQ(framed.code, 0) << framed.output;
    const CommandResult plain = Fastcal("solve" + (c.plain.empty() ? "" : " --model=" + c.plain) +
                                        " --position=" + c.hand + c.joints);
    ASSERT_EQ(plain.code, 0) << plain.output;
    for (int i = 1; i <= 6; ++i) {
      const std::string t = "T" + std::to_string(i) + "_kN";
      EXPECT_NEAR(Column(framed.output, t), Column(plain.output, t),
                  kRelTol * Column(plain.output, t))
          << c.framed << " " << t;
    }
    const char* axes[] = {"cabin_x_m", "cabin_y_m", "cabin_z_m"};
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(Column(framed.output, axes[k]), c.cabin[k], 1e-8) << c.framed << " " << axes[k];
    }
    // The given pose stays in x_m.., and the summary names the frame.
    EXPECT_NE(framed.output.find("poses of the measured frame"), std::string::npos)
        << framed.output;
    EXPECT_EQ(plain.output.find("cabin_x_m"), std::string::npos) << plain.output;
  }
}

TEST_F(CliMeasuredFrameTest, ASurveyWithALeverArmAndTheRotatorIsCalibratedToItsTruth) {
  constexpr double kSigmas = 2.5;       // the issue's bound, per estimate
  constexpr double kPriorSigmaM = 0.2;  // the spec's prior on each offset component
  // 432 random poses up to 40 deg off axis, the rotator following the pointing (the feed
  // axis along the focal sphere's radius), the phase centre 2 m below the anchor plane.
  const CommandResult sim = Fastcal(
      "simulate --truth=" + FeedModel() +
      " --trajectory=random --max-off-axis-deg=40 --samples=432 --seed=21 --joint-law=focal "
      "--prismatic-spread-m=0.05 --interval-s=10 --mass-centre=0.22,0.11,0.5 "
      "--tension-noise-percent=3 --sensor-gain-spread-percent=1 --sensor-bias-spread-kN=1.5 "
      "--out=" +
      Path("survey.csv") + " --force");
  ASSERT_EQ(sim.code, 0) << sim.output;
  // From the drawings' offset, 20 cm off the truth, with the prior centred there.
  std::string start = ReadFile(FeedModel());
  start = std::regex_replace(start, std::regex(R"(offset_m: \[0, 0, -1.2\])"),
                             "offset_m: [0, 0, -1.0]");
  Write("start.yaml", start);
  std::string spec = ReadFile(Source() + "/calibration_data/spec_measured_frame.yaml");
  spec =
      std::regex_replace(spec, std::regex(R"(mean: -1.2, sigma: 0.2)"), "mean: -1.0, sigma: 0.2");
  Write("spec.yaml", spec);
  const CommandResult cal =
      Fastcal("calibrate --spec=" + Path("spec.yaml") + " --model=" + Path("start.yaml") +
              " --data=" + Path("survey.csv") + " --out=" + Path("cal") + " --force");
  ASSERT_EQ(cal.code, 0) << cal.output;
  EXPECT_NE(cal.output.find("verdict: ok"), std::string::npos) << cal.output;
  const char axes[] = "xyz";
  const double centre[] = {0.22, 0.11, 0.5}, offset[] = {0, 0, -1.2};
  for (int a = 0; a < 3; ++a) {
    double v = 0, s = 0;
    ConsoleEstimate(cal.output, std::string("mass_centre_m.") + axes[a], &v, &s);
    EXPECT_LT(std::abs(v - centre[a]), kSigmas * s) << axes[a];
    ConsoleEstimate(cal.output, std::string("measured_frame.offset_m.") + axes[a], &v, &s);
    EXPECT_LT(std::abs(v - offset[a]), kSigmas * s) << axes[a];
    // Estimated, not just held: the survey narrows the prior.
    EXPECT_LT(s, 0.9 * kPriorSigmaM) << axes[a];
  }
  // The report and summary.json say which frame the data are in.
  const std::string summary = ReadFile(Path("cal/summary.json"));
  EXPECT_NE(summary.find("\"data_frame\": {"), std::string::npos);
  EXPECT_NE(summary.find("\"part\": \"stewart\""), std::string::npos);
  EXPECT_NE(ReadFile(Path("cal/report.html")).find("stewart&apos;s frame"), std::string::npos);
  // The calibrated model carries the estimated offset.
  EXPECT_EQ(ReadFile(Path("cal/model_calibrated.yaml")).find("offset_m: [0, 0, -1]"),
            std::string::npos);
}

TEST_F(CliMeasuredFrameTest, LocateGivesTheDataFramesPoseAndTheCabins) {
  constexpr double kRoundTripM = 1e-5;  // locate's tolerance on simulate's own lengths
  const CommandResult sim =
      Fastcal("simulate --truth=" + FeedModel() +
              " --trajectory=random --max-off-axis-deg=30 --samples=8 --seed=22 "
              "--joint-law=focal --tension-noise-percent=0 --out=" +
              Path("survey.csv") + " --force");
  ASSERT_EQ(sim.code, 0) << sim.output;
  const CommandResult located =
      Fastcal("locate --model=" + FeedModel() + " --data=" + Path("survey.csv") +
              " --use=lengths --output=" + Path("located.csv"));
  ASSERT_EQ(located.code, 0) << located.output;
  const std::regex rms(R"(against the file's x_m,y_m,z_m: RMS (\S+) m)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(located.output, m, rms)) << located.output;
  EXPECT_LT(std::stod(m[1]), kRoundTripM) << located.output;
  const std::string csv = ReadFile(Path("located.csv"));
  EXPECT_NE(csv.find("yaw_deg,cabin_x_m,cabin_y_m,cabin_z_m,cabin_roll_deg"), std::string::npos);
  // The cabin is 2 m or so from the phase centre.
  const double dx = Column(csv, "x_m") - Column(csv, "cabin_x_m"),
               dy = Column(csv, "y_m") - Column(csv, "cabin_y_m"),
               dz = Column(csv, "z_m") - Column(csv, "cabin_z_m");
  EXPECT_NEAR(std::sqrt(dx * dx + dy * dy + dz * dz), 2.0, 0.1);
}

TEST_F(CliMeasuredFrameTest, TheBundledFeedExportIsReadAsTheFeeds) {
  const std::string data = Source() + "/calibration_data/";
  const CommandResult cal =
      Fastcal("calibrate --spec=" + data + "spec_measured_frame.yaml --model=" + data +
              "fast_feed.yaml --columns=" + data + "fast_feed_export.columns.yaml --data=" + data +
              "fast_feed_export.csv --out=" + Path("feed") + " --force");
  ASSERT_EQ(cal.code, 0) << cal.output;
  EXPECT_NE(cal.output.find("verdict: ok"), std::string::npos) << cal.output;
  // The same numbers as the canonical survey it was exported from.
  const CommandResult canonical =
      Fastcal("calibrate --spec=" + data + "spec_measured_frame.yaml --model=" + data +
              "fast_feed.yaml --data=" + data + "fast_feed_survey.csv --out=" + Path("canonical") +
              " --force");
  ASSERT_EQ(canonical.code, 0) << canonical.output;
  double a = 0, sa = 0, b = 0, sb = 0;
  ConsoleEstimate(cal.output, "measured_frame.offset_m.z", &a, &sa);
  ConsoleEstimate(canonical.output, "measured_frame.offset_m.z", &b, &sb);
  EXPECT_EQ(a, b);
  EXPECT_EQ(sa, sb);
}

TEST_F(CliMeasuredFrameTest, ATrackOfTheFeedsDataFindsTheMassCentreEachDay) {
  constexpr double kSigmas = 2.5;
  // Two days of the feed's telemetry, the measured frame's offset shared by the season.
  const CommandResult sim = Fastcal(
      "simulate --truth=" + FeedModel() +
      " --trajectory=random --max-off-axis-deg=40 --samples=400 --seed=23 --joint-law=focal "
      "--interval-s=10 --days=2 --start=2024-05-01T20:00:00Z --mass-centre=0.22,0.11,0.5 "
      "--tension-noise-percent=3 --out=" +
      Path("season.csv") + " --force");
  ASSERT_EQ(sim.code, 0) << sim.output;
  std::string spec = ReadFile(Source() + "/calibration_data/spec_track.yaml");
  spec = std::regex_replace(spec, std::regex("\nsessions:"),
                            "\n  measured_frame:\n    offset_m:\n"
                            "      x: {free: true, prior: {mean: 0, sigma: 0.2}}\n"
                            "      y: {free: true, prior: {mean: 0, sigma: 0.2}}\n"
                            "      z: {free: true, prior: {mean: -1.2, sigma: 0.2}}\nsessions:");
  Write("spec.yaml", spec);
  const CommandResult track =
      Fastcal("track --spec=" + Path("spec.yaml") + " --model=" + FeedModel() +
              " --data=" + Path("season.csv") + " --out=" + Path("track"));
  ASSERT_EQ(track.code, 0) << track.output;
  // Each day's mass centre, from track.csv: estimate and sigma_total columns by name.
  const std::string csv = ReadFile(Path("track/track.csv"));
  std::vector<std::string> lines;
  for (size_t at = 0, end; at < csv.size(); at = end + 1) {
    end = csv.find('\n', at);
    if (end == std::string::npos) end = csv.size();
    if (csv[at] != '#') lines.push_back(csv.substr(at, end - at));
  }
  ASSERT_GE(lines.size(), 3u) << csv;
  const std::vector<std::string> header = CsvFields(lines[0]);
  const char axes[] = "xyz";
  const double truth[] = {0.22, 0.11, 0.5};
  for (size_t row = 1; row < lines.size(); ++row) {
    const std::vector<std::string> f = CsvFields(lines[row]);
    for (int a = 0; a < 3; ++a) {
      const std::string name = std::string("mass_centre_m.") + axes[a];
      double value = NAN, sigma = NAN;
      for (size_t k = 0; k < header.size() && k < f.size(); ++k) {
        if (header[k] == name) value = std::stod(f[k]);
        if (header[k] == name + "_sigma_total") sigma = std::stod(f[k]);
      }
      ASSERT_TRUE(std::isfinite(value) && std::isfinite(sigma)) << lines[0];
      EXPECT_LT(std::abs(value - truth[a]), kSigmas * sigma) << "day " << row << " " << axes[a];
    }
  }
  EXPECT_NE(ReadFile(Path("track/track.html")).find("cabin.measured_frame)"), std::string::npos);
}

TEST_F(CliMeasuredFrameTest, RefusalsNameWhatToDeclare) {
  const std::string data = Source() + "/calibration_data/";
  // An offset to calibrate in a model that declares no frame: the spec's key and line.
  RunBoundedAndExpect({"calibrate --spec=" + data + "spec_measured_frame.yaml --data=" + data +
                           "realistic_survey.csv --out=" + Path("x"),
                       2, "parameters.measured_frame: the model declares no measured frame"});
  // A pose file of the frame's poses without the joints its part needs.
  Write("poses.csv", "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,140,0,0,0\n");
  RunBoundedAndExpect({"simulate --truth=" + FeedModel() + " --poses=" + Path("poses.csv") +
                           " --out=" + Path("sim.csv"),
                       2, "the file needs the joint columns (rotator_a_deg,rotator_b_deg,"});
  // A model naming a part it does not have.
  Write("bad.yaml", "format: fastcal-model-1\ncabin:\n  measured_frame: {part: stewart}\n");
  RunBoundedAndExpect({"solve --model=" + Path("bad.yaml") + " --position=0,0,140", 2,
                       "bad.yaml:3: cabin.measured_frame.part: 'stewart' is not a moving part"});
  Write("nan.yaml",
        "format: fastcal-model-1\ncabin:\n  measured_frame: {offset_m: [0, .nan, 0]}\n");
  RunBoundedAndExpect({"solve --model=" + Path("nan.yaml") + " --position=0,0,140", 2,
                       "nan.yaml:3: cabin.measured_frame.offset_m[1]: must be finite"});
}

}  // namespace
}  // namespace fastcal::test
