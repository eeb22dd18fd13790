// Tests of the trajectory plot page (trajectory_plot.h): its charts, the path's length,
// the per-cable extremes and largest AAS error against values computed here from the
// solutions, failed poses named, inputs that do not fit refused.
#include "fastcal/trajectory_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class TrajectoryPlotTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<Eigen::Vector3d> positions;
    ASSERT_TRUE(LinePositions({50, 0, 150}, {-50, 0, 150}, 11, &positions, nullptr));
    ASSERT_TRUE(PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses_, nullptr));
    const CableRobot robot = CableRobot::NominalFast();
    for (StaticsMethod method : {StaticsMethod::kAas, StaticsMethod::kExact}) {
      StaticsOptions options;
      options.method = method;
      std::vector<StaticsSolution>& run = method == StaticsMethod::kAas ? aas_ : exact_;
      for (const Pose& pose : poses_) {
        run.emplace_back();
        ASSERT_EQ(SolveStatics(robot, pose, options, &run.back()), StaticsStatus::kOk);
      }
    }
    in_.title = "Tensions along --trajectory=line";
    in_.provenance = "fastcal solve --trajectory=line --nodes=11 <test>";
    in_.poses = &poses_;
    in_.runs = {{"aas", &aas_}, {"exact", &exact_}};
  }
  std::vector<Pose> poses_;
  std::vector<StaticsSolution> aas_, exact_;
  TrajectoryPlotInputs in_;
};

// Two methods: both tension charts and the error chart, the 100 m of path, and each
// cable's largest |aas - exact| / exact as computed here.
TEST_F(TrajectoryPlotTest, ComparesTwoMethodsAlongThePath) {
  const std::string page = TrajectoryPlotHtml(in_);
  ASSERT_FALSE(page.empty());
  EXPECT_TRUE(Has(page, "<title>(a) Lower-end tensions, aas</title>"));
  EXPECT_TRUE(Has(page, "<title>(b) Lower-end tensions, exact</title>"));
  EXPECT_TRUE(Has(page, "<title>Relative error of aas against exact</title>"));
  EXPECT_TRUE(Has(page, "11 poses, 100 m of path"));
  EXPECT_TRUE(Has(page, "&lt;test&gt;"));  // the provenance, escaped
  EXPECT_FALSE(Has(page, "<script"));
  for (int i = 0; i < kNumCables; ++i) {
    double worst_pct = 0.0, lowest_kn = INFINITY;
    for (size_t n = 0; n < poses_.size(); ++n) {
      const double a = aas_[n].cables[i].lower_tension_n, e = exact_[n].cables[i].lower_tension_n;
      worst_pct = std::max(worst_pct, std::abs(100.0 * (a / e - 1.0)));
      lowest_kn = std::min(lowest_kn, e / 1e3);
    }
    char cell[64];
    std::snprintf(cell, sizeof(cell), "<td class=\"num\">%.4f</td></tr>", worst_pct);
    EXPECT_TRUE(Has(page, cell)) << "cable " << i + 1 << ": " << cell;
    std::snprintf(cell, sizeof(cell), "<td class=\"num\">%.3f</td>", lowest_kn);
    EXPECT_TRUE(Has(page, cell)) << "cable " << i + 1 << ": " << cell;
  }
}

// One method: its chart alone; a grid's nodes are numbered, not a distance.
TEST_F(TrajectoryPlotTest, OneMethodAndNodesInsteadOfDistance) {
  in_.runs = {{"exact", &exact_}};
  in_.along_path = false;
  const std::string page = TrajectoryPlotHtml(in_);
  EXPECT_TRUE(Has(page, "<title>Lower-end tensions, exact</title>"));
  EXPECT_FALSE(Has(page, "Relative error"));
  EXPECT_TRUE(Has(page, ">node</text>"));
  EXPECT_FALSE(Has(page, "m of path"));
}

// A failed pose is a gap, counted and named; never a NaN on the page.
TEST_F(TrajectoryPlotTest, FailedPosesAreNamed) {
  aas_[4].status = StaticsStatus::kInaccurate;
  const std::string page = TrajectoryPlotHtml(in_);
  EXPECT_TRUE(Has(page, "1 of 11 poses failed")) << page.substr(0, 3000);
  EXPECT_TRUE(Has(page, "node 4 (aas: inaccurate)"));
  EXPECT_FALSE(Has(page, "nan"));
}

TEST_F(TrajectoryPlotTest, InputsThatDoNotFitGiveNothing) {
  exact_.pop_back();
  EXPECT_EQ(TrajectoryPlotHtml(in_), "");
  in_.runs.clear();
  EXPECT_EQ(TrajectoryPlotHtml(in_), "");
  in_.runs = {{"exact", nullptr}};
  EXPECT_EQ(TrajectoryPlotHtml(in_), "");
  in_.poses = nullptr;
  EXPECT_EQ(TrajectoryPlotHtml(in_), "");
}

}  // namespace
}  // namespace fastcal
