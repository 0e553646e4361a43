#pragma once
// The ball the physics tests roll: the thesis's, table::Ball's default.

namespace pinball::testing {

/// Ball radius (m).
inline constexpr double kR = 0.0135;

}  // namespace pinball::testing
