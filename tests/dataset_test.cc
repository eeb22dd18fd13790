// Tests of the measurement dataset CSV reader and writer
// (fastcal/dataset.h, docs/data-format.md).
#include "fastcal/dataset.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bounded_process.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

// Success when `text` contains `part`; the failure shows both.
::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

// Attitudes converted through a quaternion or angles agree to rounding only.
constexpr double kRotationTolerance = 1e-12;
// Thirteen columns: the required ones, attitude as angles.
constexpr char kHeader[] =
    "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n";
constexpr char kRow[] = "0.5,1,2,140,0.1,0.2,0.3,150,151,152,153,154,155\n";

class DatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "dataset_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  std::string PathOf(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> DirEntries() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }
  void WriteText(const std::string& name, const std::string& text) const {
    std::ofstream(PathOf(name), std::ios::binary) << text;
  }

  fs::path dir_;
};

// Parses `text` as "data.csv"; the error message of a failure, or "" on success.
std::string ParseError(const std::string& text, bool skip = false) {
  Dataset dataset;
  std::string error;
  DatasetReadOptions options;
  options.skip_invalid_rows = skip;
  if (ParseDataset(text, "data.csv", options, &dataset, &error)) return "";
  return error;
}

Dataset ParseOk(const std::string& text, bool skip = false) {
  Dataset dataset;
  std::string error;
  DatasetReadOptions options;
  options.skip_invalid_rows = skip;
  EXPECT_TRUE(ParseDataset(text, "data.csv", options, &dataset, &error)) << error;
  return dataset;
}

void ExpectMatrixEq(const Eigen::Matrix3d& expected, const Eigen::Matrix3d& actual) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(expected(r, c), actual(r, c)) << r << "," << c;
  }
}

void ExpectSamplesEqual(const Sample& expected, const Sample& actual, bool quaternion, bool planned,
                        bool unstretched) {
  EXPECT_EQ(expected.time_s, actual.time_s);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(expected.pose.position_m[k], actual.pose.position_m[k]);
  ExpectMatrixEq(expected.pose.rotation, actual.pose.rotation);
  if (quaternion) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(expected.measured_quaternion_wxyz[k], actual.measured_quaternion_wxyz[k]);
    }
  } else {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(expected.measured_rpy_deg[k], actual.measured_rpy_deg[k]);
  }
  EXPECT_EQ(actual.has_planned_attitude, planned);
  if (planned) {
    ExpectMatrixEq(expected.planned_rotation, actual.planned_rotation);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(expected.planned_rpy_deg[k], actual.planned_rpy_deg[k]);
  }
  for (int i = 0; i < kNumCables; ++i) EXPECT_EQ(expected.tension_n[i], actual.tension_n[i]);
  EXPECT_EQ(actual.has_unstretched_lengths, unstretched);
  if (unstretched) {
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(expected.unstretched_length_m[i], actual.unstretched_length_m[i]);
    }
  }
}

// A random dataset with full-precision values, as a telemetry export would never give
// them: the hardest case for an exact round trip.
Dataset RandomDataset(unsigned seed, bool quaternion, bool optional_columns, int rows) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> position(-100.0, 100.0);
  std::uniform_real_distribution<double> height(100.0, 170.0);
  std::uniform_real_distribution<double> angle(-15.0, 15.0);
  std::uniform_real_distribution<double> tension(20e3, 400e3);
  std::uniform_real_distribution<double> length(200.0, 420.0);
  std::normal_distribution<double> normal;
  Dataset dataset;
  dataset.attitude_as_quaternion = quaternion;
  dataset.has_planned_attitude = optional_columns;
  dataset.has_unstretched_lengths = optional_columns;
  for (int n = 0; n < rows; ++n) {
    Sample s;
    s.time_s = 0.1 * n + 1e-3 * normal(rng);
    s.pose.position_m = Eigen::Vector3d(position(rng), position(rng), height(rng));
    if (quaternion) {
      Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
      q.normalize();
      s.measured_quaternion_wxyz = q;
      std::string error;
      EXPECT_TRUE(RotationFromQuaternion(q[0], q[1], q[2], q[3], &s.pose.rotation, &error));
    } else {
      s.measured_rpy_deg = Eigen::Vector3d(angle(rng), angle(rng), 12.0 * angle(rng));
      s.pose.rotation =
          RotationFromRpyDeg(s.measured_rpy_deg[0], s.measured_rpy_deg[1], s.measured_rpy_deg[2]);
    }
    if (optional_columns) {
      s.has_planned_attitude = true;
      s.planned_rpy_deg = Eigen::Vector3d(angle(rng), angle(rng), angle(rng));
      s.planned_rotation =
          RotationFromRpyDeg(s.planned_rpy_deg[0], s.planned_rpy_deg[1], s.planned_rpy_deg[2]);
      s.has_unstretched_lengths = true;
      for (double& l : s.unstretched_length_m) l = length(rng);
    }
    for (double& t : s.tension_n) t = tension(rng);
    dataset.samples.push_back(s);
  }
  return dataset;
}

TEST_F(DatasetTest, ReadsRowsAndConvertsKilonewtonsToNewtons) {
  const Dataset d = ParseOk(std::string(kHeader) + kRow);
  ASSERT_EQ(d.samples.size(), 1u);
  const Sample& s = d.samples[0];
  EXPECT_EQ(d.path, "data.csv");
  EXPECT_FALSE(d.attitude_as_quaternion);
  EXPECT_FALSE(d.has_planned_attitude);
  EXPECT_FALSE(d.has_unstretched_lengths);
  EXPECT_TRUE(d.skipped.empty());
  EXPECT_EQ(s.line, 2);
  EXPECT_EQ(s.time_s, 0.5);
  EXPECT_EQ(s.pose.position_m, Eigen::Vector3d(1, 2, 140));
  ExpectMatrixEq(RotationFromRpyDeg(0.1, 0.2, 0.3), s.pose.rotation);
  for (int i = 0; i < kNumCables; ++i) EXPECT_EQ(s.tension_n[i], (150.0 + i) * 1000.0) << i;
  EXPECT_FALSE(s.has_planned_attitude);
  EXPECT_FALSE(s.has_unstretched_lengths);
}

