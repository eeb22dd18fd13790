// Tests of column maps (fastcal/column_map.h): the map's reader and its errors, and
// telemetry read through a map by the dataset and pose readers: units, time stamps and
// zones, delimiters and decimal commas, header lines and unit rows, quotes, trailing
// delimiters, unmapped channels (docs/data-format.md, "Column maps").
#include "fastcal/column_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fastcal/dataset.h"
#include "fastcal/sessions.h"
#include "fastcal/svg_plot.h"
#include "fastcal/time_text.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

std::string SourceDir() {
  const char* env = std::getenv("FASTCAL_TEST_SOURCE_DIR");
  return env != nullptr ? env : FASTCAL_TEST_SOURCE_DIR;
}

// A map's YAML: the format line, then `body`.
std::string MapText(const std::string& body) { return "format: fastcal-columns-1\n" + body; }

// The columns of a whole dataset in fastcal's units, mapped to themselves but for `over`
// (fastcal name -> "{column: ..., unit: ...}").
std::string Columns(const std::vector<std::pair<std::string, std::string>>& over = {}) {
  std::vector<std::string> names = {"x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"};
  for (int i = 1; i <= 6; ++i) names.push_back("T" + std::to_string(i) + "_kN");
  std::string text = "columns:\n";
  for (const std::string& n : names) {
    std::string value = n;
    for (const auto& [name, v] : over) {
      if (name == n) value = v;
    }
    text += "  " + n + ": " + value + "\n";
  }
  return text;
}

ColumnMap Map(const std::string& text) {
  ColumnMap map;
  std::string error;
  EXPECT_TRUE(ParseColumnMap(text, "map.yaml", &map, &error)) << error;
  return map;
}

std::string MapError(const std::string& text) {
  ColumnMap map;
  std::string error;
  EXPECT_FALSE(ParseColumnMap(text, "map.yaml", &map, &error));
  return error;
}

bool ReadMapped(const std::string& data, const std::string& map_text, Dataset* out,
                std::string* error, int threads = 1) {
  DatasetReadOptions options;
  options.threads = threads;
  auto map = std::make_shared<ColumnMap>();
  if (!ParseColumnMap(map_text, "map.yaml", map.get(), error)) return false;
  options.columns = map;
  return ParseDataset(data, "data.csv", options, out, error);
}

Dataset Mapped(const std::string& data, const std::string& map_text) {
  Dataset out;
  std::string error;
  EXPECT_TRUE(ReadMapped(data, map_text, &out, &error)) << error;
  return out;
}

std::string MappedError(const std::string& data, const std::string& map_text) {
  Dataset out;
  std::string error;
  EXPECT_FALSE(ReadMapped(data, map_text, &out, &error));
  return error;
}

// One plausible row in fastcal's names and units.
constexpr char kCanonicalHeader[] =
    "t,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN";
constexpr char kRow[] = "2.5,70.96,4.65,156.73,0.35,-5.30,0.09,214.0,190.2,141.8,149.9,188.6,207.1";

std::string PlainMap() { return MapText("time: {column: t}\n" + Columns()); }

TEST(ColumnMapTest, ReadsAMapWithEveryKey) {
  const ColumnMap map =
      Map(MapText("delimiter: \";\"\ndecimal: \",\"\nheader_line: 2\nskip_after_header: 1\n"
                  "time: {column: SysTime, format: iso8601, zone: \"+08:00\"}\n"
                  "columns:\n  x_m: {column: SDP_PhaPos_X, unit: mm}\n  T1_kN: CableForce1\n"
                  "unmapped: ignore\n"));
  EXPECT_EQ(map.delimiter, ';');
  EXPECT_EQ(map.decimal, ',');
  EXPECT_EQ(map.header_line, 2);
  EXPECT_EQ(map.skip_after_header, 1);
  ASSERT_TRUE(map.has_time);
  EXPECT_EQ(map.time.column, "SysTime");
  EXPECT_EQ(map.time.format, TimeFormat::kIso8601);
  EXPECT_EQ(map.time.offset_s, 8 * 3600);
  ASSERT_EQ(map.columns.size(), 2u);
  EXPECT_EQ(map.columns[0].unit, "mm");
  EXPECT_EQ(map.columns[0].line, 8);
  EXPECT_EQ(map.columns[1].column, "CableForce1");
  EXPECT_EQ(map.columns[1].unit, "kN");  // a plain name: fastcal's unit
  EXPECT_TRUE(map.ignore_unmapped);
}

TEST(ColumnMapTest, BadMapsNameTheKeyAndTheLine) {
  // A source column named twice.
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  x_m: {column: X}\n  y_m: {column: X}\n")),
                       "map.yaml:4: columns.y_m.column: source column 'X' is already mapped to "
                       "x_m (line 3)"));
  EXPECT_TRUE(Contains(MapError(MapText("time: {column: T}\ncolumns:\n  x_m: T\n")),
                       "map.yaml:4: columns.x_m.column: source column 'T' is already mapped to "
                       "time (line 2)"));
  // An unknown unit, and one of another quantity.
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  x_m: {column: X, unit: inch}\n")),
                       "map.yaml:3: columns.x_m.unit: unknown unit 'inch' for a length "
                       "(accepted: m, cm, mm)"));
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  T1_kN: {column: F, unit: mm}\n")),
                       "map.yaml:3: columns.T1_kN.unit: unknown unit 'mm' for a force "
                       "(accepted: kN, N, tf)"));
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  roll_deg: {column: R, unit: grad}\n")),
                       "columns.roll_deg.unit: unknown unit 'grad' for an angle"));
  // Unknown keys, at every level.
  EXPECT_TRUE(Contains(MapError(MapText("delimeter: \";\"\ncolumns: {}\n")),
                       "map.yaml:2: delimeter: unknown key (allowed here: format, delimiter"));
  EXPECT_TRUE(
      Contains(MapError(MapText("time: {column: T, fromat: iso8601}\ncolumns: {}\n")),
               "map.yaml:2: time.fromat: unknown key (allowed here: column, format, zone)"));
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  x_m: {column: X, scale: 2}\n")),
                       "map.yaml:3: columns.x_m.scale: unknown key (allowed here: column, unit)"));
  // An unknown fastcal name; time_s under columns.
  EXPECT_TRUE(Contains(
      MapError(MapText("columns:\n  x_mm: X\n")),
      "map.yaml:3: columns.x_mm: unknown fastcal name (did you mean 'x_m'?) (accepted: x_m, y_m"));
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  time_s: T\n")),
                       "map.yaml:3: columns.time_s: the time is given by the map's time:"));
  // The format, missing or wrong.
  EXPECT_TRUE(Contains(MapError("columns: {}\n"), "map.yaml: format: missing"));
  EXPECT_TRUE(Contains(MapError("format: fastcal-columns-2\ncolumns: {}\n"),
                       "map.yaml:1: format: 'fastcal-columns-2' is not a column map format"));
  EXPECT_TRUE(Contains(MapError(MapText("time: {column: T}\n")), "columns: missing"));
  // Values.
  EXPECT_TRUE(Contains(MapError(MapText("time: {column: T, format: iso}\ncolumns: {}\n")),
                       "map.yaml:2: time.format: unknown format 'iso'"));
  EXPECT_TRUE(Contains(MapError(MapText("time: {column: T, zone: Asia/Shanghai}\ncolumns: {}\n")),
                       "map.yaml:2: time.zone: 'Asia/Shanghai' is not a UTC offset"));
  EXPECT_TRUE(Contains(MapError(MapText("decimal: \",\"\ndelimiter: \",\"\ncolumns: {}\n")),
                       "map.yaml:3: delimiter: the same as the decimal mark"));
  EXPECT_TRUE(Contains(MapError(MapText("header_line: 0\ncolumns: {}\n")),
                       "map.yaml:2: header_line: '0' is not a whole number from 1 to 10000"));
  EXPECT_TRUE(Contains(MapError(MapText("skip_after_header: 2147483647\ncolumns: {}\n")),
                       "skip_after_header: '2147483647' is not a whole number from 0 to 10000"));
  EXPECT_TRUE(Contains(MapError(MapText("unmapped: drop\ncolumns: {}\n")),
                       "map.yaml:2: unmapped: 'drop' is neither ignore nor error"));
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  x_m: {column: X}\n  x_m: {column: Y}\n")),
                       "columns.x_m"));
}

