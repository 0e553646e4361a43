#include "pinball/learn/parallel_runner.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

namespace pinball::learn {

std::vector<BallOutcome> play_balls(const BallObjective& objective, const std::vector<BallTask>& tasks,
                                    int threads) {
  std::vector<BallOutcome> results(tasks.size());
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    while (true) {
      const std::size_t i = next.fetch_add(1);
      if (i >= tasks.size()) return;
      try {
        results[i] = objective.play(*tasks[i].controller, tasks[i].seed);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = tasks.size();
      }
    }
  };
  const int n = std::max(1, std::min<int>(threads, static_cast<int>(tasks.size())));
  if (n <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < n; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
  return results;
}

}  // namespace pinball::learn
