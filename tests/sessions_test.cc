// Tests of sessions (sessions.h): the session column and merged files, the spec's
// sessions block, and the joint fit: equal to separate fits when nothing is shared, and
// the difference's sigma_total against its spread over seeds.
#include "fastcal/sessions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/simulation.h"
#include "fastcal/trajectory.h"
#include "random_cap_poses.h"
#include "temp_path.h"

namespace fastcal {
namespace {

constexpr char kHeader[] =
    "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN";
constexpr char kRow[] = "0,0,0,140,0,0,0,500,500,500,500,500,500";

std::string Rows(const std::vector<std::string>& labels) {
  std::string text = std::string(kHeader) + ",session\n";
  for (const std::string& l : labels) text += std::string(kRow) + "," + l + "\n";
  return text;
}

TEST(SessionsTest, SessionColumnGivesLabelsInOrderOfFirstSample) {
  Dataset d;
  std::string error;
  ASSERT_TRUE(ParseDataset(Rows({"B", "B", "a-1", "B", "x_2"}), "s.csv", {}, &d, &error)) << error;
  EXPECT_EQ(d.session_labels, (std::vector<std::string>{"B", "a-1", "x_2"}));
  ASSERT_EQ(d.samples.size(), 5u);
  EXPECT_EQ(d.samples[0].session, 0);
  EXPECT_EQ(d.samples[2].session, 1);
  EXPECT_EQ(d.samples[3].session, 0);
  EXPECT_EQ(d.samples[4].session, 2);
  // Without the column: no labels, every sample session 0.
  std::string plain = std::string(kHeader) + "\n" + kRow + "\n";
  Dataset p;
  ASSERT_TRUE(ParseDataset(plain, "p.csv", {}, &p, &error)) << error;
  EXPECT_TRUE(p.session_labels.empty());
  EXPECT_EQ(p.samples[0].session, 0);
}

TEST(SessionsTest, BadSessionLabelNamesLineAndColumn) {
  Dataset d;
  std::string error;
  EXPECT_FALSE(ParseDataset(Rows({"A", "two words"}), "s.csv", {}, &d, &error));
  EXPECT_NE(error.find("s.csv:3:"), std::string::npos) << error;
  EXPECT_NE(error.find("'session'"), std::string::npos) << error;
  EXPECT_FALSE(ParseDataset(Rows({"A", ""}), "s.csv", {}, &d, &error));
  EXPECT_NE(error.find("s.csv:3:"), std::string::npos) << error;
  const std::string twice = std::string(kHeader) + ",session,session\n";
  EXPECT_FALSE(ParseDataset(twice + kRow + ",A,A\n", "s.csv", {}, &d, &error));
  EXPECT_NE(error.find("duplicate column 'session'"), std::string::npos) << error;
}

TEST(SessionsTest, SessionColumnRoundTrips) {
  Dataset d;
  std::string error;
  ASSERT_TRUE(ParseDataset(Rows({"A", "B", "A"}), "s.csv", {}, &d, &error)) << error;
  const std::string path = test::TempPath("sessions_round_trip", ".csv");
  ASSERT_TRUE(WriteDataset(path, d, "", &error)) << error;
  Dataset back;
  ASSERT_TRUE(ReadDataset(path, {}, &back, &error)) << error;
  EXPECT_EQ(back.session_labels, d.session_labels);
  for (size_t k = 0; k < d.samples.size(); ++k) {
    EXPECT_EQ(back.samples[k].session, d.samples[k].session);
  }
}

TEST(SessionsTest, MergedFilesAreOneSessionEachLabelledByStem) {
  Dataset a, b, c;
  std::string error;
  const std::string plain = std::string(kHeader) + "\n" + kRow + "\n" + kRow + "\n";
  ASSERT_TRUE(ParseDataset(plain, "dir/day-1.csv", {}, &a, &error)) << error;
  ASSERT_TRUE(ParseDataset(plain, "other/day_2.csv", {}, &b, &error)) << error;
  ASSERT_TRUE(ParseDataset(Rows({"x", "y"}), "c.csv", {}, &c, &error)) << error;
  Dataset merged;
  ASSERT_TRUE(MergeSessionFiles({a, b, c}, &merged, &error)) << error;
  EXPECT_EQ(merged.session_labels, (std::vector<std::string>{"day-1", "day_2", "x", "y"}));
  ASSERT_EQ(merged.samples.size(), 6u);
  EXPECT_EQ(merged.samples[1].session, 0);
  EXPECT_EQ(merged.samples[2].session, 1);
  EXPECT_EQ(merged.samples[5].session, 3);
  EXPECT_EQ(merged.samples[2].line, 2);  // its own file's line
  EXPECT_EQ(merged.path, "dir/day-1.csv,other/day_2.csv,c.csv");
  // Messages name a sample's own file and line.
  EXPECT_EQ(SampleWhere(merged, merged.samples[2]), "other/day_2.csv:2");
  EXPECT_EQ(SampleWhere(merged, merged.samples[5]), "c.csv:3");
  EXPECT_EQ(SampleWhere(a, a.samples[1]), "dir/day-1.csv:3");
  // The same stem twice: an error naming both files.
  Dataset a2 = a;
  a2.path = "elsewhere/day-1.csv";
  EXPECT_FALSE(MergeSessionFiles({a, a2}, &merged, &error));
  EXPECT_NE(error.find("dir/day-1.csv"), std::string::npos) << error;
  EXPECT_NE(error.find("elsewhere/day-1.csv"), std::string::npos) << error;
  // A file name that is not a label.
  Dataset bad = a;
  bad.path = "my survey.v2.csv";
  EXPECT_FALSE(MergeSessionFiles({a, bad}, &merged, &error));
  EXPECT_NE(error.find("my survey.v2.csv"), std::string::npos) << error;
}

TEST(SessionsTest, SpecSessionsBlockIsReadCheckedAndWritten) {
  const std::string base =
      "parameters:\n  mass_centre_m: {x: {free: true}, y: {free: true}}\n"
      "  sensor_gain: {mode: common, free: false}\n";
  CalibrationSpec spec;
  std::string error;
  ASSERT_TRUE(ParseCalibrationSpecYaml(base + "sessions: {separate: [mass_centre_m]}\n", "s.yaml",
                                       6, &spec, &error))
      << error;
  EXPECT_EQ(spec.separate_groups, (std::vector<std::string>{"mass_centre_m"}));
  CalibrationSpec back;
  ASSERT_TRUE(ParseCalibrationSpecYaml(CalibrationSpecToYaml(spec), "back", 6, &back, &error))
      << error;
  EXPECT_EQ(back.separate_groups, spec.separate_groups);
  EXPECT_FALSE(ParseCalibrationSpecYaml(base + "sessions: {separate: [mass]}\n", "s.yaml", 6, &spec,
                                        &error));
  EXPECT_NE(error.find("s.yaml:4: sessions.separate: unknown parameter group"), std::string::npos)
      << error;
  EXPECT_FALSE(ParseCalibrationSpecYaml(base + "sessions: {separate: [sensor_gain]}\n", "s.yaml", 6,
                                        &spec, &error));
  EXPECT_NE(error.find("no free parameter"), std::string::npos) << error;
}

TEST(SessionsTest, SeparateParametersAreCopiedPerSessionInPlace) {
  CalibrationSpec spec;
  std::string error;
  ASSERT_TRUE(ParseCalibrationSpecYaml(
      "parameters:\n  mass_centre_m: {x: {free: true}, z: {free: false}}\n"
      "  sensor_gain: {mode: common, free: true}\nsessions: {separate: [mass_centre_m]}\n",
      "s.yaml", 6, &spec, &error))
      << error;
  const CalibrationSpec joint = SeparateSessionParameters(spec, {"A", "B"});
  std::vector<std::string> names;
  for (const ParameterSpec& p : joint.parameters) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"mass_centre_m.x@A", "mass_centre_m.x@B",
                                             "mass_centre_m.z", "sensor_gain"}));
  EXPECT_EQ(joint.parameters[1].session, 1);
  EXPECT_EQ(joint.parameters[2].session, -1);
  EXPECT_TRUE(joint.IsValid(&error)) << error;
  // One session: nothing to separate.
  EXPECT_EQ(SeparateSessionParameters(spec, {"A"}).parameters.size(), spec.parameters.size());
}

