#pragma once
// Plays a batch of balls on several threads. Each task carries its own
// controller and ball seed and its result goes to its own slot, so the
// results depend only on the tasks, never on the thread count or timing.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "pinball/learn/evaluator.h"

namespace pinball::learn {

/// One ball to play.
struct BallTask {
  const control::ControllerSpec* controller = nullptr;  ///< borrowed; must outlive the call
  std::uint64_t seed = 0;                               ///< the ball's seed
};

/// Calls task(i) for every i in [0, count) on `threads` std::threads (>= 1; 1
/// runs on the calling thread), each i exactly once, in no fixed order. An
/// exception in a task stops the remaining ones and is rethrown after all
/// threads have joined.
void parallel_for(std::size_t count, int threads, const std::function<void(std::size_t)>& task);

/// Plays every task (std::thread, `threads` >= 1; 1 plays on the calling
/// thread) and returns the outcomes in task order. An exception in a task is
/// rethrown after all threads have joined.
std::vector<BallOutcome> play_balls(const BallObjective& objective, const std::vector<BallTask>& tasks, int threads);

}  // namespace pinball::learn
