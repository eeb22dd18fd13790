// Tests of the calibration (calibration.h) on synthetic data made here with the exact
// statics: recovery without noise, the problem's size, estimates and sigmas under noise
// over several seeds, Jacobian against central differences, refused free sets, and the
// same calibration from the bundled files under a locale whose decimal separator is a comma.
#include "fastcal/calibration.h"

#include <gtest/gtest.h>

#include <array>
#include <clocale>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <locale>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/report.h"
#include "fastcal/simulation.h"
#include "fastcal/trajectory.h"
#include "temp_path.h"

namespace fastcal {
namespace {

const Eigen::Vector3d kTruthMassCentreM(0.22, 0.11, 0.5);
constexpr double kTruthDensityKgPerM = 11.9;

CableRobot Truth() {
  CableRobot t = CableRobot::NominalFast();
  t.mass_centre_cabin_m = kTruthMassCentreM;
  for (CableProperties& c : t.cables) c.linear_density_kg_per_m = kTruthDensityKgPerM;
  return t;
}

// The paper's measured circle (radius 71.11 m about (0, 0, 156.73)) with the focal law,
// plus optional multiplicative Gaussian tension noise.
Dataset CircleData(const CableRobot& truth, int nodes, double noise_fraction, uint64_t seed) {
  Dataset d;
  d.path = "synthetic";
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  StaticsOptions exact;
  exact.method = StaticsMethod::kExact;
  for (int n = 0; n < nodes; ++n) {
    const double a = 2 * M_PI * n / nodes;
    Sample s;
    s.line = n + 2;
    s.time_s = n;
    s.pose.position_m = Eigen::Vector3d(71.11 * std::cos(a), 71.11 * std::sin(a), 156.73);
    s.pose.rotation = FocalAttitude(s.pose.position_m, FocalAttitudeLaw());
    StaticsSolution sol;
    EXPECT_EQ(SolveStatics(truth, s.pose, exact, &sol), StaticsStatus::kOk);
    for (int i = 0; i < kNumCables; ++i) {
      s.tension_n[i] = sol.cables[i].lower_tension_n * (1.0 + noise_fraction * normal(rng));
    }
    d.samples.push_back(s);
  }
  return d;
}

ParameterSpec Free(ParameterKind kind, int index, int component, const std::string& name) {
  ParameterSpec p;
  p.kind = kind;
  p.index = index;
  p.component = component;
  p.name = name;
  p.unit = "1";
  p.free = true;
  return p;
}

CalibrationSpec MassCentreAndDensitySpec(StaticsMethod forward) {
  CalibrationSpec spec;
  spec.forward_model = forward;
  for (int c = 0; c < 3; ++c) {
    spec.parameters.push_back(
        Free(ParameterKind::kMassCentre, -1, c, std::string("mass_centre_m.") + "xyz"[c]));
  }
  spec.parameters.push_back(Free(ParameterKind::kLinearDensity, -1, -1, "linear_density_kg_per_m"));
  spec.tension_sigma_percent = 3.0;
  spec.num_threads = 2;
  return spec;
}

// Calibrate from the nominal model with default options; the error message on failure.
::testing::AssertionResult CalibrateNominal(const CalibrationSpec& spec, const Dataset& data,
                                            CalibrationResult* result) {
  std::string error;
  if (Calibrate(CableRobot::NominalFast(), spec, data, CalibrationOptions(), result, &error) ==
      CalibrationStatus::kOk) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << error;
}

TEST(CalibrationTest, NoiseFreeDataRecoversTruth) {
  constexpr double kRelTol = 1e-6;
  constexpr int kNodes = 36;
  const Dataset data = CircleData(Truth(), kNodes, 0.0, 1);
  const CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  CalibrationResult result;
  ASSERT_TRUE(CalibrateNominal(spec, data, &result));
  // The problem's size is what the spec implies.
  EXPECT_EQ(result.num_free, 4);
  EXPECT_EQ(result.num_residuals, kNumCables * kNodes);
  EXPECT_EQ(result.num_fit_samples, kNodes);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(result.calibrated.mass_centre_cabin_m[c], kTruthMassCentreM[c],
                kRelTol * kTruthMassCentreM.norm())
        << "axis " << c;
  }
  for (const CableProperties& c : result.calibrated.cables) {
    EXPECT_NEAR(c.linear_density_kg_per_m, kTruthDensityKgPerM, kRelTol * kTruthDensityKgPerM);
  }
  EXPECT_LT(result.final_cost, 1e-10);
  EXPECT_GT(result.initial_cost, 1.0);  // the nominal model does not fit
  EXPECT_TRUE(result.before.undetermined.empty());
}

// Ctrl-C from Python (issue 37): CalibrationOptions::should_stop is asked before each
// stage and after each solver iteration; true stops the calibration with kCancelled,
// and it is not asked again. One that never says stop changes nothing.
TEST(CalibrationTest, ShouldStopCancelsBetweenStagesAndIterations) {
  const Dataset data = CircleData(Truth(), 36, 0.0, 1);
  const CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  CalibrationResult plain;
  ASSERT_TRUE(CalibrateNominal(spec, data, &plain));
  // 0: before the first stage; 3: before the fourth; 6: inside the solve (five stages
  // are asked before it, then Ceres after its iteration 0).
  for (int allowed : {0, 3, 6}) {
    int asked = 0;
    CalibrationOptions options;
    options.should_stop = [&] { return ++asked > allowed; };
    CalibrationResult result;
    std::string error;
    EXPECT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &result, &error),
              CalibrationStatus::kCancelled)
        << "after " << allowed << " asks";
    EXPECT_NE(error.find("stopped on request"), std::string::npos) << error;
    EXPECT_EQ(asked, allowed + 1);
  }
  CalibrationOptions never;
  never.should_stop = [] { return false; };
  CalibrationResult result;
  std::string error;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, never, &result, &error),
            CalibrationStatus::kOk)
      << error;
  EXPECT_EQ(result.final_cost, plain.final_cost);
  EXPECT_EQ(result.calibrated.mass_centre_cabin_m, plain.calibrated.mass_centre_cabin_m);
}

// A fit through AAS converges like one through exact: Calibrate solves with
// ModelFitStaticsOptions. With AAS's loose control-loop tolerances (the default
// StaticsOptions) Ceres took 17 iterations instead of 6 on 1e4 samples.
TEST(CalibrationTest, AasForwardModelConvergesLikeExact) {
  constexpr int kExtraIterations = 2;
  constexpr double kNoiseFraction = 0.03;  // as the spec's sigma
  const Dataset data = CircleData(Truth(), 200, kNoiseFraction, 7);
  int iterations[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const CalibrationSpec spec =
        MassCentreAndDensitySpec(k == 0 ? StaticsMethod::kAas : StaticsMethod::kExact);
    CalibrationResult result;
    ASSERT_TRUE(CalibrateNominal(spec, data, &result));
    EXPECT_TRUE(result.converged) << result.termination;
    iterations[k] = result.iterations;
  }
  EXPECT_LE(iterations[0], iterations[1] + kExtraIterations)
      << "aas " << iterations[0] << ", exact " << iterations[1];
}