TEST_F(DatasetTest, KilonewtonConversionIsTheCorrectlyRoundedDecimal) {
  // 159.17 kN is 159170 N exactly; 0.1 kN is 100 N exactly, although 0.1 * 1000 in
  // binary is not guaranteed to be; exponent forms are shifted too.
  const Dataset d =
      ParseOk(std::string(kHeader) + "0,0,0,140,0,0,0,159.17,0.1,1.5e2,2E-1,+7,0.000123456789\n");
  ASSERT_EQ(d.samples.size(), 1u);
  const auto& t = d.samples[0].tension_n;
  EXPECT_EQ(t[0], 159170.0);
  EXPECT_EQ(t[1], 100.0);
  EXPECT_EQ(t[2], 150000.0);
  EXPECT_EQ(t[3], 200.0);
  EXPECT_EQ(t[4], 7000.0);
  EXPECT_EQ(t[5], 0.123456789);
}

TEST_F(DatasetTest, ReadsQuaternionAttitude) {
  const double half = 15.0 * M_PI / 180.0;  // 30 deg about z
  std::ostringstream text;
  text.precision(17);
  text << "time_s,x_m,y_m,z_m,qw,qx,qy,qz,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n"
       << "0,1,2,3," << std::cos(half) << ",0,0," << std::sin(half) << ",1,2,3,4,5,6\n";
  const Dataset d = ParseOk(text.str());
  ASSERT_EQ(d.samples.size(), 1u);
  EXPECT_TRUE(d.attitude_as_quaternion);
  const Eigen::Matrix3d expected =
      Eigen::AngleAxisd(2.0 * half, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((d.samples[0].pose.rotation - expected).cwiseAbs().maxCoeff(), kRotationTolerance);
  EXPECT_EQ(d.samples[0].measured_quaternion_wxyz[3], std::sin(half));
}

TEST_F(DatasetTest, ColumnsInAnyOrder) {
  const std::string text =
      "s0_6_m,T6_kN,qz,planned_yaw_deg,z_m,s0_5_m,T5_kN,qy,planned_pitch_deg,y_m,s0_4_m,"
      "T4_kN,qx,planned_roll_deg,x_m,s0_3_m,T3_kN,qw,time_s,s0_2_m,T2_kN,s0_1_m,T1_kN\n"
      "306,16,0,3,140,305,15,0,2,-20,304,14,0,1,10,303,13,1,7.25,302,12,301,11\n";
  const Dataset d = ParseOk(text);
  ASSERT_EQ(d.samples.size(), 1u);
  EXPECT_TRUE(d.attitude_as_quaternion);
  EXPECT_TRUE(d.has_planned_attitude);
  EXPECT_TRUE(d.has_unstretched_lengths);
  const Sample& s = d.samples[0];
  EXPECT_EQ(s.time_s, 7.25);
  EXPECT_EQ(s.pose.position_m, Eigen::Vector3d(10, -20, 140));
  ExpectMatrixEq(Eigen::Matrix3d::Identity(), s.pose.rotation);
  ASSERT_TRUE(s.has_planned_attitude);
  ExpectMatrixEq(RotationFromRpyDeg(1, 2, 3), s.planned_rotation);
  EXPECT_EQ(s.planned_rpy_deg, Eigen::Vector3d(1, 2, 3));
  ASSERT_TRUE(s.has_unstretched_lengths);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_EQ(s.tension_n[i], (11.0 + i) * 1000.0) << i;
    EXPECT_EQ(s.unstretched_length_m[i], 301.0 + i) << i;
  }
}

TEST_F(DatasetTest, SkipsCommentsBlankLinesAndCarriageReturns) {
  const std::string text = std::string("\xEF\xBB\xBF# exported 2024-05-01\r\n") +  // BOM
                           "\n"
                           "   # indented comment\n" +
                           " time_s , x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,"
                           "T4_kN,T5_kN,T6_kN\r\n" +
                           "\t\n" + kRow + "# between rows\n" +
                           "1.5, 1 ,2,140,0.1,0.2,0.3,150,151,152,153,154,155\r\n" + "\n";
  const Dataset d = ParseOk(text);
  ASSERT_EQ(d.samples.size(), 2u);
  EXPECT_EQ(d.samples[0].line, 6);
  EXPECT_EQ(d.samples[1].line, 8);
  EXPECT_EQ(d.samples[1].time_s, 1.5);
  EXPECT_EQ(d.samples[1].tension_n[5], 155000.0);
}

struct ErrorCase {
  const char* name;
  std::string text;
  std::vector<std::string> expected;  // substrings of the message
};

