// Reader of the measurement dataset CSV (docs/data-format.md; declarations: dataset.h;
// the writer: dataset_write.cc).
#include "fastcal/dataset.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <new>
#include <string_view>

#include "data/dataset_columns.h"
#include "fastcal/column_map.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/column_reading.h"
#include "fastcal/internal/csv.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/plausibility.h"
#include "fastcal/pose.h"

namespace fastcal {
namespace {

using namespace internal::dataset_columns;  // NOLINT: the file's own columns

// The optional label column's field (kSessionColumn): text, not a number, so it has no
// Column.
constexpr int kSessionField = -1;
// A field of an export read through a column map that fastcal does not read.
constexpr int kIgnoredField = -2;
// The field of moving-part joint j (DatasetReadOptions::joint_columns) is
// kFirstJointField - j.
constexpr int kFirstJointField = -10;
bool IsJointField(int column) { return column <= kFirstJointField; }
int JointOfField(int column) { return kFirstJointField - column; }

std::string_view Trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// The comma-separated fields of `line` into *fields (cleared first, its capacity kept).
void SplitFields(std::string_view line, std::vector<std::string_view>* fields) {
  fields->clear();
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      fields->push_back(Trim(line.substr(start)));
      return;
    }
    fields->push_back(Trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  SplitFields(line, &fields);
  return fields;
}

bool IsCommentOrBlank(std::string_view line) {
  const std::string_view t = Trim(line);
  return t.empty() || t.front() == '#';
}

std::string AcceptedColumns() {
  std::string list;
  for (int c = 0; c < kNumColumns; ++c) {
    if (c > 0) list += ", ";
    list += kColumnNames[c];
  }
  return list;
}

// Parses a whole trimmed field (internal::ParseFiniteDecimal: decimal, '.' in every
// locale, finite). Returns false with a message in *reason otherwise.
bool ParseNumber(std::string_view field, double* value, std::string* reason) {
  return internal::ParseFiniteDecimal(field, value, reason);
}

// `field` (already accepted by ParseNumber) times 10^kKilo, computed by shifting the
// decimal exponent of the text, so the result is the correctly rounded value of the
// decimal number and the writer's inverse shift round-trips exactly.
double ScaleByKilo(std::string_view field, double parsed_value) {
  return internal::ScaleDecimal(field, parsed_value, kKilo);
}

// The header: which field holds each column (-1: absent).
struct Header {
  std::array<int, kNumColumns> field_of{};
  std::vector<int> column_of_field;
  // Which column groups the file has: all but the lengths always in a measurement file
  // (DatasetColumns::kMeasurements), each optional in a lengths file (kLengths).
  bool time = true, position = true, attitude = true, tensions = true;
  bool quaternion = false;
  bool planned = false;
  bool unstretched = false;
  int session_field = -1;  // the field holding the session label, or -1
  // The moving parts' joint columns asked for (DatasetReadOptions::joint_columns), and
  // their joints when the ranges are checked (DatasetReadOptions::joints).
  std::vector<std::string> joint_names;
  std::vector<Joint> joints;
  // Read through a column map (column_map.h; null: the canonical format): the fields are
  // split at `delimiter` with quotes, numbers have the map's decimal mark and are
  // converted by `conversion`; fields of no column are kIgnoredField.
  const ColumnMap* map = nullptr;
  char delimiter = ',';
  std::array<internal::ValueConversion, kNumColumns> conversion{};
  std::vector<internal::ValueConversion> joint_conversion;  // per joint, through a map
  std::array<const ColumnMapEntry*, kNumColumns> entry{};   // through a map, per column
  // How messages name a column: "column 'x_m'", or through a map "column 'SDP_PhaPos_X'
  // (x_m)"; the position's three and the quaternion's four together.
  std::array<std::string, kNumColumns> label;
  std::string session_label = "column 'session'";
  std::string position_label = "columns 'x_m,y_m,z_m'";
  std::string quaternion_label = "columns 'qw,qx,qy,qz'";
  std::string rpy_label = "roll_deg, pitch_deg, yaw_deg";
};

// Checks that a group of columns is all present or all absent; on a partial group names
// the first missing column (`missing`: "missing column ", or a map's "no entry for ").
// Returns whether the group is present.
// "missing columns " before a list of several, else `missing` as it is.
std::string Plural(const char* missing, const std::string& names) {
  const std::string m = missing;
  return m == "missing column " && names.find(',') != std::string::npos ? "missing columns " : m;
}

bool GroupPresent(const Header& header, int first, int count, const std::string& where,
                  const char* group_note, const char* missing, bool* ok, std::string* error) {
  int present = 0;
  for (int c = first; c < first + count; ++c) present += header.field_of[c] >= 0 ? 1 : 0;
  if (present == 0 || present == count) return present == count;
  std::string names;  // every one missing, not only the first (issue 39)
  for (int c = first; c < first + count; ++c) {
    if (header.field_of[c] < 0) names += (names.empty() ? "" : ", ") + Quoted(kColumnNames[c]);
  }
  *error = where + Plural(missing, names) + names + " (" + group_note + ")";
  *ok = false;
  return false;
}

// Columns [first, end) all present; else every one missing named at once (issue 39).
bool RequireAll(const std::string& where, const char* missing, int first, int end,
                const Header& header, std::string* error) {
  std::string names;
  for (int c = first; c < end; ++c) {
    if (header.field_of[c] < 0) names += (names.empty() ? "" : ", ") + Quoted(kColumnNames[c]);
  }
  if (names.empty()) return true;
  *error = where + Plural(missing, names) + names;
  return false;
}

// The columns a dataset needs, and its groups whole or absent. `where` is the header's
// "file:line: " (or the map's "map.yaml:5: columns: "), `missing` as in GroupPresent.
bool CheckColumnGroups(const std::string& where, const char* missing, DatasetColumns required,
                       Header* header, std::string* error) {
  bool ok = true;
  const bool lengths_file = required == DatasetColumns::kLengths;
  if (lengths_file) {
    // Only the lengths are required; every other group complete or absent.
    header->time = header->field_of[kTime] >= 0;
    header->position = GroupPresent(*header, kX, 3, where, "the position needs all three or none",
                                    missing, &ok, error);
    if (!ok) return false;
    header->tensions =
        GroupPresent(*header, kTension1, kNumCables, where,
                     "the measured tensions need all six or none", missing, &ok, error);
    if (!ok) return false;
  } else {
    if (!RequireAll(where, missing, kTime, kZ + 1, *header, error)) return false;
  }
  const bool rpy =
      GroupPresent(*header, kRoll, 3, where, "the measured attitude as angles needs all three",
                   missing, &ok, error);
  if (!ok) return false;
  const bool quaternion =
      GroupPresent(*header, kQw, 4, where, "the measured attitude as a quaternion needs all four",
                   missing, &ok, error);
  if (!ok) return false;
  if (rpy && quaternion) {
    *error = where +
             "measured attitude given twice: use either roll_deg,pitch_deg,yaw_deg or "
             "qw,qx,qy,qz";
    return false;
  }
  if (!rpy && !quaternion && !lengths_file) {
    *error = where + "missing measured attitude: columns roll_deg,pitch_deg,yaw_deg or qw,qx,qy,qz";
    return false;
  }
  header->attitude = rpy || quaternion;
  header->quaternion = quaternion;
  if (!lengths_file &&
      !RequireAll(where, missing, kTension1, kTension1 + kNumCables, *header, error)) {
    return false;
  }
  header->planned =
      GroupPresent(*header, kPlannedRoll, 3, where, "the planned attitude needs all three or none",
                   missing, &ok, error);
  if (!ok) return false;
  header->unstretched =
      GroupPresent(*header, kUnstretched1, kNumCables, where,
                   "the unstretched lengths need all six or none", missing, &ok, error);
  if (ok && lengths_file && !header->unstretched) {
    *error = where + missing + Quoted(kColumnNames[kUnstretched1]) +
             " (a lengths file needs s0_1_m ... s0_6_m)";
    return false;
  }
  return ok;
}

// Every joint column asked for is in the header; else names each one missing.
bool CheckJointFields(const Header& header, const std::string& where, std::string* error) {
  std::string missing;
  int count = 0;
  for (size_t j = 0; j < header.joint_names.size(); ++j) {
    const int field = kFirstJointField - static_cast<int>(j);
    if (std::find(header.column_of_field.begin(), header.column_of_field.end(), field) ==
        header.column_of_field.end()) {
      missing += (missing.empty() ? "" : ", ") + Quoted(header.joint_names[j]);
      ++count;
    }
  }
  if (count == 0) return true;
  *error = where +
           (header.map != nullptr ? (count == 1 ? "no entry for " : "no entries for ")
                                  : (count == 1 ? "missing column " : "missing columns ")) +
           missing +
           ": the model's moving parts need their joint values in every row (cabin."
           "moving_parts in the model file; docs/data-format.md, \"Moving parts\")";
  return false;
}

// The header of an export read through a column map: its source columns matched to the
// map's (column_reading.h), the conversions, the labels of messages.
bool ParseMappedHeader(std::string_view line, const std::string& where, const std::string& path,
                       DatasetColumns required, Header* header, std::string* error) {
  const ColumnMap& map = *header->map;
  header->delimiter =
      map.delimiter != 0 ? map.delimiter : internal::DetectDelimiter(line, map.decimal);
  std::vector<std::string_view> fields;
  std::deque<std::string> scratch;
  std::string why;
  if (!internal::SplitRecord(line, header->delimiter, &fields, &scratch, &why)) {
    *error = where + "header: " + why;
    return false;
  }
  // Trailing delimiters (a spreadsheet's empty cells at the end): no columns.
  while (fields.size() > 1 && fields.back().empty()) fields.pop_back();
  for (const ColumnMapEntry& e : map.columns) {  // a joint the model does not have
    if (IsJointColumnName(e.name) &&
        std::find(header->joint_names.begin(), header->joint_names.end(), e.name) ==
            header->joint_names.end()) {
      std::string joints;
      for (const std::string& j : header->joint_names) joints += (joints.empty() ? "" : ", ") + j;
      *error =
          internal::EntryWhere(map, e) +
          (joints.empty()
               ? "the model has no moving parts (cabin.moving_parts), so no "
                 "joint column"
               : "the model's moving parts have no joint of that name (theirs: " + joints + ")");
      return false;
    }
  }
  if (!map.has_time) {
    *error = map.path +
             ": time: missing: a dataset needs the time of each row (time: {column: "
             "NAME, format: seconds | unix_s | unix_ms | iso8601, zone: ...})";
    return false;
  }
  {
    // The map gives what a dataset needs, before the header is looked at.
    Header given;
    given.field_of.fill(-1);
    given.field_of[kTime] = 0;
    for (int c = kX; c < kNumColumns; ++c) {
      if (map.Find(kColumnNames[c]) != nullptr) given.field_of[c] = 0;
    }
    if (!CheckColumnGroups(internal::ColumnsWhere(map), "no entry for ", required, &given, error)) {
      return false;
    }
  }
  // The model's joint columns after the map's own names: target index size + j.
  std::vector<std::string> targets = ColumnMapNames();
  const int first_joint_target = static_cast<int>(targets.size());
  targets.insert(targets.end(), header->joint_names.begin(), header->joint_names.end());
  header->joint_conversion.assign(header->joint_names.size(), {});
  internal::MappedHeader mapped;
  if (!internal::ResolveMappedHeader(map, fields, targets, where, path, &mapped, error)) {
    return false;
  }
  constexpr int kSessionTarget = kNumColumns - 1;  // ColumnMapNames(): the columns after
                                                   // time_s, then session
  header->column_of_field.assign(fields.size(), kIgnoredField);
  for (size_t f = 0; f < fields.size(); ++f) {
    const int target = mapped.target_of_field[f];
    if (target == internal::kTimeTarget) {
      header->column_of_field[f] = kTime;
      header->field_of[kTime] = static_cast<int>(f);
      header->label[kTime] = "column " + Quoted(map.time.column) + " (time_s, " +
                             TimeFormatName(map.time.format, map.time.pattern) + ")";
    } else if (target >= first_joint_target) {
      const int j = target - first_joint_target;
      const ColumnMapEntry& entry = *mapped.entry_of_target[target];
      header->column_of_field[f] = kFirstJointField - j;
      header->joint_conversion[j] = internal::ConversionOf(entry.name, entry.unit);
    } else if (target == kSessionTarget) {
      header->column_of_field[f] = kSessionField;
      header->session_field = static_cast<int>(f);
      header->session_label = "column " + Quoted(fields[f]) + " (session)";
    } else if (target >= 0) {
      const int column = target + 1;
      const ColumnMapEntry& entry = *mapped.entry_of_target[target];
      header->column_of_field[f] = column;
      header->field_of[column] = static_cast<int>(f);
      header->conversion[column] = internal::ConversionOf(entry.name, entry.unit);
      header->entry[column] = &entry;
      const std::string unit = entry.unit == CanonicalUnitOf(entry.name) ? "" : ", " + entry.unit;
      header->label[column] = "column " + Quoted(entry.column) + " (" + entry.name + unit + ")";
    }
  }
  const auto names = [&](int first, int count) {
    std::string sources, fastcal;
    for (int c = first; c < first + count; ++c) {
      const ColumnMapEntry* e = map.Find(kColumnNames[c]);
      sources += (c > first ? "," : "") + (e ? e->column : std::string("?"));
      fastcal += (c > first ? "," : "") + std::string(kColumnNames[c]);
    }
    return "columns " + Quoted(sources) + " (" + fastcal + ")";
  };
  header->position_label = names(kX, 3);
  header->quaternion_label = names(kQw, 4);
  if (header->field_of[kRoll] >= 0) {
    header->rpy_label = names(kRoll, 3).substr(8);
  }
  return CheckJointFields(*header, internal::ColumnsWhere(map), error) &&
         CheckColumnGroups(internal::ColumnsWhere(map), "no entry for ", required, header, error);
}

bool ParseHeader(std::string_view line, const std::string& where, const std::string& path,
                 DatasetColumns required, Header* header, std::string* error) {
  header->field_of.fill(-1);
  for (int c = 0; c < kNumColumns; ++c) header->label[c] = "column " + Quoted(kColumnNames[c]);
  if (header->map != nullptr) return ParseMappedHeader(line, where, path, required, header, error);
  const std::string separator_error = internal::WrongSeparatorMessage(line);
  if (!separator_error.empty()) {
    *error = where + separator_error;
    return false;
  }
  const std::vector<std::string_view> fields = SplitFields(line);
  for (size_t f = 0; f < fields.size(); ++f) {
    const std::string_view name = fields[f];
    if (name.empty()) {
      *error = where + "empty column name in field " + std::to_string(f + 1);
      return false;
    }
    if (name == kSessionColumn) {
      if (header->session_field >= 0) {
        *error = where + "duplicate column " + Quoted(kSessionColumn) + " (fields " +
                 std::to_string(header->session_field + 1) + " and " + std::to_string(f + 1) + ")";
        return false;
      }
      header->session_field = static_cast<int>(f);
      header->column_of_field.push_back(kSessionField);
      continue;
    }
    int column = -1;
    for (int c = 0; c < kNumColumns; ++c) {
      if (name == kColumnNames[c]) column = c;
    }
    const std::vector<std::string>& joints = header->joint_names;
    const auto joint = std::find(joints.begin(), joints.end(), name);
    if (column < 0 && joint != joints.end()) {
      const int field = kFirstJointField - static_cast<int>(joint - joints.begin());
      if (std::find(header->column_of_field.begin(), header->column_of_field.end(), field) !=
          header->column_of_field.end()) {
        *error = where + "duplicate column " + Quoted(name);
        return false;
      }
      header->column_of_field.push_back(field);
      continue;
    }
    if (column < 0) {
      std::vector<std::string> known(std::begin(kColumnNames), std::end(kColumnNames));
      known.push_back(kSessionColumn);
      known.insert(known.end(), joints.begin(), joints.end());
      *error = where + "unknown column " + Quoted(name) + internal::DidYouMean(name, known) +
               " (accepted: " + AcceptedColumns() +
               "; an export with other names, units or channels is read through a column map, "
               "--columns=MAP.yaml, docs/data-format.md)";
      if (IsJointColumnName(name)) {
        *error +=
            "; if it is a moving part's joint, the model names no joint with it "
            "(cabin.moving_parts in the model file, --model)";
      }
      return false;
    }
    if (header->field_of[column] >= 0) {
      *error = where + "duplicate column " + Quoted(name) + " (fields " +
               std::to_string(header->field_of[column] + 1) + " and " + std::to_string(f + 1) + ")";
      return false;
    }
    header->field_of[column] = static_cast<int>(f);
    header->column_of_field.push_back(column);
  }
  for (int c = 0; c < kNumColumns; ++c) {
    header->conversion[c].shift = IsTension(c) ? kKilo : 0;
    header->conversion[c].internal_per_file = IsTension(c) ? 1e3 : 1.0;
  }
  if (!CheckJointFields(*header, where, error)) return false;
  return CheckColumnGroups(where, "missing column ", required, header, error);
}

}  // namespace

namespace internal::dataset_columns {

// Checks a parsed value (kN for a tension) against the plausibility limits.
bool CheckValue(int column, double value, const PlausibilityLimits& limits, std::string* why) {
  if (column == kTime && !(std::abs(value) <= limits.max_abs_time_s)) {
    *why = internal::FormatDouble("%.6g", value) +
           " s is beyond any time of a telescope's telemetry (|time_s| <= " +
           internal::FormatDouble("%.6g", limits.max_abs_time_s) +
           " s: Unix times to 2286, or seconds from a survey's start)";
    return false;
  }
  if (IsTension(column)) {
    // Compared in kN as read, so that 1e308 kN is called implausible, not "not finite"
    // after the conversion to N.
    const double max_kn = limits.max_tension_n / 1e3;
    if (value > max_kn) {
      *why = internal::FormatDouble("%.6g", value) + " kN is above the plausible maximum of " +
             internal::FormatDouble("%.6g", max_kn) + " kN";
      return false;
    }
    return CheckTensionN(value * 1e3, limits, why);
  }
  if (IsUnstretched(column)) return CheckUnstretchedLengthM(value, limits, why);
  if (IsAngle(column)) return CheckAngleDeg(value, limits, why);
  return true;
}

}  // namespace internal::dataset_columns

namespace {

// The numbers of one row, by column (tensions in N; columns the file lacks stay 0).
using FieldValues = std::array<double, kNumColumns>;

// Through a map whose x, y, z share a unit: the other unit in which the row's position
// would be plausible, as a hint (issue 39: mm declared as m put the cabin above the
// towers); "" otherwise.
std::string PositionUnitHint(std::string_view line, const Header& header,
                             const PlausibilityLimits& limits);

// Parses one data row into *sample and *values; on failure *reason says why (without
// file:line). `previous` (may be null): the last valid row, for the decimal-comma hint.
bool ParseRow(std::string_view line, const Header& header, const PlausibilityLimits& limits,
              const FieldValues* previous, Sample* sample, FieldValues* values,
              std::string* reason);

// The message for a row with one field more than the header. Most often a decimal comma
// ("244,5" for 244.5, from a spreadsheet in a German or French locale) split one number
// in two. Each place where a whole number is followed by a field of digits is tried as
// one decimal number; of those that make the row valid, the one closest to the previous
// row (telemetry changes little from one row to the next) is named with its column. No
// previous row: named only when it is the only one.
std::string TooManyFieldsMessage(const std::vector<std::string_view>& fields, const Header& header,
                                 const PlausibilityLimits& limits, const FieldValues* previous) {
  const size_t expected = header.column_of_field.size();
  std::string message = "expected " + std::to_string(expected) +
                        " fields (as in the header), found " + std::to_string(fields.size());
  if (!fields.empty() && fields.back().empty()) return message + " (a comma at the end?)";
  const auto digits = [](std::string_view s, bool sign) {
    if (sign && !s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
    return !s.empty() && s.find_first_not_of("0123456789") == std::string_view::npos;
  };
  int valid = 0;
  size_t best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t f = 0; fields.size() == expected + 1 && f + 1 < fields.size(); ++f) {
    if (header.column_of_field[f] == kSessionField) continue;
    if (!digits(fields[f], true) || !digits(fields[f + 1], false)) continue;
    std::string joined;
    for (size_t k = 0; k < fields.size(); ++k) {
      joined += std::string(k == 0 ? "" : k == f + 1 ? "." : ",") + std::string(fields[k]);
    }
    Sample ignored;
    FieldValues values{};
    std::string why;
    if (!ParseRow(joined, header, limits, nullptr, &ignored, &values, &why)) continue;
    double distance = 0.0;
    for (int c = 0; previous != nullptr && c < kNumColumns; ++c) {
      distance += std::abs(values[c] - (*previous)[c]);
    }
    if (valid++ == 0 || distance < best_distance) {
      best = f;
      best_distance = distance;
    }
  }
  if (valid == 1 || (valid > 1 && previous != nullptr)) {
    return message + ": a decimal comma? " +
           Quoted(std::string(fields[best]) + "," + std::string(fields[best + 1])) + " in column " +
           Quoted(kColumnNames[header.column_of_field[best]]) +
           " reads as two fields; numbers must use '.' as the decimal point (or say decimal: "
           "\",\" in a column map, --columns)";
  }
  return message + " (fields cannot contain a comma; a decimal comma must be a '.')";
}

// The fields of a row read through a column map, a trailing delimiter dropped; false
// with *reason on a quote left open or a wrong number of fields.
bool SplitMappedRow(std::string_view line, const Header& header,
                    std::vector<std::string_view>* fields, std::string* reason) {
  thread_local std::deque<std::string> scratch;
  scratch.clear();
  if (!internal::SplitRecord(line, header.delimiter, fields, &scratch, reason)) return false;
  const size_t expected = header.column_of_field.size();
  // Trailing delimiters beyond the header's columns (empty fields): none.
  while (fields->size() > expected && fields->back().empty()) fields->pop_back();
  if (fields->size() == expected) return true;
  *reason = "expected " + std::to_string(expected) + " fields (as in the header), found " +
            std::to_string(fields->size());
  if (fields->size() > expected && header.delimiter == ',' && header.map->decimal == '.') {
    *reason += " (a decimal comma? say decimal: \",\" and the delimiter in the column map)";
  } else if (fields->size() < expected) {
    *reason += " (separated by " + internal::DelimiterName(header.delimiter) + ")";
  }
  return false;
}

std::string PositionUnitHint(std::string_view line, const Header& header,
                             const PlausibilityLimits& limits) {
  const ColumnMapEntry* x = header.entry[kX];
  if (header.map == nullptr || x == nullptr || header.entry[kY] == nullptr ||
      header.entry[kZ] == nullptr || header.entry[kY]->unit != x->unit ||
      header.entry[kZ]->unit != x->unit) {
    return "";
  }
  std::vector<std::string_view> fields;
  std::string ignored;
  if (!SplitMappedRow(line, header, &fields, &ignored)) return "";
  for (const std::string& unit : internal::UnitsOf(x->name)) {
    if (unit == x->unit) continue;
    Eigen::Vector3d p;
    bool read = true;
    for (int c = kX; c <= kZ && read; ++c) {
      double file_value = 0.0;
      const int field = header.field_of[c];
      read = field >= 0 && field < static_cast<int>(fields.size()) &&
             internal::ReadConvertedNumber(fields[field], header.map->decimal,
                                           internal::ConversionOf(x->name, unit), &file_value,
                                           &p[c - kX], &ignored);
    }
    if (read && CheckPosition(p, limits, &ignored)) {
      return "; in " + unit + " it would be plausible: are the columns' units " + unit +
             " (unit: " + unit + ")?";
    }
  }
  return "";
}

// The row's fields, as many as the header's; false with *reason otherwise.
bool SplitRow(std::string_view line, const Header& header, const PlausibilityLimits& limits,
              const FieldValues* previous, std::vector<std::string_view>* fields,
              std::string* reason) {
  // Room for the header's fields at once: growing from empty took six allocations a row.
  // (Not one vector kept across rows: TooManyFieldsMessage parses the row again.)
  fields->reserve(header.column_of_field.size() + 1);
  if (header.map != nullptr) return SplitMappedRow(line, header, fields, reason);
  SplitFields(line, fields);
  if (fields->size() == header.column_of_field.size()) return true;
  *reason = fields->size() > header.column_of_field.size()
                ? TooManyFieldsMessage(*fields, header, limits, previous)
                : "expected " + std::to_string(header.column_of_field.size()) +
                      " fields (as in the header), found " + std::to_string(fields->size());
  return false;
}

// Moving-part joint j's field into sample->joint[j].
bool ReadJointField(const Header& header, std::string_view field, int j, Sample* sample,
                    std::string* reason) {
  std::string why;
  double v = 0.0, file_value = 0.0;
  const bool read = header.map != nullptr ? internal::ReadConvertedNumber(
                                                field, header.map->decimal,
                                                header.joint_conversion[j], &file_value, &v, &why)
                                          : ParseNumber(field, &v, &why);
  if (!read || !(j < static_cast<int>(header.joints.size())
                     ? CheckJointValue(header.joints[j], v, &why)
                     : PlausibleJointValue(header.joint_names[j], v, &why))) {
    *reason = "column " + Quoted(header.joint_names[j]) + ": " + why;
    return false;
  }
  sample->joint[j] = v + 0.0;  // -0 read as 0, as ParseRow's values
  return true;
}

// A field read through the column map into *value (SI); false with *why (the column's
// label not yet in it).
bool ReadMappedField(const Header& header, const PlausibilityLimits& limits, int column,
                     std::string_view field, bool first_row, double* value, std::string* why) {
  if (column == kTime) {
    if (!internal::ReadTimeField(field, header.map->time, header.map->decimal, value, why)) {
      *why += internal::NotANumberHint(field, '\0', first_row);
      return false;
    }
    return CheckValue(column, *value, limits, why);
  }
  double file_value = 0.0;
  const char decimal = header.map->decimal;
  if (!internal::ReadConvertedNumber(field, decimal, header.conversion[column], &file_value, value,
                                     why)) {
    *why += internal::NotANumberHint(field, decimal, first_row);
    return false;
  }
  if (CheckValue(column, file_value, limits, why)) return true;
  if (const ColumnMapEntry* e = header.entry[column]; e != nullptr) {
    const auto plausible = [&](double v) {
      std::string ignored;
      return CheckValue(column, v, limits, &ignored);
    };
    *why += internal::UnitHint(e->name, e->unit, field, decimal, plausible);
  }
  return false;
}

// A field of the canonical format into *value (SI: a tension's kN shifted to N, exactly);
// false with *why.
bool ReadPlainField(const PlausibilityLimits& limits, int column, std::string_view field,
                    double* value, std::string* why) {
  // A tension read straight to N, its text shifted (one scan, not a parse in kN and
  // another shifted), and checked in kN a few ulps either side (the kN value read is
  // within one of n * 1e-3, and the limits are an interval): any text it refuses, or a
  // value near a limit, is read the general way below, which decides as before.
  constexpr double kUlpsMargin = 1e-15;
  if (double n = 0.0; IsTension(column) && internal::ParseShiftedDecimal(field, kKilo, &n) &&
                      CheckValue(column, n * 1e-3 * (1.0 - kUlpsMargin), limits, why) &&
                      CheckValue(column, n * 1e-3 * (1.0 + kUlpsMargin), limits, why)) {
    *value = n;
    return true;
  }
  if (!ParseNumber(field, value, why) || !CheckValue(column, *value, limits, why)) return false;
  if (IsTension(column)) *value = ScaleByKilo(field, *value);
  return true;
}

// The sample of a row's values: the position checked, the attitude made a rotation.
bool SampleFromValues(std::string_view line, const Header& header, const PlausibilityLimits& limits,
                      const FieldValues& value, Sample* sample, std::string* reason) {
  if (header.position) {
    const Eigen::Vector3d position(value[kX], value[kY], value[kZ]);
    std::string why;
    if (!CheckPosition(position, limits, &why)) {
      *reason = header.position_label + ": " + why + PositionUnitHint(line, header, limits);
      return false;
    }
  }
  sample->time_s = value[kTime];
  sample->pose.position_m = Eigen::Vector3d(value[kX], value[kY], value[kZ]);
  if (!header.attitude) {
    // A lengths file without an attitude: the identity, unused (Dataset::has_attitude).
  } else if (header.quaternion) {
    sample->measured_quaternion_wxyz =
        Eigen::Vector4d(value[kQw], value[kQx], value[kQy], value[kQz]);
    std::string why;
    if (!RotationFromQuaternion(value[kQw], value[kQx], value[kQy], value[kQz],
                                &sample->pose.rotation, &why)) {
      *reason = header.quaternion_label + ": " + why;
      return false;
    }
  } else {
    sample->measured_rpy_deg = Eigen::Vector3d(value[kRoll], value[kPitch], value[kYaw]);
    sample->pose.rotation = RotationFromRpyDeg(value[kRoll], value[kPitch], value[kYaw]);
  }
  sample->has_planned_attitude = header.planned;
  if (header.planned) {
    sample->planned_rpy_deg =
        Eigen::Vector3d(value[kPlannedRoll], value[kPlannedPitch], value[kPlannedYaw]);
    sample->planned_rotation =
        RotationFromRpyDeg(value[kPlannedRoll], value[kPlannedPitch], value[kPlannedYaw]);
  }
  for (int i = 0; i < kNumCables; ++i) sample->tension_n[i] = value[kTension1 + i];
  sample->has_unstretched_lengths = header.unstretched;
  if (header.unstretched) {
    for (int i = 0; i < kNumCables; ++i) {
      sample->unstretched_length_m[i] = value[kUnstretched1 + i];
    }
  }
  return true;
}

bool ParseRow(std::string_view line, const Header& header, const PlausibilityLimits& limits,
              const FieldValues* previous, Sample* sample, FieldValues* values,
              std::string* reason) {
  std::vector<std::string_view> fields;
  if (!SplitRow(line, header, limits, previous, &fields, reason)) return false;
  // The unit-row hint only where the map skips no row after the header (a second re-check
  // of issue 37: "#NV" in the first row suggested what the map already said).
  const bool first_row =
      header.map != nullptr && previous == nullptr && header.map->skip_after_header == 0;
  FieldValues& value = *values;
  value.fill(0.0);
  for (size_t f = 0; f < fields.size(); ++f) {
    const int column = header.column_of_field[f];
    if (column == kIgnoredField) continue;
    if (IsJointField(column)) {
      if (!ReadJointField(header, fields[f], JointOfField(column), sample, reason)) return false;
      continue;
    }
    if (column == kSessionField) {
      if (IsValidSessionLabel(std::string(fields[f]))) continue;
      *reason = header.session_label + ": " + Quoted(std::string(fields[f])) +
                " is not a session label (letters, digits, '-' and '_', at most " +
                std::to_string(kMaxSessionLabelLength) + ")";
      return false;
    }
    std::string why;
    const bool read =
        header.map != nullptr
            ? ReadMappedField(header, limits, column, fields[f], first_row, &value[column], &why)
            : ReadPlainField(limits, column, fields[f], &value[column], &why);
    if (!read) {
      *reason = header.label[column] + ": " + why;
      return false;
    }
  }
  // "-0" is the reading 0, and the writer writes it so: a written and re-read dataset then
  // holds the same bits (the fuzzer's round trip), and -0 never reaches a sign test.
  for (double& v : value) v += 0.0;
  return SampleFromValues(line, header, limits, value, sample, reason);
}

// Attitudes written in radians under *_deg columns: a unit slip the per-value limits
// cannot see (0.3 rad is a plausible 0.3 deg). Two signs, on the whole file: the planned
// angles (in degrees, written by the planner) are about 57.3 times the measured ones; or
// every angle of the file is below 1 deg where the focal attitude law (how FAST flies)
// tilts the cabin by several degrees on most samples. Returns the
// message, or "" when neither holds.
// The sums AttitudeInRadiansProblem judges, gathered sample by sample (a file read in
// chunks is judged as a whole).
struct RadiansCheck {
  double pm = 0.0, mm = 0.0;  // planned . measured, measured . measured (significant angles)
  int angles = 0;
  double largest_deg = 0.0, largest_focal_deg = 0.0;
  int tilted = 0, samples = 0;