TEST(ColumnMapTest, AMissingRequiredQuantityNamesTheMapsColumnsLine) {
  std::string columns = Columns();
  columns.erase(columns.find("  T4_kN"), std::string("  T4_kN: T4_kN\n").size());
  const std::string map = MapText("time: {column: t}\n" + columns);
  EXPECT_TRUE(Contains(MappedError(std::string(kCanonicalHeader) + "\n" + kRow + "\n", map),
                       "map.yaml:3: columns: no entry for 'T4_kN'"));
  // Part of a group.
  EXPECT_TRUE(Contains(
      MappedError("t,x_m,y_m,z_m,qw,qx,qy,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n",
                  MapText("time: {column: t}\ncolumns:\n  x_m: x_m\n  y_m: y_m\n  z_m: z_m\n"
                          "  qw: qw\n  qx: qx\n  qy: qy\n  T1_kN: T1_kN\n  T2_kN: T2_kN\n"
                          "  T3_kN: T3_kN\n  T4_kN: T4_kN\n  T5_kN: T5_kN\n  T6_kN: T6_kN\n")),
      "columns: no entry for 'qz' (the measured attitude as a quaternion needs all four)"));
  // No time at all.
  EXPECT_TRUE(
      Contains(MappedError(std::string(kCanonicalHeader) + "\n" + kRow + "\n", MapText(Columns())),
               "map.yaml: time: missing: a dataset needs the time of each row"));
}

TEST(ColumnMapTest, ASourceColumnNotInTheHeaderIsNamedWithTheMapsKeyAndANearName) {
  const std::string map =
      MapText("time: {column: t}\n" + Columns({{"x_m", "{column: SDP_PhaPos_X, unit: mm}"}}));
  const std::string error = MappedError(
      "t,sdp_phapos_x,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n",
      map);
  EXPECT_TRUE(Contains(error,
                       "map.yaml:4: columns.x_m: source column 'SDP_PhaPos_X' is not in "
                       "the header of data.csv (data.csv:1) (did you mean "
                       "'sdp_phapos_x'?)"));
}

TEST(ColumnMapTest, ReadsTheModelsJointColumnsInTheirUnits) {
  // A moving part's joints through a map (issue 35): a revolute joint in rad, a prismatic
  // one in mm, read into Sample::joint in deg and m for the model's joint columns.
  const std::string map = MapText("time: {column: t}\n" + Columns() +
                                  "  rotator_a_deg: {column: ROT_A, unit: rad}\n"
                                  "  stewart_z_m: {column: SP_Z, unit: mm}\n");
  const std::string data = std::string(kCanonicalHeader) + ",ROT_A,SP_Z\n" + kRow + ",0.1,25\n";
  DatasetReadOptions options;
  options.joint_columns = {"rotator_a_deg", "stewart_z_m"};
  options.columns = std::make_shared<ColumnMap>(Map(map));
  Dataset d;
  std::string error;
  ASSERT_TRUE(ParseDataset(data, "data.csv", options, &d, &error)) << error;
  ASSERT_EQ(d.samples.size(), 1u);
  EXPECT_DOUBLE_EQ(d.samples[0].joint[0], 0.1 * 180.0 / M_PI);
  EXPECT_EQ(d.samples[0].joint[1], 0.025);
  EXPECT_EQ(JointColumnsOf(*options.columns),
            (std::vector<std::string>{"rotator_a_deg", "stewart_z_m"}));
  // A joint of the model the map does not name, and one the model does not have.
  options.joint_columns = {"rotator_a_deg", "stewart_z_m", "rotator_b_deg"};
  EXPECT_FALSE(ParseDataset(data, "data.csv", options, &d, &error));
  EXPECT_TRUE(Contains(error, "map.yaml:3: columns: no entry for 'rotator_b_deg'")) << error;
  options.joint_columns = {"rotator_a_deg"};
  EXPECT_FALSE(ParseDataset(data, "data.csv", options, &d, &error));
  EXPECT_TRUE(Contains(error,
                       "columns.stewart_z_m: the model's moving parts have no joint of "
                       "that name (theirs: rotator_a_deg)"))
      << error;
  options.joint_columns.clear();
  EXPECT_FALSE(ParseDataset(data, "data.csv", options, &d, &error));
  EXPECT_TRUE(Contains(error, "the model has no moving parts")) << error;
  // A name neither fastcal's nor a joint's is still refused by the map's reader.
  EXPECT_TRUE(Contains(MapError(MapText("columns:\n  rotator: ROT\n")), "unknown fastcal name"));
}