// ---------------------------------------------------------------------------------------
// The joint fit.

// Two surveys of `samples` poses, the mass centre moved by `shift_m` between them; the
// sensor gains drawn once (1%) and the same in both.
Dataset TwoSurveys(int samples, const Eigen::Vector3d& shift_m, std::uint64_t seed,
                   CableRobot* truth_a) {
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = Eigen::Vector3d(0.2, 0.0, 0.5);
  SimulationOptions o;
  o.tension_noise_percent = 3.0;
  o.sensor_gain_spread_percent = 1.0;
  o.seed = seed;
  Dataset a, b;
  CableRobot used;
  std::string error;
  EXPECT_TRUE(Simulate(truth, RandomCapPoses(samples, seed), o, &a, &used, nullptr, &error))
      << error;
  CableRobot moved = used;
  moved.mass_centre_cabin_m += shift_m;
  o.sensor_gain_spread_percent = 0.0;  // the gains of `used` as they are
  o.seed = seed + 7919;
  EXPECT_TRUE(
      Simulate(moved, RandomCapPoses(samples, seed + 7919), o, &b, nullptr, nullptr, &error))
      << error;
  a.path = "a.csv";
  b.path = "b.csv";
  Dataset merged;
  EXPECT_TRUE(MergeSessionFiles({a, b}, &merged, &error)) << error;
  if (truth_a != nullptr) *truth_a = used;
  return merged;
}

