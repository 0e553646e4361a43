#include "pinball/sim/game_rules.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "pinball/sim/collision.h"

namespace pinball::sim::rules {

void lose_ball(const table::Board& board, GameState& state, StepEvents& events) {
  events.flags |= StepEvents::kBallLost;
  events.lost_position_m = state.ball.position_m;
  events.lost_velocity_mps = state.ball.velocity_mps;
  state.ball_in_play = false;
  state.balls_left = std::max(0, state.balls_left - 1);
  state.ball.position_m = board.launcher.position;
  state.ball.velocity_mps = Vec2::Zero();
  for (auto& f : state.flippers) f.ball_contact = false;
}

void raise_flags(const table::Board& board, GameState& state, double clear_m) {
  for (const table::Bank& bank : board.banks) {
    for (const std::int32_t m : bank.members) {
      if (state.visible[m] != kRising) continue;
      if (state.ball_in_play && table::distance_to_shape(board.shapes[m], state.ball.position_m) < clear_m) continue;
      state.visible[m] = kVisible;
      --state.rising_flags;
    }
  }
}

void hit_obstacle(const table::Board& board, GameState& state, std::int32_t index, const Vec2& normal,
                  StepEvents& events, double clear_m) {
  const table::Obstacle& o = board.obstacles[index];
  const double strike_mps = -state.ball.velocity_mps.dot(normal);
  state.ball.velocity_mps = obstacle_response(o, normal, state.ball.velocity_mps);
  if (strike_mps >= kMinStrikeSpeed_mps || o.action.eats_ball) {
    score_obstacle_hit(board, state, index, events, clear_m);
  } else {
    events.flags |= StepEvents::kHitObstacle;  // touched: the physics above, no score and no flag
    events.obstacle = index;
  }
}

void score_obstacle_hit(const table::Board& board, GameState& state, std::int32_t index, StepEvents& events,
                        double clear_m) {
  const table::Obstacle& o = board.obstacles[index];
  events.flags |= StepEvents::kHitObstacle;
  events.obstacle = index;
  state.score += o.action.score;
  events.score_gained += o.action.score;
  if (o.bank >= 0) {
    // A flag falls (every shape of its statement); when the whole bank is
    // down it pays and resets (thesis 3.4).
    const table::Bank& bank = board.banks[o.bank];
    for (const std::int32_t m : bank.members) {
      const bool same_flag = m == index || (o.source_line > 0 && board.obstacles[m].source_line == o.source_line);
      if (same_flag) state.visible[m] = kHidden;
    }
    const bool all_down = std::none_of(bank.members.begin(), bank.members.end(),
                                       [&](std::int32_t m) { return state.visible[m] != kHidden; });
    if (all_down) {
      // A flag never rises into the ball: it waits until the ball has left.
      for (const std::int32_t m : bank.members) {
        state.visible[m] = kRising;
        ++state.rising_flags;
      }
      raise_flags(board, state, clear_m);
      state.score += bank.bonus;
      events.score_gained += bank.bonus;
      events.flags |= StepEvents::kBankComplete;
    }
  }
  if (o.action.eats_ball) lose_ball(board, state, events);
}

Vec2 kickout_velocity(const table::Sensor& sensor, Rng& rng) {
  Vec2 v = sensor.kickout_mps;
  // Draws only what the hole has, angle first, so a hole without spread and
  // noise leaves the random stream (and every later launch) untouched.
  if (sensor.kickout_spread_rad > 0.0) {
    const double a = rng.uniform(-sensor.kickout_spread_rad, sensor.kickout_spread_rad);
    const double c = std::cos(a), s = std::sin(a);
    v = Vec2{c * v.x() - s * v.y(), s * v.x() + c * v.y()};
  }
  if (sensor.kickout_noise > 0.0) v *= 1.0 - rng.uniform(0.0, sensor.kickout_noise);
  return v;
}

void fire_sensor(const table::Board& board, GameState& state, std::int32_t index, StepEvents& events) {
  const table::Sensor& sensor = board.sensors[index];
  if (events.sensor < 0) events.sensor = index;
  events.flags |= StepEvents::kSensor;
  state.score += sensor.action.score;
  events.score_gained += sensor.action.score;
  if (sensor.action.eats_ball) {
    lose_ball(board, state, events);
    return;
  }
  if (sensor.has_kickout) {
    state.ball.position_m = sensor.shape.p0;
    state.ball.velocity_mps = kickout_velocity(sensor, state.rng);
    state.sensor_inside[index] = 1;
  }
}

double take_command(const table::Flipper& f, FlipperState& fs, std::uint64_t& flips) {
  if (fs.energized && !fs.was_energized) ++flips;
  fs.was_energized = fs.energized;
  return fs.energized ? f.omega_rad_s : -f.omega_rad_s;
}

bool on_sensor(const table::Sensor& sensor, const Vec2& p, double r) {
  const table::Shape& shape = sensor.shape;
  if (sensor.kind == table::SensorKind::kHole) return (p - shape.p0).norm() <= shape.radius_m;
  if (shape.kind == table::ShapeKind::kLine) return distance_point_segment(p, shape.p0, shape.p1) <= r;
  return (p - shape.p0).norm() <= r + shape.radius_m;
}

bool swept_onto_sensor(const table::Sensor& sensor, const Vec2& from, const Vec2& to, double r) {
  const table::Shape& shape = sensor.shape;
  if (sensor.kind == table::SensorKind::kHole) return distance_point_segment(shape.p0, from, to) <= shape.radius_m;
  if (shape.kind == table::ShapeKind::kLine) return distance_segment_segment(from, to, shape.p0, shape.p1) <= r;
  return distance_point_segment(shape.p0, from, to) <= r + shape.radius_m;
}

void update_contacts(const table::Board& board, GameState& state, std::span<const std::int32_t> candidates, double touch_m,
                     double dt_s, bool has_contact_score, StepEvents& events) {
  const Vec2& p = state.ball.position_m;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const table::Flipper& f = board.flippers[i];
    state.flippers[i].ball_contact =
        distance_point_segment(p, f.pivot, table::flipper_tip(f, state.flippers[i].theta_rad)) <= touch_m;
  }
  if (!has_contact_score) return;
  for (const std::int32_t i : candidates) {
    const double rate = board.obstacles[i].action.contact_score_per_s;
    if (rate <= 0.0 || state.visible[i] != kVisible) continue;
    if (table::distance_to_shape(board.shapes[i], p) <= touch_m) {
      state.score += rate * dt_s;
      events.score_gained += rate * dt_s;
    }
  }
}

bool has_contact_score(const table::Board& board) {
  return std::any_of(board.obstacles.begin(), board.obstacles.end(),
                     [](const table::Obstacle& o) { return o.action.contact_score_per_s > 0.0; });
}

std::vector<table::Shape> sensor_shapes(const table::Board& board) {
  std::vector<table::Shape> shapes;
  shapes.reserve(board.sensors.size());
  for (const table::Sensor& s : board.sensors) shapes.push_back(s.shape);
  return shapes;
}

std::vector<std::int32_t> all_indices(std::size_t n) {
  std::vector<std::int32_t> v(n);
  std::iota(v.begin(), v.end(), 0);
  return v;
}

}  // namespace pinball::sim::rules
