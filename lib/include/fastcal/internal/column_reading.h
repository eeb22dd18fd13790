// Reading a telemetry export through a column map (column_map.h): records and fields as
// RFC 4180 readers split them, the delimiter detected from the header line, the header's
// source columns matched to fastcal names, and each field's number or time stamp
// converted to fastcal's units. Shared by the dataset reader (dataset.cc) and the pose
// file reader (trajectory.cc), so that one text reads alike everywhere.
#ifndef FASTCAL_INTERNAL_COLUMN_READING_H_
#define FASTCAL_INTERNAL_COLUMN_READING_H_

#include <deque>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "fastcal/column_map.h"

namespace fastcal::internal {

// Where the record that starts at text[start] ends: the index of its terminating '\n',
// or npos when the text ends first. With `quotes`, a '\n' inside a quoted field (an odd
// number of '"' before it in the record) does not end it; *newlines (may be null)
// counts the line breaks inside the record.
size_t RecordEnd(std::string_view text, size_t start, bool quotes, int* newlines);

// Splits one record into fields at `delimiter` (' ' splits at runs of spaces and tabs),
// RFC 4180 style: a field may be quoted ("a,b", "say ""hi"""), spaces and tabs around a
// field (and a trailing '\r') are dropped. A quoted field with doubled quotes is
// unescaped into *scratch (its views stay valid until *scratch is cleared). False, with
// *why, on a quote left open or text after a closing quote.
bool SplitRecord(std::string_view record, char delimiter, std::vector<std::string_view>* fields,
                 std::deque<std::string>* scratch, std::string* why);

// The delimiter of a header line: of ',' ';' '\t' '|' the one found most often outside
// quotes (',' not when the decimal mark is ','); ',' (';' with a decimal comma) when
// none is.
char DetectDelimiter(std::string_view header, char decimal);

// "','", "';'", "tab", "'|'", "spaces".
std::string DelimiterName(char delimiter);

// How a source number becomes fastcal's value: internal = number x 10^shift (exact: the
// decimal exponent of the text is shifted) x factor (one rounding; 1 for none). The
// canonical file's unit (kN, m, deg) is internal / internal_per_file (1e3 for a tension:
// N in memory, kN in files), the value the plausibility limits are stated in.
struct ValueConversion {
  int shift = 0;
  double factor = 1.0;
  double internal_per_file = 1.0;
};

// The conversion of fastcal name `name` from `unit` (checked by the map's reader).
ValueConversion ConversionOf(const std::string& name, const std::string& unit);

// The units fastcal name `name` may come in (m, cm, mm; deg, rad; kN, N, tf), canonical
// first; none for a label or a quaternion.
std::vector<std::string> UnitsOf(const std::string& name);

// The hint for a value the map's unit makes implausible (issue 39): the other unit of
// `name` in which `field` would pass `plausible` (a test of the canonical file's value),
// as "; in N it would be plausible: is the column's unit N (unit: N)?", else "".
std::string UnitHint(const std::string& name, const std::string& unit, std::string_view field,
                     char decimal, const std::function<bool(double)>& plausible);

// " (did you mean 'X'?)" for the candidate nearest `name` when it is a likely typo: the
// same but for case, spaces, '_' and '-', or within a few edits of it (Levenshtein: one
// in a short name, up to three in a long one); "" otherwise.
std::string DidYouMean(std::string_view name, const std::vector<std::string_view>& candidates);
std::string DidYouMean(std::string_view name, const std::vector<std::string>& candidates);

// The hint for a field that is not a number (issue 39): a decimal comma under the map's
// '.', or a unit row ("mm", "N") under the header: "; ... (decimal: \",\")", else "".
std::string NotANumberHint(std::string_view field, char decimal, bool first_data_row);

// Reads one field as a number with `decimal` as its decimal mark and converts it:
// *file_value in the canonical file's unit (for the limits), *internal in memory's.
// False with *why ("'abc' is not a number", "missing value", ...).
bool ReadConvertedNumber(std::string_view field, char decimal, const ValueConversion& conversion,
                         double* file_value, double* internal, std::string* why);

// `field` (a decimal number already parsed as `parsed`) x 10^shift, by shifting the
// exponent of its text: the correctly rounded value of the decimal number.
double ScaleDecimal(std::string_view field, double parsed, int shift);

// Reads one time stamp as the map's `time` says: seconds (any epoch, or Unix), Unix
// milliseconds or microseconds, ISO 8601 or a pattern (zone: time.offset_s when the
// text has none). *time_s in seconds (Unix seconds for absolute formats).
bool ReadTimeField(std::string_view field, const ColumnMapTime& time, char decimal,
                   double* time_s, std::string* why);

// A header line's fields matched to a reader's quantities. `names` are the fastcal names
// the reader takes (a subset of ColumnMapNames(), e.g. no tensions for a pose file);
// map entries of other names are not read.
struct MappedHeader {
  std::vector<int> target_of_field;  // per field: index into names, kTimeTarget, or -1
  std::vector<int> field_of_target;  // per index into names: the field, or -1
  int time_field = -1;
  std::vector<const ColumnMapEntry*> entry_of_target;  // per index into names, or null
};
inline constexpr int kTimeTarget = -2;

// Matches the map's source columns to the header's `fields`. Errors: a mapped source
// column missing from the header (named with the map's key and line, and a near name:
// "did you mean 'sdp_phapos_x'"), a mapped column the header has twice, and, unless the
// map says `unmapped: ignore`, every header column the map does not name. `where` is
// "data.csv:2: " (the header line), `data_path` the file's name.
bool ResolveMappedHeader(const ColumnMap& map, const std::vector<std::string_view>& fields,
                         const std::vector<std::string>& names, const std::string& where,
                         const std::string& data_path, MappedHeader* header, std::string* error);

// "map.yaml:7: columns.x_m: " for messages about an entry, "map.yaml:3: time: " for the
// time, "map.yaml:5: columns: " for the map as a whole.
std::string EntryWhere(const ColumnMap& map, const ColumnMapEntry& entry);
std::string TimeWhere(const ColumnMap& map);
std::string ColumnsWhere(const ColumnMap& map);

// A file that is a spreadsheet rather than text (.xlsx, .xls, .ods by name when
// `by_name`, or a ZIP or OLE2 signature at its start): the message that says how to read
// it (the Python route, or xlsx2csv); "" otherwise. `start`: the file's first bytes (may
// be empty).
std::string SpreadsheetMessage(const std::string& path, std::string_view start,
                               bool by_name = true);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_COLUMN_READING_H_