TEST_F(DatasetTest, ErrorsNameFileLineAndColumn) {
  const std::string comments = "# telemetry\n#\n\n";  // the header is on line 4
  const std::string header = comments + kHeader;
  const std::string rows = header + kRow + kRow;  // data on lines 5 and 6
  const std::string q_header =
      "time_s,x_m,y_m,z_m,qw,qx,qy,qz,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n";
  const std::vector<ErrorCase> cases = {
      {"not a number",
       rows + "0,1,2,140,0,0,0,150,151,abc,153,154,155\n",
       {"data.csv:7: column 'T3_kN': 'abc' is not a number"}},
      {"trailing junk",
       rows + "0,1,2,140,0,0,0,150,151,152,153,154,155kN\n",
       {"data.csv:7: column 'T6_kN': '155kN' is not a number"}},
      {"infinite",
       rows + "0,1,2,140,0,0,0,150,151,inf,153,154,155\n",
       {"data.csv:7: column 'T3_kN': value is not finite"}},
      {"nan",
       header + "0,nan,2,140,0,0,0,150,151,152,153,154,155\n",
       {"data.csv:5: column 'x_m': value is not finite"}},
      {"empty field",
       header + "0,1,2,140,0,,0,150,151,152,153,154,155\n",
       {"data.csv:5: column 'pitch_deg': missing value"}},
      {"too few fields",
       rows + "0,1,2,140,0,0,0,150,151,152,153,154\n",
       {"data.csv:7: expected 13 fields (as in the header), found 12"}},
      {"too many fields",
       header + "0,1,2,140,0,0,0,150,151,152,153,154,155,\n",
       {"data.csv:5: expected 13 fields (as in the header), found 14 (a comma at the end?)"}},
      {"decimal comma",
       header + "0,1,2,140,0,0,0,150,151,152,153,154,155\n" +
           "0,1,2,140,0,0,0,150,151,244,5,153,154,155\n",
       {"data.csv:6: expected 13 fields (as in the header), found 14: a decimal comma? '244,5' "
        "in column 'T3_kN' reads as two fields; numbers must use '.' as the decimal point"}},
      {"hexadecimal",
       header + "0,0x10,2,140,0,0,0,150,151,152,153,154,155\n",
       {"data.csv:5: column 'x_m': '0x10' is not a decimal number (hexadecimal is not "
        "accepted)"}},
      {"negative tension",
       header + "0,1,2,140,0,0,0,150,151,152,153,-154,155\n",
       {"data.csv:5: column 'T5_kN': -154 kN is negative: a tension reading is >= 0"}},
      {"implausible tension",
       header + "0,1,2,140,0,0,0,150,151,1e30,153,154,155\n",
       {"data.csv:5: column 'T3_kN': 1e+30 kN is above the plausible maximum of 5000 kN"}},
      {"tension a hair above the maximum",  // 5e6 N once shifted: decided in kN as read
       header + "0,1,2,140,0,0,0,150,151,5000.00000000000046,153,154,155\n",
       {"data.csv:5: column 'T3_kN': 5000 kN is above the plausible maximum of 5000 kN"}},
      {"tension near the largest double",
       header + "0,1,2,140,0,0,0,150,151,1e308,153,154,155\n",
       {"data.csv:5: column 'T3_kN': 1e+308 kN is above the plausible maximum of 5000 kN"}},
      {"position below the reflector",
       header + "0,0,0,-50,0,0,0,150,151,152,153,154,155\n",
       {"data.csv:5: columns 'x_m,y_m,z_m': z = -50 m is below the reflector (z >= 0 m at 0 "
        "m from the axis)"}},
      {"position outside the towers",
       header + "0,400,0,150,0,0,0,150,151,152,153,154,155\n",
       {"data.csv:5: columns 'x_m,y_m,z_m': the position is 400 m from the axis, beyond the "
        "ring of towers (at most 350 m)"}},
      {"position above the towers",
       header + "0,0,0,1e308,0,0,0,150,151,152,153,154,155\n",
       {"data.csv:5: columns 'x_m,y_m,z_m': z = 1e+308 m is above the tower tops (at most 300 "
        "m)"}},
      {"implausible angle",
       header + "0,1,2,140,0,0,1e300,150,151,152,153,154,155\n",
       {"data.csv:5: column 'yaw_deg': 1e+300 deg is beyond the plausible +-360 deg"}},
      {"control bytes and a long name in the header",
       "time_s,x_m,\x1b[2J" + std::string(200, 'a') + "\n",
       {"data.csv:1: unknown column '\\x1b[2J" + std::string(60, 'a') +
        "'... (204 bytes) "
        "(accepted:"}},
      {"non-unit quaternion",
       q_header + "0,1,2,140,1,0.1,0,0,1,2,3,4,5,6\n",
       {"data.csv:2: ", "qw,qx,qy,qz", "must be unit"}},
      {"missing column",
       "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,"
       "T5_kN,T6_kN\n" +
           std::string(kRow),
       {"data.csv:1: missing column 'T4_kN'"}},
      {"missing column after comments",
       comments + "time_s,y_m,z_m\n",
       {"data.csv:4: missing column 'x_m'"}},
      {"unknown column",
       "T7_kN," + std::string(kHeader) + "1," + kRow,
       {"data.csv:1: unknown column 'T7_kN' (accepted: time_s, x_m,", "T6_kN", "s0_6_m"}},
      {"time beyond any telemetry",
       std::string(kHeader) + "1e300" + std::string(kRow).substr(std::string(kRow).find(',')),
       {"column 'time_s': 1e+300 s is beyond any time of a telescope's telemetry"}},
      {"unknown column typo",
       comments + "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw,T1_kN\n",
       {"data.csv:4: unknown column 'yaw' (accepted:"}},
      {"duplicate column",
       "time_s,x_m," + std::string(kHeader),
       {"data.csv:1: duplicate column 'time_s' (fields 1 and 3)"}},
      {"empty column name", "time_s,,x_m\n", {"data.csv:1: empty column name in field 2"}},
      {"semicolon separator",
       comments + "time_s;x_m;y_m;z_m;roll_deg;pitch_deg;yaw_deg;T1_kN\n",
       {"data.csv:4: the header is separated by ';': fields must be separated by commas"}},
      {"tab separator",
       "time_s\tx_m\ty_m\tz_m\n",
       {"data.csv:1: the header is separated by tabs: fields must be separated by commas"}},
      {"no attitude",
       "time_s,x_m,y_m,z_m,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n",
       {"data.csv:1: missing measured attitude"}},
      {"two attitudes",
       "qw,qx,qy,qz," + std::string(kHeader),
       {"data.csv:1: measured attitude given twice"}},
      {"partial angles",
       "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,T1_kN\n",
       {"data.csv:1: missing column 'yaw_deg'"}},
      {"partial quaternion",
       "time_s,x_m,y_m,z_m,qw,qx,qz,T1_kN\n",
       {"data.csv:1: missing column 'qy'"}},
      {"partial planned attitude",
       "planned_roll_deg,planned_yaw_deg," + std::string(kHeader),
       {"data.csv:1: missing column 'planned_pitch_deg' (the planned attitude needs all three"}},
      {"partial unstretched lengths",
       "s0_1_m,s0_2_m," + std::string(kHeader),
       {"data.csv:1: missing columns 's0_3_m', 's0_4_m', 's0_5_m', 's0_6_m' (the unstretched "
        "lengths need all six"}},
      {"non-positive unstretched length",
       "s0_1_m,s0_2_m,s0_3_m,s0_4_m,s0_5_m,s0_6_m," + std::string(kHeader) +
           "300,300,300,300,-1,300," + kRow,
       {"data.csv:2: column 's0_5_m': unstretched length must be > 0"}},
  };
  for (const ErrorCase& c : cases) {
    const std::string error = ParseError(c.text);
    ASSERT_FALSE(error.empty()) << c.name;
    for (const std::string& part : c.expected) {
      EXPECT_TRUE(Contains(error, part)) << c.name;
    }
  }
}

// A dropout (0 kN, or nearly) is a possible reading, not a file error: the calibration
// flags it as a gross error. It used to refuse the whole file.
// The bundled circle with `transform` applied to each data row's fields (the header
// given to it too, as row -1), as text.
std::string CircleWith(
    const std::function<void(int row, std::vector<std::string>* fields)>& transform) {
  std::ifstream in(std::string(FASTCAL_TEST_SOURCE_DIR) + "/calibration_data/circle_paper.csv");
  std::string line, text;
  int row = -1;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') {
      text += line + "\n";
      continue;
    }
    std::vector<std::string> fields;
    std::stringstream split(line);
    for (std::string f; std::getline(split, f, ',');) fields.push_back(f);
    transform(row++, &fields);
    for (size_t k = 0; k < fields.size(); ++k) text += (k ? "," : "") + fields[k];
    text += "\n";
  }
  return text;
}

