// fastcal: statics and calibration of the FAST cable robot from the command line.
#include <gflags/gflags.h>
#include <glog/logging.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <iostream>
#include <new>
#include <string>
#include <system_error>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/quote.h"
#include "fastcal/version.h"

namespace fastcal::cli {

namespace {
const char kUsage[] = R"(fastcal: statics and calibration of the FAST cable-driven parallel robot.

Usage: fastcal <command> [--flag=value ...]

Commands:
  solve      cable forces, tensions and unstretched lengths at a pose or along a trajectory
             (exact, AAS, refined AAS, or AAS against exact), every answer checked
  locate     where the cabin hangs, from the six unstretched cable lengths (with a
             measured attitude and tensions, the pose that fits them all); stability
  calibrate  estimate mass centre, cable density, offsets, sensor gains... from measured
             poses and tensions; refuse free sets the data cannot determine; report
  evaluate   RMS of model minus measured tensions per cable, for any model file
  simulate   synthetic telemetry from a "truth" model along a trajectory, with noise
  workspace  where the cabin can go with every cable within tension limits: CSV and an
             HTML map of the focal-sphere cap
  track      the mass centre and the sensors through a season of telemetry: a window
             (day) at a time as one joint fit, with the events (moves, re-zeroed sensors)
  design     the calibration survey that determines the wanted parameters best: poses,
             samples per pose and flight order, with predicted sigma_total
  modes      natural frequencies and modes of the cabin on its sagging cables at a pose
             (the equilibrium linearised, each cable a lumped-mass chain): modes.csv
  dynamics   the cabin and its cables in time (a move, winch lengths, a free decay, wind)
             against the quasi-static answer: the departures and the settle time
  loop       the cabin in its control loop: a truth model against the controller's model
             (feed-forward and PID): the cabin's error in mm, and the feed's efficiency
  import     a telemetry export as it comes (its columns, units, ISO time stamps, decimal
             comma), read through a column map, written as the canonical dataset CSV

Run 'fastcal <command> --help' (or 'fastcal help <command>') for the flags of a command. Documentation: docs/cli.md.
)";
}  // namespace
}  // namespace fastcal::cli

namespace fastcal::cli {
namespace {

// Runs `command`; *known is false for a name that is not a command.
int Dispatch(const std::string& command, int argc, char** argv, bool* known) {
  *known = true;
  if (command == "solve") return RunSolve(argc, argv);
  if (command == "locate") return RunLocate(argc, argv);
  if (command == "calibrate") return RunCalibrate(argc, argv);
  if (command == "evaluate") return RunEvaluate(argc, argv);
  if (command == "simulate") return RunSimulate(argc, argv);
  if (command == "workspace") return RunWorkspace(argc, argv);
  if (command == "design") return RunDesign(argc, argv);
  if (command == "import") return RunImport(argc, argv);
  if (command == "track") return RunTrack(argc, argv);
  if (command == "modes") return RunModes(argc, argv);
  if (command == "dynamics") return RunDynamicsCommand(argc, argv);
  if (command == "loop") return RunLoopCommand(argc, argv);
  *known = false;
  return kExitUsage;
}

// The command, with what the machine may refuse it (memory, a thread) said in words.
int RunCommand(const std::string& command, int argc, char** argv) {
  bool known = true;
  int code = kExitUsage;
  try {
    code = Dispatch(command, argc, argv, &known);
  } catch (const std::bad_alloc&) {
    // Outputs are written last and atomically; what was being written (a temporary, a new
    // track's staging directory DIR.partial-PID) is removed here, as on SIGINT.
    fastcal::internal::RemoveTemporariesOnSignal();
    std::cerr << "fastcal " << command
              << ": out of memory: the input or the flags ask for more than this machine has\n";
    return kExitFailure;
  } catch (const std::system_error& e) {
    // The library falls back to fewer threads; this is what remains (e.g. a thread the
    // command line itself could not start): a failure of the machine, not of the input.
    fastcal::internal::RemoveTemporariesOnSignal();
    std::cerr << "fastcal " << command << ": the system refused a resource: " << e.what() << "\n";
    return kExitFailure;
  } catch (const std::exception& e) {
    // What a command did not turn into a message (issue 57: a library's exception ended in
    // std::terminate, exit 134): named with the command, what was being written removed.
    fastcal::internal::RemoveTemporariesOnSignal();
    std::cerr << "fastcal " << command << ": unexpected error: " << e.what()
              << " (a defect of fastcal: please report it with the command line)\n";
    return kExitFailure;
  }
  if (!known) {
    const std::vector<std::string> closest =
        ClosestNames(command, {"solve", "locate", "calibrate", "evaluate", "simulate", "workspace",
                               "track", "design", "modes", "dynamics", "loop", "import"});
    std::cerr << "fastcal: unknown command " << fastcal::internal::Quote(command)
              << (closest.empty() ? "" : "; did you mean " + closest.front() + "?") << "\n\n"
              << kUsage;
  }
  return code;
}

}  // namespace
}  // namespace fastcal::cli

namespace {

// SIGINT (Ctrl-C) and SIGTERM stop a command cleanly (issue 37): the temporaries it was
// writing are removed, nothing half-written is left where a result goes, and it exits
// 128 + the signal (130, 143) as a shell expects. What a killed run leaves (a staging
// directory, a track store's uncommitted samples) the next run removes or repairs.
extern "C" void StopOnSignal(int signal_number) {
  fastcal::internal::RemoveTemporariesOnSignal();
  const char message[] = "\nfastcal: interrupted: stopped, nothing half-written left\n";
  const ssize_t ignored = ::write(2, message, sizeof(message) - 1);
  (void)ignored;
  ::_exit(128 + signal_number);
}

void InstallSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = StopOnSignal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace fastcal::cli;
  InstallSignalHandlers();
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  InstallCheckedStdout();  // every result on stdout checked (FinishStandardOutput)
  const std::string command = argc < 2 ? std::string() : argv[1];
  int code = 0;
  if (command == "help" && argc >= 3) {
    // `fastcal help CMD`: the command's own help, as `fastcal CMD --help`.
    std::vector<char*> args = {argv[0], argv[2], const_cast<char*>("--help")};
    code = RunCommand(argv[2], static_cast<int>(args.size()), args.data());
  } else if (argc < 2 || command == "--help" || command == "-h" || command == "help") {
    // Asked for: the usage on stdout, exit 0; no command at all is a usage error.
    (argc < 2 ? std::cerr : std::cout) << kUsage;
    code = argc < 2 ? kExitUsage : 0;
  } else if (command == "--version") {
    std::cout << "fastcal " << FASTCAL_VERSION << "\n";
  } else {
    code = RunCommand(command, argc, argv);
  }
  return FinishStandardOutput(command.empty() ? "" : command, code);
}
