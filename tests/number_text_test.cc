// Numbers as text (internal/number_text.h): counts in the singular or plural; and
// ParseDecimalFastPath (Clinger's fast path) against std::from_chars, the correctly
// rounded reference, bit for bit: seeded random decimals of every shape a telemetry
// export writes, and the edges of the path (2^53, 10^22, 19 digits, zeros, signs,
// exponents); the text it declines is read the general way.
#include "fastcal/internal/number_text.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace fastcal::internal {
namespace {

TEST(CountedTest, OneIsSingularEveryOtherCountPlural) {
  EXPECT_EQ(Counted(1, "window", "windows"), "1 window");
  EXPECT_EQ(Counted(0, "window", "windows"), "0 windows");
  EXPECT_EQ(Counted(2, "file", "files"), "2 files");
  EXPECT_EQ(Counted(10000000000LL, "sample", "samples"), "10000000000 samples");
}

TEST(WithoutNegativeZeroTest, MinusZeroReadsAsZero) {
  EXPECT_EQ(WithoutNegativeZero(FormatDouble("%.3f", -0.0001)), "0.000");
  EXPECT_EQ(WithoutNegativeZero(FormatDouble("%.3f", -0.5)), "-0.500");
}

// std::from_chars of `text` with its exponent shifted by `shift` (the reference).
double Reference(const std::string& text, int shift) {
  std::string t = text;
  bool negative = false;
  if (!t.empty() && (t[0] == '+' || t[0] == '-')) {
    negative = t[0] == '-';
    t.erase(0, 1);
  }
  long exponent = 0;
  const size_t e = t.find_first_of("eE");
  if (e != std::string::npos) {
    exponent = std::stol(t.substr(e + 1));
    t.erase(e);
  }
  t += "e" + std::to_string(exponent + shift);
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  EXPECT_TRUE(ec == std::errc() && ptr == t.data() + t.size()) << t;
  return negative ? -v : v;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// A random decimal: a sign or none, 1 to 20 digits with the point anywhere (or none), an
// exponent or none.
std::string RandomDecimal(std::mt19937_64* rng) {
  std::uniform_int_distribution<int> digit(0, 9), count(1, 20), coin(0, 3), exp(-30, 30);
  std::string s;
  const int sign = coin(*rng);
  if (sign == 1) s += '-';
  if (sign == 2) s += '+';
  const int n = count(*rng);
  const int point = std::uniform_int_distribution<int>(-1, n)(*rng);
  for (int k = 0; k < n; ++k) {
    if (k == point) s += '.';
    s += static_cast<char>('0' + digit(*rng));
  }
  if (point == n) s += '.';
  if (coin(*rng) == 0) s += (coin(*rng) < 2 ? "e" : "E") + std::to_string(exp(*rng));
  return s;
}

TEST(NumberTextTest, FastPathAndParseFiniteDecimalAreFromCharsBitForBit) {
  std::mt19937_64 rng(41);  // seeded: the same strings every run
  constexpr int kStrings = 200000;
  int taken = 0;
  for (int k = 0; k < kStrings; ++k) {
    const std::string text = RandomDecimal(&rng);
    // ParseFiniteDecimal, by the fast path or past it, reads every one as from_chars does.
    double read = 0.0;
    std::string why;
    ASSERT_TRUE(ParseFiniteDecimal(text, &read, &why)) << text << ": " << why;
    ASSERT_TRUE(SameBits(read, Reference(text, 0))) << text;
    for (const int shift : {3, -3}) {  // a kN field to N, and back
      double shifted = 0.0;
      ASSERT_TRUE(ParseShiftedDecimal(text, shift, &shifted)) << text;
      ASSERT_TRUE(SameBits(shifted, Reference(text, shift))) << text << " shift " << shift;
    }
    for (const int shift : {0, 3, -3}) {
      double fast = 0.0;
      if (!ParseDecimalFastPath(text, shift, &fast)) continue;
      ++taken;
      ASSERT_TRUE(SameBits(fast, Reference(text, shift))) << text << " shift " << shift;
    }
  }
  // Most of them take the path (a test of the path, not of its refusals).
  EXPECT_GT(taken, kStrings);
}

TEST(NumberTextTest, FastPathEdges) {
  struct Case {
    const char* text;
    int shift;
    bool fast;
  };
  const Case cases[] = {
      {"9007199254740992", 0, true},   // 2^53
      {"9007199254740993", 0, false},  // above 2^53
      {"1e22", 0, true},
      {"1e23", 0, false},
      {"1e19", 3, true},
      {"1e20", 3, false},
      {"1e-22", 0, true},
      {"1e-23", 0, false},
      {"1234567890123456789", 0, false},    // 19 digits, above 2^53
      {"0.00000000000000000001", 0, true},  // leading zeros count in the power, not the digits
      {"0.000000000000000000000000001", 0, false},  // 1e-27
      {"12345678901234567890", 0, false},           // 20 significant digits
      {"-0", 0, true},
      {"-0.0e5", 3, true},
      {"0e99999", 0, true},
      {"1e99999", 0, false},
      {"+7", 0, true},
      {".5", 0, true},
      {"5.", 0, true},
      {"1E+05", 0, true},
      {"", 0, false},
      {".", 0, false},
      {"-", 0, false},
      {"1e", 0, false},
      {"1e+", 0, false},
      {"1x", 0, false},
      {"0x10", 0, false},
      {"inf", 0, false},
      {"nan", 0, false},
      {" 1", 0, false},
      {"1 ", 0, false},
      {"1,5", 0, false},
      {"--1", 0, false},
      {"1.2.3", 0, false},
  };
  for (const Case& c : cases) {
    double v = 12345.0;
    EXPECT_EQ(ParseDecimalFastPath(c.text, c.shift, &v), c.fast) << c.text;
    if (c.fast) {
      EXPECT_TRUE(SameBits(v, Reference(c.text, c.shift))) << c.text;
    } else {
      EXPECT_EQ(v, 12345.0) << c.text << ": untouched";
    }
  }
  double v = 0.0;
  ASSERT_TRUE(ParseDecimalFastPath("-0", 0, &v));
  EXPECT_TRUE(std::signbit(v));
}

TEST(NumberTextTest, ShiftedDecimalTakesOnlyAPlainDecimal) {
  // Past the fast path (more than 17 characters) and on it, with a sign of either kind.
  for (const char* text : {"+271.73286881555006", "-271.73286881555006", "271.7", "+1e-5",
                           "0.000000000000000000001234567", "1234567890123456789012e-3",
                           "271.73286881555006e+2", "271.73286881555006E-2"}) {
    double v = 0.0;
    ASSERT_TRUE(ParseShiftedDecimal(text, 3, &v)) << text;
    EXPECT_TRUE(SameBits(v, Reference(text, 3))) << text;
  }
  // Refused (a caller reads them the general way, for its message).
  const std::vector<std::string> refused = {"",
                                            ".",
                                            "-",
                                            "+",
                                            "1e",
                                            "1e+",
                                            "1x",
                                            "0x10",
                                            "0x1p3",
                                            "inf",
                                            "-inf",
                                            "nan",
                                            "+-1",
                                            "--1",
                                            "++1",
                                            "1.2.3",
                                            "1e5e3",
                                            "1e3.5",
                                            "e5",
                                            "1e999999",
                                            "1e306",
                                            "123456789012345678e306",
                                            " 1",
                                            "1e+-5",
                                            "1.0000000000000000e+-5",
                                            "1.0000000000000000e++5",
                                            "1.0000000000000000e--5"};
  for (const std::string& text : refused) {
    double v = 12345.0;
    EXPECT_FALSE(ParseShiftedDecimal(text, 3, &v)) << text;
    EXPECT_EQ(v, 12345.0) << text << ": untouched";
  }
}

TEST(NumberTextTest, DeclinedTextIsReadOrRefusedAsBefore) {
  // ParseFiniteDecimal takes the fast path first; what it declines keeps its reading and
  // its messages.
  double v = 0.0;
  std::string why;
  EXPECT_TRUE(ParseFiniteDecimal("1e23", &v, &why));
  EXPECT_EQ(v, 1e23);
  EXPECT_TRUE(ParseFiniteDecimal("-17.1234567890123456789", &v, &why));
  EXPECT_EQ(v, -17.1234567890123456789);
  EXPECT_FALSE(ParseFiniteDecimal("0x10", &v, &why));
  EXPECT_NE(why.find("hexadecimal is not accepted"), std::string::npos) << why;
  EXPECT_FALSE(ParseFiniteDecimal("1e999", &v, &why));
  EXPECT_NE(why.find("out of the range"), std::string::npos) << why;
  EXPECT_FALSE(ParseFiniteDecimal("", &v, &why));
  EXPECT_EQ(why, "missing value");
  EXPECT_FALSE(ParseFiniteDecimal("-inf", &v, &why));
  EXPECT_EQ(why, "value is not finite");
  EXPECT_FALSE(ParseFiniteDecimal("1.5.", &v, &why));
  EXPECT_NE(why.find("is not a number"), std::string::npos) << why;
}

}  // namespace
}  // namespace fastcal::internal
