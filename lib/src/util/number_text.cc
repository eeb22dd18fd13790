// Locale-independent number text (declarations: internal/number_text.h).
#include "fastcal/internal/number_text.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <system_error>

#include "fastcal/internal/quote.h"

namespace fastcal::internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool StartsWithNoCase(std::string_view text, std::string_view prefix) {
  if (text.size() < prefix.size()) return false;
  for (size_t i = 0; i < prefix.size(); ++i) {
    if ((text[i] | 0x20) != prefix[i]) return false;
  }
  return true;
}

// For an unsigned number that std::from_chars found out of range: true when it is too
// large, false when too small. Out of range means beyond 1.8e308 or below 4.9e-324, so
// the decimal magnitude (where the first non-zero digit stands, plus the exponent)
// decides. `exponent_chars` is "eE" for decimal text, "pP" for hexadecimal.
bool TooLarge(std::string_view text, const char* exponent_chars, const char* nonzero_digits) {
  long exponent = 0;
  const size_t e = text.find_first_of(exponent_chars);
  if (e != std::string_view::npos) {
    std::string_view x = text.substr(e + 1);
    const bool negative = !x.empty() && x.front() == '-';
    if (!x.empty() && (x.front() == '+' || x.front() == '-')) x.remove_prefix(1);
    long magnitude = 0;
    const auto [ptr, ec] = std::from_chars(x.data(), x.data() + x.size(), magnitude);
    if (ec == std::errc::result_out_of_range) return !negative;
    exponent = negative ? -magnitude : magnitude;
    text = text.substr(0, e);
  }
  const size_t point = std::min(text.find('.'), text.size());
  const size_t first = text.find_first_of(nonzero_digits);
  if (first == std::string_view::npos) return false;
  const long lead =
      first < point ? static_cast<long>(point - first) : -static_cast<long>(first - point - 1);
  return lead + exponent > 0;
}

}  // namespace

bool ParseDouble(std::string_view text, double* value) {
  std::string_view t = text;
  bool negative = false;
  if (!t.empty() && (t.front() == '+' || t.front() == '-')) {
    negative = t.front() == '-';
    t.remove_prefix(1);
  }
  // from_chars takes no sign of its own here (the '-' it would take is handled above, so
  // "+-1" and "--1" stay errors), and hexadecimal text without its "0x".
  if (t.empty() || t.front() == '+' || t.front() == '-') return false;
  std::chars_format format = std::chars_format::general;
  const char* exponent_chars = "eE";
  const char* nonzero_digits = "123456789";
  if (StartsWithNoCase(t, "0x")) {
    t.remove_prefix(2);
    format = std::chars_format::hex;
    exponent_chars = "pP";
    nonzero_digits = "123456789abcdefABCDEF";
  }
  double parsed = 0.0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), parsed, format);
  if (ptr != t.data() + t.size() || ptr == t.data()) return false;
  if (ec == std::errc::result_out_of_range) {
    parsed = TooLarge(t, exponent_chars, nonzero_digits) ? kInf : 0.0;
  } else if (ec != std::errc()) {
    return false;
  }
  *value = negative ? -parsed : parsed;
  return true;
}