TEST(ColumnMapTest, PoseFilesReadTheModelsJointColumnsThroughAMap) {
  // A pose file as exported, its joints in rad and mm: read in deg and m; a map with only
  // some of the model's joints is refused by name.
  const fs::path dir = fs::temp_directory_path() / "fastcal_pose_map_joints";
  fs::create_directories(dir);
  const std::string path = (dir / "poses.csv").string();
  std::ofstream(path) << "X;Y;Z;ROT_A;SP_Z\n1;2;150;0,2;-30\n";
  const ColumnMap map = Map(MapText(
      "delimiter: ';'\ndecimal: ','\ncolumns:\n  x_m: X\n  y_m: Y\n  z_m: Z\n"
      "  rotator_a_deg: {column: ROT_A, unit: rad}\n  stewart_z_m: {column: SP_Z, unit: mm}\n"
      "unmapped: ignore\n"));
  std::vector<Pose> poses;
  std::vector<JointValues> joints;
  std::string error;
  ASSERT_TRUE(
      ReadPosesCsv(path, map, {"rotator_a_deg", "stewart_z_m"}, &poses, &joints, nullptr, &error))
      << error;
  ASSERT_EQ(joints.size(), 1u);
  EXPECT_DOUBLE_EQ(joints[0][0], 0.2 * 180.0 / M_PI);
  EXPECT_EQ(joints[0][1], -0.03);
  EXPECT_FALSE(ReadPosesCsv(path, map, {"rotator_a_deg", "stewart_z_m", "rotator_b_deg"}, &poses,
                            &joints, nullptr, &error));
  EXPECT_TRUE(Contains(error, "not 'rotator_b_deg'")) << error;
  fs::remove_all(dir);
}

TEST(ColumnMapTest, AThousandsSeparatorUnderADecimalCommaIsRefused) {
  // "1.234" under decimal: "," is 1234 written German style: read as 1.234 it was 1000x
  // small (issue 37); now refused, naming the field.
  const std::string map = MapText(
      "decimal: \",\"\ndelimiter: \";\"\ntime: t\ncolumns:\n  x_m: X\n  y_m: Y\n  z_m: Z\n"
      "  roll_deg: R\n  pitch_deg: P\n  yaw_deg: W\n  T1_kN: {column: F1, unit: N}\n"
      "  T2_kN: F2\n  T3_kN: F3\n  T4_kN: F4\n  T5_kN: F5\n  T6_kN: F6\n");
  const std::string header = "t;X;Y;Z;R;P;W;F1;F2;F3;F4;F5;F6\n";
  const std::string row =
      "0;70,96;4,65;156,73;0,35;-5,3;0,09;214.000;190,2;141,8;149,9;188,6;207,1\n";
  EXPECT_TRUE(Contains(MappedError(header + row, map),
                       "column 'F1' (T1_kN, N): '214.000' has a '.' where the map says "
                       "decimal: \",\": a thousands separator?"));
  // The same row without the separator reads.
  const Dataset d =
      Mapped(header + std::string(row).replace(row.find("214.000"), 7, "214000"), map);
  ASSERT_EQ(d.samples.size(), 1u);
  EXPECT_EQ(d.samples[0].tension_n[0], 214000.0);
}

TEST(ColumnMapTest, MapErrorsNameTheLikelyFix) {
  // Issue 39: a unit 1000x off names the unit that fits, a decimal comma under '.' asks
  // for decimal: ",", a unit row asks for skip_after_header, every missing entry is
  // named at once, and a typo in a source column or a fastcal name gets its near name.
  const std::string header = "t,X,Y,Z,R,P,W,F1,F2,F3,F4,F5,F6\n";
  const std::string forces_in_n =
      "0,70.96,4.65,156.73,0.35,-5.3,0.09,214000,190200,141800,149900,188600,207100\n";
  const std::string map = MapText(
      "time: t\ncolumns:\n  x_m: X\n  y_m: Y\n  z_m: Z\n  roll_deg: R\n  pitch_deg: P\n"
      "  yaw_deg: W\n  T1_kN: F1\n  T2_kN: F2\n  T3_kN: F3\n  T4_kN: F4\n  T5_kN: F5\n"
      "  T6_kN: F6\n");
  EXPECT_TRUE(Contains(MappedError(header + forces_in_n, map),
                       "214000 kN is above the plausible maximum of 5000 kN; in N it would be "
                       "plausible: is the column's unit N (unit: N)?"));
  const std::string mm = "0,70960,4650,156730,0.35,-5.3,0.09,214,190.2,141.8,149.9,188.6,207.1\n";
  EXPECT_TRUE(Contains(MappedError(header + mm, map),
                       "in mm it would be plausible: are the columns' units mm (unit: mm)?"));
  const std::string comma =
      "0,70.96,4.65,156.73,\"0,35\",-5.3,0.09,214,190.2,141.8,149.9,188.6,207.1\n";
  EXPECT_TRUE(Contains(MappedError(header + comma, map), "(give decimal: \",\")"));
  EXPECT_TRUE(Contains(MappedError(header + "s,m,m,m,deg,deg,deg,kN,kN,kN,kN,kN,kN\n", map),
                       "a unit row? (skip_after_header: 1)"));
  // Issue 37: "inf" or "nan" is a value that is not finite, not a unit row.
  const std::string not_finite =
      "0,70.96,4.65,156.73,0.35,-5.3,0.09,-INF,190.2,141.8,149.9,188.6,nan\n";
  const std::string why = MappedError(header + not_finite, map);
  EXPECT_TRUE(Contains(why, "not finite")) << why;
  EXPECT_FALSE(Contains(why, "a unit row?")) << why;
  // Nor where the map already skips the unit row: "#NV" under it is a missing value.
  const std::string skipping = MapText(
      "time: t\nskip_after_header: 1\ncolumns:\n  x_m: X\n  y_m: Y\n  z_m: Z\n  roll_deg: R\n"
      "  pitch_deg: P\n  yaw_deg: W\n  T1_kN: F1\n  T2_kN: F2\n  T3_kN: F3\n  T4_kN: F4\n"
      "  T5_kN: F5\n  T6_kN: F6\n");
  const std::string missing =
      MappedError(header + "s,m,m,m,deg,deg,deg,kN,kN,kN,kN,kN,kN\n" +
                      "0,70.96,4.65,156.73,0.35,-5.3,0.09,#NV,190.2,141.8,149.9,188.6,207.1\n",
                  skipping);
  EXPECT_TRUE(Contains(missing, "is not a number")) << missing;
  EXPECT_FALSE(Contains(missing, "a unit row?")) << missing;
  EXPECT_TRUE(Contains(MappedError(header, MapText("time: t\ncolumns:\n  x_m: X\n  y_m: Y\n"
                                                   "  z_m: Z\n  roll_deg: R\n  pitch_deg: P\n"
                                                   "  yaw_deg: W\n  T1_kN: F1\n  T2_kN: F2\n"
                                                   "unmapped: ignore\n")),
                       "no entry for 'T3_kN', 'T4_kN', 'T5_kN', 'T6_kN'"));
  const std::string typos = "t,X,SDP_PhasPos_Y,Z,R,P,W,F1,F2,CableForcee3,F4,F5,F6\n";
  EXPECT_TRUE(
      Contains(MappedError(typos, MapText("time: t\ncolumns:\n  x_m: X\n  y_m: SDP_PhaPos_Y\n"
                                          "  z_m: Z\n  roll_deg: R\n  pitch_deg: P\n"
                                          "  yaw_deg: W\n  T1_kN: F1\n  T2_kN: F2\n"
                                          "  T3_kN: F3\n  T4_kN: F4\n  T5_kN: F5\n"
                                          "  T6_kN: F6\nunmapped: ignore\n")),
               "(did you mean 'SDP_PhasPos_Y'?)"));
  EXPECT_TRUE(
      Contains(MappedError(typos, MapText("time: t\ncolumns:\n  x_m: X\n  y_m: SDP_PhasPos_Y\n"
                                          "  z_m: Z\n  roll_deg: R\n  pitch_deg: P\n"
                                          "  yaw_deg: W\n  T1_kN: F1\n  T2_kN: F2\n"
                                          "  T3_kN: CableForce3\n  T4_kN: F4\n  T5_kN: F5\n"
                                          "  T6_kN: F6\nunmapped: ignore\n")),
               "(did you mean 'CableForcee3'?)"));
}

