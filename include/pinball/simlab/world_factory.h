#pragma once
// Picks and builds the world a command plays (design.md, "Worlds and
// beliefs"): which board the world really is, and which world plays it. The
// belief (what the tracker and controller assume) is loaded by the caller;
// the world defaults to the same board, so how a controller fares when the
// world is not its model is one option away.

#include <memory>
#include <cstdint>
#include <string>
#include <string_view>

#include "pinball/sim/model_world.h"
#include "pinball/sim/world.h"
#include "pinball/table/board.h"

namespace pinball::simlab {

/// Which kind of world plays the table.
enum class WorldKind : std::uint8_t {
  kModel,  ///< the thesis model on a stepper (sim::make_model_world)
  kTwin,   ///< the MuJoCo lab twin (twin_world.h): not written as our model
};

/// Which world to play.
struct WorldSpec {
  WorldKind kind = WorldKind::kModel;            ///< model or twin
  std::string board_path;                        ///< the world's own board file; empty: the belief's board
  sim::StepperKind stepper = sim::StepperKind::kThesis;  ///< the model world's integrator (model only)
  double dt_s = 0.0;                             ///< step or step horizon (s); 0: the board's (model) or the twin's
  std::string twin_params_path;                  ///< the twin's physical parameters; empty: the shipped config/twin.yaml
};

/// Parses "model" or "twin"; throws std::invalid_argument naming the value otherwise.
WorldKind parse_world_kind(std::string_view name);
/// "model" or "twin".
std::string_view world_kind_name(WorldKind kind);
/// What a report calls the world of `spec`: "thesis", "event" or "twin".
std::string_view world_name(const WorldSpec& spec);
/// The shipped twin parameter file, config/twin.yaml, found as shipped data (data_path.h).
std::string default_twin_params_path();
/// True when this build has the MuJoCo twin (configured with PINBALL_TWIN and libmujoco-dev).
bool twin_available();

/// The world of `spec` for a belief that is the board file `belief_board`
/// with the identified overlay `identified` laid over it ("": none;
/// table::load_belief_board). The rule for worlds (docs/identification.md):
/// the overlay is part of the belief only. A model world that defaults to
/// the belief plays it with the overlay (a controller is learned "on the
/// identified model"), but the twin stands in for the real table: it is built
/// from the board file, never from identified values (it classifies
/// materials by the file's ρ). So with an overlay, a twin without a world
/// board of its own gets `belief_board`; every other spec is returned as it is.
/// Every command that takes --identified passes its spec through here.
WorldSpec world_for_belief(WorldSpec spec, const std::string& belief_board, const std::string& identified);

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
/// The twin loads its parameter file (TwinParamsError naming file:key) and
/// refuses a board it cannot represent (std::invalid_argument); in a build
/// without it, kTwin throws std::invalid_argument saying so.
OwnedWorld make_world(const WorldSpec& spec, const table::Board& belief);

}  // namespace pinball::simlab