TEST(CalibrationTest, CostAtTruthIsZeroAndJacobianMatchesNumeric) {
  constexpr double kCostTol = 1e-18;
  constexpr double kJacobianRelTol = 1e-5;
  const Dataset data = CircleData(Truth(), 12, 0.0, 1);
  const CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  const internal::CalibrationModel model(CableRobot::NominalFast(), spec);
  const double truth[4] = {kTruthMassCentreM[0], kTruthMassCentreM[1], kTruthMassCentreM[2],
                           kTruthDensityKgPerM};
  for (StaticsMethod forward :
       {StaticsMethod::kAas, StaticsMethod::kAasRefined, StaticsMethod::kExact}) {
    for (const Sample& s : data.samples) {
      internal::TensionResidual f{
          &model, s.pose, s.tension_n, internal::TensionSigmas(s.tension_n, 0.0, 3.0), {}, {}};
      f.statics = ModelFitStaticsOptions(forward);  // as Calibrate
      internal::TensionCost cost(f);
      double r[kNumCables], jac[kNumCables * 4];
      const double* params[1] = {truth};
      double* jacs[1] = {jac};
      ASSERT_TRUE(cost.Evaluate(params, r, jacs));
      if (forward == StaticsMethod::kExact) {
        for (double v : r) EXPECT_LT(v * v, kCostTol);
      }
      for (int k = 0; k < 4; ++k) {
        const double h = 1e-6 * std::max(std::abs(truth[k]), 0.1);
        double up[4], dn[4], ru[kNumCables], rd[kNumCables];
        std::copy(truth, truth + 4, up);
        std::copy(truth, truth + 4, dn);
        up[k] += h;
        dn[k] -= h;
        const double* pu[1] = {up};
        const double* pd[1] = {dn};
        ASSERT_TRUE(cost.Evaluate(pu, ru, nullptr));
        ASSERT_TRUE(cost.Evaluate(pd, rd, nullptr));
        for (int i = 0; i < kNumCables; ++i) {
          const double numeric = (ru[i] - rd[i]) / (2 * h);
          EXPECT_NEAR(jac[i * 4 + k], numeric, kJacobianRelTol * (std::abs(numeric) + 1e-3))
              << StaticsMethodName(forward) << " param " << k << " cable " << i + 1;
        }
      }
    }
  }
}

TEST(CalibrationTest, NoisyEstimatesWithinThreeSigmaAndSigmasMatchSpread) {
  // 3% noise on 72 poses of the circle, 12 seeds: every estimate within 3 sigma of the
  // truth; the reported sigma within a factor 2 of the scatter over the seeds (12 seeds
  // estimate a standard deviation to ~20%); the mean over the seeds unbiased; and sharp:
  // the mean of ((estimate - truth) / sigma)^2 over the 48 estimates near 1, for the
  // formal sigma and sigma_total alike (white noise, a correct model: nothing to widen).
  // Its standard deviation is ~sqrt(2 / 48) = 0.2, and a sigma 1.5x too large gives 0.44.
  constexpr int kSeeds = 12;
  constexpr int kNodes = 72;
  constexpr double kMaxPull = 3.0;
  constexpr double kSpreadRatioLow = 0.5, kSpreadRatioHigh = 2.0;
  constexpr double kMinMeanZ2 = 0.6, kMaxMeanZ2 = 1.6;
  const CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kAasRefined);
  const double truth[4] = {kTruthMassCentreM[0], kTruthMassCentreM[1], kTruthMassCentreM[2],
                           kTruthDensityKgPerM};
  std::vector<std::array<double, 4>> estimates;
  std::array<double, 4> sigma_sum{};
  double z2_formal = 0.0, z2_total = 0.0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const Dataset data = CircleData(Truth(), kNodes, 0.03, 1000 + seed);
    CalibrationResult result;
    ASSERT_TRUE(CalibrateNominal(spec, data, &result));
    ASSERT_TRUE(result.covariance_ok);
    std::array<double, 4> e;
    for (int k = 0; k < 4; ++k) {
      e[k] = result.parameters[k].estimate;
      const double sigma = result.parameters[k].sigma;
      ASSERT_GT(sigma, 0.0);
      EXPECT_LT(std::abs(e[k] - truth[k]) / sigma, kMaxPull)
          << result.parameters[k].name << " seed " << seed;
      sigma_sum[k] += sigma;
      z2_formal += std::pow((e[k] - truth[k]) / sigma, 2) / (4 * kSeeds);
      z2_total += std::pow((e[k] - truth[k]) / result.parameters[k].sigma_total, 2) / (4 * kSeeds);
    }
    estimates.push_back(e);
  }
  EXPECT_GT(z2_formal, kMinMeanZ2);
  EXPECT_LT(z2_formal, kMaxMeanZ2);
  EXPECT_GT(z2_total, kMinMeanZ2);
  EXPECT_LT(z2_total, kMaxMeanZ2);
  for (int k = 0; k < 4; ++k) {
    double mean = 0, var = 0;
    for (const auto& e : estimates) mean += e[k] / kSeeds;
    for (const auto& e : estimates) var += (e[k] - mean) * (e[k] - mean) / (kSeeds - 1);
    const double ratio = std::sqrt(var) / (sigma_sum[k] / kSeeds);
    EXPECT_GT(ratio, kSpreadRatioLow) << "parameter " << k;
    EXPECT_LT(ratio, kSpreadRatioHigh) << "parameter " << k;
    // Unbiased: the mean over the seeds within 3 of its own standard errors of the truth.
    // Weights from the measured readings failed this for the density (-0.8%, ~5 standard
    // errors): a low reading weighed more.
    EXPECT_LT(std::abs(mean - truth[k]), kMaxPull * (sigma_sum[k] / kSeeds) / std::sqrt(kSeeds))
        << "parameter " << k << " mean " << mean << " truth " << truth[k];
  }
}

TEST(CalibrationTest, CabinMassAndCommonGainDegeneracyIsReported) {
  // Scaling cabin mass, cable weight and EA together and dividing a common sensor gain leaves
  // every reading unchanged: exactly degenerate, refused. Cabin mass and gain alone are
  // not exactly degenerate (the cables' own weight and stiffness do not scale with the cabin mass)
  // but nearly so: accepted, with the pair reported as strongly correlated.
  constexpr double kNearlyDegenerateCorrelation = 0.99;
  const Dataset data = CircleData(Truth(), 36, 0.0, 1);
  CalibrationSpec spec;
  spec.parameters.push_back(Free(ParameterKind::kCabinMass, -1, -1, "cabin_mass_kg"));
  spec.parameters.push_back(Free(ParameterKind::kLinearDensity, -1, -1, "linear_density_kg_per_m"));
  spec.parameters.push_back(Free(ParameterKind::kEa, -1, -1, "ea_n"));
  spec.parameters.push_back(Free(ParameterKind::kSensorGain, -1, -1, "sensor_gain"));
  CalibrationResult result;
  std::string error;
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, CalibrationOptions(), &result, &error),
            CalibrationStatus::kUndetermined);
  for (const char* name : {"cabin_mass_kg", "sensor_gain", "linear_density_kg_per_m"}) {
    EXPECT_NE(error.find(name), std::string::npos) << error;
  }
  ASSERT_EQ(result.before.undetermined.size(), 1u);
  EXPECT_LT(result.before.undetermined[0].singular_value_ratio, 1e-10);
  // A prior on the gain holds the combination: accepted, and the data-only analysis
  // still reports that the data alone cannot tell them apart.
  spec.parameters[3].has_prior = true;
  spec.parameters[3].prior_mean_si = 1.0;
  spec.parameters[3].prior_sigma_si = 1e-4;
  spec.parameters.erase(spec.parameters.begin() + 2);  // EA fixed: near, not exact
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, CalibrationOptions(), &result, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_FALSE(result.data_only.undetermined.empty() && result.data_only.poorly_determined.empty());
  const ParameterDirection& weak = result.data_only.undetermined.empty()
                                       ? result.data_only.poorly_determined[0]
                                       : result.data_only.undetermined[0];
  EXPECT_NE(weak.Describe().find("sensor_gain"), std::string::npos) << weak.Describe();
  // Mass and gain alone.
  spec.parameters.erase(spec.parameters.begin() + 1);
  spec.parameters[1].has_prior = false;
  ASSERT_EQ(spec.parameters[1].kind, ParameterKind::kSensorGain);
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, CalibrationOptions(), &result, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_TRUE(result.covariance_ok);
  EXPECT_GT(std::abs(result.correlation(0, 1)), kNearlyDegenerateCorrelation);
  ASSERT_FALSE(result.strong_correlations.empty());
  EXPECT_NE(result.strong_correlations[0].find("cabin_mass_kg ~ sensor_gain"), std::string::npos);
}

