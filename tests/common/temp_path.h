#pragma once
// A file name in gtest's temporary folder, unique to this process and test file.

#include <unistd.h>

#include <string>

#include <gtest/gtest.h>

namespace pinball::testing {

/// TempDir()/<prefix>_<pid>_<name>.
inline std::string temp_path(const std::string& prefix, const std::string& name) {
  return ::testing::TempDir() + "/" + prefix + "_" + std::to_string(::getpid()) + "_" + name;
}

}  // namespace pinball::testing
