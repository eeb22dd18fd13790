// The fuzz targets (fuzz_targets.h): invariants every reader keeps on any input.
#include "fuzz_targets.h"

#include <stdlib.h>
#include <unistd.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/internal/track_state.h"
#include "fastcal/plausibility.h"
#include "fastcal/pose.h"
#include "fastcal/track_fold.h"
#include "fastcal/trajectory.h"
#include "fastcal/vibration_record.h"

namespace fastcal::fuzz {
namespace {

// Anchor points of the nominal model, which bound a spec's anchor_offset_m[j].
constexpr int kNumAnchorPoints = 3;
// A rotation the readers return is orthonormal to rounding.
constexpr double kRotationTolerance = 1e-9;

// A private directory for the round trips' files, made once per process and removed when
// it exits.
struct Scratch {
  std::string dir;
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};
const std::string& ScratchDir() {
  static const Scratch scratch{[] {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp != nullptr ? tmp : "/tmp") + "/fastcal_fuzz_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) Violation("cannot make a scratch directory");
    return pattern;
  }()};
  return scratch.dir;
}

bool IsRotation(const Eigen::Matrix3d& r) {
  return r.allFinite() && (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <
                              kRotationTolerance;
}

// Bitwise equality of doubles (a round trip is exact; -0 and 0 differ).
bool Same(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }
template <typename M>
bool Same(const M& a, const M& b) {
  for (int k = 0; k < a.size(); ++k) {
    if (!Same(a.data()[k], b.data()[k])) return false;
  }
  return true;
}

void CheckSampleInvariants(const Sample& s) {
  const PlausibilityLimits limits;
  std::string why;
  if (!IsRotation(s.pose.rotation)) Violation("a sample's rotation is not a rotation");
  if (!CheckPosition(s.pose.position_m, limits, &why)) Violation("implausible position: " + why);
  for (double t : s.tension_n) {
    if (!std::isfinite(t) || t < 0.0 || t > limits.max_tension_n) Violation("tension out of range");
  }
}

void CompareSamples(const Sample& a, const Sample& b) {
  const bool same = Same(a.time_s, b.time_s) && Same(a.pose.position_m, b.pose.position_m) &&
                    Same(a.pose.rotation, b.pose.rotation) &&
                    a.has_planned_attitude == b.has_planned_attitude &&
                    Same(a.planned_rotation, b.planned_rotation) &&
                    a.has_unstretched_lengths == b.has_unstretched_lengths;
  if (!same) Violation("a sample differs after write and read (time, pose or attitude)");
  for (int i = 0; i < kNumCables; ++i) {
    if (!Same(a.tension_n[i], b.tension_n[i])) {
      Violation("tension of cable " + std::to_string(i + 1) + " differs after write and read");
    }
    if (a.has_unstretched_lengths && !Same(a.unstretched_length_m[i], b.unstretched_length_m[i])) {
      Violation("unstretched length differs after write and read");
    }
  }
}

}  // namespace

void WindowFoldBytes(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  WindowFold fold;
  std::string error;
  if (!ParseWindowFold(bytes, "fuzz.fold", &fold, &error)) {
    if (error.empty()) Violation("a refused fold without a message");
    return;
  }
  // A fold read has its numbers in the reader's ranges, and what the writer makes of it
  // reads back to the same bytes (the reader may normalise: a flag 2 is true, written 1).
  if (!fold.information.allFinite() || !std::isfinite(fold.chi_square)) {
    Violation("a fold read with numbers out of range");
  }
  const std::string written = SerializeWindowFold(fold);
  WindowFold again;
  if (!ParseWindowFold(written, "fuzz.fold", &again, &error)) {
    Violation("the reader refuses what the writer wrote: " + error);
  }
  if (SerializeWindowFold(again) != written) Violation("a fold differs after write and read");
}

void TrackStateJson(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  int windows = 0;
  std::string error;
  if (!internal::ParseTrackStateText(text, &windows, &error)) {
    if (error.empty()) Violation("a refused state without a message");
    return;
  }
  if (windows < 0) Violation("a negative number of windows");
}

void Violation(const std::string& what) {
  std::fprintf(stderr, "fastcal fuzz invariant broken: %s\n", what.c_str());
  std::abort();
}

void DatasetCsv(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  DatasetReadOptions options;
  options.skip_invalid_rows = size > 0 && (data[0] & 1);  // both modes
  Dataset first;
  std::string error;
  if (!ParseDataset(text, "fuzz.csv", options, &first, &error)) {
    if (error.empty()) Violation("a refused dataset without a message");
    return;
  }
  for (const Sample& s : first.samples) CheckSampleInvariants(s);
  const std::string path = ScratchDir() + "/dataset.csv";
  if (!WriteDataset(path, first, "round trip", &error)) {
    Violation("the writer refuses what the reader accepted: " + error);
  }
  Dataset second;
  if (!ReadDataset(path, DatasetReadOptions(), &second, &error)) {
    Violation("the reader refuses what the writer wrote: " + error);
  }
  if (second.samples.size() != first.samples.size() ||
      second.attitude_as_quaternion != first.attitude_as_quaternion ||
      second.has_planned_attitude != first.has_planned_attitude ||
      second.has_unstretched_lengths != first.has_unstretched_lengths) {
    Violation("the dataset's shape differs after write and read");
  }
  for (size_t n = 0; n < first.samples.size(); ++n) {
    CompareSamples(first.samples[n], second.samples[n]);
  }
}

void VibrationRecordCsv(const uint8_t* data, size_t size) {
  // The identification of a record the reader accepts, when it is short enough that an
  // execution stays well under the fuzzer's 10 s (ERA and a bootstrap of 2 records).
  constexpr long long kMaxIdentifiedSamples = 4000;
  const std::string text(reinterpret_cast<const char*>(data), size);
  VibrationRecordFile file;
  std::string error;
  if (!ParseVibrationRecord(text, "fuzz.csv", DatasetReadOptions(), &file, &error)) {
    if (error.empty()) Violation("a refused record without a message");
    return;
  }
  const VibrationRecord& record = file.record;
  if (record.channels.cols() < 2 || record.channels.cols() > kMaxRecordSamples ||
      !(record.sample_interval_s > 0.0) || !std::isfinite(record.sample_interval_s) ||
      !record.channels.allFinite() || !IsRotation(file.mean_pose.rotation) ||
      !file.mean_pose.position_m.allFinite()) {
    Violation("an accepted record that is not finite, evenly sampled and bounded");
  }
  EraOptions options;
  options.bootstrap_records = 2;
  if (!CheckRecordSampling(record, options, &error)) {
    if (error.empty()) Violation("a refused sampling without a message");
    return;
  }
  if (record.channels.cols() > kMaxIdentifiedSamples) return;
  std::vector<IdentifiedMode> modes;
  if (!IdentifyModesEra(record, options, &modes, &error)) {
    if (error.empty()) Violation("a failed identification without a message");
    return;
  }
  for (const IdentifiedMode& m : modes) {
    if (!(m.frequency_hz >= options.min_frequency_hz &&
          m.frequency_hz <= options.max_frequency_hz) ||
        !std::isfinite(m.frequency_sigma_hz) || !std::isfinite(m.damping_ratio)) {
      Violation("an identified mode outside the band or not finite");
    }
  }
}

void PoseCsv(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<Pose> poses;
  std::vector<double> times;
  std::string error;
  if (!ParsePosesCsv(text, "fuzz.csv", &poses, &times, &error)) {
    if (error.empty()) Violation("a refused pose file without a message");
    return;
  }
  if (poses.empty()) Violation("a pose file accepted without poses");
  if (!times.empty() && times.size() != poses.size()) Violation("one time per pose");
  const PlausibilityLimits limits;
  for (const Pose& p : poses) {
    std::string why;
    if (!IsRotation(p.rotation)) Violation("a pose's rotation is not a rotation");
    if (!CheckPosition(p.position_m, limits, &why)) Violation("implausible position: " + why);
  }
}

void ModelYaml(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  CableRobot first;
  std::string error;
  if (!ParseCableRobotYaml(text, "fuzz.yaml", &first, &error)) {
    if (error.empty()) Violation("a refused model without a message");
    return;
  }
  std::string why;
  if (!first.IsValid(&why)) Violation("an invalid model accepted: " + why);
  const std::string yaml = CableRobotToYaml(first, "round trip");
  CableRobot second;
  if (!ParseCableRobotYaml(yaml, "written.yaml", &second, &error)) {
    Violation("the reader refuses what the writer wrote: " + error + "\n" + yaml);
  }
  if (CableRobotToYaml(second, "round trip") != yaml) {
    Violation("the model differs after write and read:\n" + yaml);
  }
}

void SpecYaml(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  CalibrationSpec first;
  std::string error;
  if (!ParseCalibrationSpecYaml(text, "fuzz.yaml", kNumAnchorPoints, &first, &error)) {
    if (error.empty()) Violation("a refused spec without a message");
    return;
  }
  std::string why;
  if (!first.IsValid(&why)) Violation("an invalid spec accepted: " + why);
  const std::string yaml = CalibrationSpecToYaml(first);
  CalibrationSpec second;
  if (!ParseCalibrationSpecYaml(yaml, "written.yaml", kNumAnchorPoints, &second, &error)) {
    Violation("the reader refuses what the writer wrote: " + error + "\n" + yaml);
  }
  if (CalibrationSpecToYaml(second) != yaml) {
    Violation("the spec differs after write and read:\n" + yaml);
  }
}

}  // namespace fastcal::fuzz
