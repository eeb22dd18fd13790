// Tests of the calibration spec (calibration_spec.h): parameter lists for every group and
// mode, unit conversion, validation, error messages, the YAML round trip and the example
// specs in calibration_data/.
#include "fastcal/calibration_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bounded_process.h"
#include "temp_path.h"

namespace fastcal {
namespace {

constexpr char kSource[] = "spec.yaml";
constexpr int kNumAnchors = 3;  // as in the nominal FAST model
constexpr double kNewtonsPerKilonewton = 1e3;

CalibrationSpec ParseOk(const std::string& text, int num_anchor_points = kNumAnchors) {
  CalibrationSpec spec;
  std::string error;
  EXPECT_TRUE(ParseCalibrationSpecYaml(text, kSource, num_anchor_points, &spec, &error))
      << error << "\n--- text ---\n"
      << text;
  return spec;
}

// The parse error of `text` ("" when it parses).
std::string ParseError(const std::string& text, int num_anchor_points = kNumAnchors) {
  CalibrationSpec spec;
  std::string error;
  if (ParseCalibrationSpecYaml(text, kSource, num_anchor_points, &spec, &error)) return "";
  return error;
}

int CountFree(const CalibrationSpec& spec) {
  int n = 0;
  for (const ParameterSpec& p : spec.parameters) n += p.free;
  return n;
}

std::vector<std::string> Names(const CalibrationSpec& spec) {
  std::vector<std::string> names;
  for (const ParameterSpec& p : spec.parameters) names.push_back(p.name);
  return names;
}

void ExpectSameParameter(const ParameterSpec& a, const ParameterSpec& b) {
  SCOPED_TRACE(a.name);
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.component, b.component);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.unit, b.unit);
  EXPECT_EQ(a.to_si, b.to_si);
  EXPECT_EQ(a.free, b.free);
  EXPECT_EQ(a.has_initial, b.has_initial);
  EXPECT_EQ(a.initial_si, b.initial_si);
  EXPECT_EQ(a.has_prior, b.has_prior);
  EXPECT_EQ(a.prior_mean_si, b.prior_mean_si);
  EXPECT_EQ(a.prior_sigma_si, b.prior_sigma_si);
}

void ExpectSameSpec(const CalibrationSpec& a, const CalibrationSpec& b) {
  EXPECT_EQ(a.forward_model, b.forward_model);
  EXPECT_EQ(a.tension_sigma_n, b.tension_sigma_n);
  EXPECT_EQ(a.tension_sigma_percent, b.tension_sigma_percent);
  EXPECT_EQ(a.robust_loss, b.robust_loss);
  EXPECT_EQ(a.robust_loss_scale, b.robust_loss_scale);
  EXPECT_EQ(a.holdout_fraction, b.holdout_fraction);
  EXPECT_EQ(a.holdout_seed, b.holdout_seed);
  EXPECT_EQ(a.use_planned_attitude, b.use_planned_attitude);
  EXPECT_EQ(a.max_iterations, b.max_iterations);
  EXPECT_EQ(a.function_tolerance, b.function_tolerance);
  EXPECT_EQ(a.gradient_tolerance, b.gradient_tolerance);
  EXPECT_EQ(a.parameter_tolerance, b.parameter_tolerance);
  EXPECT_EQ(a.num_threads, b.num_threads);
  EXPECT_EQ(a.holdout_blocks, b.holdout_blocks);
  EXPECT_EQ(a.cross_validation_blocks, b.cross_validation_blocks);
  EXPECT_EQ(a.detect_gross_errors, b.detect_gross_errors);
  EXPECT_EQ(a.gross_error_threshold_sigmas, b.gross_error_threshold_sigmas);
  EXPECT_EQ(a.max_gross_error_fraction, b.max_gross_error_fraction);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  for (size_t k = 0; k < a.parameters.size(); ++k) {
    ExpectSameParameter(a.parameters[k], b.parameters[k]);
  }
}

// The example of the brief / docs: every key, every group.
constexpr char kFullSpec[] = R"(format: fastcal-calibration-spec-1
forward_model: exact
noise:
  tension_sigma_kN: 0.5
  tension_sigma_percent: 2.5
robust_loss: {type: huber, scale: 1.5}
gross_errors: {detect: false, threshold_sigmas: 6, max_fraction: 0.1}
holdout: {fraction: 0.2, seed: 7, blocks: 5}
cross_validation: {blocks: 8}
attitude: planned
solver: {max_iterations: 50, function_tolerance: 1e-10, gradient_tolerance: 1e-11, parameter_tolerance: 1e-9, threads: 4}
parameters:
  mass_centre_m:
    x: {free: true}
    y: {free: true, initial: 0.1, prior: {mean: 0, sigma: 0.5}}
    z: {free: false, initial: 0.5}
  cabin_mass_kg: {free: false}
  linear_density_kg_per_m: {mode: common, free: true}
  ea_n: {mode: per_cable, free: false}
  sensor_gain: {mode: common, free: true, prior: {mean: 1, sigma: 0.03}}
  sensor_bias_kN: {mode: per_cable, free: true, prior: {mean: 0, sigma: 2}}
  anchor_offset_m: {all: {free: true, prior: {mean: 0, sigma: 0.02}}}
  tower_offset_m:
    - {x: {free: true}, y: {free: false}}
    - {}
)";

// yaml-cpp 0.7's LoadAll never returns on a stray top-level comma (and grows without
// bound): the spec reader must refuse it at once, naming line and column.
TEST(CalibrationSpecTest, StrayTopLevelCommaIsASyntaxErrorNotAHang) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {",", "s.yaml:1: YAML syntax error: unexpected ',' at column 1"},
      {"{format: fastcal-calibration-spec-1},", "s.yaml:1: YAML syntax error: unexpected ','"},
      {"{a: 1}, {b: 2}", "s.yaml:1: YAML syntax error: unexpected ',' at column 7"}};
  for (const auto& [text, expected] : cases) {
    EXPECT_EXIT(
        {
          test::LimitThisProcess();
          CalibrationSpec spec;
          std::string error;
          const bool ok = ParseCalibrationSpecYaml(text, "s.yaml", 3, &spec, &error);
          std::fprintf(stderr, "%s\n", error.c_str());
          std::exit(ok ? 1 : 0);
        },
        ::testing::ExitedWithCode(0), expected)
        << text;
  }
}