TEST(ColumnMapTest, ReadsEveryUnit) {
  const std::string map = MapText(
      "time: {column: t}\ncolumns:\n"
      "  x_m: {column: X, unit: mm}\n  y_m: {column: Y, unit: cm}\n  z_m: {column: Z, unit: m}\n"
      "  roll_deg: {column: R, unit: rad}\n  pitch_deg: {column: P, unit: deg}\n"
      "  yaw_deg: {column: W, unit: rad}\n"
      "  T1_kN: {column: F1, unit: N}\n  T2_kN: {column: F2, unit: kN}\n"
      "  T3_kN: {column: F3, unit: tf}\n  T4_kN: {column: F4, unit: N}\n"
      "  T5_kN: {column: F5, unit: N}\n  T6_kN: {column: F6, unit: N}\n"
      "  s0_1_m: {column: L1, unit: mm}\n  s0_2_m: {column: L2, unit: cm}\n"
      "  s0_3_m: {column: L3, unit: m}\n  s0_4_m: {column: L4, unit: mm}\n"
      "  s0_5_m: {column: L5, unit: mm}\n  s0_6_m: {column: L6, unit: mm}\n");
  const Dataset d = Mapped(
      "t,X,Y,Z,R,P,W,F1,F2,F3,F4,F5,F6,L1,L2,L3,L4,L5,L6\n"
      "0,70960.5,465,156.73,0.01,-5.3,-0.02,214000.5,190.2,20,149900,188600,207100,"
      "312500,31250,312.5,300000,300000,300000\n",
      map);
  ASSERT_EQ(d.samples.size(), 1u);
  const Sample& s = d.samples[0];
  // Decimal units: the text's digits moved, one rounding: the double nearest the value.
  EXPECT_EQ(s.pose.position_m.x(), 70.9605);
  EXPECT_EQ(s.pose.position_m.y(), 4.65);
  EXPECT_EQ(s.pose.position_m.z(), 156.73);
  EXPECT_EQ(s.tension_n[0], 214000.5);
  EXPECT_EQ(s.tension_n[1], 190200.0);
  EXPECT_DOUBLE_EQ(s.tension_n[2], 20 * 9806.65);  // tonne-force
  EXPECT_EQ(s.tension_n[3], 149900.0);
  EXPECT_EQ(s.unstretched_length_m[0], 312.5);
  EXPECT_EQ(s.unstretched_length_m[1], 312.5);
  EXPECT_EQ(s.unstretched_length_m[2], 312.5);
  EXPECT_DOUBLE_EQ(s.measured_rpy_deg[0], 0.01 * 180.0 / M_PI);
  EXPECT_EQ(s.measured_rpy_deg[1], -5.3);
  EXPECT_DOUBLE_EQ(s.measured_rpy_deg[2], -0.02 * 180.0 / M_PI);
  EXPECT_TRUE(d.has_unstretched_lengths);
}

TEST(ColumnMapTest, ThroughAMapTheSameNumbersAsTheCanonicalFile) {
  // Mapped to itself (units and names fastcal's), a file reads exactly as without a map.
  const std::string text = std::string(kCanonicalHeader) + "\n" + kRow + "\n" +
                           "5,70.5,4.1,156.7,0.3,-5.2,0.1,213.9,190.1,141.7,149.8,188.5,207.0\n";
  Dataset canonical;
  std::string error;
  std::string renamed = text;
  renamed.replace(0, 1, "time_s");
  ASSERT_TRUE(ParseDataset(renamed, "data.csv", {}, &canonical, &error)) << error;
  const Dataset mapped = Mapped(text, PlainMap());
  ASSERT_EQ(mapped.samples.size(), canonical.samples.size());
  for (size_t k = 0; k < mapped.samples.size(); ++k) {
    EXPECT_EQ(mapped.samples[k].time_s, canonical.samples[k].time_s);
    EXPECT_EQ(mapped.samples[k].pose.position_m, canonical.samples[k].pose.position_m);
    EXPECT_EQ(mapped.samples[k].pose.rotation, canonical.samples[k].pose.rotation);
    EXPECT_EQ(mapped.samples[k].tension_n, canonical.samples[k].tension_n);
    EXPECT_EQ(mapped.samples[k].line, canonical.samples[k].line);
  }
}

// The time stamps of one row in `format` (and `zone`), read.
double TimeOf(const std::string& stamp, const std::string& time_map) {
  const Dataset d = Mapped(std::string(kCanonicalHeader) + "\n\"" + stamp + "\"" +
                               std::string(kRow).substr(std::string(kRow).find(',')) + "\n",
                           MapText("time: " + time_map + "\n" + Columns()));
  return d.samples.empty() ? NAN : d.samples[0].time_s;
}

