// The number options' checks: what CLI11's own let through (NaN, infinity,
// a negative or overflowing seed) is refused with a message a person reads.

#include "pinball/core/number_option.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace pinball {
namespace {

// Parses `--x VALUE` into `value` under `check`; "" when accepted, else the error.
template <class T>
std::string parse(const CLI::Validator& check, const std::string& text, T& value) {
  CLI::App app;
  app.add_option("--x", value)->check(check);
  std::vector<std::string> args{text, "--x"};  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(NumberOption, ARangeRefusesNanAndInfinityAndSaysItsBoundsPlainly) {
  double v = -1.0;
  EXPECT_EQ(parse(finite_range(0.0, 1e9), "2.5", v), "");
  EXPECT_EQ(v, 2.5);
  EXPECT_EQ(parse(finite_range(0.0, 1e9), "nan", v), "--x: nan is not a finite number in [0, 1000000000]");
  EXPECT_EQ(parse(finite_range(0.0, 1e9), "inf", v), "--x: inf is not a finite number in [0, 1000000000]");
  EXPECT_EQ(parse(finite_range(1e-7, 1.0), "0", v), "--x: 0 is not in [1e-07, 1]");
  EXPECT_EQ(parse(finite_range(0.0, 1.0), "abc", v), "--x: 'abc' is not a number");
  int n = 0;
  EXPECT_EQ(parse(finite_range(1, 100'000'000), "100000000", n), "");
  EXPECT_EQ(n, 100'000'000);
  EXPECT_NE(parse(finite_range(1, 100'000'000), "1.5", n), "") << "an integer option still takes only integers";
}

TEST(NumberOption, PositiveAndNonNegativeRefuseNanAndInfinity) {
  double v = 0.0;
  EXPECT_EQ(parse(finite_positive(), "0.5", v), "");
  for (const char* bad : {"0", "-1"}) {
    EXPECT_EQ(parse(finite_positive(), bad, v), std::string("--x: ") + bad + " is not > 0");
  }
  for (const char* bad : {"nan", "-nan", "inf"}) {
    EXPECT_EQ(parse(finite_positive(), bad, v), std::string("--x: ") + bad + " is not a finite number > 0");
  }
  EXPECT_EQ(parse(finite_non_negative(), "0", v), "");
  EXPECT_EQ(parse(finite_non_negative(), "nan", v), "--x: nan is not a finite number >= 0");
  EXPECT_EQ(parse(finite_non_negative(), "-0.1", v), "--x: -0.1 is not >= 0");
}

// --bootstrap: 0 (none) or 2..10000. CLI11's IsMember | Range said "(1 not in {0}) OR (1 is not in [2, 10000])".
TEST(NumberOption, ZeroOrARangeSaysBothInOnePhrase) {
  int v = -1;
  EXPECT_EQ(parse(zero_or_range(2, 10000), "0", v), "");
  EXPECT_EQ(v, 0);
  EXPECT_EQ(parse(zero_or_range(2, 10000), "50", v), "");
  EXPECT_EQ(parse(zero_or_range(2, 10000), "1", v), "--x: 1 is not 0 or in [2, 10000]");
  EXPECT_EQ(parse(zero_or_range(2, 10000), "abc", v), "--x: 'abc' is not a number");
}

TEST(NumberOption, ASeedIsAWholeNumberThatFitsIn64Bits) {
  std::uint64_t seed = 0;
  EXPECT_EQ(parse(unsigned_64(), "18446744073709551615", seed), "");
  EXPECT_EQ(seed, UINT64_MAX);
  EXPECT_EQ(parse(unsigned_64(), "-1", seed), "--x: '-1' is not a whole number >= 0") << "CLI11 wrapped it to 2^64 - 1";
  EXPECT_EQ(parse(unsigned_64(), "18446744073709551616", seed),
            "--x: 18446744073709551616 does not fit in 64 bits (at most 18446744073709551615)")
      << "CLI11 clamped it";
  EXPECT_EQ(parse(unsigned_64(), "7x", seed), "--x: '7x' is not a whole number >= 0");
  EXPECT_EQ(parse(unsigned_64(), "1e3", seed), "--x: '1e3' is not a whole number >= 0");
}

}  // namespace
}  // namespace pinball
