#pragma once
// What the commands' file options share: data_file(), the transform that
// finds the shipped data from any folder (pinball/core/data_file_option.h,
// as pinballd does), and the check that an output's folder exists.

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pinball/core/data_file_option.h"
#include "pinball/core/text_file.h"
#include "pinball/plot/png_file.h"

namespace pinball::cli {

/// A file a command writes when it has finished: its folder must exist now
/// and take a new file, and it must not be a folder itself, so that a long
/// run (or a lab's flipper fired twenty times) does not end in a write
/// error. A file written whole (write_text_file: renamed into place) must
/// not be a device or a pipe either, which the rename would replace;
/// `streamed` outputs (a trace) may be. Throws std::runtime_error "OPTION
/// PATH: the folder F does not exist", "OPTION PATH: is a folder, not a
/// file", "OPTION PATH: is not a regular file ..." or "OPTION PATH: cannot
/// write in F (why)".
inline void check_output_folder(const std::string& path, const char* option, bool streamed = false) {
  namespace fs = std::filesystem;
  if (path.empty()) return;
  const std::string said = std::string(option) + " " + path;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw std::runtime_error(said + ": is a folder, not a file");
  const fs::path folder = fs::path(path).parent_path();
  if (!folder.empty() && !fs::is_directory(folder, ec))
    throw std::runtime_error(said + ": the folder " + folder.string() + " does not exist");
  if (fs::exists(path, ec)) {
    if (!streamed && !fs::is_regular_file(path, ec)) {
      throw std::runtime_error(said + ": is not a regular file (a device, a pipe); it would be replaced by the file "
                                      "written, so it is refused");
    }
    return;
  }
  // The folder takes a new file (not /proc, not a read-only mount): a probe, made and removed.
  const fs::path probe = (folder.empty() ? fs::path(".") : folder) / (".pinball-probe-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    // ENOENT in a folder that exists: a file system that makes no files (/proc), not a missing folder.
    const std::string why = errno == ENOENT ? "its file system takes no new files" : std::strerror(errno);
    throw std::runtime_error(said + ": cannot write in " + (folder.empty() ? std::string(".") : folder.string()) +
                             " (" + why + ")");
  }
  ::close(fd);
  fs::remove(probe, ec);
}

/// Outputs of one command that name the same file would overwrite each
/// other: refused, naming both options.
inline void check_distinct_outputs(const std::vector<std::pair<const char*, std::string>>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (std::size_t k = i + 1; k < outputs.size(); ++k) {
      const std::string& a = outputs[i].second;
      const std::string& b = outputs[k].second;
      if (a.empty() || b.empty()) continue;
      if (same_written_file(a, b)) {  // the path, a link (made or not yet) or a hard link
        throw std::runtime_error(std::string(outputs[i].first) + " and " + outputs[k].first + " both name " + a +
                                 ": each would overwrite the other");
      }
    }
  }
}

/// An output that is one of the inputs (the same path, a link or a hard link)
/// would replace it: refused, "OUT-OPTION PATH is the input IN-OPTION PATH;
/// it would be replaced". Empty paths are options not given.
inline void check_outputs_replace_no_input(const std::vector<std::pair<const char*, std::string>>& outputs,
                                           const std::vector<std::pair<const char*, std::string>>& inputs) {
  for (const auto& [out_option, out] : outputs) {
    for (const auto& [in_option, in] : inputs) {
      if (out.empty() || in.empty() || !same_file(out, in)) continue;
      throw std::runtime_error(std::string(out_option) + " " + out + " is the input " + in_option + " " + in +
                               "; it would be replaced");
    }
  }
}

/// One file given twice to an option that takes many (the same path, a link
/// or a hard link, or a copy of its bytes) would count its data twice and
/// narrow every interval: refused, "OPTION PATH is given twice: WHY" or
/// "OPTION PATH is a copy of OTHER: WHY".
inline void check_distinct_inputs(const std::vector<std::string>& paths, const char* option, const char* why) {
  for (std::size_t i = 0; i < paths.size(); ++i) {
    for (std::size_t k = i + 1; k < paths.size(); ++k) {
      if (same_file(paths[i], paths[k])) {
        throw std::runtime_error(std::string(option) + " " + paths[k] + " is given twice: " + why);
      }
      if (same_contents(paths[i], paths[k])) {
        throw std::runtime_error(std::string(option) + " " + paths[k] + " is a copy of " + paths[i] + ": " + why);
      }
    }
  }
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