CalibrationSpec MassCentreSpec(bool gains_free) {
  CalibrationSpec spec;
  std::string error;
  std::string yaml =
      "parameters:\n  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}\n";
  if (gains_free) {
    yaml += "  sensor_gain: {mode: per_cable, free: true, prior: {mean: 1, sigma: 0.01}}\n";
  }
  yaml += "sessions: {separate: [mass_centre_m]}\n";
  EXPECT_TRUE(ParseCalibrationSpecYaml(yaml, "spec", 6, &spec, &error)) << error;
  return spec;
}

const ParameterEstimate& Named(const CalibrationResult& r, const std::string& name) {
  for (const ParameterEstimate& p : r.parameters) {
    if (p.name == name) return p;
  }
  ADD_FAILURE() << "no parameter " << name;
  return r.parameters.front();
}

TEST(SessionsTest, JointFitEqualsSeparateFitsWhenNothingIsShared) {
  // Only the mass centre is free, and it is separate: the joint problem is the two
  // separate ones side by side (a block-diagonal normal matrix).
  constexpr double kEstimateTolM = 1e-7;  // 1e-5 sigma: both converge to 1e-12 in cost
  constexpr double kSigmaRelTol = 1e-6;
  const Dataset data = TwoSurveys(120, Eigen::Vector3d(0.05, 0.0, 0.03), 11, nullptr);
  // The gross-error screen off: it judges each cable's readings by their median and MAD
  // over the fitted samples, pooled over the sessions in the joint fit; at the initial
  // model it can keep different readings out of the first pass, and the second pass's
  // weights come from the first's solution, which moves the answer by ~1e-3 sigma.
  CalibrationSpec spec = MassCentreSpec(false);
  spec.detect_gross_errors = false;
  CalibrationResult joint;
  std::string error;
  ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, {}, &joint, &error),
            CalibrationStatus::kOk)
      << error;
  ASSERT_EQ(joint.session_models.size(), 2u);

  ASSERT_EQ(joint.session_differences.size(), 3u);
  for (int s = 0; s < 2; ++s) {
    Dataset part = data;
    part.samples.clear();
    part.session_labels.clear();
    for (Sample sample : data.samples) {
      if (sample.session != s) continue;
      sample.session = 0;
      part.samples.push_back(sample);
    }
    CalibrationSpec alone = spec;
    alone.separate_groups.clear();
    CalibrationResult r;
    ASSERT_EQ(Calibrate(CableRobot::NominalFast(), alone, part, {}, &r, &error),
              CalibrationStatus::kOk)
        << error;
    for (int c = 0; c < 3; ++c) {
      const std::string name = std::string("mass_centre_m.") + "xyz"[c];
      const ParameterEstimate& j = Named(joint, SessionParameterName(name, data.session_labels[s]));
      EXPECT_NEAR(j.estimate, r.parameters[c].estimate, kEstimateTolM) << name << " session " << s;
      EXPECT_NEAR(j.sigma / r.parameters[c].sigma, 1.0, kSigmaRelTol) << name;
      EXPECT_NEAR(joint.session_models[s].mass_centre_cabin_m[c], r.parameters[c].estimate,
                  kEstimateTolM);
    }
  }
  // Independent sessions: the difference's variance is the sum of the two.
  for (const SessionDifference& d : joint.session_differences) {
    const double a = Named(joint, SessionParameterName(d.name, d.from)).sigma_total;
    const double b = Named(joint, SessionParameterName(d.name, d.to)).sigma_total;
    EXPECT_NEAR(d.sigma_total, std::hypot(a, b), 1e-9) << d.name;
  }
}

TEST(SessionsTest, DifferenceSigmaTotalMatchesSpreadOverSeeds) {
  // Shared gains (1% prior), a mass centre per session; 16 seeds. The differences'
  // pulls (d - truth) / sigma_total have a mean square near 1: its standard deviation over
  // 48 pulls (3 axes, correlated a little) is ~0.2; a sigma_total 1.5x off gives 0.44 or 2.25.
  // The shared gains cancel: x and y's sigma is well below the separate fits' sqrt(2) sigma.
  constexpr int kSeeds = 16;
  constexpr double kMinMeanZ2 = 0.5, kMaxMeanZ2 = 1.7;
  const Eigen::Vector3d shift(0.05, 0.0, 0.03);
  const CalibrationSpec spec = MassCentreSpec(true);
  double z2 = 0.0;
  int found = 0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const Dataset data = TwoSurveys(150, shift, 100 + seed, nullptr);
    CalibrationResult r;
    std::string error;
    ASSERT_EQ(Calibrate(CableRobot::NominalFast(), spec, data, {}, &r, &error),
              CalibrationStatus::kOk)
        << error;
    ASSERT_EQ(r.session_differences.size(), 3u);
    for (int c = 0; c < 3; ++c) {
      const SessionDifference& d = r.session_differences[c];
      ASSERT_GT(d.sigma_total, 0.0);
      z2 += std::pow((d.difference - shift[c]) / d.sigma_total, 2) / (3 * kSeeds);
    }
    found += r.verdict_text.find("moved mass_centre_m.x") != std::string::npos;
  }
  EXPECT_GT(z2, kMinMeanZ2);
  EXPECT_LT(z2, kMaxMeanZ2);
  EXPECT_EQ(found, kSeeds);  // 5 cm in x is many sigma on 150 + 150 poses
}

