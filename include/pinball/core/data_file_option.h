#pragma once
// The command-line face of find_data_file, for both programs: a board,
// controller or configuration option of `pinball` or `pinballd` takes a path
// that may name the shipped data from any folder, e.g.
// `pinballd --controller controllers/spastic.json` outside the source tree.
// Header-only, for the programs' main code, which links CLI11.

#include <filesystem>
#include <string>
#include <system_error>

#include <CLI/CLI.hpp>

#include "pinball/core/data_path.h"
#include "pinball/core/text_file.h"

namespace pinball {

/// Why `path`, an input, is not one to read: "" for a file or a pipe; a
/// device (/dev/zero, /dev/full) would be read for ever, or fail as no file.
inline std::string device_input_problem(const std::string& path) {
  const std::string problem = input_file_problem(path);
  return problem.empty() ? "" : path + " " + problem;
}

/// A check for an input file option: it must exist, and be no folder and no device.
inline CLI::Validator input_file() {
  return CLI::Validator(
      [](std::string& path) {
        const std::string missing = CLI::ExistingFile(path);
        return missing.empty() ? device_input_problem(path) : missing;
      },
      "FILE");
}

/// A check for an output file option: a value given must name a file. An
/// empty one (a script's unset variable) had meant "write nothing", silently.
inline CLI::Validator output_file() {
  return CLI::Validator(
      [](std::string& path) { return path.empty() ? std::string("an empty path names no file to write") : ""; },
      "FILE");
}

/// A check for an LCM URL option: a value given must name a provider. An empty
/// one (a script's unset variable) had quietly meant the default's.
inline CLI::Validator lcm_url_given() {
  return CLI::Validator(
      [](std::string& url) {
        return url.empty() ? std::string("an empty URL names no LCM provider (memq:// is the in-process one)") : "";
      },
      "URL");
}

/// A transform for a file option: the path through find_data_file, which must then be an input_file().
inline CLI::Validator data_file() {
  return CLI::Validator(
      [](std::string& path) {
        path = find_data_file(path);
        const std::string missing = CLI::ExistingFile(path);
        return missing.empty() ? device_input_problem(path) : missing;
      },
      "FILE");
}

}  // namespace pinball
