#include "pinball/learn/parallel_runner.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "pinball/learn/checkpoint.h"
#include "pinball/learn/team.h"

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

std::vector<Blob> distributed_map(std::size_t count, int threads, const std::function<Blob(std::size_t)>& task) {
  std::vector<Blob> all;
  if (checkpoint_replay(count, all)) return all;
  const int ranks = team_size();
  const int rank = team_rank();
  std::vector<std::size_t> mine;
  for (std::size_t i = 0; i < count; ++i) {
    if (rank_of_item(i, ranks) == rank) mine.push_back(i);
  }
  std::vector<Blob> local(mine.size());
  try {
    parallel_for(mine.size(), threads, [&](std::size_t k) { local[k] = task(mine[k]); });
  } catch (const std::exception& e) {
    if (ranks == 1) throw;
    team_abort(e.what());
  }
  all = team_gather(count, std::move(local));
  checkpoint_record(all);
  return all;
}

void distributed_batches(std::size_t count, std::size_t batch, int threads,
                         const std::function<Blob(std::size_t)>& task,
                         const std::function<void(std::size_t first, std::vector<Blob>& results)>& take) {
  if (batch == 0) throw std::invalid_argument("distributed_batches: batch must be >= 1");
  for (std::size_t first = 0; first < count; first += batch) {
    const std::size_t n = std::min(batch, count - first);
    std::vector<Blob> results = distributed_map(n, threads, [&](std::size_t k) { return task(first + k); });
    take(first, results);
  }
}

Blob to_blob(const BallOutcome& o) {
  BlobWriter w;
  w.put(o.score).put(o.duration_s).put(o.flips).put(o.cut);
  std::vector<int> partitions;
  std::vector<double> values;
  for (const Opportunity& op : o.opportunities) {
    partitions.push_back(op.partition);
    values.push_back(op.value);
  }
  w.put_vector(partitions).put_vector(values);
  return w.take();
}

BallOutcome ball_outcome_from_blob(const Blob& blob) {
  BlobReader r(blob);
  BallOutcome o;
  o.score = r.get<double>();
  o.duration_s = r.get<double>();
  o.flips = r.get<int>();
  o.cut = r.get<bool>();
  const std::vector<int> partitions = r.get_vector<int>();
  const std::vector<double> values = r.get_vector<double>();
  r.expect_end();
  if (partitions.size() != values.size()) throw std::runtime_error("ball outcome: opportunity fields differ in length");
  for (std::size_t k = 0; k < partitions.size(); ++k) o.opportunities.push_back({partitions[k], values[k]});
  return o;
}

std::vector<BallOutcome> play_balls(const BallObjective& objective, const std::vector<BallTask>& tasks,
                                    int threads) {
  const std::vector<Blob> blobs = distributed_map(tasks.size(), threads, [&](std::size_t i) {
    return to_blob(objective.play(*tasks[i].controller, tasks[i].seed));
  });
  std::vector<BallOutcome> results;
  results.reserve(blobs.size());
  for (const Blob& b : blobs) results.push_back(ball_outcome_from_blob(b));
  return results;
}

}  // namespace pinball::learn
