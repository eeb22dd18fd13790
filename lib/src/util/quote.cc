// Safe quoting of user text in messages (internal/quote.h).
#include "fastcal/internal/quote.h"

#include <cstdint>

namespace fastcal::internal {
namespace {

// Length of the valid UTF-8 sequence at text[i] (1..4), or 0 when the bytes there are not
// one (a stray continuation byte, an overlong form, a surrogate, beyond U+10FFFF) or
// encode a C1 control character.
size_t Utf8Length(std::string_view text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<uint8_t>(text[k]); };
  const uint8_t b0 = byte(i);
  size_t n = 0;
  uint32_t code = 0;
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    n = 2;
    code = b0 & 0x1F;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    n = 3;
    code = b0 & 0x0F;
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    n = 4;
    code = b0 & 0x07;
  } else {
    return 0;
  }
  if (i + n > text.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(i + k) & 0x3F);
  }
  const bool overlong = (n == 3 && code < 0x800) || (n == 4 && code < 0x10000);
  const bool surrogate = code >= 0xD800 && code <= 0xDFFF;
  const bool c1_control = code >= 0x80 && code <= 0x9F;
  if (overlong || surrogate || c1_control || code > 0x10FFFF) return 0;
  return n;
}

// Appends text[i..] escaped, up to `max_bytes` of input; returns the input bytes used.
size_t AppendEscaped(std::string_view text, size_t max_bytes, bool escape_quote, std::string* out) {
  static const char kHex[] = "0123456789abcdef";
  size_t i = 0;
  while (i < text.size()) {
    const uint8_t c = static_cast<uint8_t>(text[i]);
    size_t n = 1;
    std::string piece;
    if (c == '\t') {
      piece = "\\t";
    } else if (c == '\n') {
      piece = "\\n";
    } else if (c == '\r') {
      piece = "\\r";
    } else if (c == '\\' || (escape_quote && c == '\'')) {
      piece = std::string("\\") + static_cast<char>(c);
    } else if (c >= 0x20 && c < 0x7f) {
      piece = static_cast<char>(c);
    } else if (c >= 0x80 && (n = Utf8Length(text, i)) > 0) {
      piece = std::string(text.substr(i, n));
    } else {
      n = 1;
      piece = std::string("\\x") + kHex[c >> 4] + kHex[c & 0xF];
    }
    if (i + n > max_bytes) break;
    *out += piece;
    i += n;
  }
  return i;
}

}  // namespace

std::string Quote(std::string_view text, size_t max_bytes) {
  std::string out = "'";
  const size_t used = AppendEscaped(text, max_bytes, /*escape_quote=*/true, &out);
  out += "'";
  if (used < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

std::string Escape(std::string_view text) {
  std::string out;
  AppendEscaped(text, text.size(), /*escape_quote=*/false, &out);
  return out;
}

}  // namespace fastcal::internal