namespace {

enum class Decimal {
  kExact,  // Clinger's fast path gave the value
  kPlain,  // the grammar of a plain decimal, beyond the fast path: std::from_chars reads it
  kOther,  // not a plain decimal (empty, hexadecimal, inf, nan, a stray character...)
};

// `text`'s grammar ([+-]digits[.digits][(e|E)[+-]digits]) in one scan, then, when it has
// at most 16 significant digits (2^53 has 16: a 17-digit mantissa is above it), its
// value times 10^shift by Clinger's fast path.
Decimal ScanDecimal(std::string_view text, int shift, double* value) {
  constexpr int kMaxDigits = 16;
  constexpr std::uint64_t kMaxExact = 1ULL << 53;
  constexpr int kMaxPower = 22;          // 10^22 is the largest exact power of ten
  constexpr long kMaxExponent = 100000;  // beyond: the exponent is only checked
  static constexpr double kPowers[kMaxPower + 1] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                                    1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                                    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const auto is_digit = [](char c) { return static_cast<unsigned char>(c - '0') < 10; };
  const char* p = text.data();
  const char* const end = p + text.size();
  bool negative = false;
  if (p != end && (*p == '+' || *p == '-')) negative = *p++ == '-';
  const char* const whole = p;  // the integer digits [whole, whole_end)
  while (p != end && is_digit(*p)) ++p;
  const char* const whole_end = p;
  const char* fraction = p;  // the fraction digits [fraction, fraction_end)
  if (p != end && *p == '.') {
    fraction = ++p;
    while (p != end && is_digit(*p)) ++p;
  }
  const char* const fraction_end = p;
  if (whole == whole_end && fraction == fraction_end) return Decimal::kOther;
  long exponent = 0;
  if (p != end && (*p == 'e' || *p == 'E')) {
    ++p;
    bool negative_exponent = false;
    if (p != end && (*p == '+' || *p == '-')) negative_exponent = *p++ == '-';
    if (p == end || !is_digit(*p)) return Decimal::kOther;
    for (; p != end && is_digit(*p); ++p) {
      if (exponent <= kMaxExponent) exponent = exponent * 10 + (*p - '0');
    }
    if (negative_exponent) exponent = -exponent;
  }
  if (p != end) return Decimal::kOther;
  // The significant digits: from the first non-zero one.
  const char* first = whole;
  while (first != whole_end && *first == '0') ++first;
  const char* first_fraction = fraction;
  if (first == whole_end) {
    while (first_fraction != fraction_end && *first_fraction == '0') ++first_fraction;
  }
  const long digits = first != whole_end ? (whole_end - first) + (fraction_end - fraction)
                                         : fraction_end - first_fraction;
  if (digits == 0) {  // zero, whatever the exponent
    *value = negative ? -0.0 : 0.0;
    return Decimal::kExact;
  }
  if (digits > kMaxDigits || std::labs(exponent) > kMaxExponent) return Decimal::kPlain;
  std::uint64_t m = 0;
  for (const char* d = first; d < whole_end; ++d) m = m * 10 + static_cast<std::uint64_t>(*d - '0');
  for (const char* d = first != whole_end ? fraction : first_fraction; d < fraction_end; ++d) {
    m = m * 10 + static_cast<std::uint64_t>(*d - '0');
  }
  const long power = shift + exponent - (fraction_end - fraction);
  if (m > kMaxExact || power < -kMaxPower || power > kMaxPower) return Decimal::kPlain;
  const double v = power < 0 ? static_cast<double>(m) / kPowers[-power]
                             : static_cast<double>(m) * kPowers[power];
  *value = negative ? -v : v;
  return Decimal::kExact;
}

}  // namespace

bool ParseDecimalFastPath(std::string_view text, int shift, double* value) {
  return ScanDecimal(text, shift, value) == Decimal::kExact;
}

bool ParseShiftedDecimal(std::string_view text, int shift, double* value) {
  // The fast path where the text may have 16 significant digits or fewer: 16 digits and
  // a point. A longer text has more, but for a sign, leading zeros or an exponent; the
  // shifted text gives it the same bits, one scan instead of two.
  constexpr size_t kFastPathLongest = 17;
  if (!text.empty() && text.front() == '+') {  // from_chars takes no '+': dropped here
    text.remove_prefix(1);
    if (text.empty() || text.front() == '+' || text.front() == '-') return false;
  }
  if (text.size() <= kFastPathLongest) {
    const Decimal kind = ScanDecimal(text, shift, value);
    if (kind == Decimal::kExact) return true;
    if (kind == Decimal::kOther) return false;
  }
  constexpr long kMaxShiftableExponent = 100000;
  const size_t e = text.find_first_of("eE");
  const std::string_view mantissa = text.substr(0, e);
  long exponent = 0;
  if (e != std::string_view::npos) {
    std::string_view x = text.substr(e + 1);
    if (!x.empty() && x.front() == '+') {
      x.remove_prefix(1);
      if (!x.empty() && (x.front() == '-' || x.front() == '+')) return false;  // "e+-5"
    }
    const auto [end, ec] = std::from_chars(x.data(), x.data() + x.size(), exponent);
    if (ec != std::errc() || end != x.data() + x.size() ||
        std::labs(exponent) > kMaxShiftableExponent) {
      return false;
    }
  }
  // "<mantissa>e<exponent + shift>", on the stack for the usual field (no allocation a
  // field: 10^6 rows of them). from_chars checks the mantissa's grammar: "inf", "nan" and
  // "0x..." stop it before the 'e'.
  char stack[96];
  std::string heap;
  char* out = stack;
  if (mantissa.size() + 24 > sizeof(stack)) {
    heap.resize(mantissa.size() + 24);
    out = heap.data();
  }
  std::memcpy(out, mantissa.data(), mantissa.size());
  char* end = out + mantissa.size();
  *end++ = 'e';
  end = std::to_chars(end, out + mantissa.size() + 24, exponent + shift).ptr;
  double shifted = 0.0;
  const auto [stop, ec] = std::from_chars(out, end, shifted, std::chars_format::general);
  if (ec != std::errc() || stop != end || !std::isfinite(shifted)) return false;
  *value = shifted;
  return true;
}

