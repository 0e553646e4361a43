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

/// A setting outside its range, as a range check found it: one check serves
/// a constructor (which throws with check_input) and a file reader (which
/// names file:key). An empty key means every setting is in range.
struct RangeViolation {
  std::string key;   ///< the setting as files spell it ("angle_scale_rad")
  std::string rule;  ///< what it must be ("must be in [0.001, 3.14159] rad")
  explicit operator bool() const { return !key.empty(); }
};

/// Throws std::invalid_argument("<context>: <key> <rule>") for a violation.
inline void check_input(const RangeViolation& v, std::string_view context) {
  check_input(!v, context, v.key + " " + v.rule);
}

}  // namespace pinball
