// A record of the cabin's free vibration read from a dataset file (`fastcal modes
// --data`): its channels (x, y, z in m, roll, pitch, yaw in deg, and the six tensions in
// kN when the file has them), its sample interval and its mean pose, checked against what
// a record can hold before the identification (modal_identification.h) sees it.
//
// What is checked (issue 57: a record re-stamped every 1e-12 s gave modes at 1.5e10 Hz,
// one every 1e3 s modes at 1.5e-8 Hz, and a 1 h clock jump at line 2004 was blamed on
// line 3): times that increase evenly (each step within kSpacingTolerance of the
// record's median step, a step that is not named by its line), at most kMaxRecordSamples
// samples (refused at the first row beyond, before the rest is read). Whether the interval
// and span suit the modes sought is the identification's check (EraOptions). The record
// is one of a vibration about one pose (issue 59: a survey day, its poses tens of metres
// apart, gave three "modes" at a mean pose the cabin never visited): no sample's position
// further than kMaxPoseSpreadM from the record's mean.
//
// The file is read a chunk at a time (DatasetChunkReader): memory is the record's, 108
// bytes a sample (its 12 channels, time and line), not the dataset's 2.2 KB a sample.
#ifndef FASTCAL_VIBRATION_RECORD_H_
#define FASTCAL_VIBRATION_RECORD_H_

#include <string>

#include "fastcal/dataset.h"
#include "fastcal/modal_identification.h"
#include "fastcal/pose.h"

namespace fastcal {

// How far a step of time_s may be from the record's median step, as a fraction of it:
// ERA takes evenly spaced samples (its Hankel matrices shift by one sample), and a
// logger's clock jitters by far less than 1% of its interval.
inline constexpr double kSpacingTolerance = 0.01;

// How far a sample's position may lie from the record's mean position (m): the modes are
// predicted at that mean, and near the zenith the lowest mode's frequency moves by about
// 0.4% a metre (-0.8% at 2 m off the axis), an identification's uncertainty; a free decay
// from `fastcal simulate --vibration` moves the cabin by at most 1.2 m (three modes at the
// largest --amplitude-m, 1 m). An attitude spread is not bounded: such a decay turns the
// cabin by up to 13 deg, as far as a survey's focal law does.
inline constexpr double kMaxPoseSpreadM = 2.0;

struct VibrationRecordFile {
  VibrationRecord record;
  Pose mean_pose;  // the channels' mean pose: where the modes are predicted
  std::string path;
};

// Reads `path` as a dataset (`options`: a column map, joint columns...) into a record.
// False with *error naming the file and line: an unreadable dataset, fewer than two
// samples, more than kMaxRecordSamples, times that do not increase evenly, a position
// further than kMaxPoseSpreadM from the mean (named by its line).
bool ReadVibrationRecord(const std::string& path, const DatasetReadOptions& options,
                         VibrationRecordFile* record, std::string* error);
// The same from the file's text (`source_name` in messages): the fuzz target's entry.
bool ParseVibrationRecord(const std::string& text, const std::string& source_name,
                          const DatasetReadOptions& options, VibrationRecordFile* record,
                          std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_VIBRATION_RECORD_H_