// Radians under *_deg columns (issue 17): per value they are plausible angles, so the
// whole file is checked, and the message says what was seen and how to fix it.
TEST_F(DatasetTest, AttitudesInRadiansUnderDegreeColumnsAreRefused) {
  constexpr double kRadPerDeg = M_PI / 180.0;
  // Columns 4-6: roll, pitch, yaw (measured); 7-9 planned.
  auto to_radians = [&](int first, int row, std::vector<std::string>* f) {
    if (row < 0) return;
    for (int c = first; c < first + 3; ++c) {
      (*f)[c] = internal::FormatDouble("%.17g", std::stod((*f)[c]) * kRadPerDeg);
    }
  };
  const std::string measured =
      ParseError(CircleWith([&](int row, std::vector<std::string>* f) { to_radians(4, row, f); }));
  EXPECT_TRUE(Contains(measured,
                       "data.csv: roll_deg, pitch_deg, yaw_deg look like radians: the "
                       "planned_*_deg angles are 57."));
  EXPECT_TRUE(Contains(measured, "write degrees (radians x 57.2958)"));
  // Both in radians, or no planned columns: every angle below 1 deg where the focal law
  // tilts the cabin by 10.8 deg (0.41 of the circle's 26.4 deg off axis).
  const std::string both = ParseError(CircleWith([&](int row, std::vector<std::string>* f) {
    to_radians(4, row, f);
    to_radians(7, row, f);
  }));
  EXPECT_TRUE(Contains(both, "every angle is below 1 deg (largest 0."));
  EXPECT_TRUE(Contains(both, "while the focal attitude law tilts the cabin by up to 10.8 deg"));
  const std::string unplanned = ParseError(CircleWith([&](int row, std::vector<std::string>* f) {
    to_radians(4, row, f);
    f->erase(f->begin() + 7, f->begin() + 10);
  }));
  EXPECT_TRUE(Contains(unplanned, "every angle is below 1 deg"));
  // Degrees pass, planned or not; so does a level cabin near the axis (kRow).
  ParseOk(CircleWith([](int, std::vector<std::string>*) {}));
  ParseOk(CircleWith(
      [](int, std::vector<std::string>* f) { f->erase(f->begin() + 7, f->begin() + 10); }));
  ParseOk(std::string(kHeader) + kRow + kRow + kRow + kRow + kRow + kRow + kRow + kRow + kRow +
          kRow + kRow);
}

// "-0" is written as "0" (issue 17, item 7): the same value, and a reader wonders.
// A lengths file (fastcal locate): the six s0 columns are all it needs; every other group
// may be there, complete, or not.
TEST_F(DatasetTest, LengthsFileNeedsOnlyTheLengths) {
  DatasetReadOptions options;
  options.required_columns = DatasetColumns::kLengths;
  const std::string lengths = "s0_1_m,s0_2_m,s0_3_m,s0_4_m,s0_5_m,s0_6_m";
  Dataset d;
  std::string error;
  ASSERT_TRUE(ParseDataset(lengths + "\n300,301,302,303,304,305\n", "l.csv", options, &d, &error))
      << error;
  ASSERT_EQ(d.samples.size(), 1u);
  EXPECT_FALSE(d.has_time || d.has_position || d.has_measured_attitude || d.has_tensions);
  EXPECT_TRUE(d.has_unstretched_lengths);
  EXPECT_EQ(d.samples[0].unstretched_length_m[5], 305.0);
  EXPECT_EQ(d.samples[0].pose.rotation, Eigen::Matrix3d::Identity());
  // With an attitude and tensions, no position.
  ASSERT_TRUE(ParseDataset("time_s,qw,qx,qy,qz,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN," + lengths +
                               "\n2,1,0,0,0,150,151,152,153,154,155,300,301,302,303,304,305\n",
                           "l.csv", options, &d, &error))
      << error;
  EXPECT_TRUE(d.has_time && d.has_measured_attitude && d.has_tensions);
  EXPECT_FALSE(d.has_position);
  EXPECT_EQ(d.samples[0].tension_n[0], 150000.0);
  // What a lengths file cannot lack, and half groups.
  EXPECT_FALSE(ParseDataset("time_s,x_m,y_m,z_m\n0,0,0,140\n", "l.csv", options, &d, &error));
  EXPECT_TRUE(Contains(error, "l.csv:1: missing column 's0_1_m' (a lengths file needs"));
  EXPECT_FALSE(ParseDataset("x_m,y_m," + lengths + "\n0,0,300,301,302,303,304,305\n", "l.csv",
                            options, &d, &error));
  EXPECT_TRUE(Contains(error, "missing column 'z_m' (the position needs all three or none)"));
  EXPECT_FALSE(ParseDataset("T1_kN," + lengths + "\n150,300,301,302,303,304,305\n", "l.csv",
                            options, &d, &error));
  EXPECT_TRUE(Contains(error, "missing columns 'T2_kN', 'T3_kN', 'T4_kN', 'T5_kN', 'T6_kN' (the measured tensions need all six"));
  // A measurement file still needs its columns, and keeps its flags.
  EXPECT_TRUE(Contains(ParseError(lengths + "\n300,301,302,303,304,305\n"), "missing column"));
  const Dataset full = ParseOk(std::string(kHeader) + kRow);
  EXPECT_TRUE(full.has_time && full.has_position && full.has_measured_attitude &&
              full.has_tensions);
}

TEST_F(DatasetTest, NegativeZeroIsWrittenAsZero) {
  const Dataset d =
      ParseOk(std::string(kHeader) + "0.5,-0,2,140,-0,0.2,-0.0,150,151,152,153,154,0\n");
  const std::string path = PathOf("zero.csv");
  std::string error;
  ASSERT_TRUE(WriteDataset(path, d, "", &error)) << error;
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("-0,"), std::string::npos) << text;
  EXPECT_NE(text.find("0.5,0,2,140,0,0.2,0,"), std::string::npos) << text;
}

