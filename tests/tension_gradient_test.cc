// Exact's tension derivatives by the implicit-function theorem (internal/tension_gradient.h)
// against central differences of the solution, for every statics parameter, on uniform
// cables and on cables with attachments, at tilted poses across the workspace.
#include "fastcal/internal/tension_gradient.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/internal/compact_start.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"
#include "test_robots.h"

namespace fastcal {
namespace {

using internal::TensionGradient;
using internal::Vector6d;
using testing::AsBuiltRobot;
using testing::TiltedPoses;

// One statics parameter: where it lives in StaticsParameters, its column of the gradient,
// and a central-difference step well above the solves' 1e-12 and well inside the
// derivative's linear range.
struct Entry {
  std::string name;
  std::function<double*(StaticsParameters<double>*)> value;
  std::function<Vector6d(const TensionGradient&)> column;
  double step;
};

std::vector<Entry> Entries(const StaticsParameters<double>& p) {
  std::vector<Entry> e;
  const std::string axes = "xyz";
  for (int c = 0; c < 3; ++c) {
    e.push_back({std::string("mass_centre.") + axes[c],
                 [c](StaticsParameters<double>* q) { return &q->mass_centre_cabin_m[c]; },
                 [c](const TensionGradient& g) { return Vector6d(g.mass_centre_cabin_m.col(c)); },
                 1e-3});
  }
  e.push_back({"cabin_mass", [](StaticsParameters<double>* q) { return &q->cabin_mass_kg; },
               [](const TensionGradient& g) { return g.cabin_mass_kg; }, 1.0});
  for (int i = 0; i < kNumCables; ++i) {
    const std::string cable = "[" + std::to_string(i + 1) + "]";
    e.push_back({"density" + cable,
                 [i](StaticsParameters<double>* q) { return &q->linear_density_kg_per_m[i]; },
                 [i](const TensionGradient& g) { return g.linear_density_kg_per_m[i]; }, 1e-3});
    e.push_back({"ea" + cable, [i](StaticsParameters<double>* q) { return &q->ea_n[i]; },
                 [i](const TensionGradient& g) { return g.ea_n[i]; }, 1e3});
    for (int c = 0; c < 3; ++c) {
      e.push_back({"tower" + cable + axes[c],
                   [i, c](StaticsParameters<double>* q) { return &q->tower_top_m[i][c]; },
                   [i, c](const TensionGradient& g) { return Vector6d(g.tower_top_m[i].col(c)); },
                   1e-3});
      e.push_back({"anchor" + cable + axes[c],
                   [i, c](StaticsParameters<double>* q) { return &q->anchor_cabin_m[i][c]; },
                   [i, c](const TensionGradient& g) { return Vector6d(g.anchor_m[i].col(c)); },
                   1e-3});
    }
    for (int j = 0; j < p.chain[i].num_attachments; ++j) {
      e.push_back({"chain" + cable + std::to_string(j),
                   [i, j](StaticsParameters<double>* q) { return &q->chain[i].value[j]; },
                   [i, j](const TensionGradient& g) { return g.chain_value[i][j]; }, 1e-2});
    }
  }
  return e;
}

// Every entry's column against central differences of the solved tensions; the tolerance
// is relative to the column's largest entry (a parameter moves some cables little).
void ExpectMatchesCentralDifferences(const CableRobot& robot, const std::vector<Pose>& poses) {
  constexpr double kRelTol = 1e-6;
  const StaticsParameters<double> p0 = MakeStaticsParameters(robot);
  const StaticsOptions options = ModelFitStaticsOptions(StaticsMethod::kExact);
  const auto tensions = [&](const StaticsParameters<double>& p, const Pose& pose) {
    StaticsSolution s;
    EXPECT_EQ(SolveStaticsWithParameters(p, pose, options, &s), StaticsStatus::kOk);
    Vector6d t;
    for (int i = 0; i < kNumCables; ++i) t[i] = s.cables[i].lower_tension_n;
    return t;
  };
  for (size_t k = 0; k < poses.size(); ++k) {
    StaticsSolution solution;
    ASSERT_EQ(SolveStaticsWithParameters(p0, poses[k], options, &solution), StaticsStatus::kOk);
    TensionGradient g;
    ASSERT_EQ(internal::ExactTensionGradient(p0, poses[k], solution,
                                             options.catenary.vertical_span_fraction, true, &g),
              StaticsStatus::kOk);
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_EQ(g.tension_n[i], solution.cables[i].lower_tension_n);
    }
    for (const Entry& e : Entries(p0)) {
      StaticsParameters<double> up = p0, down = p0;
      *e.value(&up) += e.step;
      *e.value(&down) -= e.step;
      const Vector6d numeric = (tensions(up, poses[k]) - tensions(down, poses[k])) / (2 * e.step);
      const Vector6d analytic = e.column(g);
      const double scale = numeric.cwiseAbs().maxCoeff();
      ASSERT_GT(scale, 0.0) << e.name << " moves no tension";
      for (int i = 0; i < kNumCables; ++i) {
        EXPECT_NEAR(analytic[i], numeric[i], kRelTol * scale)
            << e.name << ", pose " << k << ", cable " << i + 1;
      }
    }
  }
}

TEST(TensionGradientTest, UniformCablesMatchCentralDifferences) {
  ExpectMatchesCentralDifferences(CableRobot::NominalFast(), TiltedPoses(6, 28, 3.0));
}

TEST(TensionGradientTest, CablesWithAttachmentsMatchCentralDifferences) {
  ExpectMatchesCentralDifferences(AsBuiltRobot(), TiltedPoses(3, 29, 3.0));
}

TEST(TensionGradientTest, MovingThePoseIsMovingEveryTowerTheOtherWay) {
  // The chords are B_i - (R a_i + p): moving the cabin by d is moving every tower top by
  // -d, so d T / d position = -sum_i d T / d tower_i. The position is not a parameter:
  // an independent check of the chord columns (central differences in the pose).
  constexpr double kRelTol = 1e-6;
  constexpr double kStepM = 1e-3;
  const StaticsParameters<double> p = MakeStaticsParameters(CableRobot::NominalFast());
  const StaticsOptions options = ModelFitStaticsOptions(StaticsMethod::kExact);
  for (const Pose& pose : TiltedPoses(3, 30, 3.0)) {
    StaticsSolution s;
    ASSERT_EQ(SolveStaticsWithParameters(p, pose, options, &s), StaticsStatus::kOk);
    TensionGradient g;
    ASSERT_EQ(internal::ExactTensionGradient(p, pose, s, options.catenary.vertical_span_fraction,
                                             true, &g),
              StaticsStatus::kOk);
    for (int c = 0; c < 3; ++c) {
      Vector6d towers = Vector6d::Zero();
      for (int i = 0; i < kNumCables; ++i) towers += g.tower_top_m[i].col(c);
      Pose up = pose, down = pose;
      up.position_m[c] += kStepM;
      down.position_m[c] -= kStepM;
      StaticsSolution su, sd;
      ASSERT_EQ(SolveStaticsWithParameters(p, up, options, &su), StaticsStatus::kOk);
      ASSERT_EQ(SolveStaticsWithParameters(p, down, options, &sd), StaticsStatus::kOk);
      Vector6d numeric;
      for (int i = 0; i < kNumCables; ++i) {
        numeric[i] = (su.cables[i].lower_tension_n - sd.cables[i].lower_tension_n) / (2 * kStepM);
      }
      const double scale = numeric.cwiseAbs().maxCoeff();
      for (int i = 0; i < kNumCables; ++i) {
        EXPECT_NEAR(-towers[i], numeric[i], kRelTol * scale) << "axis " << c << " cable " << i + 1;
      }
    }
  }
}

TEST(TensionGradientTest, FromTheStateAloneTheSameTensionsAndColumns) {
  // A solution's state (Fl, Fz, s0), all a CompactStart keeps: the tensions evaluated
  // there are the solver's own, bit for bit (its last check's end evaluation), on uniform
  // cables and on cables with attachments; the columns are the solution's.
  for (const CableRobot& robot : {CableRobot::NominalFast(), AsBuiltRobot()}) {
    const StaticsParameters<double> p = MakeStaticsParameters(robot);
    const StaticsOptions options = ModelFitStaticsOptions(StaticsMethod::kExact);
    for (const Pose& pose : TiltedPoses(3, 31, 3.0)) {
      StaticsSolution solved;
      ASSERT_EQ(SolveStaticsWithParameters(p, pose, options, &solved), StaticsStatus::kOk);
      StaticsSolution state;
      internal::CompactStart::Of(solved).Restore(pose, StaticsMethod::kExact, &state);
      TensionGradient from_solution, from_state;
      const double fraction = options.catenary.vertical_span_fraction;
      ASSERT_EQ(internal::ExactTensionGradient(p, pose, solved, fraction, true, &from_solution),
                StaticsStatus::kOk);
      ASSERT_EQ(internal::ExactTensionGradient(p, pose, state, fraction, true, &from_state,
                                               /*tensions_from_state=*/true),
                StaticsStatus::kOk);
      for (int i = 0; i < kNumCables; ++i) {
        EXPECT_EQ(from_state.tension_n[i], solved.cables[i].lower_tension_n) << i;
      }
      EXPECT_EQ(from_state.mass_centre_cabin_m, from_solution.mass_centre_cabin_m);
      EXPECT_EQ(from_state.linear_density_kg_per_m[0], from_solution.linear_density_kg_per_m[0]);
    }
  }
}

}  // namespace
}  // namespace fastcal
