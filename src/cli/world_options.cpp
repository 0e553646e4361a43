#include "world_options.h"

#include "data_file.h"
#include "pinball/core/json_read_archive.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/number_option.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/table/board_overlay.h"

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
      ->transform(CLI::IsMember({"model", "twin"}).description(""))  // runs first: CLI11's own message garbles the map
      ->type_name("{model,twin}")
      ->default_str("model");
  // --world is declared first, so its value is in place when these two are checked, wherever it stands.
  const simlab::WorldKind& kind = world.kind;
  cmd.add_option("--twin-params", world.twin_params_path,
                 "the twin's physical parameters (default: config/twin.yaml)")
      ->transform(data_file())
      ->check(CLI::Validator(
          [&kind](std::string&) {
            return kind == simlab::WorldKind::kTwin ? "" : "only the twin reads it: give --world twin too";
          },
          ""));
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
      ->transform(CLI::IsMember({"thesis", "event"}).description(""))  // first, as --world's
      ->check(CLI::Validator(
          [&kind](std::string&) {
            return kind == simlab::WorldKind::kModel ? ""
                                                     : "the twin steps with MuJoCo's own integrator, not a stepper";
          },
          ""))
      ->type_name("{thesis,event}")
      ->default_str("thesis");
  cmd.add_option("--dt", world.dt_s,
                 "the world's time step in seconds (default: the board's, the twin's own for --world twin); for --stepper event the rate at which "
                 "the flipper commands may change")
      ->check(finite_range(table::kMinDt_s, table::kMaxDt_s))
      ->default_str("");  // 0: the board's
}

void add_identified_option(CLI::App& cmd, std::string& identified) {
  cmd.add_option("--identified", identified,
                 "identified parameters laid over the belief board (`pinball identify`, docs/identification.md)")
      ->transform(data_file());
}

double world_actuation_delay_s(std::optional<double> given_s, const simlab::WorldSpec& world,
                               const std::string& identified) {
  if (given_s) return *given_s;
  if (world.kind == simlab::WorldKind::kModel && !identified.empty()) {
    if (const std::optional<double> d = table::identified_actuation_delay_s(table::read_board_overlay(identified)))
      return *d;
  }
  return firmware::kDefaultActuationDelay_s;
}

nlohmann::json identified_report(const std::string& identified) {
  return {{"identified", identified.empty() ? nlohmann::json() : nlohmann::json(identified)}};
}

std::string identified_text_line(const std::string& identified) {
  return identified.empty() ? "" : "identified       " + identified + " (laid over the belief)\n";
}

nlohmann::json world_report(const simlab::WorldSpec& spec, const std::string& belief_board, const sim::World& world) {
  const sim::WorldWarnings w = world.warnings();
  nlohmann::json j = {{"world", std::string(world.name())},
                      {"world_board", spec.board_path.empty() ? belief_board : spec.board_path},
                      {"stepper", spec.kind == simlab::WorldKind::kTwin  // MuJoCo integrates the twin: no stepper
                                      ? nlohmann::json()
                                      : nlohmann::json(sim::stepper_kind_name(spec.stepper))},
                      {"world_warnings", to_json_value(w)}};
  if (spec.kind == simlab::WorldKind::kTwin) {
    j["twin_params"] = spec.twin_params_path.empty() ? std::string("config/twin.yaml") : spec.twin_params_path;
  }
  return j;
}

std::string world_text_line(const nlohmann::json& report) {
  const std::string world = report["world"].get<std::string>();
  const std::string board = report["world_board"].get<std::string>();
  if (world == "twin") {
    sim::WorldWarnings warnings;
    JsonReadArchive("world report").read(&report.at("world_warnings"), "world_warnings", &warnings);
    return "world            MuJoCo twin of " + board + " (" + report["twin_params"].get<std::string>() + "), " +
           describe(warnings) + "\n";
  }
  return "world            " + board + " on the " + world + " stepper\n";
}

}  // namespace pinball::cli
