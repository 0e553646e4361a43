#include "pinball/core/json_write_archive.h"

#include <gtest/gtest.h>

#include "core/archive_test_types.h"
#include "pinball/core/json_read_archive.h"

namespace pinball {
namespace {

using archive_test::Colour;
using archive_test::Everything;
using archive_test::Inner;
using nlohmann::json;

Everything sample() {
  Everything e;
  e.flag = true;
  e.small = 200;
  e.seed = UINT64_MAX;
  e.g_mps2 = 1.0 / 3.0;
  e.colour = Colour::kGreen;
  e.inners = {Inner{2.0, "a"}};
  e.maybe = Inner{3.0, "b"};
  return e;
}

TEST(JsonWriteArchive, WritesEveryFieldUnderItsName) {
  const json j = to_json_value(sample());
  EXPECT_EQ(j, json::parse(R"({
    "flag": true, "count": 3, "small": 200, "big": -5, "seed": 18446744073709551615,
    "g_mps2": 0.3333333333333333, "name": "default", "colour": "green", "values": [1.0, 2.0],
    "triple": [1, 2, 3], "p_m": [0.5, 0.25], "inner": {"x_m": 1.5, "label": "in"},
    "inners": [{"x_m": 2.0, "label": "a"}], "maybe": {"x_m": 3.0, "label": "b"}})"));
  EXPECT_TRUE(j["small"].is_number_unsigned());
  EXPECT_TRUE(j["count"].is_number_integer());
}

TEST(JsonWriteArchive, AnEmptyOptionalWritesNoKey) {
  EXPECT_FALSE(to_json_value(Everything{}).contains("maybe"));
}

TEST(JsonReadArchive, ReadsBackWhatWasWritten) {
  const json j = to_json_value(sample());
  Everything e;
  JsonReadArchive("t.json").read(&j, "", &e);
  EXPECT_EQ(to_json_value(e), j);
  EXPECT_EQ(e.g_mps2, 1.0 / 3.0);  // bit for bit
}

TEST(JsonReadArchive, TypesAreTheDocumentsOwn) {
  auto error_of = [](const std::string& text) -> std::string {
    const json j = json::parse(text);
    Everything e;
    try {
      JsonReadArchive("t.json").read(&j, "", &e);
    } catch (const KeyError& k) {
      return k.what();
    }
    return "";
  };
  EXPECT_EQ(error_of(R"({"count": "3"})"), "t.json:count: expected an integer (int32), got text '3'");
  EXPECT_EQ(error_of(R"({"count": 3.5})"), "t.json:count: expected an integer (int32), got 3.5");
  EXPECT_EQ(error_of(R"({"small": 256})"), "t.json:small: expected an integer in [0, 255], got 256");
  EXPECT_EQ(error_of(R"({"seed": -1})"), "t.json:seed: expected an integer in [0, 18446744073709551615], got -1");
  EXPECT_EQ(error_of(R"({"flag": 1})"), "t.json:flag: expected true or false, got 1");
  EXPECT_EQ(error_of(R"({"inner": {"lable": "x"}})"), "t.json:inner.lable: unknown key");
  EXPECT_EQ(error_of(R"({"g_mps2": null})"), "t.json:g_mps2: expected a number (double), got null");
  EXPECT_EQ(error_of(R"({"count": 4})"), "");
}

TEST(JsonReadArchive, ParseJsonRefusesWhatNlohmannWouldResolveSilently) {
  auto error_of = [](const std::string& text) -> std::string {
    try {
      (void)parse_json(text, "t.json");
    } catch (const KeyError& k) {
      return k.what();
    }
    return "";
  };
  // nlohmann keeps the last of two equal keys; a reader of the file cannot tell which counts.
  EXPECT_EQ(error_of(R"({"count": 1, "count": 2})"), "t.json:count: duplicate key");
  EXPECT_EQ(error_of(R"({"inner": {"x_m": 1, "x_m": 1}})"), "t.json:inner.x_m: duplicate key");
  EXPECT_EQ(error_of(R"({"inners": [{}, [3, {"a": 1}], {"label": "a", "label": "b"}]})"),
            "t.json:inners[2].label: duplicate key");
  EXPECT_EQ(error_of(R"({"a": {"b": 1}, "c": {"b": 2}})"), "");  // the same key in two objects is fine
  // A number past a double's range is nlohmann's out_of_range, not a parse error.
  EXPECT_EQ(error_of(R"({"g_mps2": 1e400})").rfind("t.json:(file): not valid JSON: ", 0), 0u);
  EXPECT_NE(error_of("{\"count\": 1,\n \"x\": }").find("line 2"), std::string::npos);
  // Where and what, without nlohmann's "[json.exception.parse_error.101]" tag.
  EXPECT_EQ(error_of(""), "t.json:(file): not valid JSON: parse error at line 1, column 1: syntax error while parsing "
                          "value - unexpected end of input; expected '[', '{', or a literal");
  EXPECT_EQ(error_of(R"({"g_mps2": 1e400})"), "t.json:(file): not valid JSON: number overflow parsing '1e400'");
}

}  // namespace
}  // namespace pinball
