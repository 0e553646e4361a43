#include "pinball/learn/parallel_runner.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

namespace pinball::learn {

void parallel_for(std::size_t count, int threads, const std::function<void(std::size_t)>& task) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    while (true) {
      const std::size_t i = next.fetch_add(1);
      if (i >= count) return;
      try {
        task(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = count;
      }
    }
  };
  const std::size_t n = std::min(static_cast<std::size_t>(std::max(threads, 1)), count);
  if (n <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (std::size_t t = 0; t < n; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
}

std::vector<BallOutcome> play_balls(const BallObjective& objective, const std::vector<BallTask>& tasks,
                                    int threads) {
  std::vector<BallOutcome> results(tasks.size());
  parallel_for(tasks.size(), threads,
               [&](std::size_t i) { results[i] = objective.play(*tasks[i].controller, tasks[i].seed); });
  return results;
}

}  // namespace pinball::learn
