// The fastcal subcommands. Each maps its flags to library options in one place, calls
// the library and prints; the library itself never reads flags.
#ifndef FASTCAL_APPS_COMMANDS_H_
#define FASTCAL_APPS_COMMANDS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fastcal/pose.h"

namespace fastcal::cli {

int RunSolve(int argc, char** argv);
int RunCalibrate(int argc, char** argv);
int RunEvaluate(int argc, char** argv);
int RunSimulate(int argc, char** argv);

// Positions of the trajectory `kind` (line, arc, grid, random) from the shared trajectory
// flags; *known is false for any other kind.
bool TrajectoryPositionsFromFlags(const std::string& kind, const Eigen::Vector3d& focal_centre_m,
                                  std::vector<Eigen::Vector3d>* positions, bool* known,
                                  std::string* error);

// A trajectory generator's message (trajectory.h names its parameters) with the flag
// names instead.
std::string WithTrajectoryFlagNames(const std::string& message);

// PosesWithAttitudeLaw, with its message in terms of the flags (--focal-centre, node i).
bool PosesWithFocalLawFromFlags(const std::vector<Eigen::Vector3d>& positions,
                                const FocalAttitudeLaw& law, std::vector<Pose>* poses,
                                std::string* error);

}  // namespace fastcal::cli

#endif  // FASTCAL_APPS_COMMANDS_H_
