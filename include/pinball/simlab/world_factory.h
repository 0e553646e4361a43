#pragma once
// Picks and builds the world a command plays (design.md, "Worlds and
// beliefs"): which board the world really is, and which world plays it. The
// belief (what the tracker and controller assume) is loaded by the caller;
// the world defaults to the same board, so how a controller fares when the
// world is not its model is one option away.

#include <memory>
#include <string>

#include "pinball/sim/model_world.h"
#include "pinball/sim/world.h"
#include "pinball/table/board.h"

namespace pinball::simlab {

/// Which world to play.
struct WorldSpec {
  std::string board_path;                        ///< the world's own board file; empty: the belief's board
  sim::StepperKind stepper = sim::StepperKind::kThesis;  ///< the model world's integrator
  double dt_s = 0.0;                             ///< step or step horizon (s); 0: the board's
};

/// A world with the board it plays (the world borrows it, so they travel together).
struct OwnedWorld {
  std::unique_ptr<const table::Board> board;  ///< the world's board
  std::unique_ptr<sim::World> world;          ///< plays *board

  sim::World& operator*() const { return *world; }
  sim::World* operator->() const { return world.get(); }
};

/// Builds the world of `spec` for a controller that believes `belief`: loads
/// spec.board_path (table::BoardError on a bad file) or copies the belief, and
/// checks that world and belief wire the same flippers (std::invalid_argument).
OwnedWorld make_world(const WorldSpec& spec, const table::Board& belief);

}  // namespace pinball::simlab