  // The tilt of the focal law at the sample's position (trigonometry: computed where the
  // rows are parsed in parallel, not in Add, which takes the rows in turn).
  static double FocalDeg(const Sample& s) {
    const Eigen::AngleAxisd focal(FocalAttitude(s.pose.position_m, FocalAttitudeLaw()));
    return std::abs(focal.angle()) * kDegPerRad;
  }

  void Add(const Sample& s, bool planned, double focal_deg) {
    constexpr double kSignificantPlannedDeg = 1.0;  // planned angles compared from here
    constexpr double kFocalTiltDeg = 5.0;           // "several degrees" of the focal law
    ++samples;
    if (planned) {
      for (int a = 0; a < 3; ++a) {
        if (std::abs(s.planned_rpy_deg[a]) < kSignificantPlannedDeg) continue;
        pm += s.planned_rpy_deg[a] * s.measured_rpy_deg[a];
        mm += s.measured_rpy_deg[a] * s.measured_rpy_deg[a];
        ++angles;
      }
    }
    largest_deg = std::max(largest_deg, s.measured_rpy_deg.cwiseAbs().maxCoeff());
    if (planned) largest_deg = std::max(largest_deg, s.planned_rpy_deg.cwiseAbs().maxCoeff());
    largest_focal_deg = std::max(largest_focal_deg, focal_deg);
    if (focal_deg > kFocalTiltDeg) ++tilted;
  }
  static constexpr double kDegPerRad = 57.29577951308232;
};

std::string AttitudeInRadiansProblem(const std::string& path, const Header& header,
                                     const RadiansCheck& c) {
  const bool quaternion = header.quaternion, planned = header.planned;
  constexpr double kDegPerRad = RadiansCheck::kDegPerRad;
  constexpr double kFactorTolerance = 0.25;  // of kDegPerRad: 43 to 72
  constexpr int kFewestAngles = 10;
  constexpr double kLevelBelowDeg = 1.0;
  if (quaternion || c.samples == 0) return "";
  const std::string columns = path + ": " + header.rpy_label + " look like radians: ";
  const std::string fix = header.map != nullptr
                              ? "; say unit: rad for them in the column map " + header.map->path
                              : "; write degrees (radians x 57.2958)";
  if (planned) {
    const double factor = c.mm > 0.0 ? c.pm / c.mm : 0.0;
    if (c.angles >= kFewestAngles && std::abs(factor / kDegPerRad - 1.0) <= kFactorTolerance) {
      return columns + "the planned_*_deg angles are " + internal::FormatDouble("%.3g", factor) +
             " times the measured ones (least squares over " + std::to_string(c.angles) +
             " angles above 1 deg)" + fix;
    }
  }
  // Measured (and planned, when given) angles all below 1 deg where FAST tilts.
  const int n = c.samples;
  if (n < kFewestAngles || c.largest_deg >= kLevelBelowDeg || 2 * c.tilted < n) return "";
  return columns + "every angle is below 1 deg (largest " +
         internal::FormatDouble("%.3g", c.largest_deg) +
         " deg), while the focal attitude law tilts the cabin by up to " +
         internal::FormatDouble("%.3g", c.largest_focal_deg) + " deg at these positions" + fix;
}

// The index of `label` in dataset->session_labels, appended when new.
int SessionIndex(std::string_view label, Dataset* dataset) {
  std::vector<std::string>& labels = dataset->session_labels;
  for (size_t k = 0; k < labels.size(); ++k) {
    if (labels[k] == label) return static_cast<int>(k);
  }
  labels.emplace_back(label);
  return static_cast<int>(labels.size()) - 1;
}

// Reads a dataset line by line, for ParseDataset (the whole text) and DatasetChunkReader
// (a file in pieces): one set of checks and messages for both. Samples and skipped rows
// go to the Dataset given to each Line; the header's flags and the session labels stay
// in layout().
class LineParser {
 public:
  LineParser(const std::string& source_name, const DatasetReadOptions& options)
      : options_(options) {
    layout_.path = source_name;
    layout_.joint_columns = options_.joint_columns;
    header_.joint_names = options_.joint_columns;
    if (options_.joints.size() == options_.joint_columns.size()) header_.joints = options_.joints;
    header_.map = options_.columns.get();
    if (header_.map != nullptr) layout_.time_offset_s = header_.map->time.offset_s;
  }