TEST(CalibrationTest, FreeSetWithoutEnoughDataIsRefused) {
  // Tower offsets from a single circle without priors (model.md: not determined).
  const Dataset data = CircleData(Truth(), 36, 0.0, 1);
  CalibrationSpec spec;
  for (int t = 0; t < kNumCables; ++t) {
    for (int c = 0; c < 3; ++c) {
      spec.parameters.push_back(Free(ParameterKind::kTowerOffset, t, c,
                                     "tower_offset_m[" + std::to_string(t + 1) + "]." + "xyz"[c]));
    }
  }
  CalibrationResult result;
  std::string error;
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, CalibrationOptions(), &result, &error),
            CalibrationStatus::kUndetermined)
      << error;
  EXPECT_NE(error.find("tower_offset_m"), std::string::npos);
  // Fewer residuals than free parameters.
  const Dataset two = CircleData(Truth(), 2, 0.0, 1);
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), spec, two, CalibrationOptions(), &result, &error),
            CalibrationStatus::kInvalidInput);
  EXPECT_NE(error.find("free parameters"), std::string::npos);
}

TEST(CalibrationTest, HoldoutMaskIsSeededAndSized) {
  const std::vector<bool> a = HoldoutMask(100, 0.2, 7), b = HoldoutMask(100, 0.2, 7),
                          c = HoldoutMask(100, 0.2, 8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  EXPECT_EQ(std::count(a.begin(), a.end(), true), 20);
  const std::vector<bool> none = HoldoutMask(10, 0.0, 1);
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);
  // A small fraction still holds out one block; never every block.
  const std::vector<bool> one = HoldoutMask(100, 0.01, 1);
  EXPECT_EQ(std::count(one.begin(), one.end(), true), 10);
  const std::vector<bool> most = HoldoutMask(100, 0.99, 1);
  EXPECT_EQ(std::count(most.begin(), most.end(), true), 90);
}

// A random single sample of a slow trajectory is predicted by its neighbours: the
// hold-out keeps whole contiguous blocks out, each of the size BlockOfSample gives.
TEST(CalibrationTest, HoldoutKeepsWholeContiguousBlocksOut) {
  constexpr int kSamples = 103, kBlocks = 10;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const std::vector<bool> mask = HoldoutMask(kSamples, 0.3, seed, kBlocks);
    std::vector<int> held_in_block(kBlocks, 0), size_of_block(kBlocks, 0);
    for (int t = 0; t < kSamples; ++t) {
      const int b = BlockOfSample(t, kSamples, kBlocks);
      ASSERT_GE(b, 0);
      ASSERT_LT(b, kBlocks);
      if (t > 0) {
        ASSERT_GE(b, BlockOfSample(t - 1, kSamples, kBlocks));  // contiguous
      }
      ++size_of_block[b];
      held_in_block[b] += mask[t];
    }
    int blocks_held = 0;
    for (int b = 0; b < kBlocks; ++b) {
      EXPECT_TRUE(held_in_block[b] == 0 || held_in_block[b] == size_of_block[b]) << "block " << b;
      EXPECT_GE(size_of_block[b], kSamples / kBlocks);
      EXPECT_LE(size_of_block[b], kSamples / kBlocks + 1);
      blocks_held += held_in_block[b] > 0;
    }
    EXPECT_EQ(blocks_held, 3) << "seed " << seed;
  }
}

CalibrationSpec MassCentreSpec() {
  CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  spec.parameters.pop_back();  // density fixed
  return spec;
}

// The worst fitted readings are the largest |model - measured| / sigma at the solution,
// largest first: recomputed here from the calibrated row of the RMS table (the fit's last
// prediction) and the spec's noise model over every fitted reading.
TEST(CalibrationTest, WorstReadingsAreTheLargestResiduals) {
  constexpr double kRelTol = 1e-12;
  const Dataset data = CircleData(Truth(), 400, 0.03, 41);
  const CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  CalibrationResult result;
  ASSERT_TRUE(CalibrateNominal(spec, data, &result));
  const VariantEvaluation& calibrated = result.variants.back();
  ASSERT_EQ(calibrated.predicted_n.size(), data.samples.size());
  std::vector<double> sizes;
  for (size_t t = 0; t < data.samples.size(); ++t) {
    const std::array<double, kNumCables> sigma = internal::TensionSigmas(
        calibrated.predicted_n[t], spec.tension_sigma_n, spec.tension_sigma_percent);
    for (int i = 0; i < kNumCables; ++i) {
      sizes.push_back(std::abs(calibrated.predicted_n[t][i] - data.samples[t].tension_n[i]) /
                      sigma[i]);
    }
  }
  std::sort(sizes.rbegin(), sizes.rend());
  const size_t kept = static_cast<size_t>(CalibrationOptions().worst_readings);
  ASSERT_EQ(result.worst_readings.size(), kept);
  for (size_t k = 0; k < kept; ++k) {
    EXPECT_NEAR(std::abs(result.worst_readings[k].residual_sigma), sizes[k], kRelTol * sizes[k])
        << "rank " << k;
  }
}

// The RMS table's initial-model rows are the input model's own evaluation, whether the
// fit's first prediction stands in for one (exact statics, no spec value in place of the
// model's: issue 41) or not (an initial value in the spec: the fit starts elsewhere), at
// the measured and at the planned attitude (0.3 deg apart), fitting either, with held-out
// samples and a reading kept out as a gross error.
TEST(CalibrationTest, InitialModelRowIsTheInputModelsEvaluation) {
  constexpr double kRelTol = 1e-9;  // warm and cold statics, to the solver's tolerance
  Dataset data = CircleData(Truth(), 240, 0.03, 43);
  data.samples[17].tension_n[2] *= 3.0;  // a gross error, left out of every row
  data.has_planned_attitude = true;
  const Eigen::Matrix3d off = RotationFromRpyDeg(0.3, -0.2, 0.1);
  for (Sample& s : data.samples) {
    s.has_planned_attitude = true;
    s.planned_rotation = s.pose.rotation * off;
  }
  for (bool initial_value : {false, true}) {
    for (bool planned : {false, true}) {
      CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
      spec.holdout_fraction = 0.25;
      spec.use_planned_attitude = planned;
      if (initial_value) {
        spec.parameters[2].has_initial = true;
        spec.parameters[2].initial_si = 0.3;  // mass_centre_m.z: not the nominal model's
      }
      CalibrationResult result;
      ASSERT_TRUE(CalibrateNominal(spec, data, &result));
      ASSERT_TRUE(result.excluded[17][2]);
      ASSERT_EQ(result.variants.size(), 3u);
      for (AttitudeSource attitude : {AttitudeSource::kPlanned, AttitudeSource::kMeasured}) {
        const bool is_planned = attitude == AttitudeSource::kPlanned;
        const VariantEvaluation& initial = result.variants[is_planned ? 0 : 1];
        ASSERT_EQ(initial.name, std::string("initial model, ") +
                                    (is_planned ? "planned" : "measured") + " attitude");
        VariantEvaluation plain;
        std::string error;
        ASSERT_TRUE(EvaluateVariant("plain", CableRobot::NominalFast(), data, attitude,
                                    StaticsMethod::kExact, result.held_out, &plain, &error,
                                    result.excluded))
            << error;
        for (int i = 0; i < kNumCables; ++i) {
          EXPECT_NEAR(initial.fit.rms_n[i], plain.fit.rms_n[i], kRelTol * plain.fit.rms_n[i])
              << initial.name << ", initial value " << initial_value << ", fit planned " << planned
              << ", cable " << i;
          EXPECT_NEAR(initial.holdout.rms_n[i], plain.holdout.rms_n[i],
                      kRelTol * plain.holdout.rms_n[i])
              << initial.name << ", initial value " << initial_value << ", cable " << i;
          EXPECT_EQ(initial.fit.excluded[i], plain.fit.excluded[i]);
        }
      }
    }
  }
}

