#pragma once
// Board, controller and configuration options take a path that may name the
// shipped data from any folder (pinball/core/data_path.h), as pinballd does:
// `pinball sim boards/mit1993.board` works outside the source tree too.

#include <filesystem>
#include <stdexcept>
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

/// A file a command writes when it has finished: its folder must exist now,
/// so that a long run does not end in a write error. Throws
/// std::runtime_error "OPTION PATH: the folder F does not exist".
inline void check_output_folder(const std::string& path, const char* option) {
  if (path.empty()) return;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder))
    throw std::runtime_error(std::string(option) + " " + path + ": the folder " + folder.string() + " does not exist");
}

}  // namespace pinball::cli
