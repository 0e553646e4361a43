#pragma once
// Round numbers for axes and scale bars: ticks at 1, 2 or 5 times a power of
// ten, and labels that print them without trailing digits ("0.5", "1000",
// "2.5e-05" only when a fixed form would be too long).

#include <string>
#include <vector>

namespace pinball::plot {

/// The smallest step of 1, 2 or 5 times a power of ten that is at least `raw`
/// (raw > 0 and finite; throws std::invalid_argument otherwise).
double nice_step(double raw);

/// The largest length of 1, 2 or 5 times a power of ten that is at most `x`
/// (x > 0 and finite; throws std::invalid_argument otherwise): scale bars, arrow gains.
double round_at_most(double x);

/// At most `max_ticks` (>= 2) round, evenly spaced values whose first is <= lo
/// and last >= hi. A zero-width range is widened around its value. Throws
/// std::invalid_argument for a non-finite bound or max_ticks < 2.
std::vector<double> nice_ticks(double lo, double hi, int max_ticks = 6);

/// Powers of ten (as values) from the decade at or below lo to the one at or
/// above hi (lo, hi > 0), every k-th so that at most `max_ticks` remain.
/// Throws std::invalid_argument for non-positive or non-finite bounds.
std::vector<double> decade_ticks(double lo, double hi, int max_ticks = 8);

/// A tick value as text with as many decimals as `step` needs and no more
/// ("0.5", "1000", "-0.002"); exponent form below 1e-4 or from 1e6 ("2.5e-05").
std::string tick_label(double value, double step);

/// A power of ten as text: plain from 0.001 to 1000, else "1e-05".
std::string decade_label(double value);

}  // namespace pinball::plot
