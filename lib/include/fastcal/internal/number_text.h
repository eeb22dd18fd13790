// Numbers as text, the same in every locale. std::strtod and printf's %f/%e/%g follow the
// C locale's LC_NUMERIC, so a program that calls setlocale(LC_ALL, "") under a German or
// French locale (a GUI host, a Python session that did locale.setlocale) would read
// "1.5" as 1 and write "1,5" into CSV, JSON, YAML and SVG. These use std::from_chars and
// std::to_chars, which always use '.'.
#ifndef FASTCAL_INTERNAL_NUMBER_TEXT_H_
#define FASTCAL_INTERNAL_NUMBER_TEXT_H_

#include <string>
#include <string_view>

namespace fastcal::internal {

// Parses the whole of `text` as a number, as strtod does in the "C" locale: an optional
// sign ('+' too), a decimal number with an optional exponent ("1.5", "-2e-3", ".5"), a
// hexadecimal one ("0x1.8p1"), "inf", "infinity" or "nan" (any case; callers that need a
// finite value check). A value beyond the range of a double reads as +-infinity, one
// below the smallest subnormal as +-0. No white space is skipped. False (and *value
// untouched) when the text is not entirely a number.
bool ParseDouble(std::string_view text, double* value);

// Reads the whole of `text` as a number the way every fastcal file and flag does: a
// decimal number with an optional sign and exponent ("1.5", "-2e-3", "+7", ".5", "5.").
// Hexadecimal ("0x10", which strtod reads as 16), "inf", "nan", white space and anything
// else is not a number. On success *value is finite; otherwise false with *why, e.g.
//   "missing value", "'0x10' is not a decimal number (hexadecimal is not accepted)",
//   "'abc' is not a number", "'1e999' is out of the range of a double",
//   "value is not finite" (inf, nan).
// User text in *why is quoted with internal::Quote (escaped, length capped).
bool ParseFiniteDecimal(std::string_view text, double* value, std::string* why);

// The decimal text's value times 10^shift, correctly rounded, when `text` is a plain
// decimal ([+-]digits[.digits][(e|E)[+-]digits], as ParseFiniteDecimal reads) of at
// most 16 significant digits whose integer mantissa m is at most 2^53 and whose power of
// ten p (the exponent, the point's place and `shift` together) is within [-22, 22]:
// then m and 10^|p| are exact doubles and their one product or quotient is rounded
// correctly by IEEE arithmetic (Clinger's fast path, W. D. Clinger, "How to read
// floating point numbers accurately", PLDI 1990), the value std::from_chars gives.
// False otherwise, *value untouched: parse the text the general way. Most telemetry
// fields (a few decimals of a kN or a metre) take this path; std::from_chars and the
// grammar check were a quarter of reading a CSV (issue 41).
bool ParseDecimalFastPath(std::string_view text, int shift, double* value);

// `text`, a plain decimal ([+-]digits[.digits][(e|E)[+-]digits]), times 10^shift: the
// correctly rounded value of the decimal number with its exponent shifted (so a kN field
// read as N is the value a reader of "<digits>e<exponent + 3>" gets), in one scan of the
// text (the fast path above where it may hold, else std::from_chars of the shifted
// text). False, *value untouched, for other text (hexadecimal, inf, nan) and for
// a value out of range: read it the general way.
bool ParseShiftedDecimal(std::string_view text, int shift, double* value);

// `value` formatted by a printf format with exactly one floating-point conversion,
// %[+][width][.precision](f|e|g), and literal text around it ('%%' for a percent sign),
// e.g. FormatDouble("%+.3f", x), FormatDouble("%.6g kN", t). Output as printf's in the
// "C" locale, whatever the current one.
std::string FormatDouble(std::string_view format, double value);

// `text` with the minus of a number that reads as zero dropped ("-0.00 m" -> "0.00 m",
// "-0" -> "0"; "-0.01" and "-1e-300" kept): for text a person reads, where a value that
// rounds to zero has no sign. FormatDouble itself stays printf's.
std::string WithoutNegativeZero(std::string text);

// `value` with the fewest of 6, 10 or 17 significant digits that tell it from `limit`
// ("40.0000001", not "40", beside a limit of 40; issue 57): for "VALUE is beyond LIMIT"
// messages, the limit itself written with 6 ("%.6g").
std::string FormatBeyond(double value, double limit);

// "1 window", "3 windows": n and the noun in the singular or the plural.
std::string Counted(long long n, const char* one, const char* many);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_NUMBER_TEXT_H_