// The fuzzer's round trip (tests/fuzz): a dataset read, written and read again holds the
// same bits, -0 included (read as the reading 0, which the writer writes).
TEST_F(DatasetTest, NegativeZeroRoundTripsBitForBit) {
  const Dataset d =
      ParseOk(std::string(kHeader) + "-0,-0,2,140,-0,-0.0,-0,150,151,152,153,154,0\n");
  const std::string path = PathOf("zero_bits.csv");
  std::string error;
  ASSERT_TRUE(WriteDataset(path, d, "", &error)) << error;
  Dataset again;
  ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &again, &error)) << error;
  const Sample& a = d.samples.at(0);
  const Sample& b = again.samples.at(0);
  EXPECT_FALSE(std::signbit(a.time_s));
  EXPECT_FALSE(std::signbit(a.pose.position_m[0]));
  EXPECT_EQ(std::memcmp(&a.time_s, &b.time_s, sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(a.pose.position_m.data(), b.pose.position_m.data(), 3 * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(a.pose.rotation.data(), b.pose.rotation.data(), 9 * sizeof(double)), 0);
}

TEST_F(DatasetTest, DropoutReadingsOfZeroAreAccepted) {
  const Dataset d = ParseOk(std::string(kHeader) + "0,1,2,140,0,0,0,150,0,152,1e-300,-0,155\n");
  ASSERT_EQ(d.samples.size(), 1u);
  EXPECT_EQ(d.samples[0].tension_n[1], 0.0);
  EXPECT_EQ(d.samples[0].tension_n[3], 1e-297);
  EXPECT_EQ(d.samples[0].tension_n[4], 0.0);
}

// User text in messages (internal/quote.h): control bytes escaped, invalid UTF-8 and C1
// controls escaped, valid UTF-8 kept, long text cut at a character boundary.
TEST(QuoteTest, EscapesControlBytesAndCapsTheLength) {
  EXPECT_EQ(internal::Quote("T1_kN"), "'T1_kN'");
  EXPECT_EQ(internal::Quote("a\x1b[2Jb\tc\n\x7f"), "'a\\x1b[2Jb\\tc\\n\\x7f'");
  EXPECT_EQ(internal::Quote("it's \\"), "'it\\'s \\\\'");
  EXPECT_EQ(internal::Quote("Zugkraft_\xc3\xa4"), "'Zugkraft_\xc3\xa4'");    // UTF-8 kept
  EXPECT_EQ(internal::Quote("\xc2\x9b\xff\xc3"), "'\\xc2\\x9b\\xff\\xc3'");  // C1 CSI, invalid
  const std::string long_text(10 << 20, 'x');
  const std::string quoted = internal::Quote(long_text);
  EXPECT_EQ(quoted, "'" + std::string(internal::kMaxQuotedBytes, 'x') + "'... (10485760 bytes)");
  // A cut never splits a character: 63 bytes of 'x' and a 2-byte character.
  EXPECT_EQ(internal::Quote(std::string(63, 'x') + "\xc3\xa4\xc3\xa4"),
            "'" + std::string(63, 'x') + "'... (67 bytes)");
}

TEST_F(DatasetTest, NoDataRowsIsAnError) {
  EXPECT_EQ(ParseError(std::string("# nothing yet\n") + kHeader + "\n# end\n"),
            "data.csv: no data rows");
  EXPECT_TRUE(Contains(ParseError(""), "data.csv: no header line"));
  EXPECT_TRUE(Contains(ParseError("# only a comment\n\n"), "data.csv: no header line"));
}

TEST_F(DatasetTest, SkipInvalidRowsSkipsAndListsThem) {
  const std::string text = std::string("# header follows\n") + kHeader +  // lines 1-2
                           kRow +                                         // 3
                           "1,1,2,140,0,0,0,150,151,abc,153,154,155\n"    // 4
                           "2,1,2,140,0,0,0,150,151,152\n"                // 5
                           "# a comment\n"                                // 6
                           "3,1,2,140,0,0,0,150,151,152,153,-1,155\n"     // 7
                           "4,1,2,140,0,0,0,150,151,152,153,154,155\n";   // 8
  EXPECT_TRUE(Contains(ParseError(text), "data.csv:4: column 'T3_kN'"));
  const Dataset d = ParseOk(text, /*skip=*/true);
  ASSERT_EQ(d.samples.size(), 2u);
  EXPECT_EQ(d.samples[0].line, 3);
  EXPECT_EQ(d.samples[1].line, 8);
  EXPECT_EQ(d.samples[1].time_s, 4.0);
  ASSERT_EQ(d.skipped.size(), 3u);
  EXPECT_EQ(d.skipped[0], "data.csv:4: column 'T3_kN': 'abc' is not a number");
  EXPECT_EQ(d.skipped[1], "data.csv:5: expected 13 fields (as in the header), found 10");
  EXPECT_TRUE(Contains(d.skipped[2], "data.csv:7: column 'T5_kN': -1 kN is negative"));
}

TEST_F(DatasetTest, SkipInvalidRowsNeverSkipsHeaderErrorsOrEverything) {
  EXPECT_TRUE(Contains(ParseError("T7_kN," + std::string(kHeader) + "1," + kRow, /*skip=*/true),
                       "data.csv:1: unknown column 'T7_kN'"));
  const std::string all_bad = std::string(kHeader) + "x,1,2,140,0,0,0,150,151,152,153,154,155\n" +
                              "0,1,2,140,0,0,0,150,151,152,153,154\n";
  const std::string error = ParseError(all_bad, /*skip=*/true);
  EXPECT_TRUE(Contains(error, "data.csv: no valid data rows: all 2 rows skipped"));
  EXPECT_TRUE(Contains(error, "data.csv:2: column 'time_s'"));
}

std::string Repeated(const std::string& text, int times) {
  std::string out;
  for (int k = 0; k < times; ++k) out += text;
  return out;
}

// Reads `path` with DatasetChunkReader, `chunk` samples at a time, into one dataset (the
// chunks concatenated); the error message on failure, "" on success.
std::string ReadInChunks(const std::string& path, const DatasetReadOptions& options, size_t chunk,
                         Dataset* whole) {
  DatasetChunkReader reader;
  std::string error;
  if (!reader.Open(path, options, &error)) return error;
  for (bool done = false; !done;) {
    Dataset part;
    if (!reader.Next(chunk, &part, &done, &error)) return error;
    EXPECT_LE(part.samples.size(), chunk);
    for (Sample& s : part.samples) whole->samples.push_back(std::move(s));
    for (std::string& s : part.skipped) whole->skipped.push_back(std::move(s));
    whole->path = part.path;
    whole->has_planned_attitude = part.has_planned_attitude;
    whole->has_unstretched_lengths = part.has_unstretched_lengths;
    whole->attitude_as_quaternion = part.attitude_as_quaternion;
    whole->session_labels = part.session_labels;
  }
  return "";
}

// fastcal evaluate reads its data in chunks, and ReadDataset reads through the chunked
// reader with rows parsed on several threads (issue 20): both give the samples, skipped
// rows and messages of the whole text read line by line (ParseDataset), whatever the
// chunk size and the number of threads, on good files, bad rows (skipped or not), bad
// headers and whole-file problems.
TEST_F(DatasetTest, ChunkedReaderGivesTheSamplesAndMessagesOfReadDataset) {
  const std::string rows = std::string("# c\n") + kHeader + kRow + kRow + kRow;
  const auto to_radians = [](int row, std::vector<std::string>* f) {
    for (int c = 4; row >= 0 && c < 7; ++c) {
      (*f)[c] = internal::FormatDouble("%.17g", std::stod((*f)[c]) * M_PI / 180.0);
    }
  };
  const std::vector<std::string> texts = {
      rows,
      "\xEF\xBB\xBF" + rows + "1,1,2,140,0,0,0,150,151,152,153,154,155",  // no final newline
      rows + "1,1,2,140,0,0,0,150,151,abc,153,154,155\n" + kRow,
      rows + "2,1,2,140,0,0,0,150,151,152\n\n# x\n" + kRow + "3,1,2,140,0,0,0,1,2,3,4,-1,6\n",
      std::string(kHeader) + "0,1,2,140,0,0,0,150,151,244,5,153,154,155\n" + kRow,
      std::string(kHeader) + "x,1,2,140,0,0,0,150,151,152,153,154,155\n",
      "T7_kN," + std::string(kHeader) + "1," + kRow,
      std::string("# nothing\n") + kHeader,
      "",
      std::string(kHeader) + kRow + "\r\n",
      "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN,"
      "session\n0,1,2,140,0,0,0,1,2,3,4,5,6,B\n1,1,2,140,0,0,0,1,2,3,4,5,6,A\n"
      "2,1,2,140,0,0,0,1,2,3,4,5,6,B\n",
      CircleWith(to_radians),
      CircleWith([](int, std::vector<std::string>*) {}),
      // Long enough for several parse chunks per thread, a bad row deep inside.
      std::string(kHeader) + Repeated(kRow, 1500) + "1,1,2,140,0,0,0,150,151,244,5,153,154,155\n" +
          Repeated(kRow, 1500),
  };
  int failures = 0;
  for (size_t k = 0; k < texts.size(); ++k) {
    const std::string path = PathOf("data" + std::to_string(k) + ".csv");
    WriteText("data" + std::to_string(k) + ".csv", texts[k]);
    for (int variant = 0; variant < 4; ++variant) {
      const bool skip = variant % 2 == 1;
      DatasetReadOptions options;
      options.skip_invalid_rows = skip;
      options.threads = variant < 2 ? 1 : 3;
      Dataset expected;
      std::string expected_error;
      const bool ok = ParseDataset(texts[k], path, options, &expected, &expected_error);
      failures += !ok;
      for (size_t chunk : {size_t{1}, size_t{2}, size_t{7}, size_t{100000}, size_t{0}}) {
        SCOPED_TRACE("text " + std::to_string(k) + (skip ? " skip" : "") + " threads " +
                     std::to_string(options.threads) + " chunk " + std::to_string(chunk));
        Dataset got;
        std::string error;
        if (chunk > 0) {
          error = ReadInChunks(path, options, chunk, &got);
        } else if (!ReadDataset(path, options, &got, &error)) {  // 0: the whole file
          EXPECT_FALSE(error.empty());
        }
        EXPECT_EQ(error, ok ? "" : expected_error);
        if (!ok || !error.empty()) continue;
        EXPECT_EQ(got.path, expected.path);
        EXPECT_EQ(got.skipped, expected.skipped);
        EXPECT_EQ(got.session_labels, expected.session_labels);
        ASSERT_EQ(got.samples.size(), expected.samples.size());
        for (size_t n = 0; n < got.samples.size(); ++n) {
          EXPECT_EQ(got.samples[n].line, expected.samples[n].line);
          EXPECT_EQ(got.samples[n].session, expected.samples[n].session);
          ExpectSamplesEqual(expected.samples[n], got.samples[n], expected.attitude_as_quaternion,
                             expected.has_planned_attitude, expected.has_unstretched_lengths);
        }
      }
    }
  }
  EXPECT_GE(failures, 20);  // the bad files above fail (without skip, and some with it)
  // Refused before reading, as ReadDataset refuses: a directory, a file above the limit.
  Dataset unused;
  std::string expected_error;
  EXPECT_FALSE(ReadDataset(dir_.string(), DatasetReadOptions(), &unused, &expected_error));
  EXPECT_EQ(ReadInChunks(dir_.string(), DatasetReadOptions(), 5, &unused), expected_error);
  DatasetReadOptions small;
  small.max_file_bytes = 10;
  EXPECT_FALSE(ReadDataset(PathOf("data0.csv"), small, &unused, &expected_error));
  EXPECT_EQ(ReadInChunks(PathOf("data0.csv"), small, 5, &unused), expected_error);
}

TEST_F(DatasetTest, RoundTripIsExact) {
  constexpr int kRows = 50;
  unsigned seed = 20240501;
  for (const bool quaternion : {false, true}) {
    for (const bool optional_columns : {false, true}) {
      SCOPED_TRACE(::testing::Message()
                   << "quaternion " << quaternion << ", optional " << optional_columns);
      const Dataset original = RandomDataset(seed++, quaternion, optional_columns, kRows);
      const std::string path = PathOf("round_trip.csv");
      std::string error;
      ASSERT_TRUE(WriteDataset(path, original, "provenance\nsecond line", &error)) << error;
      Dataset read;
      ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &read, &error)) << error;
      EXPECT_EQ(read.path, path);
      EXPECT_EQ(read.attitude_as_quaternion, quaternion);
      EXPECT_EQ(read.has_planned_attitude, optional_columns);
      EXPECT_EQ(read.has_unstretched_lengths, optional_columns);
      ASSERT_EQ(read.samples.size(), original.samples.size());
      for (size_t i = 0; i < read.samples.size(); ++i) {
        ExpectSamplesEqual(original.samples[i], read.samples[i], quaternion, optional_columns,
                           optional_columns);
        EXPECT_EQ(read.samples[i].line, static_cast<int>(i) + 4);  // 2 comments, header
      }
    }
  }
}

