// Tests of the winches' lengths as calibration data (issue 31; docs/calibration.md,
// "Lengths"): the spec's noise.length_sigma_m and length_offset_m group, their errors and
// round trip; the length rows' derivatives against central differences; simulated
// telemetry of cables with per-cable EA and encoder offsets, whose EA and offsets a fit
// with lengths finds within sigma_total; a survey at one pose, which cannot tell a cable's
// EA from its encoder's zero (named); and a slipped encoder, a gross error of a length.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/design.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/simulation.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

CalibrationSpec Parse(const std::string& text,
                      const CableRobot& model = CableRobot::NominalFast()) {
  CalibrationSpec spec;
  std::string error;
  EXPECT_TRUE(ParseCalibrationSpecYaml(text, "spec.yaml", model, &spec, &error)) << error;
  return spec;
}

std::string ParseError(const std::string& text) {
  CalibrationSpec spec;
  std::string error;
  return ParseCalibrationSpecYaml(text, "spec.yaml", CableRobot::NominalFast(), &spec, &error)
             ? ""
             : error;
}

// The spec of calibration_data/spec_lengths.yaml: the mass centre, per cable EA and
// encoder offset, lengths at 5 mm.
constexpr char kLengthsSpec[] =
    "noise: {tension_sigma_percent: 3, length_sigma_m: 0.005}\n"
    "parameters:\n"
    "  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}\n"
    "  ea_n: {mode: per_cable, free: true}\n"
    "  length_offset_m: {mode: per_cable, free: true}\n";

TEST(CalibrationLengthsTest, SpecReadsLengthsAndOffsetsAndRefusesThemAlone) {
  const CalibrationSpec spec = Parse(kLengthsSpec);
  EXPECT_TRUE(spec.UsesLengths());
  EXPECT_EQ(spec.length_sigma_m, 0.005);
  ASSERT_EQ(spec.parameters.size(), 3u + 6u + 6u);
  EXPECT_EQ(spec.parameters.back().name, "length_offset_m[6]");
  EXPECT_EQ(spec.parameters.back().kind, ParameterKind::kLengthOffset);
  EXPECT_EQ(spec.parameters.back().index, 5);
  const CalibrationSpec back = Parse(CalibrationSpecToYaml(spec));
  EXPECT_EQ(back.length_sigma_m, spec.length_sigma_m);
  EXPECT_EQ(CalibrationSpecToYaml(back), CalibrationSpecToYaml(spec));
  // A common offset is one parameter.
  EXPECT_EQ(Parse("noise: {length_sigma_m: 0.01}\n"
                  "parameters: {length_offset_m: {free: true}}\n")
                .parameters.front()
                .name,
            "length_offset_m");
  // Offsets without the lengths, lengths through an approximate model, bad sigmas.
  EXPECT_NE(ParseError("parameters: {length_offset_m: {mode: per_cable, free: true}}\n")
                .find("length_offset_m[1]: the lengths are not in the fit, so nothing determines "
                      "it: give noise.length_sigma_m"),
            std::string::npos);
  EXPECT_NE(ParseError("forward_model: aas\nnoise: {length_sigma_m: 0.01}\n")
                .find("the lengths need forward_model: exact"),
            std::string::npos);
  EXPECT_NE(ParseError("noise: {length_sigma_m: 0}\n").find("spec.yaml:1: noise.length_sigma_m"),
            std::string::npos);
  EXPECT_NE(ParseError("noise: {length_sigma_m: 5}\n").find("mm written as m?"), std::string::npos);
  // An encoder's tenth of a millimetre is a sigma (the tension sensors' floor is not).
  EXPECT_EQ(Parse("noise: {length_sigma_m: 0.0001}\n").length_sigma_m, 0.0001);
  // A fixed offset without the lengths is harmless: the model's value, listed.
  EXPECT_FALSE(Parse("parameters: {length_offset_m: {initial: 0.2}}\n").UsesLengths());
}

