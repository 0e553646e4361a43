#pragma once
// Recorded play made in the thesis model, where the truth is known: balls
// launched into a world board with the flippers never raised, seen by a
// 200 fps camera with Gaussian noise, as a RecordedPlay.

#include <cstdint>

#include "pinball/bus/recorded_play.h"
#include "pinball/core/rng.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/model_world.h"
#include "pinball/table/board.h"

namespace pinball::testing {

inline bus::RecordedPlay record_model_play(const table::Board& world_board, int balls, double sigma_m,
                                           std::uint64_t seed, double max_ball_s = 30.0) {
  const auto world = sim::make_model_world(world_board);
  sim::GameState state = sim::make_game_state(world_board, seed);
  Rng noise(seed + 1);
  bus::RecordedPlay play;
  play.source = "model";
  const double frame_s = 0.005;
  const auto steps_per_frame = static_cast<int>(std::lround(frame_s / world->dt_s()));
  double t0 = 0.0;
  std::int64_t seq = 0;
  for (int b = 0; b < balls; ++b) {
    world->launch(state, world_board.launcher.pull);
    play.commands.push_back({t0, -1, false, 1});  // the daemon releases at a launch
    for (double t = 0.0; t < max_ball_s && state.ball_in_play; t += frame_s) {
      for (int k = 0; k < steps_per_frame; ++k) world->step(state);
      const Vec2 seen = state.ball.position_m + sigma_m * Vec2(noise.normal(), noise.normal());
      play.frames.push_back({t0 + t + frame_s, seq++, state.ball_in_play, seen, state.flippers[0].ball_contact,
                             state.flippers[1].ball_contact});
    }
    t0 = play.frames.back().t_s + 1.0;
  }
  return play;
}

}  // namespace pinball::testing
