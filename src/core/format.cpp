#include "pinball/core/format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace pinball {

namespace {

// The magnitude from which format_number writes an exponent.
constexpr double kLargestFixed = 1e15;

// Decimals that give `digits` significant digits for |x|, at least 0.
int decimals_for(double x, int digits) {
  if (x == 0.0 || !std::isfinite(x)) return 0;
  const int magnitude = static_cast<int>(std::floor(std::log10(std::fabs(x))));
  return std::clamp(digits - 1 - magnitude, 0, 12);
}

std::string fixed(double x, int decimals) {
  if (!std::isfinite(x)) return std::isnan(x) ? "nan" : (x > 0 ? "inf" : "-inf");
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
  std::string s = buf;
  // A negative number rounded to zero prints as zero, not "-0".
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

}  // namespace

std::string format_number(double x, int digits) {
  // Past 15 integer digits a fixed number is noise to a reader (1e100 had printed 101 digits).
  if (std::isfinite(x) && std::fabs(x) >= kLargestFixed) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*g", std::clamp(digits, 1, 17), x);
    return buf;
  }
  // 9.996 at 3 digits rounds to 10.0, which has one decimal fewer than 9.996 needs.
  int d = decimals_for(x, digits);
  const double rounded = std::round(x * std::pow(10.0, d)) / std::pow(10.0, d);
  d = decimals_for(rounded, digits);
  std::string s = fixed(x, d);
  // No trailing zeros after the point: "0.0005", not "0.000500"; "10", not "10.0".
  if (s.find('.') != std::string::npos) {
    s.erase(s.find_last_not_of('0') + 1);
    if (s.back() == '.') s.pop_back();
  }
  return s;
}

std::string format_mean_ci(double mean, double half_width, int digits) {
  if (!std::isfinite(half_width)) return format_number(mean, digits) + " ± ∞";
  if (!(half_width > 0.0)) return format_number(mean, digits) + " ± 0";
  if (std::fabs(mean) >= kLargestFixed || half_width >= kLargestFixed) {
    return format_number(mean, digits) + " ± " + format_number(half_width, 2);
  }
  const int d = decimals_for(half_width, 2);
  return fixed(mean, d) + " ± " + fixed(half_width, d);
}

std::string format_exact(double x) {
  char buf[32];  // the longest double, -2.2250738585072014e-308, is 24 characters
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

}  // namespace pinball
