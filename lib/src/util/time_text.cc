// Time stamps as text (time_text.h): ISO 8601 and patterns read through the date
// library, UTC offsets, dates and clock times for display.
#include "fastcal/time_text.h"

#include <date/date.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"

namespace fastcal {
namespace {

constexpr int kMaxOffsetS = 14 * 3600;
constexpr std::int64_t kMicrosPerSecond = 1000000;
constexpr std::int64_t kMicrosPerDay = 86400 * kMicrosPerSecond;

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// Two digits at text[at], as a number; -1 when they are not digits.
int TwoDigits(std::string_view text, size_t at) {
  if (at + 2 > text.size() || !IsDigit(text[at]) || !IsDigit(text[at + 1])) return -1;
  return (text[at] - '0') * 10 + (text[at + 1] - '0');
}

// The thread's string stream for the date library, reused: constructing one per field
// costs more than the parse.
std::istringstream& Stream(std::string_view text) {
  thread_local std::istringstream stream;
  stream.clear();
  stream.str(std::string(text));
  return stream;
}

// "2024-05-01 12:34:56" (+ fraction) of `micros` microseconds since the epoch (local).
std::string CivilText(std::int64_t micros, int decimals) {
  std::int64_t day = micros / kMicrosPerDay;
  std::int64_t in_day = micros % kMicrosPerDay;
  if (in_day < 0) {
    in_day += kMicrosPerDay;
    --day;
  }
  const date::year_month_day ymd{date::sys_days{date::days{day}}};
  const std::int64_t second = in_day / kMicrosPerSecond;
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%04d-%02u-%02u %02d:%02d:%02d", int(ymd.year()),
                unsigned(ymd.month()), unsigned(ymd.day()), static_cast<int>(second / 3600),
                static_cast<int>(second / 60 % 60), static_cast<int>(second % 60));
  std::string text = buffer;
  if (decimals > 0) {
    std::snprintf(buffer, sizeof(buffer), ".%06lld",
                  static_cast<long long>(in_day % kMicrosPerSecond));
    text += std::string(buffer).substr(0, static_cast<size_t>(decimals) + 1);
  }
  return text;
}

// Microseconds since the epoch of `unix_s` in zone `offset_s`, rounded to `decimals`
// digits of the second.
std::int64_t LocalMicros(double unix_s, int offset_s, int decimals) {
  const double local = unix_s + offset_s;
  std::int64_t unit = 1;
  for (int k = decimals; k < 6; ++k) unit *= 10;
  const double units = std::round(local * (static_cast<double>(kMicrosPerSecond) / unit));
  return static_cast<std::int64_t>(units) * unit;
}

std::string OffsetText(int offset_s, bool z_for_utc) {
  if (offset_s == 0 && z_for_utc) return "Z";
  const int a = offset_s < 0 ? -offset_s : offset_s;
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "%c%02d:%02d", offset_s < 0 ? '-' : '+', a / 3600,
                a / 60 % 60);
  return buffer;
}

}  // namespace

bool ParseUtcOffset(std::string_view text, int* offset_s, std::string* why) {
  const auto fail = [&] {
    *why = internal::Quote(text) +
           " is not a UTC offset (Z, UTC, +08:00, +0800, +08 or -05:30; a zone name such as "
           "Asia/Shanghai is not read: give its offset)";
    return false;
  };
  if (text == "Z" || text == "z" || text == "UTC" || text == "utc") {
    *offset_s = 0;
    return true;
  }
  if (text.size() < 3 || (text[0] != '+' && text[0] != '-')) return fail();
  const int hours = TwoDigits(text, 1);
  int minutes = 0;
  if (hours < 0) return fail();
  if (text.size() == 6 && text[3] == ':') {
    minutes = TwoDigits(text, 4);
  } else if (text.size() == 5) {
    minutes = TwoDigits(text, 3);
  } else if (text.size() != 3) {
    return fail();
  }
  if (minutes < 0 || minutes >= 60) return fail();
  const int offset = (hours * 3600 + minutes * 60) * (text[0] == '-' ? -1 : 1);
  if (offset > kMaxOffsetS || offset < -kMaxOffsetS) return fail();
  *offset_s = offset;
  return true;
}

std::string UtcOffsetName(int offset_s) {
  return offset_s == 0 ? "UTC" : "UTC" + OffsetText(offset_s, false);
}

