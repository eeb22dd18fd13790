// Time stamps as text: ISO 8601 date-times read (through Howard Hinnant's date library,
// Debian's libhowardhinnant-date-dev), fixed UTC offsets, and times shown as dates and
// clock times in reports, plots and messages (docs/data-format.md, "Time stamps").
//
// A dataset's time_s is a double: seconds of any epoch, or Unix seconds (since
// 1970-01-01T00:00:00Z, leap seconds not counted, as POSIX time). The rule that tells
// them apart everywhere a time is shown: a time_s at or beyond kUnixTimeFromS (1e8 s,
// 1973-03-03T09:46:40Z) is a Unix time, shown as a date and time; a smaller one is
// seconds from any epoch, shown as seconds. No survey's seconds from its own start reach
// 1e8 s (3.2 years).
//
// Resolution: a double holds a Unix time near 1.7e9 s to 2^-22 s (0.24 us); times read
// from text are rounded once to the nearest double, so they keep 1 us.
#ifndef FASTCAL_TIME_TEXT_H_
#define FASTCAL_TIME_TEXT_H_

#include <string>
#include <string_view>

namespace fastcal {

inline constexpr double kUnixTimeFromS = 1e8;
// Dates are shown up to the end of year 9999 (10000-01-01T00:00:00Z); a larger time_s is
// shown as seconds.
inline constexpr double kUnixTimeUntilS = 253402300800.0;

// True when `time_s` is a Unix time by the rule above (and before year 10000).
inline bool IsUnixTime(double time_s) {
  return time_s >= kUnixTimeFromS && time_s < kUnixTimeUntilS;
}

// A fixed offset from UTC, in seconds east of Greenwich: "Z", "UTC", "+08:00", "+0800",
// "+08", "-05:30" (|offset| <= 14 h). False with *why otherwise (a zone name such as
// "Asia/Shanghai" is not read: give its offset; China has kept +08:00 all year since 1991).
bool ParseUtcOffset(std::string_view text, int* offset_s, std::string* why);

// "UTC" for 0, else "UTC+08:00", "UTC-05:30".
std::string UtcOffsetName(int offset_s);

// Reads an ISO 8601 date and time: YYYY-MM-DD, 'T' or one space, hh:mm, optionally :ss
// with an optional fraction ('.' or ','), optionally a zone ("Z", "+08:00", "+0800",
// "+08"). Text without a zone is in `default_offset_s`. The date, hour and minute are
// parsed and checked by the date library (2024-02-30 and 25:00 are refused); the seconds
// are read as a decimal number 0 <= s < 60. *unix_s: seconds since 1970-01-01T00:00:00Z.
// False with *why (which quotes the text) otherwise.
bool ParseIso8601(std::string_view text, int default_offset_s, double* unix_s, std::string* why);

// Reads a date and time by a pattern of the date library's parse flags (those of
// strptime: "%Y/%m/%d %H:%M:%S", "%d.%m.%Y %H:%M"; %S reads a fraction too, to 1 us; %z
// reads a zone "+0800"), the whole text consumed; without %z in `default_offset_s`.
bool ParseTimePattern(std::string_view text, const std::string& pattern, int default_offset_s,
                      double* unix_s, std::string* why);

// A Unix time as "2024-05-01 12:34:56" in the zone `offset_s` (no zone written), with
// `decimals` (0 to 6) digits of the second; rounded to them.
std::string FormatUnixTime(double unix_s, int offset_s, int decimals = 0);

// A Unix time in ISO 8601 with its zone, "2024-05-01T12:34:56.5+08:00" ("Z" for UTC),
// the fraction rounded to 1 us, trailing zeros dropped: ParseIso8601 reads it back to
// within 1 us. For files and flags (--sessions-at).
std::string IsoUnixTime(double unix_s, int offset_s);

// How a dataset's times are shown: dates and times in a zone when they are Unix times,
// seconds otherwise.
struct TimeDisplay {
  bool absolute = false;  // the times are Unix times (IsUnixTime of the earliest)
  int offset_s = 0;       // the zone they are shown in (seconds east of UTC)
};

// The display of times from `earliest_s` on: absolute when IsUnixTime(earliest_s).
TimeDisplay TimeDisplayFor(double earliest_s, int offset_s);

// One time: "2024-05-01 12:34:56 UTC+08:00" (the fraction shown to the millisecond when
// there is one), or "800 s" (6 significant digits) for seconds.
std::string TimeText(double time_s, const TimeDisplay& display);

// A range: "2024-05-01 12:00:00 to 12:48:00 UTC+08:00" (the date once when both ends
// share it), or "t = 0 to 2880 s".
std::string TimeRangeText(double from_s, double to_s, const TimeDisplay& display);

// The label of a clock-time axis (svg_plot.h, PlotOptions::x_unix_time) over [from_s,
// to_s]: "time on 2024-05-01 (UTC+08:00)", or "time (UTC+08:00)" over several days.
std::string TimeAxisLabel(double from_s, double to_s, const TimeDisplay& display);

// A time as a user gives it (--sessions-at): a number, in the data's time_s (Unix
// seconds when its times are absolute), or an ISO 8601 date and time (in
// `default_offset_s` when it has no zone). False with *why otherwise.
bool ParseTimeValue(std::string_view text, int default_offset_s, double* time_s,
                    std::string* why);

// The text a user would give for `time_s` to ParseTimeValue: ISO 8601 with the zone for
// a Unix time, the shortest decimal that reads back otherwise.
std::string TimeValueText(double time_s, const TimeDisplay& display);

}  // namespace fastcal

#endif  // FASTCAL_TIME_TEXT_H_
