// A vibration record read from a dataset file, chunk by chunk, and checked
// (vibration_record.h).
#include "fastcal/vibration_record.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fastcal/internal/number_text.h"
#include "fastcal/internal/units.h"

namespace fastcal {
namespace {

using internal::kNPerKn;
constexpr int kPoseChannels = 6;
constexpr int kAllChannels = kPoseChannels + kNumCables;
// Samples read at a time: the dataset's chunk (about 2 KB a sample) stays small beside
// the record.
constexpr size_t kChunkSamples = 4096;

std::string Num(double value) { return internal::FormatDouble("%.6g", value); }

// The record as it is read: each sample's time, line and channels.
class RecordBuilder {
 public:
  explicit RecordBuilder(std::string path) : path_(std::move(path)) {}

  // Appends the chunk's samples; false past kMaxRecordSamples, naming the first row beyond.
  bool Add(const Dataset& chunk, std::string* error) {
    if (channels_ == 0 && !chunk.samples.empty()) {
      channels_ = chunk.has_tensions ? kAllChannels : kPoseChannels;
    }
    for (const Sample& s : chunk.samples) {
      if (static_cast<long long>(times_.size()) >= kMaxRecordSamples) {
        *error = Where(s.line) + ": the record has more than " + std::to_string(kMaxRecordSamples) +
                 " samples, the most a vibration record may hold (a free decay of FAST's "
                 "modes is over within an hour: cut the record to the decay, or sample it "
                 "more slowly)";
        return false;
      }
      times_.push_back(s.time_s);
      lines_.push_back(s.line);
      const Eigen::Vector3d rpy = RpyDegFromRotation(s.pose.rotation);
      for (int k = 0; k < 3; ++k) values_.push_back(s.pose.position_m[k]);
      for (int k = 0; k < 3; ++k) values_.push_back(rpy[k]);
      for (int i = 0; i < channels_ - kPoseChannels; ++i) {
        values_.push_back(s.tension_n[i] / kNPerKn);
      }
    }
    return true;
  }

  // The record, its interval from evenly increasing times, and its mean pose.
  bool Finish(VibrationRecordFile* out, std::string* error) {
    const long long n = static_cast<long long>(times_.size());
    if (n < 2) {
      *error = path_ + ": a record needs many samples, it has " + std::to_string(n);
      return false;
    }
    double step_s = 0.0;
    if (!CheckSpacing(&step_s, error)) return false;
    out->path = path_;
    out->record.sample_interval_s = (times_.back() - times_.front()) / static_cast<double>(n - 1);
    out->record.channels =
        Eigen::Map<const Eigen::MatrixXd>(values_.data(), channels_, static_cast<Eigen::Index>(n));
    std::vector<double>().swap(values_);
    const Eigen::VectorXd mean = out->record.channels.rowwise().mean();
    out->mean_pose.position_m = mean.head<3>();
    // FAST's attitudes stay far from the +-180 deg wrap: the angles' mean is the attitude's.
    out->mean_pose.rotation = RotationFromRpyDeg(mean[3], mean[4], mean[5]);
    return CheckPoseSpread(*out, error);
  }

 private:
  std::string Where(int line) const { return path_ + ":" + std::to_string(line); }

  // Every step of time_s positive and within kSpacingTolerance of the median step (a
  // step at line L that is not is named there, not at the record's first step).
  bool CheckSpacing(double* median_s, std::string* error) const {
    std::vector<double> steps(times_.size() - 1);
    for (size_t k = 1; k < times_.size(); ++k) steps[k - 1] = times_[k] - times_[k - 1];
    for (size_t k = 0; k < steps.size(); ++k) {
      if (steps[k] > 0.0) continue;
      *error = Where(lines_[k + 1]) + ": time_s " + Num(times_[k + 1]) +
               " s does not increase (line " + std::to_string(lines_[k]) + ": " + Num(times_[k]) +
               " s): a record's times increase, one sample after another";
      return false;
    }
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    *median_s = sorted[sorted.size() / 2];
    for (size_t k = 0; k < steps.size(); ++k) {
      if (std::abs(steps[k] - *median_s) <= kSpacingTolerance * *median_s) continue;
      *error = Where(lines_[k + 1]) + ": time_s steps by " + Num(steps[k]) +
               " s where the record steps by " + Num(*median_s) +
               " s (its median step): the identification needs evenly spaced samples (one "
               "record, no gaps or clock jumps)";
      return false;
    }
    return true;
  }

  // No sample's position further than kMaxPoseSpreadM from the mean: one pose's vibration.
  bool CheckPoseSpread(const VibrationRecordFile& out, std::string* error) const {
    const Eigen::MatrixXd& c = out.record.channels;
    Eigen::Index far = 0;
    const double spread =
        (c.topRows<3>().colwise() - out.mean_pose.position_m).colwise().norm().maxCoeff(&far);
    if (spread <= kMaxPoseSpreadM) return true;
    const Eigen::Vector3d& m = out.mean_pose.position_m;
    *error = Where(lines_[far]) + ": the cabin is " + Num(spread) +
             " m from the record's mean position (" + Num(m.x()) + ", " + Num(m.y()) + ", " +
             Num(m.z()) + ") m, beyond the " + Num(kMaxPoseSpreadM) +
             " m a vibration about one pose may spread (the modes are predicted at that mean, "
             "and they change by about 0.4% a metre): not a vibration record (a survey, a "
             "move?); cut it to a stretch where the cabin holds one pose";
    return false;
  }

  std::string path_;
  int channels_ = 0;
  std::vector<double> times_;
  std::vector<int> lines_;
  std::vector<double> values_;  // channels_ per sample
};

}  // namespace

bool ReadVibrationRecord(const std::string& path, const DatasetReadOptions& options,
                         VibrationRecordFile* record, std::string* error) {
  DatasetChunkReader reader;
  if (!reader.Open(path, options, error)) return false;
  RecordBuilder builder(path);
  Dataset chunk;
  for (bool done = false; !done;) {
    if (!reader.Next(kChunkSamples, &chunk, &done, error) || !builder.Add(chunk, error)) {
      return false;
    }
  }
  return builder.Finish(record, error);
}

bool ParseVibrationRecord(const std::string& text, const std::string& source_name,
                          const DatasetReadOptions& options, VibrationRecordFile* record,
                          std::string* error) {
  Dataset data;
  if (!ParseDataset(text, source_name, options, &data, error)) return false;
  RecordBuilder builder(source_name);
  return builder.Add(data, error) && builder.Finish(record, error);
}

}  // namespace fastcal
