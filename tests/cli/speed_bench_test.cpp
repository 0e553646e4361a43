#include "speed_bench.h"
#include "pinball/simlab/world_factory.h"

#include <gtest/gtest.h>

#include "pinball/table/board_loader.h"

namespace pinball::bench {
namespace {

TEST(SpeedBench, FarObstaclesAreCopiesOutOfTheTable) {
  const table::Board b = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const table::Board crowded = with_far_obstacles(b, 10);
  ASSERT_EQ(crowded.shapes.size(), 11 * b.shapes.size());
  ASSERT_EQ(crowded.obstacles.size(), crowded.shapes.size());
  for (std::size_t i = b.shapes.size(); i < crowded.shapes.size(); ++i) {
    EXPECT_GT(crowded.shapes[i].p0.x(), b.width_m + 0.4) << i;
    EXPECT_EQ(crowded.obstacles[i].bank, -1);
  }
}

TEST(SpeedBench, ReportComparesGridWithLinearScanOnTheSameRun) {
  const table::Board b = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  SpeedBenchOptions options;
  options.steps = 20'000;
  options.twin_steps = 2'000;
  options.repeats = 1;
  int progress_lines = 0;
  std::string first;
  const SpeedReport r = run_speed_bench(b, options, [&](const std::string& l) {
    if (++progress_lines == 1) first = l;
  });
  EXPECT_EQ(first.rfind("speed: 1/7 runs (14 %)", 0), 0u) << "percent and ETA: " << first;
  EXPECT_NE(first.find(", ETA "), std::string::npos) << first;
  ASSERT_EQ(r.runs.size(), 4u);
  EXPECT_EQ(progress_lines, 7) << "the twin's run or the line that says why it was skipped";
  EXPECT_TRUE(r.grid_matches_linear);
  EXPECT_EQ(r.runs[0].steps, r.runs[2].steps) << "far obstacles must not change the game";
  EXPECT_LT(r.runs[0].mean_candidates, r.runs[1].mean_candidates);
  EXPECT_DOUBLE_EQ(r.runs[1].mean_candidates, static_cast<double>(b.shapes.size()));
  EXPECT_GE(r.runs[0].steps, options.steps);
  const auto j = to_json(r);
  EXPECT_EQ(j.at("runs").size(), 4u);
  EXPECT_TRUE(j.contains("crowded_cost_ratio"));
}

TEST(SpeedBench, EventStepperRunsOnBothBoards) {
  const table::Board b = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  SpeedBenchOptions options;
  options.steps = 20'000;
  options.repeats = 1;
  options.twin_steps = 2'000;
  const SpeedReport r = run_speed_bench(b, options, {});
  ASSERT_EQ(r.event_runs.size(), simlab::twin_available() ? 3u : 2u);
  EXPECT_GT(r.thesis_sim_s_per_wall_s, 0.0);
  if (simlab::twin_available()) {
    const EventSpeedRun& twin = r.event_runs[2];
    EXPECT_EQ(twin.name, "twin");
    EXPECT_GE(twin.steps, options.twin_steps);
    EXPECT_GT(twin.sim_s_per_wall_s, 0.0);
    EXPECT_TRUE(r.twin_skipped.empty());
  } else {
    EXPECT_FALSE(r.twin_skipped.empty());
  }
  for (std::size_t i = 0; i < 2; ++i) {
    const EventSpeedRun& e = r.event_runs[i];
    EXPECT_GE(e.steps, options.steps) << e.name;
    EXPECT_GT(e.events, 0u) << e.name;
    EXPECT_NEAR(e.simulated_s, static_cast<double>(e.steps) * b.dt_s, 1e-6 * e.simulated_s) << e.name;
    EXPECT_GT(e.sim_s_per_wall_s, 0.0) << e.name;
  }
  // Far obstacles must not change the game.
  EXPECT_EQ(r.event_runs[0].events, r.event_runs[1].events);
  EXPECT_EQ(r.event_runs[0].steps, r.event_runs[1].steps);
  EXPECT_GT(r.event_crowded_cost_ratio, 0.0);
  const auto j = to_json(r);
  EXPECT_EQ(j.at("event_runs").size(), r.event_runs.size());
  EXPECT_TRUE(j.contains("thesis_sim_s_per_wall_s"));
  EXPECT_TRUE(j.contains("event_crowded_cost_ratio"));
}

}  // namespace
}  // namespace pinball::bench