TEST_F(DatasetTest, WritesHeaderCommentReadableKilonewtonsAndRereadsTheSameFile) {
  Dataset dataset =
      ParseOk(std::string(kHeader) + "0.5,1,2,140.25,0.1,0.2,0.3,159.17,151,152,153,154,155.5\n");
  const std::string path = PathOf("out.csv");
  std::string error;
  ASSERT_TRUE(WriteDataset(path, dataset, "from telemetry.csv\n\nsha256 0123", &error)) << error;
  std::ifstream in(path);
  std::stringstream contents;
  contents << in.rdbuf();
  EXPECT_EQ(contents.str(),
            "# from telemetry.csv\n#\n# sha256 0123\n"
            "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n"
            "0.5,1,2,140.25,0.1,0.2,0.3,159.17,151,152,153,154,155.5\n");
  // Writing what was read gives the same bytes.
  Dataset again;
  ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &again, &error)) << error;
  const std::string path2 = PathOf("out2.csv");
  ASSERT_TRUE(WriteDataset(path2, again, "from telemetry.csv\n\nsha256 0123", &error));
  std::ifstream in2(path2);
  std::stringstream contents2;
  contents2 << in2.rdbuf();
  EXPECT_EQ(contents2.str(), contents.str());
}

TEST_F(DatasetTest, ExtremeTensionsRoundTripExactly) {
  const PlausibilityLimits limits;
  const std::vector<double> values = {0.0,
                                      std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::min(),
                                      1e-7,
                                      0.1,
                                      1.0 / 3.0,
                                      159170.00000000003,
                                      4999999.999999999,
                                      limits.max_tension_n};
  Dataset dataset;
  for (size_t start = 0; start < values.size(); ++start) {
    Sample s;
    for (int i = 0; i < kNumCables; ++i) s.tension_n[i] = values[(start + i) % values.size()];
    dataset.samples.push_back(s);
  }
  const std::string path = PathOf("extreme.csv");
  std::string error;
  ASSERT_TRUE(WriteDataset(path, dataset, "", &error)) << error;
  Dataset read;
  ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &read, &error)) << error;
  ASSERT_EQ(read.samples.size(), dataset.samples.size());
  for (size_t k = 0; k < read.samples.size(); ++k) {
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(read.samples[k].tension_n[i], dataset.samples[k].tension_n[i]) << k << "," << i;
    }
  }
}

