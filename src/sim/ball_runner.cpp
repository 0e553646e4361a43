#include "pinball/sim/ball_runner.h"

#include <algorithm>

namespace pinball::sim {

void begin_ball(World& world, GameState& state, double pull) {
  table::check_launch_pull(world.board(), pull);
  if (state.balls_left <= 0) reset_game(world.board(), state);
  world.launch(state, pull);
}

bool resting_in_launcher(const table::Board& board, const GameState& state) {
  // "Whenever the ball is in the launch chute" (thesis 5.1): back at the
  // launch point and nearly still.
  return state.ball_in_play &&
         (state.ball.position_m - board.launcher.position).norm() < board.ball.radius_m &&
         state.ball.velocity_mps.norm() < table::kLauncherStillSpeed_mps;
}

void cut_ball(const table::Board& board, GameState& state) {
  state.ball_in_play = false;
  state.balls_left = std::max(0, state.balls_left - 1);
  state.ball.position_m = board.launcher.position;
  state.ball.velocity_mps = Vec2::Zero();
}

}  // namespace pinball::sim
