// End-to-end tests of `fastcal modes` (apps/modes_command.cc): the CSV and its summary,
// atomic output and --force, and bad input named by its flag with exit 2 (no output) or a
// pose without equilibrium with exit 1.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"
#include "fastcal/modal_identification.h"
#include "fastcal/modes.h"
#include "fastcal/statics.h"
#include "fastcal/subspace_identification.h"

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

// A record of the cabin's vibration at 40 deg off axis, made here from the predicted modes
// 2, 7 and 18 of a model whose cables are `density_factor` times as dense, damping
// 0.5-1.5%, noise 2 mm, 0.005 deg and 0.5 kN: a free decay at 10 Hz for 400 s, or
// (`ambient`) the modes driven by white noise at 2 Hz for an hour (each mode's spread 5 cm,
// the tensions' 0.5 kN under noise of 5 kN). Canonical dataset CSV.
std::string DecayRecordCsv(double density_factor, bool ambient = false) {
  CableRobot truth = CableRobot::NominalFast();
  for (CableProperties& c : truth.cables) c.linear_density_kg_per_m *= density_factor;
  Pose pose;
  pose.position_m = Eigen::Vector3d(102.846, 0.0, 177.433);
  pose.rotation = FocalAttitude(pose.position_m, FocalAttitudeLaw());
  ModesResult predicted;
  std::string error;
  EXPECT_TRUE(ComputeModes(truth, pose, ModesOptions(), &predicted, &error)) << error;
  FreeDecaySpec spec;
  const int picked[3] = {1, 6, 17};
  spec.shape.resize(12, 3);
  for (int j = 0; j < 3; ++j) {
    const Mode& m = predicted.modes[picked[j]];
    spec.frequency_hz.push_back(m.frequency_hz);
    spec.damping_ratio.push_back(0.005 * (j + 1));
    spec.phase_rad.push_back(j);
    const double scale = 0.05 / m.cabin_shape.head<3>().cwiseAbs().maxCoeff();
    spec.shape.col(j).head<3>() = scale * m.cabin_shape.head<3>();
    spec.shape.col(j).segment<3>(3) = scale * 180.0 / M_PI * m.cabin_shape.tail<3>();
    for (int i = 0; i < 6; ++i) spec.shape(6 + i, j) = 5.0 * std::sin(1.0 + i + 2.0 * j);
  }
  spec.noise_sigma.resize(12);
  spec.noise_sigma << 0.002, 0.002, 0.002, 0.005, 0.005, 0.005, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5;
  VibrationRecord record;
  if (ambient) {
    AmbientRecordSpec a;
    a.frequency_hz = spec.frequency_hz;
    a.damping_ratio = spec.damping_ratio;
    a.shape = spec.shape;
    a.noise_sigma = spec.noise_sigma;
    // The tensions swing by ~0.5 kN under the sensors' 3% noise (5 kN), as in the wind.
    a.shape.bottomRows(6) *= 0.1;
    a.noise_sigma.tail(6).setConstant(5.0);
    a.duration_s = 3600.0;
    EXPECT_TRUE(SimulateAmbientRecord(a, &record, &error)) << error;
  } else {
    EXPECT_TRUE(SimulateFreeDecay(spec, &record, &error)) << error;
  }
  StaticsSolution statics;
  SolveStatics(truth, pose, StaticsOptions(), &statics);
  const Eigen::Vector3d rpy = RpyDegFromRotation(pose.rotation);
  std::ostringstream csv;
  csv.precision(10);
  csv << "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n";
  for (int k = 0; k < record.channels.cols(); ++k) {
    csv << k * record.sample_interval_s;
    for (int c = 0; c < 12; ++c) {
      const double base = c < 3   ? pose.position_m[c]
                          : c < 6 ? rpy[c - 3]
                                  : statics.cables[c - 6].lower_tension_n / 1e3;
      csv << "," << base + record.channels(c, k);
    }
    csv << "\n";
  }
  return csv.str();
}

