#pragma once
// The check of user input (style.md's third level, after Drake's
// DRAKE_THROW_UNLESS): settings and files that are wrong throw
// std::invalid_argument naming what was wrong; every module uses this one
// helper. Our own invariants use assert(); the real-time loop never throws
// and reports with status values and counters.

#include <stdexcept>
#include <string>
#include <string_view>

namespace pinball {

/// Throws std::invalid_argument("<context>: <what>") unless `ok`.
inline void check_input(bool ok, std::string_view context, std::string_view what) {
  if (!ok) throw std::invalid_argument(std::string(context) + ": " + std::string(what));
}

}  // namespace pinball
