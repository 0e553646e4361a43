#include "pinball/core/writer_lock.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/temp_path.h"

namespace pinball {
namespace {

// Two pinballd runs writing one LCM log interleaved it into a damaged file, and both said all was
// recorded. flock(2) locks per open file: a second lock on the file, in this process too, is refused.
TEST(WriterLock, ASecondWriterOfOneFileIsRefusedUntilTheFirstLetsGo) {
  const std::string path = testing::temp_path("writer_lock", "run.lcm");
  std::filesystem::remove(path);
  {
    const WriterLock first(path);
    EXPECT_TRUE(std::filesystem::exists(path));  // created empty, so that the second finds it
    try {
      const WriterLock second(path);
      ADD_FAILURE() << "two writers of one file";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), path + " is being written by another process (another pinballd?): two "
                                              "writers would interleave their records into one damaged file");
    }
  }
  EXPECT_NO_THROW(WriterLock again(path));  // released with the first
  std::filesystem::remove(path);
}

TEST(WriterLock, NothingAPipeOrADeviceIsLocked) {
  EXPECT_NO_THROW(WriterLock none(""));
  const WriterLock a("/dev/null");
  EXPECT_NO_THROW(WriterLock b("/dev/null"));  // /dev/null's readers are nobody's business
  EXPECT_THROW(WriterLock missing_folder("/nonexistent/folder/run.lcm"), std::runtime_error);
}

}  // namespace
}  // namespace pinball
