#pragma once
// The checks of number options, for both programs (`pinball`, `pinballd`).
// CLI11's own let two things through: CLI::Range and CLI::PositiveNumber
// compare, and every comparison with NaN is false, so `--max-ball-time nan`
// passed and ran a ball for ever; and an unsigned option takes "-1" as
// 2^64 - 1 and clamps what overflows. Their messages also print a bound of
// 1.8e308 with all its 309 digits. Header-only, like data_file_option.h.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <system_error>

#include <CLI/CLI.hpp>

namespace pinball {

namespace number_option_detail {

// A bound as a reader writes it: 1000000000, 0.0001, 1e-07.
inline std::string bound_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

/// A check that `text` is a finite number for which `ok` holds; `rule` ends
/// the message ("-1 is not > 0", "nan is not a finite number > 0") and is
/// the help's text.
template <class Ok>
CLI::Validator finite_number(Ok ok, const std::string& rule) {
  return CLI::Validator(
      [ok, rule](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return "'" + text + "' is not a number";
        if (!std::isfinite(v)) return text + " is not a finite number " + rule;
        // "-1 is not a finite number in [0, 1]" had read as if -1 were not finite.
        if (!ok(v)) return text + " is not " + rule;
        return "";
      },
      rule);
}

}  // namespace number_option_detail

/// A finite number in [min, max]: "0 is not in [1, 1000]".
inline CLI::Validator finite_range(double min, double max) {
  return number_option_detail::finite_number([min, max](double v) { return v >= min && v <= max; },
                                             "in [" + number_option_detail::bound_text(min) + ", " +
                                                 number_option_detail::bound_text(max) + "]");
}

/// 0, or a finite number in [min, max] ("0: none"): "1 is not 0 or in [2, 10000]"
/// (CLI11's IsMember | Range had said "(1 not in {0}) OR (1 is not in [2, 10000])").
inline CLI::Validator zero_or_range(double min, double max) {
  return number_option_detail::finite_number([min, max](double v) { return v == 0.0 || (v >= min && v <= max); },
                                             "0 or in [" + number_option_detail::bound_text(min) + ", " +
                                                 number_option_detail::bound_text(max) + "]");
}

/// A finite number > 0 (for CLI::PositiveNumber).
inline CLI::Validator finite_positive() {
  return number_option_detail::finite_number([](double v) { return v > 0.0; }, "> 0");
}

/// A finite number >= 0 (for CLI::NonNegativeNumber).
inline CLI::Validator finite_non_negative() {
  return number_option_detail::finite_number([](double v) { return v >= 0.0; }, ">= 0");
}

/// A whole number in [0, 2^64 - 1], written in decimal: a seed. Refuses "-1"
/// (which CLI11 would wrap to 2^64 - 1) and what does not fit (which it clamps).
inline CLI::Validator unsigned_64() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::uint64_t v = 0;
        const char* end = text.data() + text.size();
        const auto [at, ec] = std::from_chars(text.data(), end, v);
        if (ec == std::errc::result_out_of_range) {
          return text + " does not fit in 64 bits (at most 18446744073709551615)";
        }
        if (ec != std::errc() || at != end) return "'" + text + "' is not a whole number >= 0";
        return "";
      },
      "0..2^64-1");
}

}  // namespace pinball
