#pragma once
// The project's one way to read a whole text file (configuration, calibration,
// overlay, randomization): its bytes, or an error naming the file.

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace pinball {

/// The whole file at `path`. Throws std::runtime_error "path: cannot open"
/// or "path: cannot read".
inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw std::runtime_error(path + ": cannot read");
  return s.str();
}

}  // namespace pinball