  // Whether the records may hold quoted line breaks (read through a column map).
  bool quotes() const { return header_.map != nullptr; }

  // A comment or blank line; through a column map also a row of empty fields only
  // (";;;;", as spreadsheets export their empty rows), once the delimiter is known.
  bool Blank(std::string_view line) const {
    if (IsCommentOrBlank(line)) return true;
    if (header_.map == nullptr || !have_header_) return false;
    for (char c : line) {
      if (c != header_.delimiter && c != ' ' && c != '\t' && c != '\r' && c != '"') return false;
    }
    return true;
  }

  // One line of the file (without its '\n'), numbered from 1; through a column map, one
  // record (which may span lines inside quotes), numbered by its first line.
  bool Line(int line_number, std::string_view line, Dataset* out, std::string* error) {
    // Built only for a message: two allocations a row add up at 10^6 rows.
    const auto where = [&] { return layout_.path + ":" + std::to_string(line_number) + ": "; };
    const int header_line = header_.map != nullptr ? header_.map->header_line : 0;
    if (!have_header_ && header_line > 0) {
      // The map says where the names are: the lines before are not read, whatever they hold.
      if (line_number < header_line) return true;
      line = Trim(line);
      if (!line.empty() && line.front() == '#') line.remove_prefix(1);  // "#time,x,..."
      if (Trim(line).empty()) {
        *error = where() + "the header line (header_line: " + std::to_string(header_line) + " in " +
                 header_.map->path + ") is empty";
        return false;
      }
    } else if (Blank(line) || line_number <= skip_until_) {
      return true;
    }
    if (!have_header_) {
      if (!ParseHeader(line, where(), layout_.path, options_.required_columns, &header_, error)) {
        return false;
      }
      have_header_ = true;
      if (header_.map != nullptr) skip_until_ = line_number + header_.map->skip_after_header;
      layout_.has_time = header_.time;
      layout_.has_position = header_.position;
      layout_.has_measured_attitude = header_.attitude;
      layout_.has_tensions = header_.tensions;
      layout_.has_planned_attitude = header_.planned;
      layout_.has_unstretched_lengths = header_.unstretched;
      layout_.attitude_as_quaternion = header_.quaternion;
      return true;
    }
    ++rows_;
    Sample sample;
    sample.line = line_number;
    std::string reason;
    FieldValues values{};
    if (ParseRow(line, header_, options_.limits, have_previous_ ? &previous_ : nullptr, &sample,
                 &values, &reason)) {
      Take(line, &sample, values, FocalDeg(sample), out);
    } else if (options_.skip_invalid_rows) {
      if (first_skipped_.empty()) first_skipped_ = where() + reason;
      out->skipped.push_back(where() + reason);
    } else {
      *error = where() + reason;
      return false;
    }
    return true;
  }