// Gross errors: readings several times off, a dropout near zero and one 150 kN too high
// are named by line and cable and kept out of the fit, which then agrees with the fit of
// the clean data within its sigma.
TEST(CalibrationTest, GrossErrorsAreNamedAndDoNotMoveTheEstimates) {
  constexpr int kNodes = 120;
  const Dataset clean = CircleData(Truth(), kNodes, 0.03, 21);
  Dataset dirty = clean;
  struct Injected {
    int sample, cable;  // cable 0-based
    double tension_n;
  };
  const Injected injected[] = {{8, 2, 3.0 * clean.samples[8].tension_n[2]},
                               {40, 0, 500.0},  // a dropout: 0.5 kN
                               {77, 5, clean.samples[77].tension_n[5] + 150e3},
                               {101, 3, 3.0 * clean.samples[101].tension_n[3]}};
  for (const Injected& g : injected) dirty.samples[g.sample].tension_n[g.cable] = g.tension_n;
  const CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  CalibrationResult fit_clean, fit_dirty;
  ASSERT_TRUE(CalibrateNominal(spec, clean, &fit_clean));
  ASSERT_TRUE(CalibrateNominal(spec, dirty, &fit_dirty));
  EXPECT_TRUE(fit_clean.gross_errors.empty());
  ASSERT_EQ(fit_dirty.gross_errors.size(), std::size(injected));
  for (size_t k = 0; k < std::size(injected); ++k) {
    const ReadingResidual& g = fit_dirty.gross_errors[k];
    EXPECT_EQ(g.line, dirty.samples[injected[k].sample].line);
    EXPECT_EQ(g.cable, injected[k].cable + 1);
    EXPECT_EQ(g.measured_n, injected[k].tension_n);
    EXPECT_GT(std::abs(g.residual_sigma), spec.gross_error_threshold_sigmas);
    EXPECT_TRUE(fit_dirty.excluded[injected[k].sample][injected[k].cable]);
  }
  EXPECT_EQ(fit_dirty.num_residuals, fit_clean.num_residuals - 4);
  for (size_t k = 0; k < fit_clean.parameters.size(); ++k) {
    const ParameterEstimate& a = fit_clean.parameters[k];
    const ParameterEstimate& b = fit_dirty.parameters[k];
    EXPECT_LT(std::abs(a.estimate - b.estimate), a.sigma_total) << a.name;
  }
  // Turned off, the same errors steer the fit far away.
  CalibrationSpec off = spec;
  off.detect_gross_errors = false;
  CalibrationResult fit_off;
  ASSERT_TRUE(CalibrateNominal(off, dirty, &fit_off));
  EXPECT_TRUE(fit_off.gross_errors.empty());
  EXPECT_GT(std::abs(fit_off.parameters[2].estimate - fit_clean.parameters[2].estimate),
            3.0 * fit_clean.parameters[2].sigma_total);
}

// Dropouts of exactly 0 kN reach the calibration through the file reader (which used to
// refuse the whole file for them) and, with a glitch of 4 times the normal tension, are
// flagged by the robust screen; the fit stays ok and near the truth, and no statistic
// divides by a 0 kN reading.
TEST(CalibrationTest, ZeroReadingsFromAFileAreGrossErrorsAndNothingIsInfinite) {
  constexpr int kNodes = 120;
  // Estimates within this many sigma_total of the truth (3: a seeded draw, not a search
  // for a lucky one).
  constexpr double kCoverageSigmas = 3.0;
  Dataset simulated = CircleData(Truth(), kNodes, 0.03, 41);
  const std::array<std::pair<int, int>, 3> dropouts = {{{15, 1}, {16, 1}, {70, 4}}};
  for (const auto& [sample, cable] : dropouts) simulated.samples[sample].tension_n[cable] = 0.0;
  const int glitch_sample = 93, glitch_cable = 0;
  simulated.samples[glitch_sample].tension_n[glitch_cable] *= 4.0;
  const std::string path = test::TempPath("calibration_test_dropouts", ".csv");
  std::string error;
  ASSERT_TRUE(WriteDataset(path, simulated, "", &error)) << error;
  Dataset data;
  ASSERT_TRUE(ReadDataset(path, DatasetReadOptions(), &data, &error)) << error;
  std::remove(path.c_str());
  ASSERT_EQ(data.samples.size(), simulated.samples.size());

  const CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  CalibrationResult result;
  ASSERT_TRUE(CalibrateNominal(spec, data, &result));
  EXPECT_EQ(result.verdict, FitVerdict::kOk) << result.verdict_text;
  ASSERT_EQ(result.gross_errors.size(), dropouts.size() + 1);
  for (const auto& [sample, cable] : dropouts) {
    EXPECT_TRUE(result.excluded[sample][cable]) << "sample " << sample << " cable " << cable;
  }
  EXPECT_TRUE(result.excluded[glitch_sample][glitch_cable]);
  const double truth[] = {kTruthMassCentreM.x(), kTruthMassCentreM.y(), kTruthMassCentreM.z(),
                          kTruthDensityKgPerM};
  ASSERT_EQ(result.parameters.size(), std::size(truth));
  for (size_t k = 0; k < std::size(truth); ++k) {
    const ParameterEstimate& p = result.parameters[k];
    EXPECT_LT(std::abs(p.estimate - truth[k]), kCoverageSigmas * p.sigma_total) << p.name;
  }
  // Every statistic finite: the calibration's variants, and a plain evaluation (no
  // exclusions) of the dropouts, whose percents are of the model's reading.
  std::vector<VariantEvaluation> evaluated;
  ASSERT_TRUE(EvaluateModel(Truth(), data, StaticsMethod::kExact, &evaluated, &error)) << error;
  for (const std::vector<VariantEvaluation>* set : {&result.variants, &evaluated}) {
    for (const VariantEvaluation& v : *set) {
      for (int i = 0; i < kNumCables; ++i) {
        for (double x : {v.fit.rms_n[i], v.fit.mean_n[i], v.fit.max_abs_n[i], v.fit.rms_percent[i],
                         v.fit.max_abs_percent[i]}) {
          EXPECT_TRUE(std::isfinite(x)) << v.name << " cable " << i + 1;
        }
      }
    }
  }
  // A 0 kN reading is 100% below the model's reading.
  EXPECT_NEAR(evaluated.back().fit.max_abs_percent[1], 100.0, 1e-9);
}

TEST(CalibrationTest, DataThatAreMostlyGrossErrorsAreRefused) {
  constexpr int kNodes = 60;
  constexpr double kGrossFraction = 0.6;
  Dataset data = CircleData(Truth(), kNodes, 0.03, 23);
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> uniform;
  for (Sample& s : data.samples) {
    for (double& t : s.tension_n) {
      if (uniform(rng) < kGrossFraction) t *= 3.0;
    }
  }
  CalibrationResult result;
  std::string error;
  EXPECT_EQ(Calibrate(CableRobot::NominalFast(), MassCentreSpec(), data, CalibrationOptions(),
                      &result, &error),
            CalibrationStatus::kMostlyGrossErrors);
  EXPECT_NE(error.find("the data are mostly not what the model predicts"), std::string::npos)
      << error;
  EXPECT_NE(error.find("synthetic:"), std::string::npos) << error;  // names a line
}

