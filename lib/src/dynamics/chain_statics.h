// The chains' own statics and their linearisation: the equilibrium the time integration
// starts from and compares with, the lowest modes about it, and the strain-rate damping
// that gives the lowest mode its stated damping ratio (dynamics.h).
#ifndef FASTCAL_SRC_DYNAMICS_CHAIN_STATICS_H_
#define FASTCAL_SRC_DYNAMICS_CHAIN_STATICS_H_

#include <string>
#include <vector>

#include "dynamics/chain_system.h"
#include "fastcal/cable_robot.h"
#include "fastcal/pose.h"

namespace fastcal::internal {

struct ChainStaticsOptions {
  // Converged when Newton's correction of every displacement is below this (m; rad for
  // the body's rotation).
  double tolerance_m = 1e-10;
  int max_iterations = 50;
  // The body held where it is (the chains settle onto it): a free decay's start.
  bool body_held = false;
};

// Newton on the static equilibrium (no velocity, no wind, the tangent of the forces),
// from `state`, with a backtracking line search on the largest force. Velocities are set
// to zero. False with *error when it does not converge.
bool SolveChainStatics(const ChainModel& model, const ChainStaticsOptions& options,
                       ChainState* state, int* iterations, std::string* error);

// The lowest `count` undamped modes of the system linearised at `state` (an
// equilibrium), ascending: omega^2 and the M-normalised shapes (columns over the
// degrees of freedom, body first). By shift-invert Lanczos about 0 on a sparse LDL^T
// (Spectra), or densely for small systems. False with *error when K is not positive
// definite or the iteration fails.
bool LowestModes(const ChainModel& model, const ChainState& state, int count,
                 Eigen::VectorXd* omega2, Eigen::MatrixXd* shapes, std::string* error);

// phi^T K_axial,i phi for each cable i: the axial strain energy (times 2) the shape `phi`
// (over the degrees of freedom) puts in cable i's segments, per unit damping time.
std::vector<double> AxialQuadratic(const ChainModel& model, const ChainState& state,
                                   const Eigen::VectorXd& phi);

// What the lumped chains can describe, checked once for the modes and the dynamics in
// time: the model file's checks with plausibility (issue 57: an inertia of 1e300 kg m^2
// broke the eigensolver), uniform cables (no attachments) and a finite pose. `user` names
// the caller in the attachments' message ("the modes", "the dynamics"). False with *error
// ("model: ...", "pose: ...").
bool CheckChainInputs(const CableRobot& robot, const Pose& pose, const std::string& user,
                      std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_SRC_DYNAMICS_CHAIN_STATICS_H_