TEST(CalibrationSpecTest, EmptySpecHasTheDefaults) {
  const CalibrationSpec defaults;
  for (const char* text : {"", "# only a comment\n", "parameters:\n"}) {
    SCOPED_TRACE(text);
    const CalibrationSpec spec = ParseOk(text);
    ExpectSameSpec(spec, defaults);
  }
  EXPECT_EQ(defaults.forward_model, StaticsMethod::kExact);
  EXPECT_EQ(defaults.tension_sigma_percent, 3.0);
  // Gross errors screened by default, at 5 robust sigmas; hold-out and cross-validation
  // by 10 contiguous blocks.
  EXPECT_TRUE(defaults.detect_gross_errors);
  EXPECT_EQ(defaults.gross_error_threshold_sigmas, 5.0);
  EXPECT_EQ(defaults.max_gross_error_fraction, 0.25);
  EXPECT_EQ(defaults.holdout_blocks, 10);
  EXPECT_EQ(defaults.cross_validation_blocks, 10);
  EXPECT_TRUE(defaults.IsValid(nullptr));
}

TEST(CalibrationSpecTest, OptionsAreRead) {
  const CalibrationSpec spec = ParseOk(kFullSpec);
  EXPECT_EQ(spec.forward_model, StaticsMethod::kExact);
  EXPECT_EQ(spec.tension_sigma_n, 0.5 * kNewtonsPerKilonewton);
  EXPECT_EQ(spec.tension_sigma_percent, 2.5);
  EXPECT_EQ(spec.robust_loss, RobustLoss::kHuber);
  EXPECT_EQ(spec.robust_loss_scale, 1.5);
  EXPECT_EQ(spec.holdout_fraction, 0.2);
  EXPECT_EQ(spec.holdout_seed, 7u);
  EXPECT_EQ(spec.holdout_blocks, 5);
  EXPECT_EQ(spec.cross_validation_blocks, 8);
  EXPECT_FALSE(spec.detect_gross_errors);
  EXPECT_EQ(spec.gross_error_threshold_sigmas, 6.0);
  EXPECT_EQ(spec.max_gross_error_fraction, 0.1);
  EXPECT_TRUE(spec.use_planned_attitude);
  EXPECT_EQ(spec.max_iterations, 50);
  EXPECT_EQ(spec.function_tolerance, 1e-10);
  EXPECT_EQ(spec.gradient_tolerance, 1e-11);
  EXPECT_EQ(spec.parameter_tolerance, 1e-9);
  EXPECT_EQ(spec.num_threads, 4);
  EXPECT_EQ(ParseOk("robust_loss: {type: cauchy}\n").robust_loss, RobustLoss::kCauchy);
  EXPECT_EQ(ParseOk("forward_model: aas\n").forward_model, StaticsMethod::kAas);
  EXPECT_FALSE(ParseOk("attitude: measured\n").use_planned_attitude);
}

TEST(CalibrationSpecTest, MassCentreListsOnlyNamedAxes) {
  const CalibrationSpec spec = ParseOk(
      "parameters:\n"
      "  mass_centre_m:\n"
      "    x: {free: true}\n"
      "    z: {free: false, initial: 0.5}\n");
  ASSERT_EQ(spec.parameters.size(), 2u);
  const ParameterSpec& x = spec.parameters[0];
  const ParameterSpec& z = spec.parameters[1];
  EXPECT_EQ(x.kind, ParameterKind::kMassCentre);
  EXPECT_EQ(x.name, "mass_centre_m.x");
  EXPECT_EQ(x.component, 0);
  EXPECT_EQ(x.index, -1);
  EXPECT_EQ(x.unit, "m");
  EXPECT_EQ(x.to_si, 1.0);
  EXPECT_TRUE(x.free);
  EXPECT_FALSE(x.has_initial);
  EXPECT_FALSE(x.has_prior);
  EXPECT_EQ(z.name, "mass_centre_m.z");
  EXPECT_EQ(z.component, 2);
  EXPECT_FALSE(z.free);
  EXPECT_TRUE(z.has_initial);
  EXPECT_EQ(z.initial_si, 0.5);
}

TEST(CalibrationSpecTest, EntryDefaultsToFixedAndReadsPrior) {
  const CalibrationSpec spec = ParseOk(
      "parameters:\n"
      "  cabin_mass_kg:\n"
      "  mass_centre_m: {y: {free: true, initial: 0.1, prior: {mean: -0.2, sigma: 0.5}}}\n");
  ASSERT_EQ(spec.parameters.size(), 2u);
  const ParameterSpec& y = spec.parameters[0];
  EXPECT_EQ(y.name, "mass_centre_m.y");
  EXPECT_TRUE(y.has_initial);
  EXPECT_EQ(y.initial_si, 0.1);
  EXPECT_TRUE(y.has_prior);
  EXPECT_EQ(y.prior_mean_si, -0.2);
  EXPECT_EQ(y.prior_sigma_si, 0.5);
  const ParameterSpec& mass = spec.parameters[1];
  EXPECT_EQ(mass.kind, ParameterKind::kCabinMass);
  EXPECT_EQ(mass.name, "cabin_mass_kg");
  EXPECT_EQ(mass.unit, "kg");
  EXPECT_EQ(mass.index, -1);
  EXPECT_EQ(mass.component, -1);
  EXPECT_FALSE(mass.free);
  EXPECT_FALSE(mass.has_initial);
}

struct GroupCase {
  const char* key;
  ParameterKind kind;
  const char* unit;
  double to_si;
};

constexpr GroupCase kPerCableGroups[] = {
    {"linear_density_kg_per_m", ParameterKind::kLinearDensity, "kg/m", 1.0},
    {"ea_n", ParameterKind::kEa, "N", 1.0},
    {"sensor_gain", ParameterKind::kSensorGain, "1", 1.0},
    {"sensor_bias_kN", ParameterKind::kSensorBias, "kN", 1e3},
};

TEST(CalibrationSpecTest, CommonModeGivesOneParameter) {
  for (const GroupCase& g : kPerCableGroups) {
    SCOPED_TRACE(g.key);
    for (const std::string mode : {"mode: common, ", ""}) {  // common is the default
      const CalibrationSpec spec =
          ParseOk(std::string("parameters:\n  ") + g.key + ": {" + mode + "free: true}\n");
      ASSERT_EQ(spec.parameters.size(), 1u);
      const ParameterSpec& p = spec.parameters[0];
      EXPECT_EQ(p.kind, g.kind);
      EXPECT_EQ(p.name, g.key);
      EXPECT_EQ(p.index, -1);
      EXPECT_EQ(p.component, -1);
      EXPECT_EQ(p.unit, g.unit);
      EXPECT_EQ(p.to_si, g.to_si);
      EXPECT_TRUE(p.free);
    }
  }
}