bool ParseIso8601(std::string_view text, int default_offset_s, double* unix_s, std::string* why) {
  const auto fail = [&](const std::string& what) {
    *why = internal::Quote(text) + " is not an ISO 8601 date and time" + what +
           " (e.g. 2024-05-01T12:34:56.5+08:00 or 2024-05-01 12:34:56; another layout "
           "needs a pattern in the column map, format: \"%Y/%m/%d %H:%M:%S\")";
    return false;
  };
  if (text.empty()) {
    *why = "missing value";
    return false;
  }
  // The date, then 'T' or a space, then the time of day.
  size_t sep = text.find_first_of("Tt ");
  if (sep == std::string_view::npos || sep < 8) return fail(": no time of day after the date");
  std::string_view body = text;
  int offset_s = default_offset_s;
  if (body.back() == 'Z' || body.back() == 'z') {
    offset_s = 0;
    body.remove_suffix(1);
  } else if (const size_t sign = body.find_first_of("+-", sep); sign != std::string_view::npos) {
    std::string ignored;
    if (!ParseUtcOffset(body.substr(sign), &offset_s, &ignored)) {
      return fail(": " + internal::Quote(body.substr(sign)) + " is not a UTC offset");
    }
    body = body.substr(0, sign);
  }
  // hh:mm, then optionally :ss[.fff]
  const size_t colon1 = body.find(':', sep);
  if (colon1 == std::string_view::npos) return fail(": no hh:mm");
  const size_t colon2 = body.find(':', colon1 + 1);
  const std::string_view minute_text = body.substr(0, colon2);
  double seconds = 0.0;
  if (colon2 != std::string_view::npos) {
    const std::string_view s = body.substr(colon2 + 1);
    if (TwoDigits(s, 0) < 0) return fail(": the seconds must be two digits");
    char digits[40];  // "ss.ffffff...": no allocation a row
    if (s.size() > sizeof(digits)) return fail(": the seconds must be ss[.fff]");
    std::memcpy(digits, s.data(), s.size());
    if (s.size() > 2) {
      if (digits[2] != '.' && digits[2] != ',') return fail(": the seconds must be ss[.fff]");
      digits[2] = '.';
      if (s.size() == 3 || s.find_first_not_of("0123456789", 3) != std::string_view::npos) {
        return fail(": the seconds must be ss[.fff]");
      }
    }
    const auto [end, ec] = std::from_chars(digits, digits + s.size(), seconds);
    if (ec != std::errc() || end != digits + s.size()) return fail("");
    // :60 is a leap second (issue 37: one was refused); checked at 23:59 UTC below.
    if (!(seconds < 61.0)) return fail(": seconds beyond 60");
  }
  // The date, hour and minute: the date library's, cached per thread (rows of one minute
  // share them).
  thread_local std::string cached_text;
  thread_local std::int64_t cached_minutes = 0;
  std::int64_t minutes = 0;
  if (minute_text == cached_text && !cached_text.empty()) {
    minutes = cached_minutes;
  } else {
    const char format[] = {'%', 'Y', '-', '%', 'm', '-', '%', 'd', text[sep],
                           '%', 'H', ':', '%', 'M', '\0'};
    std::istringstream& in = Stream(minute_text);
    date::sys_time<std::chrono::minutes> tp;
    date::from_stream(in, format, tp);
    if (in.fail() || in.peek() != std::char_traits<char>::eof()) {
      return fail(": no such date, hour or minute");
    }
    minutes = tp.time_since_epoch().count();
    cached_text.assign(minute_text);
    cached_minutes = minutes;
  }
  const std::int64_t minute_utc_s = minutes * 60 - offset_s;
  constexpr std::int64_t kDayS = 86400, kLastMinuteS = kDayS - 60;
  if (seconds >= 60.0 && ((minute_utc_s % kDayS) + kDayS) % kDayS != kLastMinuteS) {
    return fail(": seconds beyond 59 (a leap second, :60, is only at 23:59 UTC)");
  }
  // A leap second reads as the next day's first second (POSIX time has no 86401st):
  // 23:59:60.5 is 00:00:00.5, one second after 23:59:59.5, as the telemetry went on.
  *unix_s = static_cast<double>(minute_utc_s) + seconds;
  return true;
}

bool ParseTimePattern(std::string_view text, const std::string& pattern, int default_offset_s,
                      double* unix_s, std::string* why) {
  if (text.empty()) {
    *why = "missing value";
    return false;
  }
  std::istringstream& in = Stream(text);
  date::sys_time<std::chrono::microseconds> tp;
  std::chrono::minutes offset{0};
  std::string abbreviation;
  date::from_stream(in, pattern.c_str(), tp, &abbreviation, &offset);
  if (in.fail() || in.peek() != std::char_traits<char>::eof()) {
    *why = internal::Quote(text) + " does not match the time pattern " + internal::Quote(pattern);
    return false;
  }
  const bool zoned = pattern.find("%z") != std::string::npos ||
                     pattern.find("%Ez") != std::string::npos ||
                     pattern.find("%Oz") != std::string::npos;
  // With %z the library has applied the text's offset already.
  const double local = std::chrono::duration<double>(tp.time_since_epoch()).count();
  *unix_s = zoned ? local : local - default_offset_s;
  return true;
}

