// Numbers as text (internal/number_text.h): counts in the singular or plural.
#include "fastcal/internal/number_text.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace fastcal::internal