TEST(CalibrationSpecTest, PerCableModeGivesSixParameters) {
  for (const GroupCase& g : kPerCableGroups) {
    SCOPED_TRACE(g.key);
    const CalibrationSpec spec =
        ParseOk(std::string("parameters:\n  ") + g.key + ": {mode: per_cable, free: true}\n");
    ASSERT_EQ(spec.parameters.size(), static_cast<size_t>(kNumCables));
    for (int i = 0; i < kNumCables; ++i) {
      const ParameterSpec& p = spec.parameters[i];
      EXPECT_EQ(p.kind, g.kind);
      EXPECT_EQ(p.name, std::string(g.key) + "[" + std::to_string(i + 1) + "]");
      EXPECT_EQ(p.index, i);
      EXPECT_EQ(p.component, -1);
      EXPECT_EQ(p.unit, g.unit);
      EXPECT_EQ(p.to_si, g.to_si);
      EXPECT_TRUE(p.free);
    }
  }
}

TEST(CalibrationSpecTest, BiasAndNoiseAreGivenInKilonewtonsAndStoredInNewtons) {
  const CalibrationSpec spec = ParseOk(
      "noise: {tension_sigma_kN: 1.5}\n"
      "parameters:\n"
      "  sensor_bias_kN: {free: true, initial: 0.25, prior: {mean: -1, sigma: 2}}\n");
  EXPECT_EQ(spec.tension_sigma_n, 1.5e3);
  ASSERT_EQ(spec.parameters.size(), 1u);
  const ParameterSpec& bias = spec.parameters[0];
  EXPECT_EQ(bias.initial_si, 250.0);
  EXPECT_EQ(bias.prior_mean_si, -1e3);
  EXPECT_EQ(bias.prior_sigma_si, 2e3);
  EXPECT_EQ(bias.initial_si / bias.to_si, 0.25);  // the file value, as a report shows it
}

TEST(CalibrationSpecTest, PerCableEntriesOverrideTheGroupFieldByField) {
  const CalibrationSpec spec = ParseOk(
      "parameters:\n"
      "  linear_density_kg_per_m:\n"
      "    mode: per_cable\n"
      "    free: true\n"
      "    initial: 11.7\n"
      "    prior: {mean: 11.718, sigma: 0.2}\n"
      "    cables:\n"
      "      - {}\n"
      "      - {free: false}\n"
      "      - {initial: 12.5}\n"
      "      - {prior: {mean: 12, sigma: 0.1}}\n"
      "      -\n"
      "      - {free: false, initial: 11, prior: {mean: 10, sigma: 1}}\n");
  ASSERT_EQ(spec.parameters.size(), static_cast<size_t>(kNumCables));
  const std::vector<ParameterSpec>& p = spec.parameters;
  // Cable 1 and 5: all from the group.
  for (int i : {0, 4}) {
    SCOPED_TRACE(i);
    EXPECT_TRUE(p[i].free);
    EXPECT_EQ(p[i].initial_si, 11.7);
    EXPECT_EQ(p[i].prior_mean_si, 11.718);
    EXPECT_EQ(p[i].prior_sigma_si, 0.2);
  }
  EXPECT_FALSE(p[1].free);
  EXPECT_EQ(p[1].initial_si, 11.7);
  EXPECT_TRUE(p[2].free);
  EXPECT_EQ(p[2].initial_si, 12.5);
  EXPECT_EQ(p[2].prior_mean_si, 11.718);
  EXPECT_EQ(p[3].initial_si, 11.7);
  EXPECT_EQ(p[3].prior_mean_si, 12.0);
  EXPECT_EQ(p[3].prior_sigma_si, 0.1);
  EXPECT_FALSE(p[5].free);
  EXPECT_EQ(p[5].initial_si, 11.0);
  EXPECT_EQ(p[5].prior_mean_si, 10.0);
  for (const ParameterSpec& q : p) {
    EXPECT_TRUE(q.has_initial);
    EXPECT_TRUE(q.has_prior);
  }
}

TEST(CalibrationSpecTest, AllShorthandCoversEveryPointAndAxis) {
  const CalibrationSpec spec = ParseOk(
      "parameters:\n"
      "  anchor_offset_m: {all: {free: true, prior: {mean: 0, sigma: 0.02}}}\n"
      "  tower_offset_m: {all: {free: false}}\n");
  constexpr int kAnchorParameters = kNumAnchors * 3;
  constexpr int kTowerParameters = kNumCables * 3;
  ASSERT_EQ(spec.parameters.size(), static_cast<size_t>(kAnchorParameters + kTowerParameters));
  EXPECT_EQ(CountFree(spec), kAnchorParameters);
  for (int k = 0; k < kAnchorParameters; ++k) {
    const ParameterSpec& p = spec.parameters[k];
    EXPECT_EQ(p.kind, ParameterKind::kAnchorOffset);
    EXPECT_EQ(p.index, k / 3);  // point by point, x, y, z
    EXPECT_EQ(p.component, k % 3);
    EXPECT_EQ(p.unit, "m");
    EXPECT_EQ(p.prior_sigma_si, 0.02);
  }
  EXPECT_EQ(spec.parameters[0].name, "anchor_offset_m[1].x");
  EXPECT_EQ(spec.parameters[5].name, "anchor_offset_m[2].z");
  EXPECT_EQ(spec.parameters[kAnchorParameters].name, "tower_offset_m[1].x");
  EXPECT_EQ(spec.parameters.back().name, "tower_offset_m[6].z");
  EXPECT_EQ(spec.parameters.back().kind, ParameterKind::kTowerOffset);
  // The count follows the model's anchor points.
  EXPECT_EQ(ParseOk("parameters: {anchor_offset_m: {all: {free: true}}}\n", 5).parameters.size(),
            15u);
}

TEST(CalibrationSpecTest, OffsetListsNameTheirPointsAndAxes) {
  const CalibrationSpec spec = ParseOk(
      "parameters:\n"
      "  tower_offset_m:\n"
      "    - {x: {free: true}, y: {free: false}}\n"
      "    - {}\n"
      "    - {z: {free: true, initial: 0.01}}\n"
      "  anchor_offset_m:\n"
      "    -\n"
      "    - {y: {free: true}}\n");
  EXPECT_EQ(Names(spec), (std::vector<std::string>{"anchor_offset_m[2].y", "tower_offset_m[1].x",
                                                   "tower_offset_m[1].y", "tower_offset_m[3].z"}));
  EXPECT_EQ(spec.parameters[0].index, 1);
  EXPECT_EQ(spec.parameters[0].component, 1);
  EXPECT_EQ(spec.parameters[3].index, 2);
  EXPECT_EQ(spec.parameters[3].component, 2);
  EXPECT_EQ(spec.parameters[3].initial_si, 0.01);
  EXPECT_EQ(CountFree(spec), 3);
}

