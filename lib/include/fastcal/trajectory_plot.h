// The statics along a trajectory as a self-contained HTML page (fastcal solve --plot), in
// the report's style: the six lower-end tensions against the distance the cabin has
// travelled, as the paper's Figs. 9 and 10 (a straight line G1 -> G2 and a half circle,
// the forces by AAS and by the iteration side by side), and, when two methods are
// compared, the first one's relative error per cable along the path,
//
//   e_i(s) = 100 (T_i,first(s) / T_i,second(s) - 1)  [%],
//
// whose maxima are the paper's Tables 4 and 5. Distance travelled: s_0 = 0,
// s_n = s_(n-1) + |p_n - p_(n-1)| (m). Poses whose statics failed are gaps in every
// curve and are counted and named on the page.
#ifndef FASTCAL_TRAJECTORY_PLOT_H_
#define FASTCAL_TRAJECTORY_PLOT_H_

#include <string>
#include <vector>

#include "fastcal/pose.h"
#include "fastcal/statics.h"

namespace fastcal {

// One method's solutions, one per pose (in the poses' order).
struct TrajectoryRun {
  std::string method;                                       // e.g. "aas", "exact"
  const std::vector<StaticsSolution>* solutions = nullptr;  // not owned
};

struct TrajectoryPlotInputs {
  std::string title;       // the page's heading, e.g. "Tensions along --trajectory=line"
  std::string provenance;  // command line, version, model, attitude: one per line
  const std::vector<Pose>* poses = nullptr;  // not owned; in flight order
  // x: the distance travelled (true) or the node number (false: a grid or a random
  // sample of the cap, which is no path).
  bool along_path = true;
  // One run, or two compared: the first against the second (aas against exact).
  std::vector<TrajectoryRun> runs;
};

// The page. An empty string when the inputs do not fit together (no poses, no run, or a
// run with another number of solutions than poses): the caller checks its own inputs.
std::string TrajectoryPlotHtml(const TrajectoryPlotInputs& inputs);

}  // namespace fastcal

#endif  // FASTCAL_TRAJECTORY_PLOT_H_
