#include "pinball/sim/penetration.h"

#include <algorithm>

namespace pinball::sim {

double shape_penetration_m(const table::Shape& shape, const Vec2& p, double r) {
  if (shape.kind == table::ShapeKind::kCircle) return std::max(0.0, r + shape.radius_m - (p - shape.p0).norm());
  const double s = (p - shape.p0).dot(shape.normal);
  if (s < 0.0 || s >= r) return 0.0;
  const Vec2 ab = shape.p1 - shape.p0;
  const double u = (p - shape.p0).dot(ab) / ab.squaredNorm();
  return (u < 0.0 || u > 1.0) ? 0.0 : r - s;
}

double obstacle_penetration_m(const table::Board& board, const GameState& state, std::span<const std::int32_t> candidates,
                              const Vec2& p) {
  double depth = 0.0;
  for (const std::int32_t i : candidates) {
    if (state.visible[i] != kVisible) continue;
    depth = std::max(depth, shape_penetration_m(board.shapes[i], p, board.ball.radius_m));
  }
  return depth;
}

double flipper_penetration_m(const table::Board& board, const GameState& state, const Vec2& p) {
  double depth = 0.0;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const table::Flipper& f = board.flippers[i];
    const double d = distance_point_segment(p, f.pivot, table::flipper_tip(f, state.flippers[i].theta_rad));
    depth = std::max(depth, board.ball.radius_m - d);
  }
  return depth;
}

double max_penetration_m(const table::Board& board, const GameState& state) {
  double depth = flipper_penetration_m(board, state, state.ball.position_m);
  for (std::size_t i = 0; i < board.shapes.size(); ++i) {
    if (state.visible[i] != kVisible) continue;
    depth = std::max(depth, shape_penetration_m(board.shapes[i], state.ball.position_m, board.ball.radius_m));
  }
  return depth;
}

}  // namespace pinball::sim