TEST(CalibrationSpecTest, ParametersComeInCanonicalOrderWhateverTheFileOrder) {
  const CalibrationSpec spec = ParseOk(
      "parameters:\n"
      "  sensor_bias_kN: {free: true}\n"
      "  sensor_gain: {free: true}\n"
      "  tower_offset_m: [{x: {free: true}}]\n"
      "  anchor_offset_m: [{z: {free: true}}]\n"
      "  ea_n: {free: true}\n"
      "  linear_density_kg_per_m: {free: true}\n"
      "  cabin_mass_kg: {free: true}\n"
      "  mass_centre_m: {z: {free: true}, x: {free: true}, y: {free: true}}\n");
  EXPECT_EQ(Names(spec),
            (std::vector<std::string>{"mass_centre_m.x", "mass_centre_m.y", "mass_centre_m.z",
                                      "cabin_mass_kg", "linear_density_kg_per_m", "ea_n",
                                      "anchor_offset_m[1].z", "tower_offset_m[1].x", "sensor_gain",
                                      "sensor_bias_kN"}));
  const std::vector<ParameterKind> kinds = {
      ParameterKind::kMassCentre,   ParameterKind::kMassCentre,    ParameterKind::kMassCentre,
      ParameterKind::kCabinMass,    ParameterKind::kLinearDensity, ParameterKind::kEa,
      ParameterKind::kAnchorOffset, ParameterKind::kTowerOffset,   ParameterKind::kSensorGain,
      ParameterKind::kSensorBias};
  ASSERT_EQ(spec.parameters.size(), kinds.size());
  for (size_t k = 0; k < kinds.size(); ++k) EXPECT_EQ(spec.parameters[k].kind, kinds[k]) << k;
}

TEST(CalibrationSpecTest, FullExampleHasTheExpectedParameters) {
  const CalibrationSpec spec = ParseOk(kFullSpec);
  // 3 mass centre + mass + density + 6 EA + 9 anchor + 2 tower + gain + 6 bias.
  constexpr size_t kListed = 3 + 1 + 1 + 6 + 9 + 2 + 1 + 6;
  constexpr int kFree = 2 + 1 + 9 + 1 + 1 + 6;
  EXPECT_EQ(spec.parameters.size(), kListed);
  EXPECT_EQ(CountFree(spec), kFree);
  EXPECT_TRUE(spec.IsValid(nullptr));
}

TEST(CalibrationSpecTest, WrittenSpecReadsBackIdentical) {
  const std::vector<std::string> texts = {
      kFullSpec,
      "",
      "parameters:\n"
      "  sensor_bias_kN:\n"
      "    mode: per_cable\n"
      "    cables: [{initial: 0.1}, {initial: 0.2, free: true}, {initial: 0.3},\n"
      "             {initial: -1.7}, {prior: {mean: 0.123456789, sigma: 0.0007}},\n"
      // x * 1000 / 1000 != x for this one: the written kN text differs, the newtons not.
      "             {initial: -9.129825816118114}]\n"
      "  anchor_offset_m: [{}, {y: {initial: 0.003}}]\n"
      "  tower_offset_m: {all: {free: true, initial: -0.25}}\n"
      "noise: {tension_sigma_kN: 0.3, tension_sigma_percent: 0}\n",
  };
  for (const std::string& text : texts) {
    SCOPED_TRACE(text);
    const CalibrationSpec spec = ParseOk(text);
    const std::string yaml = CalibrationSpecToYaml(spec);
    SCOPED_TRACE(yaml);
    const CalibrationSpec again = ParseOk(yaml);
    ExpectSameSpec(spec, again);
    EXPECT_EQ(CalibrationSpecToYaml(again), yaml);  // a fixed point
  }
}

TEST(CalibrationSpecTest, SlowErrorIsReadAndWrittenBack) {
  EXPECT_FALSE(ParseOk("").slow_error.enabled);  // off unless asked for
  EXPECT_FALSE(ParseOk("noise: {slow_error: none}").slow_error.enabled);
  const CalibrationSpec both = ParseOk("noise: {slow_error: estimate}");
  EXPECT_TRUE(both.slow_error.enabled && both.slow_error.estimate_amplitude &&
              both.slow_error.amplitude_in_percent && both.slow_error.estimate_time_constant);
  EXPECT_FALSE(both.slow_error.Initial().IsActive());  // white until estimated
  const CalibrationSpec stated =
      ParseOk("noise:\n  slow_error: {sigma_percent: 1.5, sigma_kN: 0.5, time_constant_s: 60}\n");
  EXPECT_FALSE(stated.slow_error.estimates_any());
  EXPECT_DOUBLE_EQ(stated.slow_error.stated.sigma_percent, 1.5);
  EXPECT_DOUBLE_EQ(stated.slow_error.stated.sigma_n, 0.5 * kNewtonsPerKilonewton);
  EXPECT_DOUBLE_EQ(stated.slow_error.Initial().time_constant_s, 60.0);
  const CalibrationSpec kn =
      ParseOk("noise: {slow_error: {sigma_kN: estimate, time_constant_s: 20}}");
  EXPECT_TRUE(kn.slow_error.estimate_amplitude && !kn.slow_error.amplitude_in_percent);
  EXPECT_FALSE(kn.slow_error.estimate_time_constant);
  for (const CalibrationSpec& spec : {both, stated, kn}) {
    const std::string yaml = CalibrationSpecToYaml(spec);
    SCOPED_TRACE(yaml);
    const CalibrationSpec again = ParseOk(yaml);
    EXPECT_EQ(CalibrationSpecToYaml(again), yaml);
    EXPECT_EQ(again.slow_error.estimate_amplitude, spec.slow_error.estimate_amplitude);
    EXPECT_EQ(again.slow_error.amplitude_in_percent, spec.slow_error.amplitude_in_percent);
    EXPECT_EQ(again.slow_error.stated.sigma_n, spec.slow_error.stated.sigma_n);
  }
}

TEST(CalibrationSpecTest, SlowErrorErrorsNameTheKey) {
  const std::pair<const char*, const char*> cases[] = {
      {"noise: {slow_error: maybe}", "noise.slow_error: unknown value"},
      {"noise: {slow_error: {sigma_percent: 1}}", "time_constant_s is missing"},
      {"noise: {slow_error: {time_constant_s: 10}}", "no amplitude"},
      {"noise: {slow_error: {sigma_percent: estimate, sigma_kN: estimate, time_constant_s: 1}}",
       "both \"estimate\""},
      {"noise: {slow_error: {sigma_percent: -1, time_constant_s: 1}}",
       "noise.slow_error.sigma_percent: must be >= 0"},
      {"noise: {slow_error: {sigma_percent: 1, time_constant_s: 0}}",
       "noise.slow_error.time_constant_s: must be > 0"},
      {"noise: {slow_error: {sigma_percent: 1, time_constant_s: 1e9}}", "at most a year"},
      {"noise: {slow_error: {sigma_percent: 1, tau: 1}}", "noise.slow_error.tau: unknown key"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string error = ParseError(text);
    EXPECT_NE(error.find(expected), std::string::npos) << text << " -> " << error;
    EXPECT_EQ(error.rfind(std::string(kSource) + ":1: ", 0), 0u) << error;
  }
  CalibrationSpec spec;
  spec.slow_error.enabled = true;
  spec.slow_error.stated.sigma_percent = 1.0;
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));  // no time constant
  EXPECT_NE(why.find("slow_error: time_constant_s"), std::string::npos) << why;
  spec.slow_error.stated.time_constant_s = 30.0;
  EXPECT_TRUE(spec.IsValid(&why)) << why;
}

