// Column maps (column_map.h): the fastcal-columns-1 YAML reader, and reading an export's
// records, fields, numbers and time stamps through a map (internal/column_reading.h).
#include "fastcal/column_map.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <new>
#include <set>

#include "fastcal/internal/edit_distance.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/column_reading.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/time_text.h"
#include "util/yaml_document.h"

namespace fastcal {
namespace {

using internal::LineOf;

constexpr char kFormat[] = "fastcal-columns-1";
constexpr double kDegPerRad = 57.29577951308232;
constexpr double kNewtonsPerTonneForce = 9806.65;  // standard gravity x 1000 kg

std::vector<std::string> MakeNames() {
  std::vector<std::string> names = {"x_m",       "y_m",       "z_m",     "roll_deg",
                                    "pitch_deg", "yaw_deg",   "qw",      "qx",
                                    "qy",        "qz",        "planned_roll_deg",
                                    "planned_pitch_deg",      "planned_yaw_deg"};
  for (int i = 1; i <= 6; ++i) names.push_back("T" + std::to_string(i) + "_kN");
  for (int i = 1; i <= 6; ++i) names.push_back("s0_" + std::to_string(i) + "_m");
  names.push_back("session");
  return names;
}

bool EndsWith(const std::string& s, const char* suffix) {
  const size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

// The units a quantity may come in, its canonical one first.
std::vector<std::string> UnitsOfName(const std::string& name) {
  const std::string unit = CanonicalUnitOf(name);
  if (unit == "m") return {"m", "cm", "mm"};
  if (unit == "deg") return {"deg", "rad"};
  if (unit == "kN") return {"kN", "N", "tf"};
  if (unit == "1") return {"1"};
  return {};
}

std::string UnitKind(const std::string& name) {
  const std::string unit = CanonicalUnitOf(name);
  return unit == "m" ? "a length" : unit == "deg" ? "an angle" : unit == "kN" ? "a force" : "";
}

std::string Join(const std::vector<std::string>& items, const char* separator = ", ") {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : separator) + s;
  return out;
}

// The reader of one map: fails with "<file>:<line>: <key path>: <what>".
class MapReader : public internal::YamlErrorRecorder {
 public:
  explicit MapReader(std::string source) : YamlErrorRecorder(std::move(source)) {}

  struct KeyValue {
    YAML::Node value;
    int line = 0;
  };
  using Keys = std::map<std::string, KeyValue>;