// --data: the record's three modes identified, each matched to the predicted mode it was
// made from; a record of the nominal model agrees with it, one whose cables are 3% denser
// points to the density (+3% within its 1% here).
TEST_F(CliTest, ModesDataIdentifiesAndComparesWithThePrediction) {
  Write("nominal.csv", DecayRecordCsv(1.0));
  Write("dense.csv", DecayRecordCsv(1.03));
  const std::string out = Path("identified.csv");
  CommandResult r = Fastcal("modes --data=" + Path("nominal.csv") + " --output=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("the record agrees with the model"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(ERA, chosen:"), std::string::npos) << r.output;
  std::istringstream lines(ReadFile(out));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(CsvFields(line)[2], "frequency_sigma_hz") << line;
  const char* predicted[3] = {"2", "7", "18"};
  for (int j = 0; j < 3; ++j) {
    ASSERT_TRUE(std::getline(lines, line));
    EXPECT_EQ(CsvFields(line)[5], predicted[j]) << line;
  }
  r = Fastcal("modes --data=" + Path("dense.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("disagrees"), std::string::npos) << r.output;
  const size_t density = r.output.find("linear_density ");
  ASSERT_NE(density, std::string::npos) << r.output;
  EXPECT_NEAR(std::stod(r.output.substr(density + 15)), 3.0, 1.0) << r.output;
  EXPECT_NE(r.output.find("the best single explanation", density), std::string::npos);
  EXPECT_LT(r.output.find("the best single explanation", density),
            r.output.find("cabin_mass", density));
  RunBoundedAndExpect({"modes --data=" + Path("nominal.csv") + " --position=0,0,140", 2,
                       "does not apply to --data"});
}

// An ambient record (no free decay): --identification=auto takes SSI for it (the
// envelope does not fall) and finds the same three modes (the free decays above take
// ERA); --identification names its bad values.
TEST_F(CliTest, ModesDataTakesSsiForAnAmbientRecord) {
  Write("ambient.csv", DecayRecordCsv(1.0, true));
  const std::string out = Path("identified.csv");
  CommandResult r = Fastcal("modes --data=" + Path("ambient.csv") + " --output=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("(SSI-cov, chosen:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("an ambient record"), std::string::npos) << r.output;
  std::istringstream lines(ReadFile(out));
  std::string line;
  std::getline(lines, line);
  const char* predicted[3] = {"2", "7", "18"};
  for (int j = 0; j < 3; ++j) {
    ASSERT_TRUE(std::getline(lines, line));
    const std::vector<std::string> f = CsvFields(line);
    EXPECT_EQ(f[5], predicted[j]) << line;
    EXPECT_LT(std::abs(std::stod(f[8])), 1.0) << line;  // difference_percent
  }
  RunBoundedAndExpect({"modes --data=" + Path("ambient.csv") +
                           " --identification=fdd --output=" + Path("never.csv"),
                       2, "--identification=fdd"});
  EXPECT_FALSE(fs::exists(Path("never.csv")));
}

// simulate --vibration writes a record modes --data identifies: the excited modes back.
TEST_F(CliTest, SimulateVibrationRoundTripsThroughModesData) {
  const std::string record = Path("record.csv"), out = Path("identified.csv");
  CommandResult r = Fastcal(
      "simulate --vibration --position=102.846,0,177.433 --attitude-law=focal --excite=2,7,18 "
      "--damping=0.005,0.01,0.015 --position-noise-m=0.002 --attitude-noise-deg=0.005 "
      "--tension-noise-kN=0.5 --segments=24 --out=" +
      record);
  ASSERT_EQ(r.code, 0) << r.output;
  r = Fastcal("modes --data=" + record + " --segments=24 --output=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  std::istringstream lines(ReadFile(out));
  std::string line;
  std::getline(lines, line);
  const char* predicted[3] = {"2", "7", "18"};
  const double damping[3] = {0.005, 0.01, 0.015};
  for (int j = 0; j < 3; ++j) {
    ASSERT_TRUE(std::getline(lines, line));
    const std::vector<std::string> f = CsvFields(line);
    EXPECT_EQ(f[5], predicted[j]) << line;
    EXPECT_NEAR(std::stod(f[3]) / damping[j], 1.0, 0.25) << line;
    EXPECT_LT(std::abs(std::stod(f[8])), 1.0) << line;  // difference_percent
  }
  RunBoundedAndExpect({"simulate --vibration --trajectory=line --out=" + Path("x.csv"), 2,
                       "--trajectory does not apply to --vibration"});
  RunBoundedAndExpect(
      {"simulate --excite=1 --out=" + Path("x.csv"), 2, "--excite applies to --vibration only"});
  RunBoundedAndExpect(
      {"simulate --vibration --position=0,0,140 --excite=1,2 --damping=0.01 "
       "--out=" +
           Path("x.csv"),
       2, "--damping gives 1 ratios for 2 --excite modes"});
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