// A fixed parameter with a prior is a consider parameter: its prior sigma enters the
// estimates' budget as the first-order change of the estimates when it moves by that
// sigma (checked by refitting with it moved), and the group is named.
TEST(CalibrationTest, ConsiderBudgetMatchesTheRefitWithTheParameterMoved) {
  constexpr double kGainSigma = 0.002;
  constexpr double kRelTol = 0.05;  // first order at a 0.2% gain step
  const Dataset data = CircleData(Truth(), 72, 0.03, 25);
  CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  ParameterSpec gain;
  gain.kind = ParameterKind::kSensorGain;
  gain.index = 2;
  gain.name = "sensor_gain[3]";
  gain.unit = "1";
  gain.has_prior = true;
  gain.prior_mean_si = 1.0;
  gain.prior_sigma_si = kGainSigma;
  spec.parameters.push_back(gain);
  CalibrationResult base, moved;
  ASSERT_TRUE(CalibrateNominal(spec, data, &base));
  ASSERT_EQ(base.budget.consider_groups, std::vector<std::string>{"sensor_gain"});
  EXPECT_TRUE(base.parameters.back().consider);
  EXPECT_EQ(base.parameters.back().sigma_total, kGainSigma);
  spec.parameters.back().has_initial = true;
  spec.parameters.back().initial_si = 1.0 + kGainSigma;
  ASSERT_TRUE(CalibrateNominal(spec, data, &moved));
  for (int k = 0; k < 4; ++k) {
    const ParameterEstimate& p = base.parameters[k];
    const double shift = std::abs(moved.parameters[k].estimate - p.estimate);
    ASSERT_EQ(p.systematic_by_group.size(), 1u);
    EXPECT_NEAR(p.systematic_by_group[0], shift, kRelTol * shift) << p.name;
    EXPECT_NEAR(p.sigma_systematic, shift, kRelTol * shift) << p.name;
    EXPECT_NEAR(p.sigma_total, std::hypot(p.sigma_statistical, p.sigma_systematic), 1e-12);
  }
}

// Data from sensors whose gain on cable 3 is 3% high, fitted without gains: the score
// test names sensor_gain[3] first, and freeing it lowers the chi-square by about the
// predicted amount.
TEST(CalibrationTest, MisfitRankingNamesTheMissingParameterAndPredictsItsDecrease) {
  constexpr double kDecreaseRelTol = 0.1;
  CableRobot truth = Truth();
  truth.cables[2].sensor_gain = 1.03;
  Dataset data = CircleData(truth, 180, 0.0, 27);  // noise-free readings of the truth tensions
  std::mt19937_64 rng(29);
  std::normal_distribution<double> normal;
  for (Sample& s : data.samples) {
    s.tension_n[2] *= 1.03;
    for (double& t : s.tension_n) t *= 1.0 + 0.01 * normal(rng);
  }
  CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  spec.tension_sigma_percent = 1.0;
  CalibrationResult without, with;
  ASSERT_TRUE(CalibrateNominal(spec, data, &without));
  ASSERT_FALSE(without.misfit_ranking.empty());
  const MisfitCandidate& top = without.misfit_ranking.front();
  EXPECT_EQ(top.name, "sensor_gain[3]");
  EXPECT_TRUE(top.significant);
  ParameterSpec gain = Free(ParameterKind::kSensorGain, 2, -1, "sensor_gain[3]");
  spec.parameters.push_back(gain);
  ASSERT_TRUE(CalibrateNominal(spec, data, &with));
  const double chi2_without = without.reduced_chi_square * (without.num_residuals - 4);
  const double chi2_with = with.reduced_chi_square * (with.num_residuals - 5);
  EXPECT_NEAR(chi2_without - chi2_with, top.expected_decrease,
              kDecreaseRelTol * top.expected_decrease);
  EXPECT_NEAR(with.parameters.back().estimate, 1.03, 3 * with.parameters.back().sigma_total);
  // What freeing it does, predicted without refitting: the gain's own change and the
  // shift of each estimate.
  EXPECT_NEAR(top.change, with.parameters.back().estimate - 1.0, 0.1 * std::abs(top.change));
  ASSERT_EQ(top.shifts.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    const double moved = with.parameters[k].estimate - without.parameters[k].estimate;
    EXPECT_NEAR(top.shifts[k], moved, 0.1 * std::abs(moved) + 0.1 * without.parameters[k].sigma)
        << without.parameters[k].name;
  }
}

// A prior the data disagree with beyond their noise is a candidate too ("prior of ..."):
// a sensor reading 5% high held at 1 +- 0.5% by its prior is a model incomplete, and the
// gain is marked; with the prior widened to its real tolerance the verdict is ok.
TEST(CalibrationTest, ADoubtedPriorIsAModelIncomplete) {
  Dataset data = CircleData(Truth(), 180, 0.02, 41);
  for (Sample& s : data.samples) s.tension_n[2] *= 1.05;  // cable 3's sensor reads 5% high
  CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  spec.tension_sigma_percent = 2.0;
  ParameterSpec gain = Free(ParameterKind::kSensorGain, 2, -1, "sensor_gain[3]");
  gain.has_prior = true;
  gain.prior_mean_si = 1.0;
  gain.prior_sigma_si = 0.005;
  spec.parameters.push_back(gain);
  CalibrationResult tight, wide;
  ASSERT_TRUE(CalibrateNominal(spec, data, &tight));
  EXPECT_EQ(tight.verdict, FitVerdict::kModelIncomplete) << tight.verdict_text;
  EXPECT_EQ(tight.verdict_text.rfind("releasing the prior of sensor_gain[3]", 0), 0u)
      << tight.verdict_text;
  EXPECT_EQ(tight.parameters.back().moved_by, "prior of sensor_gain[3]");
  spec.parameters.back().prior_sigma_si = 0.1;
  ASSERT_TRUE(CalibrateNominal(spec, data, &wide));
  EXPECT_NE(wide.verdict, FitVerdict::kModelIncomplete) << wide.verdict_text;
  EXPECT_NEAR(wide.parameters.back().estimate, 1.05, 3 * wide.parameters.back().sigma_total);
}

