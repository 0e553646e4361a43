#include "pinball/track/flipper_geometry.h"

#include <cmath>
#include <stdexcept>

namespace pinball::track {

FlipperGeometry make_flipper_geometry(const FlipperLine& left, const FlipperLine& right) {
  FlipperGeometry g;
  g.lines = {left, right};
  const Vec2 fl = left.axis();
  const Vec2 fr = right.axis();
  const double denom = cross(fl, fr);
  if (!(std::abs(denom) > 1e-12 * fl.norm() * fr.norm())) {
    throw std::invalid_argument("flipper lines are parallel: they form no 'V'");
  }
  // left.pivot + hl·fl = right.pivot + hr·fr
  const Vec2 d = right.pivot - left.pivot;
  const double hl = cross(d, fr) / denom;
  const double hr = cross(d, fl) / denom;
  if (!(hl > 0.0 && hr > 0.0)) throw std::invalid_argument("flipper lines meet behind a pivot: they form no 'V'");
  g.apex = left.pivot + hl * fl;
  g.h_apex = {hl, hr};
  return g;
}

FlipperGeometry flipper_geometry_from_board(const table::Board& board) {
  const table::Flipper* left = nullptr;
  const table::Flipper* right = nullptr;
  for (const table::Flipper& f : board.flippers) {
    const table::Flipper*& slot = f.side == table::Side::kLeft ? left : right;
    if (slot) throw std::invalid_argument("board '" + board.source + "' has more than one flipper on a side");
    slot = &f;
  }
  if (!left || !right) throw std::invalid_argument("board '" + board.source + "' needs a left and a right flipper");
  try {
    return make_flipper_geometry({left->pivot, table::flipper_tip(*left, left->theta_min_rad)},
                                 {right->pivot, table::flipper_tip(*right, right->theta_min_rad)});
  } catch (const std::invalid_argument& e) {
    // Named by the file and its flipper lines: the tracker and the controllers need the V.
    throw std::invalid_argument(board.source + ":" + std::to_string(left->source_line) + ": flipper '" + left->name +
                                "' (and '" + right->name + "' at line " + std::to_string(right->source_line) +
                                ") at rest: " + e.what() + " (the left flipper points right, the right one left)");
  }
}

bool above_flippers(const FlipperGeometry& g, const Vec2& p) {
  // Left flipper points right: "above" is to its left. The right one points left.
  const FlipperLine& l = g.lines[kLeftFlipper];
  const FlipperLine& r = g.lines[kRightFlipper];
  return cross(l.axis(), p - l.pivot) > 0.0 && cross(r.axis(), p - r.pivot) < 0.0;
}

}  // namespace pinball::track