TEST(ColumnMapTest, ReadsEachTimeFormatAndZone) {
  // 2024-05-01T12:34:56Z
  constexpr double kUnix = 1714566896.0;
  EXPECT_EQ(TimeOf("2.5", "{column: t}"), 2.5);
  EXPECT_EQ(TimeOf("2.5", "{column: t, format: seconds}"), 2.5);
  EXPECT_EQ(TimeOf("1714566896.25", "{column: t, format: unix_s}"), kUnix + 0.25);
  EXPECT_EQ(TimeOf("1714566896250", "{column: t, format: unix_ms}"), kUnix + 0.25);
  EXPECT_EQ(TimeOf("1714566896250000", "{column: t, format: unix_us}"), kUnix + 0.25);
  const std::string iso = "{column: t, format: iso8601, zone: UTC}";
  EXPECT_EQ(TimeOf("2024-05-01T12:34:56Z", iso), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01 12:34:56", iso), kUnix);  // no zone in the text: the map's
  EXPECT_EQ(TimeOf("2024-05-01T12:34:56.25", iso), kUnix + 0.25);
  EXPECT_EQ(TimeOf("2024-05-01T12:34:56,25", iso), kUnix + 0.25);  // ISO's decimal comma
  EXPECT_EQ(TimeOf("2024-05-01T12:34", iso), kUnix - 56);
  EXPECT_EQ(TimeOf("2024-05-01T20:34:56+08:00", iso), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01T20:34:56+0800", iso), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01T20:34:56+08", iso), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01T07:04:56-05:30", iso), kUnix);
  // The map's zone applies to text without one; text with one keeps its own.
  const std::string beijing = "{column: t, format: iso8601, zone: \"+08:00\"}";
  EXPECT_EQ(TimeOf("2024-05-01 20:34:56", beijing), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01 12:34:56Z", beijing), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01 13:34:56+01:00", beijing), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01 20:34:56", "{column: t, format: iso8601, zone: UTC}"),
            kUnix + 8 * 3600);
  // A pattern of the date library's flags.
  EXPECT_EQ(TimeOf("2024/05/01 20:34:56.5",
                   "{column: t, format: \"%Y/%m/%d %H:%M:%S\", zone: \"+0800\"}"),
            kUnix + 0.5);
  EXPECT_EQ(TimeOf("01.05.2024 12:34", "{column: t, format: \"%d.%m.%Y %H:%M\", zone: UTC}"),
            kUnix - 56);
  // A date cell or a datetime column arrives as ISO text whatever the pattern: read as
  // the instant it is, in the map's zone; text neither the pattern nor ISO still fails.
  const std::string slashes = "{column: t, format: \"%Y/%m/%d %H:%M:%S\", zone: \"+08:00\"}";
  EXPECT_EQ(TimeOf("2024-05-01 20:34:56", slashes), kUnix);
  EXPECT_EQ(TimeOf("2024-05-01T20:34:56.5", slashes), kUnix + 0.5);
  EXPECT_TRUE(Contains(MappedError(std::string(kCanonicalHeader) + "\n01.05.2024 20:34:56" +
                                       std::string(kRow).substr(std::string(kRow).find(',')) + "\n",
                                   MapText("time: " + slashes + "\n" + Columns())),
                       "data.csv:2: column 't'"));
  // A leap second (2016-12-31T23:59:60Z, the last one) reads as the next day's first
  // second; :60 at another minute is refused (issue 37).
  EXPECT_EQ(TimeOf("2016-12-31T23:59:60.5Z", iso), 1483228800.5);
  EXPECT_EQ(TimeOf("2017-01-01T07:59:60+08:00", iso), 1483228800.0);
  // A zone's name is not read (issue 37): %Z refused at the map's line.
  EXPECT_TRUE(Contains(MapError(MapText("time: {column: t, format: \"%Y-%m-%d %H:%M %Z\", "
                                        "zone: UTC}\ncolumns: {}\n")),
                       "map.yaml:2: time.format: %Z (a zone's name) is not read"));
  // Clock times without a zone in the map: an error that asks for one (issue 39; they
  // were read as UTC, a Beijing export 8 hours off).
  for (const char* time : {"{column: t, format: iso8601}", "{column: t, format: \"%Y %H\"}"}) {
    EXPECT_TRUE(Contains(MapError(MapText(std::string("time: ") + time + "\ncolumns: {}\n")),
                         "map.yaml:2: time.zone: missing: clock times need the zone"))
        << time;
  }
  // Across a day and a year.
  EXPECT_EQ(TimeOf("2024-01-01T07:59:59+08:00", iso), 1704067199.0);
  EXPECT_EQ(TimeOf("2024-02-29T00:00:00Z", iso), 1709164800.0);
  // Microseconds are kept.
  EXPECT_NEAR(TimeOf("2024-05-01T12:34:56.000001Z", iso) - kUnix, 1e-6, 2.5e-7);
}

TEST(ColumnMapTest, BadTimeStampsNameTheSourceColumnAndTheFastcalName) {
  const std::string map =
      MapText("time: {column: SysTime, format: iso8601, zone: UTC}\n" + Columns());
  const std::string header = "SysTime" + std::string(kCanonicalHeader).substr(1);
  const std::string row = std::string(kRow).substr(std::string(kRow).find(','));
  for (const char* bad :
       {"2024-02-30 00:00:00", "2024-05-01 25:00:00", "2024-05-01", "2024-05-01 12:00:61",
        "2024-05-01 12:00:60", "12:00:00", "2024-05-01 12:00:00+25:00"}) {
    const std::string error = MappedError(header + "\n" + bad + row + "\n", map);
    EXPECT_TRUE(Contains(error, "data.csv:2: column 'SysTime' (time_s, iso8601): ")) << bad;
    EXPECT_TRUE(Contains(error, "is not an ISO 8601 date and time")) << bad;
  }
  EXPECT_TRUE(
      Contains(MappedError(header + "\n1714566896abc" + row + "\n",
                           MapText("time: {column: SysTime, format: unix_ms}\n" + Columns())),
               "data.csv:2: column 'SysTime' (time_s, unix_ms): '1714566896abc' is not a number"));
}

TEST(ColumnMapTest, ValueErrorsNameTheFileLineSourceColumnAndFastcalName) {
  const std::string map =
      MapText("time: {column: t}\n" + Columns({{"T3_kN", "{column: CableForce3, unit: N}"},
                                               {"z_m", "{column: PosZ, unit: mm}"}}));
  const std::string header =
      "t,x_m,y_m,PosZ,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,CableForce3,T4_kN,T5_kN,T6_kN";
  EXPECT_TRUE(Contains(MappedError(header + "\n0,1,2,150000,0,0,0,200,200,abc,200,200,200\n", map),
                       "data.csv:2: column 'CableForce3' (T3_kN, N): 'abc' is not a number"));
  EXPECT_TRUE(Contains(MappedError(header + "\n0,1,2,150000,0,0,0,200,200,-5,200,200,200\n", map),
                       "data.csv:2: column 'CableForce3' (T3_kN, N): -0.005 kN is negative"));
  // The position's three columns, named as the export names them.
  EXPECT_TRUE(Contains(
      MappedError(header + "\n0,1,2,-150,0,0,0,200,200,200000,200,200,200\n", map),
      "data.csv:2: columns 'x_m,y_m,PosZ' (x_m,y_m,z_m): z = -0.15 m is below the reflector"));
}

