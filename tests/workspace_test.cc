// Tests of the feasible-workspace map (workspace.h): the paper's focal law holds the whole
// 40 deg cap with every tension between ~112 and ~316 kN (what solve's grid gives), and
// nodes outside the limits say why and which cable; CSV and HTML.
#include "fastcal/workspace.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace fastcal {
namespace {

constexpr double kKn = 1e3;

// The smallest and largest lower-end tension over the feasible nodes (N).
void FeasibleRange(const WorkspaceMap& map, double offset_m, double* lo_n, double* hi_n) {
  *lo_n = HUGE_VAL;
  *hi_n = 0.0;
  for (const WorkspaceNode& n : map.nodes) {
    if (n.radial_offset_m != offset_m || n.verdict != WorkspaceVerdict::kFeasible) continue;
    *lo_n = std::min(*lo_n, n.min_tension_n);
    *hi_n = std::max(*hi_n, n.max_tension_n);
  }
}

// A grid over the cap to 45 deg off axis, and 5 m inside and outside the sphere (the
// issue's sweep reached that far), with lower-end tension limits in kN.
WorkspaceOptions EdgeOptions(double ring_step_deg, double azimuth_step_deg, double min_kn,
                             double max_kn) {
  WorkspaceOptions options;
  options.grid.max_off_axis_deg = 45.0;
  options.grid.off_axis_step_deg = ring_step_deg;
  options.grid.azimuth_step_deg = azimuth_step_deg;
  options.radial_offset_m = 5.0;
  options.min_tension_n = min_kn * kKn;
  options.max_tension_n = max_kn * kKn;
  return options;
}

// The check: with the paper's focal law the whole 40 deg cap on the sphere is
// feasible, every tension between about 112 and 316 kN, as solve --trajectory=grid
// --method=exact --off-axis-step-deg=1 --azimuth-step-deg=5 gave before (112.3376 and
// 316.0204 kN), and each node's extremes are those of its own exact solve.
TEST(WorkspaceTest, FocalLawHoldsTheWholeCapBetween112And316Kn) {
  constexpr double kSolveGridMinKn = 112.3375758, kSolveGridMaxKn = 316.0203915;
  constexpr double kTensionTolKn = 1e-6;  // the same solves: to the printed digits
  const CableRobot robot = CableRobot::NominalFast();
  const WorkspaceOptions options;
  WorkspaceMap map;
  std::string error;
  ASSERT_TRUE(ComputeWorkspace(robot, options, &map, &error)) << error;
  ASSERT_EQ(map.nodes.size(), 2881u);
  for (const WorkspaceNode& n : map.nodes) {
    EXPECT_EQ(n.verdict, WorkspaceVerdict::kFeasible) << n.off_axis_deg << " " << n.reason;
    EXPECT_TRUE(n.reason.empty());
    EXPECT_EQ(n.cable, -1);
  }
  double lo_n, hi_n;
  FeasibleRange(map, 0.0, &lo_n, &hi_n);
  EXPECT_NEAR(lo_n / kKn, kSolveGridMinKn, kTensionTolKn);
  EXPECT_NEAR(hi_n / kKn, kSolveGridMaxKn, kTensionTolKn);
  // A node 38 deg off axis at 125 deg azimuth, against its own cold exact solve.
  const WorkspaceNode& node = map.nodes[1 + 37 * 72 + 25];
  ASSERT_NEAR(node.off_axis_deg, 38.0, 1e-9);
  ASSERT_NEAR(node.azimuth_deg, 125.0, 1e-9);
  StaticsSolution s;
  ASSERT_EQ(SolveStatics(robot, node.pose, StaticsOptions(), &s), StaticsStatus::kOk);
  double lo = HUGE_VAL, hi = 0.0, upper = 0.0;
  for (const CableSolution& c : s.cables) {
    lo = std::min(lo, c.lower_tension_n);
    hi = std::max(hi, c.lower_tension_n);
    upper = std::max(upper, c.upper_tension_n);
  }
  EXPECT_NEAR(node.min_tension_n, lo, kTensionTolKn * kKn);
  EXPECT_NEAR(node.max_tension_n, hi, kTensionTolKn * kKn);
  EXPECT_NEAR(node.max_upper_tension_n, upper, kTensionTolKn * kKn);
  EXPECT_GT(node.max_upper_tension_n, node.max_tension_n);  // the cable's weight
}

// With limits, every node is feasible exactly when its tensions are within them; the
// others name the cable and the numbers, below the minimum before above the maximum.
// Off the cap's edge (45 deg, 5 m inside and outside) some have no equilibrium in range.
TEST(WorkspaceTest, NodesOutsideTheLimitsSayWhyAndWhichCable) {
  constexpr double kMinKn = 130.0, kMaxKn = 300.0;
  const CableRobot robot = CableRobot::NominalFast();
  const WorkspaceOptions options = EdgeOptions(3.0, 15.0, kMinKn, kMaxKn);
  WorkspaceMap map;
  std::string error;
  ASSERT_TRUE(ComputeWorkspace(robot, options, &map, &error)) << error;
  EXPECT_EQ(map.layers_m, (std::vector<double>{-5.0, 0.0, 5.0}));
  ASSERT_EQ(map.nodes.size(), 3u * (1 + 15 * 24));
  std::map<std::string, int> codes;
  for (const WorkspaceNode& n : map.nodes) {
    ++codes[WorkspaceNodeCode(n)];
    const double radius_m = (n.pose.position_m - options.grid.focal_centre_m).norm();
    EXPECT_NEAR(radius_m, options.grid.focal_radius_m + n.radial_offset_m, 1e-9);
    if (n.status != StaticsStatus::kOk) {
      EXPECT_EQ(n.verdict, WorkspaceVerdict::kStatics);
      EXPECT_FALSE(n.reason.empty());
      EXPECT_EQ(n.min_tension_n, 0.0);
      continue;
    }
    const bool low = n.min_tension_n < options.min_tension_n;
    const bool high = n.max_tension_n > options.max_tension_n;
    if (low) {
      EXPECT_EQ(n.verdict, WorkspaceVerdict::kBelowMinTension);
      EXPECT_EQ(n.cable, n.min_tension_cable);
      EXPECT_NE(n.reason.find("cable " + std::to_string(n.cable + 1) + " below the minimum"),
                std::string::npos)
          << n.reason;
    } else if (high) {
      EXPECT_EQ(n.verdict, WorkspaceVerdict::kAboveMaxTension);
      EXPECT_EQ(n.cable, n.max_tension_cable);
      EXPECT_NE(n.reason.find("above the maximum tension"), std::string::npos) << n.reason;
    } else {
      EXPECT_EQ(n.verdict, WorkspaceVerdict::kFeasible);
    }
  }
  EXPECT_GT(codes["feasible"], 0);
  EXPECT_GT(codes["below_min_tension"], 0);
  EXPECT_GT(codes["above_max_tension"], 0);
  EXPECT_GT(codes["sagging_cable"], 0);
}

TEST(WorkspaceTest, InvalidOptionsNameTheField) {
  const CableRobot robot = CableRobot::NominalFast();
  const std::pair<void (*)(WorkspaceOptions*), const char*> cases[] = {
      {[](WorkspaceOptions* o) { o->min_tension_n = -1.0; }, "min_tension_n"},
      {[](WorkspaceOptions* o) { o->max_tension_n = o->min_tension_n; }, "max_tension_n"},
      {[](WorkspaceOptions* o) { o->radial_offset_m = -2.0; }, "radial_offset_m"},
      {[](WorkspaceOptions* o) { o->grid.off_axis_step_deg = 0.0; }, "grid.off_axis_step_deg"},
      {[](WorkspaceOptions* o) { o->statics.max_length_ratio = 1.0; }, "max_length_ratio"},
  };
  for (const auto& [change, field] : cases) {
    WorkspaceOptions options;
    change(&options);
    std::string error;
    EXPECT_FALSE(options.IsValid(&error)) << field;
    EXPECT_NE(error.find(field), std::string::npos) << error;
    WorkspaceMap map;
    EXPECT_FALSE(ComputeWorkspace(robot, options, &map, &error)) << field;
  }
}

// One CSV row per node, the message quoted, tensions empty where the statics failed; the
// HTML has one map per layer, one cell per node, a mark per infeasible node.
TEST(WorkspaceTest, CsvAndHtmlHaveEveryNode) {
  constexpr double kMinKn = 120.0;
  const CableRobot robot = CableRobot::NominalFast();
  const WorkspaceOptions options =
      EdgeOptions(5.0, 30.0, kMinKn, std::numeric_limits<double>::infinity());
  WorkspaceMap map;
  std::string error;
  ASSERT_TRUE(ComputeWorkspace(robot, options, &map, &error)) << error;
  const std::string csv = WorkspaceCsv(map);
  EXPECT_EQ(static_cast<size_t>(std::count(csv.begin(), csv.end(), '\n')), map.nodes.size() + 1);
  EXPECT_EQ(csv.find("nan"), std::string::npos);
  int infeasible = 0;
  for (const WorkspaceNode& n : map.nodes) infeasible += n.verdict != WorkspaceVerdict::kFeasible;
  ASSERT_GT(infeasible, 0);
  EXPECT_NE(csv.find(",sagging_cable,"), std::string::npos);
  EXPECT_NE(csv.find(",,,,,\"cable "), std::string::npos);  // no tensions, then the message
  const std::string html = WorkspaceHtml(map, robot, "nominal FAST", "made by a test");
  auto count = [&html](const std::string& what) {
    size_t n = 0;
    for (size_t at = html.find(what); at != std::string::npos; at = html.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("<svg "), map.layers_m.size());
  EXPECT_EQ(count("class=\"cell\""), map.nodes.size());
  EXPECT_EQ(count("class=\"mark\""), static_cast<size_t>(infeasible));
  EXPECT_EQ(count("data-value=\"n/a\""),
            static_cast<size_t>(std::count_if(map.nodes.begin(), map.nodes.end(), [](auto& n) {
              return n.status != StaticsStatus::kOk;
            })));
  EXPECT_NE(html.find(">T1<"), std::string::npos);
  EXPECT_NE(html.find("made by a test"), std::string::npos);
  EXPECT_EQ(html.find("nan"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
}

}  // namespace
}  // namespace fastcal
