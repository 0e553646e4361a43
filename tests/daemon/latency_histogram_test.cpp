#include "pinball/daemon/latency_histogram.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>

namespace pinball::daemon {
namespace {

TEST(LatencyHistogram, EmptyIsZero) {
  const LatencySummary s = LatencyHistogram{}.summary();
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.p50_us, 0.0);
  EXPECT_EQ(s.max_us, 0.0);
}

TEST(LatencyHistogram, PercentilesWithinOneBinOfTheExactValues) {
  LatencyHistogram h;
  for (int i = 1; i <= 1000; ++i) h.record(i);  // 1..1000 us: p50 = 500, p99 = 990
  const LatencySummary s = h.summary();
  EXPECT_EQ(s.count, 1000u);
  EXPECT_NEAR(s.p50_us, 500.0, 500.0 * 0.02);
  EXPECT_NEAR(s.p99_us, 990.0, 990.0 * 0.02);
  EXPECT_EQ(s.max_us, 1000.0);
  EXPECT_GE(s.p50_us, 500.0);  // the bin's upper edge: never optimistic
}

TEST(LatencyHistogram, OutliersMoveMaxNotMedian) {
  LatencyHistogram h;
  for (int i = 0; i < 999; ++i) h.record(10.0);
  h.record(5e6);
  const LatencySummary s = h.summary();
  EXPECT_NEAR(s.p50_us, 10.0, 0.2);
  EXPECT_NEAR(s.p99_us, 10.0, 0.2);
  EXPECT_EQ(s.max_us, 5e6);
}

TEST(LatencyHistogram, IgnoresNegativeAndNaNAndClampsTheRange) {
  LatencyHistogram h;
  h.record(-1.0);
  h.record(std::nan(""));
  EXPECT_EQ(h.summary().count, 0u);
  h.record(0.0);
  h.record(1e12);
  const LatencySummary s = h.summary();
  EXPECT_EQ(s.count, 2u);
  EXPECT_EQ(s.max_us, 1e12);
  EXPECT_TRUE(std::isfinite(s.p50_us));
}

TEST(LatencyHistogram, ReaderSeesConsistentCountsWhileAWriterRecords) {
  LatencyHistogram h;
  std::thread writer([&] {
    for (int i = 0; i < 200000; ++i) h.record(1.0 + (i % 100));
  });
  for (int i = 0; i < 100; ++i) {
    const LatencySummary s = h.summary();
    EXPECT_LE(s.p50_us, 101.0 * 1.02 + 1e-9);
  }
  writer.join();
  EXPECT_EQ(h.summary().count, 200000u);
}

}  // namespace
}  // namespace pinball::daemon
