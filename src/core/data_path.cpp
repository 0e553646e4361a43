#include "pinball/core/data_path.h"

#include <filesystem>
#include <system_error>

#ifndef PINBALL_SOURCE_DIR_FOR_DATA
#error "PINBALL_SOURCE_DIR_FOR_DATA must name the source tree (CMakeLists.txt sets it)"
#endif
#ifndef PINBALL_INSTALL_DATA_SUBDIR
#error "PINBALL_INSTALL_DATA_SUBDIR must name <prefix>-relative data folder (CMakeLists.txt sets it)"
#endif

namespace pinball {

namespace fs = std::filesystem;

std::vector<std::string> data_dirs() {
  std::vector<std::string> dirs;
  std::error_code ec;
  // The installed copy: bin/pinball -> share/pinball, whatever the prefix was.
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / PINBALL_INSTALL_DATA_SUBDIR;
    if (fs::is_directory(installed, ec)) dirs.push_back(installed.string());
  }
  const fs::path source = PINBALL_SOURCE_DIR_FOR_DATA;
  if (fs::is_directory(source, ec)) dirs.push_back(source.string());
  return dirs;
}

std::string find_data_file(const std::string& path) {
  std::error_code ec;
  if (path.empty() || path.front() == '/' || fs::exists(path, ec)) return path;
  for (const std::string& dir : data_dirs()) {
    const fs::path candidate = fs::path(dir) / path;
    if (fs::exists(candidate, ec)) return candidate.string();
  }
  return path;
}

}  // namespace pinball
