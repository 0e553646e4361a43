#pragma once
// Where the flippers are when down, as the tracker knows it: from the board
// file now, from calibration on the lab machine (thesis 4.1.3). The 'V' is
// each flipper line extended past its tip to where the two lines meet.

#include <array>

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"

namespace pinball::track {

/// Index of the left and right flipper in the tracker's arrays.
enum FlipperIndex : int { kLeftFlipper = 0, kRightFlipper = 1 };

/// One flipper in its down position.
struct FlipperLine {
  Vec2 pivot = Vec2::Zero();   ///< pivot (m)
  Vec2 tip = Vec2::Zero();     ///< tip when down (m)
  Vec2 axis() const { return tip - pivot; }  ///< F: pivot to tip, h = 1 at the tip
};

/// The two flipper lines and their 'V'.
struct FlipperGeometry {
  std::array<FlipperLine, 2> lines;  ///< [kLeftFlipper], [kRightFlipper]
  Vec2 apex = Vec2::Zero();          ///< where the extended lines meet (the V's centre)
  std::array<double, 2> h_apex{};    ///< h of the apex on each line (> 1; thesis: 1.5)
};

/// Builds the geometry from two lines. Throws std::invalid_argument if the
/// lines are parallel or meet behind a pivot (no 'V').
FlipperGeometry make_flipper_geometry(const FlipperLine& left, const FlipperLine& right);

/// The geometry of a board's flippers at θ_min. Throws std::invalid_argument
/// unless the board has exactly one left and one right flipper.
FlipperGeometry flipper_geometry_from_board(const table::Board& board);

/// True when p lies above both flipper lines (inside the 'V' or above it).
bool above_flippers(const FlipperGeometry& geometry, const Vec2& p);

}  // namespace pinball::track
