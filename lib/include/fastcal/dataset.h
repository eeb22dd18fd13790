// The measurement dataset: a CSV telemetry export of measured cabin poses and measured
// lower-end cable tensions (format: docs/data-format.md), its reader and writer.
//
// Files give tensions in kN (column names say so: T1_kN ... T6_kN); in memory they are in
// N, like every other quantity in the library. The kN <-> N conversion is done on the
// decimal text (the exponent is shifted by 3), so a write/read round trip is bit-exact.
#ifndef FASTCAL_DATASET_H_
#define FASTCAL_DATASET_H_

#include <Eigen/Core>
#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/column_map.h"
#include "fastcal/plausibility.h"
#include "fastcal/pose.h"
#include "fastcal/time_text.h"

namespace fastcal {

// One row of the dataset: one instant of telemetry.
struct Sample {
  // 1-based line of the row in the file it was read from (0 for samples built in code).
  int line = 0;
  double time_s = 0.0;
  // Measured position of the cabin-frame origin and measured attitude, global frame.
  Pose pose;
  // The measured attitude as the file gives it (only the one matching
  // Dataset::attitude_as_quaternion is filled by the reader). WriteDataset writes these
  // numbers when they reproduce pose.rotation exactly, so a read/write round trip keeps
  // them bit for bit; otherwise it writes the attitude converted from pose.rotation.
  // Code that builds samples may leave them at their defaults and set pose.rotation only.
  Eigen::Vector3d measured_rpy_deg = Eigen::Vector3d::Zero();
  Eigen::Vector4d measured_quaternion_wxyz = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);
  // Planned (commanded) attitude, when the file has the planned_*_deg columns.
  bool has_planned_attitude = false;
  Eigen::Matrix3d planned_rotation = Eigen::Matrix3d::Identity();
  // As in the file; written when it reproduces planned_rotation exactly (as above).
  Eigen::Vector3d planned_rpy_deg = Eigen::Vector3d::Zero();
  // Measured lower-end cable tensions, cable i at index i-1 (>= 0: 0 is a dropout, which
  // a calibration flags as a gross error; at most PlausibilityLimits::max_tension_n).
  std::array<double, kNumCables> tension_n{};
  // The winches' length readings, when the file has the s0_*_m columns (> 0): each cable's
  // unstretched length as its encoder gives it (commanded or measured), the model's s0
  // plus CableProperties::length_offset_m.
  bool has_unstretched_lengths = false;
  std::array<double, kNumCables> unstretched_length_m{};
  // The survey (session) the sample belongs to: an index into Dataset::session_labels,
  // 0 when the dataset has no sessions.
  int session = 0;
  // The cabin's moving parts' joint values (moving_parts.h), when the file has joint
  // columns: in Dataset::joint_columns order and in those columns' units (deg for a
  // column ending in _deg, m for _m), as the file gives them, so that a write/read round
  // trip is exact; MovingParts::ShiftsAt converts to SI. Read with a model's
  // columns (DatasetReadOptions::joint_columns), that is the model's joint order.
  JointValues joint{};
};

// A session label (the `session` column, or a file's stem): 1 to kMaxSessionLabelLength
// letters, digits, '-' and '_', so that it can end a parameter name (NAME@LABEL) and a
// file name (model_calibrated@LABEL.yaml) unquoted.
inline constexpr int kMaxSessionLabelLength = 64;
bool IsValidSessionLabel(const std::string& label);

struct Dataset {
  // The file (or source name) the dataset was read from; used in messages.
  std::string path;
  std::vector<Sample> samples;  // in file order
  // Which optional column groups the file has (then every sample has them).
  bool has_planned_attitude = false;
  bool has_unstretched_lengths = false;
  // Measured attitude given as qw,qx,qy,qz (true) or roll_deg,pitch_deg,yaw_deg (false).
  bool attitude_as_quaternion = false;
  // Always true for a measurement file; a lengths file (DatasetColumns::kLengths) may
  // lack any of these groups, whose values are then 0 (the identity attitude) and unused.
  bool has_time = true;
  bool has_position = true;
  bool has_measured_attitude = true;
  bool has_tensions = true;
  // The sessions, in the order of their first sample (docs/data-format.md, "Sessions"):
  // from the file's `session` column, or one per file when several files are merged
  // (sessions.h). Empty: no session column, one survey.
  std::vector<std::string> session_labels;
  // With files merged (sessions.h): the file each session came from, parallel to
  // session_labels; empty otherwise.
  std::vector<std::string> session_paths;
  // The joint columns the file has (DatasetReadOptions::joint_columns; Sample::joint);
  // empty for a cabin without moving parts.
  std::vector<std::string> joint_columns;
  // One message per row skipped under DatasetReadOptions::skip_invalid_rows, in file
  // order, formatted like the error the row would otherwise have caused ("file:line: ...");
  // then those of samples removed by SkipUnsolvableSamples (evaluation.h).
  std::vector<std::string> skipped;
  // The zone Unix times (time_text.h: time_s >= 1e8 s) are shown in by reports, plots and
  // messages, in seconds east of UTC: the column map's time zone when the file was read
  // through one, else 0 (UTC). time_s itself is always UTC.
  int time_offset_s = 0;
};

