// Tests of the cable robot model (cable_robot.h): the nominal FAST layout against the
// formulas of model.md, physical validation naming the offending key, the YAML format of
// docs/model-format.md (exact round trip, defaults, every class of error with file, line
// and key) and the atomic save.
#include "fastcal/cable_robot.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bounded_process.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kSeed = 20240917;
// The nominal layout is computed with the same cos/sin as the formulas: a few ulps of
// 300 m at most.
constexpr double kGeometryTolM = 1e-12;
constexpr double kDeg = M_PI / 180.0;

// Field-by-field exact equality (EXPECT_EQ on every double).
void ExpectIdentical(const CableRobot& a, const CableRobot& b) {
  ASSERT_EQ(a.anchor_points_cabin_m.size(), b.anchor_points_cabin_m.size());
  for (size_t j = 0; j < a.anchor_points_cabin_m.size(); ++j) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(a.anchor_points_cabin_m[j][k], b.anchor_points_cabin_m[j][k])
          << "anchor " << j << " coordinate " << k;
    }
  }
  for (int i = 0; i < kNumCables; ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(a.cables[i].tower_top_m[k], b.cables[i].tower_top_m[k])
          << "cable " << i << " coordinate " << k;
    }
    EXPECT_EQ(a.cables[i].anchor_index, b.cables[i].anchor_index) << "cable " << i;
    EXPECT_EQ(a.cables[i].ea_n, b.cables[i].ea_n) << "cable " << i;
    EXPECT_EQ(a.cables[i].linear_density_kg_per_m, b.cables[i].linear_density_kg_per_m)
        << "cable " << i;
  }
  EXPECT_EQ(a.cabin_mass_kg, b.cabin_mass_kg);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(a.mass_centre_cabin_m[k], b.mass_centre_cabin_m[k]);
  EXPECT_EQ(a.cabin_inertia_kg_m2, b.cabin_inertia_kg_m2);
  EXPECT_EQ(a.gravity_m_per_s2, b.gravity_m_per_s2);
  ASSERT_EQ(a.reflector.has_value(), b.reflector.has_value());
  if (a.reflector.has_value()) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.reflector->centre_m[k], b.reflector->centre_m[k]);
    EXPECT_EQ(a.reflector->radius_m, b.reflector->radius_m);
    EXPECT_EQ(a.reflector->aperture_m, b.reflector->aperture_m);
  }
}

// A fresh empty directory, removed (with its contents) at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string templ = ::testing::TempDir() + "cable_robot_test.XXXXXX";
    EXPECT_NE(::mkdtemp(templ.data()), nullptr);
    path_ = templ;
  }
  ~TempDir() {
    ::chmod(path_.c_str(), 0700);
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }
  std::vector<std::string> Entries() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(path_)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }

 private:
  std::string path_;
};

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// "cables:" on line 1, then cable i (0-based) in flow style on line i + 2, with the
// nominal values written to 17 digits; `omit_key` is left out of cable `omit_in`.
std::string CablesYaml(int count, int omit_in = -1, const std::string& omit_key = "") {
  const CableRobot nominal = CableRobot::NominalFast();
  std::ostringstream s;
  s.precision(17);
  s << "cables:\n";
  for (int i = 0; i < count; ++i) {
    const CableProperties& c = nominal.cables[i % kNumCables];
    std::vector<std::string> parts;
    std::ostringstream part;
    part.precision(17);
    part << "tower_top_m: [" << c.tower_top_m.x() << ", " << c.tower_top_m.y() << ", "
         << c.tower_top_m.z() << "]";
    parts.push_back(part.str());
    parts.push_back("anchor: " + std::to_string(c.anchor_index));
    parts.push_back("ea_n: 2.4656e7");
    parts.push_back("linear_density_kg_per_m: 11.718");
    s << "  - {";
    bool first = true;
    for (const std::string& p : parts) {
      if (i == omit_in && p.rfind(omit_key + ":", 0) == 0) continue;
      s << (first ? "" : ", ") << p;
      first = false;
    }
    s << "}\n";
  }
  return s.str();
}

// Parses `text` as "m.yaml", expecting failure; returns the message.
std::string ParseError(const std::string& text) {
  CableRobot robot;
  std::string error;
  EXPECT_FALSE(ParseCableRobotYaml(text, "m.yaml", &robot, &error)) << text;
  return error;
}

