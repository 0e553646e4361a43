#pragma once
// The world flags shared by every command that plays a table (`pinball sim`,
// `pinball learn`, `pinball bench ceiling`): the world is given apart from the
// belief (the BOARD argument or --board), and defaults to it.

#include <CLI/CLI.hpp>

#include "pinball/simlab/world_factory.h"

namespace pinball::cli {

/// Adds --world-board, --stepper and --dt, writing into `world`.
void add_world_options(CLI::App& cmd, simlab::WorldSpec& world);

}  // namespace pinball::cli
