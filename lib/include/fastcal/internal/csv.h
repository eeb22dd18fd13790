// Helpers shared by the CSV readers (dataset.cc, trajectory.cc) and writers (workspace.cc,
// the command line).
#ifndef FASTCAL_INTERNAL_CSV_H_
#define FASTCAL_INTERNAL_CSV_H_

#include <string>
#include <string_view>

namespace fastcal::internal {

// For a header line without a comma but with ';' or tabs (a spreadsheet export in another
// locale): the message that the separator must be a comma. "" for any other line.
inline std::string WrongSeparatorMessage(std::string_view header) {
  if (header.find(',') != std::string_view::npos) return "";
  const char* separator = header.find(';') != std::string_view::npos    ? "';'"
                          : header.find('\t') != std::string_view::npos ? "tabs"
                                                                        : nullptr;
  if (separator == nullptr) return "";
  return std::string("the header is separated by ") + separator +
         ": fields must be separated by commas, or read the export as it is through a "
         "column map (--columns=MAP.yaml, docs/data-format.md, \"Column maps\")";
}

// `text` as one CSV field in double quotes, inner quotes doubled (RFC 4180), so that
// commas, quotes and line breaks in a message stay inside its column for any CSV reader
// (pandas, Python's csv). Messages are always quoted, so that a column reads alike.
inline std::string QuotedCsvField(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_CSV_H_
