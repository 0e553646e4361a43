#include "pinball/core/yaml_read_archive.h"

#include <gtest/gtest.h>

#include <string>

#include "core/archive_test_types.h"

namespace pinball {
namespace {

using archive_test::Colour;
using archive_test::Everything;

Everything read(const std::string& yaml, ReadOptions options = {}) {
  Everything e;
  YamlReadArchive("t.yaml", options).read(load_yaml(yaml, "t.yaml"), "", &e);
  return e;
}

std::string error_of(const std::string& yaml, ReadOptions options = {}) {
  try {
    read(yaml, options);
  } catch (const KeyError& e) {
    return e.what();
  }
  return "";
}

TEST(YamlReadArchive, ReadsEveryKindOfField) {
  const Everything e = read(R"(
flag: true
count: -12
small: 255
big: -9223372036854775808
seed: 18446744073709551615
g_mps2: 1.11
name: table
colour: green
values: [3, 4.5, -1e-3]
triple: [7, 8, 9]
p_m: [0.1, 0.2]
inner: {x_m: 2.5, label: deep}
inners: [{x_m: 1}, {label: second}]
maybe: {x_m: 4}
)");
  EXPECT_TRUE(e.flag);
  EXPECT_EQ(e.count, -12);
  EXPECT_EQ(e.small, 255);
  EXPECT_EQ(e.big, INT64_MIN);
  EXPECT_EQ(e.seed, UINT64_MAX);
  EXPECT_EQ(e.g_mps2, 1.11);
  EXPECT_EQ(e.name, "table");
  EXPECT_EQ(e.colour, Colour::kGreen);
  EXPECT_EQ(e.values, (std::vector<double>{3.0, 4.5, -1e-3}));
  EXPECT_EQ(e.triple, (std::array<int, 3>{7, 8, 9}));
  EXPECT_EQ(e.p_m, Vec2(0.1, 0.2));
  EXPECT_EQ(e.inner.x_m, 2.5);
  EXPECT_EQ(e.inner.label, "deep");
  ASSERT_EQ(e.inners.size(), 2u);
  EXPECT_EQ(e.inners[0].x_m, 1.0);
  EXPECT_EQ(e.inners[0].label, "in");  // missing keys keep the struct's default
  EXPECT_EQ(e.inners[1].label, "second");
  ASSERT_TRUE(e.maybe);
  EXPECT_EQ(e.maybe->x_m, 4.0);
}

TEST(YamlReadArchive, MissingKeysKeepDefaultsUnlessRequired) {
  const Everything e = read("count: 4");
  EXPECT_EQ(e.count, 4);
  EXPECT_EQ(e.name, "default");
  EXPECT_FALSE(e.maybe);
  EXPECT_EQ(read("").count, 3);          // an empty file: every default
  EXPECT_EQ(read("inner:").inner.label, "in");  // an empty section too
  const ReadOptions strict{.refuse_unknown_keys = true, .require_every_key = true};
  EXPECT_EQ(error_of("count: 4", strict), "t.yaml:flag: missing");
  EXPECT_EQ(error_of(R"(
{flag: true, count: 1, small: 1, big: 1, seed: 1, g_mps2: 1, name: n, colour: red, values: [], triple: [1, 2, 3],
 p_m: [0, 0], inner: {x_m: 1}, inners: []})",
                     strict),
            "t.yaml:inner.label: missing");  // std::optional `maybe` may be absent
}

TEST(YamlReadArchive, UnknownKeysAreNamedUnlessAllowed) {
  EXPECT_EQ(error_of("cuont: 4"), "t.yaml:cuont: unknown key");
  EXPECT_EQ(error_of("inner: {x: 1}"), "t.yaml:inner.x: unknown key");
  EXPECT_EQ(error_of("inners: [{}, {lable: a}]"), "t.yaml:inners[1].lable: unknown key");
  EXPECT_EQ(read("cuont: 4", {.refuse_unknown_keys = false}).count, 3);
}

TEST(YamlReadArchive, RepeatedKeysAreRefused) {
  // yaml-cpp keeps both entries and find() answers the first: the file's
  // reader and this program would disagree on the value.
  EXPECT_EQ(error_of("count: 1\ncount: 2"), "t.yaml:count: duplicate key");
  EXPECT_EQ(error_of("inner: {x_m: 1, x_m: 2}"), "t.yaml:inner.x_m: duplicate key");
  EXPECT_EQ(error_of("inners: [{}, {label: a, label: b}]"), "t.yaml:inners[1].label: duplicate key");
  EXPECT_EQ(error_of("cuont: 1\ncuont: 2", {.refuse_unknown_keys = false}), "t.yaml:cuont: duplicate key");
}

TEST(YamlReadArchive, AFileHoldsOneDocument) {
  try {
    load_yaml("count: 1\n---\ncount: 2\n", "t.yaml");
    FAIL() << "a second document was accepted";
  } catch (const YamlSyntaxError& e) {
    EXPECT_EQ(e.key(), "3");  // the line where it starts
    EXPECT_EQ(e.message(), "not valid YAML: a second YAML document (after ---): a file holds one");
  }
  EXPECT_THROW(load_yaml("count: 1\n---\n", "t.yaml"), YamlSyntaxError);
  EXPECT_TRUE(load_yaml("", "t.yaml").IsNull());
  EXPECT_TRUE(load_yaml("# a comment only\n", "t.yaml").IsNull());
  EXPECT_EQ(read("---\ncount: 5\n...\n").count, 5);  // one document, marked out, is fine
}

// A file cut short after a section's name ("sim" on the last line) read as "sim:", an empty section:
// all defaults, and pinballd ran another game than its file's.
TEST(YamlReadArchive, ABareWordWhereAKeyNeedsItsColonIsRefused) {
  try {
    load_yaml("count: 1\ninner", "t.yaml");
    FAIL() << "a bare word was read as a key";
  } catch (const YamlSyntaxError& e) {
    EXPECT_EQ(e.key(), "2");
    EXPECT_EQ(e.message(),
              "not valid YAML: 'inner' has no ':' after it (a key is 'key: value'; is the file cut short?)");
  }
  EXPECT_THROW(load_yaml("outer:\n  count: 1\n  inner\n", "t.yaml"), YamlSyntaxError);
  // An empty section written as one, or a null value, stays what it was.
  EXPECT_EQ(read("inner:\ncount: 3\n").count, 3);
  EXPECT_EQ(read("count: 3\ninner: ~\n").count, 3);
  EXPECT_EQ(read("count: 3\ninner:   # nothing yet\n").count, 3);
  EXPECT_NO_THROW(load_yaml("list:\n  - a\n  - b:\n", "t.yaml"));
  EXPECT_NO_THROW(load_yaml("{a: , b: 1}\n", "t.yaml"));
}

TEST(YamlReadArchive, WrongTypesSayWhatWasExpected) {
  EXPECT_EQ(error_of("count: many"), "t.yaml:count: expected an integer (int32), got 'many' (line 1)");
  EXPECT_EQ(error_of("count: 2.5"), "t.yaml:count: expected an integer (int32), got '2.5' (line 1)");
  EXPECT_EQ(error_of("flag: 3"), "t.yaml:flag: expected true or false, got '3' (line 1)");
  EXPECT_EQ(error_of("g_mps2: fast"), "t.yaml:g_mps2: expected a number (double), got 'fast' (line 1)");
  EXPECT_EQ(error_of("name: [a]"), "t.yaml:name: expected text, got a list of 1 (line 1)");
  EXPECT_EQ(error_of("colour: blue"), "t.yaml:colour: expected red or green");
  EXPECT_EQ(error_of("values: 3"), "t.yaml:values: expected a list, got '3' (line 1)");
  EXPECT_EQ(error_of("values: [1, x]"), "t.yaml:values[1]: expected a number (double), got 'x' (line 1)");
  EXPECT_EQ(error_of("triple: [1, 2]"), "t.yaml:triple: expected a list of 3, got a list of 2 (line 1)");
  EXPECT_EQ(error_of("p_m: [1, 2, 3]"), "t.yaml:p_m: expected a list of 2, got a list of 3 (line 1)");
  EXPECT_EQ(error_of("inner: 5"), "t.yaml:inner: expected a mapping, got '5' (line 1)");
  EXPECT_EQ(error_of("inners: [{x_m: y}]"), "t.yaml:inners[0].x_m: expected a number (double), got 'y' (line 1)");
  EXPECT_EQ(error_of("[1, 2]"), "t.yaml:(top): expected a mapping, got a list of 2 (line 1)");
}

TEST(YamlReadArchive, AWrongTypeNamesItsLine) {
  EXPECT_EQ(error_of("count: 3\n\n# a comment\ng_mps2: fast\n"),
            "t.yaml:g_mps2: expected a number (double), got 'fast' (line 4)");
  EXPECT_EQ(error_of("inner:\n  label: a\n  x_m:\n    - 2\n"),
            "t.yaml:inner.x_m: expected a number (double), got a list of 1 (line 4)");
  EXPECT_EQ(error_of("name: ~"), "t.yaml:name: expected text, got nothing (line 1)");
}

TEST(YamlReadArchive, IntegersThatDoNotFitAreRefusedNotTruncated) {
  EXPECT_EQ(error_of("small: 256"), "t.yaml:small: expected an integer in [0, 255], got '256' (line 1)");
  EXPECT_EQ(error_of("small: -1"), "t.yaml:small: expected an integer in [0, 255], got '-1' (line 1)");
  EXPECT_EQ(error_of("count: 2147483648"), "t.yaml:count: expected an integer in [-2147483648, 2147483647], got '2147483648' (line 1)");
  EXPECT_EQ(error_of("big: 9223372036854775808"),
            "t.yaml:big: expected an integer in [-9223372036854775808, 9223372036854775807], got '9223372036854775808' (line 1)");
  EXPECT_EQ(error_of("seed: 18446744073709551616"), "t.yaml:seed: expected an integer in [0, 18446744073709551615], got '18446744073709551616' (line 1)");
  EXPECT_EQ(error_of("seed: -1"), "t.yaml:seed: expected an integer in [0, 18446744073709551615], got '-1' (line 1)");
}

TEST(YamlReadArchive, NonFiniteNumbersAreRefused) {
  EXPECT_EQ(error_of("g_mps2: .nan"), "t.yaml:g_mps2: expected a finite number (double), got '.nan' (line 1)");
  EXPECT_EQ(error_of("g_mps2: .inf"), "t.yaml:g_mps2: expected a finite number (double), got '.inf' (line 1)");
  EXPECT_EQ(error_of("values: [1, -.inf]"),
            "t.yaml:values[1]: expected a finite number (double), got '-.inf' (line 1)");
}

TEST(YamlReadArchive, ErrorsCarryFileKeyAndMessageApart) {
  try {
    read("inner: {x_m: no}");
    FAIL();
  } catch (const KeyError& e) {
    EXPECT_EQ(e.file(), "t.yaml");
    EXPECT_EQ(e.key(), "inner.x_m");
    EXPECT_EQ(e.message(), "expected a number (double), got 'no' (line 1)");
  }
  try {
    load_yaml("a: [1", "t.yaml");
    FAIL();
  } catch (const YamlSyntaxError& e) {
    EXPECT_EQ(e.key(), "1");  // the line
  }
}

}  // namespace
}  // namespace pinball
