#pragma once
// A 64-bit fingerprint of a game state's bits, for determinism checks.

#include <cstdint>

#include "pinball/sim/game_state.h"

namespace pinball::sim {

/// FNV-1a over the exact bits of time, ball, flippers, score, balls and
/// visibility: equal states hash equal, and any bit of difference shows.
std::uint64_t hash_state(const GameState& state);

/// Folds `state` into a running hash (for hashing whole runs step by step).
std::uint64_t hash_combine_state(std::uint64_t seed, const GameState& state);

}  // namespace pinball::sim