TEST(ColumnMapTest, DelimitersAndDecimalCommas) {
  const std::string base = std::string(kCanonicalHeader) + "\n" + kRow + "\n";
  const auto with = [&](char delimiter, bool comma) {
    std::string text = base;
    for (char& c : text) {
      if (c == ',') c = delimiter;
    }
    if (comma) {
      for (size_t k = text.find('\n'); k < text.size(); ++k) {
        if (text[k] == '.') text[k] = ',';
      }
    }
    return text;
  };
  const Dataset expected = Mapped(base, PlainMap());
  for (char delimiter : {';', '\t', '|'}) {
    for (bool comma : {false, true}) {
      const std::string decimal = comma ? "decimal: \",\"\n" : "";
      // Detected from the header line.
      const Dataset d =
          Mapped(with(delimiter, comma), MapText(decimal + "time: {column: t}\n" + Columns()));
      ASSERT_EQ(d.samples.size(), 1u) << delimiter;
      EXPECT_EQ(d.samples[0].tension_n, expected.samples[0].tension_n);
      EXPECT_EQ(d.samples[0].pose.position_m, expected.samples[0].pose.position_m);
      EXPECT_EQ(d.samples[0].time_s, 2.5);
    }
  }
  // Said in the map, by character and by name.
  EXPECT_EQ(Mapped(with(';', true),
                   MapText("delimiter: \";\"\ndecimal: \",\"\ntime: {column: t}\n" + Columns()))
                .samples[0]
                .time_s,
            2.5);
  EXPECT_EQ(Mapped(with('\t', false), MapText("delimiter: tab\ntime: {column: t}\n" + Columns()))
                .samples[0]
                .time_s,
            2.5);
  // Runs of spaces.
  std::string spaced = with(' ', false);
  spaced.replace(spaced.find(' '), 1, "   ");
  EXPECT_EQ(Mapped("  " + spaced, MapText("delimiter: spaces\ntime: {column: t}\n" + Columns()))
                .samples[0]
                .time_s,
            2.5);
  // Quoted numbers with a decimal comma, the delimiter detected (not ',': the decimal mark).
  const Dataset quoted =
      Mapped(with(';', false).substr(0, base.find('\n') + 1) +
                 "\"2,5\";\"70,96\";4;\"156,73\";0;0;0;214;190;141;149;188;207\n",
             MapText("decimal: \",\"\ntime: {column: t}\n" + Columns()));
  ASSERT_EQ(quoted.samples.size(), 1u);
  EXPECT_EQ(quoted.samples[0].time_s, 2.5);
  EXPECT_EQ(quoted.samples[0].pose.position_m.x(), 70.96);
  // A decimal comma the map does not declare: the row has too many fields.
  EXPECT_TRUE(Contains(MappedError(base.substr(0, base.find('\n') + 1) +
                                       "2,5,70.96,4.65,156.73,0.35,-5.30,0.09,214.0,190.2,141.8,"
                                       "149.9,188.6,207.1\n",
                                   PlainMap()),
                       "data.csv:2: expected 13 fields (as in the header), found 14 (a decimal "
                       "comma? say decimal:"));
}

TEST(ColumnMapTest, HeaderLineUnitRowQuotesAndTrailingDelimiters) {
  const std::string map =
      MapText("header_line: 3\nskip_after_header: 2\ntime: {column: Time stamp}\n" +
              Columns({{"x_m", "{column: \"Pos X, mm\", unit: mm}"},
                       {"T1_kN", "{column: 'Force \"1\"', unit: N}"}}));
  const std::string text =
      "Export of the FAST feed cabin\n"
      "exported 2024-05-01,,,\n"
      "\"Time stamp\",\"Pos X, mm\",y_m,z_m,roll_deg,pitch_deg,yaw_deg,\"Force \"\"1\"\"\","
      "T2_kN,T3_kN,T4_kN,T5_kN,T6_kN,\n"
      "s,mm,m,m,deg,deg,deg,N,kN,kN,kN,kN,kN,\n"
      "\n"
      "2.5,70960,4.65,156.73,0.35,-5.30,0.09,214000,190.2,141.8,149.9,188.6,207.1,\n"
      ",,,,,,,,,,,,,\n"  // a spreadsheet's empty row: blank
      "5,\"70 960\",4.65,156.73,0.35,-5.30,0.09,214000,190.2,141.8,149.9,188.6,207.1\n";
  // Line 8's position has a space: an error naming it (line numbers count every line).
  EXPECT_TRUE(Contains(MappedError(text, map),
                       "data.csv:8: column 'Pos X, mm' (x_m, mm): '70 960' is not a number"));
  std::string good = text;
  good.replace(good.find("70 960"), 6, "70960");
  const Dataset d = Mapped(good, map);
  ASSERT_EQ(d.samples.size(), 2u);
  EXPECT_EQ(d.samples[0].line, 6);
  EXPECT_EQ(d.samples[0].pose.position_m.x(), 70.96);
  EXPECT_EQ(d.samples[0].tension_n[0], 214000.0);
  EXPECT_EQ(d.samples[1].time_s, 5.0);
}

TEST(ColumnMapTest, AQuotedHeaderMayBreakALine) {
  const std::string map =
      MapText("time: {column: t}\n" + Columns({{"T1_kN", "{column: \"Force 1\\n(N)\", unit: N}"}}));
  const std::string text =
      "t,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,\"Force 1\n(N)\",T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n"
      "2.5,70.96,4.65,156.73,0.35,-5.30,0.09,214000,190.2,141.8,149.9,188.6,207.1\n";
  const Dataset d = Mapped(text, map);
  ASSERT_EQ(d.samples.size(), 1u);
  EXPECT_EQ(d.samples[0].line, 3);
  EXPECT_EQ(d.samples[0].tension_n[0], 214000.0);
  EXPECT_TRUE(Contains(MappedError("\"t,x_m\n", map), "a quote opened at byte 1 is not closed"));
}

TEST(ColumnMapTest, UnmappedChannelsAreNamedOrIgnored) {
  const std::string header = std::string(kCanonicalHeader) + ",wind_speed_m_s,Temp";
  const std::string text = header + "\n" + kRow + ",3.2,18\n";
  EXPECT_TRUE(Contains(MappedError(text, PlainMap()),
                       "data.csv:1: 2 columns not in the column map map.yaml: "
                       "'wind_speed_m_s', 'Temp' (map each under columns:, or set unmapped: "
                       "ignore)"));
  const Dataset d = Mapped(text, PlainMap() + "unmapped: ignore\n");
  ASSERT_EQ(d.samples.size(), 1u);
  // An unmapped field is not read: any text there.
  EXPECT_EQ(Mapped(header + "\n" + kRow + ",n/a,\"x,y\"\n", PlainMap() + "unmapped: ignore\n")
                .samples.size(),
            1u);
  // A mapped column the header has twice.
  EXPECT_TRUE(Contains(MappedError(std::string(kCanonicalHeader) + ",T6_kN\n", PlainMap()),
                       "data.csv:1: column 'T6_kN' (mapped to T6_kN) appears twice (fields 13 "
                       "and 14)"));
}

TEST(ColumnMapTest, SessionsAndThreads) {
  const std::string map = PlainMap() + "  session: Survey\n";
  std::string text = std::string(kCanonicalHeader) + ",Survey\n";
  for (int k = 0; k < 3000; ++k) text += kRow + std::string(k < 1500 ? ",day1\n" : ",day2\n");
  Dataset one, two;
  std::string error;
  ASSERT_TRUE(ReadMapped(text, map, &one, &error, 1)) << error;
  ASSERT_TRUE(ReadMapped(text, map, &two, &error, 2)) << error;
  ASSERT_EQ(one.session_labels, (std::vector<std::string>{"day1", "day2"}));
  ASSERT_EQ(one.samples.size(), two.samples.size());
  EXPECT_EQ(one.samples.back().session, 1);
  EXPECT_EQ(two.samples.back().session, 1);
}

