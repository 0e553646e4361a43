#pragma once
// The command-line face of find_data_file, for both programs: a board,
// controller or configuration option of `pinball` or `pinballd` takes a path
// that may name the shipped data from any folder, e.g.
// `pinballd --controller controllers/spastic.json` outside the source tree.
// Header-only, for the programs' main code, which links CLI11.

#include <string>

#include <CLI/CLI.hpp>

#include "pinball/core/data_path.h"

namespace pinball {

/// A transform for a file option: the path through find_data_file, which must then exist.
inline CLI::Validator data_file() {
  return CLI::Validator(
      [](std::string& path) {
        path = find_data_file(path);
        return CLI::ExistingFile(path);
      },
      "FILE");
}

}  // namespace pinball
