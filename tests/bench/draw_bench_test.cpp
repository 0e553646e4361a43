#include "draw_bench.h"

#include <gtest/gtest.h>

#include "pinball/table/board_loader.h"

namespace pinball::bench {
namespace {

TEST(DrawBench, MeasuresEveryPictureAndTheBaseline) {
  const table::Board board = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  DrawBenchOptions o;
  o.frames = 5;
  o.repeats = 2;
  int lines = 0;
  const DrawBenchReport r = run_draw_bench(board, o, [&](const std::string&) { ++lines; });
  EXPECT_EQ(lines, 6);
  for (const DrawCost* c : {&r.play, &r.view, &r.copy}) {
    EXPECT_GT(c->frames_per_s, 0.0);
    EXPECT_NEAR(c->ms_per_frame * c->frames_per_s, 1e3, 1e-6);
    EXPECT_GT(c->width_px, 100);
    EXPECT_GT(c->height_px, 100);
  }
  // The view's picture is the table plus its panel; the baseline copies one of that size.
  EXPECT_GT(r.view.width_px, r.play.width_px);
  EXPECT_EQ(r.copy.width_px, r.view.width_px);
  const nlohmann::json j = to_json(r);
  EXPECT_TRUE(j.contains("baseline_copy"));
  EXPECT_EQ(j["target_frames_per_s"], 60);
}

}  // namespace
}  // namespace pinball::bench
