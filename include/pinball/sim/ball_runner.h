#pragma once
// Plays whole balls in a world: launch, step until the ball is lost or a
// time limit cuts it, relaunch a ball that falls back into the launcher. The
// policy (who presses the flipper buttons) and the observer (traces, video)
// are passed in, so the same loop serves the CLI, the tests and benchmarks.

#include <cstdint>

#include "pinball/sim/game_state.h"
#include "pinball/sim/world.h"

namespace pinball::sim {

/// Limits for one ball.
struct BallLimits {
  double max_ball_time_s = 300.0;  ///< a ball still in play after this is cut (a score cycle)
  double pull = -1.0;              ///< launcher pull fraction; negative takes the board's
};

/// Outcome of one ball.
struct BallResult {
  double score = 0.0;        ///< points scored during this ball
  double duration_s = 0.0;   ///< simulated time from first launch to loss or cut
  std::uint64_t steps = 0;   ///< integration steps
  int launches = 0;          ///< launches (more than one when a weak launch rolled back)
  int flips = 0;             ///< flipper activations (button presses)
  bool cut = false;          ///< stopped at max_ball_time_s, not lost
  bool left_table = false;   ///< lost by leaving the table's bounds rather than by a drain
  Vec2 end_position_m = Vec2::Zero();    ///< the ball when it was lost or cut (before a cut puts it back)
  Vec2 end_velocity_mps = Vec2::Zero();  ///< the same, its velocity
};

/// Starts the next ball: a new game if the last one is over, then the world's
/// launch. Throws std::invalid_argument (table::check_launch_pull) if `pull`
/// can launch the ball too slowly to leave the launcher.
void begin_ball(World& world, GameState& state, double pull);

/// True when a ball in play has rolled back to the launcher and stopped there.
bool resting_in_launcher(const table::Board& board, const GameState& state);

/// Ends a ball that ran past its time limit: counted as lost.
void cut_ball(const table::Board& board, GameState& state);

/// Plays one ball in `world`. `policy(state)` sets flipper commands before
/// each step; `observer(state, events)` sees the state after each step.
template <class Policy, class Observer>
BallResult play_ball(World& world, GameState& state, const BallLimits& limits, Policy&& policy, Observer&& observer) {
  const table::Board& board = world.board();
  const double pull = limits.pull >= 0.0 ? limits.pull : board.launcher.pull;
  begin_ball(world, state, pull);
  BallResult result;
  result.launches = 1;
  const double score_before = state.score;
  const std::uint64_t flips_before = state.flips;
  const double t0 = state.time_s;
  observer(static_cast<const GameState&>(state), StepEvents{StepEvents::kLaunch});
  while (true) {
    policy(state);
    const StepEvents events = world.step(state);
    ++result.steps;
    observer(static_cast<const GameState&>(state), events);
    if (events.has(StepEvents::kBallLost)) {
      result.left_table = events.has(StepEvents::kLeftTable);
      result.end_position_m = events.lost_position_m;  // the state holds it in the launcher already
      result.end_velocity_mps = events.lost_velocity_mps;
      break;
    }
    // Half a step of slack: time is a sum of steps and may fall just short.
    if (state.time_s - t0 >= limits.max_ball_time_s - 0.5 * world.dt_s()) {
      result.cut = true;
      result.end_position_m = state.ball.position_m;
      result.end_velocity_mps = state.ball.velocity_mps;
      cut_ball(board, state);
      break;
    }
    if (resting_in_launcher(board, state)) {
      world.launch(state, pull);
      ++result.launches;
      observer(static_cast<const GameState&>(state), StepEvents{StepEvents::kLaunch});
    }
  }
  for (auto& f : state.flippers) f.energized = false;
  result.score = state.score - score_before;
  result.flips = static_cast<int>(state.flips - flips_before);
  result.duration_s = state.time_s - t0;
  return result;
}

}  // namespace pinball::sim