// The data: the cap's grid (8 deg rings, 12 deg azimuths) repeated at three heights off the
// focal sphere, so that each cable's tension ranges widely.
std::vector<Pose> SurveyPoses() {
  std::vector<Pose> poses;
  for (double radius : {157.0, 160.0, 163.0}) {
    FocalGridSpec grid;
    grid.off_axis_step_deg = 8.0;
    grid.azimuth_step_deg = 12.0;
    grid.focal_radius_m = radius;
    std::vector<Eigen::Vector3d> positions;
    std::vector<Pose> ring;
    std::string error;
    EXPECT_TRUE(FocalSpherePositions(grid, &positions, &error)) << error;
    EXPECT_TRUE(PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &ring, &error)) << error;
    poses.insert(poses.end(), ring.begin(), ring.end());
  }
  return poses;
}

// Cables whose EA differ by up to 6% from the nominal, with encoder offsets of decimetres.
CableRobot Truth() {
  CableRobot truth = CableRobot::NominalFast();
  const double ea_factor[kNumCables] = {1.04, 0.97, 1.02, 0.95, 1.06, 0.99};
  const double offset_m[kNumCables] = {-0.27, -0.02, -0.10, 0.64, 0.05, -0.15};
  for (int i = 0; i < kNumCables; ++i) {
    truth.cables[i].ea_n *= ea_factor[i];
    truth.cables[i].length_offset_m = offset_m[i];
  }
  truth.mass_centre_cabin_m = Eigen::Vector3d(0.22, 0.11, 0.5);
  return truth;
}

Dataset Telemetry(const CableRobot& truth, const std::vector<Pose>& poses, unsigned seed) {
  SimulationOptions o;
  o.tension_noise_percent = 3.0;
  o.length_noise_m = 0.005;
  o.seed = seed;
  Dataset data;
  std::string error;
  EXPECT_TRUE(Simulate(truth, poses, o, &data, nullptr, nullptr, &error)) << error;
  return data;
}

// The length rows' derivatives (ceres::Jet through exact's solution) against central
// differences of the same residual, with respect to EA and the offset of each cable and
// the mass centre.
TEST(CalibrationLengthsTest, LengthRowsDerivativesMatchCentralDifferences) {
  constexpr double kRelTol = 1e-6;  // of the largest entry of the row
  const CableRobot truth = Truth();
  const CalibrationSpec spec = Parse(kLengthsSpec);
  const internal::CalibrationModel model(CableRobot::NominalFast(), spec);
  const Dataset data = Telemetry(truth, {SurveyPoses()[17]}, 1);
  internal::TensionResidual f;
  f.model = &model;
  f.pose = data.samples[0].pose;
  f.measured_n = data.samples[0].tension_n;
  f.sigma_n.fill(5e3);
  f.statics = ModelFitStaticsOptions(StaticsMethod::kExact);
  f.length_sigma_m = spec.length_sigma_m;
  f.measured_length_m = data.samples[0].unstretched_length_m;
  ASSERT_EQ(f.readings(), 12);
  const std::vector<double> theta = model.InitialTheta();
  const int n = model.num_free();
  std::vector<double> jacobian(12 * n), r(12);
  const internal::TensionCost cost(f);
  const double* parameters[1] = {theta.data()};
  double* jacobians[1] = {jacobian.data()};
  ASSERT_TRUE(cost.Evaluate(parameters, r.data(), jacobians));
  for (int k = 0; k < n; ++k) {
    const double h = k < 3 ? 1e-4 : k < 9 ? 1e-4 * theta[k] : 1e-6;  // m, N, m
    std::vector<double> plus = theta, minus = theta, rp(12), rm(12);
    plus[k] += h;
    minus[k] -= h;
    ASSERT_TRUE(f(plus.data(), rp.data()));
    ASSERT_TRUE(f(minus.data(), rm.data()));
    for (int i = 6; i < 12; ++i) {
      double scale = 0.0;
      for (int c = 0; c < n; ++c) scale = std::max(scale, std::abs(jacobian[i * n + c]));
      EXPECT_NEAR((rp[i] - rm[i]) / (2 * h), jacobian[i * n + k], kRelTol * scale)
          << "row " << i << " parameter " << k;
    }
  }
  // The offset enters its own cable's length only, as +1 / sigma.
  EXPECT_NEAR(jacobian[(6 + 2) * n + 9 + 2], 1.0 / spec.length_sigma_m, 1e-9);
  EXPECT_EQ(jacobian[(6 + 2) * n + 9 + 3], 0.0);
}