// Two surveys three days apart with slow sensor errors (2%, 60 s), sensors and cables
// shared; optionally cable 3's sensor re-zeroed between them by `step_kn`.
Dataset DriftingSessions(double step_kn, std::uint64_t seed) {
  SimulationOptions o;
  o.seed = seed;
  o.sessions = 2;
  o.session_gap_s = 3 * 86400.0;
  o.tension_drift_percent = 2.0;
  o.tension_drift_time_s = 60.0;
  o.sensor_bias_spread_kn = 1.5;
  o.sensor_gain_spread_percent = 1.0;
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = Eigen::Vector3d(0.22, 0.11, 0.5);
  Dataset data;
  std::string error;
  EXPECT_TRUE(Simulate(truth, RandomCapPoses(600, seed), o, &data, nullptr, nullptr, &error))
      << error;
  for (Sample& s : data.samples) {
    if (s.session == 1) s.tension_n[2] += step_kn * 1e3;
  }
  return data;
}

CalibrationSpec DriftingSessionsSpec() {
  CalibrationSpec spec;
  std::string error;
  EXPECT_TRUE(ParseCalibrationSpecYaml(
      "noise: {tension_sigma_percent: 3, slow_error: estimate}\n"
      "parameters:\n  mass_centre_m: {x: {free: true}, y: {free: true}, z: {free: true}}\n"
      "  sensor_bias_kN: {mode: per_cable, free: true, prior: {mean: 0, sigma: 2}}\n"
      "  sensor_gain: {mode: per_cable, free: true, prior: {mean: 1, sigma: 0.01}}\n"
      "sessions: {separate: [mass_centre_m]}\n",
      "spec", 3, &spec, &error))
      << error;
  return spec;
}

TEST(SessionsTest, ReZeroedSensorIsNamedAndNotReadAsAMove) {
  // A 4 kN step of cable 3's offset (the slow error explains ~1 kN between the sessions'
  // means): named, fitted per session, and the mass centre stays put. Without it, no
  // sensor is accused and the biases stay shared.
  constexpr double kStepKn = 4.0;
  constexpr double kMoveSigmas = 3.0;  // the verdict's own threshold
  for (double step : {0.0, kStepKn}) {
    SCOPED_TRACE(step);
    const Dataset data = DriftingSessions(step, 21);
    CalibrationResult r;
    std::string error;
    ASSERT_EQ(Calibrate(CableRobot::NominalFast(), DriftingSessionsSpec(), data, {}, &r, &error),
              CalibrationStatus::kOk)
        << error;
    ASSERT_TRUE(r.sensor_steps.tested);
    ASSERT_TRUE(r.slow_error.enabled);
    EXPECT_FALSE(r.slow_error.amplitude_at_floor);
    for (const SessionDifference& d : r.session_differences) {
      if (d.name.rfind("mass_centre_m", 0) != 0) continue;
      EXPECT_LT(std::abs(d.Sigmas()), kMoveSigmas) << d.name << " " << d.difference;
    }
    if (step == 0.0) {
      EXPECT_TRUE(r.sensor_steps.separated.empty());
      continue;
    }
    // Cable 3 accused, alone; then every bias fitted per session.
    int accused = 0;
    for (const SensorStep& t : r.sensor_steps.tests) {
      accused += t.significant;
      if (t.significant) {
        EXPECT_EQ(t.cable, 2);
      }
    }
    EXPECT_EQ(accused, 1);
    EXPECT_EQ(r.sensor_steps.separated.size(), 6u);
    EXPECT_NE(r.verdict_text.find("cable 3 in session 2"), std::string::npos) << r.verdict_text;
    // Fitted per session: the difference of its copies is the step.
    bool seen = false;
    for (const SessionDifference& d : r.session_differences) {
      if (d.name != "sensor_bias_kN[3]") continue;
      seen = true;
      EXPECT_NEAR(d.difference, kStepKn, 3.0 * d.sigma_total);
    }
    EXPECT_TRUE(seen);
  }
}

}  // namespace
}  // namespace fastcal
