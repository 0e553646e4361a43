#include "daemon_latency_bench.h"

#include <gtest/gtest.h>

namespace pinball::bench {
namespace {

TEST(DaemonLatencyBench, MeasuresEveryStageOnBothClocks) {
  DaemonLatencyOptions o;
  o.board = std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board";
  o.controller = std::string(PINBALL_SOURCE_DIR) + "/controllers/best.json";
  o.lockstep_balls = 2;
  o.realtime_s = 0.5;
  o.baseline_samples = 100;
  const DaemonLatencyReport r = run_daemon_latency_bench(o, {});
  EXPECT_GT(r.lockstep.frames, 1000u);
  EXPECT_GT(r.realtime.frames, 50u);
  EXPECT_GT(r.lockstep_unpinned.frames, 1000u);
  EXPECT_GT(r.realtime_idle_poll.frames, 50u);
  EXPECT_EQ(r.lockstep_unpinned.cpus, "not pinned");
  // Only the timing differs: the lockstep game is the same wherever the threads run.
  EXPECT_EQ(r.lockstep.frames, r.lockstep_unpinned.frames);
  const daemon::LatencySummary& e2e = r.lockstep.stages[daemon::kFrameToCan];
  ASSERT_GT(e2e.count, 0u);
  EXPECT_GT(e2e.p50_us, 0.0);
  EXPECT_LE(e2e.p50_us, e2e.p99_us);
  EXPECT_LE(e2e.p99_us, e2e.max_us);
  EXPECT_EQ(r.lockstep.stages[daemon::kCaptureToDetection].count, r.lockstep.frames);
  EXPECT_GT(r.wake_p50_us, 0.0);
  const nlohmann::json j = to_json(r);
  EXPECT_TRUE(j.contains("lockstep"));
  EXPECT_TRUE(j["realtime"].contains("frame_to_can_p99_us"));
  EXPECT_TRUE(j["lockstep_unpinned"].contains("cpus"));
  EXPECT_TRUE(j["realtime_idle_poll"].contains("warnings"));
}

}  // namespace
}  // namespace pinball::bench