// Unit and magnitude slips in a model file (issue 17) are refused at the key, with the
// nominal value and the likely slip, before any statics can fail on them.
TEST(CableRobotYaml, ImplausibleValuesAreRefusedAtTheirKeyWithTheLikelySlip) {
  EXPECT_EQ(ParseError("cabin:\n  mass_kg: 30\n"),
            "m.yaml:2: cabin.mass_kg: 30 kg is below the plausible minimum of 10000 kg (nominal "
            "FAST: 30000 kg; tonnes written as kg?)");
  EXPECT_EQ(ParseError("cabin:\n  mass_centre_m: [0, 0, 500]\n"),
            "m.yaml:2: cabin.mass_centre_m.z: 500 m is beyond the plausible +-5 m (mm written "
            "as m?)");
  std::string cables = "cables:\n";
  const CableRobot nominal = CableRobot::NominalFast();  // outlives the references below
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = nominal.cables[i];
    cables += "  - {tower_top_m: [" + std::to_string(c.tower_top_m.x()) + ", " +
              std::to_string(c.tower_top_m.y()) +
              ", 270], anchor: " + std::to_string(c.anchor_index) +
              ", ea_n: " + (i == 2 ? "24656" : "2.4656e7") + ", linear_density_kg_per_m: 11.718}\n";
  }
  EXPECT_EQ(ParseError(cables),
            "m.yaml:4: cables[2].ea_n: 24656 N is below the plausible minimum of 5e+06 N "
            "(nominal FAST: 2.4656e+07 N; kN written as N?)");
}

TEST(NominalFast, TowersFollowModelFormula) {
  constexpr double kTowerRadiusM = 300.0, kTowerHeightM = 270.0;
  const CableRobot robot = CableRobot::NominalFast();
  for (int i = 1; i <= kNumCables; ++i) {  // model.md numbers towers from 1
    const Eigen::Vector3d& b = robot.cables[i - 1].tower_top_m;
    EXPECT_NEAR(b.x(), kTowerRadiusM * std::cos(M_PI * (i - 1) / 3.0), kGeometryTolM) << i;
    EXPECT_NEAR(b.y(), kTowerRadiusM * std::sin(M_PI * (i - 1) / 3.0), kGeometryTolM) << i;
    EXPECT_NEAR(b.z(), kTowerHeightM, kGeometryTolM) << i;
  }
  // Tower B1 is on the +x axis (the global frame's definition).
  EXPECT_NEAR(robot.cables[0].tower_top_m.y(), 0.0, kGeometryTolM);
  EXPECT_GT(robot.cables[0].tower_top_m.x(), 0.0);
}

TEST(NominalFast, AnchorsAt30150And270Degrees) {
  constexpr double kAnchorRadiusM = 7.5;
  const CableRobot robot = CableRobot::NominalFast();
  ASSERT_EQ(robot.anchor_points_cabin_m.size(), 3u);
  const double angles_deg[3] = {30.0, 150.0, 270.0};
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d& a = robot.anchor_points_cabin_m[j];
    EXPECT_NEAR(a.x(), kAnchorRadiusM * std::cos(angles_deg[j] * kDeg), kGeometryTolM) << j;
    EXPECT_NEAR(a.y(), kAnchorRadiusM * std::sin(angles_deg[j] * kDeg), kGeometryTolM) << j;
    EXPECT_EQ(a.z(), 0.0) << j;
  }
  // Written out: (7.5 cos 30, 3.75), (-7.5 cos 30, 3.75), (0, -7.5).
  EXPECT_NEAR(robot.anchor_points_cabin_m[0].y(), 3.75, kGeometryTolM);
  EXPECT_NEAR(robot.anchor_points_cabin_m[1].x(), -7.5 * std::sqrt(3.0) / 2.0, kGeometryTolM);
  EXPECT_NEAR(robot.anchor_points_cabin_m[2].y(), -7.5, kGeometryTolM);
}

TEST(NominalFast, CablesPairedOnAnchorsWithTable1Parameters) {
  const CableRobot robot = CableRobot::NominalFast();
  // model.md: anchor of cable i (1-based) is floor((i-1)/2).
  const int expected_anchor[kNumCables] = {0, 0, 1, 1, 2, 2};
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_EQ(robot.cables[i].anchor_index, expected_anchor[i]) << i;
    EXPECT_EQ(&robot.AnchorOfCable(i), &robot.anchor_points_cabin_m[expected_anchor[i]]);
    EXPECT_EQ(robot.cables[i].ea_n, 1.6e11 * 1.541e-4) << i;
    EXPECT_EQ(robot.cables[i].linear_density_kg_per_m, 11.718) << i;
  }
  EXPECT_EQ(robot.cabin_mass_kg, 30000.0);
  EXPECT_EQ(robot.mass_centre_cabin_m, Eigen::Vector3d(0.0, 0.0, 0.5));
  EXPECT_EQ(robot.gravity_m_per_s2, -9.8);
  std::string error;
  EXPECT_TRUE(robot.IsValid(&error)) << error;
}

