#pragma once
// `pinball bench draw`: what one picture of `pinball play` and `pinball view`
// costs to draw, headless, on one core, against the 60 frames/s the windows
// must reach (16.7 ms per frame, of which the window system takes its share).
// Baseline in the same run: copying a picture of the same size (the cheapest
// frame there is).

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "pinball/table/board.h"

namespace pinball::bench {

/// What to run.
struct DrawBenchOptions {
  int frames = 2000;  ///< pictures drawn per measurement
  int repeats = 3;    ///< measurements; the best is reported (the least disturbed)
};

/// One kind of picture.
struct DrawCost {
  int width_px = 0, height_px = 0;  ///< picture size
  double frames_per_s = 0.0;        ///< best of the repeats
  double ms_per_frame = 0.0;        ///< 1000 / frames_per_s
};

/// What it measured.
struct DrawBenchReport {
  DrawCost play;      ///< pinball play: the board with flippers, ball and HUD (render_board), mid-game
  DrawCost view;      ///< pinball view: table, trail, projected path, panel and strip (render_view)
  DrawCost copy;      ///< baseline: copying a picture of the view's size
  int frames = 0;     ///< per measurement
  int repeats = 0;    ///< measurements
};

/// Runs it; `progress` (may be empty) gets a line per measurement.
DrawBenchReport run_draw_bench(const table::Board& board, const DrawBenchOptions& options,
                               const std::function<void(const std::string&)>& progress);

/// The report as one JSON object.
nlohmann::json to_json(const DrawBenchReport& report);

}  // namespace pinball::bench