TEST(CalibrationLengthsTest, LengthsFindTheOffsetsAndEachCablesEa) {
  constexpr double kMaxSigmas = 3.0;      // each estimate within 3 sigma_total of the truth
  constexpr double kMaxMeanSquare = 2.0;  // and their mean squared z about 1 (12 of them)
  const CableRobot truth = Truth();
  const Dataset data = Telemetry(truth, SurveyPoses(), 11);
  CalibrationResult r;
  std::string error;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), Parse(kLengthsSpec), data, CalibrationOptions(),
                      &r, &error),
            CalibrationStatus::kOk)
      << error;
  EXPECT_EQ(r.num_residuals, 12 * static_cast<int>(data.samples.size()));
  EXPECT_EQ(r.verdict, FitVerdict::kOk) << r.verdict_text;
  double sum_z2 = 0.0;
  int count = 0;
  for (const ParameterEstimate& e : r.parameters) {
    double expected = 0.0;
    const int i = e.name.back() == ']' ? e.name[e.name.size() - 2] - '1' : -1;
    if (e.name.rfind("ea_n[", 0) == 0) {
      expected = truth.cables[i].ea_n;
    } else if (e.name.rfind("length_offset_m[", 0) == 0) {
      expected = truth.cables[i].length_offset_m;
    } else {
      continue;
    }
    const double z = (e.estimate - expected) / e.sigma_total;  // N and m: SI already
    EXPECT_LE(std::abs(z), kMaxSigmas) << e.name << " " << e.estimate << " +- " << e.sigma_total;
    sum_z2 += z * z;
    ++count;
  }
  ASSERT_EQ(count, 12);
  EXPECT_LE(sum_z2 / count, kMaxMeanSquare);
  // The calibrated model carries the offsets; the lengths' residuals fall to the noise.
  ASSERT_TRUE(r.lengths.used);
  for (int i = 0; i < kNumCables; ++i) {
    EXPECT_NEAR(r.calibrated.cables[i].length_offset_m, truth.cables[i].length_offset_m, 0.02);
    EXPECT_GT(r.lengths.initial.rms_m[i], 0.1) << i;
    EXPECT_LT(r.lengths.calibrated.rms_m[i], 0.0065) << i;
  }
}

// At one pose every reading repeats: a cable's stretch (EA) and its encoder's zero move
// its length alike, and the tensions there barely feel EA. The refusal names the pairs.
TEST(CalibrationLengthsTest, OnePoseCannotTellEaFromTheEncodersZero) {
  const Dataset data = Telemetry(Truth(), std::vector<Pose>(60, SurveyPoses()[40]), 3);
  CalibrationResult r;
  std::string error;
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), Parse(kLengthsSpec), data, CalibrationOptions(),
                      &r, &error),
            CalibrationStatus::kUndetermined);
  EXPECT_NE(error.find("exact degeneracy"), std::string::npos) << error;
  for (int i = 1; i <= kNumCables; ++i) {
    EXPECT_NE(error.find("length_offset_m[" + std::to_string(i) + "]"), std::string::npos) << error;
    EXPECT_NE(error.find("ea_n[" + std::to_string(i) + "]"), std::string::npos) << error;
  }
  EXPECT_NE(error.find("a length encoder's offset adds the same to every reading"),
            std::string::npos)
      << error;
}

