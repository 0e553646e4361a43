#pragma once
// What the commands' file options share: data_file(), the transform that
// finds the shipped data from any folder (pinball/core/data_file_option.h,
// as pinballd does), and the check that an output's folder exists.

#include <filesystem>
#include <stdexcept>
#include <string>

#include "pinball/core/data_file_option.h"
#include "pinball/plot/png_file.h"

namespace pinball::cli {

/// A file a command writes when it has finished: its folder must exist now,
/// and it must not be a folder itself, so that a long run (or a lab's flipper
/// fired twenty times) does not end in a write error. Throws
/// std::runtime_error "OPTION PATH: the folder F does not exist" or
/// "OPTION PATH: is a folder, not a file".
inline void check_output_folder(const std::string& path, const char* option) {
  if (path.empty()) return;
  if (std::filesystem::is_directory(path))
    throw std::runtime_error(std::string(option) + " " + path + ": is a folder, not a file");
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder))
    throw std::runtime_error(std::string(option) + " " + path + ": the folder " + folder.string() + " does not exist");
}

/// check_output_folder, and the writer's own check of the file's name
/// (its extension), its error prefixed with the option.
inline void check_named_output(const std::string& path, const char* option, void (*check_name)(const std::string&)) {
  check_output_folder(path, option);
  if (path.empty()) return;
  try {
    check_name(path);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(option) + " " + e.what());
  }
}

/// A picture: "OPTION PATH: a PNG is written; give the file name a .png extension".
inline void check_png_output(const std::string& path, const char* option) {
  check_named_output(path, option, plot::check_png_name);
}

}  // namespace pinball::cli
