// fastcal: statics and calibration of the FAST cable robot from the command line.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <cstring>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "fastcal/internal/quote.h"
#include "fastcal/version.h"

namespace fastcal::cli {

namespace {
const char kUsage[] = R"(fastcal: statics and calibration of the FAST cable-driven parallel robot.

Usage: fastcal <command> [--flag=value ...]

Commands:
  solve      cable forces, tensions and unstretched lengths at a pose or along a trajectory
             (exact, AAS, refined AAS, or AAS against exact), every answer checked
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
  import     a telemetry export as it comes (its columns, units, ISO time stamps, decimal
             comma), read through a column map, written as the canonical dataset CSV

Run 'fastcal <command> --help' for the flags of a command. Documentation: docs/cli.md.
)";
}  // namespace
}  // namespace fastcal::cli

int main(int argc, char** argv) {
  using namespace fastcal::cli;
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    // Asked for: the usage on stdout, exit 0; no command at all is a usage error.
    (argc < 2 ? std::cerr : std::cout) << kUsage;
    return argc < 2 ? kExitUsage : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::cout << "fastcal " << FASTCAL_VERSION << "\n";
    return 0;
  }
  const std::string command = argv[1];
  try {
    if (command == "solve") return RunSolve(argc, argv);
    if (command == "calibrate") return RunCalibrate(argc, argv);
    if (command == "evaluate") return RunEvaluate(argc, argv);
    if (command == "simulate") return RunSimulate(argc, argv);
    if (command == "workspace") return RunWorkspace(argc, argv);
    if (command == "design") return RunDesign(argc, argv);
    if (command == "import") return RunImport(argc, argv);
    if (command == "track") return RunTrack(argc, argv);
  } catch (const std::bad_alloc&) {
    // Outputs are written last and atomically: nothing is left behind.
    std::cerr << "fastcal " << command
              << ": out of memory: the input or the flags ask for more than this machine has\n";
    return kExitFailure;
  }
  const std::vector<std::string> closest =
      ClosestNames(command, {"solve", "calibrate", "evaluate", "simulate", "workspace", "design"});
  std::cerr << "fastcal: unknown command " << fastcal::internal::Quote(command)
            << (closest.empty() ? "" : "; did you mean " + closest.front() + "?") << "\n\n"
            << kUsage;
  return kExitUsage;
}
