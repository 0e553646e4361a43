#include "pinball/simlab/world_factory.h"

#include "pinball/table/board_loader.h"

namespace pinball::simlab {

OwnedWorld make_world(const WorldSpec& spec, const table::Board& belief) {
  OwnedWorld out;
  out.board = std::make_unique<const table::Board>(spec.board_path.empty() ? belief
                                                                           : table::load_board(spec.board_path));
  sim::check_same_flippers(*out.board, belief);
  sim::ModelWorldOptions options;
  options.stepper = spec.stepper;
  options.dt_s = spec.dt_s;
  out.world = sim::make_model_world(*out.board, options);
  return out;
}

}  // namespace pinball::simlab