// The columns a file must have (docs/data-format.md).
enum class DatasetColumns {
  // A measurement file (calibrate, evaluate): time_s, the position, the measured attitude
  // and the six tensions; the planned attitude and the lengths optional.
  kMeasurements,
  // A lengths file (fastcal locate): the six s0_<i>_m; time_s, the position, the measured
  // attitude, the planned attitude and the tensions optional, each group complete or absent.
  kLengths,
};

struct DatasetReadOptions {
  DatasetColumns required_columns = DatasetColumns::kMeasurements;
  // When true, a row with a problem in its values (wrong number of fields, a missing,
  // non-numeric or non-finite value, a value beyond `limits` below, a non-unit quaternion)
  // is skipped and listed in Dataset::skipped instead of failing the read.
  // Header errors are never skipped, and a file whose rows are all skipped is an error.
  bool skip_invalid_rows = false;
  // ReadDataset reads only a regular file of at most this many bytes, refusing a larger
  // one, a device (/dev/zero), a pipe or a directory before reading (docs/data-format.md,
  // "Limits"). 1 GiB is about 4 million rows of 24 columns, days of telemetry at 10 Hz.
  long long max_file_bytes = 1LL << 30;
  // Values no real FAST file holds (a tension above 5000 kN or < 0, a position below the
  // reflector or beyond the towers, an angle beyond one turn) are errors naming the line
  // and column, or skipped rows under skip_invalid_rows. A reading of 0 kN (a dropout) is
  // accepted: the calibration flags it as a gross error.
  PlausibilityLimits limits;
  // Threads that parse rows (ReadDataset, DatasetChunkReader): rows are parsed in batches
  // in parallel and taken in file order, so the samples, skipped rows and messages are
  // the same on any number. >= 1; default 1.
  int threads = 1;
  // The moving parts' joint columns the file must have (MovingParts::JointColumns of the
  // model it is read for, in that order; each ends in _deg or _m): read into
  // Sample::joint. A file lacking any is an error naming every one it lacks; a joint
  // column read without being asked for is an unknown column. Empty: none.
  std::vector<std::string> joint_columns;
  // The model's joints in that order (MovingParts::Joints), when their stated ranges are
  // checked: a value outside its joint's range is refused as an implausible one is (issue
  // 57: `evaluate` took joints outside the model's range). Empty: plausibility only.
  // SetJointColumns fills both from a model's moving parts.
  std::vector<Joint> joints;
  // Read the file as an export through this column map (column_map.h, docs/data-format.md,
  // "Column maps"): its delimiter, decimal mark, header line, source columns, units and
  // time stamps; null: the canonical format above. Messages then name the source column
  // and the fastcal name ("data.csv:12: column 'CableForce3' (T3_kN, N): 'abc' is not a
  // number"), and those about the map its file, line and key.
  std::shared_ptr<const ColumnMap> columns;
};

// The read options for a model's moving parts: DatasetReadOptions::joint_columns and
// ::joints (their ranges checked as each value is read).
void SetJointColumns(const MovingParts& parts, DatasetReadOptions* options);

// Whether `data` has the joint columns the moving parts need, in the model's joint order
// (as ReadDataset gives them with DatasetReadOptions::joint_columns =
// parts.JointColumns()). On failure names the file and every column it lacks.
bool CheckJointColumns(const Dataset& data, const MovingParts& parts, std::string* error);

// How the dataset's times read (time_text.h): dates and times in its zone
// (Dataset::time_offset_s) when its earliest time is a Unix time (>= 1e8 s), seconds
// otherwise.
TimeDisplay TimeDisplayOf(const Dataset& data);

// "<file>:<line>" of a sample, for messages: the file of its session when the dataset was
// merged from several (Dataset::session_paths), else Dataset::path.
std::string SampleWhere(const Dataset& data, const Sample& sample);

// Reads a dataset file. On failure returns false and sets *error to a message naming the
// file, the 1-based line and, where there is one, the column, e.g.
//   data.csv:12: column 'T3_kN': 'abc' is not a number
// *dataset is only written on success.
bool ReadDataset(const std::string& path, const DatasetReadOptions& options, Dataset* dataset,
                 std::string* error);
// Same, from the file's text; `source_name` stands for the file name in messages and
// becomes Dataset::path.
bool ParseDataset(const std::string& text, const std::string& source_name,
                  const DatasetReadOptions& options, Dataset* dataset, std::string* error);