TEST(CalibrationSpecTest, BuiltSpecWritesTheSameSiValues) {
  // Values in newtons that are the image of some kN number: exact after a round trip.
  CalibrationSpec spec;
  spec.tension_sigma_n = 0.1 * kNewtonsPerKilonewton;
  spec.holdout_seed = 18446744073709551615ull;
  ParameterSpec bias;
  bias.kind = ParameterKind::kSensorBias;
  bias.index = 2;
  bias.name = "sensor_bias_kN[3]";
  bias.unit = "kN";
  bias.to_si = kNewtonsPerKilonewton;
  bias.free = true;
  bias.has_initial = true;
  bias.initial_si = 0.7 * kNewtonsPerKilonewton;
  bias.has_prior = true;
  bias.prior_mean_si = 0.0;
  bias.prior_sigma_si = 2.3 * kNewtonsPerKilonewton;
  spec.parameters.push_back(bias);
  ASSERT_TRUE(spec.IsValid(nullptr));
  const CalibrationSpec again = ParseOk(CalibrationSpecToYaml(spec));
  EXPECT_EQ(again.tension_sigma_n, spec.tension_sigma_n);
  EXPECT_EQ(again.holdout_seed, spec.holdout_seed);
  // The single per-cable bias comes back as six, the others fixed at the model's value.
  ASSERT_EQ(again.parameters.size(), static_cast<size_t>(kNumCables));
  ExpectSameParameter(again.parameters[2], bias);
  EXPECT_EQ(CountFree(again), 1);
  for (int i : {0, 1, 3, 4, 5}) {
    EXPECT_FALSE(again.parameters[i].has_initial);
    EXPECT_FALSE(again.parameters[i].has_prior);
  }
}

struct ErrorCase {
  const char* text;
  int line;          // expected in the message; 0: no line
  const char* key;   // key path expected in the message
  const char* what;  // further text expected in the message
};

