// Numbers in text reports: a few significant digits, never a raw double.

#include "pinball/core/format.h"

#include <gtest/gtest.h>

#include <limits>

namespace pinball {
namespace {

TEST(FormatNumber, KeepsAFewSignificantDigits) {
  EXPECT_EQ(format_number(9193.4567), "9193");
  EXPECT_EQ(format_number(12.3456), "12.3");
  EXPECT_EQ(format_number(0.045678), "0.0457");
  EXPECT_EQ(format_number(1.0 / 3.0, 2), "0.33");
  EXPECT_EQ(format_number(9.996), "10");
  EXPECT_EQ(format_number(0.0005), "0.0005");
  EXPECT_EQ(format_number(12.30), "12.3");
  EXPECT_EQ(format_number(1.5e6), "1500000");
  EXPECT_EQ(format_number(999999999999999.0), "999999999999999");
  EXPECT_EQ(format_number(1e100), "1e+100");
  EXPECT_EQ(format_number(-1.23456e20), "-1.23e+20");
  EXPECT_EQ(format_number(0.0), "0");
  EXPECT_EQ(format_number(-0.0001, 1), "-0.0001");
  EXPECT_EQ(format_number(-2.5e-13), "0");  // below 12 decimals: zero, not "-0"
}

TEST(FormatMeanCi, RoundsTheMeanToItsIntervalsPlace) {
  EXPECT_EQ(format_mean_ci(9193.4567, 5430.123), "9193 ± 5430");
  EXPECT_EQ(format_mean_ci(1.2437, 0.3123), "1.24 ± 0.31");
  EXPECT_EQ(format_mean_ci(1.2437, 0.0031), "1.2437 ± 0.0031");
  EXPECT_EQ(format_mean_ci(1e100, 3e99), "1e+100 ± 3e+99");
  EXPECT_EQ(format_mean_ci(812.5, 0.0), "812 ± 0");
  // One sample bounds nothing: not a spread of zero.
  EXPECT_EQ(format_mean_ci(812.4, std::numeric_limits<double>::infinity()), "812 ± ∞");
}

}  // namespace
}  // namespace pinball