  // Lines (numbered, without '\n') as Line takes them one by one, the same samples,
  // skipped rows and messages: once the header is known, the rows are parsed on
  // options.threads threads (a row's parse depends on no other valid row), then taken in
  // order; a row that fails is parsed again by Line, for its message (which may name the
  // previous row).
  bool Lines(const std::vector<std::pair<int, std::string_view>>& lines, Dataset* out,
             std::string* error) {
    size_t next = 0;
    for (; next < lines.size() && !have_header_; ++next) {
      if (!Line(lines[next].first, lines[next].second, out, error)) return false;
    }
    const int count = static_cast<int>(lines.size() - next);
    // Kept from batch to batch: a new one (4 MB) was zeroed and faulted in every time.
    std::vector<Parsed>& parsed = parsed_;
    if (parsed.size() < static_cast<size_t>(count)) parsed.resize(count);
    internal::ForEachChunk(
        count, options_.threads,
        [&](int begin, int end) {
          std::string reason;
          for (int k = begin; k < end; ++k) {
            const auto& [number, line] = lines[next + k];
            Parsed& p = parsed[k];
            p = Parsed();
            p.row = !Blank(line) && number > skip_until_;
            p.sample.line = number;
            p.ok = p.row &&
                   ParseRow(line, header_, options_.limits, nullptr, &p.sample, &p.values, &reason);
            if (p.ok) p.focal_deg = FocalDeg(p.sample);
          }
          return -1;
        },
        kParseChunkRows);
    for (int k = 0; k < count; ++k) {
      Parsed& p = parsed[k];
      const auto& [number, line] = lines[next + k];
      if (!p.row) continue;
      if (!p.ok) {
        if (!Line(number, line, out, error)) return false;
        continue;
      }
      ++rows_;
      Take(line, &p.sample, p.values, p.focal_deg, out);
    }
    return true;
  }

