#include "pinball/core/staged_file.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/temp_path.h"

namespace pinball {
namespace {

namespace fs = std::filesystem;

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A trace or a video cut short by a full disk had replaced a good one: the run writes beside it.
TEST(StagedFile, AnUncommittedRunLeavesTheOldFileAsItWasAndNoTemporary) {
  const std::string folder = testing::fresh_folder("staged_file_uncommitted").string();
  const std::string path = folder + "/trace.csv";
  std::ofstream(path) << "old\n";
  {
    const StagedFile staged(path);
    EXPECT_NE(staged.writing_path(), path);
    EXPECT_EQ(fs::path(staged.writing_path()).extension(), ".csv") << "OpenCV picks its container by it";
    EXPECT_EQ(fs::path(staged.writing_path()).parent_path(), fs::path(path).parent_path());  // a rename, no copy
    EXPECT_FALSE(fs::exists(staged.writing_path())) << "creates nothing";
    std::ofstream(staged.writing_path()) << "half";
  }
  EXPECT_EQ(read(path), "old\n");
  EXPECT_EQ(testing::entries(folder), 1u);
  fs::remove_all(folder);
}

TEST(StagedFile, ACommitPutsTheWholeFileInPlace) {
  const std::string path = testing::temp_path("staged_file", "video.avi");
  std::ofstream(path) << "old\n";
  StagedFile staged(path);
  std::ofstream(staged.writing_path()) << "new\n";
  staged.commit();
  EXPECT_EQ(read(path), "new\n");
  EXPECT_FALSE(fs::exists(staged.writing_path()));
  fs::remove(path);
}

TEST(StagedFile, ADeviceIsWrittenInPlace) {
  const StagedFile staged("/dev/null");
  EXPECT_EQ(staged.writing_path(), "/dev/null");
  const StagedFile none("");
  EXPECT_EQ(none.writing_path(), "");
}

TEST(StagedFile, ACommitThatCannotRenameNamesThePath) {
  const std::string folder = testing::temp_path("staged_file", "a_folder.csv");
  fs::remove_all(folder);
  std::string temporary;
  {
    StagedFile staged(folder);
    ASSERT_NE(staged.writing_path(), folder);
    temporary = staged.writing_path();
    std::ofstream(temporary) << "x";
    fs::create_directories(folder + "/inside");  // made during the run: a rename over it fails
    try {
      staged.commit();
      ADD_FAILURE() << "renamed over a folder";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(folder + ": cannot write (", 0), 0u) << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(temporary));
  fs::remove_all(folder);
}

// Ctrl-C during `sim --video` had left an AVI whose header said 0 frames: the handler removes the
// temporary and the process still dies of the signal.
TEST(StagedFile, ASignalRemovesTheTemporaryAndStillEndsTheProcess) {
  const std::string folder = testing::fresh_folder("staged_file_signal").string();
  const std::string path = folder + "/stopped.csv";
  const std::string writing = folder + "/stopped.partial";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const StagedFile staged(path);
    std::ofstream(staged.writing_path()) << "half";
    std::ofstream(path + ".name") << staged.writing_path();
    ::raise(SIGTERM);
    ::_exit(0);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  const std::string temporary = read(path + ".name");
  EXPECT_EQ(temporary.rfind(writing, 0), 0u) << temporary;
  EXPECT_FALSE(fs::exists(temporary));
  EXPECT_FALSE(fs::exists(path));
  fs::remove_all(folder);
}

}  // namespace
}  // namespace pinball
