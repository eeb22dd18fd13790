// A column map (format fastcal-columns-1, docs/data-format.md, "Column maps"): how to read
// a telemetry export as it comes out of a telescope's database, without converting it
// first. It says which source column holds each fastcal quantity and in what unit, how
// the time stamps are written, the field delimiter and decimal mark, where the header
// line is and what to do with the channels fastcal does not need:
//
//   format: fastcal-columns-1
//   delimiter: ";"            # optional: detected from the header line when absent
//   decimal: ","              # optional, "." by default
//   header_line: 2            # optional: the line holding the names
//   skip_after_header: 1      # optional: e.g. a unit row
//   time: {column: SysTime, format: iso8601, zone: "+08:00"}
//   columns:
//     x_m: {column: SDP_PhaPos_X, unit: mm}
//     roll_deg: {column: SDP_SwtDPose_R, unit: deg}
//     T1_kN: {column: CableForce1, unit: N}
//   unmapped: ignore          # or error (the default)
//
// Every reader of telemetry takes one (DatasetReadOptions::columns, ReadPosesCsv): the
// quantities are converted to fastcal's units once, as each field is read, on the same
// parsing path as the canonical CSV (dataset.cc).
#ifndef FASTCAL_COLUMN_MAP_H_
#define FASTCAL_COLUMN_MAP_H_

#include <string>
#include <string_view>
#include <vector>

namespace fastcal {

// How the time column is written.
enum class TimeFormat {
  kSeconds,           // a number of seconds, any epoch (as the canonical time_s)
  kUnixSeconds,       // seconds since 1970-01-01T00:00:00Z
  kUnixMilliseconds,  // milliseconds since then
  kUnixMicroseconds,  // microseconds since then
  kIso8601,           // 2024-05-01T12:34:56.5+08:00, 2024-05-01 12:34:56 (zone: the map's)
  kPattern,           // the date library's parse flags: "%Y/%m/%d %H:%M:%S"
};

// "seconds", "unix_s", "unix_ms", "unix_us", "iso8601", or the pattern.
std::string TimeFormatName(TimeFormat format, const std::string& pattern);

struct ColumnMapTime {
  std::string column;  // the source column
  TimeFormat format = TimeFormat::kSeconds;
  std::string pattern;     // for kPattern
  bool zone_given = false;  // the map says `zone`
  // Seconds east of UTC: the zone of time stamps whose text has none, and the zone times
  // are shown in (reports, plots). 0 (UTC) by default.
  int offset_s = 0;
  int line = 0;  // of the map's `time` key
};

// One quantity: fastcal name <- source column, in a unit.
struct ColumnMapEntry {
  std::string name;    // the fastcal name: "x_m", "T3_kN", "planned_yaw_deg", "session"
  std::string column;  // the source column's name, as in the export's header
  std::string unit;    // the source's unit: m, cm, mm; deg, rad; N, kN, tf; "1"; "" (label)
  int line = 0;        // of the entry in the map
};

struct ColumnMap {
  std::string path;  // the map file (or "columns (dict)"), for messages
  std::string text;  // the map as read, for provenance (fastcal import)
  char delimiter = 0;  // ',' ';' '\t' '|' or ' '; 0: detected from the header line
  char decimal = '.';  // '.' or ','
  int header_line = 0;        // 1-based line of the names; 0: the first non-comment line
  int skip_after_header = 0;  // lines skipped after the header line (a unit row)
  bool has_time = false;
  ColumnMapTime time;
  std::vector<ColumnMapEntry> columns;  // in the map's order
  bool ignore_unmapped = false;         // unmapped: ignore (else error, naming them)
  int columns_line = 0;                 // line of the `columns` key
  int format_line = 0;                  // line of the `format` key

  // The entry of fastcal name `name`, or null.
  const ColumnMapEntry* Find(const std::string& name) const;
};

// Largest column map read, as a spec (16 MiB).
inline constexpr long long kMaxColumnMapFileBytes = 16LL << 20;

// Reads a column map file. Refuses (false, *error naming the file, the line and the key):
// an unknown key, a missing or wrong `format`, an unknown fastcal name, an unknown unit or
// one of another quantity (`x_m: {unit: kN}`), a source column named twice (by two
// quantities, or by a quantity and the time), a delimiter or decimal mark it cannot use
// (the same for both), an unknown time format or zone. Which quantities a file needs is
// checked by the reader that uses the map (a dataset needs the tensions, a pose file
// does not): "map.yaml:6: columns: no T4_kN ...".
bool LoadColumnMap(const std::string& path, ColumnMap* map, std::string* error);
// Same, from the map's text; `source_name` stands for the file in messages.
bool ParseColumnMap(const std::string& text, const std::string& source_name, ColumnMap* map,
                    std::string* error);

// The fastcal names a map may give, in the canonical column order (time_s is given by
// `time`), and the unit each is in inside fastcal's files ("m", "deg", "kN", "1", "").
const std::vector<std::string>& ColumnMapNames();
std::string CanonicalUnitOf(const std::string& name);

// A name a moving part's joint column could have (cabin.moving_parts, docs/model-format.md):
// letters, digits and '_' ending in _deg (a revolute joint) or _m (a prismatic one), not
// one of ColumnMapNames(). A map may name such columns; the reader that uses the map
// checks them against the model's joints (a joint the model does not have is an error).
bool IsJointColumnName(std::string_view name);
// The joint columns a map names, in its order (fastcal import carries them through).
std::vector<std::string> JointColumnsOf(const ColumnMap& map);

}  // namespace fastcal

#endif  // FASTCAL_COLUMN_MAP_H_
