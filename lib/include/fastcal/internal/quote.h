// User text quoted for a message: file names, column names, field values and flag values
// come from files and command lines that may hold anything (a binary file read as CSV, a
// 10 MB header line). Echoed raw they would send control bytes to the terminal (escape
// sequences that rewrite the screen) and make a message as long as the file.
#ifndef FASTCAL_INTERNAL_QUOTE_H_
#define FASTCAL_INTERNAL_QUOTE_H_

#include <cstddef>
#include <string>
#include <string_view>

namespace fastcal::internal {

// Longest part of the user's text a message shows, in bytes of the input.
inline constexpr size_t kMaxQuotedBytes = 64;

// `text` between single quotes, safe to print: control bytes (below 0x20, 0x7f), bytes
// that are not part of valid UTF-8, and the C1 controls U+0080..U+009F are written as
// \xNN (\t, \n, \r as such), a quote or backslash is escaped; valid UTF-8 otherwise
// stays as it is. Text longer than `max_bytes` is cut at a character boundary and ends
// with "... (N bytes)" after the closing quote.
std::string Quote(std::string_view text, size_t max_bytes = kMaxQuotedBytes);

// The same without the quotes and without the cut: for text that must stay whole (a path
// in a message that names the file).
std::string Escape(std::string_view text);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_QUOTE_H_