TEST(ColumnMapTest, TheBundledFastExportReadsAsTheSurveyItCameFrom) {
  const std::string dir = SourceDir() + "/calibration_data/";
  auto map = std::make_shared<ColumnMap>();
  std::string error;
  ASSERT_TRUE(LoadColumnMap(dir + "fast_export.columns.yaml", map.get(), &error)) << error;
  DatasetReadOptions options;
  options.threads = 2;
  options.columns = map;
  Dataset exported, survey;
  ASSERT_TRUE(ReadDataset(dir + "fast_export.csv", options, &exported, &error)) << error;
  ASSERT_TRUE(ReadDataset(dir + "realistic_survey.csv", {}, &survey, &error)) << error;
  ASSERT_EQ(exported.samples.size(), survey.samples.size());
  EXPECT_EQ(exported.time_offset_s, 8 * 3600);
  EXPECT_TRUE(exported.has_planned_attitude);
  EXPECT_TRUE(exported.has_unstretched_lengths);
  // 2024-05-01T20:00:00+08:00
  constexpr double kStart = 1714564800.0;
  for (size_t k = 0; k < survey.samples.size(); ++k) {
    const Sample& a = exported.samples[k];
    const Sample& b = survey.samples[k];
    ASSERT_EQ(a.time_s - kStart, b.time_s) << k;
    // Units as decimal digits moved: the very same numbers.
    ASSERT_EQ(a.pose.position_m, b.pose.position_m) << k;
    ASSERT_EQ(a.measured_rpy_deg, b.measured_rpy_deg) << k;
    ASSERT_EQ(a.tension_n, b.tension_n) << k;
    ASSERT_EQ(a.unstretched_length_m, b.unstretched_length_m) << k;
    ASSERT_EQ(a.planned_rpy_deg, b.planned_rpy_deg) << k;
  }
  const TimeDisplay display = TimeDisplayOf(exported);
  EXPECT_TRUE(display.absolute);
  EXPECT_EQ(TimeText(exported.samples[1].time_s, display), "2024-05-01 20:00:02 UTC+08:00");
}

TEST(ColumnMapTest, ChunkedReadingThroughAMapGivesTheWholeRead) {
  const std::string dir = SourceDir() + "/calibration_data/";
  auto map = std::make_shared<ColumnMap>();
  std::string error;
  ASSERT_TRUE(LoadColumnMap(dir + "fast_export.columns.yaml", map.get(), &error)) << error;
  DatasetReadOptions options;
  options.columns = map;
  Dataset whole;
  ASSERT_TRUE(ReadDataset(dir + "fast_export.csv", options, &whole, &error)) << error;
  DatasetChunkReader reader;
  ASSERT_TRUE(reader.Open(dir + "fast_export.csv", options, &error)) << error;
  Dataset chunk;
  bool done = false;
  size_t n = 0;
  while (!done) {
    ASSERT_TRUE(reader.Next(100, &chunk, &done, &error)) << error;
    for (const Sample& s : chunk.samples) {
      ASSERT_EQ(s.time_s, whole.samples[n].time_s);
      ASSERT_EQ(s.line, whole.samples[n].line);
      ++n;
    }
  }
  EXPECT_EQ(n, whole.samples.size());
  EXPECT_EQ(chunk.time_offset_s, 8 * 3600);
}

TEST(ColumnMapTest, PoseFilesThroughAMap) {
  const ColumnMap map = Map(
      MapText("delimiter: \";\"\ndecimal: \",\"\ntime: {column: SysTime, format: iso8601, zone: "
              "\"+08:00\"}\ncolumns:\n  x_m: {column: X, unit: mm}\n  y_m: {column: Y, unit: mm}\n"
              "  z_m: {column: Z, unit: mm}\n  yaw_deg: {column: Yaw, unit: rad}\n"
              "  pitch_deg: P\n  roll_deg: R\n  T1_kN: {column: F1, unit: N}\nunmapped: ignore\n"));
  std::vector<Pose> poses;
  std::vector<double> times;
  std::string error;
  ASSERT_TRUE(
      ParsePosesCsv("SysTime;X;Y;Z;Yaw;P;R;Wind\n"
                    "2024-05-01 20:00:00;1000;-2500,5;150000;0;0;0;3,2\n",
                    "poses.csv", map, &poses, &times, &error))
      << error;
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].position_m, Eigen::Vector3d(1.0, -2.5005, 150.0));
  EXPECT_EQ(times[0], 1714564800.0);
  EXPECT_FALSE(ParsePosesCsv("SysTime;X;Y;Z;Yaw;P;R\n2024-05-01 20:00:00;1000;x;150000;0;0;0\n",
                             "poses.csv", map, &poses, &times, &error));
  EXPECT_TRUE(Contains(error, "poses.csv:2: column 'Y' (y_m): 'x' is not a number"));
  const ColumnMap no_z = Map(MapText("columns:\n  x_m: X\n  y_m: Y\n"));
  EXPECT_FALSE(ParsePosesCsv("X,Y\n1,2\n", "poses.csv", no_z, &poses, &times, &error));
  EXPECT_TRUE(Contains(error, "map.yaml:2: columns: no entry for 'z_m'"));
}

TEST(ColumnMapTest, SpreadsheetsAreRefusedNamingThePythonRouteAndXlsx2csv) {
  const fs::path dir = fs::temp_directory_path() / "fastcal_column_map_test";
  fs::create_directories(dir);
  const std::string xlsx = (dir / "export.xlsx").string();
  std::ofstream(xlsx) << "PK\x03\x04 not really";
  const std::string renamed = (dir / "export.csv").string();
  std::ofstream(renamed) << "PK\x03\x04 a workbook renamed";
  for (const std::string& path : {xlsx, renamed}) {
    Dataset d;
    std::string error;
    EXPECT_FALSE(ReadDataset(path, {}, &d, &error));
    EXPECT_TRUE(Contains(error, "a spreadsheet, not CSV text")) << path;
    EXPECT_TRUE(Contains(error, "fastcal.read_dataset(")) << path;
    EXPECT_TRUE(Contains(error, "xlsx2csv")) << path;
    std::vector<Pose> poses;
    EXPECT_FALSE(ReadPosesCsv(path, &poses, nullptr, &error));
    EXPECT_TRUE(Contains(error, "a spreadsheet")) << path;
  }
  fs::remove_all(dir);
}