// One case per error class.
const ErrorCase kErrorCases[] = {
    {"forward_model: aas\nfromat: x\n", 2, "fromat", "unknown key"},
    {"format: fastcal-model-1\n", 1, "format", "fastcal-calibration-spec-1"},
    {"forward_model: refined\n", 1, "forward_model", "aas-refined"},
    {"forward_model:\n", 1, "forward_model", "no value"},
    {"attitude: commanded\n", 1, "attitude", "planned"},
    {"noise:\n  tension_sigma_kN: -1\n", 2, "noise.tension_sigma_kN", ">= 0"},
    {"noise:\n  tension_sigma_percent: -3\n", 2, "noise.tension_sigma_percent", ">= 0"},
    {"\nnoise: {tension_sigma_percent: 0}\n", 2, "noise", "both 0"},
    {"noise: {tension_sigma_pct: 3}\n", 1, "noise.tension_sigma_pct", "unknown key"},
    {"robust_loss: {type: tukey}\n", 1, "robust_loss.type", "cauchy"},
    {"robust_loss:\n  type: huber\n  scale: 0\n", 3, "robust_loss.scale", "> 0"},
    {"holdout: {fraction: 1}\n", 1, "holdout.fraction", "[0, 1)"},
    {"holdout:\n  fraction: -0.1\n", 2, "holdout.fraction", "[0, 1)"},
    {"holdout:\n  seed: -1\n", 2, "holdout.seed", "integer"},
    {"holdout: {blocks: 1}\n", 1, "holdout.blocks", ">= 2"},
    {"cross_validation: {blocks: 0}\n", 1, "cross_validation.blocks", ">= 2"},
    {"cross_validation: {folds: 5}\n", 1, "cross_validation.folds", "unknown key"},
    {"gross_errors: {detect: maybe}\n", 1, "gross_errors.detect", "true or false"},
    {"gross_errors:\n  threshold_sigmas: 0\n", 2, "gross_errors.threshold_sigmas", "> 0"},
    {"gross_errors: {max_fraction: 1.5}\n", 1, "gross_errors.max_fraction", "(0, 1]"},
    {"solver:\n  threads: 0\n", 2, "solver.threads", "must be 1 to 256"},
    {"solver:\n  threads: 100000\n", 2, "solver.threads", "must be 1 to 256, got 100000"},
    {"noise: {tension_sigma_kN: 1e-160, tension_sigma_percent: 0}\n", 1, "noise.tension_sigma_kN",
     "finer than any tension sensor"},
    {"noise: {tension_sigma_kN: 1, tension_sigma_percent: 1e-9}\n", 1,
     "noise.tension_sigma_percent", "finer than any tension sensor"},
    {"parameters:\n  mass_centre_m:\n    z: {free: true, prior: {mean: 0.5, sigma: 1e-200}}\n", 3,
     "parameters.mass_centre_m.z.prior.sigma", "holds the parameter fixed"},
    {"solver:\n  max_iterations: 0\n", 2, "solver.max_iterations", ">= 1"},
    {"solver:\n  max_iterations: 1.5\n", 2, "solver.max_iterations", "integer"},
    {"solver:\n  function_tolerance: 0\n", 2, "solver.function_tolerance", "> 0"},
    {"solver:\n  gradient_tolerance: -1e-9\n", 2, "solver.gradient_tolerance", "> 0"},
    {"solver:\n  parameter_tolerance: .nan\n", 2, "solver.parameter_tolerance", "finite"},
    {"parameters:\n  mass_center_m: {x: {free: true}}\n", 2, "parameters.mass_center_m",
     "unknown parameter (accepted: mass_centre_m, cabin_mass_kg, linear_density_kg_per_m, ea_n, "
     "anchor_offset_m, tower_offset_m, sensor_gain, sensor_bias_kN, attachment_mass_kg, "
     "attachment_density_kg_per_m, length_offset_m, moving_parts, measured_frame)"},
    {"parameters:\n  mass_centre_m:\n    w: {free: true}\n", 3, "parameters.mass_centre_m.w",
     "unknown key"},
    {"parameters:\n  cabin_mass_kg: {free: true, inital: 3}\n", 2,
     "parameters.cabin_mass_kg.inital", "unknown key (allowed here: free, initial, prior)"},
    {"parameters:\n  cabin_mass_kg:\n    free: yes\n", 3, "parameters.cabin_mass_kg.free",
     "true or false"},
    {"parameters:\n  cabin_mass_kg:\n    initial: \"30000\"\n", 3,
     "parameters.cabin_mass_kg.initial", "quoted"},
    {"parameters:\n  cabin_mass_kg:\n    initial: 0\n", 3, "parameters.cabin_mass_kg.initial",
     "> 0"},
    {"parameters:\n  linear_density_kg_per_m:\n    initial: -11.7\n", 3,
     "parameters.linear_density_kg_per_m.initial", "> 0"},
    {"parameters:\n  ea_n:\n    mode: per_cable\n    cables:\n      - {}\n      - {}\n"
     "      - {initial: 0}\n      - {}\n      - {}\n      - {}\n",
     7, "parameters.ea_n.cables[3].initial", "> 0"},
    {"parameters:\n  sensor_gain:\n    initial: -1\n", 3, "parameters.sensor_gain.initial", "> 0"},
    {"parameters:\n  sensor_gain:\n    prior: {mean: 1}\n", 3, "parameters.sensor_gain.prior.sigma",
     "missing"},
    {"parameters:\n  sensor_gain:\n    prior:\n      mean: 1\n      sigma: 0\n", 5,
     "parameters.sensor_gain.prior.sigma", "> 0"},
    {"parameters:\n  sensor_gain:\n    prior:\n      mean: .inf\n      sigma: 1\n", 4,
     "parameters.sensor_gain.prior.mean", "finite"},
    // Unit and magnitude slips (issue 17): refused where they are written, the likely
    // slip named.
    {"parameters:\n  cabin_mass_kg: {initial: 30}\n", 2, "parameters.cabin_mass_kg.initial",
     "30 kg is below the plausible minimum of 10000 kg (nominal FAST: 30000 kg; tonnes written "
     "as kg?)"},
    {"parameters:\n  ea_n: {initial: 24656}\n", 2, "parameters.ea_n.initial",
     "24656 N is below the plausible minimum of 5e+06 N (nominal FAST: 2.4656e+07 N; kN "
     "written as N?)"},
    {"parameters:\n  mass_centre_m:\n    x: {initial: 150}\n", 3,
     "parameters.mass_centre_m.x.initial",
     "150 m is beyond the plausible +-5 m (mm written as m?)"},
    {"noise: {tension_sigma_kN: 3000}\n", 1, "noise.tension_sigma_kN",
     "3000 kN is above the plausible maximum of 50 kN (N written as kN?)"},
    {"noise: {tension_sigma_percent: 300}\n", 1, "noise.tension_sigma_percent",
     "300% is above the plausible maximum of 50%"},
    {"parameters:\n  sensor_bias_kN: {prior: {mean: 0, sigma: 2000}}\n", 2,
     "parameters.sensor_bias_kN.prior.sigma",
     "2000 kN is wider than the whole plausible range of the parameter (-100 kN to 100 kN)"},
    {"parameters:\n  tower_offset_m: {all: {prior: {mean: 10, sigma: 0.01}}}\n", 2,
     "parameters.tower_offset_m.all.prior.mean", "10 m is beyond the plausible +-1 m"},
    {"parameters:\n  sensor_bias_kN:\n    mode: each\n", 3, "parameters.sensor_bias_kN.mode",
     "per_cable"},
    {"parameters:\n  sensor_bias_kN:\n    cables: [{}, {}, {}, {}, {}, {}]\n", 3,
     "parameters.sensor_bias_kN.cables", "mode: per_cable"},
    {"parameters:\n  sensor_bias_kN:\n    mode: per_cable\n    cables: [{}, {}]\n", 4,
     "parameters.sensor_bias_kN.cables", "exactly 6"},
    {"parameters:\n  anchor_offset_m:\n    - {}\n    - {}\n    - {}\n    - {x: {free: true}}\n", 2,
     "parameters.anchor_offset_m", "4 entries but the model has 3 anchor points"},
    {"parameters:\n  tower_offset_m: [{}, {}, {}, {}, {}, {}, {}]\n", 2,
     "parameters.tower_offset_m", "7 entries but the model has 6 towers"},
    {"parameters:\n  tower_offset_m: {every: {free: true}}\n", 2, "parameters.tower_offset_m.every",
     "unknown key"},
    {"parameters:\n  anchor_offset_m:\n    - {x: {free: true}}\n    - {q: {}}\n", 4,
     "parameters.anchor_offset_m[2].q", "unknown key"},
    {"parameters:\n  cabin_mass_kg: {free: true}\n  cabin_mass_kg: {free: false}\n", 3,
     "parameters.cabin_mass_kg", "duplicate"},
    {"parameters:\n  mass_centre_m: [1, 2]\n", 2, "parameters.mass_centre_m", "mapping"},
    // yaml-cpp reports an unclosed flow mapping where the input ends.
    {"parameters:\n  mass_centre_m:\n    x: {free: true\n", 4, "YAML syntax error", "flow"},
    {"a: 1\n---\nb: 2\n", 3, "(top level)", "one YAML document"},
};

// A number out of range is quoted cut short (issue 29: a 10 MB number was echoed whole).
TEST(CalibrationSpecTest, AnOutOfRangeNumberIsQuotedShort) {
  const std::string huge = "1" + std::string(10000, '0') + "e99999";
  for (const std::string& text :
       {"noise: {tension_sigma_percent: " + huge + "}\n", "solver: {threads: " + huge + "}\n"}) {
    const std::string error = ParseError(text);
    EXPECT_NE(error.find("'1000000"), std::string::npos) << error.substr(0, 300);
    EXPECT_LT(error.size(), 400u) << error.substr(0, 300);
  }
}

TEST(CalibrationSpecTest, ErrorsNameTheFileTheLineAndTheKey) {
  for (const ErrorCase& c : kErrorCases) {
    SCOPED_TRACE(c.text);
    const std::string error = ParseError(c.text);
    ASSERT_FALSE(error.empty()) << "parsed without error";
    const std::string where =
        std::string(kSource) + (c.line > 0 ? ":" + std::to_string(c.line) : "") + ": ";
    EXPECT_EQ(error.rfind(where, 0), 0u) << error;
    EXPECT_NE(error.find(std::string(": ") + c.key + ": "), std::string::npos) << error;
    EXPECT_NE(error.find(c.what), std::string::npos) << error;
  }
}

