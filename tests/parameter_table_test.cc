// Tests of the table of parameter kinds (parameter_table.h): a row per kind in its place,
// names built from the rows' keys and units, the determined-sigma rules, and the rows'
// facts against the physics: a kind that "moves the forces" changes the statics
// parameters the calibration model assembles, one that "moves the geometry" changes a
// cable's ends, and a reading's kind changes neither.
#include "fastcal/parameter_table.h"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/internal/calibration_model.h"
#include "test_robots.h"

namespace fastcal {
namespace {

using internal::CalibrationModel;

// A step of a parameter's value large enough to show in any field, small enough to stay
// plausible (SI: 1 cm, 1 kg, 1 N, ...).
constexpr double kStep = 0.01;

TEST(ParameterTableTest, EveryKindHasItsRowInPlace) {
  for (int k = 0; k < kNumParameterKinds; ++k) {
    const ParameterKindInfo* row = FindParameterKind(static_cast<ParameterKind>(k));
    ASSERT_NE(row, nullptr) << "kind " << k;
    EXPECT_EQ(static_cast<int>(row->kind), k);
    EXPECT_NE(std::string(row->key), "") << "kind " << k;
    EXPECT_NE(std::string(row->unit), "") << "kind " << k;
    EXPECT_GT(row->to_si, 0.0) << "kind " << k;
    EXPECT_NE(row->max_sigma, nullptr) << "kind " << k;
  }
  EXPECT_EQ(FindParameterKind(static_cast<ParameterKind>(kNumParameterKinds)), nullptr);
  EXPECT_EQ(FindParameterKind(static_cast<ParameterKind>(-1)), nullptr);
}

// Every parameter a model has is named from its row's key and carries its row's unit.
TEST(ParameterTableTest, NamesAndUnitsComeFromTheRows) {
  for (const CableRobot& robot : {testing::AsBuiltRobot(), testing::RotatorRobot()}) {
    for (const ParameterSpec& p : AllModelParameters(robot)) {
      const ParameterKindInfo& row = KindInfo(p.kind);
      EXPECT_EQ(p.name.rfind(row.key, 0), 0u) << p.name << " does not start with " << row.key;
      EXPECT_EQ(p.unit, row.unit) << p.name;
      EXPECT_EQ(p.to_si, row.to_si) << p.name;
    }
  }
}

TEST(ParameterTableTest, DeterminedSigmaFollowsTheRowsScale) {
  CalibrationOptions o;
  // Absolute: the option, whatever the value.
  EXPECT_EQ(MaxSigmaOf(ParameterKind::kMassCentre, 0.3, 0.0, o), o.max_sigma_mass_centre_m);
  // Of the value: the option times |value|.
  EXPECT_DOUBLE_EQ(MaxSigmaOf(ParameterKind::kCabinMass, -3e4, 0.0, o),
                   o.max_sigma_cabin_mass_fraction * 3e4);
  // Absolute or prior: a prior wider than the option widens it, a narrower one does not.
  const double wide = 2.0 * o.max_sigma_part_mass_kg;
  EXPECT_GT(MaxSigmaOf(ParameterKind::kPartMass, 1e3, wide, o), wide);
  EXPECT_EQ(MaxSigmaOf(ParameterKind::kPartMass, 1e3, 0.5 * o.max_sigma_part_mass_kg, o),
            o.max_sigma_part_mass_kg);
  EXPECT_EQ(MaxSigmaOf(ParameterKind::kPartMass, 1e3, 0.0, o), o.max_sigma_part_mass_kg);
}

// The assembled model at theta: statics parameters and the readings' terms.
struct Assembled {
  StaticsParameters<double> p;
  std::array<double, kNumCables> gain{}, bias{}, offset{};
  Eigen::Vector3d measured = Eigen::Vector3d::Zero();
};

Assembled AssembleAt(const CalibrationModel& model, const std::vector<double>& theta) {
  Assembled a;
  model.Assemble<double>(theta.data(), &a.p, &a.gain, &a.bias, 0, &a.offset, &a.measured);
  return a;
}

bool GeometryDiffers(const Assembled& a, const Assembled& b) {
  bool differs = (a.measured - b.measured).norm() > 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    differs = differs || (a.p.tower_top_m[i] - b.p.tower_top_m[i]).norm() > 0.0 ||
              (a.p.anchor_cabin_m[i] - b.p.anchor_cabin_m[i]).norm() > 0.0;
  }
  return differs;
}

bool StaticsDiffer(const Assembled& a, const Assembled& b) {
  bool differs = GeometryDiffers(a, b) || a.p.cabin_mass_kg != b.p.cabin_mass_kg ||
                 (a.p.mass_centre_cabin_m - b.p.mass_centre_cabin_m).norm() > 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    differs = differs || a.p.ea_n[i] != b.p.ea_n[i] ||
              a.p.linear_density_kg_per_m[i] != b.p.linear_density_kg_per_m[i] ||
              a.p.chain[i].value != b.p.chain[i].value;
  }
  for (int k = 0; k < a.p.num_parts; ++k) {
    differs = differs || a.p.part_mass_kg[k] != b.p.part_mass_kg[k] ||
              (a.p.part_first_moment_kg_m[k] - b.p.part_first_moment_kg_m[k]).norm() > 0.0;
  }
  return differs;
}

bool ReadingsDiffer(const Assembled& a, const Assembled& b) {
  return a.gain != b.gain || a.bias != b.bias || a.offset != b.offset;
}

// Each parameter alone, freed and stepped: what it changes agrees with its row.
TEST(ParameterTableTest, RowsAgreeWithWhatTheModelAssembles) {
  std::array<bool, kNumParameterKinds> seen{};
  CableRobot rotator = testing::RotatorRobot();
  rotator.measured_frame = MeasuredFrame();
  for (const CableRobot& robot : {testing::AsBuiltRobot(), rotator}) {
    for (ParameterSpec p : AllModelParameters(robot)) {
      p.free = true;
      CalibrationSpec spec;
      spec.parameters = {p};
      const CalibrationModel model(robot, spec);
      std::vector<double> theta = model.InitialTheta();
      const Assembled before = AssembleAt(model, theta);
      theta[0] += kStep;
      const Assembled after = AssembleAt(model, theta);
      const ParameterKindInfo& row = KindInfo(p.kind);
      EXPECT_EQ(StaticsDiffer(before, after), row.moves_forces) << p.name;
      EXPECT_EQ(GeometryDiffers(before, after), row.moves_geometry) << p.name;
      EXPECT_EQ(ReadingsDiffer(before, after), !row.moves_forces) << p.name;
      seen[static_cast<int>(p.kind)] = true;
    }
  }
  for (int k = 0; k < kNumParameterKinds; ++k) EXPECT_TRUE(seen[k]) << "kind " << k << " untried";
}

}  // namespace
}  // namespace fastcal