  // A mapping's keys, each allowed and once.
  bool ReadKeys(const YAML::Node& node, int line, const std::string& path,
                const std::vector<std::string>& allowed, Keys* keys) {
    if (!node.IsMap()) return Fail(line, path, "expected a mapping of keys");
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) return Fail(LineOf(kv.first), path, "keys must be plain names");
      const std::string name = kv.first.Scalar();
      const std::string key_path = path.empty() ? name : path + "." + name;
      if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
        return Fail(LineOf(kv.first), key_path, "unknown key (allowed here: " + Join(allowed) + ")");
      }
      if (keys->count(name) != 0) return Fail(LineOf(kv.first), key_path, "given twice");
      (*keys)[name] = KeyValue{kv.second, LineOf(kv.first) > 0 ? LineOf(kv.first) : line};
    }
    return true;
  }

  bool ReadText(const KeyValue& kv, const std::string& path, std::string* text) {
    if (!kv.value.IsDefined() || kv.value.IsNull()) return Fail(kv.line, path, "has no value");
    if (!kv.value.IsScalar()) return Fail(kv.line, path, "expected a single value");
    *text = kv.value.Scalar();
    return true;
  }

  // A line count of a header: no export has a title of more lines than this, and the
  // reader adds it to line numbers (issue 37: 2^31 - 1 overflowed a signed int).
  static constexpr int kMaxHeaderLines = 10000;

  bool ReadInt(const KeyValue& kv, const std::string& path, int lowest, int* value) {
    std::string text;
    if (!ReadText(kv, path, &text)) return false;
    int v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v < lowest ||
        v > kMaxHeaderLines) {
      return Fail(kv.line, path,
                  internal::Quote(text) + " is not a whole number from " +
                      std::to_string(lowest) + " to " + std::to_string(kMaxHeaderLines));
    }
    *value = v;
    return true;
  }

  bool ReadRoot(const YAML::Node& root, ColumnMap* map) {
    Keys keys;
    if (!ReadKeys(root, LineOf(root), "",
                  {"format", "delimiter", "decimal", "header_line", "skip_after_header", "time",
                   "columns", "unmapped"},
                  &keys)) {
      return false;
    }
    const auto find = [&keys](const char* name) -> const KeyValue* {
      const auto it = keys.find(name);
      return it == keys.end() ? nullptr : &it->second;
    };
    const KeyValue* format = find("format");
    if (format == nullptr) {
      return Fail(0, "format", std::string("missing: a column map starts with format: ") + kFormat);
    }
    std::string text;
    if (!ReadText(*format, "format", &text)) return false;
    if (text != kFormat) {
      return Fail(format->line, "format",
                  internal::Quote(text) + " is not a column map format (expected " + kFormat + ")");
    }
    map->format_line = format->line;
    if (const KeyValue* kv = find("decimal")) {
      if (!ReadText(*kv, "decimal", &text)) return false;
      if (text != "." && text != ",") {
        return Fail(kv->line, "decimal", internal::Quote(text) + " is not a decimal mark (\".\" or \",\")");
      }
      map->decimal = text[0];
    }
    if (const KeyValue* kv = find("delimiter")) {
      if (!ReadText(*kv, "delimiter", &text)) return false;
      static const std::map<std::string, char> kDelimiters = {
          {",", ','},     {";", ';'},     {"\t", '\t'},     {"|", '|'},     {" ", ' '},
          {"comma", ','}, {"semicolon", ';'}, {"tab", '\t'}, {"pipe", '|'}, {"space", ' '},
          {"spaces", ' '}};
      const auto it = kDelimiters.find(text);
      if (it == kDelimiters.end()) {
        return Fail(kv->line, "delimiter",
                    internal::Quote(text) +
                        " is not a delimiter (\",\", \";\", \"\\t\" or tab, \"|\", \" \" or "
                        "spaces)");
      }
      map->delimiter = it->second;
      if (map->delimiter == map->decimal) {
        return Fail(kv->line, "delimiter", "the same as the decimal mark");
      }
    }
    if (const KeyValue* kv = find("header_line")) {
      if (!ReadInt(*kv, "header_line", 1, &map->header_line)) return false;
    }
    if (const KeyValue* kv = find("skip_after_header")) {
      if (!ReadInt(*kv, "skip_after_header", 0, &map->skip_after_header)) return false;
    }
    if (const KeyValue* kv = find("unmapped")) {
      if (!ReadText(*kv, "unmapped", &text)) return false;
      if (text != "ignore" && text != "error") {
        return Fail(kv->line, "unmapped", internal::Quote(text) + " is neither ignore nor error");
      }
      map->ignore_unmapped = text == "ignore";
    }
    if (const KeyValue* kv = find("time")) {
      if (!ReadTime(*kv, map)) return false;
    }
    const KeyValue* columns = find("columns");
    if (columns == nullptr) {
      return Fail(0, "columns", "missing: the map names its source columns under columns:");
    }
    return ReadColumns(*columns, map);
  }

  bool ReadTime(const KeyValue& kv, ColumnMap* map) {
    ColumnMapTime& time = map->time;
    time.line = kv.line;
    Keys keys;
    if (kv.value.IsScalar()) {  // time: SysTime  (seconds)
      time.column = kv.value.Scalar();
    } else {
      if (!ReadKeys(kv.value, kv.line, "time", {"column", "format", "zone"}, &keys)) return false;
      const auto it = keys.find("column");
      if (it == keys.end()) return Fail(kv.line, "time.column", "missing: the source column of the time");
      if (!ReadText(it->second, "time.column", &time.column)) return false;
    }
    if (time.column.empty()) return Fail(kv.line, "time.column", "empty");
    if (const auto it = keys.find("format"); it != keys.end()) {
      std::string text;
      if (!ReadText(it->second, "time.format", &text)) return false;
      static const std::map<std::string, TimeFormat> kFormats = {
          {"seconds", TimeFormat::kSeconds},
          {"unix_s", TimeFormat::kUnixSeconds},
          {"unix_ms", TimeFormat::kUnixMilliseconds},
          {"unix_us", TimeFormat::kUnixMicroseconds},
          {"iso8601", TimeFormat::kIso8601}};
      if (const auto f = kFormats.find(text); f != kFormats.end()) {
        time.format = f->second;
      } else if (text.find("%Z") != std::string::npos) {
        // A zone's name ("CST") was parsed and ignored: a silent hour at a DST change
        // (issue 37). The offset is read (%z) or stated (zone:).
        return Fail(it->second.line, "time.format",
                    "%Z (a zone's name) is not read: give the zone's offset with zone: "
                    "\"+08:00\", or %z if the text carries the offset (+0800)");
      } else if (text.find('%') != std::string::npos) {
        time.format = TimeFormat::kPattern;
        time.pattern = text;
      } else {
        return Fail(it->second.line, "time.format",
                    "unknown format " + internal::Quote(text) +
                        " (accepted: seconds, unix_s, unix_ms, unix_us, iso8601, or a pattern "
                        "such as \"%Y/%m/%d %H:%M:%S\")");
      }
    }
    if (const auto it = keys.find("zone"); it != keys.end()) {
      std::string text, why;
      if (!ReadText(it->second, "time.zone", &text)) return false;
      if (!ParseUtcOffset(text, &time.offset_s, &why)) return Fail(it->second.line, "time.zone", why);
      time.zone_given = true;
    }
    // Clock times without a zone were read as UTC: Beijing's export silently 8 hours off
    // (issue 39). The zone is a choice the map states, UTC included.
    if ((time.format == TimeFormat::kIso8601 || time.format == TimeFormat::kPattern) &&
        !time.zone_given) {
      return Fail(kv.line, "time.zone",
                  "missing: clock times need the zone they were written in, e.g. zone: "
                  "\"+08:00\" for Beijing time, or zone: UTC (a stamp that carries its own "
                  "offset, 2024-05-01T12:00:00+08:00, keeps it)");
    }
    map->has_time = true;
    return true;
  }

  bool ReadColumns(const KeyValue& kv, ColumnMap* map) {
    map->columns_line = kv.line;
    if (!kv.value.IsMap()) {
      return Fail(kv.line, "columns", "expected a mapping: fastcal name: {column: NAME, unit: UNIT}");
    }
    const std::vector<std::string>& names = ColumnMapNames();
    // Source column -> who names it (for "named twice").
    std::map<std::string, std::pair<std::string, int>> named;
    if (map->has_time) named[map->time.column] = {"time", map->time.line};
    for (const auto& item : kv.value) {
      const int line = LineOf(item.first);
      if (!item.first.IsScalar()) return Fail(line, "columns", "keys must be fastcal names");
      ColumnMapEntry entry;
      entry.name = item.first.Scalar();
      entry.line = line;
      const std::string path = "columns." + entry.name;
      if (entry.name == "time_s") {
        return Fail(line, path,
                    "the time is given by the map's time: {column: NAME, format: seconds | "
                    "unix_s | unix_ms | iso8601, zone: ...}, not under columns");
      }
      if (std::find(names.begin(), names.end(), entry.name) == names.end() &&
          !IsJointColumnName(entry.name)) {
        return Fail(line, path,
                    "unknown fastcal name" + internal::DidYouMean(entry.name, names) +
                        " (accepted: " + Join(names) +
                        "; and a moving part's joint column, NAME_deg or NAME_m, as the "
                        "model's cabin.moving_parts names it)");
      }
      if (map->Find(entry.name) != nullptr) return Fail(line, path, "given twice");
      const std::vector<std::string> units = UnitsOfName(entry.name);
      entry.unit = units.empty() ? "" : units.front();
      if (item.second.IsScalar()) {  // x_m: SDP_PhaPos_X  (in the canonical unit)
        entry.column = item.second.Scalar();
      } else {
        Keys keys;
        std::vector<std::string> allowed = {"column"};
        if (!units.empty()) allowed.push_back("unit");
        if (!ReadKeys(item.second, line, path, allowed, &keys)) return false;
        const auto c = keys.find("column");
        if (c == keys.end()) return Fail(line, path + ".column", "missing: the source column's name");
        if (!ReadText(c->second, path + ".column", &entry.column)) return false;
        if (const auto u = keys.find("unit"); u != keys.end()) {
          if (!ReadText(u->second, path + ".unit", &entry.unit)) return false;
          if (std::find(units.begin(), units.end(), entry.unit) == units.end()) {
            return Fail(u->second.line, path + ".unit",
                        "unknown unit " + internal::Quote(entry.unit) + " for " + UnitKind(entry.name) +
                            " (accepted: " + Join(units) + ")");
          }
        }
      }
      if (entry.column.empty()) return Fail(line, path + ".column", "empty");
      if (const auto it = named.find(entry.column); it != named.end()) {
        return Fail(line, path + ".column",
                    "source column " + internal::Quote(entry.column) + " is already mapped to " +
                        it->second.first + " (line " + std::to_string(it->second.second) +
                        "): each source column gives one quantity");
      }
      named[entry.column] = {entry.name, line};
      map->columns.push_back(std::move(entry));
    }
    return true;
  }
};

}  // namespace