TEST(TimeTextTest, ShowsUnixTimesAsDatesAndSecondsAsSeconds) {
  constexpr double kUnix = 1714566896.0;  // 2024-05-01T12:34:56Z
  EXPECT_FALSE(IsUnixTime(99999999.0));
  EXPECT_TRUE(IsUnixTime(1e8));
  const TimeDisplay utc = TimeDisplayFor(kUnix, 0), beijing = TimeDisplayFor(kUnix, 8 * 3600);
  EXPECT_EQ(TimeText(kUnix, utc), "2024-05-01 12:34:56 UTC");
  EXPECT_EQ(TimeText(kUnix + 0.25, beijing), "2024-05-01 20:34:56.25 UTC+08:00");
  EXPECT_EQ(TimeRangeText(kUnix, kUnix + 2880, beijing),
            "2024-05-01 20:34:56 to 21:22:56 UTC+08:00");
  EXPECT_EQ(TimeRangeText(kUnix, kUnix + 86400, utc),
            "2024-05-01 12:34:56 to 2024-05-02 12:34:56 UTC");
  const TimeDisplay seconds = TimeDisplayFor(0.0, 8 * 3600);
  EXPECT_FALSE(seconds.absolute);
  EXPECT_EQ(TimeText(800, seconds), "800 s");
  EXPECT_EQ(TimeRangeText(0, 2880, seconds), "t = 0 to 2880 s");
  EXPECT_EQ(IsoUnixTime(kUnix + 0.5, 8 * 3600), "2024-05-01T20:34:56.5+08:00");
  EXPECT_EQ(IsoUnixTime(kUnix, 0), "2024-05-01T12:34:56Z");
  EXPECT_EQ(IsoUnixTime(kUnix, -5 * 3600 - 1800), "2024-05-01T07:04:56-05:30");
  EXPECT_EQ(UtcOffsetName(-5 * 3600 - 1800), "UTC-05:30");
  EXPECT_EQ(TimeAxisLabel(kUnix, kUnix + 60, beijing), "time on 2024-05-01 (UTC+08:00)");
  // What a user types back reads to the same time, within 1 us.
  for (double t : {kUnix, kUnix + 0.123456, 1e8 + 0.5, 2e9 + 1.0 / 3.0}) {
    double back = 0.0;
    std::string why;
    ASSERT_TRUE(ParseTimeValue(TimeValueText(t, beijing), 0, &back, &why)) << why;
    EXPECT_NEAR(back, t, 1e-6);
    ASSERT_TRUE(ParseTimeValue(TimeValueText(t, utc), 3600, &back, &why)) << why;
    EXPECT_NEAR(back, t, 1e-6);
  }
  // Beyond year 9999: a number, not a date (and no overflow).
  EXPECT_FALSE(IsUnixTime(1e300));
  EXPECT_EQ(TimeText(1e300, beijing), "1e+300 s");
  EXPECT_EQ(TimeRangeText(3e11, 3e11, beijing), "t = 3e+11 to 3e+11 s");
  double t = 0.0;
  std::string why;
  ASSERT_TRUE(ParseTimeValue("800.5", 0, &t, &why));
  EXPECT_EQ(t, 800.5);
  ASSERT_TRUE(ParseTimeValue("2024-05-01T20:34:56", 8 * 3600, &t, &why));
  EXPECT_EQ(t, kUnix);
  EXPECT_FALSE(ParseTimeValue("noon", 0, &t, &why));
  EXPECT_TRUE(Contains(why, "'noon' is neither a time in seconds"));
}

TEST(TimeTextTest, PlotsOfUnixTimesHaveAClockTimeAxis) {
  constexpr double kStart = 1714564800.0;  // 2024-05-01T20:00:00+08:00
  PlotSeries series{"T1", {}, {}};
  for (int k = 0; k <= 1440; ++k) {
    series.x.push_back(kStart + 2.0 * k);
    series.y.push_back(150.0 + k % 7);
  }
  PlotOptions options;
  options.x_unix_time = true;
  options.x_time_offset_s = 8 * 3600;
  options.x_label = TimeAxisLabel(kStart, kStart + 2880, TimeDisplayFor(kStart, 8 * 3600));
  const std::string svg = SvgLinePlot({series}, options);
  EXPECT_TRUE(Contains(svg, ">20:10<"));
  EXPECT_TRUE(Contains(svg, ">20:40<"));
  EXPECT_TRUE(Contains(svg, "time on 2024-05-01 (UTC+08:00)"));
  EXPECT_EQ(svg.find("e+09"), std::string::npos);
  EXPECT_EQ(svg.find(">1.71"), std::string::npos);
  // Over days: dates with the clock; over weeks: dates.
  series.x = {kStart, kStart + 3 * 86400.0};
  series.y = {1, 2};
  const std::string days = SvgLinePlot({series}, options);
  EXPECT_TRUE(Contains(days, ">05-02 ")) << days;
  series.x = {kStart, kStart + 60 * 86400.0};
  EXPECT_TRUE(Contains(SvgLinePlot({series}, options), ">05-"));
  // A few seconds: seconds on the clock.
  series.x = {kStart, kStart + 20.0};
  EXPECT_TRUE(Contains(SvgLinePlot({series}, options), ">20:00:10<"));
}

TEST(TimeTextTest, CutsASurveyIntoSessionsAtTimes) {
  Dataset d;
  d.path = "survey.csv";
  for (int k = 0; k < 10; ++k) {
    Sample s;
    s.time_s = 1714564800.0 + 2.0 * k;
    s.line = k + 2;
    d.samples.push_back(s);
  }
  std::string error;
  ASSERT_TRUE(CutSessionsAt({1714564800.0 + 8.0, 1714564800.0 + 15.0}, &d, &error)) << error;
  EXPECT_EQ(d.session_labels, (std::vector<std::string>{"s1", "s2", "s3"}));
  EXPECT_EQ(d.samples[3].session, 0);
  EXPECT_EQ(d.samples[4].session, 1);  // at the cut: after it
  EXPECT_EQ(d.samples[7].session, 1);
  EXPECT_EQ(d.samples[8].session, 2);
  // A cut written to the microsecond still takes the sample at it.
  Dataset again = d;
  again.session_labels.clear();
  ASSERT_TRUE(CutSessionsAt({1714564808.0000004}, &again, &error)) << error;
  EXPECT_EQ(again.samples[4].session, 1);
  // Refused: sessions already, an empty session, times that do not increase.
  EXPECT_FALSE(CutSessionsAt({1714564810.0}, &d, &error));
  EXPECT_TRUE(Contains(error, "the data has sessions already"));
  again.session_labels.clear();
  EXPECT_FALSE(CutSessionsAt({1714564900.0}, &again, &error));
  EXPECT_TRUE(Contains(error, "no sample from 2024-05-01 12:01:40 UTC to the end (session s2"));
  EXPECT_FALSE(CutSessionsAt({5.0, 4.0}, &again, &error));
  EXPECT_TRUE(Contains(error, "the times must increase"));
}

}  // namespace
}  // namespace fastcal