  // The checks of the whole file, after its last line.
  bool Finish(std::string* error) const {
    const std::string& source_name = layout_.path;
    if (!have_header_) {
      *error = source_name + ": no header line (and no data rows)";
      if (header_.map != nullptr && header_.map->header_line > 0) {
        *error += ": the column map " + header_.map->path +
                  " says header_line: " + std::to_string(header_.map->header_line);
      }
      return false;
    }
    if (rows_ == 0) {
      *error = source_name + ": no data rows";
      return false;
    }
    if (!have_previous_) {
      *error = source_name + ": no valid data rows: all " + std::to_string(rows_) +
               " rows skipped; first: " + first_skipped_;
      return false;
    }
    if (const std::string why = AttitudeInRadiansProblem(source_name, header_, radians_);
        !why.empty()) {
      *error = why;
      return false;
    }
    return true;
  }

  // The path, the header's column flags and the session labels met so far.
  const Dataset& layout() const { return layout_; }

 private:
  // Rows a thread parses at a time in Lines.
  static constexpr int kParseChunkRows = 512;

  // The radians check's focal tilt of a parsed sample (0 where the check is not made).
  double FocalDeg(const Sample& sample) const {
    return header_.position && header_.attitude ? RadiansCheck::FocalDeg(sample) : 0.0;
  }