TEST_F(DatasetTest, WritesAttitudeFromRotationWhenOnlyTheRotationIsSet) {
  // Samples built in code: pose.rotation set, the as-read attitude fields left at defaults.
  const Eigen::Matrix3d rotation = RotationFromRpyDeg(3.0, -4.0, 100.0);
  for (const bool quaternion : {false, true}) {
    SCOPED_TRACE(quaternion ? "quaternion" : "angles");
    Dataset dataset;
    dataset.attitude_as_quaternion = quaternion;
    dataset.has_planned_attitude = true;
    Sample s;
    s.pose.rotation = rotation;
    s.has_planned_attitude = true;
    s.planned_rotation = rotation.transpose();
    s.tension_n.fill(150e3);
    dataset.samples.push_back(s);
    const std::string path = PathOf("built.csv");
    std::string error;
    ASSERT_TRUE(WriteDataset(path, dataset, "", &error)) << error;
    Dataset read;
    ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &read, &error)) << error;
    ASSERT_EQ(read.samples.size(), 1u);
    EXPECT_LT((read.samples[0].pose.rotation - rotation).cwiseAbs().maxCoeff(), kRotationTolerance);
    EXPECT_LT((read.samples[0].planned_rotation - rotation.transpose()).cwiseAbs().maxCoeff(),
              kRotationTolerance);
  }
}

TEST_F(DatasetTest, WriteFailureLeavesNoFile) {
  const Dataset dataset = RandomDataset(7, false, true, 3);
  std::string error;
  // Directory does not exist.
  const std::string missing_dir = PathOf("no_such_dir/out.csv");
  EXPECT_FALSE(WriteDataset(missing_dir, dataset, "", &error));
  EXPECT_TRUE(Contains(error, missing_dir));
  EXPECT_TRUE(DirEntries().empty());
  // The target is a directory: the temporary file is written, the rename fails.
  ASSERT_TRUE(fs::create_directory(PathOf("a_directory")));
  error.clear();
  EXPECT_FALSE(WriteDataset(PathOf("a_directory"), dataset, "", &error));
  EXPECT_TRUE(Contains(error, "a_directory"));
  EXPECT_EQ(DirEntries(), std::vector<std::string>{"a_directory"});
  EXPECT_TRUE(fs::is_empty(PathOf("a_directory")));
}

TEST_F(DatasetTest, WriteRefusesDataTheReaderWouldReject) {
  const Dataset good = RandomDataset(11, false, true, 3);
  const std::string path = PathOf("bad.csv");
  std::string error;

  Dataset bad = good;
  bad.samples[1].tension_n[2] = std::nan("");
  EXPECT_FALSE(WriteDataset(path, bad, "", &error));
  EXPECT_TRUE(Contains(error, "samples[1]: column 'T3_kN': value is not finite"));

  bad = good;
  bad.samples[2].tension_n[0] = -1.0;
  EXPECT_FALSE(WriteDataset(path, bad, "", &error));
  EXPECT_TRUE(Contains(error, "samples[2]: column 'T1_kN': -0.001 kN is negative"));

  bad = good;
  bad.samples[2].tension_n[0] = 1e10;
  EXPECT_FALSE(WriteDataset(path, bad, "", &error));
  EXPECT_TRUE(Contains(error, "samples[2]: column 'T1_kN': 1e+07 kN is above the plausible"));

  bad = good;
  bad.samples[0].has_unstretched_lengths = false;
  EXPECT_FALSE(WriteDataset(path, bad, "", &error));
  EXPECT_TRUE(Contains(error, "samples[0]: no unstretched lengths"));

  bad = good;
  bad.samples[0].pose.rotation(0, 0) = 2.0;
  EXPECT_FALSE(WriteDataset(path, bad, "", &error));
  EXPECT_TRUE(Contains(error, "samples[0]: pose.rotation is not a finite rotation matrix"));

  bad = good;
  bad.samples.clear();
  EXPECT_FALSE(WriteDataset(path, bad, "", &error));
  EXPECT_TRUE(Contains(error, "no samples"));

  EXPECT_TRUE(DirEntries().empty());
}

