// The one reader and writer of whole text files: a write is all or nothing.

#include "pinball/core/text_file.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "common/temp_path.h"

namespace pinball {
namespace {

namespace fs = std::filesystem;

using testing::entries;
using testing::fresh_folder;

TEST(TextFile, WritesWholeAndReadsBack) {
  const fs::path dir = fresh_folder("text_file_write");
  const std::string path = (dir / "a.json").string();
  write_text_file(path, "first\n");
  write_text_file(path, "second, longer\n");
  EXPECT_EQ(read_text_file(path), "second, longer\n");
  EXPECT_EQ(entries(dir), 1u);
  fs::remove_all(dir);
}

TEST(TextFile, AWriteThatFailsLeavesTheOldFileAndNoTemporary) {
  const fs::path dir = fresh_folder("text_file_fail");
  // The rename fails: a folder stands where the file would go.
  const fs::path folder = dir / "controller.json";
  fs::create_directories(folder / "inside");
  EXPECT_THROW(write_text_file(folder.string(), "x\n"), std::runtime_error);
  EXPECT_TRUE(fs::is_directory(folder / "inside"));
  EXPECT_EQ(entries(dir), 1u) << "the temporary was removed";
  // The temporary cannot be created: its folder does not exist.
  try {
    write_text_file((dir / "nowhere" / "c.json").string(), "x\n");
    ADD_FAILURE() << "a write into a missing folder succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir / "nowhere" / "c.json").string() + ": cannot write (No such file or directory)");
  }
  fs::remove_all(dir);
}

// `--out /dev/null` (or /dev/full, a pipe): the rename would have put a file
// where the device was. Refused, the device untouched.
TEST(TextFile, AWriteOverSomethingThatIsNoFileIsRefused) {
  const fs::path dir = fresh_folder("text_file_device");
  const fs::path fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    write_text_file(fifo.string(), "x\n");
    ADD_FAILURE() << "a pipe was replaced";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(fifo.string() + ": is not a regular file"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(entries(dir), 1u);
  EXPECT_THROW(write_text_file("/dev/null", "x\n"), std::runtime_error);
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  fs::remove_all(dir);
}

// What a write reaches: a hard link, or a link to a file not made yet, is the file it names.
TEST(TextFile, TheFileAWriteReachesIsFoundThroughLinks) {
  const fs::path dir = fresh_folder("text_file_links");
  write_text_file((dir / "a.txt").string(), "a");
  fs::create_hard_link(dir / "a.txt", dir / "hard.txt");
  fs::create_symlink("later.txt", dir / "dangling.txt");
  EXPECT_TRUE(same_written_file((dir / "a.txt").string(), (dir / "hard.txt").string()));
  EXPECT_TRUE(same_written_file((dir / "dangling.txt").string(), (dir / "later.txt").string()));
  EXPECT_TRUE(same_written_file((dir / "a.txt").string(), (dir / "." / "a.txt").string()));
  EXPECT_FALSE(same_written_file((dir / "a.txt").string(), (dir / "later.txt").string()));
  EXPECT_FALSE(same_written_file("", ""));
  EXPECT_EQ(write_target((dir / "dangling.txt").string()), dir / "later.txt");
}

TEST(TextFile, ReadingAMissingFileNamesIt) {
  try {
    read_text_file("/nonexistent/pinball.yaml");
    ADD_FAILURE() << "a missing file was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/pinball.yaml: cannot open");
  }
}

// pinballd's `controller: /dev/zero` was read until memory ran out (std::bad_alloc after 1 GB).
TEST(TextFile, ADeviceOrAFolderIsNamedNotRead) {
  try {
    read_text_file("/dev/zero");
    ADD_FAILURE() << "a device was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/zero: is a device, not a file");
  }
  EXPECT_EQ(input_file_problem("/dev/null"), "is a device, not a file");
  EXPECT_EQ(input_file_problem("/tmp"), "is a folder, not a file");
  EXPECT_EQ(input_file_problem("/nonexistent/pinball.yaml"), "");  // opening it says so
}

}  // namespace
}  // namespace pinball