// The realistic telemetry of simulation.h (slow tension error, drifting mass centre,
// smooth attitude control error, per-cable densities, gains and biases) fitted with a
// spec that frees the per-cable parameters with priors: over 20 seeds, sigma_total
// covers the mass centre (its average over the data, which is what the data determine)
// about as often as a standard deviation should, and is not inflated; the formal sigma
// covers it far less often.
TEST(CalibrationTest, SigmaTotalCoversTheTruthOnRealisticData) {
  constexpr int kSeeds = 20;
  constexpr double kMinCoverage = 0.9, kMaxFormalCoverage = 0.7;
  // The ranking's family-wise error is 1% for white residuals; on these it is ~10%.
  constexpr int kMaxFalseAlarms = 3;
  // The "model incomplete" verdict needs a significant candidate that also moves an
  // estimate by more than 3 sigma_total: on data the model describes, rarer still.
  constexpr int kMaxIncompleteVerdicts = 1;
  constexpr double kMinMeanZ2 = 0.6, kMaxMeanZ2 = 1.6;
  FocalGridSpec grid;
  grid.azimuth_step_deg = 2.0;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  std::string error;
  ASSERT_TRUE(FocalSpherePositions(grid, &positions, &error)) << error;
  ASSERT_TRUE(PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, &error)) << error;
  CalibrationSpec spec;
  spec.forward_model = StaticsMethod::kExact;
  for (int c = 0; c < 3; ++c) {
    spec.parameters.push_back(
        Free(ParameterKind::kMassCentre, -1, c, std::string("mass_centre_m.") + "xyz"[c]));
  }
  const struct {
    ParameterKind kind;
    const char* name;
    double mean, sigma;
  } per_cable[] = {{ParameterKind::kLinearDensity, "linear_density_kg_per_m", 11.718, 0.18},
                   {ParameterKind::kSensorGain, "sensor_gain", 1.0, 0.01},
                   {ParameterKind::kSensorBias, "sensor_bias_kN", 0.0, 2e3}};
  for (const auto& g : per_cable) {
    for (int i = 0; i < kNumCables; ++i) {
      ParameterSpec p =
          Free(g.kind, i, -1, std::string(g.name) + "[" + std::to_string(i + 1) + "]");
      p.has_prior = true;
      p.prior_mean_si = g.mean;
      p.prior_sigma_si = g.sigma;
      spec.parameters.push_back(p);
    }
  }
  // The same spec with the slow sensor error estimated (the recommended specs' noise):
  // the single-survey coverage must not suffer, and the estimate must find the drift.
  CalibrationSpec slow_spec = spec;
  slow_spec.slow_error.enabled = true;
  slow_spec.slow_error.estimate_amplitude = slow_spec.slow_error.estimate_time_constant = true;
  int slow_covered = 0, slow_process_covered = 0;
  double slow_z2 = 0.0;
  // The priors are centred on the truth's cable parameters (nominal, before the spread).
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = kTruthMassCentreM;
  int covered = 0, covered_formal = 0, count = 0, flagged = 0, incomplete = 0;
  double z2 = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    SimulationOptions o;  // calibration_data/README.md, "realistic"
    o.attitude_control_sigma_deg = 0.2;
    o.attitude_control_time_s = 60;
    o.attitude_measurement_sigma_deg = 0.02;
    o.position_measurement_sigma_m = 0.01;
    o.tension_noise_percent = 3;
    o.tension_drift_percent = 2;
    o.tension_drift_time_s = 120;
    o.mass_centre_drift_m = 0.01;
    o.mass_centre_drift_time_s = 600;
    o.density_mismatch_percent = 1.5;
    o.sensor_gain_spread_percent = 1;
    o.sensor_bias_spread_kn = 2;
    o.sample_interval_s = 2.0;
    o.seed = seed;
    Dataset data;
    SimulationSummary summary;
    ASSERT_TRUE(Simulate(truth, poses, o, &data, nullptr, &summary, &error)) << error;
    CalibrationResult r;
    ASSERT_TRUE(CalibrateNominal(spec, data, &r));
    // Every parameter the truth varies is free here: what the ranking calls significant
    // is a false alarm (correlated residuals once made every run raise one).
    flagged += !r.misfit_ranking.empty() && r.misfit_ranking.front().significant;
    incomplete += r.verdict == FitVerdict::kModelIncomplete;
    for (int k = 0; k < 3; ++k) {
      const ParameterEstimate& p = r.parameters[k];
      const double e = p.estimate - summary.mass_centre_mean_m[k];
      covered += std::abs(e) < 2.0 * p.sigma_total;
      covered_formal += std::abs(e) < 2.0 * p.sigma;
      z2 += std::pow(e / p.sigma_total, 2);
      ++count;
    }
    CalibrationResult slow;
    ASSERT_TRUE(CalibrateNominal(slow_spec, data, &slow));
    for (int k = 0; k < 3; ++k) {
      const ParameterEstimate& p = slow.parameters[k];
      const double e = p.estimate - summary.mass_centre_mean_m[k];
      slow_covered += std::abs(e) < 2.0 * p.sigma_total;
      slow_z2 += std::pow(e / p.sigma_total, 2);
    }
    // The simulated drift: 2% of the reading, 120 s; within 3 of the estimate's sigmas.
    const SlowErrorReport& d = slow.slow_error;
    slow_process_covered +=
        std::abs(d.process.sigma_percent - o.tension_drift_percent) < 3.0 * d.amplitude_sigma &&
        std::abs(d.process.time_constant_s - o.tension_drift_time_s) <
            3.0 * d.time_constant_sigma_s;
  }
  // The figures docs/calibration.md quotes.
  std::printf(
      "coverage within 2 sigma_total %d/%d, within 2 formal sigma %d/%d, "
      "mean z^2 %.2f, ranking false alarms %d/%d, model-incomplete verdicts %d/%d; with the "
      "slow error estimated: coverage %d/%d, mean z^2 %.2f, drift within 3 sigma %d/%d\n",
      covered, count, covered_formal, count, z2 / count, flagged, kSeeds, incomplete, kSeeds,
      slow_covered, count, slow_z2 / count, slow_process_covered, kSeeds);
  // Lower than the white spec's 55/60 here (51/60, mean z^2 1.44): this survey's mass
  // centre wanders (1 cm, 10 minutes) and its grid puts most of the mass centre's
  // information in the last rings, so the estimate is an average over them, not over the
  // survey; the white spec's sigma_total, widened for the sensors' drift, happened to
  // cover that too. On random poses, or with the mass centre fixed, the coverage is that
  // of white data (docs/calibration.md, "Slow sensor errors").
  constexpr double kMinSlowCoverage = 0.8, kMaxSlowMeanZ2 = 1.7;
  EXPECT_GE(slow_covered, kMinSlowCoverage * count);
  EXPECT_GT(slow_z2 / count, kMinMeanZ2);
  EXPECT_LT(slow_z2 / count, kMaxSlowMeanZ2);
  // 3 sigma per part, two parts: nearly always; the mass-centre drift and the attitude
  // control error also wander, which the estimate partly takes for the sensors'.
  constexpr double kMinProcessCoverage = 0.8;
  EXPECT_GE(slow_process_covered, kMinProcessCoverage * kSeeds);
  EXPECT_GE(covered, kMinCoverage * count);
  EXPECT_LE(covered_formal, kMaxFormalCoverage * count);
  EXPECT_GT(z2 / count, kMinMeanZ2);
  EXPECT_LT(z2 / count, kMaxMeanZ2);
  EXPECT_LE(flagged, kMaxFalseAlarms);
  EXPECT_LE(incomplete, kMaxIncompleteVerdicts);
}

// With a robust loss the verdict still reads the least-squares chi-square (twice the
// robust cost is another number), and sigma_total is the M-estimator's sandwich: over
// seeds of white data it matches the scatter of the estimates (a Gauss-Newton Hessian
// made it 15% too small).
TEST(CalibrationTest, RobustLossKeepsTheVerdictAndTheBudgetHonest) {
  constexpr int kSeeds = 12;
  constexpr double kMinMeanZ2 = 0.6, kMaxMeanZ2 = 1.6;
  CalibrationSpec huber = MassCentreAndDensitySpec(StaticsMethod::kExact);
  huber.robust_loss = RobustLoss::kHuber;
  huber.robust_loss_scale = 3.0;  // a sample's six residuals have a norm ~2.4 sigma
  const CalibrationSpec plain = MassCentreAndDensitySpec(StaticsMethod::kExact);
  const double truth[4] = {kTruthMassCentreM[0], kTruthMassCentreM[1], kTruthMassCentreM[2],
                           kTruthDensityKgPerM};
  double z2 = 0.0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const Dataset data = CircleData(Truth(), 72, 0.03, 2000 + seed);
    CalibrationResult robust, ls;
    ASSERT_TRUE(CalibrateNominal(huber, data, &robust));
    ASSERT_TRUE(CalibrateNominal(plain, data, &ls));
    EXPECT_NE(robust.verdict, FitVerdict::kNoiseOverstated) << robust.verdict_text;
    EXPECT_NEAR(robust.reduced_chi_square, ls.reduced_chi_square, 0.05);
    for (int k = 0; k < 4; ++k) {
      z2 += std::pow((robust.parameters[k].estimate - truth[k]) / robust.parameters[k].sigma_total,
                     2) /
            (4 * kSeeds);
    }
  }
  EXPECT_GT(z2, kMinMeanZ2);
  EXPECT_LT(z2, kMaxMeanZ2);
}

