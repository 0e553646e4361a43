// The shipped data is found from any folder, as pinball and pinballd need it.

#include "pinball/core/data_path.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <unistd.h>

#include <gtest/gtest.h>

namespace pinball {
namespace {

namespace fs = std::filesystem;

// Runs the test body in an empty temporary folder, then goes back.
class FromElsewhere : public ::testing::Test {
 protected:
  void SetUp() override {
    back_ = fs::current_path();
    dir_ = fs::temp_directory_path() / ("pinball_data_path_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    fs::current_path(dir_);
  }
  void TearDown() override {
    fs::current_path(back_);
    fs::remove_all(dir_);
  }
  fs::path back_, dir_;
};

TEST_F(FromElsewhere, FindsTheShippedBoardInTheSourceTree) {
  ASSERT_FALSE(fs::exists("boards/mit1993.board"));
  const std::string found = find_data_file("boards/mit1993.board");
  EXPECT_EQ(fs::path(found), fs::path(PINBALL_SOURCE_DIR) / "boards/mit1993.board");
  EXPECT_TRUE(fs::exists(found));
}

TEST_F(FromElsewhere, AFileHereWinsOverTheShippedOne) {
  fs::create_directories("boards");
  { std::FILE* f = std::fopen("boards/mit1993.board", "w"); std::fclose(f); }
  EXPECT_EQ(find_data_file("boards/mit1993.board"), "boards/mit1993.board");
}

TEST_F(FromElsewhere, AbsentAndAbsolutePathsComeBackAsTyped) {
  EXPECT_EQ(find_data_file("boards/no_such.board"), "boards/no_such.board");
  EXPECT_EQ(find_data_file("/nowhere/x.board"), "/nowhere/x.board");
  EXPECT_EQ(find_data_file(""), "");
}

TEST(DataDirs, ListTheSourceTreeOfABuildTreeProgram) {
  const auto dirs = data_dirs();
  ASSERT_FALSE(dirs.empty());
  EXPECT_EQ(fs::path(dirs.back()), fs::path(PINBALL_SOURCE_DIR));
}

}  // namespace
}  // namespace pinball
