#include "pinball/sim/game_state.h"

#include <algorithm>

namespace pinball::sim {

GameState make_game_state(const table::Board& board, std::uint64_t seed) {
  GameState s;
  s.rng = Rng(seed);
  s.flippers.resize(board.flippers.size());
  s.visible.resize(board.obstacles.size());
  s.sensor_inside.resize(board.sensors.size());
  reset_game(board, s);
  return s;
}

void reset_game(const table::Board& board, GameState& state) {
  state.score = 0.0;
  state.balls_left = board.balls_per_game;
  state.ball_in_play = false;
  state.ball.position_m = board.launcher.position;
  state.ball.velocity_mps = Vec2::Zero();
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    state.flippers[i] = FlipperState{board.flippers[i].theta_min_rad, 0.0, false, false, false};
  }
  for (std::size_t i = 0; i < board.obstacles.size(); ++i) {
    state.visible[i] = board.obstacles[i].visible ? kVisible : kHidden;
  }
  state.rising_flags = 0;
  std::fill(state.sensor_inside.begin(), state.sensor_inside.end(), std::uint8_t{0});
}

void launch_ball(const table::Board& board, GameState& state, double pull) {
  state.ball_in_play = true;
  if (board.start) {  // served, not launched: no plunger, no noise
    state.ball.position_m = board.start->position;
    state.ball.velocity_mps = board.start->velocity_mps;
    return;
  }
  const double r = state.rng.uniform(0.0, board.launcher.noise_max);
  state.ball.position_m = board.launcher.position;
  state.ball.velocity_mps = Vec2{0.0, pull * (1.0 - r) * board.ball.speed_max_mps};
  state.ball_in_play = true;
}

}  // namespace pinball::sim