std::string TimeFormatName(TimeFormat format, const std::string& pattern) {
  switch (format) {
    case TimeFormat::kSeconds:
      return "seconds";
    case TimeFormat::kUnixSeconds:
      return "unix_s";
    case TimeFormat::kUnixMilliseconds:
      return "unix_ms";
    case TimeFormat::kUnixMicroseconds:
      return "unix_us";
    case TimeFormat::kIso8601:
      return "iso8601";
    case TimeFormat::kPattern:
      return pattern;
  }
  return "";
}

const ColumnMapEntry* ColumnMap::Find(const std::string& name) const {
  for (const ColumnMapEntry& e : columns) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

const std::vector<std::string>& ColumnMapNames() {
  static const std::vector<std::string> names = MakeNames();
  return names;
}

bool IsJointColumnName(std::string_view name) {
  const auto ends = [&](std::string_view suffix) {
    return name.size() > suffix.size() && name.substr(name.size() - suffix.size()) == suffix;
  };
  const std::vector<std::string>& names = ColumnMapNames();
  return (ends("_deg") || ends("_m")) &&
         name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") ==
             std::string_view::npos &&
         std::find(names.begin(), names.end(), name) == names.end();
}

std::vector<std::string> JointColumnsOf(const ColumnMap& map) {
  std::vector<std::string> joints;
  for (const ColumnMapEntry& e : map.columns) {
    if (IsJointColumnName(e.name)) joints.push_back(e.name);
  }
  return joints;
}

std::string CanonicalUnitOf(const std::string& name) {
  if (name == "session") return "";
  if (name.size() == 2 && name[0] == 'q') return "1";
  if (EndsWith(name, "_deg")) return "deg";
  if (EndsWith(name, "_kN")) return "kN";
  if (EndsWith(name, "_m")) return "m";
  return "";
}

bool ParseColumnMap(const std::string& text, const std::string& source_name, ColumnMap* map,
                    std::string* error) {
  MapReader reader(source_name);
  ColumnMap parsed;
  parsed.path = source_name;
  parsed.text = text;
  try {
    const internal::YamlDocuments documents = internal::LoadYamlDocuments(text);
    if (documents.count > 1) {
      reader.Fail(documents.second_line, "format", "only one YAML document is allowed");
    } else if (documents.first.IsNull()) {
      reader.Fail(0, "format", std::string("empty: a column map starts with format: ") + kFormat);
    } else {
      reader.ReadRoot(documents.first, &parsed);
    }
  } catch (const YAML::Exception& e) {
    reader.Fail(e.mark.line < 0 ? 0 : e.mark.line + 1, "YAML syntax error", e.msg);
  } catch (const std::bad_alloc&) {
    throw;  // the machine's, not the file's: the caller says "out of memory" (exit 1)
  } catch (const std::exception& e) {
    reader.Fail(0, "format", std::string("cannot read: ") + e.what());
  }
  if (!reader.error().empty()) {
    if (error != nullptr) *error = reader.error();
    return false;
  }
  *map = std::move(parsed);
  return true;
}

bool LoadColumnMap(const std::string& path, ColumnMap* map, std::string* error) {
  std::string text, message;
  if (!internal::ReadRegularFile(path, kMaxColumnMapFileBytes, "column map", &text, &message)) {
    if (error != nullptr) *error = message;
    return false;
  }
  return ParseColumnMap(text, path, map, error);
}

namespace internal {

size_t RecordEnd(std::string_view text, size_t start, bool quotes, int* newlines) {
  size_t from = start;
  bool open = false;  // inside a quoted field
  while (true) {
    const size_t newline = text.find('\n', from);
    if (quotes) {
      const size_t end = newline == std::string_view::npos ? text.size() : newline;
      for (const char* p = static_cast<const char*>(
               std::memchr(text.data() + from, '"', end - from));
           p != nullptr;
           p = static_cast<const char*>(std::memchr(p + 1, '"', text.data() + end - (p + 1)))) {
        open = !open;
      }
    }
    if (!open || newline == std::string_view::npos) return newline;
    if (newlines != nullptr) ++*newlines;
    from = newline + 1;
  }
}

namespace {

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view TrimBlank(std::string_view s) {
  while (!s.empty() && IsBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsBlank(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace

bool SplitRecord(std::string_view record, char delimiter, std::vector<std::string_view>* fields,
                 std::deque<std::string>* scratch, std::string* why) {
  fields->clear();
  const bool spaces = delimiter == ' ';
  const auto is_delimiter = [&](char c) { return spaces ? (c == ' ' || c == '\t') : c == delimiter; };
  size_t i = 0;
  const size_t n = record.size();
  if (spaces) {
    while (i < n && IsBlank(record[i])) ++i;
    if (i == n) return true;
  }
  while (true) {
    // Leading blanks (not the delimiter itself).
    while (i < n && IsBlank(record[i]) && !is_delimiter(record[i])) ++i;
    if (i < n && record[i] == '"') {
      const size_t open = i++;
      std::string unescaped;
      bool doubled = false;
      size_t begin = i;
      while (true) {
        const size_t quote = record.find('"', i);
        if (quote == std::string_view::npos) {
          *why = "field " + std::to_string(fields->size() + 1) +
                 ": a quote opened at byte " + std::to_string(open + 1) + " is not closed";
          return false;
        }
        if (quote + 1 < n && record[quote + 1] == '"') {  // "" inside: one quote
          unescaped.append(record.substr(i, quote + 1 - i));
          doubled = true;
          i = quote + 2;
          continue;
        }
        std::string_view value;
        if (doubled) {
          unescaped.append(record.substr(i, quote - i));
          scratch->push_back(std::move(unescaped));
          value = scratch->back();
        } else {
          value = record.substr(begin, quote - begin);
        }
        fields->push_back(TrimBlank(value));
        i = quote + 1;
        break;
      }
      while (i < n && IsBlank(record[i]) && !is_delimiter(record[i])) ++i;
      if (spaces) {
        const size_t before = i;
        while (i < n && is_delimiter(record[i])) ++i;
        if (i == n) return true;
        if (i == before) {
          *why = "field " + std::to_string(fields->size()) + ": text after its closing quote";
          return false;
        }
        continue;
      }
      if (i == n) return true;
      if (record[i] != delimiter) {
        *why = "field " + std::to_string(fields->size()) + ": text after its closing quote";
        return false;
      }
      ++i;
      continue;
    }
    size_t end = i;
    while (end < n && !is_delimiter(record[end])) ++end;
    fields->push_back(TrimBlank(record.substr(i, end - i)));
    if (end == n) return true;
    i = end + 1;
    if (spaces) {
      while (i < n && is_delimiter(record[i])) ++i;
      if (i == n || (i == n - 1 && record[i] == '\r')) return true;
    }
  }
}

char DetectDelimiter(std::string_view header, char decimal) {
  const char candidates[] = {',', ';', '\t', '|'};
  int counts[4] = {0, 0, 0, 0};
  bool open = false;
  for (char c : header) {
    if (c == '"') open = !open;
    if (open) continue;
    for (int k = 0; k < 4; ++k) counts[k] += c == candidates[k];
  }
  int best = -1;
  for (int k = 0; k < 4; ++k) {
    if (candidates[k] == decimal) continue;
    if (counts[k] > 0 && (best < 0 || counts[k] > counts[best])) best = k;
  }
  if (best >= 0) return candidates[best];
  return decimal == ',' ? ';' : ',';
}

std::string DelimiterName(char delimiter) {
  switch (delimiter) {
    case '\t':
      return "tab";
    case ' ':
      return "spaces";
    default:
      return std::string("'") + delimiter + "'";
  }
}

ValueConversion ConversionOf(const std::string& name, const std::string& unit) {
  ValueConversion c;
  const std::string canonical = CanonicalUnitOf(name);
  if (canonical == "kN") {
    c.internal_per_file = 1e3;
    if (unit == "kN") c.shift = 3;
    if (unit == "tf") c.factor = kNewtonsPerTonneForce;
  } else if (unit == "cm") {
    c.shift = -2;
  } else if (unit == "mm") {
    c.shift = -3;
  } else if (unit == "rad") {
    c.factor = kDegPerRad;
  }
  return c;
}

double ScaleDecimal(std::string_view field, double parsed, int shift) {
  if (shift == 0) return parsed;
  if (double shifted = 0.0; ParseShiftedDecimal(field, shift, &shifted)) return shifted;
  // Only where the text cannot be shifted (hexadecimal, out of range once shifted): a
  // pow a field was 4.5% of reading 10^6 rows.
  return parsed * std::pow(10.0, shift);
}

namespace {

// The field with a decimal comma made a point: in `stack` (64 bytes) when it fits, else
// in `heap`.
std::string_view DecimalPoint(std::string_view field, char decimal, char* stack,
                              std::string* heap) {
  if (decimal != ',' || field.find(',') == std::string_view::npos) return field;
  char* out = stack;
  if (field.size() > 64) {
    heap->assign(field);
    out = heap->data();
  } else {
    std::memcpy(stack, field.data(), field.size());
  }
  std::replace(out, out + field.size(), ',', '.');
  return std::string_view(out, field.size());
}

}  // namespace

bool ReadConvertedNumber(std::string_view field, char decimal, const ValueConversion& conversion,
                         double* file_value, double* internal, std::string* why) {
  // Under a decimal comma a '.' is a thousands separator ("1.234" for 1234, German
  // style) that would read 1000x small: refused, not guessed (issue 37).
  if (decimal == ',' && field.find('.') != std::string_view::npos) {
    *why = Quote(field) + " has a '.' where the map says decimal: \",\": a thousands "
           "separator? (fastcal reads none: remove them from the export, or give "
           "decimal: \".\" if '.' is the decimal point)";
    return false;
  }
  char stack[64];
  std::string heap;
  const std::string_view text = DecimalPoint(field, decimal, stack, &heap);
  double parsed = 0.0;
  if (!ParseFiniteDecimal(text, &parsed, why)) {
    if (decimal == ',' && text != field) *why = Quote(field) + " is not a number";
    return false;
  }
  double value = ScaleDecimal(text, parsed, conversion.shift);
  if (conversion.factor != 1.0) value *= conversion.factor;
  if (!std::isfinite(value)) {
    *why = Quote(field) + " is out of range once converted";
    return false;
  }
  *internal = value;
  const bool same = conversion.factor == 1.0 &&
                    ((conversion.internal_per_file == 1e3 && conversion.shift == 3) ||
                     (conversion.internal_per_file == 1.0 && conversion.shift == 0));
  *file_value = same ? parsed : value / conversion.internal_per_file;
  return true;
}

std::vector<std::string> UnitsOf(const std::string& name) { return UnitsOfName(name); }

namespace {

// A name as compared for "did you mean": lower case, without spaces, '_' and '-'.
std::string NameKey(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == ' ' || c == '_' || c == '-') continue;
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}


}  // namespace

std::string DidYouMean(std::string_view name, const std::vector<std::string_view>& candidates) {
  const std::string wanted = NameKey(name);
  // A typo's reach: one edit in a short name, up to three in a long one.
  // (A name of one or two letters is only matched but for case and separators: one
  // edit away from it lies every other short name.)
  const size_t reach = wanted.size() < 3 ? 0 : std::clamp<size_t>(wanted.size() / 4, 1, 3);
  size_t best = reach + 1;
  std::string_view found;
  const auto letters = [](const std::string& key) {
    std::string out;
    for (char ch : key) {
      if (!std::isdigit(static_cast<unsigned char>(ch))) out += ch;
    }
    return out;
  };
  for (std::string_view c : candidates) {
    const std::string key = NameKey(c);
    // Names that differ only in their numbers (T7_kN, T1_kN) are other channels, not typos.
    if (key != wanted && letters(key) == letters(wanted)) continue;
    const size_t d = EditDistance(wanted, key);
    if (d < best) {
      best = d;
      found = c;
    }
  }
  return best <= reach ? " (did you mean " + Quote(found) + "?)" : "";
}

std::string DidYouMean(std::string_view name, const std::vector<std::string>& candidates) {
  return DidYouMean(name, std::vector<std::string_view>(candidates.begin(), candidates.end()));
}

std::string UnitHint(const std::string& name, const std::string& unit, std::string_view field,
                     char decimal, const std::function<bool(double)>& plausible) {
  for (const std::string& other : UnitsOfName(name)) {
    if (other == unit) continue;
    double file_value = 0.0, internal = 0.0;
    std::string why;
    if (ReadConvertedNumber(field, decimal, ConversionOf(name, other), &file_value, &internal,
                            &why) &&
        plausible(file_value)) {
      return "; in " + other + " it would be plausible: is the column's unit " + other +
             " (unit: " + other + ")?";
    }
  }
  return "";
}

std::string NotANumberHint(std::string_view field, char decimal, bool first_data_row) {
  const bool digits = field.find_first_of("0123456789") != std::string_view::npos;
  if (decimal == '.' && digits && field.find(',') != std::string_view::npos &&
      field.find('.') == std::string_view::npos) {
    return "; a decimal comma? the map says decimal: \".\" (give decimal: \",\")";
  }
  // "inf" or "nan" is a value that is not finite (its own message says so), not a unit.
  std::string word(field.substr(!field.empty() && (field[0] == '-' || field[0] == '+')));
  std::transform(word.begin(), word.end(), word.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const bool not_finite = word == "inf" || word == "infinity" || word == "nan";
  if (first_data_row && !digits && !not_finite) {
    return "; the first row under the header is text: a unit row? (skip_after_header: 1)";
  }
  return "";
}

bool ReadTimeField(std::string_view field, const ColumnMapTime& time, char decimal,
                   double* time_s, std::string* why) {
  switch (time.format) {
    case TimeFormat::kIso8601:
      return ParseIso8601(field, time.offset_s, time_s, why);
    case TimeFormat::kPattern: {
      if (ParseTimePattern(field, time.pattern, time.offset_s, time_s, why)) return true;
      // A spreadsheet's date cell or a DataFrame's datetime column reaches the reader as
      // ISO 8601 text ("2024-05-01 20:00:00"), whatever the pattern the map's CSV export
      // needs: one map serves both (issue 39). Only where the pattern fails, and only a
      // whole ISO date and time (the year first is unambiguous), in the map's zone.
      double iso = 0.0;
      std::string ignored;
      if (field.size() >= 16 && field[4] == '-' && field[7] == '-' &&
          ParseIso8601(field, time.offset_s, &iso, &ignored)) {
        *time_s = iso;
        return true;
      }
      return false;
    }
    default:
      break;
  }
  ValueConversion c;
  c.shift = time.format == TimeFormat::kUnixMilliseconds   ? -3
            : time.format == TimeFormat::kUnixMicroseconds ? -6
                                                           : 0;
  double ignored = 0.0;
  return ReadConvertedNumber(field, decimal, c, &ignored, time_s, why);
}

std::string EntryWhere(const ColumnMap& map, const ColumnMapEntry& entry) {
  return map.path + ":" + std::to_string(entry.line) + ": columns." + Escape(entry.name) + ": ";
}
std::string TimeWhere(const ColumnMap& map) {
  return map.path + ":" + std::to_string(map.time.line) + ": time: ";
}
std::string ColumnsWhere(const ColumnMap& map) {
  return map.path + ":" + std::to_string(map.columns_line) + ": columns: ";
}

namespace {

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string NearName(const std::string& name, const std::vector<std::string_view>& fields) {
  return DidYouMean(name, fields);
}

}  // namespace

bool ResolveMappedHeader(const ColumnMap& map, const std::vector<std::string_view>& fields,
                         const std::vector<std::string>& names, const std::string& where,
                         const std::string& data_path, MappedHeader* header, std::string* error) {
  header->target_of_field.assign(fields.size(), -1);
  header->field_of_target.assign(names.size(), -1);
  header->entry_of_target.assign(names.size(), nullptr);
  header->time_field = -1;
  std::map<std::string_view, std::vector<size_t>> positions;
  for (size_t f = 0; f < fields.size(); ++f) positions[fields[f]].push_back(f);
  // Finds source column `column` (for `what`, named at `map_where`): its field or -1.
  const auto find = [&](const std::string& column, const std::string& what,
                        const std::string& map_where, int* field) {
    const auto it = positions.find(column);
    if (it == positions.end()) {
      *error = map_where + "source column " + Quote(column) + " is not in the header of " +
               Escape(data_path) + " (" + where.substr(0, where.size() - 2) + ")" +
               NearName(column, fields);
      return false;
    }
    if (it->second.size() > 1) {
      *error = where + "column " + Quote(column) + " (mapped to " + what + ") appears twice (fields " +
               std::to_string(it->second[0] + 1) + " and " + std::to_string(it->second[1] + 1) + ")";
      return false;
    }
    *field = static_cast<int>(it->second.front());
    return true;
  };
  if (map.has_time) {
    if (!find(map.time.column, "time_s", TimeWhere(map), &header->time_field)) return false;
    header->target_of_field[header->time_field] = kTimeTarget;
  }
  std::set<size_t> used;
  if (header->time_field >= 0) used.insert(static_cast<size_t>(header->time_field));
  for (const ColumnMapEntry& entry : map.columns) {
    const auto it = std::find(names.begin(), names.end(), entry.name);
    if (it == names.end()) {
      // Not a quantity this reader takes: its column is not an unmapped one.
      if (const auto p = positions.find(entry.column); p != positions.end()) {
        for (size_t f : p->second) used.insert(f);
      }
      continue;
    }
    const int target = static_cast<int>(it - names.begin());
    int field = -1;
    if (!find(entry.column, entry.name, EntryWhere(map, entry), &field)) return false;
    header->target_of_field[field] = target;
    header->field_of_target[target] = field;
    header->entry_of_target[target] = &entry;
    used.insert(static_cast<size_t>(field));
  }
  if (map.ignore_unmapped) return true;
  std::vector<std::string> unmapped;
  for (size_t f = 0; f < fields.size(); ++f) {
    if (used.count(f) == 0) unmapped.push_back(fields[f].empty() ? "(field " + std::to_string(f + 1) + ", no name)" : Quote(fields[f]));
  }
  if (unmapped.empty()) return true;
  constexpr size_t kShown = 12;
  const size_t count = unmapped.size();
  if (count > kShown) {
    unmapped.resize(kShown);
    unmapped.push_back("... (" + std::to_string(count) + " in all)");
  }
  *error = where + (count == 1 ? "a column" : std::to_string(count) + " columns") +
           " not in the column map " + Escape(map.path) + ": " + Join(unmapped) +
           " (map each under columns:, or set unmapped: ignore)";
  return false;
}

std::string SpreadsheetMessage(const std::string& path, std::string_view start, bool by_name) {
  std::string extension;
  if (const size_t dot = path.rfind('.'); dot != std::string::npos && path.find('/', dot) == std::string::npos) {
    extension = Lower(path.substr(dot + 1));
  }
  by_name = by_name && (extension == "xlsx" || extension == "xlsm" || extension == "xls" ||
                        extension == "ods");
  const bool zip = start.substr(0, 4) == std::string_view("PK\x03\x04", 4);
  const bool ole = start.substr(0, 4) == std::string_view("\xD0\xCF\x11\xE0", 4);
  if (!by_name && !zip && !ole) return "";
  const std::string name = Escape(path);
  return name +
         ": a spreadsheet, not CSV text: the command line reads CSV. Read it in Python "
         "(python3-openpyxl): fastcal.read_dataset(\"" +
         name +
         "\", columns=\"MAP.yaml\"), or convert it first: xlsx2csv " + name +
         " export.csv (Debian package xlsx2csv), then fastcal import --columns=MAP.yaml "
         "--data=export.csv --out=data.csv (docs/data-format.md, \"Column maps\")";
}

}  // namespace internal
}  // namespace fastcal
