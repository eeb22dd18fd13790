// A short path through a set of points, for flying a survey's stops (design.h): a
// nearest-neighbour tour from a given start, improved by 2-opt (Croes 1958) until no
// reversal of a segment shortens it. The path is open (it ends at its last stop, it does
// not return), with straight legs between the points; for a few hundred points it comes
// within a few percent of the shortest.
//
// 2-opt on an open path: reversing stops a..b (0 < a < b) changes the length by
//   |p[a-1] p[b]| + |p[a] p[b+1]| - |p[a-1] p[a]| - |p[b] p[b+1]|
// (the last term and |p[a] p[b+1]| absent when b is the last stop).
#ifndef FASTCAL_SURVEY_PATH_H_
#define FASTCAL_SURVEY_PATH_H_

#include <Eigen/Core>
#include <vector>

namespace fastcal {

// The order in which to visit `points`, starting at index `start` (in range when points
// is not empty). Deterministic: ties go to the lower index.
std::vector<int> ShortPathOrder(const std::vector<Eigen::Vector3d>& points, int start);

// Sum of the straight legs between consecutive points of `order`.
double PathLength(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& order);

}  // namespace fastcal

#endif  // FASTCAL_SURVEY_PATH_H_