// A fixed parameter with a prior is a consider parameter (it was silently ignored).
TEST(CalibrationSpecTest, FixedWithPriorIsAConsiderParameter) {
  const CalibrationSpec spec = ParseOk(
      "parameters:\n  sensor_gain: {mode: per_cable, free: false, prior: {mean: 1, sigma: 0.01}}\n"
      "  cabin_mass_kg: {free: true, prior: {mean: 30000, sigma: 300}}\n"
      "  ea_n: {free: false}\n");
  int consider = 0;
  for (const ParameterSpec& p : spec.parameters) {
    consider += p.IsConsider();
    EXPECT_EQ(p.IsConsider(), p.kind == ParameterKind::kSensorGain) << p.name;
  }
  EXPECT_EQ(consider, kNumCables);
}

// The candidates of the misfit ranking: every parameter a spec can name.
TEST(CalibrationSpecTest, AllModelParametersNamesEveryParameterOnce) {
  const std::vector<ParameterSpec> all = AllModelParameters(3);
  // 3 mass centre, 1 cabin mass, 4 per-cable groups x (common + 6), 3 x 3 anchor, 6 x 3 tower,
  // the length offsets (common + 6).
  EXPECT_EQ(all.size(), 3u + 1u + 4u * 7u + 9u + 18u + 7u);
  for (size_t a = 0; a < all.size(); ++a) {
    EXPECT_FALSE(all[a].free);
    for (size_t b = a + 1; b < all.size(); ++b) {
      EXPECT_FALSE(SameParameter(all[a], all[b])) << all[a].name << " " << all[b].name;
      EXPECT_NE(all[a].name, all[b].name);
    }
  }
  EXPECT_EQ(all[0].name, "mass_centre_m.x");
  EXPECT_EQ(all.back().name, "length_offset_m[6]");
  EXPECT_EQ(all[all.size() - 8].name, "sensor_bias_kN[6]");
  EXPECT_EQ(all[all.size() - 8].to_si, kNewtonsPerKilonewton);
  EXPECT_STREQ(ParameterGroupName(ParameterKind::kTowerOffset), "tower_offset_m");
}

TEST(CalibrationSpecTest, AllShorthandNeedsAnchorPoints) {
  const std::string error = ParseError("parameters: {anchor_offset_m: {all: {}}}\n", 0);
  EXPECT_NE(error.find("anchor_offset_m.all"), std::string::npos) << error;
}

TEST(CalibrationSpecTest, FailedParseLeavesTheSpecAlone) {
  CalibrationSpec spec;
  spec.max_iterations = 7;
  std::string error;
  EXPECT_FALSE(ParseCalibrationSpecYaml("solver: {max_iterations: 9, threads: 0}\n", kSource,
                                        kNumAnchors, &spec, &error));
  EXPECT_EQ(spec.max_iterations, 7);
  EXPECT_FALSE(ParseCalibrationSpecYaml("x: 1\n", kSource, kNumAnchors, &spec, nullptr));
}

TEST(CalibrationSpecTest, MissingFileIsReported) {
  const std::string path = testing::TempDir() + "/no_such_spec.yaml";
  CalibrationSpec spec;
  std::string error;
  EXPECT_FALSE(LoadCalibrationSpec(path, kNumAnchors, &spec, &error));
  EXPECT_EQ(error, path + ": cannot open: No such file or directory");
}

TEST(CalibrationSpecTest, LoadedFileErrorsNameThePath) {
  const std::string path = test::TempPath("bad_spec", ".yaml");
  {
    std::ofstream out(path);
    out << "# comment\nholdout:\n  fraction: 2\n";
  }
  CalibrationSpec spec;
  std::string error;
  EXPECT_FALSE(LoadCalibrationSpec(path, kNumAnchors, &spec, &error));
  EXPECT_EQ(error.rfind(path + ":3: holdout.fraction: ", 0), 0u) << error;
}

// IsValid on specs built in code: one broken field at a time.
TEST(CalibrationSpecTest, IsValidRejectsEachImpossibleValue) {
  ParameterSpec gain;
  gain.kind = ParameterKind::kSensorGain;
  gain.name = "sensor_gain";
  gain.unit = "1";
  gain.free = true;
  struct Case {
    const char* expected;  // in the message
    void (*breaks)(CalibrationSpec*);
  };
  const Case kCases[] = {
      {"tension_sigma_n", [](CalibrationSpec* s) { s->tension_sigma_n = -1; }},
      {"tension_sigma_percent", [](CalibrationSpec* s) { s->tension_sigma_percent = -1; }},
      {"both 0", [](CalibrationSpec* s) { s->tension_sigma_percent = 0; }},
      {"robust_loss_scale", [](CalibrationSpec* s) { s->robust_loss_scale = 0; }},
      {"holdout_fraction", [](CalibrationSpec* s) { s->holdout_fraction = 1; }},
      {"holdout_blocks", [](CalibrationSpec* s) { s->holdout_blocks = 1; }},
      {"cross_validation_blocks", [](CalibrationSpec* s) { s->cross_validation_blocks = 1; }},
      {"gross_error_threshold_sigmas",
       [](CalibrationSpec* s) { s->gross_error_threshold_sigmas = 0; }},
      {"max_gross_error_fraction", [](CalibrationSpec* s) { s->max_gross_error_fraction = 0; }},
      {"max_iterations", [](CalibrationSpec* s) { s->max_iterations = 0; }},
      {"num_threads", [](CalibrationSpec* s) { s->num_threads = 0; }},
      {"function_tolerance", [](CalibrationSpec* s) { s->function_tolerance = 0; }},
      {"gradient_tolerance", [](CalibrationSpec* s) { s->gradient_tolerance = -1; }},
      {"parameter_tolerance", [](CalibrationSpec* s) { s->parameter_tolerance = NAN; }},
      {"sensor_gain.initial",
       [](CalibrationSpec* s) {
         s->parameters[0].has_initial = true;
         s->parameters[0].initial_si = 0;
       }},
      {"sensor_gain.prior.sigma",
       [](CalibrationSpec* s) {
         s->parameters[0].has_prior = true;
         s->parameters[0].prior_mean_si = 1;  // a plausible gain: the sigma is what fails
         s->parameters[0].prior_sigma_si = 0;
       }},
      {"sensor_gain.prior.mean: 0 is below the plausible minimum of 0.5",
       [](CalibrationSpec* s) {
         s->parameters[0].has_prior = true;
         s->parameters[0].prior_sigma_si = 0.01;
       }},
      {"tension_sigma_n: 3000 kN is above the plausible maximum of 50 kN (N written as kN?)",
       [](CalibrationSpec* s) { s->tension_sigma_n = 3e6; }},
      {"initial: 30 kg is below the plausible minimum of 10000 kg (nominal FAST: 30000 kg; "
       "tonnes written as kg?)",
       [](CalibrationSpec* s) {
         s->parameters[0].kind = ParameterKind::kCabinMass;
         s->parameters[0].has_initial = true;
         s->parameters[0].initial_si = 30;
       }},
      {"sensor_gain: index", [](CalibrationSpec* s) { s->parameters[0].index = kNumCables; }},
      {"sensor_gain: to_si", [](CalibrationSpec* s) { s->parameters[0].to_si = 0; }},
      {"listed twice", [](CalibrationSpec* s) { s->parameters.push_back(s->parameters[0]); }},
      {"choose one mode",
       [](CalibrationSpec* s) {
         s->parameters.push_back(s->parameters[0]);
         s->parameters.back().index = 3;
         s->parameters.back().name = "sensor_gain[4]";
       }},
      {"parameters[0]: has no name", [](CalibrationSpec* s) { s->parameters[0].name.clear(); }},
      {"component",
       [](CalibrationSpec* s) {
         s->parameters[0].kind = ParameterKind::kMassCentre;
         s->parameters[0].component = 3;
       }},
      {"tower 0..5",
       [](CalibrationSpec* s) {
         s->parameters[0].kind = ParameterKind::kTowerOffset;
         s->parameters[0].component = 0;
         s->parameters[0].index = -1;
       }},
      {"initial: must be > 0",
       [](CalibrationSpec* s) {
         s->parameters[0].kind = ParameterKind::kCabinMass;
         s->parameters[0].has_initial = true;
         s->parameters[0].initial_si = -30000;
       }},
  };
  CalibrationSpec good;
  good.parameters.push_back(gain);
  std::string error;
  ASSERT_TRUE(good.IsValid(&error)) << error;
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.expected);
    CalibrationSpec spec = good;
    c.breaks(&spec);
    error.clear();
    EXPECT_FALSE(spec.IsValid(&error));
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
  }
}

