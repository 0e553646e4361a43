#include "speed_bench.h"

#include <gtest/gtest.h>

#include "pinball/sim/board_loader.h"

namespace pinball::bench {
namespace {

TEST(SpeedBench, FarObstaclesAreCopiesOutOfTheTable) {
  const sim::Board b = sim::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const sim::Board crowded = with_far_obstacles(b, 10);
  ASSERT_EQ(crowded.shapes.size(), 11 * b.shapes.size());
  ASSERT_EQ(crowded.obstacles.size(), crowded.shapes.size());
  for (std::size_t i = b.shapes.size(); i < crowded.shapes.size(); ++i) {
    EXPECT_GT(crowded.shapes[i].p0.x(), b.width_m + 0.4) << i;
    EXPECT_EQ(crowded.obstacles[i].bank, -1);
  }
}

TEST(SpeedBench, ReportComparesGridWithLinearScanOnTheSameRun) {
  const sim::Board b = sim::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  SpeedBenchOptions options;
  options.steps = 20'000;
  options.repeats = 1;
  int progress_lines = 0;
  const SpeedReport r = run_speed_bench(b, options, [&](const std::string&) { ++progress_lines; });
  ASSERT_EQ(r.runs.size(), 4u);
  EXPECT_EQ(progress_lines, 4);
  EXPECT_TRUE(r.grid_matches_linear);
  EXPECT_EQ(r.runs[0].steps, r.runs[2].steps) << "far obstacles must not change the game";
  EXPECT_LT(r.runs[0].mean_candidates, r.runs[1].mean_candidates);
  EXPECT_DOUBLE_EQ(r.runs[1].mean_candidates, static_cast<double>(b.shapes.size()));
  EXPECT_GE(r.runs[0].steps, options.steps);
  const auto j = to_json(r);
  EXPECT_EQ(j.at("runs").size(), 4u);
  EXPECT_TRUE(j.contains("crowded_cost_ratio"));
}

}  // namespace
}  // namespace pinball::bench
