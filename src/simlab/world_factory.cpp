#include "pinball/simlab/world_factory.h"

#include <stdexcept>

#include "pinball/core/data_path.h"
#include "pinball/core/format.h"
#include "pinball/table/board.h"
#include "pinball/table/board_loader.h"
#ifdef PINBALL_HAVE_TWIN
#include "pinball/simlab/twin_world.h"
#endif

namespace pinball::simlab {

WorldKind parse_world_kind(std::string_view name) {
  if (name == "model") return WorldKind::kModel;
  if (name == "twin") return WorldKind::kTwin;
  throw std::invalid_argument("unknown world '" + std::string(name) + "' (expected model or twin)");
}

std::string_view world_kind_name(WorldKind kind) { return kind == WorldKind::kTwin ? "twin" : "model"; }

std::string_view world_name(const WorldSpec& spec) {
  return spec.kind == WorldKind::kTwin ? "twin" : sim::stepper_kind_name(spec.stepper);
}

std::string default_twin_params_path() { return find_data_file("config/twin.yaml"); }

bool twin_available() {
#ifdef PINBALL_HAVE_TWIN
  return true;
#else
  return false;
#endif
}

WorldSpec world_for_belief(WorldSpec spec, const std::string& belief_board, const std::string& identified) {
  if (!identified.empty() && spec.kind == WorldKind::kTwin && spec.board_path.empty()) spec.board_path = belief_board;
  return spec;
}

OwnedWorld make_world(const WorldSpec& spec, const table::Board& belief) {
  OwnedWorld out;
  out.board = std::make_unique<const table::Board>(spec.board_path.empty() ? belief
                                                                           : table::load_board(spec.board_path));
  sim::check_same_flippers(*out.board, belief);
  if (spec.kind == WorldKind::kTwin) {
#ifdef PINBALL_HAVE_TWIN
    out.world = make_twin_world(*out.board, load_twin_params(spec.twin_params_path.empty() ? default_twin_params_path()
                                                                                             : spec.twin_params_path),
                                spec.dt_s);
    return out;
#else
    throw std::invalid_argument("this build has no MuJoCo twin: install libmujoco-dev and configure with "
                                "-DPINBALL_TWIN=ON (docs/worlds.md)");
#endif
  }
  sim::ModelWorldOptions options;
  options.stepper = spec.stepper;
  options.dt_s = spec.dt_s;
  if (spec.dt_s > 0.0) {
    // The step asked for (--dt, sim.dt) against the board's flippers: said as that choice, not the board's.
    try {
      table::check_flipper_time_step(*out.board, spec.dt_s);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("the time step asked for (--dt " + format_number(spec.dt_s) +
                                  " s) is too long for this board's flippers: " + e.what());
    }
  }
  out.world = sim::make_model_world(*out.board, options);
  return out;
}

}  // namespace pinball::simlab
