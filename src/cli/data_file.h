#pragma once
// Board, controller and configuration options take a path that may name the
// shipped data from any folder (pinball/core/data_path.h), as pinballd does:
// `pinball sim boards/mit1993.board` works outside the source tree too.

#include <string>

#include <CLI/CLI.hpp>

#include "pinball/core/data_path.h"

namespace pinball::cli {

/// A transform for a file option: the path through find_data_file, which must then exist.
inline CLI::Validator data_file() {
  return CLI::Validator(
      [](std::string& path) {
        path = find_data_file(path);
        return CLI::ExistingFile(path);
      },
      "FILE");
}

}  // namespace pinball::cli
