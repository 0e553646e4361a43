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
}

}  // namespace
}  // namespace pinball