struct InvalidCase {
  const char* name;
  std::function<void(CableRobot*)> spoil;
  const char* key;  // IsValid's message must start with "<key>: "
};

TEST(CableRobotIsValid, NamesTheKeyOfEachNonPhysicalValue) {
  const std::vector<InvalidCase> cases = {
      {"zero EA", [](CableRobot* r) { r->cables[2].ea_n = 0.0; }, "cables[2].ea_n"},
      {"negative EA", [](CableRobot* r) { r->cables[5].ea_n = -1.0; }, "cables[5].ea_n"},
      {"NaN EA", [](CableRobot* r) { r->cables[1].ea_n = NAN; }, "cables[1].ea_n"},
      {"zero density", [](CableRobot* r) { r->cables[0].linear_density_kg_per_m = 0.0; },
       "cables[0].linear_density_kg_per_m"},
      {"negative density", [](CableRobot* r) { r->cables[4].linear_density_kg_per_m = -2.0; },
       "cables[4].linear_density_kg_per_m"},
      {"zero mass", [](CableRobot* r) { r->cabin_mass_kg = 0.0; }, "cabin_mass_kg"},
      {"negative mass", [](CableRobot* r) { r->cabin_mass_kg = -1.0; }, "cabin_mass_kg"},
      {"coincident towers",
       [](CableRobot* r) { r->cables[3].tower_top_m = r->cables[1].tower_top_m; },
       "cables[3].tower_top_m"},
      {"coincident anchors",
       [](CableRobot* r) { r->anchor_points_cabin_m[2] = r->anchor_points_cabin_m[0]; },
       "anchor_points_cabin_m[2]"},
      {"anchor index too large", [](CableRobot* r) { r->cables[4].anchor_index = 3; },
       "cables[4].anchor"},
      {"negative anchor index", [](CableRobot* r) { r->cables[1].anchor_index = -1; },
       "cables[1].anchor"},
      {"zero gravity", [](CableRobot* r) { r->gravity_m_per_s2 = 0.0; }, "gravity_m_per_s2"},
      {"upward gravity", [](CableRobot* r) { r->gravity_m_per_s2 = 9.8; }, "gravity_m_per_s2"},
      {"infinite tower", [](CableRobot* r) { r->cables[0].tower_top_m.z() = INFINITY; },
       "cables[0].tower_top_m"},
      {"no anchor points", [](CableRobot* r) { r->anchor_points_cabin_m.clear(); },
       "anchor_points_cabin_m"},
  };
  for (const InvalidCase& c : cases) {
    CableRobot robot = CableRobot::NominalFast();
    c.spoil(&robot);
    std::string error;
    EXPECT_FALSE(robot.IsValid(&error)) << c.name;
    EXPECT_EQ(error.rfind(std::string(c.key) + ": ", 0), 0u)
        << c.name << ": message \"" << error << "\" does not start with " << c.key;
  }
}

TEST(CableRobotYaml, NominalRoundTripIsExact) {
  const CableRobot nominal = CableRobot::NominalFast();
  CableRobot loaded;
  loaded.cabin_mass_kg = 1.0;  // must be overwritten
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(CableRobotToYaml(nominal, ""), "nominal", &loaded, &error))
      << error;
  ExpectIdentical(loaded, nominal);
}

