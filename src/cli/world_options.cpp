#include "world_options.h"

#include "data_file.h"

#include <map>
#include <string>

namespace pinball::cli {

void add_world_options(CLI::App& cmd, simlab::WorldSpec& world) {
  const std::map<std::string, simlab::WorldKind> kinds{{"model", simlab::WorldKind::kModel},
                                                       {"twin", simlab::WorldKind::kTwin}};
  cmd.add_option("--world", world.kind,
                 "which world plays the table: model (the thesis model on --stepper) or twin (the MuJoCo lab twin, "
                 "docs/worlds.md)")
      ->transform(CLI::CheckedTransformer(kinds).description(""))
      ->type_name("{model,twin}")
      ->default_str("model");
  cmd.add_option("--twin-params", world.twin_params_path,
                 "the twin's physical parameters (default: config/twin.yaml)")
      ->transform(data_file());
  cmd.add_option("--world-board", world.board_path,
                 "the world: the board the table really is (default: the belief, the board the tracker and "
                 "controller assume); same flippers required")
      ->transform(data_file());
  const std::map<std::string, sim::StepperKind> steppers{{"thesis", sim::StepperKind::kThesis},
                                                         {"event", sim::StepperKind::kEvent}};
  cmd.add_option("--stepper", world.stepper,
                 "the model world's integrator: thesis (fixed-step Euler, Ch. 3) or event (exact between events, "
                 "docs/physics.md)")
      ->transform(CLI::CheckedTransformer(steppers).description(""))
      ->type_name("{thesis,event}")
      ->default_str("thesis");
  cmd.add_option("--dt", world.dt_s,
                 "the world's time step in seconds (default: the board's, the twin's own for --world twin); for --stepper event the rate at which "
                 "the flipper commands may change")
      ->check(CLI::PositiveNumber)
      ->default_str("");  // 0: the board's
}

}  // namespace pinball::cli
