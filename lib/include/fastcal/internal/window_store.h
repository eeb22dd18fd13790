// A track's samples sorted into windows, one binary file per window (docs/calibration.md,
// "Tracking: files"): what a window's fold reads, on this machine or on a Dask worker
// that sees the same path, without parsing the telemetry again.
//
// Each sample is one record of little-endian fields:
//   time_s (f64), line (i32), file (i32: index into the track's files),
//   position_m[3] (f64), rotation[9] (f64, row-major: the attitude the fit uses, measured
//   or planned as the spec says), tension_n[6] (f64),
//   and for a model with moving parts joint[J] (f64, the model's J joints: Sample::joint)
// 160 + 8 J bytes (160 for a rigid cabin, as before moving parts), in the order the
// samples were read; a fold sorts them by time (stably).
#ifndef FASTCAL_INTERNAL_WINDOW_STORE_H_
#define FASTCAL_INTERNAL_WINDOW_STORE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "fastcal/dataset.h"

namespace fastcal::internal {

struct StoredSample {
  double time_s;
  std::int32_t line;
  std::int32_t file;
  double position_m[3];
  double rotation[9];
  double tension_n[6];
  double joint[kMaxJoints];  // the first `joints` of them on disk (RecordBytes)
};
static_assert(sizeof(StoredSample) == 160 + 8 * kMaxJoints, "the store's record layout");

// A record's bytes on disk for a model of `joints` joints (0..kMaxJoints).
inline long long RecordBytes(int joints) { return 160 + 8LL * joints; }

// The record of a sample (its attitude: the planned one when `planned`).
StoredSample ToStored(const Sample& sample, int file, bool planned);

// Appends records of `joints` joints each to `path` (created if absent).
bool AppendStoredSamples(const std::string& path, const std::vector<StoredSample>& samples,
                         int joints, std::string* error);

// A window's records in time order (stably sorted), read a range at a time: a fold's
// passes stream a window through it, so that its samples are never all in memory as
// Samples (issue 27: 10^5 samples a window, ~1 kB each, twice at once). A store appended
// in time order (files each in time order, given in turn: the usual case) is read where
// its records lie; one that is not is sorted once in memory, its records alone (160
// bytes a sample).
class StoredWindowReader {
 public:
  StoredWindowReader() = default;
  StoredWindowReader(const StoredWindowReader&) = delete;
  StoredWindowReader& operator=(const StoredWindowReader&) = delete;
  ~StoredWindowReader();

  // Reads every record once: refuses a file whose size is not a whole number of records,
  // and a record that is not finite (named by its index in the file).
  bool Open(const std::string& path, int joints, std::string* error);
  long long size() const { return size_; }
  // Records [first, first + count) of the time order as samples (pose: the stored
  // attitude; session 0) and each one's file index. Safe from several threads at once.
  bool Read(long long first, int count, std::vector<Sample>* samples, std::vector<int>* file_of,
            std::string* error) const;
  // As Read, of the records first, first + step, ... (count of them): only those are
  // converted (a subsample's fold read and converted every record of its spans).
  bool ReadEvery(long long first, int count, int step, std::vector<Sample>* samples,
                 std::vector<int>* file_of, std::string* error) const;

 private:
  std::string path_;
  int fd_ = -1;
  long long size_ = 0;
  int joints_ = 0;
  std::vector<StoredSample> sorted_;  // the records, when the file is not in time order
};

// Reads a window's records into data->samples, sorted by time (stably), and each one's
// file index into *file_of (parallel to the samples). Refuses what Open refuses.
bool ReadStoredWindow(const std::string& path, int joints, Dataset* data,
                      std::vector<int>* file_of, std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_WINDOW_STORE_H_
