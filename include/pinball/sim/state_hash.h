#pragma once
// A 64-bit fingerprint of a game state's bits, for determinism checks.

#include <cstdint>

#include "pinball/sim/ball_runner.h"
#include "pinball/sim/game_state.h"

namespace pinball::sim {

/// FNV-1a over the exact bits of time, ball, flippers, score, balls and
/// visibility: equal states hash equal, and any bit of difference shows.
std::uint64_t hash_state(const GameState& state);

/// Folds `state` into a running hash (for hashing whole runs step by step).
std::uint64_t hash_combine_state(std::uint64_t seed, const GameState& state);

/// Folds one ball's end into a running hash: where the ball was when it was
/// lost or cut, and its velocity. A cut puts the ball back in the launcher, so
/// the state after it tells two runs cut at the same moment apart only by this.
std::uint64_t hash_combine_ball_end(std::uint64_t seed, const BallResult& ball);

}  // namespace pinball::sim
