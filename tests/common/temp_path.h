#pragma once
// A file name in gtest's temporary folder, unique to this process and test file.

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace pinball::testing {

/// TempDir()/<prefix>_<pid>_<name>.
inline std::string temp_path(const std::string& prefix, const std::string& name) {
  return ::testing::TempDir() + "/" + prefix + "_" + std::to_string(::getpid()) + "_" + name;
}

/// TempDir()/<name>_<pid>, emptied and created: a folder whose entries a test can count.
inline std::filesystem::path fresh_folder(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / (name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// How many entries `dir` holds (no temporary left beside the files named).
inline std::size_t entries(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace pinball::testing
