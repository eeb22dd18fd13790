// `fastcal modes --data=FILE`: the dominant modes of a record of the cabin's vibration,
// free (ERA, modal_identification.h) or ambient (SSI-cov, subspace_identification.h; by
// --identification, or chosen by the record's envelope: a falling one is a free decay),
// compared with the prediction at the record's pose, and what the differences point to.
#include <gflags/gflags.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

#include "cli_util.h"
#include "columns_flag.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/dataset.h"
#include "fastcal/internal/csv.h"
#include "fastcal/modal_identification.h"
#include "fastcal/subspace_identification.h"
#include "fastcal/vibration_record.h"

DEFINE_int32(identified_modes, 3, "modes --data: how many dominant modes to identify.");
DEFINE_string(identification, "auto",
              "modes --data: era (a free decay) | ssi (an ambient record) | auto (era when "
              "the record's envelope falls by 4x in mean square from its first quarter to its "
              "last, else ssi).");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "modes";
std::string ComparisonSummary(const ModesComparisonResult& r, const Pose& pose,
                              const std::string& method) {
  std::ostringstream s;
  s << "fastcal modes --data: " << r.modes.size() << " modes identified (" << method
    << "), predicted at the "
    << "record's mean pose (" << FormatDouble(pose.position_m.x(), 5) << ", "
    << FormatDouble(pose.position_m.y(), 5) << ", " << FormatDouble(pose.position_m.z(), 5)
    << ") m";
  for (const ModeComparison& c : r.modes) {
    s << "\n  " << FormatDouble(c.identified.frequency_hz, 5) << " +- "
      << FormatDouble(c.identified.frequency_sigma_hz, 2) << " Hz, damping "
      << FormatDouble(100 * c.identified.damping_ratio, 3) << " +- "
      << FormatDouble(100 * c.identified.damping_sigma, 2) << "%; predicted mode "
      << c.predicted_mode << " " << FormatDouble(c.predicted_hz, 5) << " Hz ("
      << (c.predicted_cabin_share > 0.5 ? "cabin" : "cable")
      << "): " << FormatDouble(100 * c.difference, 3) << " +- "
      << FormatDouble(100 * c.difference_sigma, 2) << "%";
  }
  s << "\n  against the model as it is: chi2 " << FormatDouble(r.chi2_model, 3) << " for "
    << r.modes.size() << " degrees of freedom: "
    << (r.agrees ? "the record agrees with the model" : "the record disagrees with the model");
  s << "\n  each parameter alone (the change that explains the differences best, chi2 for "
    << (r.modes.size() > 0 ? r.modes.size() - 1 : 0) << " degrees of freedom):";
  for (int p = 0; p < kModeParameters; ++p) {
    const ParameterFit& f = r.fits[p];
    s << "\n    " << ModeParameterName(p) << " " << FormatDouble(100 * f.relative_change, 3)
      << " +- " << FormatDouble(100 * f.sigma, 2) << "%, chi2 " << FormatDouble(f.chi2, 3)
      << (p == r.best && !r.agrees ? "  <- the best single explanation" : "");
  }
  return s.str();
}

}  // namespace

int RunModesIdentify(const CableRobot& robot, const ModesOptions& options, bool to_file) {
  std::string error;
  for (const char* flag : {"position", "rpy", "quat", "rotvec", "attitude-law", "cap"}) {
    if (FlagGiven(flag)) {
      PrintError(kCommand, std::string("--") + flag +
                               " does not apply to --data: the record gives its own pose");
      return kExitUsage;
    }
  }
  if (FLAGS_identification != "auto" && FLAGS_identification != "era" &&
      FLAGS_identification != "ssi") {
    PrintError(kCommand, "--identification=" + FLAGS_identification +
                             ": must be era (a free decay), ssi (an ambient record) or auto");
    return kExitUsage;
  }
  DatasetReadOptions read;
  VibrationRecordFile file;
  EraOptions era;
  SsiOptions ssi;
  era.modes = ssi.modes = FLAGS_identified_modes;
  if (!era.IsValid(&error) || !ssi.IsValid(&error)) {
    PrintError(kCommand, WithFlagNames(error, {{"modes", "--identified-modes"}}));
    return kExitUsage;
  }
  if (!ColumnsFromFlag(&read.columns, &error) ||
      !ReadVibrationRecord(FLAGS_data, read, &file, &error)) {
    PrintError(kCommand,
               (error.rfind("the record", 0) == 0 ? "--data=" + FLAGS_data + ": " : "") + error);
    return kExitUsage;
  }
  const VibrationRecord& record = file.record;
  const Pose& pose = file.mean_pose;
  std::string method = FLAGS_identification;
  const double decay = EnvelopeDecayRatio(record);
  if (method == "auto") method = decay >= kFreeDecayRatio ? "era" : "ssi";
  // A free decay's sampling and length are checked before the work (issue 57); an
  // ambient record may run for hours, and SSI says itself when it is too short.
  if (method == "era" && !CheckRecordSampling(record, era, &error)) {
    PrintError(kCommand, "--data=" + FLAGS_data + ": " + error);
    return kExitUsage;
  }
  const std::string described =
      (method == "era" ? "ERA" : "SSI-cov") +
      (FLAGS_identification == "auto"
           ? std::string(", chosen: the envelope's mean square falls ") + FormatDouble(decay, 3) +
                 "x from the first quarter to the last, " +
                 (method == "era" ? "a free decay" : "an ambient record") + " (era from " +
                 FormatDouble(kFreeDecayRatio, 2) + "x)"
           : std::string());
  std::vector<IdentifiedMode> identified;
  ModesComparisonResult comparison;
  const bool found = method == "era" ? IdentifyModesEra(record, era, &identified, &error)
                                     : IdentifyModesSsi(record, ssi, &identified, &error);
  if (!found) {
    PrintError(kCommand, "--data=" + FLAGS_data + ": " + described + ": " + error +
                             " (--identified-modes=" + std::to_string(FLAGS_identified_modes) +
                             ")");
    return kExitFailure;
  }
  if (!CompareWithPrediction(robot, pose, identified, options, &comparison, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  if (!WriteOutput(to_file ? FLAGS_output : "-", ModesComparisonCsv(comparison), &error, FLAGS_force)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  (to_file ? std::cout : std::cerr) << ComparisonSummary(comparison, pose, described) << std::endl;
  return 0;
}

}  // namespace fastcal::cli
