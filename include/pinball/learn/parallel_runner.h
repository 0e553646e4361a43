#pragma once
// Plays a batch of balls on several threads. Each task carries its own
// controller and ball seed and its result goes to its own slot, so the
// results depend only on the tasks, never on the thread count or timing.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "pinball/learn/blob.h"
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

/// Runs task(i) for every i in [0, count) across the job: the items dealt to
/// the MPI ranks in small chunks (team.h), each rank's on `threads` threads;
/// or, when the run's checkpoint already holds this batch, none at all
/// (checkpoint.h). Returns every result in item order, on every rank, and
/// records the batch in the checkpoint. A task's exception is rethrown in a
/// job of one; with several ranks it ends the whole job (team_abort), since
/// the other ranks would wait for this one forever.
std::vector<Blob> distributed_map(std::size_t count, int threads, const std::function<Blob(std::size_t)>& task);

/// distributed_map over [0, count) in batches of at most `batch` items, in
/// order: `take(first, results)` gets each batch's results (items first ..
/// first + results.size() - 1) before the next batch runs. Memory holds one
/// batch, however many items; each batch is one checkpoint batch. The batch
/// size must not depend on the ranks or threads, or a checkpoint would not
/// resume on other counts.
void distributed_batches(std::size_t count, std::size_t batch, int threads,
                         const std::function<Blob(std::size_t)>& task,
                         const std::function<void(std::size_t first, std::vector<Blob>& results)>& take);

/// Plays every task across the job (distributed_map) and returns the
/// outcomes in task order.
std::vector<BallOutcome> play_balls(const BallObjective& objective, const std::vector<BallTask>& tasks, int threads);

/// A ball's outcome as bytes and back.
Blob to_blob(const BallOutcome& outcome);
BallOutcome ball_outcome_from_blob(const Blob& blob);

}  // namespace pinball::learn