// The block cross-validation is one Gauss-Newton step per block: it matches fits that
// leave each block out, predicting it with the exact statics.
TEST(CalibrationTest, BlockCrossValidationMatchesRefitsWithoutEachBlock) {
  constexpr int kNodes = 60, kBlocks = 5;
  // The step's quadratic term included, the one-step prediction matches the refits to
  // 1.3e-4 here (seeded); the per-cable normal matrices half filled moved it by up to 4.5e-4.
  constexpr double kRelTol = 2e-4;
  const Dataset data = CircleData(Truth(), kNodes, 0.03, 31);
  CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  spec.cross_validation_blocks = kBlocks;
  CalibrationResult full;
  ASSERT_TRUE(CalibrateNominal(spec, data, &full));
  ASSERT_EQ(full.cross_validation.folds_used, kBlocks);
  std::array<double, kNumCables> sse{};
  for (int b = 0; b < kBlocks; ++b) {
    Dataset rest = data, block = data;
    rest.samples.clear();
    block.samples.clear();
    for (int t = 0; t < kNodes; ++t) {
      (BlockOfSample(t, kNodes, kBlocks) == b ? block : rest).samples.push_back(data.samples[t]);
    }
    CalibrationResult fit;
    ASSERT_TRUE(CalibrateNominal(spec, rest, &fit));
    std::vector<std::array<double, kNumCables>> predicted;
    std::string error;
    ASSERT_TRUE(PredictTensions(fit.calibrated, block, AttitudeSource::kMeasured,
                                StaticsMethod::kExact, &predicted, &error))
        << error;
    for (size_t t = 0; t < block.samples.size(); ++t) {
      for (int i = 0; i < kNumCables; ++i) {
        sse[i] += std::pow(predicted[t][i] - block.samples[t].tension_n[i], 2);
      }
    }
  }
  double cv = 0.0, fitted = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    const double rms = std::sqrt(sse[i] / kNodes);
    EXPECT_NEAR(full.cross_validation.rms_n[i], rms, kRelTol * rms) << "cable " << i + 1;
    cv += std::pow(full.cross_validation.rms_n[i], 2);
    fitted += std::pow(full.cross_validation.fit_rms_n[i], 2);
  }
  EXPECT_GT(cv, fitted);  // predicted without its own block, the data fit worse
}

// One thread or more: the same numbers, to the last bit (issue 20).
TEST(CalibrationTest, ThreadsDoNotChangeTheResult) {
  // Three chunks of samples (internal/sample_chunks.h), a robust loss and a hold-out:
  // every number the outputs print is the same bits on 1, 2 and 3 threads; with white
  // noise and with a slow sensor error estimated and whitened (its filters in time order).
  Dataset data = CircleData(Truth(), 2600, 0.03, 33);
  for (size_t t = 0; t < data.samples.size(); ++t) data.samples[t].time_s = static_cast<double>(t);
  // Third case, as the recommended spec: no loss, per-cable sensor gains and biases with
  // priors (the fold by reading, folded_cost.h) and the slow error.
  for (int variant : {0, 1, 2}) {
    const bool slow = variant > 0;
    SCOPED_TRACE(variant == 2 ? "sensors, no loss" : slow ? "slow error" : "white");
    CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
    spec.robust_loss = variant == 2 ? RobustLoss::kNone : RobustLoss::kHuber;
    spec.robust_loss_scale = 2.0;
    spec.holdout_fraction = 0.2;
    spec.slow_error.enabled = spec.slow_error.estimate_amplitude = slow;
    spec.slow_error.estimate_time_constant = slow;
    for (int i = 0; variant == 2 && i < kNumCables; ++i) {
      const std::string cable = "[" + std::to_string(i + 1) + "]";
      ParameterSpec gain = Free(ParameterKind::kSensorGain, i, -1, "sensor_gain" + cable);
      gain.has_prior = true;
      gain.prior_mean_si = 1.0;
      gain.prior_sigma_si = 0.01;
      ParameterSpec bias = Free(ParameterKind::kSensorBias, i, -1, "sensor_bias_kN" + cable);
      bias.has_prior = true;
      bias.prior_sigma_si = 2000.0;
      spec.parameters.push_back(gain);
      spec.parameters.push_back(bias);
    }
    CalibrationResult results[3];
    for (int k = 0; k < 3; ++k) {
      spec.num_threads = k + 1;
      ASSERT_TRUE(CalibrateNominal(spec, data, &results[k]));
    }
    for (int k = 1; k < 3; ++k) {
      const CalibrationResult& a = results[0];
      const CalibrationResult& b = results[k];
      SCOPED_TRACE(std::to_string(k + 1) + " threads");
      EXPECT_EQ(a.final_cost, b.final_cost);
      EXPECT_EQ(a.reduced_chi_square, b.reduced_chi_square);
      EXPECT_EQ(a.iterations, b.iterations);
      for (size_t p = 0; p < a.parameters.size(); ++p) {
        EXPECT_EQ(a.parameters[p].estimate, b.parameters[p].estimate) << a.parameters[p].name;
        EXPECT_EQ(a.parameters[p].sigma_total, b.parameters[p].sigma_total) << a.parameters[p].name;
      }
      ASSERT_EQ(a.variants.size(), b.variants.size());
      for (size_t v = 0; v < a.variants.size(); ++v) {
        EXPECT_EQ(a.variants[v].fit.rms_n, b.variants[v].fit.rms_n) << a.variants[v].name;
        EXPECT_EQ(a.variants[v].holdout.rms_n, b.variants[v].holdout.rms_n) << a.variants[v].name;
      }
      EXPECT_EQ(a.cross_validation.rms_n, b.cross_validation.rms_n);
      ASSERT_EQ(a.misfit_ranking.size(), b.misfit_ranking.size());
      for (size_t c = 0; c < a.misfit_ranking.size(); ++c) {
        EXPECT_EQ(a.misfit_ranking[c].expected_decrease, b.misfit_ranking[c].expected_decrease);
      }
      EXPECT_EQ(a.slow_error.process.sigma_percent, b.slow_error.process.sigma_percent);
      EXPECT_EQ(a.slow_error.process.time_constant_s, b.slow_error.process.time_constant_s);
    }
  }
}

TEST(CalibrationTest, ReplayedJacobiansGiveTheBudgetOfKeptOnes) {
  // Slow tension drift: the residuals are correlated, and the budget's batch correction
  // reads every sample's J_t, replayed from the linearisation's inputs (no change scan,
  // issue 28) or kept in memory (the change scan's): the same bits. 1500 samples: two
  // chunks of rows.
  std::vector<Pose> poses;
  for (const Sample& s : CircleData(Truth(), 1500, 0.0, 1).samples) poses.push_back(s.pose);
  SimulationOptions o;
  o.tension_noise_percent = 3;
  o.tension_drift_percent = 2;
  o.tension_drift_time_s = 60;
  o.seed = 3;
  Dataset data;
  std::string error;
  ASSERT_TRUE(Simulate(Truth(), poses, o, &data, nullptr, nullptr, &error)) << error;
  CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  CalibrationOptions options;
  options.change_scan_replicates = 20;  // the scan's own numbers are not compared
  CalibrationResult replayed, kept;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &replayed, &error),
            CalibrationStatus::kOk)
      << error;
  spec.change_scan_groups = {"mass_centre_m"};
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &kept, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_TRUE(replayed.budget.correlated);
  EXPECT_EQ(replayed.budget.bandwidth, kept.budget.bandwidth);
  EXPECT_EQ(replayed.budget.widest_bandwidth, kept.budget.widest_bandwidth);
  EXPECT_EQ(replayed.budget.max_batch_correction, kept.budget.max_batch_correction);
  EXPECT_GT(replayed.budget.max_batch_correction, 1.0);
  for (size_t p = 0; p < replayed.parameters.size(); ++p) {
    EXPECT_EQ(replayed.parameters[p].sigma_total, kept.parameters[p].sigma_total)
        << replayed.parameters[p].name;
  }
}

