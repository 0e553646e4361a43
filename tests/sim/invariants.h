#pragma once
// The per-step invariants every stiff-case test checks, for any stepper: a
// finite state and no ball inside an obstacle or flipper. Records a GoogleTest
// failure and returns false on the first violation.

#include <gtest/gtest.h>

#include <cmath>

#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/penetration.h"
#include "test_boards.h"

namespace pinball::sim::testing {

/// Overlap tolerated by default (m): the thesis stepper's separation is 1 µm.
constexpr double kDefaultMaxDepth_m = 1e-6;

/// True when the ball and flippers are finite and the ball overlaps nothing
/// deeper than max_depth_m; otherwise records a failure naming the step.
inline bool invariants_hold(const table::Board& b, const GameState& s, long step, double max_depth_m = kDefaultMaxDepth_m) {
  if (!finite(s.ball.position_m) || !finite(s.ball.velocity_mps)) {
    ADD_FAILURE() << "non-finite ball state at step " << step;
    return false;
  }
  for (const FlipperState& f : s.flippers) {
    if (!std::isfinite(f.theta_rad)) {
      ADD_FAILURE() << "non-finite flipper angle at step " << step;
      return false;
    }
  }
  const double depth = max_penetration_m(b, s);
  if (!(depth < max_depth_m)) {
    ADD_FAILURE() << "penetration " << depth << " m at step " << step << " ball (" << s.ball.position_m.x() << ", "
                  << s.ball.position_m.y() << ") v (" << s.ball.velocity_mps.x() << ", " << s.ball.velocity_mps.y()
                  << ")";
    return false;
  }
  return true;
}

}  // namespace pinball::sim::testing
