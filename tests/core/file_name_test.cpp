// The extension as every writer and reader of pictures and videos judges it.

#include "pinball/core/file_name.h"

#include <gtest/gtest.h>

namespace pinball {
namespace {

TEST(FileName, TheExtensionIsComparedLowercase) {
  EXPECT_EQ(lowercase_extension("shot.PNG"), ".png");
  EXPECT_EQ(lowercase_extension("/runs/play.Avi"), ".avi");
  EXPECT_EQ(lowercase_extension("a.b/notes"), "");         // a dot in a folder is no extension
  EXPECT_EQ(lowercase_extension("curve.tar.GZ"), ".gz");   // the last one only
}

}  // namespace
}  // namespace pinball
