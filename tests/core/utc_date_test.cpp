#include "pinball/core/utc_date.h"

#include <gtest/gtest.h>

namespace pinball {
namespace {

TEST(UtcDate, TheDateIsIso8601Utc) {
  const std::string d = utc_now_iso8601();
  ASSERT_EQ(d.size(), 20u);
  EXPECT_EQ(d[4], '-');
  EXPECT_EQ(d[10], 'T');
  EXPECT_EQ(d.back(), 'Z');
  EXPECT_TRUE(is_utc_iso8601(d));
}

TEST(UtcDate, OnlyARealUtcSecondIsADate) {
  EXPECT_TRUE(is_utc_iso8601("2026-12-02T13:45:21Z"));
  EXPECT_TRUE(is_utc_iso8601("2024-02-29T23:59:60Z"));   // a leap day, a leap second
  EXPECT_FALSE(is_utc_iso8601("2026-02-29T00:00:00Z"));  // not a leap year
  EXPECT_FALSE(is_utc_iso8601("2026-13-01T00:00:00Z"));
  EXPECT_FALSE(is_utc_iso8601("2026-12-00T00:00:00Z"));
  EXPECT_FALSE(is_utc_iso8601("2026-12-02T24:00:00Z"));
  EXPECT_FALSE(is_utc_iso8601("2026-12-02T13:60:00Z"));
  EXPECT_FALSE(is_utc_iso8601("2026-12-02T13:45:21"));       // no zone
  EXPECT_FALSE(is_utc_iso8601("2026-12-02T13:45:21+01:00"));  // another zone
  EXPECT_FALSE(is_utc_iso8601("2026-12-02 13:45:21Z"));
  EXPECT_FALSE(is_utc_iso8601("yesterday"));
  EXPECT_FALSE(is_utc_iso8601(""));
}

}  // namespace
}  // namespace pinball