TEST(CableRobotYaml, PerturbedModelSaveLoadRoundTripIsExact) {
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> offset_m(-0.5, 0.5), factor(0.8, 1.2);
  CableRobot robot = CableRobot::NominalFast();
  // A fourth anchor point and a non-nominal assignment of cables to points.
  robot.anchor_points_cabin_m.push_back(Eigen::Vector3d(0.1, -0.2, 1.5));
  for (Eigen::Vector3d& a : robot.anchor_points_cabin_m) {
    for (int k = 0; k < 3; ++k) a[k] += offset_m(rng);
  }
  const int anchors[kNumCables] = {3, 0, 1, 2, 2, 3};
  for (int i = 0; i < kNumCables; ++i) {
    CableProperties& c = robot.cables[i];
    for (int k = 0; k < 3; ++k) c.tower_top_m[k] += offset_m(rng);
    c.anchor_index = anchors[i];
    c.ea_n *= factor(rng);
    c.linear_density_kg_per_m *= factor(rng);
  }
  robot.cabin_mass_kg *= factor(rng);
  robot.mass_centre_cabin_m = Eigen::Vector3d(offset_m(rng), 1e-300, -0.0);  // extreme values
  // Within Earth's plausible gravity (model_plausibility.h): the last digits drawn.
  robot.gravity_m_per_s2 = -9.80665 * std::uniform_real_distribution<double>(0.995, 1.005)(rng);
  // Subnormal: must survive the text round trip too (on a coordinate: an EA that small
  // is refused as implausible).
  robot.anchor_points_cabin_m[0].z() = 3.0e-310;
  std::string error;
  ASSERT_TRUE(robot.IsValid(&error)) << error;

  TempDir dir;
  const std::string path = dir.path() + "/model.yaml";
  ASSERT_TRUE(SaveCableRobot(robot, path, "perturbed model\nfor the round trip", &error)) << error;
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"model.yaml"});  // no temporary left
  const std::string text = ReadFile(path);
  EXPECT_EQ(text.rfind("# perturbed model\n# for the round trip\n", 0), 0u) << text;

  CableRobot loaded;
  ASSERT_TRUE(LoadCableRobot(path, &loaded, &error)) << error;
  ExpectIdentical(loaded, robot);
}

TEST(CableRobotYaml, CalibrationDataNominalFileEqualsNominal) {
  const char* source_dir = (std::getenv("FASTCAL_SOURCE_DIR") ? std::getenv("FASTCAL_SOURCE_DIR")
                                                              : FASTCAL_TEST_SOURCE_DIR);
  if (source_dir == nullptr) GTEST_SKIP() << "FASTCAL_SOURCE_DIR is not set (set by CTest)";
  CableRobot loaded;
  std::string error;
  ASSERT_TRUE(LoadCableRobot(std::string(source_dir) + "/calibration_data/nominal_fast.yaml",
                             &loaded, &error))
      << error;
  ExpectIdentical(loaded, CableRobot::NominalFast());
}

TEST(CableRobotYaml, AbsentKeysTakeNominalValues) {
  CableRobot loaded;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml("# only the mass\ncabin:\n  mass_kg: 31000.5\n", "m.yaml",
                                  &loaded, &error))
      << error;
  CableRobot expected = CableRobot::NominalFast();
  expected.cabin_mass_kg = 31000.5;
  ExpectIdentical(loaded, expected);

  ASSERT_TRUE(ParseCableRobotYaml("{}", "braces.yaml", &loaded, &error)) << error;
  ExpectIdentical(loaded, CableRobot::NominalFast());
}

// An empty document is most likely a truncated or wrong file, not a request for the
// nominal model (which needs no file): an error naming the file, and *robot untouched.
TEST(CableRobotYaml, EmptyDocumentIsAnError) {
  for (const char* text : {"", "\n  \n", "# only a comment\n\n  # another\n", "---\n"}) {
    CableRobot loaded = CableRobot::NominalFast();
    loaded.cabin_mass_kg = 12345.0;
    std::string error;
    EXPECT_FALSE(ParseCableRobotYaml(text, "empty.yaml", &loaded, &error)) << '"' << text << '"';
    EXPECT_EQ(error,
              "empty.yaml: empty model file: omit the model file for the nominal FAST layout")
        << '"' << text << '"';
    EXPECT_EQ(loaded.cabin_mass_kg, 12345.0);
  }
}

TEST(CableRobotYaml, AnchorPointsReplaceTheNominalList) {
  const std::string text =
      "format: fastcal-model-1\n"
      "cabin:\n"
      "  anchor_points_m:\n"
      "    - [1, 2, 3]\n"
      "    - [-4, 5.5, +6e-1]\n"
      "    - [0, -7, 0]\n"
      "    - [8, 8, 8]\n";
  CableRobot loaded;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(text, "m.yaml", &loaded, &error)) << error;
  ASSERT_EQ(loaded.anchor_points_cabin_m.size(), 4u);
  EXPECT_EQ(loaded.anchor_points_cabin_m[1], Eigen::Vector3d(-4.0, 5.5, 0.6));
  EXPECT_EQ(loaded.anchor_points_cabin_m[3], Eigen::Vector3d(8.0, 8.0, 8.0));
}

TEST(CableRobotYaml, SixCablesInFlowStyleLoad) {
  CableRobot loaded;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(CablesYaml(kNumCables), "m.yaml", &loaded, &error)) << error;
  ExpectIdentical(loaded, CableRobot::NominalFast());
}

