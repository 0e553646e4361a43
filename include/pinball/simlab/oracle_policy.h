#pragma once
// The thesis's "spastic flipper" (1.1.1) played from the simulator's true ball
// state. It exists so that `pinball sim --policy spastic` and the benchmarks
// exercise the flippers before the tracker lands; the controller proper never
// sees true state (thesis 4.1) and will replace this with the tracker's
// projection.

#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"

namespace pinball::simlab {

/// Energises the flipper nearest the ball while the ball is within
/// `reach_factor` ball radii of that flipper's down-position segment and
/// falling; releases every other flipper.
void oracle_spastic_policy(const table::Board& board, sim::GameState& state, double reach_factor = 2.5);

}  // namespace pinball::simlab
