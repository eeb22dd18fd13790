// Writer of the measurement dataset CSV (docs/data-format.md; declarations: dataset.h;
// the reader: dataset.cc): the shortest decimal text of each number that the reader reads
// back to the same double, a kN column's exponent shifted, so Write then Read is exact.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "data/dataset_columns.h"
#include "fastcal/dataset.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/plausibility.h"
#include "fastcal/pose.h"

namespace fastcal {
namespace {

using namespace internal::dataset_columns;  // NOLINT: the file's own columns

// WriteDataset refuses a pose.rotation farther than this (max |R^T R - I| entry) from a
// rotation: it could not be written as angles or a quaternion.
constexpr double kRotationTolerance = 1e-6;

// The shortest decimal text that ParseNumber reads back as value * 10^-shift exactly
// after the reader shifts it back (shift 0: plain shortest round-trip formatting). Plain
// notation for moderate exponents, scientific otherwise. `value` must be finite.
std::string FormatNumber(double value, int shift) {
  if (value == 0.0) return "0";  // -0 too: the same reading, and "-0" puzzles a reader
  char buffer[64];
  const std::to_chars_result result =
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::scientific);
  std::string_view s(buffer, static_cast<size_t>(result.ptr - buffer));  // "-1.5917e+05"
  std::string out;
  if (s.front() == '-') {
    out = "-";
    s.remove_prefix(1);
  }
  const size_t e = s.find('e');
  std::string digits;
  for (char c : s.substr(0, e)) {
    if (c != '.') digits += c;
  }
  const std::string exponent_text(s.substr(e + 1));
  // value = d0.d1d2... * 10^exponent
  const long exponent = std::strtol(exponent_text.c_str(), nullptr, 10) - shift;
  const long n = static_cast<long>(digits.size());
  if (exponent >= 0 && exponent <= 16) {
    if (n <= exponent + 1) {
      out += digits + std::string(static_cast<size_t>(exponent + 1 - n), '0');
    } else {
      out += digits.substr(0, static_cast<size_t>(exponent + 1)) + "." +
             digits.substr(static_cast<size_t>(exponent + 1));
    }
  } else if (exponent < 0 && exponent >= -5) {
    out += "0." + std::string(static_cast<size_t>(-exponent - 1), '0') + digits;
  } else {
    out += digits.substr(0, 1);
    if (n > 1) out += "." + digits.substr(1);
    out += "e" + std::to_string(exponent);
  }
  return out;
}

bool IsRotation(const Eigen::Matrix3d& r) {
  return r.allFinite() &&
         ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <=
          kRotationTolerance) &&
         r.determinant() > 0.0;
}

// The numbers of one row in column order (columns the dataset does not write are left 0),
// or false with a reason.
bool RowValues(const Dataset& dataset, const Sample& s, std::array<double, kNumColumns>* value,
               std::string* reason) {
  if (!IsRotation(s.pose.rotation)) {
    *reason = "pose.rotation is not a finite rotation matrix";
    return false;
  }
  auto& v = *value;
  v[kTime] = s.time_s;
  for (int k = 0; k < 3; ++k) v[kX + k] = s.pose.position_m[k];
  if (dataset.attitude_as_quaternion) {
    Eigen::Matrix3d from_file;
    std::string ignored;
    const bool exact =
        RotationFromQuaternion(s.measured_quaternion_wxyz[0], s.measured_quaternion_wxyz[1],
                               s.measured_quaternion_wxyz[2], s.measured_quaternion_wxyz[3],
                               &from_file, &ignored) &&
        from_file == s.pose.rotation;
    const Eigen::Vector4d q =
        exact ? s.measured_quaternion_wxyz : QuaternionFromRotation(s.pose.rotation);
    for (int k = 0; k < 4; ++k) v[kQw + k] = q[k];
  } else {
    const Eigen::Vector3d& r = s.measured_rpy_deg;
    const bool exact = r.allFinite() && RotationFromRpyDeg(r[0], r[1], r[2]) == s.pose.rotation;
    const Eigen::Vector3d rpy = exact ? r : RpyDegFromRotation(s.pose.rotation);
    for (int k = 0; k < 3; ++k) v[kRoll + k] = rpy[k];
  }
  if (dataset.has_planned_attitude) {
    if (!s.has_planned_attitude) {
      *reason = "no planned attitude, which the dataset declares";
      return false;
    }
    if (!IsRotation(s.planned_rotation)) {
      *reason = "planned_rotation is not a finite rotation matrix";
      return false;
    }
    const Eigen::Vector3d& r = s.planned_rpy_deg;
    const bool exact = r.allFinite() && RotationFromRpyDeg(r[0], r[1], r[2]) == s.planned_rotation;
    const Eigen::Vector3d rpy = exact ? r : RpyDegFromRotation(s.planned_rotation);
    for (int k = 0; k < 3; ++k) v[kPlannedRoll + k] = rpy[k];
  }
  for (int i = 0; i < kNumCables; ++i) v[kTension1 + i] = s.tension_n[i];
  if (dataset.has_unstretched_lengths) {
    if (!s.has_unstretched_lengths) {
      *reason = "no unstretched lengths, which the dataset declares";
      return false;
    }
    for (int i = 0; i < kNumCables; ++i) v[kUnstretched1 + i] = s.unstretched_length_m[i];
  }
  // What the reader would refuse, with its default limits.
  const PlausibilityLimits limits;
  for (int c = 0; c < kNumColumns; ++c) {
    const std::string prefix = "column " + Quoted(kColumnNames[c]) + ": ";
    if (!std::isfinite(v[c])) {
      *reason = prefix + "value is not finite";
      return false;
    }
    const bool written = !(IsUnstretched(c) && !dataset.has_unstretched_lengths);
    std::string why;
    if (written && !CheckValue(c, IsTension(c) ? v[c] / 1e3 : v[c], limits, &why)) {
      *reason = prefix + why;
      return false;
    }
  }
  std::string why;
  if (!CheckPosition(s.pose.position_m, limits, &why)) {
    *reason = "columns 'x_m,y_m,z_m': " + why;
    return false;
  }
  return true;
}

