#include "pinball/core/json_text.h"

#include <gtest/gtest.h>

namespace pinball {
namespace {

TEST(JsonText, IndentsAsDumpDoes) {
  const nlohmann::json j{{"a", 1}, {"b", {2, 3}}};
  EXPECT_EQ(json_text(j), j.dump());
  EXPECT_EQ(json_text(j, 2), j.dump(2));
}

// A Latin-1 file name ("caf\xe9.board") made dump() throw type_error.316 after the run: the report was lost.
TEST(JsonText, AStringThatIsNotUtf8IsWrittenWithReplacementCharacters) {
  const nlohmann::json j{{"board", "boards/caf\xe9.board"}};
  std::string text;
  ASSERT_NO_THROW(text = json_text(j));
  EXPECT_EQ(text, "{\"board\":\"boards/caf\xef\xbf\xbd.board\"}");  // U+FFFD
  EXPECT_EQ(nlohmann::json::parse(text).at("board"), "boards/caf\xef\xbf\xbd.board");
}

}  // namespace
}  // namespace pinball
