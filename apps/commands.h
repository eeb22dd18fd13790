// The fastcal subcommands. Each maps its flags to library options in one place, calls
// the library and prints; the library itself never reads flags.
#ifndef FASTCAL_APPS_COMMANDS_H_
#define FASTCAL_APPS_COMMANDS_H_

#include <Eigen/Core>
#include <set>
#include <string>
#include <vector>

#include "cli_util.h"
#include "fastcal/dynamics.h"
#include "fastcal/modes.h"
#include "fastcal/pose.h"
#include "fastcal/simulation.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"
#include "fastcal/wind.h"
#include "fastcal/workspace.h"

namespace fastcal::cli {

int RunSolve(int argc, char** argv);
int RunLocate(int argc, char** argv);
int RunCalibrate(int argc, char** argv);
int RunEvaluate(int argc, char** argv);
int RunSimulate(int argc, char** argv);
int RunWorkspace(int argc, char** argv);
int RunDesign(int argc, char** argv);
int RunImport(int argc, char** argv);
int RunTrack(int argc, char** argv);
int RunModes(int argc, char** argv);
// `fastcal dynamics` (dynamics_command.cc).
int RunDynamicsCommand(int argc, char** argv);
// The wind from --wind=SPEED,DIRECTION_DEG, --gust-spectrum, --turbulence-intensity and
// --seed (dynamics, simulate --dynamics); false with the flag named.
bool WindFromFlags(WindOptions* wind, std::string* error);
// The dynamics' options from --segments, --damping-ratio, --cable-damping-ratio, --step-s
// and the wind's flags (dynamics, loop).
bool DynamicsOptionsFromFlags(DynamicsOptions* options, std::string* error);
int RunLoopCommand(int argc, char** argv);
// modes --data: the identified modes of a record against the prediction (modes_identify.cc).
int RunModesIdentify(const CableRobot& robot, const ModesOptions& options, bool to_file);
// simulate --vibration (simulate_vibration.cc): its flags, and the run after StartCommand.
const std::set<std::string>& VibrationFlags();
int RunSimulateVibration(int argc, char** argv);
// simulate --dynamics (simulate_dynamics.cc): its flags, and the flight's source put into
// *options from the poses to fly (a copy of the stream is drawn); *note for the summary.
const std::set<std::string>& SimulateDynamicsFlags();
bool SurveyFlightFromFlags(const PoseStream& poses, SimulationOptions* options, std::string* note,
                           std::string* error);

// Positions of the trajectory `kind` (circle, line, arc, grid, random) from the shared trajectory
// flags; *known is false for any other kind.
bool TrajectoryPositionsFromFlags(const std::string& kind, const Eigen::Vector3d& focal_centre_m,
                                  std::vector<Eigen::Vector3d>* positions, bool* known,
                                  std::string* error);
// The same positions as a stream (trajectory.h), checked the same way (every node is
// generated once to check it, not kept): simulate's memory does not grow with --samples.
// The grid (at most kMaxGridPositions) is held and handed out from memory.
bool TrajectoryPositionStreamFromFlags(const std::string& kind,
                                       const Eigen::Vector3d& focal_centre_m,
                                       PositionStream* stream, bool* known, std::string* error);

// Poses held in memory (a --poses file: bounded by its size; one --position), as a stream.
PoseStream StreamOf(std::vector<Pose> poses);

// The poses of a generated trajectory, made as they are used: the positions' stream with
// the focal attitude law (`focal`) or R = I applied to each, so that none is held (solve,
// simulate). The law's domain is checked first on a copy of the stream; a position it
// cannot take is named as PosesWithFocalLawFromFlags names it.
bool PosesFromPositions(const PositionStream& positions, bool focal, const FocalAttitudeLaw& law,
                        PoseStream* poses, std::string* error);

// The scopes of the trajectory flags (cli_util.h) for trajectory `kind` (circle, line, arc,
// grid, random, or another mode: point, poses): each generator's parameters apply to their
// generators only, --tilt-fraction to the focal attitude law (`focal_law`: the poses fly
// it), --focal-centre to that law and to the focal-sphere trajectories grid and random.
std::vector<FlagScope> TrajectoryFlagScopes(const std::string& kind, bool focal_law);

// A trajectory generator's message (trajectory.h names its parameters) with the flag
// names instead.
std::string WithTrajectoryFlagNames(const std::string& message);

// PosesWithAttitudeLaw, with its message in terms of the flags (--focal-centre, node i).
bool PosesWithFocalLawFromFlags(const std::vector<Eigen::Vector3d>& positions,
                                const FocalAttitudeLaw& law, std::vector<Pose>* poses,
                                std::string* error);

// The poses of --poses=FILE (solve, simulate) under --attitude-law: "focal" replaces the
// file's attitudes by the law's, "none" by R = I, "" keeps them. With `joint_columns`
// (a model's moving parts) the file's joint columns too, into *joints (left empty when the
// file has none; a column map's export is read without them).
bool ReadPosesWithAttitudeLaw(const std::string& path, const std::string& attitude_law,
                              const FocalAttitudeLaw& law, std::vector<Pose>* poses,
                              std::string* error,
                              const std::vector<std::string>* joint_columns = nullptr,
                              std::vector<JointValues>* joints = nullptr);

// The workspace's grid, focal law, tension limits and statics checks from its flags
// (workspace, design); false with the flags named when invalid.
bool WorkspaceOptionsFromFlags(WorkspaceOptions* options, std::string* error);

// One cabin pose from --position with its attitude (--rpy, --quat, --rotvec or
// --attitude-law=focal|none with --tilt-fraction and --focal-centre; R = I without
// one), as solve takes it; *attitude says which, for summaries.
bool SinglePoseFromFlags(Pose* pose, std::string* attitude, std::string* error);

// `message` of a FocalGridSpec (`grid.`) or FocalAttitudeLaw (`attitude_law.`) field
// with the flags that set it (--max-off-axis-deg, ..., --tilt-fraction), and the
// command's own fields in `more` (field, flag) (workspace, modes --cap).
std::string WithGridFlagNames(const std::string& message,
                              std::vector<std::pair<std::string, std::string>> more = {});

// Sets the model-range limits of `options` from --max-strain, --max-length-ratio and
// --reflector-clearance (solve, workspace); false with the flags named when invalid.
bool ModelRangeFromFlags(StaticsOptions* options, std::string* error);

}  // namespace fastcal::cli

#endif  // FASTCAL_APPS_COMMANDS_H_