// The columns a dataset with `layout`'s flags has, in file order.
std::vector<int> ColumnsOf(const Dataset& layout) {
  std::vector<int> columns;
  for (int c = 0; c < kNumColumns; ++c) {
    const bool rpy = c >= kRoll && c <= kYaw;
    const bool quaternion = c >= kQw && c <= kQz;
    const bool planned = c >= kPlannedRoll && c <= kPlannedYaw;
    if ((rpy && layout.attitude_as_quaternion) || (quaternion && !layout.attitude_as_quaternion) ||
        (planned && !layout.has_planned_attitude) ||
        (IsUnstretched(c) && !layout.has_unstretched_lengths)) {
      continue;
    }
    columns.push_back(c);
  }
  return columns;
}

// The header comment as '# ' lines, then the column names (and the session column when
// `sessions`).
std::string HeaderText(const std::vector<int>& columns, const std::string& header_comment,
                       bool sessions, const std::vector<std::string>& joints) {
  std::string text;
  std::string_view rest(header_comment);
  while (!rest.empty()) {
    const size_t newline = rest.find('\n');
    const std::string_view line = rest.substr(0, newline);
    text += line.empty() ? "#\n" : "# " + std::string(line) + "\n";
    rest.remove_prefix(newline == std::string_view::npos ? rest.size() : newline + 1);
  }
  for (size_t k = 0; k < columns.size(); ++k) {
    text += (k > 0 ? "," : "") + std::string(kColumnNames[columns[k]]);
  }
  for (const std::string& joint : joints) text += "," + joint;
  if (sessions) text += std::string(",") + kSessionColumn;
  return text + "\n";
}

// Appends sample `s`'s row to *text; false with *reason when the reader would refuse it.
bool AppendRow(const Dataset& layout, const std::vector<int>& columns, const Sample& s,
               std::string* text, std::string* reason) {
  std::array<double, kNumColumns> value{};
  if (!RowValues(layout, s, &value, reason)) return false;
  std::string label;
  if (!layout.session_labels.empty()) {
    if (s.session < 0 || s.session >= static_cast<int>(layout.session_labels.size()) ||
        !IsValidSessionLabel(layout.session_labels[s.session])) {
      *reason = "session " + std::to_string(s.session) + " has no valid label in session_labels";
      return false;
    }
    label = "," + layout.session_labels[s.session];
  }
  for (size_t k = 0; k < columns.size(); ++k) {
    const int c = columns[k];
    if (k > 0) *text += ",";
    *text += FormatNumber(value[c], IsTension(c) ? kKilo : 0);
  }
  for (size_t j = 0; j < layout.joint_columns.size(); ++j) {
    std::string why;
    if (!PlausibleJointValue(layout.joint_columns[j], s.joint[j], &why)) {
      *reason = "column " + Quoted(layout.joint_columns[j]) + ": " + why;
      return false;
    }
    *text += "," + FormatNumber(s.joint[j] + 0.0, 0);
  }
  *text += label + "\n";
  return true;
}

