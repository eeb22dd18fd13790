// --columns and --sessions-at (columns_flag.h).
#include "columns_flag.h"

#include <gflags/gflags.h>

#include <filesystem>
#include <string_view>

#include "common_flags.h"
#include "fastcal/change_scan.h"
#include "fastcal/file_digest.h"
#include "fastcal/internal/quote.h"
#include "fastcal/sessions.h"
#include "fastcal/time_text.h"

namespace fastcal::cli {

const char kColumnsFlagHelp[] =
    R"(  --columns=MAP.yaml  read the telemetry export as it comes, through a column map
                      (format fastcal-columns-1): which source column holds each
                      quantity and in what unit (mm, cm, rad, N, tf...), the time stamps
                      (seconds, unix_s, unix_ms, iso8601 with a zone), delimiter, decimal
                      comma, header line, unit row, extra channels; docs/data-format.md,
                      "Column maps")";

const char kSessionsAtFlagHelp[] =
    R"(  --sessions-at=TIME[,TIME...]  cut one survey into sessions s1, s2, ... at these
                      times (a sample at or after a time belongs to the next session):
                      each a number in the data's time_s or an ISO 8601 date and time
                      (2024-05-01T12:34:56+08:00; without a zone, the column map's zone,
                      else UTC). --sessions-at=DIR/summary.json takes the changes a
                      previous calibrate's change scan found (its verdict also prints
                      the value to give))";

bool ColumnsFromFlag(std::shared_ptr<const ColumnMap>* map, std::string* error) {
  map->reset();
  if (FLAGS_columns.empty()) return true;
  auto loaded = std::make_shared<ColumnMap>();
  if (!LoadColumnMap(FLAGS_columns, loaded.get(), error)) return false;
  *map = std::move(loaded);
  return true;
}

std::string ColumnsDigest() {
  std::string hex, ignored;
  return !FLAGS_columns.empty() && FileSha256(FLAGS_columns, &hex, &ignored) ? hex : "";
}

bool SessionCutsFromFlag(const Dataset& layout, std::vector<double>* cuts_s, std::string* error) {
  cuts_s->clear();
  if (FLAGS_sessions_at.empty()) return true;
  const std::string& value = FLAGS_sessions_at;
  const std::string where = "--sessions-at=" + internal::Escape(value) + ": ";
  std::error_code ec;
  const bool json = value.size() > 5 && value.compare(value.size() - 5, 5, ".json") == 0;
  if (json || std::filesystem::is_regular_file(value, ec)) {
    if (!ReadSummaryChangeTimes(value, cuts_s, error)) return false;
  } else {
    std::string_view rest(value);
    while (true) {
      const size_t comma = rest.find(',');
      const std::string_view item = rest.substr(0, comma);
      double t = 0.0;
      std::string why;
      if (!ParseTimeValue(item, layout.time_offset_s, &t, &why)) {
        *error = where + why;
        return false;
      }
      cuts_s->push_back(t);
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
  }
  std::string why;
  if (!CheckSessionCuts(*cuts_s, &why)) {
    *error = where + why;
    return false;
  }
  return true;
}

}  // namespace fastcal::cli