// A slipped encoder: three readings of cable 3's length 0.25 m off. Each is a gross error
// of a length, named by line and cable, and the estimates are those of the clean data.
TEST(CalibrationLengthsTest, ASlippedEncoderIsAGrossErrorOfALength) {
  const CableRobot truth = Truth();
  const Dataset clean = Telemetry(truth, SurveyPoses(), 5);
  Dataset slipped = clean;
  for (int t : {20, 90, 200}) slipped.samples[t].unstretched_length_m[2] += 0.25;
  CalibrationResult a, b;
  std::string error;
  const CalibrationSpec spec = Parse(kLengthsSpec);
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, clean, CalibrationOptions(), &a, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, slipped, CalibrationOptions(), &b, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_EQ(b.gross_errors.size(), a.gross_errors.size() + 3);
  int lengths = 0;
  for (const ReadingResidual& g : b.gross_errors) {
    if (!g.length) continue;
    ++lengths;
    EXPECT_EQ(g.cable, 3);
    EXPECT_NEAR(g.measured_m - g.predicted_m, 0.25, 0.03);
    EXPECT_GT(std::abs(g.residual_sigma), 30.0);
  }
  EXPECT_EQ(lengths, 3);
  EXPECT_EQ(b.gross_error_summary.length_count[2], 3);
  ASSERT_EQ(b.length_excluded.size(), slipped.samples.size());
  EXPECT_TRUE(b.length_excluded[90][2]);
  for (size_t k = 0; k < a.parameters.size(); ++k) {
    EXPECT_NEAR(b.parameters[k].estimate, a.parameters[k].estimate,
                0.2 * a.parameters[k].sigma_total)
        << a.parameters[k].name;
  }
}

// An encoder's offset the spec leaves fixed at 0 while the truth has 2 cm on cable 4: the
// misfit ranking names it first, significant, and its one-step change is the 2 cm.
TEST(CalibrationLengthsTest, MisfitRankingNamesAFixedEncodersOffset) {
  constexpr double kChangeTolM = 0.004;  // the one-step change against the truth's 2 cm
  CableRobot truth = CableRobot::NominalFast();
  truth.cables[3].length_offset_m = 0.02;
  const Dataset data = Telemetry(truth, SurveyPoses(), 7);
  CalibrationResult r;
  std::string error;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(),
                      Parse("noise: {tension_sigma_percent: 3, length_sigma_m: 0.005}\n"
                            "parameters:\n"
                            "  mass_centre_m: {x: {free: true}, y: {free: true}}\n"),
                      data, CalibrationOptions(), &r, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_FALSE(r.misfit_ranking.empty());
  const MisfitCandidate& top = r.misfit_ranking.front();
  EXPECT_EQ(top.name, "length_offset_m[4]");
  EXPECT_TRUE(top.significant);
  EXPECT_NEAR(top.change, 0.02, kChangeTolM);
  // Without the lengths in the fit no offset is a candidate (it moves no reading).
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(),
                      Parse("parameters:\n  mass_centre_m: {x: {free: true}, y: {free: true}}\n"),
                      data, CalibrationOptions(), &r, &error),
            CalibrationStatus::kOk)
      << error;
  for (const MisfitCandidate& c : r.misfit_ranking) {
    EXPECT_EQ(c.name.rfind("length_offset_m", 0), std::string::npos) << c.name;
  }
}

