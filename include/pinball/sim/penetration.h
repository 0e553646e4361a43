#pragma once
// How far the ball overlaps what it must not: the invariant every stepper and
// every stiff-case test checks ("no ball left inside an obstacle").

#include <cstdint>
#include <span>

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"

namespace pinball::sim {

/// Overlap depth (m) of a ball of radius r at p with one obstacle shape; 0
/// when apart. One-sided lines count only on their front face and within the
/// segment (a ball behind a gate is passing through it).
double shape_penetration_m(const table::Shape& shape, const Vec2& p, double r);

/// Deepest overlap with the visible reflecting obstacles listed in `candidates`.
double obstacle_penetration_m(const table::Board& board, const GameState& state, std::span<const std::int32_t> candidates,
                              const Vec2& p);

/// Deepest overlap with any flipper at its current angle (two-sided).
double flipper_penetration_m(const table::Board& board, const GameState& state, const Vec2& p);

/// Deepest overlap of the ball in `state` with every visible obstacle and
/// flipper (linear scan: for tests and diagnostics, not hot loops).
double max_penetration_m(const table::Board& board, const GameState& state);

}  // namespace pinball::sim
