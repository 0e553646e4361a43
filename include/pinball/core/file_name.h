#pragma once
// A file name's extension as the writers and readers judge it: ".PNG" is ".png".

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace pinball {

/// The extension of `path` with its dot, lowercase ("shot.PNG" -> ".png"; none: "").
inline std::string lowercase_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace pinball
