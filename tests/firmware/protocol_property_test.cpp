// The protocol property test: random and mutated frame streams into the
// reference board, every rule checked from outside (ProtocolRuleChecker) and
// every coil against the absolute caps. CI runs 4 x 100 000 frames; `pinball
// bench protocol` runs millions (docs/results.md).

#include <gtest/gtest.h>

#include "protocol_bench.h"

namespace pinball::bench {
namespace {

TEST(ProtocolProperty, RandomAndMutatedStreamsBreakNoRule) {
  ProtocolBenchOptions o;
  o.frames = 100'000;
  o.seed = 101;
  o.seeds = 4;
  const ProtocolBenchReport r = run_protocol_bench(o, {});
  EXPECT_EQ(r.rule_violations, 0u) << r.first_violation;
  EXPECT_EQ(r.cap_violations, 0u) << r.first_violation;
  // The streams reach every corner the rules speak of.
  EXPECT_EQ(r.frames, 400'000u);
  EXPECT_GT(r.switch_ons, 5'000u);
  EXPECT_GT(r.bad_frames, 50'000u);
  EXPECT_GT(r.stale, 1'000u);
  EXPECT_GT(r.watchdog_trips, 100u);
  EXPECT_GT(r.hold_cap_trips, 100u);
  EXPECT_GT(r.refused_locked, 100u);
}

TEST(ProtocolProperty, SixDriversToo) {
  ProtocolBenchOptions o;
  o.frames = 50'000;
  o.seed = 7;
  o.driver_count = 6;
  const ProtocolBenchReport r = run_protocol_bench(o, {});
  EXPECT_EQ(r.rule_violations + r.cap_violations, 0u) << r.first_violation;
  EXPECT_GT(r.switch_ons, 1'000u);
}

}  // namespace
}  // namespace pinball::bench
