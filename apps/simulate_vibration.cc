// `fastcal simulate --vibration`: a record of the cabin's free vibration at one pose from
// the linearised model (modal superposition of predicted modes with the damping and noise
// given; modal_identification.h, SimulateVibrationRecord), as a dataset CSV that
// `fastcal modes --data` identifies.
#include <gflags/gflags.h>

#include <iostream>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/modal_identification.h"
#include "fastcal/version.h"

DEFINE_string(excite, "1,2,3", "simulate --vibration: the predicted modes excited (1-based).");
DEFINE_string(damping, "0.005,0.01,0.015",
              "simulate --vibration: a damping ratio per mode (without it: 0.005,0.01,0.015 "
              "for the default modes 1,2,3, else 0.01 each).");
DEFINE_double(amplitude_m, 0.05,
              "simulate --vibration: each mode's largest initial motion of a point of the "
              "cabin (m, at most 1).");
DEFINE_double(duration_s, 400.0, "simulate --vibration: the record's length (s).");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "simulate";
// The record's sampling when --interval-s is not given (a survey's default is 1 s).
constexpr double kVibrationIntervalS = 0.1;
// Each excited mode's damping ratio when --damping is not given and --excite is not the
// default's modes (issue 59: --excite=25 complained of a --damping never given): 1%, in
// the middle of FAST's 0.4-1.5%.
constexpr double kDefaultDampingRatio = 0.01;

bool SpecFromFlags(VibrationRecordSpec* spec, std::string* error) {
  std::vector<double> excite;
  if (!ParseNumberList("excite", FLAGS_excite, &excite, error) ||
      !ParseNumberList("damping", FLAGS_damping, &spec->damping_ratio, error)) {
    return false;
  }
  spec->modes.clear();
  for (double m : excite) {
    if (m != static_cast<int>(m) || m < 1 || m > 200) {
      *error = "--excite=" + FLAGS_excite + ": modes are whole numbers from 1 to 200";
      return false;
    }
    spec->modes.push_back(static_cast<int>(m));
  }
  for (double z : spec->damping_ratio) {
    if (!(z > 0.0 && z < 0.5)) {
      *error = "--damping=" + FLAGS_damping + ": each damping ratio in (0, 0.5)";
      return false;
    }
  }
  if (!FlagGiven("damping") && spec->modes != std::vector<int>{1, 2, 3}) {
    spec->damping_ratio.assign(spec->modes.size(), kDefaultDampingRatio);
  }
  if (spec->damping_ratio.size() != spec->modes.size()) {
    *error = "--damping gives " + std::to_string(spec->damping_ratio.size()) + " ratios for " +
             std::to_string(spec->modes.size()) + " --excite modes: give one ratio per mode";
    return false;
  }
  spec->sample_interval_s = FlagGiven("interval-s") ? FLAGS_interval_s : kVibrationIntervalS;
  if (!(spec->sample_interval_s > 0.0) || !(FLAGS_duration_s > 10 * spec->sample_interval_s) ||
      !(FLAGS_duration_s <= 1e6)) {
    *error = "--interval-s > 0 and --duration-s of at least 10 intervals (at most 1e6 s)";
    return false;
  }
  spec->duration_s = FLAGS_duration_s;
  spec->amplitude_m = FLAGS_amplitude_m;
  spec->position_noise_m = FLAGS_position_noise_m;
  spec->attitude_noise_deg = FLAGS_attitude_noise_deg;
  spec->tension_noise_kn = FLAGS_tension_noise_kN;
  spec->seed = FLAGS_seed;
  spec->modes_options.segments = FLAGS_segments;
  if (spec->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"amplitude_m", "--amplitude-m"},
                                  {"sample_interval_s", "--interval-s"},
                                  {"duration_s", "--duration-s"},
                                  {"segments", "--segments"}});
  return false;
}