// Reads a dataset file a chunk of rows at a time, for files too long to hold (fastcal
// evaluate at 10^6 samples): memory bounded by the chunk, not the file. Every row is
// checked as ReadDataset checks it, with the same messages (file, line, column), and
// the same options (skip_invalid_rows, max_file_bytes, limits); the checks of the
// whole file (no header, no data rows, every row skipped, angles that look like radians)
// are made after the last row, by the Next that sets *done. Concatenating the chunks'
// samples and skipped rows gives ReadDataset's.
// Longest line DatasetChunkReader reads (a dataset's rows and header are under 1 KiB): a
// longer one is refused as soon as it is seen, with memory and time bounded by it.
inline constexpr size_t kMaxDatasetLineBytes = size_t{1} << 20;  // 1 MiB

class DatasetChunkReader {
 public:
  DatasetChunkReader();
  DatasetChunkReader(const DatasetChunkReader&) = delete;
  DatasetChunkReader& operator=(const DatasetChunkReader&) = delete;
  ~DatasetChunkReader();

  // Opens `path`, refusing what ReadDataset refuses before reading (a directory, device,
  // pipe, a file larger than options.max_file_bytes).
  bool Open(const std::string& path, const DatasetReadOptions& options, std::string* error);
  // Replaces chunk->samples and chunk->skipped by the next at most `max_samples` (>= 1)
  // valid samples and the rows skipped before the last of them, and sets chunk's path,
  // column flags and session labels (those met so far; sample.session indexes them).
  // *done: the file is finished and passed the whole-file checks (the chunk may still
  // hold samples). False, with the message ReadDataset would give, on an error.
  bool Next(size_t max_samples, Dataset* chunk, bool* done, std::string* error);
  // As Next, but appends the samples and skipped rows to data->samples and data->skipped
  // (ReadDataset: no copy of each chunk into the whole).
  bool Append(size_t max_samples, Dataset* data, bool* done, std::string* error);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Writes `dataset` in the format ReadDataset reads: `header_comment` (may be empty, may
// have several lines) as leading '# ' lines, then the columns
//   time_s, x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg (or qw, qx, qy, qz when
//   dataset.attitude_as_quaternion), planned_roll_deg, planned_pitch_deg,
//   planned_yaw_deg (if dataset.has_planned_attitude), T1_kN ... T6_kN,
//   s0_1_m ... s0_6_m (if dataset.has_unstretched_lengths), session (if
//   dataset.session_labels is not empty: the label of each sample's session).
// Numbers are written with the fewest significant digits (at most 17) that read back to
// the same double, so Write then Read is exact. Refuses (returns false) data the reader
// would reject with its default options: non-finite values, values beyond the default
// PlausibilityLimits, unstretched lengths <= 0, a sample lacking
// a column group the dataset declares, no samples. Writes atomically (temporary file in
// the same directory, then rename): a failure leaves no file behind.
bool WriteDataset(const std::string& path, const Dataset& dataset,
                  const std::string& header_comment, std::string* error);

// The same file written row by row, for data too long to hold (fastcal simulate at 10^6
// samples): memory independent of the number of rows. Open creates `path` (refusing an
// existing file) and writes the header comment and the column line of `layout`'s column
// groups (its flags; its samples are not read); Write appends one sample's row, refusing
// what WriteDataset refuses; Close flushes, syncs and closes, and refuses a file of no
// rows. Not atomic: write to a temporary name and rename (and remove it on failure).
// The open file holds an flock(2) (internal/atomic_file.h: a temporary in use).
class DatasetWriter {
 public:
  DatasetWriter() = default;
  DatasetWriter(const DatasetWriter&) = delete;
  DatasetWriter& operator=(const DatasetWriter&) = delete;
  ~DatasetWriter();  // closes the file if still open (it is left as written so far)

  bool Open(const std::string& path, const Dataset& layout, const std::string& header_comment,
            std::string* error);
  bool Write(const Sample& sample, std::string* error);
  // The session labels grown as a reader meets them (DatasetChunkReader: a chunk's
  // session_labels are those met so far): `labels` replaces the layout's when it opened
  // with labels (a session column) and begins with them. For streamed copies.
  void UpdateSessionLabels(const std::vector<std::string>& labels);
  bool Close(std::string* error);
  // Whether a failure was the file's (a write, flush, sync or close: a full disk), not a
  // sample's value.
  bool io_failed() const { return io_failed_; }

 private:
  bool Flush(std::string* error);

  std::string path_;
  Dataset layout_;
  std::vector<int> columns_;
  std::string buffer_;
  size_t rows_ = 0;
  bool io_failed_ = false;
  std::FILE* file_ = nullptr;
};

}  // namespace fastcal

#endif  // FASTCAL_DATASET_H_