TEST(CableRobotYaml, UnknownKeyNamesKeyAndLine) {
  EXPECT_EQ(ParseError("cabin:\n  mass_kg: 1\n  mas_centre_m: [0, 0, 0]\n")
                .rfind("m.yaml:3: cabin.mas_centre_m: unknown key", 0),
            0u);
  EXPECT_EQ(ParseError("# comment\ngravity: -9.8\n").rfind("m.yaml:2: gravity: unknown key", 0),
            0u);
  // Inside a cable entry: cable index 4 is on line 6.
  const std::string cable4_line =
      "  - {tower_top_m: [1, 1, 1], anchor: 2, ea_n: 1, linear_density_kg_per_m: 1, colour: red}";
  std::istringstream lines(CablesYaml(kNumCables));
  std::string rebuilt;
  int line_no = 0;
  for (std::string line; std::getline(lines, line);) {
    rebuilt += (++line_no == 6 ? cable4_line : line) + "\n";
  }
  EXPECT_EQ(ParseError(rebuilt).rfind("m.yaml:6: cables[4].colour: unknown key", 0), 0u);
}

TEST(CableRobotYaml, MissingCableKeyNamesKeyAndEntryLine) {
  const std::string error = ParseError(CablesYaml(kNumCables, 1, "ea_n"));
  EXPECT_EQ(error.rfind("m.yaml:3: cables[1].ea_n: missing", 0), 0u) << error;
  const std::string error2 = ParseError(CablesYaml(kNumCables, 5, "tower_top_m"));
  EXPECT_EQ(error2.rfind("m.yaml:7: cables[5].tower_top_m: missing", 0), 0u) << error2;
}

TEST(CableRobotYaml, WrongNumberOfCablesIsAnError) {
  EXPECT_EQ(ParseError(CablesYaml(5)).rfind("m.yaml:1: cables: expected exactly 6 entries", 0), 0u);
  EXPECT_EQ(ParseError(CablesYaml(7)).rfind("m.yaml:1: cables: expected exactly 6 entries", 0), 0u);
}

TEST(CableRobotYaml, WrongTypesAreErrors) {
  EXPECT_EQ(ParseError("cabin:\n  mass_kg: heavy\n")
                .rfind("m.yaml:2: cabin.mass_kg: expected a number", 0),
            0u);
  EXPECT_EQ(ParseError("cabin:\n  mass_kg: \"30000\"\n")
                .rfind("m.yaml:2: cabin.mass_kg: expected a number", 0),
            0u);
  EXPECT_EQ(ParseError("cabin:\n  mass_kg: 3e4kg\n").rfind("m.yaml:2: cabin.mass_kg: expected", 0),
            0u);
  EXPECT_EQ(ParseError("\n\ncabin:\n  mass_centre_m: [0, 0]\n")
                .rfind("m.yaml:4: cabin.mass_centre_m: expected a list of 3 numbers", 0),
            0u);
  EXPECT_EQ(ParseError("cabin:\n  mass_centre_m: [0, x, 1]\n")
                .rfind("m.yaml:2: cabin.mass_centre_m[1]: expected a number", 0),
            0u);
  EXPECT_EQ(ParseError("cabin: 5\n").rfind("m.yaml:1: cabin: expected a mapping", 0), 0u);
  EXPECT_EQ(ParseError("cabin:\n  anchor_points_m: []\n")
                .rfind("m.yaml:2: cabin.anchor_points_m: expected a list of at least one", 0),
            0u);
  EXPECT_EQ(ParseError("format: fastcal-model-2\n").rfind("m.yaml:1: format: must be", 0), 0u);
  std::string text = CablesYaml(kNumCables);
  text.replace(text.find("anchor: 1"), 9, "anchor: 1.5");
  EXPECT_EQ(ParseError(text).rfind("m.yaml:4: cables[2].anchor: expected an integer", 0), 0u);
}

TEST(CableRobotYaml, NonFiniteNumbersAreErrors) {
  EXPECT_EQ(
      ParseError("gravity_m_per_s2: .nan\n").rfind("m.yaml:1: gravity_m_per_s2: must be finite", 0),
      0u);
  EXPECT_EQ(ParseError("cabin:\n  mass_centre_m: [0, -.inf, 1]\n")
                .rfind("m.yaml:2: cabin.mass_centre_m[1]: must be finite", 0),
            0u);
  EXPECT_EQ(ParseError("cabin:\n  mass_kg: 1e999\n").rfind("m.yaml:2: cabin.mass_kg: ", 0), 0u);
}