bool WriteDatasetImpl(const std::string& path, const Dataset& dataset,
                      const std::string& header_comment, std::string* error) {
  if (dataset.samples.empty()) {
    *error = path + ": no samples to write";
    return false;
  }
  const std::vector<int> columns = ColumnsOf(dataset);
  if (dataset.joint_columns.size() > static_cast<size_t>(kMaxJoints)) {
    *error = path + ": " + std::to_string(dataset.joint_columns.size()) +
             " joint columns; at most " + std::to_string(kMaxJoints);
    return false;
  }
  std::string text =
      HeaderText(columns, header_comment, !dataset.session_labels.empty(), dataset.joint_columns);
  for (size_t i = 0; i < dataset.samples.size(); ++i) {
    std::string reason;
    if (!AppendRow(dataset, columns, dataset.samples[i], &text, &reason)) {
      *error = path + ": samples[" + std::to_string(i) + "]: " + reason;
      return false;
    }
  }
  return internal::WriteFileAtomically(path, text, error);
}

}  // namespace

bool WriteDataset(const std::string& path, const Dataset& dataset,
                  const std::string& header_comment, std::string* error) {
  return internal::dataset_columns::FileErrors(path, error, [&](std::string* message) {
    return WriteDatasetImpl(path, dataset, header_comment, message);
  });
}

DatasetWriter::~DatasetWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

bool DatasetWriter::Open(const std::string& path, const Dataset& layout,
                         const std::string& header_comment, std::string* error) {
  path_ = path;
  layout_ = Dataset();
  layout_.attitude_as_quaternion = layout.attitude_as_quaternion;
  layout_.has_planned_attitude = layout.has_planned_attitude;
  layout_.has_unstretched_lengths = layout.has_unstretched_lengths;
  layout_.session_labels = layout.session_labels;
  layout_.joint_columns = layout.joint_columns;
  if (layout_.joint_columns.size() > static_cast<size_t>(kMaxJoints)) {
    *error = path + ": at most " + std::to_string(kMaxJoints) + " joint columns";
    return false;
  }
  columns_ = ColumnsOf(layout_);
  rows_ = 0;
  io_failed_ = false;
  file_ = std::fopen(path.c_str(), "wbx");  // x: never over an existing file
  if (file_ == nullptr) {
    io_failed_ = true;
    *error = path + ": cannot create: " + std::strerror(errno);
    return false;
  }
  ::flock(::fileno(file_), LOCK_EX | LOCK_NB);  // a temporary in use, not a killed run's
  buffer_ =
      HeaderText(columns_, header_comment, !layout_.session_labels.empty(), layout_.joint_columns);
  return Flush(error);
}

bool DatasetWriter::Write(const Sample& sample, std::string* error) {
  std::string reason;
  if (file_ == nullptr) {
    *error = path_ + ": not open";
    return false;
  }
  if (!AppendRow(layout_, columns_, sample, &buffer_, &reason)) {
    *error = path_ + ": samples[" + std::to_string(rows_) + "]: " + reason;
    return false;
  }
  ++rows_;
  constexpr size_t kFlushBytes = 1 << 20;  // a few thousand rows per write
  return buffer_.size() < kFlushBytes || Flush(error);
}

void DatasetWriter::UpdateSessionLabels(const std::vector<std::string>& labels) {
  std::vector<std::string>& own = layout_.session_labels;
  if (own.empty() || labels.size() < own.size() ||
      !std::equal(own.begin(), own.end(), labels.begin())) {
    return;
  }
  own = labels;
}

bool DatasetWriter::Close(std::string* error) {
  if (file_ == nullptr) {
    *error = path_ + ": not open";
    return false;
  }
  bool ok = Flush(error);
  if (ok && rows_ == 0) {
    *error = path_ + ": no samples to write";
    ok = false;
  }
  if (ok && (std::fflush(file_) != 0 || ::fsync(::fileno(file_)) != 0)) {
    *error = path_ + ": cannot write: " + std::strerror(errno);
    io_failed_ = true;
    ok = false;
  }
  if (std::fclose(file_) != 0 && ok) {
    *error = path_ + ": cannot write: " + std::strerror(errno);
    io_failed_ = true;
    ok = false;
  }
  file_ = nullptr;
  return ok;
}

bool DatasetWriter::Flush(std::string* error) {
  if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    *error = path_ + ": cannot write: " + std::strerror(errno);
    io_failed_ = true;
    return false;
  }
  buffer_.clear();
  return true;
}

}  // namespace fastcal
