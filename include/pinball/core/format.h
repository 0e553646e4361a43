#pragma once
// Numbers in text output for people: a few significant digits, never a
// 17-digit double or an exponent ("9193 ± 5430", "0.0457", "1.23"). JSON
// keeps full precision; only the text reports go through here.

#include <string>

namespace pinball {

/// `x` to `digits` significant digits in fixed notation, trailing zeros
/// dropped; a number with more integer digits than that is rounded to an
/// integer ("9193", "12.3", "0.0457", "0.0005"); from 1e15 on, which only
/// a corrupt input reaches, `digits` digits with an exponent ("1e+100").
std::string format_number(double x, int digits = 3);

/// A mean and the half-width of its interval, both to the half-width's
/// place at 2 significant digits, the mean to at least `digits` ("9193 ± 5430", "1.24 ± 0.31");
/// an infinite half-width (one sample: no bound) is "812 ± ∞".
std::string format_mean_ci(double mean, double half_width, int digits = 3);

/// The shortest text that reads back as the same double ("0.1", "2.0000001",
/// "1e+300"): for files written to be read again, and for a refused value,
/// which rounding would hide ("at most 2, got 2").
std::string format_exact(double x);

}  // namespace pinball