TEST_F(DatasetTest, WriteReplacesAnExistingFile) {
  const std::string path = PathOf("replace.csv");
  WriteText("replace.csv", "old contents\n");
  std::string error;
  ASSERT_TRUE(WriteDataset(path, RandomDataset(3, true, false, 2), "", &error)) << error;
  Dataset read;
  ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &read, &error)) << error;
  EXPECT_EQ(read.samples.size(), 2u);
  EXPECT_EQ(DirEntries(), std::vector<std::string>{"replace.csv"});
}

TEST_F(DatasetTest, ReadMissingFileFails) {
  const std::string path = PathOf("absent.csv");
  Dataset dataset;
  std::string error;
  EXPECT_FALSE(ReadDataset(path, DatasetReadOptions(), &dataset, &error));
  EXPECT_TRUE(Contains(error, path + ": cannot open"));
}

// /dev/zero (any endless or huge non-regular file) was read until memory ran out: now it
// is refused before reading. Run in a bounded child so that without the check the test
// fails within seconds instead of taking the machine's memory.
TEST_F(DatasetTest, NonRegularFilesAreRefusedBeforeReading) {
  EXPECT_EXIT(
      {
        test::LimitThisProcess();
        Dataset dataset;
        std::string error;
        const bool ok = ReadDataset("/dev/zero", DatasetReadOptions(), &dataset, &error);
        std::fprintf(stderr, "%s\n", error.c_str());
        std::exit(ok ? 1 : 0);
      },
      ::testing::ExitedWithCode(0),
      "/dev/zero: not a regular file \\(a device, pipe or socket\\): a dataset file must be "
      "a regular file");
  // A pipe is refused without waiting for a writer.
  const std::string fifo = PathOf("fifo.csv");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  Dataset dataset;
  std::string error;
  EXPECT_FALSE(ReadDataset(fifo, DatasetReadOptions(), &dataset, &error));
  EXPECT_TRUE(Contains(error, fifo + ": not a regular file"));
  EXPECT_FALSE(ReadDataset(dir_.string(), DatasetReadOptions(), &dataset, &error));
  EXPECT_TRUE(Contains(error, dir_.string() + ": is a directory, not a dataset file"));
}

TEST_F(DatasetTest, FilesAboveTheSizeLimitAreRefusedBeforeReading) {
  const std::string text = std::string(kHeader) + kRow + kRow;
  WriteText("data.csv", text);
  DatasetReadOptions options;
  options.max_file_bytes = 100;
  Dataset dataset;
  std::string error;
  EXPECT_FALSE(ReadDataset(PathOf("data.csv"), options, &dataset, &error));
  EXPECT_EQ(error, PathOf("data.csv") + ": " + std::to_string(text.size()) +
                       " bytes is larger than the limit for a dataset file, 100 bytes "
                       "(docs/data-format.md, \"Limits\")");
  options.max_file_bytes = static_cast<long long>(text.size());
  EXPECT_TRUE(ReadDataset(PathOf("data.csv"), options, &dataset, &error)) << error;
  EXPECT_EQ(DatasetReadOptions().max_file_bytes, 1LL << 30);  // as documented
}

// The readers' number parser accepts what strtod accepts in the "C" locale (the program
// runs in it: setlocale is never called), with the same value, and refuses the rest;
// the writers' formatter prints what printf prints there.
// Text a person reads: a value that rounds to zero has no sign; any other keeps it.
TEST(NumberTextTest, NegativeZeroLosesItsSignOnlyWhenItReadsAsZero) {
  EXPECT_EQ(internal::WithoutNegativeZero("-0.00"), "0.00");
  EXPECT_EQ(internal::WithoutNegativeZero("-0"), "0");
  EXPECT_EQ(internal::WithoutNegativeZero("-0.000 m"), "0.000 m");
  EXPECT_EQ(internal::WithoutNegativeZero("-0.000000e+00"), "0.000000e+00");
  EXPECT_EQ(internal::WithoutNegativeZero("-0.01"), "-0.01");
  EXPECT_EQ(internal::WithoutNegativeZero("-1e-300"), "-1e-300");
  EXPECT_EQ(internal::WithoutNegativeZero("-100"), "-100");
  EXPECT_EQ(internal::WithoutNegativeZero("-"), "-");
  EXPECT_EQ(internal::WithoutNegativeZero("-x"), "-x");
  EXPECT_EQ(internal::WithoutNegativeZero("0.00"), "0.00");
}

TEST(NumberTextTest, ParsesAndFormatsLikeTheCLocale) {
  for (const char* text :
       {"1.5", "-2e-3", "+7", ".5", "5.", "1e308", "1e309", "-1e400", "1e-320", "1e-400", "-0",
        "0x1.8p1", "-0X10", "inf", "-Infinity", "nan", "123456789012345678901234567890",
        "0.000000000000000000000000000000000000000000000000000000000000000000000000000001"}) {
    char* end = nullptr;
    const double expected = std::strtod(text, &end);
    ASSERT_EQ(*end, '\0') << text;
    double parsed = 0.0;
    ASSERT_TRUE(internal::ParseDouble(text, &parsed)) << text;
    if (std::isnan(expected)) {
      EXPECT_TRUE(std::isnan(parsed)) << text;
    } else {
      EXPECT_EQ(parsed, expected) << text;
      EXPECT_EQ(std::signbit(parsed), std::signbit(expected)) << text;
    }
  }
  for (const char* text :
       {"", " 1", "1 ", "1,5", "1.5.2", "++1", "+-1", "e5", "1e", "0x", "1kN", "--1", "nanx"}) {
    double parsed = 42.0;
    EXPECT_FALSE(internal::ParseDouble(text, &parsed)) << "'" << text << "'";
    EXPECT_EQ(parsed, 42.0) << text;
  }
  for (const char* format : {"%.3f", "%+.2f", "%.6g", "%g", "%.12g", "%.1e", "%+.3e", "%8.3f",
                             "%-8.1fx", "%.0f%%", "T = %.3g kN"}) {
    for (double v : {0.0, -0.0, 1.0, -1.5, 0.1234567, 158981.123456, 1e-7, -2.5e12, 1e300}) {
      char expected[512];
      std::snprintf(expected, sizeof(expected), format, v);
      EXPECT_EQ(internal::FormatDouble(format, v), expected) << format << " " << v;
    }
  }
}

}  // namespace
}  // namespace fastcal
