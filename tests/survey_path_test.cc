// Tests of the survey path (survey_path.h): the order visits every point once from the
// start, 2-opt undoes a crossing, and the length is the sum of the legs.
#include "fastcal/survey_path.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace fastcal {
namespace {

constexpr double kLengthToleranceM = 1e-9;

TEST(SurveyPath, VisitsEveryPointOnceFromTheStart) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 200; ++i) p.emplace_back(u(rng), u(rng), 150.0);
  const std::vector<int> order = ShortPathOrder(p, 17);
  ASSERT_EQ(order.size(), p.size());
  EXPECT_EQ(order.front(), 17);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < 200; ++i) EXPECT_EQ(sorted[i], i);
}

TEST(SurveyPath, PointsOnALineAreVisitedInOrder) {
  // A shuffled line from one end: the shortest path is the line itself, length 99 m.
  std::vector<Eigen::Vector3d> p;
  for (int i : {5, 0, 9, 3, 7, 1, 8, 2, 6, 4}) p.emplace_back(11.0 * i, 0.0, 0.0);
  const std::vector<int> order = ShortPathOrder(p, 1);  // the point at x = 0
  EXPECT_NEAR(PathLength(p, order), 99.0, kLengthToleranceM);
}

TEST(SurveyPath, TwoOptShortensANearestNeighbourTourOnACircle) {
  // Points on a circle: the best open path is the circle less one chord.
  std::vector<Eigen::Vector3d> p;
  const int n = 60;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * ((i * 37) % n) / n;  // scrambled
    p.emplace_back(50.0 * std::cos(a), 50.0 * std::sin(a), 0.0);
  }
  const double best = (n - 1) * 2.0 * 50.0 * std::sin(M_PI / n);
  const double length = PathLength(p, ShortPathOrder(p, 0));
  EXPECT_LE(length, best * 1.05);
  EXPECT_GE(length, best - kLengthToleranceM);
}

TEST(SurveyPath, EmptyAndSingle) {
  EXPECT_TRUE(ShortPathOrder({}, 0).empty());
  const std::vector<Eigen::Vector3d> one = {Eigen::Vector3d(1, 2, 3)};
  EXPECT_EQ(ShortPathOrder(one, 0), std::vector<int>{0});
  EXPECT_EQ(PathLength(one, {0}), 0.0);
}

}  // namespace
}  // namespace fastcal
