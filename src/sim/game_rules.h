#pragma once
// What a hit or a sensor entry does to the game (thesis 3.3.2, 3.4): shared by
// every stepper so that steppers differ only in how they integrate. Internal
// to pinball_sim.

#include <cstdint>

#include "pinball/core/geometry.h"
#include "pinball/sim/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::sim::rules {

/// The ball is lost: back to the launcher, out of play, one ball fewer.
void lose_ball(const Board& board, GameState& state, StepEvents& events);

/// Raises the flags waiting in state kRising whose shape is at least clear_m
/// from the ball (a flag never rises into the ball).
void raise_flags(const Board& board, GameState& state, double clear_m);

/// The ball strikes obstacle `index` with contact normal `normal`: reflection
/// with ρ, the kick, the score, the bank flag falling (and the bank's bonus),
/// the ball eaten. clear_m as for raise_flags.
void hit_obstacle(const Board& board, GameState& state, std::int32_t index, const Vec2& normal,
                  StepEvents& events, double clear_m);

/// The ball entered sensor `index`: score, eat, or the hole's kickout.
void fire_sensor(const Board& board, GameState& state, std::int32_t index, StepEvents& events);

}  // namespace pinball::sim::rules