  // A valid row: its session, the radians check, the sample kept.
  void Take(std::string_view line, Sample* sample, const FieldValues& values, double focal_deg,
            Dataset* out) {
    if (header_.session_field >= 0) {
      if (header_.map != nullptr) {
        std::vector<std::string_view> fields;
        std::string ignored;
        SplitMappedRow(line, header_, &fields, &ignored);
        sample->session = SessionIndex(fields[header_.session_field], &layout_);
      } else {
        sample->session = SessionIndex(SplitFields(line)[header_.session_field], &layout_);
      }
    }
    if (header_.position && header_.attitude) radians_.Add(*sample, header_.planned, focal_deg);
    out->samples.push_back(std::move(*sample));
    previous_ = values;
    have_previous_ = true;
  }

  // A row parsed on the threads of Lines, before it is taken.
  struct Parsed {
    bool row = false, ok = false;
    Sample sample;
    FieldValues values{};
    double focal_deg = 0.0;
  };

  DatasetReadOptions options_;
  std::vector<Parsed> parsed_;  // Lines's rows
  Dataset layout_;
  Header header_;
  bool have_header_ = false;
  int skip_until_ = 0;  // lines up to this one after the header are skipped (a unit row)
  int rows_ = 0;
  FieldValues previous_{};  // the last valid row
  bool have_previous_ = false;
  std::string first_skipped_;
  RadiansCheck radians_;
};

// Copies the layout's path, flags and session labels into `data` (its samples and
// skipped rows kept).
void TakeLayout(const Dataset& layout, Dataset* data) {
  data->path = layout.path;
  data->has_planned_attitude = layout.has_planned_attitude;
  data->has_unstretched_lengths = layout.has_unstretched_lengths;
  data->attitude_as_quaternion = layout.attitude_as_quaternion;
  data->has_time = layout.has_time;
  data->has_position = layout.has_position;
  data->has_measured_attitude = layout.has_measured_attitude;
  data->has_tensions = layout.has_tensions;
  data->session_labels = layout.session_labels;
  data->time_offset_s = layout.time_offset_s;
  data->joint_columns = layout.joint_columns;
}

bool ParseDatasetImpl(const std::string& text, const std::string& source_name,
                      const DatasetReadOptions& options, Dataset* dataset, std::string* error) {
  Dataset result;
  if (const std::string spreadsheet =
          internal::SpreadsheetMessage(source_name, std::string_view(text).substr(0, 8), false);
      !spreadsheet.empty()) {
    *error = spreadsheet;
    return false;
  }
  LineParser parser(source_name, options);
  std::string_view rest(text);
  if (rest.substr(0, 3) == "\xEF\xBB\xBF") rest.remove_prefix(3);  // UTF-8 byte order mark
  for (int line_number = 1; !rest.empty(); ++line_number) {
    int breaks = 0;  // line breaks inside a quoted field of the record
    const size_t newline = internal::RecordEnd(rest, 0, parser.quotes(), &breaks);
    const std::string_view line = rest.substr(0, newline);
    rest.remove_prefix(newline == std::string_view::npos ? rest.size() : newline + 1);
    if (!parser.Line(line_number, line, &result, error)) return false;
    line_number += breaks;
  }
  if (!parser.Finish(error)) return false;
  TakeLayout(parser.layout(), &result);
  *dataset = std::move(result);
  return true;
}

}  // namespace

void SetJointColumns(const MovingParts& parts, DatasetReadOptions* options) {
  options->joint_columns = parts.JointColumns();
  options->joints.clear();
  for (const auto& [part, joint] : parts.Joints()) options->joints.push_back(*joint);
}

bool CheckJointColumns(const Dataset& data, const MovingParts& parts, std::string* error) {
  const std::vector<std::string> wanted = parts.JointColumns();
  if (data.joint_columns == wanted) return true;
  std::string missing;
  for (const std::string& name : wanted) {
    if (std::find(data.joint_columns.begin(), data.joint_columns.end(), name) ==
        data.joint_columns.end()) {
      missing += (missing.empty() ? "" : ", ") + Quoted(name);
    }
  }
  if (error != nullptr) {
    *error = data.path + ": " +
             (missing.empty() ? "the joint columns were read for another model (" +
                                    std::to_string(data.joint_columns.size()) + " of them)"
                              : "no joint column " + missing) +
             ": the model's moving parts need their joint values (cabin.moving_parts; "
             "docs/data-format.md, \"Moving parts\")";
  }
  return false;
}

bool ParseDataset(const std::string& text, const std::string& source_name,
                  const DatasetReadOptions& options, Dataset* dataset, std::string* error) {
  return FileErrors(source_name, error, [&](std::string* message) {
    return ParseDatasetImpl(text, source_name, options, dataset, message);
  });
}

bool ReadDataset(const std::string& path, const DatasetReadOptions& options, Dataset* dataset,
                 std::string* error) {
  // Chunk by chunk (issue 20): the file's text is never whole in memory (400 MB at 10^6
  // samples, as much as the samples themselves).
  constexpr size_t kChunkSamples = 8192;
  // Rows are at least this long (13 numbers and separators): capacity for
  // file size / kMinRowBytes samples is reserved up front, so the vector never doubles
  // (a doubling holds the old and the new array at once). Capacity never written is
  // address space, not memory.
  constexpr long long kMinRowBytes = 64;
  DatasetChunkReader reader;
  if (!reader.Open(path, options, error)) return false;
  Dataset all;
  std::error_code size_error;
  const auto bytes = std::filesystem::file_size(path, size_error);
  if (!size_error) {
    try {
      all.samples.reserve(static_cast<size_t>(bytes / kMinRowBytes) + 1);
    } catch (const std::bad_alloc&) {
      // More address space than the system grants (a 4 GB file asks for 24 GB, beyond
      // this 23 GB machine's overcommit): the vector grows as it is read instead.
    }
  }
  bool done = false;
  while (!done) {
    // Appended in place: no copy of each chunk into the whole (a serial pass over it).
    if (!reader.Append(kChunkSamples, &all, &done, error)) return false;
  }
  // The layout (path, column flags, session labels) is the last chunk's: the whole file's.
  *dataset = std::move(all);
  return true;
}

// The longest record read through a column map (a row is a few hundred bytes).
constexpr size_t kMaxMappedRecordBytes = 16u << 20;

struct DatasetChunkReader::State {
  State(const std::string& path, const DatasetReadOptions& options) : parser(path, options) {}
  internal::RegularFileReader file;
  LineParser parser;
  std::string text;  // read and not yet parsed: the start of a line
  size_t start = 0;  // where in `text` the next line starts
  // How far from `start` is known to hold no newline: each read is searched once, so
  // that a long line costs linear time (issue 29: a 1 GiB line took a minute).
  size_t searched = 0;
  int line_number = 0;
  bool first = true;  // before the first line (a byte order mark may open it)
  bool end = false;   // the whole file is in `text`
  bool done = false;  // the whole-file checks passed