TEST(CableRobotYaml, NonPhysicalValueNamesYamlKeyAndLine) {
  std::string text = CablesYaml(kNumCables);
  text.replace(text.find("ea_n: 2.4656e7", text.find("anchor: 1")), 14, "ea_n: -1");
  EXPECT_EQ(ParseError(text), "m.yaml:4: cables[2].ea_n: must be > 0");
  // IsValid's field names are reported as YAML key paths.
  EXPECT_EQ(ParseError("cabin:\n  mass_kg: 0\n"), "m.yaml:2: cabin.mass_kg: must be > 0");
  EXPECT_EQ(ParseError("cabin:\n  anchor_points_m:\n    - [1, 0, 0]\n    - [1, 0, 0]\n"),
            "m.yaml:4: cabin.anchor_points_m[1]: coincides with cabin.anchor_points_m[0]");
  // A nominal default the file does not give has no line.
  EXPECT_EQ(ParseError("cabin:\n  anchor_points_m:\n    - [1, 0, 0]\n")
                .rfind("m.yaml: cables[2].anchor: index 1 is not an anchor point", 0),
            0u);
}

TEST(CableRobotYaml, SyntaxErrorNamesLine) {
  const std::string error = ParseError("cabin:\n  mass_kg: 1\n  mass_centre_m: [0, 0, 1\n");
  EXPECT_EQ(error.rfind("m.yaml:", 0), 0u) << error;
  EXPECT_NE(error.find("syntax error"), std::string::npos) << error;
  // yaml-cpp reports the unclosed flow sequence on line 3 or at the end of the input.
  const int line = std::atoi(error.c_str() + std::string("m.yaml:").size());
  EXPECT_GE(line, 3) << error;
  EXPECT_LE(line, 4) << error;
  const std::string error2 = ParseError("cabin:\n  mass_kg: 1\n mass_centre_m: [0, 0, 1]\n");
  EXPECT_EQ(error2.rfind("m.yaml:3: YAML syntax error", 0), 0u) << error2;
}

// yaml-cpp 0.7's LoadAll never returns on a stream it cannot advance through (a stray
// top-level comma) and grows past 1 GB in 15 s; the reader must refuse it at once.
TEST(CableRobotYaml, StrayTopLevelCommaIsASyntaxErrorNotAHang) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {",", "m.yaml:1: YAML syntax error: unexpected ',' at column 1"},
      {"{format: fastcal-model-1, gravity_m_per_s2: -9.8},",
       "m.yaml:1: YAML syntax error: unexpected ',' at column 50"},
      {"{a: 1}, {b: 2}", "m.yaml:1: YAML syntax error: unexpected ',' at column 7"},
      {"{cabin: {mass_kg: 1}}\n,\n", "m.yaml:2: YAML syntax error: unexpected ',' at column 1"}};
  for (const auto& [text, expected] : cases) {
    EXPECT_EXIT(
        {
          test::LimitThisProcess();
          CableRobot robot;
          std::string error;
          const bool ok = ParseCableRobotYaml(text, "m.yaml", &robot, &error);
          std::fprintf(stderr, "%s\n", error.c_str());
          std::exit(ok ? 1 : 0);
        },
        ::testing::ExitedWithCode(0), expected)
        << text;
  }
}