// Cable 2's encoder offset considered (fixed at 0, known to 1 cm): what it adds to each
// EA's sigma_total is, to first order, how far the estimate moves when the offset is
// fixed 1 cm away instead, which two fits measure independently of the budget.
TEST(CalibrationLengthsTest, AConsideredOffsetAddsWhatMovingItMovesTheEstimates) {
  constexpr double kRelTol = 0.05;  // linearisation over 1 cm
  constexpr double kOffsetSigmaM = 0.01;
  CableRobot truth = Truth();
  for (auto& c : truth.cables) c.length_offset_m = 0.0;
  const Dataset data = Telemetry(truth, SurveyPoses(), 9);
  const std::string head =
      "noise: {tension_sigma_percent: 3, length_sigma_m: 0.005}\n"
      "parameters:\n"
      "  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}\n"
      "  ea_n: {mode: per_cable, free: true}\n"
      "  length_offset_m:\n"
      "    mode: per_cable\n";
  CalibrationResult considered, at_zero, moved;
  std::string error;
  const CableRobot nominal = CableRobot::NominalFast();
  ASSERT_EQ(Calibrate(nominal,
                      Parse(head + "    cables: [{}, {prior: {mean: 0, sigma: 0.01}}, {}, {}, {}, "
                                   "{}]\n"),
                      data, CalibrationOptions(), &considered, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_EQ(Calibrate(nominal, Parse(head), data, CalibrationOptions(), &at_zero, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_EQ(Calibrate(nominal, Parse(head + "    cables: [{}, {initial: 0.01}, {}, {}, {}, {}]\n"),
                      data, CalibrationOptions(), &moved, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_EQ(considered.parameters.size(), at_zero.parameters.size());
  int checked = 0;
  for (size_t k = 0; k < considered.parameters.size(); ++k) {
    const ParameterEstimate& e = considered.parameters[k];
    if (e.name.rfind("ea_n[", 0) != 0) continue;
    const double shift = std::abs(moved.parameters[k].estimate - at_zero.parameters[k].estimate) *
                         (kOffsetSigmaM / 0.01);
    EXPECT_NEAR(e.sigma_systematic, shift, kRelTol * shift + 1e-3 * e.sigma) << e.name;
    ++checked;
  }
  EXPECT_EQ(checked, kNumCables);
  // Cable 2's own EA carries most of it.
  EXPECT_GT(considered.parameters[3 + 1].sigma_systematic,
            3.0 * considered.parameters[3].sigma_systematic);
}

// The design counts the lengths as the calibration does: its predicted formal sigma of
// every free parameter (mass centre, EA and offset per cable) at the survey's poses is the
// sigma the calibration with lengths reports on telemetry simulated there.
TEST(CalibrationLengthsTest, DesignPredictsTheSigmasOfACalibrationWithLengths) {
  constexpr double kRelTol = 0.03;  // the fit's weights follow its own predicted readings
  const CableRobot nominal = CableRobot::NominalFast();
  const CalibrationSpec spec = Parse(kLengthsSpec);
  const std::vector<Pose> poses = SurveyPoses();
  DesignPrediction predicted;
  std::string error;
  ASSERT_TRUE(PredictSurvey(nominal, spec, DesignOptions(), poses, &predicted, &error)) << error;
  ASSERT_TRUE(predicted.ok) << predicted.note;
  CalibrationResult r;
  ASSERT_EQ(
      Calibrate(nominal, spec, Telemetry(nominal, poses, 13), CalibrationOptions(), &r, &error),
      CalibrationStatus::kOk)
      << error;
  ASSERT_EQ(predicted.budget.parameters.size(), r.parameters.size());
  for (size_t k = 0; k < r.parameters.size(); ++k) {
    const double sigma = predicted.budget.parameters[k].formal;
    EXPECT_NEAR(r.parameters[k].sigma, sigma, kRelTol * sigma) << r.parameters[k].name;
  }
}

TEST(CalibrationLengthsTest, LengthsNeedTheDatasetsColumns) {
  Dataset data = Telemetry(Truth(), SurveyPoses(), 2);
  data.has_unstretched_lengths = false;
  data.path = "survey.csv";
  CalibrationResult r;
  std::string error;
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), Parse(kLengthsSpec), data, CalibrationOptions(),
                      &r, &error),
            CalibrationStatus::kInvalidInput);
  EXPECT_NE(error.find("survey.csv: the spec fits the lengths (noise.length_sigma_m) but the "
                       "dataset has no s0_1_m ... s0_6_m columns"),
            std::string::npos)
      << error;
}

}  // namespace
}  // namespace fastcal
