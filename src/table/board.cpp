#include "pinball/table/board.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pinball/core/format.h"

namespace pinball::table {

Shape make_line_shape(const Vec2& p0, const Vec2& p1) {
  Shape s;
  s.kind = ShapeKind::kLine;
  s.p0 = p0;
  s.p1 = p1;
  s.normal = perp_left(p1 - p0).normalized();
  return s;
}

void set_wall_thickness(Board& board, double thickness_m) {
  if (!(thickness_m >= 0.0) || !std::isfinite(thickness_m))
    throw std::invalid_argument("wall thickness must be a finite number >= 0 m, got " + std::to_string(thickness_m));
  const double was = 0.5 * board.wall_thickness_m;
  const double now = 0.5 * thickness_m;
  constexpr double kSame_m = 1e-9;
  // A face's centre-line end points, from its face and the thickness it had.
  const auto centre = [was](const Shape& s) { return std::pair<Vec2, Vec2>{s.p0 - was * s.normal, s.p1 - was * s.normal}; };
  std::vector<char> paired(board.shapes.size(), 0);
  for (std::size_t i = 0; i < board.shapes.size(); ++i) {
    const Shape& a = board.shapes[i];
    if (a.kind != ShapeKind::kLine || paired[i]) continue;
    const auto [a0, a1] = centre(a);
    for (std::size_t j = i + 1; j < board.shapes.size(); ++j) {
      const Shape& b = board.shapes[j];
      if (b.kind != ShapeKind::kLine || paired[j]) continue;
      const auto [b0, b1] = centre(b);
      if ((a0 - b1).norm() > kSame_m || (a1 - b0).norm() > kSame_m) continue;
      paired[i] = paired[j] = 1;
      break;
    }
  }
  for (std::size_t i = 0; i < board.shapes.size(); ++i) {
    if (!paired[i]) continue;
    Shape& s = board.shapes[i];
    const auto [c0, c1] = centre(s);
    s.p0 = c0 + now * s.normal;
    s.p1 = c1 + now * s.normal;
  }
  board.wall_thickness_m = thickness_m;
}

Shape make_circle_shape(const Vec2& centre, double radius_m) {
  Shape s;
  s.kind = ShapeKind::kCircle;
  s.p0 = centre;
  s.p1 = centre;
  s.radius_m = radius_m;
  return s;
}

double distance_to_shape(const Shape& shape, const Vec2& p) {
  if (shape.kind == ShapeKind::kLine) return distance_point_segment(p, shape.p0, shape.p1);
  return (p - shape.p0).norm() - shape.radius_m;
}

std::optional<BallOverlap> ball_overlap(const Board& board, const Vec2& p) {
  const double r = board.ball.radius_m;
  for (std::size_t i = 0; i < board.shapes.size(); ++i) {
    const double d = distance_to_shape(board.shapes[i], p);
    if (d < r) return BallOverlap{"'" + board.obstacles[i].name + "'", d};
  }
  for (const Flipper& f : board.flippers) {
    const double d = distance_point_segment(p, f.pivot, flipper_tip(f, f.theta_min_rad));
    if (d < r) return BallOverlap{"flipper '" + f.name + "' in its down position", d};
  }
  return std::nullopt;
}

std::array<int, 2> flippers_by_side(const Board& board) {
  std::array<int, 2> index{-1, -1};
  for (std::size_t i = 0; i < board.flippers.size(); ++i)
    index[board.flippers[i].side == Side::kLeft ? 0 : 1] = static_cast<int>(i);
  return index;
}

std::string_view side_name(Side side) { return side == Side::kLeft ? "left" : "right"; }

std::optional<Side> parse_side(std::string_view text) {
  if (text == "left") return Side::kLeft;
  if (text == "right") return Side::kRight;
  return std::nullopt;
}

Vec2 flipper_direction(const Flipper& f, double theta_rad) {
  const double c = std::cos(theta_rad);
  const double s = std::sin(theta_rad);
  return f.side == Side::kLeft ? Vec2{c, s} : Vec2{-c, s};
}

Vec2 flipper_up_normal(const Flipper& f, double theta_rad) {
  // d/dθ of the direction: the way every point of the flipper moves as θ grows.
  const double c = std::cos(theta_rad);
  const double s = std::sin(theta_rad);
  return f.side == Side::kLeft ? Vec2{-s, c} : Vec2{s, c};
}

Vec2 flipper_tip(const Flipper& f, double theta_rad) {
  return f.pivot + f.length_m * flipper_direction(f, theta_rad);
}

std::pair<int, double> nearest_flipper_at_rest(const Board& board, const Vec2& p) {
  int nearest = -1;
  double nearest_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const Flipper& f = board.flippers[i];
    const double d = distance_point_segment(p, f.pivot, flipper_tip(f, f.theta_min_rad));
    if (d < nearest_d) {
      nearest_d = d;
      nearest = static_cast<int>(i);
    }
  }
  return {nearest, nearest_d};
}

