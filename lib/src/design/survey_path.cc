// Nearest-neighbour tour and 2-opt (survey_path.h).
#include "fastcal/survey_path.h"

#include <algorithm>
#include <limits>

namespace fastcal {
namespace {

// A reversal must shorten the path by more than this (m) to be taken: rounding cannot
// make 2-opt cycle.
constexpr double kImprovementM = 1e-9;

std::vector<int> NearestNeighbourTour(const std::vector<Eigen::Vector3d>& p, int start) {
  const int n = static_cast<int>(p.size());
  std::vector<int> order{start};
  std::vector<bool> used(n, false);
  used[start] = true;
  for (int k = 1; k < n; ++k) {
    const Eigen::Vector3d& from = p[order.back()];
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (int j = 0; j < n; ++j) {
      if (used[j]) continue;
      const double d = (p[j] - from).squaredNorm();
      if (d < best_d) {
        best_d = d;
        best = j;
      }
    }
    used[best] = true;
    order.push_back(best);
  }
  return order;
}

// One sweep of 2-opt moves; true when one was made.
bool TwoOptSweep(const std::vector<Eigen::Vector3d>& p, std::vector<int>* order) {
  std::vector<int>& o = *order;
  const int n = static_cast<int>(o.size());
  auto d = [&p, &o](int a, int b) { return (p[o[a]] - p[o[b]]).norm(); };
  bool improved = false;
  for (int a = 1; a + 1 <= n - 1; ++a) {
    for (int b = a + 1; b < n; ++b) {
      double change = d(a - 1, b) - d(a - 1, a);
      if (b + 1 < n) change += d(a, b + 1) - d(b, b + 1);
      if (change < -kImprovementM) {
        std::reverse(o.begin() + a, o.begin() + b + 1);
        improved = true;
      }
    }
  }
  return improved;
}

}  // namespace

std::vector<int> ShortPathOrder(const std::vector<Eigen::Vector3d>& points, int start) {
  if (points.empty()) return {};
  std::vector<int> order = NearestNeighbourTour(points, start);
  // Each sweep shortens the path; a bound on the sweeps keeps a pathological case finite.
  for (int sweep = 0; sweep < 1000 && TwoOptSweep(points, &order); ++sweep) {
  }
  return order;
}

double PathLength(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& order) {
  double length = 0.0;
  for (size_t k = 1; k < order.size(); ++k) {
    length += (points[order[k]] - points[order[k - 1]]).norm();
  }
  return length;
}

}  // namespace fastcal
