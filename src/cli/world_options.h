#pragma once
// The world flags shared by every command that plays a table (`pinball sim`,
// `pinball learn`, `pinball bench ceiling`): the world is given apart from the
// belief (the BOARD argument or --board, with --identified laid over it), and
// defaults to it.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "pinball/simlab/world_factory.h"

namespace pinball::cli {

/// Adds --world, --twin-params, --world-board, --stepper and --dt, writing into `world`.
void add_world_options(CLI::App& cmd, simlab::WorldSpec& world);

/// Adds --identified FILE: the identified parameters (`pinball identify`)
/// laid over the belief board (table::load_belief_board). The world follows
/// simlab::world_for_belief: a model world defaulting to the belief plays
/// them too, the twin never.
void add_identified_option(CLI::App& cmd, std::string& identified);

/// The delay from a coil command to the bat's first motion that a world
/// plays: `given_s` (--actuation-delay) when set; else, in a model world, the
/// overlay's identified actuation delay (table::identified_actuation_delay_s)
/// when `identified` has one; else the firmware's default. The twin never
/// takes the identified delay: it plays the coil's rise and the bat's inertia
/// itself, behind the driver's default delay.
double world_actuation_delay_s(std::optional<double> given_s, const simlab::WorldSpec& world,
                               const std::string& identified);

/// `identified`: the overlay laid over the belief, or null when the belief is
/// the board file alone, so that a reader of a report knows which belief played.
nlohmann::json identified_report(const std::string& identified);

/// The overlay as one text line ("identified       F (laid over the belief)"), empty without one.
std::string identified_text_line(const std::string& identified);

/// What a report says of the world it played: `world` (thesis, event or
/// twin), `world_board`, `stepper`, `twin_params` (twin only) and
/// `world_warnings` (penetration, instability, overflow: the twin's MuJoCo
/// warnings, counted over every ball its forks played).
nlohmann::json world_report(const simlab::WorldSpec& spec, const std::string& belief_board, const sim::World& world);

/// The report as one text line ("world            twin of B (P), 0 warnings"),
/// empty for the belief's own board on the thesis stepper.
std::string world_text_line(const nlohmann::json& report);

}  // namespace pinball::cli