// On long data the candidates come from an evenly spaced subsample (the option): the
// consider budget and the ranking's leader agree with the full pass.
TEST(CalibrationTest, CandidateSubsampleAgreesWithTheFullPass) {
  constexpr double kSystematicRelTol = 0.05;
  Dataset data = CircleData(Truth(), 240, 0.0, 35);
  std::mt19937_64 rng(37);
  std::normal_distribution<double> normal;
  for (Sample& s : data.samples) {
    s.tension_n[2] *= 1.03;  // cable 3's sensor reads 3% high
    for (double& t : s.tension_n) t *= 1.0 + 0.01 * normal(rng);
  }
  CalibrationSpec spec = MassCentreAndDensitySpec(StaticsMethod::kExact);
  spec.tension_sigma_percent = 1.0;
  ParameterSpec tower = Free(ParameterKind::kTowerOffset, 1, 0, "tower_offset_m[2].x");
  tower.free = false;
  tower.has_prior = true;
  tower.prior_sigma_si = 0.01;
  spec.parameters.push_back(tower);
  CalibrationOptions options;
  CalibrationResult full, sub;
  std::string error;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &full, &error),
            CalibrationStatus::kOk)
      << error;
  options.max_candidate_samples = 120;  // every other sample
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, options, &sub, &error),
            CalibrationStatus::kOk)
      << error;
  EXPECT_EQ(full.misfit_ranking.front().name, "sensor_gain[3]");
  EXPECT_EQ(sub.misfit_ranking.front().name, "sensor_gain[3]");
  EXPECT_TRUE(sub.misfit_ranking.front().significant);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(sub.parameters[k].sigma_systematic, full.parameters[k].sigma_systematic,
                kSystematicRelTol * full.parameters[k].sigma_systematic)
        << full.parameters[k].name;
  }
}

// The band of a correct noise model, 1 +- 3 sqrt(2 / nu), shared by the report and the CLI.
TEST(CalibrationTest, ReducedChiSquareBand) {
  CalibrationResult r;
  r.num_residuals = 52;
  r.num_free = 2;  // nu = 50: 3 sqrt(2 / 50) = 0.6
  r.reduced_chi_square = 1.59;
  ChiSquareBand band = ReducedChiSquareBand(r);
  EXPECT_EQ(band.degrees_of_freedom, 50);
  EXPECT_NEAR(band.half_width, 0.6, 1e-15);
  EXPECT_TRUE(band.within);
  r.reduced_chi_square = 0.39;
  EXPECT_FALSE(ReducedChiSquareBand(r).within);
  r.reduced_chi_square = 17.5;
  EXPECT_FALSE(ReducedChiSquareBand(r).within);
  r.reduced_chi_square = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ReducedChiSquareBand(r).within);
  r.reduced_chi_square = 1.0;
  r.num_free = 52;  // no degrees of freedom: no band
  band = ReducedChiSquareBand(r);
  EXPECT_EQ(band.half_width, 0.0);
  EXPECT_FALSE(band.within);
}

// Sets the C and C++ global locales to the first installed one whose decimal separator is
// a comma (scripts/setup.sh generates de_DE.UTF-8), as a GUI host or a Python session that
// called setlocale(LC_ALL, "") would; restores both on destruction.
class CommaDecimalLocale {
 public:
  CommaDecimalLocale() : saved_c_(std::setlocale(LC_ALL, nullptr)) {
    for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"}) {
      if (std::setlocale(LC_ALL, name) == nullptr) continue;
      if (std::string(std::localeconv()->decimal_point) == ",") {
        std::locale::global(std::locale(name));
        name_ = name;
        return;
      }
    }
    std::setlocale(LC_ALL, saved_c_.c_str());
  }
  ~CommaDecimalLocale() {
    std::locale::global(saved_cpp_);
    std::setlocale(LC_ALL, saved_c_.c_str());
  }
  const std::string& name() const { return name_; }  // empty: none installed

 private:
  std::string saved_c_;
  std::locale saved_cpp_;
  std::string name_;
};

// What a calibration from the bundled files gives, as a program embedding the library
// would write it.
struct BundledCalibration {
  std::vector<double> estimates;
  std::string model_yaml, summary_json, report_html;
};

BundledCalibration CalibrateBundledCircle() {
  const char* dir = (std::getenv("FASTCAL_SOURCE_DIR") ? std::getenv("FASTCAL_SOURCE_DIR")
                                                       : FASTCAL_TEST_SOURCE_DIR);
  const std::string data_dir = std::string(dir) + "/calibration_data/";
  BundledCalibration out;
  CableRobot model;
  CalibrationSpec spec;
  Dataset data;
  std::string error;
  EXPECT_TRUE(LoadCableRobot(data_dir + "nominal_fast.yaml", &model, &error)) << error;
  EXPECT_TRUE(LoadCalibrationSpec(data_dir + "spec_mass_centre_density.yaml",
                                  static_cast<int>(model.anchor_points_cabin_m.size()), &spec,
                                  &error))
      << error;
  EXPECT_TRUE(ReadDataset(data_dir + "circle_paper.csv", {}, &data, &error)) << error;
  if (!error.empty()) return out;
  CalibrationResult result;
  EXPECT_EQ(Calibrate(model, spec, data, CalibrationOptions(), &result, &error),
            CalibrationStatus::kOk)
      << error;
  for (const ParameterEstimate& p : result.parameters) out.estimates.push_back(p.estimate);
  // Not ours to compare: the solve time, and Ceres' own report, which Ceres formats with
  // printf in the current locale (the HTML report quotes it as it is).
  result.seconds = 0.0;
  result.ceres_full_report.clear();
  result.ceres_brief_report.clear();
  VariantEvaluation after;
  EXPECT_TRUE(EvaluateVariant("calibrated", result.calibrated, data, AttitudeSource::kMeasured,
                              StaticsMethod::kExact, result.held_out, &after, &error,
                              result.excluded))
      << error;
  ReportInputs report;
  report.spec_path = "spec.yaml";
  report.data_path = "data.csv";
  report.run_utc = "2026-11-22T15:04:05Z";
  report.initial_model = &model;
  report.spec = &spec;
  report.data = &data;
  report.result = &result;
  report.variants = {after};
  report.evaluation_method = "exact";
  out.model_yaml = CableRobotToYaml(result.calibrated, "calibrated");
  out.summary_json = SummaryJson(report);
  out.report_html = ReportHtml(report);
  return out;
}

// Numbers are read and written with '.' whatever the locale: under one whose decimal
// separator is a comma, the bundled files read the same, the calibration gives the same
// estimates to the bit, and the model file, summary.json and the report (tables, SVG
// coordinates) are byte for byte the same.
TEST(CalibrationTest, SameCalibrationUnderACommaDecimalLocale) {
  const BundledCalibration reference = CalibrateBundledCircle();
  ASSERT_FALSE(reference.estimates.empty());
  CommaDecimalLocale comma;
  if (comma.name().empty()) {
    GTEST_SKIP() << "no locale with a decimal comma is installed (tried de_DE.UTF-8, "
                    "fr_FR.UTF-8); scripts/setup.sh generates de_DE.UTF-8 when run as root";
  }
  const BundledCalibration under_comma = CalibrateBundledCircle();
  EXPECT_EQ(under_comma.estimates, reference.estimates) << comma.name();
  EXPECT_EQ(under_comma.model_yaml, reference.model_yaml);
  EXPECT_EQ(under_comma.summary_json, reference.summary_json);
  EXPECT_EQ(under_comma.report_html, reference.report_html);
}

}  // namespace
}  // namespace fastcal