bool ParseFiniteDecimal(std::string_view text, double* value, std::string* why) {
  double parsed = 0.0;
  // Most fields in one scan: std::from_chars's grammar ([-]digits[.digits][(e|E)[+-]digits],
  // inf and nan) is the decimal grammar but for a leading '+' and the infinities, and its
  // value the correctly rounded one, as the fast path's. (The scan first, then from_chars
  // again beyond 16 digits, read a simulated file's fields twice.)
  if (!text.empty() && text.front() != '+') {
    const auto [end, ec] =
        std::from_chars(text.data(), text.data() + text.size(), parsed, std::chars_format::general);
    if (ec == std::errc() && end == text.data() + text.size() && std::isfinite(parsed)) {
      *value = parsed;
      return true;
    }
  }
  const Decimal kind = ScanDecimal(text, 0, &parsed);
  if (kind == Decimal::kExact) {
    *value = parsed;
    return true;
  }
  // A plain decimal beyond the fast path: std::from_chars alone (its grammar is checked).
  const bool number = ParseDouble(text, &parsed);
  if (kind == Decimal::kPlain && number && std::isfinite(parsed)) {
    *value = parsed;
    return true;
  }
  if (text.empty()) {
    *why = "missing value";
  } else if (number && kind == Decimal::kOther) {
    *why = std::isfinite(parsed)
               ? Quote(text) + " is not a decimal number (hexadecimal is not accepted)"
               : "value is not finite";
  } else if (!number) {
    *why = Quote(text) + " is not a number";
  } else {
    *why = Quote(text) + " is out of the range of a double";
  }
  return false;
}

std::string FormatDouble(std::string_view format, double value) {
  std::string out;
  size_t i = 0;
  bool converted = false;
  while (i < format.size()) {
    const char c = format[i++];
    if (c != '%') {
      out += c;
      continue;
    }
    if (i < format.size() && format[i] == '%') {
      out += '%';
      ++i;
      continue;
    }
    bool plus = false, left = false;
    for (; i < format.size() && (format[i] == '+' || format[i] == '-'); ++i) {
      (format[i] == '+' ? plus : left) = true;
    }
    size_t width = 0;
    for (; i < format.size() && format[i] >= '0' && format[i] <= '9'; ++i) {
      width = width * 10 + static_cast<size_t>(format[i] - '0');
    }
    int precision = 6;  // printf's default
    if (i < format.size() && format[i] == '.') {
      precision = 0;
      for (++i; i < format.size() && format[i] >= '0' && format[i] <= '9'; ++i) {
        precision = precision * 10 + (format[i] - '0');
      }
    }
    const char conversion = i < format.size() ? format[i++] : 'g';
    const std::chars_format chars = conversion == 'f'   ? std::chars_format::fixed
                                    : conversion == 'e' ? std::chars_format::scientific
                                                        : std::chars_format::general;
    // Large enough for %.*f of the largest double with the precisions fastcal uses.
    char buffer[400];
    std::string number;
    if (std::isnan(value)) {
      number = std::signbit(value) ? "-nan" : "nan";  // to_chars' spelling of the sign varies
    } else {
      const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value, chars, precision);
      number.assign(buffer, result.ec == std::errc() ? result.ptr : buffer);
    }
    if (plus && !number.empty() && number.front() != '-') number.insert(0, "+");
    if (number.size() < width) {
      const std::string pad(width - number.size(), ' ');
      number = left ? number + pad : pad + number;
    }
    out += converted ? std::string() : number;  // a second conversion has no argument
    converted = true;
  }
  return out;
}

std::string WithoutNegativeZero(std::string text) {
  if (text.size() < 2 || text[0] != '-') return text;
  // The mantissa's digits, up to an exponent, a unit or the end: all zero?
  const size_t end = text.find_first_not_of("0.", 1);
  const bool zero = end != 1 && (end == std::string::npos ||
                                 !std::isdigit(static_cast<unsigned char>(text[end])));
  if (zero) text.erase(0, 1);
  return text;
}

std::string FormatBeyond(double value, double limit) {
  const std::string shown_limit = FormatDouble("%.6g", limit);
  for (const char* format : {"%.6g", "%.10g"}) {
    const std::string shown = FormatDouble(format, value);
    if (shown != shown_limit) return shown;
  }
  return FormatDouble("%.17g", value);
}

std::string Counted(long long n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace fastcal::internal
