#pragma once
// Plays a batch of balls on several threads. Each task carries its own
// controller and ball seed and its result goes to its own slot, so the
// results depend only on the tasks, never on the thread count or timing.

#include <cstdint>
#include <vector>

#include "pinball/learn/evaluator.h"

namespace pinball::learn {

/// One ball to play.
struct BallTask {
  const control::ControllerSpec* controller = nullptr;  ///< borrowed; must outlive the call
  std::uint64_t seed = 0;                               ///< the ball's seed
};

/// Plays every task (std::thread, `threads` >= 1; 1 plays on the calling
/// thread) and returns the outcomes in task order. An exception in a task is
/// rethrown after all threads have joined.
std::vector<BallOutcome> play_balls(const BallObjective& objective, const std::vector<BallTask>& tasks, int threads);

}  // namespace pinball::learn
