#pragma once
// Draws a board and, optionally, a game state into an OpenCV image: for
// `pinball render`, `pinball sim --video`, and people checking a board file.

#include <vector>

#include <opencv2/core.hpp>

#include "pinball/plot/draw.h"

#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"

namespace pinball::sim {

/// How to draw.
struct RenderOptions {
  double px_per_m = 800.0;   ///< scale: 800 px/m draws the 0.51 x 1.07 m table at about 430 x 880 px
  int margin_px = 12;        ///< border around the playfield
  bool draw_normals = false; ///< draw each line's normal as a short tick (debugging one-sided lines)
  bool draw_hud = true;      ///< score, balls and time in the top-left corner (needs a state)
  bool draw_scale_bar = false;  ///< a strip below the playfield with a round-length scale bar (`pinball render`)
};

/// Image size (width, height in px) that render_board produces for `board`.
cv::Size render_size(const table::Board& board, const RenderOptions& options);

/// Board point (m) to image pixel (u right, v down) under `options`.
cv::Point2d board_to_pixel(const table::Board& board, const RenderOptions& options, const Vec2& p_board);

/// The longest side render_board draws (px): a 10 m board at 10 000 px/m
/// needed a 30 GB image. 16384 is also what image viewers and codecs take.
inline constexpr int kMaxRenderSide_px = 16384;

/// Draws the board; with a state also draws flippers at their angles, hidden
/// flags greyed out, the ball and the HUD. Returns an 8-bit BGR image.
/// Throws std::invalid_argument, with the largest scale that fits, when a
/// side would exceed kMaxRenderSide_px.
cv::Mat render_board(const table::Board& board, const GameState* state, const RenderOptions& options);

/// What render_board's colours mean (walls, kickers, ball eaters, hidden
/// obstacles, sensors, flippers), for a legend beside the picture.
std::vector<plot::LegendEntry> board_legend();

}  // namespace pinball::sim
