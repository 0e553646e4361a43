#include "pinball/core/yaml_write_archive.h"

#include <gtest/gtest.h>

#include "core/archive_test_types.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/yaml_read_archive.h"

namespace pinball {
namespace {

using archive_test::Colour;
using archive_test::Everything;
using archive_test::Inner;

Everything yaml_sample() {
  Everything e;
  e.flag = true;
  e.small = 200;
  e.seed = UINT64_MAX;
  e.g_mps2 = 1.0 / 3.0;
  e.name = "null";  // text YAML would read as null
  e.colour = Colour::kGreen;
  e.inners = {Inner{2.0, "a"}, Inner{0.1, ""}};
  e.maybe = Inner{3.0, "b"};
  return e;
}

Everything yaml_read_back(const std::string& text) {
  Everything e;
  YamlReadArchive("t.yaml", {.refuse_unknown_keys = true, .require_every_key = true})
      .read(load_yaml(text, "t.yaml"), "", &e);
  return e;
}

TEST(YamlWriteArchive, ReadsBackWhatWasWrittenBitForBit) {
  const Everything a = yaml_sample();
  const Everything b = yaml_read_back(to_yaml_text(a));
  EXPECT_EQ(to_json_value(b), to_json_value(a));
  EXPECT_EQ(b.g_mps2, 1.0 / 3.0);
  EXPECT_EQ(b.name, "null");
  EXPECT_EQ(b.inners[1].label, "");
}

TEST(YamlWriteArchive, KeysInSerializeOrderNumbersShort) {
  Everything e;
  e.g_mps2 = 0.6;
  const std::string text = to_yaml_text(e);
  EXPECT_LT(text.find("flag:"), text.find("count:"));
  EXPECT_LT(text.find("inner:"), text.find("inners:"));
  EXPECT_NE(text.find("g_mps2: 0.6\n"), std::string::npos) << text;
  EXPECT_NE(text.find("values: [1, 2]"), std::string::npos) << text;
  EXPECT_EQ(text.find("maybe"), std::string::npos) << "an empty optional writes no key";
}

}  // namespace
}  // namespace pinball