// Within the years a date is shown for (0001 to 9999), with room for the zone.
static bool Showable(double unix_s) {
  return std::isfinite(unix_s) && unix_s > -62135596800.0 + 86400.0 &&
         unix_s < kUnixTimeUntilS - 86400.0;
}

std::string FormatUnixTime(double unix_s, int offset_s, int decimals) {
  if (!Showable(unix_s)) return internal::FormatDouble("%.6g", unix_s) + " s";
  decimals = decimals < 0 ? 0 : decimals > 6 ? 6 : decimals;
  return CivilText(LocalMicros(unix_s, offset_s, decimals), decimals);
}

std::string IsoUnixTime(double unix_s, int offset_s) {
  if (!Showable(unix_s)) return internal::FormatDouble("%.17g", unix_s);
  std::string text = CivilText(LocalMicros(unix_s, offset_s, 6), 6);
  text[10] = 'T';
  while (text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  return text + OffsetText(offset_s, true);
}

TimeDisplay TimeDisplayFor(double earliest_s, int offset_s) {
  TimeDisplay d;
  d.absolute = std::isfinite(earliest_s) && IsUnixTime(earliest_s);
  d.offset_s = offset_s;
  return d;
}

namespace {

// Digits of the second worth showing: 0, or 3 when the time has a fraction at 1 ms.
int ShownDecimals(double unix_s, int offset_s) {
  if (!Showable(unix_s)) return 0;
  return LocalMicros(unix_s, offset_s, 3) % kMicrosPerSecond == 0 ? 0 : 3;
}

std::string StripFraction(std::string text) {
  if (text.find('.') == std::string::npos) return text;
  while (text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  return text;
}

}  // namespace

std::string TimeText(double time_s, const TimeDisplay& display) {
  if (!display.absolute || !Showable(time_s)) {
    return internal::FormatDouble("%.6g", time_s) + " s";
  }
  return StripFraction(FormatUnixTime(time_s, display.offset_s,
                                      ShownDecimals(time_s, display.offset_s))) +
         " " + UtcOffsetName(display.offset_s);
}

std::string TimeRangeText(double from_s, double to_s, const TimeDisplay& display) {
  if (!display.absolute || !Showable(from_s) || !Showable(to_s)) {
    return "t = " + internal::FormatDouble("%.6g", from_s) + " to " +
           internal::FormatDouble("%.6g", to_s) + " s";
  }
  const int decimals = std::max(ShownDecimals(from_s, display.offset_s),
                                ShownDecimals(to_s, display.offset_s));
  const std::string a = StripFraction(FormatUnixTime(from_s, display.offset_s, decimals));
  std::string b = StripFraction(FormatUnixTime(to_s, display.offset_s, decimals));
  if (a.size() >= 19 && b.size() >= 19 && a.compare(0, 10, b, 0, 10) == 0) {
    b = b.substr(11);  // the same day: the date once
  }
  return a + " to " + b + " " + UtcOffsetName(display.offset_s);
}

std::string TimeAxisLabel(double from_s, double to_s, const TimeDisplay& display) {
  const std::string a = FormatUnixTime(from_s, display.offset_s);
  const std::string b = FormatUnixTime(to_s, display.offset_s);
  const std::string zone = "(" + UtcOffsetName(display.offset_s) + ")";
  if (a.size() >= 19 && b.size() >= 19 && a.compare(0, 10, b, 0, 10) == 0) {
    return "time on " + a.substr(0, 10) + " " + zone;
  }
  return "time " + zone;
}

bool ParseTimeValue(std::string_view text, int default_offset_s, double* time_s,
                    std::string* why) {
  double value = 0.0;
  std::string number_why;
  if (internal::ParseFiniteDecimal(text, &value, &number_why)) {
    *time_s = value;
    return true;
  }
  if (text.find('-') == std::string_view::npos || text.size() < 10) {
    *why = internal::Quote(text) +
           " is neither a time in seconds (as the data's time_s) nor an ISO 8601 date and time";
    return false;
  }
  return ParseIso8601(text, default_offset_s, time_s, why);
}

std::string TimeValueText(double time_s, const TimeDisplay& display) {
  if (display.absolute) return IsoUnixTime(time_s, display.offset_s);
  char buffer[64];
  const auto r = std::to_chars(buffer, buffer + sizeof(buffer), time_s);
  return std::string(buffer, r.ptr);
}

}  // namespace fastcal