// Writes the record as dataset CSV to `path` a MiB at a time, through the same atomic
// publishing as every output (a temporary renamed into place, over an existing file only
// with `replace`): the record's text is never whole in memory (10^6 samples, 193 MB of
// text, peaked at 480 MB when it was).
bool WriteRecordCsv(const std::string& path, const VibrationRecord& record,
                    const std::string& header, bool replace, std::string* error) {
  constexpr size_t kChunkBytes = 1 << 20;
  internal::AtomicFileWriter writer;
  if (!writer.Open(path, error)) return false;
  std::string chunk = header;
  chunk += "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n";
  for (int k = 0; k < record.channels.cols(); ++k) {
    chunk += FormatDouble(k * record.sample_interval_s, 12);
    for (int c = 0; c < record.channels.rows(); ++c) {
      chunk += ',';
      chunk += FormatDouble(record.channels(c, k), 12);
    }
    chunk += '\n';
    if (chunk.size() < kChunkBytes) continue;
    if (!writer.Write(chunk, error)) return false;
    chunk.clear();
  }
  return writer.Write(chunk, error) && writer.Commit(replace, error);
}

// "damping ratios 0.005, 0.01, 0.015; noise: none (...)": what the record holds besides
// the modes (issue 59: the summary said nothing of the noise, which is 0 by default).
std::string DampingAndNoise(const VibrationRecordSpec& spec) {
  std::string text = "damping ratios";
  for (size_t i = 0; i < spec.damping_ratio.size(); ++i) {
    text += (i == 0 ? " " : ", ") + FormatDouble(spec.damping_ratio[i], 4);
  }
  if (spec.position_noise_m == 0.0 && spec.attitude_noise_deg == 0.0 &&
      spec.tension_noise_kn == 0.0) {
    return text +
           "; noise: none (--position-noise-m, --attitude-noise-deg and --tension-noise-kN "
           "are 0 unless given)";
  }
  return text + "; white noise, sigma: position " + FormatDouble(spec.position_noise_m, 4) +
         " m, attitude " + FormatDouble(spec.attitude_noise_deg, 4) + " deg, tensions " +
         FormatDouble(spec.tension_noise_kn, 4) + " kN";
}

}  // namespace

const std::set<std::string>& VibrationFlags() {
  static const std::set<std::string> flags = {"vibration",
                                              "truth",
                                              "position",
                                              "rpy",
                                              "quat",
                                              "rotvec",
                                              "attitude-law",
                                              "tilt-fraction",
                                              "focal-centre",
                                              "excite",
                                              "damping",
                                              "amplitude-m",
                                              "duration-s",
                                              "interval-s",
                                              "position-noise-m",
                                              "attitude-noise-deg",
                                              "tension-noise-kN",
                                              "seed",
                                              "segments",
                                              "out",
                                              "force"};
  return flags;
}

int RunSimulateVibration(int argc, char** argv) {
  std::string error, attitude;
  CableRobot robot;
  Pose pose;
  VibrationRecordSpec spec;
  if (FLAGS_out.empty() || FLAGS_out == "-") {
    PrintError(kCommand, "give --out=FILE.csv");
    return kExitUsage;
  }
  if (!CheckCanWrite("out", FLAGS_out, FLAGS_force, &error) ||
      !LoadModelFlag("truth", FLAGS_truth, &robot, &error) ||
      !SinglePoseFromFlags(&pose, &attitude, &error) || !SpecFromFlags(&spec, &error)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  VibrationRecord record;
  if (!SimulateVibrationRecord(robot, pose, spec, &record, &error)) {
    PrintError(kCommand, WithFlagNames(error, {{"amplitude_m", "--amplitude-m"}}));
    return kExitFailure;
  }
  const std::string header = "# Simulated by fastcal " + std::string(FASTCAL_VERSION) +
                             ": a free vibration from the linearised model\n# " +
                             CommandLine(argc, argv, {"force"}) + "\n";
  if (!WriteRecordCsv(FLAGS_out, record, header, FLAGS_force, &error)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  std::cout << "fastcal simulate --vibration: " << record.channels.cols() << " samples every "
            << FormatDouble(spec.sample_interval_s) << " s of modes " << FLAGS_excite << " at "
            << attitude << ", written to " << FLAGS_out << "\n  " << DampingAndNoise(spec)
            << std::endl;
  return 0;
}

}  // namespace fastcal::cli
