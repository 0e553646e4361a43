#pragma once
// Helpers that build small boards in code for the simulator tests. Every
// obstacle is added to Board::shapes and Board::obstacles at the same index.
// Units: metres, seconds, radians, board frame (+y up the table).

#include <cmath>
#include <cstdint>
#include <string>

#include "pinball/core/geometry.h"
#include "pinball/core/rng.h"
#include "pinball/table/board.h"
#include "pinball/table/board_loader.h"
#include "pinball/sim/game_state.h"

namespace pinball::sim::testing {

/// How many of a ball's bounces score when it falls h0_m onto a floor of
/// reflectivity rho under g: impact k comes at sqrt(2 g h0)·ρ^(k−1), and
/// only strikes of at least `min_strike_mps` score.
inline int scoring_bounces(double g_mps2, double h0_m, double rho, double min_strike_mps) {
  int n = 0;
  for (double v = std::sqrt(2.0 * g_mps2 * h0_m); v >= min_strike_mps; v *= rho) ++n;
  return n;
}

/// Obstacle attributes with reflectivity rho and everything else default.
inline table::Obstacle obstacle_with_rho(double rho) {
  table::Obstacle o;
  o.rho = rho;
  return o;
}

/// Adds a one-sided line p0 -> p1 (normal = unit left perpendicular of p1 - p0); returns its index.
inline int add_line(table::Board& board, const Vec2& p0, const Vec2& p1, double rho = 1.0, table::Action action = {},
                    const std::string& name = "line") {
  const table::Shape s = table::make_line_shape(p0, p1);
  table::Obstacle o = obstacle_with_rho(rho);
  o.action = action;
  o.name = name;
  board.shapes.push_back(s);
  board.obstacles.push_back(o);
  return static_cast<int>(board.shapes.size()) - 1;
}

/// Adds a circle of radius_m (0: a point) around c; returns its index.
inline int add_circle(table::Board& board, const Vec2& c, double radius_m, double rho = 1.0, table::Action action = {},
                      const std::string& name = "circle") {
  const table::Shape s = table::make_circle_shape(c, radius_m);
  table::Obstacle o = obstacle_with_rho(rho);
  o.action = action;
  o.name = name;
  board.shapes.push_back(s);
  board.obstacles.push_back(o);
  return static_cast<int>(board.shapes.size()) - 1;
}

/// Adds a point (a circle of radius 0) at c; returns its index.
inline int add_point(table::Board& board, const Vec2& c, double rho = 1.0, table::Action action = {}) {
  return add_circle(board, c, 0.0, rho, action, "point");
}

/// Adds a thin two-sided wall a-b: the lines a->b and b->a and a point at each
/// end. Returns the index of the first of its four obstacles.
inline int add_wall(table::Board& board, const Vec2& a, const Vec2& b, double rho = 1.0) {
  const int first = add_line(board, a, b, rho, {}, "wall");
  add_line(board, b, a, rho, {}, "wall");
  add_point(board, a, rho);
  add_point(board, b, rho);
  return first;
}

/// Adds a flipper; returns its index.
inline int add_flipper(table::Board& board, table::Side side, const Vec2& pivot, double length_m = 0.076,
                       double theta_min_rad = -0.5, double theta_max_rad = 0.5, double omega_rad_s = 33.0,
                       double rho = 0.5, double mu = 1.0) {
  table::Flipper f;
  f.side = side;
  f.pivot = pivot;
  f.length_m = length_m;
  f.theta_min_rad = theta_min_rad;
  f.theta_max_rad = theta_max_rad;
  f.omega_rad_s = omega_rad_s;
  f.rho = rho;
  f.mu = mu;
  f.name = side == table::Side::kLeft ? "left" : "right";
  board.flippers.push_back(f);
  return static_cast<int>(board.flippers.size()) - 1;
}

/// A hole of `radius_m` at `centre` that kicks the ball out at exactly
/// `kickout_mps` (no spread, no noise).
inline table::Sensor exact_kickout_hole(const Vec2& centre, double radius_m, const Vec2& kickout_mps) {
  table::Sensor hole;
  hole.kind = table::SensorKind::kHole;
  hole.shape = table::make_circle_shape(centre, radius_m);
  hole.has_kickout = true;
  hole.kickout_mps = kickout_mps;
  hole.kickout_spread_rad = 0.0;
  hole.kickout_noise = 0.0;
  return hole;
}

/// Two flippers whose sweeps overlap, the ball served at rest on the right
/// one 5 mm under the left one's blade: raising the right pinches it there.
inline table::Board ball_between_two_flippers() {
  return table::parse_board(R"(pinball-board 1
size 1 1.5
ball 0.0135 5
gravity 1.11
dt 0.0005
balls 1
launcher 0.9 1.4 noise=0
start 0.390872753573 0.283081920028 0 0
flipper right 0.45 0.3 0.1 -0.5 0.5 35.0 rho=0.6 mu=1.6 name=rf
flipper left 0.330872754 0.304584423 0.1 -0.05 0.5 35.0 rho=0.6 mu=1.6 name=lf
)", "two_flippers.board");
}

/// An empty table of the given size: ball radius 13.5 mm, the given gravity
/// and dt, a large speed clamp (so that it does not interfere unless a test
/// lowers it), launcher in the lower right.
inline table::Board empty_board(double width_m = 1.0, double height_m = 1.0, double gravity_mps2 = 1.11,
                         double dt_s = 5e-4) {
  table::Board b;
  b.source = "test";
  b.width_m = width_m;
  b.height_m = height_m;
  b.ball.radius_m = 0.0135;
  b.ball.speed_max_mps = 100.0;
  b.gravity_mps2 = gravity_mps2;
  b.dt_s = dt_s;
  b.balls_per_game = 3;
  b.launcher.position = Vec2{width_m - 0.05, 0.05};
  b.launcher.pull = 1.0;
  b.launcher.noise_max = 0.03;
  return b;
}

/// Adds a closed box [0, w] x [0, h] of one-sided lines whose normals point
/// inwards (counter-clockwise order). Returns the index of the floor line.
inline int add_box(table::Board& board, double w, double h, double rho = 1.0) {
  const int floor = add_line(board, {0.0, 0.0}, {w, 0.0}, rho, {}, "floor");
  add_line(board, {w, 0.0}, {w, h}, rho, {}, "right");
  add_line(board, {w, h}, {0.0, h}, rho, {}, "top");
  add_line(board, {0.0, h}, {0.0, 0.0}, rho, {}, "left");
  return floor;
}

/// A box board of the table's size with inward walls.
inline table::Board box_board(double rho = 1.0, double gravity_mps2 = 1.11, double dt_s = 5e-4) {
  table::Board b = empty_board(0.51, 1.07, gravity_mps2, dt_s);
  add_box(b, b.width_m, b.height_m, rho);
  return b;
}

/// A box board with interior bumpers and walls and two flippers near the bottom.
inline table::Board box_with_bumpers_and_flippers(double dt_s = 5e-4) {
  table::Board b = box_board(0.9, 1.11, dt_s);
  b.ball.speed_max_mps = 5.0;
  add_circle(b, {0.15, 0.70}, 0.03, 1.3);
  add_circle(b, {0.35, 0.72}, 0.03, 1.3);
  add_circle(b, {0.25, 0.55}, 0.025, 0.8);
  add_point(b, {0.40, 0.45}, 0.9);
  add_wall(b, {0.05, 0.40}, {0.15, 0.30}, 0.7);
  add_wall(b, {0.46, 0.40}, {0.36, 0.30}, 0.7);
  add_wall(b, {0.20, 0.90}, {0.30, 0.95}, 1.0);
  add_flipper(b, table::Side::kLeft, {0.15, 0.20}, 0.076, -0.5, 0.5, 33.0, 0.6, 1.0);
  add_flipper(b, table::Side::kRight, {0.36, 0.20}, 0.076, -0.5, 0.5, 33.0, 0.6, 1.0);
  return b;
}

/// A pocket closed round a left flipper: a roof parallel to the raised flipper
/// 20 mm above its face (less than the ball's 27 mm diameter) and walls at the
/// pivot and just beyond the tip, all with rho 0.5. With the ball inside, the
/// flipper can never reach its up stop.
struct FlipperPocket {
  Vec2 roof0 = Vec2::Zero();  ///< roof start (above the pivot)
  Vec2 roof1 = Vec2::Zero();  ///< roof end (beyond the tip)
  double left_x = 0.0;        ///< inner wall at the pivot
  double right_x = 0.0;       ///< inner wall beyond the tip
};

/// Adds the walls of a FlipperPocket round left flipper `fl`.
inline FlipperPocket add_flipper_pocket(table::Board& b, int fl) {
  const table::Flipper f = b.flippers[fl];
  const Vec2 up_max = table::flipper_up_normal(f, f.theta_max_rad);
  const Vec2 dir_max = table::flipper_direction(f, f.theta_max_rad);
  FlipperPocket p;
  p.roof0 = f.pivot + 0.020 * up_max - 0.01 * dir_max;
  p.roof1 = f.pivot + 0.020 * up_max + 0.15 * dir_max;
  add_wall(b, p.roof0, p.roof1, 0.5);
  p.left_x = f.pivot.x() - 0.001;
  p.right_x = f.pivot.x() + f.length_m + 0.002;
  add_wall(b, {p.left_x, f.pivot.y() - 0.08}, {p.left_x, p.roof0.y()}, 0.5);
  const double roof_at_right = p.roof0.y() + (p.right_x - p.roof0.x()) * dir_max.y() / dir_max.x();
  add_wall(b, {p.right_x, f.pivot.y() - 0.08}, {p.right_x, roof_at_right}, 0.5);
  return p;
}

/// A fresh state with the ball in play at p with velocity v.
inline GameState state_with_ball(const table::Board& board, const Vec2& p, const Vec2& v, std::uint64_t seed = 1) {
  GameState s = make_game_state(board, seed);
  s.ball_in_play = true;
  s.ball.position_m = p;
  s.ball.velocity_mps = v;
  return s;
}

/// True when both components are finite.
inline bool finite(const Vec2& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }

}  // namespace pinball::sim::testing