// ---------------------------------------------------------------------------------------
// Files in the source tree.

std::string SourceDir() {
  const char* dir = (std::getenv("FASTCAL_SOURCE_DIR") ? std::getenv("FASTCAL_SOURCE_DIR")
                                                       : FASTCAL_TEST_SOURCE_DIR);
  return dir == nullptr ? "" : dir;
}

TEST(CalibrationSpecTest, ExampleSpecsLoadWithTheExpectedFreeParameters) {
  if (SourceDir().empty()) GTEST_SKIP() << "FASTCAL_SOURCE_DIR is not set";
  struct Example {
    const char* file;
    int num_free;
  };
  const Example kExamples[] = {
      {"spec_mass_centre.yaml", 2},          {"spec_mass_centre_density.yaml", 4},
      {"spec_wide.yaml", 3 + 1 + 1 + 6 + 9}, {"spec_realistic.yaml", 3 + 6 + 6 + 6},
      {"spec_sessions.yaml", 3 + 6 + 6 + 6}, {"spec_change_scan.yaml", 3 + 6 + 6 + 6},
  };
  for (const Example& e : kExamples) {
    SCOPED_TRACE(e.file);
    CalibrationSpec spec;
    std::string error;
    ASSERT_TRUE(LoadCalibrationSpec(SourceDir() + "/calibration_data/" + e.file, kNumAnchors, &spec,
                                    &error))
        << error;
    EXPECT_EQ(CountFree(spec), e.num_free);
    EXPECT_TRUE(spec.IsValid(&error)) << error;
    // Every example states its forward model, and it is exact: right wherever it answers
    // (docs/model.md), and no slower than aas-refined.
    EXPECT_EQ(spec.forward_model, StaticsMethod::kExact);
  }
}

TEST(CalibrationSpecTest, ExampleSpecsFixWhatTheyShould) {
  if (SourceDir().empty()) GTEST_SKIP() << "FASTCAL_SOURCE_DIR is not set";
  const std::string dir = SourceDir() + "/calibration_data/";
  CalibrationSpec spec;
  std::string error;
  ASSERT_TRUE(LoadCalibrationSpec(dir + "spec_mass_centre.yaml", kNumAnchors, &spec, &error))
      << error;
  ASSERT_EQ(spec.parameters.size(), 3u);
  EXPECT_EQ(spec.parameters[2].name, "mass_centre_m.z");
  EXPECT_FALSE(spec.parameters[2].free);
  EXPECT_TRUE(spec.parameters[2].has_initial);
  EXPECT_EQ(spec.parameters[2].initial_si, 0.5);

  ASSERT_TRUE(LoadCalibrationSpec(dir + "spec_wide.yaml", kNumAnchors, &spec, &error)) << error;
  bool mass_listed_fixed = false;
  for (const ParameterSpec& p : spec.parameters) {
    if (p.kind == ParameterKind::kCabinMass) mass_listed_fixed = !p.free;
    if (p.kind == ParameterKind::kSensorGain) {
      EXPECT_EQ(p.index, -1);
      EXPECT_EQ(p.prior_mean_si, 1.0);
      EXPECT_EQ(p.prior_sigma_si, 0.03);
    }
    if (p.kind == ParameterKind::kSensorBias) {
      EXPECT_GE(p.index, 0);
      EXPECT_EQ(p.prior_mean_si, 0.0);
      EXPECT_EQ(p.prior_sigma_si, 2.0 * kNewtonsPerKilonewton);
    }
    if (p.kind == ParameterKind::kAnchorOffset) {
      EXPECT_EQ(p.prior_sigma_si, 0.02);
    }
    if (p.free && p.kind != ParameterKind::kMassCentre && p.kind != ParameterKind::kLinearDensity) {
      EXPECT_TRUE(p.has_prior) << p.name;  // only what the data determines is prior-free
    }
  }
  EXPECT_TRUE(mass_listed_fixed);
}

// The first ```yaml block of docs/calibration.md is the documented example: it must parse.
TEST(CalibrationSpecTest, DocumentedExampleParses) {
  if (SourceDir().empty()) GTEST_SKIP() << "FASTCAL_SOURCE_DIR is not set";
  std::ifstream in(SourceDir() + "/docs/calibration.md");
  ASSERT_TRUE(in) << "docs/calibration.md";
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const std::string open = "```yaml\n";
  const size_t begin = doc.find(open);
  ASSERT_NE(begin, std::string::npos);
  const size_t end = doc.find("```", begin + open.size());
  ASSERT_NE(end, std::string::npos);
  const CalibrationSpec spec = ParseOk(doc.substr(begin + open.size(), end - begin - open.size()));
  // The counts the text states under the example.
  EXPECT_EQ(spec.parameters.size(), 29u);
  EXPECT_EQ(CountFree(spec), 20);
}

}  // namespace
}  // namespace fastcal