// Text from the file in a message is escaped and capped (internal/quote.h): YAML's "\e"
// is an escape byte, which must not reach the terminal.
TEST(CableRobotYaml, MessagesQuoteTheFilesTextSafely) {
  const std::string error =
      ParseError("cabin:\n  mass_kg: \"\\e[2J" + std::string(500, 'x') + "\"\n");
  EXPECT_EQ(error.find('\x1b'), std::string::npos) << error;
  EXPECT_NE(error.find("cabin.mass_kg: expected a number, got the quoted text '\\x1b[2Jxxx"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("'... (504 bytes)"), std::string::npos) << error;
}

TEST(CableRobotYaml, SecondDocumentIsAnErrorOnItsLine) {
  const std::string error = ParseError("gravity_m_per_s2: -9.8\n---\ngravity_m_per_s2: -9.8\n");
  EXPECT_EQ(error, "m.yaml:3: (top level): only one YAML document is allowed");
}

TEST(CableRobotYaml, FailedParseLeavesRobotUntouched) {
  CableRobot robot = CableRobot::NominalFast();
  robot.cabin_mass_kg = 12345.0;
  std::string error;
  EXPECT_FALSE(ParseCableRobotYaml("cabin:\n  mass_kg: 1\n  bogus: 1\n", "m.yaml", &robot, &error));
  EXPECT_EQ(robot.cabin_mass_kg, 12345.0);
}

TEST(CableRobotYaml, MissingFileCannotOpen) {
  TempDir dir;
  const std::string path = dir.path() + "/absent.yaml";
  CableRobot robot;
  std::string error;
  EXPECT_FALSE(LoadCableRobot(path, &robot, &error));
  EXPECT_EQ(error, path + ": cannot open: No such file or directory");
}

TEST(CableRobotYaml, LoadReportsTheFileName) {
  TempDir dir;
  const std::string path = dir.path() + "/bad.yaml";
  std::ofstream(path) << "# line 1\ncabin:\n  mass_kg: 0\n";
  CableRobot robot;
  std::string error;
  EXPECT_FALSE(LoadCableRobot(path, &robot, &error));
  EXPECT_EQ(error, path + ":3: cabin.mass_kg: must be > 0");
}

TEST(SaveCableRobot, ReplacesExistingFileAndLeavesNoTemporary) {
  TempDir dir;
  const std::string path = dir.path() + "/model.yaml";
  std::ofstream(path) << "old contents\n";
  CableRobot robot = CableRobot::NominalFast();
  robot.cabin_mass_kg = 29000.0;
  std::string error;
  ASSERT_TRUE(SaveCableRobot(robot, path, "", &error)) << error;
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"model.yaml"});
  EXPECT_EQ(ReadFile(path), CableRobotToYaml(robot, ""));
}

TEST(SaveCableRobot, MissingDirectoryFailsAndLeavesNothing) {
  TempDir dir;
  const std::string path = dir.path() + "/no_such_dir/model.yaml";
  std::string error;
  EXPECT_FALSE(SaveCableRobot(CableRobot::NominalFast(), path, "", &error));
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(SaveCableRobot, FailedRenameRemovesTemporary) {
  TempDir dir;
  const std::string path = dir.path() + "/model.yaml";
  ASSERT_TRUE(fs::create_directory(path));  // rename of a file onto a directory fails
  std::string error;
  EXPECT_FALSE(SaveCableRobot(CableRobot::NominalFast(), path, "", &error));
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"model.yaml"});
  EXPECT_TRUE(fs::is_directory(path));
}

TEST(SaveCableRobot, UnwritableDirectoryFailsAndLeavesExistingFile) {
  TempDir dir;
  const std::string path = dir.path() + "/model.yaml";
  const std::string old_contents = "old contents\n";
  std::ofstream(path) << old_contents;
  ASSERT_EQ(::chmod(dir.path().c_str(), 0555), 0);
  // Root ignores permission bits: then the directory is not unwritable.
  const std::string probe = dir.path() + "/probe";
  if (std::ofstream(probe).is_open()) {
    ::unlink(probe.c_str());
    GTEST_SKIP() << "directory permissions are not enforced (running as root?)";
  }
  std::string error;
  EXPECT_FALSE(SaveCableRobot(CableRobot::NominalFast(), path, "", &error));
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"model.yaml"});
  EXPECT_EQ(ReadFile(path), old_contents);
}

}  // namespace
}  // namespace fastcal