double max_stable_dt_s(const Board& board) {
  double dt = std::numeric_limits<double>::infinity();
  for (const Flipper& f : board.flippers) {
    if (f.length_m <= board.ball.radius_m) continue;  // any step is safe
    dt = std::min(dt, 2.0 * std::asin(board.ball.radius_m / f.length_m) / f.omega_rad_s);
  }
  return dt;
}

double min_launch_speed_mps(const Board& board) {
  const double g = board.gravity_mps2;
  return std::sqrt(2.0 * g * board.ball.radius_m + kLauncherStillSpeed_mps * kLauncherStillSpeed_mps) +
         g * board.dt_s;
}

double slowest_launch_mps(const Board& board, double pull) {
  return pull * (1.0 - board.launcher.noise_max) * board.ball.speed_max_mps;
}

bool near_playfield(const Board& board, const Vec2& p) {
  const double m = kOffPlayfieldMargin_m;
  return p.x() >= -m && p.x() <= board.width_m + m && p.y() >= -m && p.y() <= board.height_m + m;
}

std::string off_playfield_text(const Board& board) {
  return "over " + format_number(kOffPlayfieldMargin_m * 1e2) + " cm off the " + format_number(board.width_m) +
         " x " + format_number(board.height_m) + " m playfield of " + board.source;
}

void check_launch_pull(const Board& board, double pull) {
  if (board.start) return;
  const double slowest = slowest_launch_mps(board, pull);
  const double needed = min_launch_speed_mps(board);
  if (!(slowest >= needed)) {
    std::ostringstream msg;
    msg << "launch pull " << pull << " gives launches as slow as " << slowest << " m/s (pull*(1 - noise)*speed_max), "
        << "below the " << needed << " m/s a ball needs to rise more than its radius (" << board.ball.radius_m
        << " m) above the launcher against g = " << board.gravity_mps2
        << " m/s^2: it would stop there and be relaunched at its apex for ever";
    throw std::invalid_argument(msg.str());
  }
}

double flipper_step_chord_m(const Flipper& flipper, double dt_s) {
  const double half_sweep = flipper.omega_rad_s * dt_s / 2.0;
  // sin is only monotonic up to π/2; beyond it the sweep is certainly too large.
  return half_sweep >= M_PI / 2.0 ? flipper.length_m : flipper.length_m * std::sin(half_sweep);
}

std::string flipper_tip_speed_problem(const Board& board, const Flipper& f) {
  const double tip_mps = f.omega_rad_s * f.length_m;
  if (tip_mps < board.ball.speed_max_mps) return "";
  return "flipper '" + f.name + "': its tip moves at " + format_number(tip_mps, 4) +
         " m/s (OMEGA x LENGTH), not below the ball's speed clamp SPEED_MAX " +
         format_number(board.ball.speed_max_mps, 4) +
         " m/s: a struck ball, held to the clamp, could never leave the blade";
}

void check_flipper_time_step(const Board& board, double dt_s) {
  for (const Flipper& f : board.flippers) {
    const double chord = flipper_step_chord_m(f, dt_s);
    if (!(chord < board.ball.radius_m)) {
      std::ostringstream msg;
      msg << "flipper '" << f.name << "': l*sin(omega*dt/2) = " << chord << " m is not below the ball radius "
          << board.ball.radius_m << " m at dt = " << dt_s << " s (largest stable dt is " << max_stable_dt_s(board)
          << " s)";
      throw std::invalid_argument(msg.str());
    }
  }
}

}  // namespace pinball::table
