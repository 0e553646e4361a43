#include "pinball/plot/ticks.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace pinball::plot {
namespace {

// Whether v is 1, 2 or 5 times a power of ten (or 0).
bool is_round(double v) {
  if (v == 0.0) return true;
  const double m = std::abs(v) / std::pow(10.0, std::floor(std::log10(std::abs(v)) + 1e-12));
  for (const double r : {1.0, 2.0, 5.0, 10.0}) {
    if (std::abs(m - r) < 1e-9 * r) return true;
  }
  return false;
}

void expect_round_cover(double lo, double hi, int max_ticks) {
  const std::vector<double> t = nice_ticks(lo, hi, max_ticks);
  ASSERT_GE(t.size(), 2u) << lo << ".." << hi;
  EXPECT_LE(t.size(), static_cast<std::size_t>(max_ticks)) << lo << ".." << hi;
  EXPECT_LE(t.front(), std::min(lo, hi));
  EXPECT_GE(t.back(), std::max(lo, hi));
  const double step = t[1] - t[0];
  EXPECT_TRUE(is_round(step)) << "step " << step;
  for (std::size_t i = 0; i < t.size(); ++i) {
    // Each tick a whole number of steps.
    EXPECT_NEAR(t[i] / step, std::round(t[i] / step), 1e-6) << t[i];
    if (i > 0) {
      EXPECT_NEAR(t[i] - t[i - 1], step, 1e-9 * std::max(1.0, std::abs(step)));
    }
  }
}

TEST(NiceTicksTest, CoverAwkwardRangesWithRoundValues) {
  expect_round_cover(0.0, 1.0, 6);
  expect_round_cover(0.0, 8388.0, 7);
  expect_round_cover(-0.003, 0.007, 6);
  expect_round_cover(0.1234, 0.1236, 5);
  expect_round_cover(-7.0, -3.0, 6);
  expect_round_cover(1e-9, 3e-9, 6);
  expect_round_cover(12345.0, 987654.0, 8);
}

TEST(NiceTicksTest, ZeroToOneIsInFifthsOrTenths) {
  const std::vector<double> t = nice_ticks(0.0, 1.0, 6);
  EXPECT_DOUBLE_EQ(t.front(), 0.0);
  EXPECT_DOUBLE_EQ(t.back(), 1.0);
  EXPECT_DOUBLE_EQ(t[1], 0.2);
}

TEST(NiceTicksTest, ZeroWidthRangeIsWidenedAroundItsValue) {
  for (const double v : {0.0, 5.0, -0.02, 1e6}) {
    const std::vector<double> t = nice_ticks(v, v, 6);
    ASSERT_GE(t.size(), 2u) << v;
    EXPECT_LT(t.front(), v);
    EXPECT_GT(t.back(), v);
  }
}

TEST(NiceTicksTest, HugeRangesEndAndNonFiniteIsRejected) {
  const double big = std::numeric_limits<double>::max();
  EXPECT_NO_THROW(nice_ticks(-big, big, 6));
  EXPECT_LE(nice_ticks(-big, big, 6).size(), 6u);
  EXPECT_NO_THROW(nice_ticks(0.0, 1e300, 6));
  EXPECT_NO_THROW(nice_ticks(0.0, std::numeric_limits<double>::denorm_min(), 6));
  EXPECT_THROW(nice_ticks(0.0, std::nan(""), 6), std::invalid_argument);
  EXPECT_THROW(nice_ticks(-std::numeric_limits<double>::infinity(), 1.0, 6), std::invalid_argument);
  EXPECT_THROW(nice_ticks(0.0, 1.0, 1), std::invalid_argument);
}

TEST(NiceTicksTest, ReversedBoundsGiveTheSameTicks) { EXPECT_EQ(nice_ticks(8.0, 1.0, 6), nice_ticks(1.0, 8.0, 6)); }

TEST(RoundNumbersTest, StepAndLengthAreOneTwoOrFive) {
  EXPECT_DOUBLE_EQ(nice_step(0.13), 0.2);
  EXPECT_DOUBLE_EQ(nice_step(3.0), 5.0);
  EXPECT_DOUBLE_EQ(nice_step(7.0), 10.0);
  EXPECT_DOUBLE_EQ(nice_step(2.0), 2.0);
  EXPECT_DOUBLE_EQ(round_at_most(0.13), 0.1);
  EXPECT_DOUBLE_EQ(round_at_most(0.27), 0.2);
  EXPECT_DOUBLE_EQ(round_at_most(0.5), 0.5);
  EXPECT_DOUBLE_EQ(round_at_most(999.0), 500.0);
  EXPECT_THROW(nice_step(0.0), std::invalid_argument);
  EXPECT_THROW(round_at_most(std::nan("")), std::invalid_argument);
}

TEST(DecadeTicksTest, CoverTheRangeInPowersOfTen) {
  const std::vector<double> t = decade_ticks(3e-7, 0.02, 8);
  EXPECT_LE(t.front(), 3e-7);
  EXPECT_GE(t.back(), 0.02);
  EXPECT_LE(t.size(), 8u);
  EXPECT_THROW(decade_ticks(0.0, 1.0), std::invalid_argument);
  EXPECT_LE(decade_ticks(1e-300, 1e300, 8).size(), 8u);
}

TEST(TickLabelTest, PrintsRoundValuesWithoutTrailingDigits) {
  EXPECT_EQ(tick_label(0.5, 0.1), "0.5");
  EXPECT_EQ(tick_label(1000.0, 500.0), "1000");
  EXPECT_EQ(tick_label(-0.002, 0.002), "-0.002");
  EXPECT_EQ(tick_label(0.30000000000000004, 0.1), "0.3");
  EXPECT_EQ(tick_label(-1e-17, 0.1), "0.0");
  EXPECT_EQ(tick_label(2.5e-05, 5e-06), "2.5e-05");
  EXPECT_EQ(tick_label(2e6, 1e6), "2e+06");
  EXPECT_EQ(decade_label(0.001), "0.001");
  EXPECT_EQ(decade_label(100.0), "100");
  EXPECT_EQ(decade_label(1e-5), "1e-5");
}

}  // namespace
}  // namespace pinball::plot