namespace fastcal {
namespace {

TEST(CableRobotYaml, SensorGainAndBiasRoundTripAndValidate) {
  CableRobot robot = CableRobot::NominalFast();
  robot.cables[2].sensor_gain = 1.0123;
  robot.cables[4].sensor_bias_n = -1250.0;
  CableRobot back;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml(CableRobotToYaml(robot, ""), "m.yaml", &back, &error)) << error;
  EXPECT_EQ(back.cables[2].sensor_gain, 1.0123);
  EXPECT_EQ(back.cables[4].sensor_bias_n, -1250.0);
  EXPECT_EQ(back.cables[0].sensor_gain, 1.0);
  robot.cables[1].sensor_gain = 0.0;
  EXPECT_FALSE(robot.IsValid(&error));
  EXPECT_NE(error.find("cables[1].sensor_gain"), std::string::npos) << error;
}

// The cabin's inertia (vibrations only): an assumed diagonal default, [Ixx, Iyy, Izz] or
// three rows in the file, an exact round trip of either, and a tensor no rigid body has
// refused with its key.
TEST(CableRobotYaml, CabinInertiaDiagonalOrFullRoundTripsAndValidates) {
  const Eigen::Matrix3d nominal = CableRobot::NominalFast().cabin_inertia_kg_m2;
  EXPECT_EQ(nominal, Eigen::Matrix3d(Eigen::Vector3d(3.5e5, 3.5e5, 5.0e5).asDiagonal()));
  CableRobot robot, back;
  std::string error;
  ASSERT_TRUE(
      ParseCableRobotYaml("cabin:\n  inertia_kg_m2: [3e5, 4e5, 6e5]\n", "m.yaml", &robot, &error))
      << error;
  EXPECT_EQ(robot.cabin_inertia_kg_m2.diagonal(), Eigen::Vector3d(3e5, 4e5, 6e5));
  ASSERT_TRUE(ParseCableRobotYaml(
      "cabin:\n  inertia_kg_m2: [[3e5, 1e4, 0], [1e4, 4e5, -2e3], [0, -2e3, 6e5]]\n", "m.yaml",
      &robot, &error))
      << error;
  EXPECT_EQ(robot.cabin_inertia_kg_m2(1, 2), -2e3);
  ASSERT_TRUE(ParseCableRobotYaml(CableRobotToYaml(robot, ""), "m.yaml", &back, &error)) << error;
  ExpectIdentical(back, robot);
  const std::pair<const char*, const char*> bad[] = {
      {"cabin:\n  inertia_kg_m2: [1, 2]\n", "cabin.inertia_kg_m2: expected"},
      {"cabin:\n  inertia_kg_m2: [3e5, -1, 6e5]\n",
       "m.yaml:2: cabin.inertia_kg_m2: must be positive definite"},
      {"cabin:\n  inertia_kg_m2: [1e5, 1e5, 6e5]\n", "cabin.inertia_kg_m2: principal moments"},
      {"cabin:\n  inertia_kg_m2: [[3e5, 1e4, 0], [0, 4e5, 0], [0, 0, 6e5]]\n",
       "cabin.inertia_kg_m2: must be symmetric"},
  };
  for (const auto& [text, expect] : bad) {
    EXPECT_FALSE(ParseCableRobotYaml(text, "m.yaml", &robot, &error)) << text;
    EXPECT_NE(error.find(expect), std::string::npos) << error;
  }
}

// The reflector is optional model data: FAST's in the nominal model (design notes: a
// sphere of radius 300 m about (0, 0, 300) m, aperture 500 m), `reflector: none` for a
// model without it, partial keys keep the nominal values, and it round-trips.
TEST(CableRobotYaml, ReflectorIsOptionalModelData) {
  const CableRobot nominal = CableRobot::NominalFast();
  ASSERT_TRUE(nominal.reflector.has_value());
  EXPECT_EQ(nominal.reflector->centre_m, Eigen::Vector3d(0, 0, 300));
  EXPECT_EQ(nominal.reflector->radius_m, 300.0);
  EXPECT_EQ(nominal.reflector->aperture_m, 500.0);
  EXPECT_FALSE(CableRobot().reflector.has_value());
  CableRobot robot;
  std::string error;
  ASSERT_TRUE(ParseCableRobotYaml("reflector: none\n", "m.yaml", &robot, &error)) << error;
  EXPECT_FALSE(robot.reflector.has_value());
  CableRobot back;
  ASSERT_TRUE(ParseCableRobotYaml(CableRobotToYaml(robot, ""), "m.yaml", &back, &error)) << error;
  ExpectIdentical(back, robot);
  ASSERT_TRUE(ParseCableRobotYaml("reflector:\n  radius_m: 310\n", "m.yaml", &robot, &error))
      << error;
  ASSERT_TRUE(robot.reflector.has_value());
  EXPECT_EQ(robot.reflector->radius_m, 310.0);
  EXPECT_EQ(robot.reflector->aperture_m, 500.0);
  ASSERT_TRUE(ParseCableRobotYaml(CableRobotToYaml(robot, ""), "m.yaml", &back, &error)) << error;
  ExpectIdentical(back, robot);
  const std::pair<const char*, const char*> bad[] = {
      {"reflector: nothing\n", "reflector: expected a mapping"},
      {"reflector:\n  radius: 300\n", "reflector.radius: unknown key"},
      {"reflector:\n  radius_m: -1\n", "reflector.radius_m: must be > 0"},
      {"reflector:\n  aperture_m: 700\n", "reflector.aperture_m: must be > 0 and at most 2"},
      {"reflector:\n  centre_m: [0, 0]\n", "reflector.centre_m: expected a list of 3"},
  };
  for (const auto& [text, message] : bad) {
    EXPECT_FALSE(ParseCableRobotYaml(text, "m.yaml", &robot, &error)) << text;
    EXPECT_NE(error.find(message), std::string::npos) << text << ": " << error;
  }
}

}  // namespace
}  // namespace fastcal