  // The complete lines of `text` from `start` (a record through a map), numbered, up to
  // `room` of them (each gives at most one sample); false with *message on a spreadsheet
  // or a line too long to be a dataset's.
  bool TakeLines(size_t room, std::vector<std::pair<int, std::string_view>>* lines,
                 std::string* message) {
    while (lines->size() < room) {
      if (first && start == 0) {
        if (!end && text.size() < 8) break;  // the first bytes, to tell a spreadsheet
        const std::string spreadsheet =
            internal::SpreadsheetMessage(parser.layout().path, std::string_view(text).substr(0, 8));
        if (!spreadsheet.empty()) {
          *message = spreadsheet;
          return false;
        }
      }
      // A record ends at the first newline outside quotes. Without quotes each read is
      // searched once (`searched`); with them the record is rescanned, bounded by
      // kMaxMappedRecordBytes.
      const bool quotes = parser.quotes();
      int breaks = 0;  // line breaks inside a quoted field of the record
      const size_t newline = quotes ? internal::RecordEnd(text, start, true, &breaks)
                                    : text.find('\n', start + searched);
      searched = newline == std::string::npos ? text.size() - start : 0;
      if (newline == std::string::npos &&
          searched > (quotes ? kMaxMappedRecordBytes : kMaxDatasetLineBytes)) {
        // A quote left open would make the rest of the file one record; a file without
        // line breaks is no dataset.
        *message = parser.layout().path + ":" + std::to_string(line_number + 1) +
                   (quotes ? ": a record longer than 16 MiB (a quote not closed?)"
                           : ": a line longer than " + std::to_string(kMaxDatasetLineBytes >> 20) +
                                 " MiB: not a dataset (its lines are under 1 KiB)");
        return false;
      }
      if (newline == std::string::npos && (!end || start == text.size())) break;
      std::string_view line(text);
      line = line.substr(start, newline == std::string::npos ? std::string::npos : newline - start);
      start = newline == std::string::npos ? text.size() : newline + 1;
      if (first && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);
      first = false;
      lines->emplace_back(++line_number, line);
      line_number += breaks;
    }
    return true;
  }
};

DatasetChunkReader::DatasetChunkReader() = default;
DatasetChunkReader::~DatasetChunkReader() = default;

bool DatasetChunkReader::Open(const std::string& path, const DatasetReadOptions& options,
                              std::string* error) {
  state_ = std::make_unique<State>(path, options);
  if (const std::string spreadsheet = internal::SpreadsheetMessage(path, "");
      !spreadsheet.empty()) {
    if (error != nullptr) *error = spreadsheet;
    return false;
  }
  return state_->file.Open(path, options.max_file_bytes, "dataset", error);
}

bool DatasetChunkReader::Next(size_t max_samples, Dataset* chunk, bool* done, std::string* error) {
  chunk->samples.clear();
  chunk->skipped.clear();
  // Room at once (a chunk grown from empty was copied a dozen times); not in Append, whose
  // caller may append the whole file a chunk at a time.
  chunk->samples.reserve(std::max<size_t>(max_samples, 1));
  return Append(max_samples, chunk, done, error);
}

bool DatasetChunkReader::Append(size_t max_samples, Dataset* chunk, bool* done,
                                std::string* error) {
  // Read at a time (~10 000 rows of 24 columns): the rows of one read are parsed on the
  // threads together, and 1 MiB (~2500 rows in 5 parts) left a thread idle for a fifth.
  constexpr size_t kReadBytes = 4 << 20;
  State& st = *state_;
  return internal::dataset_columns::FileErrors(
      st.parser.layout().path, error, [&](std::string* message) {
        const size_t wanted = chunk->samples.size() + std::max<size_t>(max_samples, 1);
        std::vector<std::pair<int, std::string_view>> lines;
        bool ok = true;
        while (ok && !st.done && chunk->samples.size() < wanted) {
          // The complete lines read so far, parsed together; else more of the file.
          lines.clear();
          ok = st.TakeLines(wanted - chunk->samples.size(), &lines, message);
          if (!ok) break;
          if (!lines.empty()) {
            ok = st.parser.Lines(lines, chunk, message);
          } else if (!st.end) {
            st.text.erase(0, st.start);  // keep the unfinished line only
            st.start = 0;
            ok = st.file.Read(kReadBytes, &st.text, &st.end, message);
          } else {
            ok = st.parser.Finish(message);
            st.done = ok;
          }
        }
        TakeLayout(st.parser.layout(), chunk);
        *done = st.done;
        return ok;
      });
}

TimeDisplay TimeDisplayOf(const Dataset& data) {
  double earliest = std::numeric_limits<double>::infinity();
  for (const Sample& s : data.samples) earliest = std::min(earliest, s.time_s);
  return TimeDisplayFor(earliest, data.time_offset_s);
}

std::string SampleWhere(const Dataset& data, const Sample& sample) {
  const bool merged =
      sample.session >= 0 && sample.session < static_cast<int>(data.session_paths.size());
  return (merged ? data.session_paths[sample.session] : data.path) + ":" +
         std::to_string(sample.line);
}

bool IsValidSessionLabel(const std::string& label) {
  if (label.empty() || label.size() > static_cast<size_t>(kMaxSessionLabelLength)) return false;
  for (char c : label) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '-' || c == '_';
    if (!ok) return false;
  }
  return true;
}

}  // namespace fastcal
