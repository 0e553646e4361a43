#include "pinball/learn/search.h"

#include <algorithm>
#include <ostream>

#include "pinball/core/format.h"
#include "pinball/core/progress.h"
#include "pinball/learn/checkpoint.h"

namespace pinball::learn {

SearchRun::SearchRun(const BallObjective& objective, const SearchConfig& config, std::string method)
    : objective_(objective), config_(config), rng_(config.seed), start_(std::chrono::steady_clock::now()) {
  result_.method = std::move(method);
  result_.best = objective.prototype();
  result_.cycle_controller = result_.best;
}

std::vector<BallOutcome> SearchRun::play(const std::vector<BallTask>& tasks) {
  std::vector<BallOutcome> out = play_balls(objective_, tasks, config_.threads);
  balls_ += tasks.size();
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!out[i].cut) continue;
    if (!result_.cycle_found) {
      result_.cycle_found = true;
      result_.cycle_controller = *tasks[i].controller;
      if (config_.progress) *config_.progress << result_.method << ": cycle found (ball alive at the time limit, score " << out[i].score << ")\n";
    }
    if (config_.on_cycle) config_.on_cycle(*tasks[i].controller, out[i]);
  }
  return out;
}

void SearchRun::offer(const control::ControllerSpec& spec, double mean, std::uint64_t balls) {
  if (!has_best_ || mean > result_.best_mean) set_best(spec, mean, balls);
}

void SearchRun::set_best(const control::ControllerSpec& spec, double mean, std::uint64_t balls) {
  result_.best = spec;
  result_.best_mean = mean;
  result_.best_balls = balls;
  has_best_ = true;
}

void SearchRun::end_generation(double population_mean, double generation_best, double population_ci95) {
  CurvePoint p;
  p.generation = ++result_.generations;
  p.balls = balls_;
  p.population_mean = population_mean;
  p.generation_best = generation_best;
  p.best_so_far = result_.best_mean;
  p.population_ci95 = population_ci95;
  p.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  result_.curve.push_back(p);
  if (config_.progress) {
    // Balls a resumed run took from its checkpoint took no time: rate and ETA are the played balls'.
    const auto replayed = static_cast<double>(checkpoint_status().replayed_items);
    const double played = static_cast<double>(balls_) - replayed;
    // "tournament: 1200/6000 balls (20 %), 41 s elapsed, ETA 2 min 44 s; generation 3, ..."
    const std::string note = "generation " + std::to_string(p.generation) + ", population mean " +
                             format_number(population_mean, 4) + ", generation best " +
                             format_number(generation_best, 4) + ", best so far " + format_number(p.best_so_far, 4) +
                             ", " + format_number(p.wall_s > 0 ? played / p.wall_s : 0.0) +
                             " balls/s";
    *config_.progress << format_progress(result_.method, static_cast<double>(balls_),
                                         static_cast<double>(config_.budget_balls), "balls", p.wall_s, note, replayed)
                      << "\n";
  }
}

void SearchRun::count(const std::string& name, double value) {
  for (auto& c : result_.counters) {
    if (c.first == name) {
      c.second += value;
      return;
    }
  }
  result_.counters.emplace_back(name, value);
}

SearchResult SearchRun::finish() {
  result_.balls_used = balls_;
  result_.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return result_;
}

double mean_score(const std::vector<BallOutcome>& outcomes, std::size_t begin, std::size_t end) {
  if (end <= begin) return 0.0;
  double sum = 0.0;
  for (std::size_t i = begin; i < end; ++i) sum += outcomes[i].score;
  return sum / static_cast<double>(end - begin);
}

RunningStats score_stats(const std::vector<BallOutcome>& outcomes, std::size_t begin, std::size_t end) {
  RunningStats s;
  for (std::size_t i = begin; i < end && i < outcomes.size(); ++i) s.add(outcomes[i].score);
  return s;
}

control::ControllerSpec seed_controller(SearchRun& run, const control::ControllerSpec& prototype) {
  control::ControllerSpec best = prototype;
  best.action_function.randomise(run.rng());
  double best_score = -1e300;
  int tried = 0;
  while (tried < run.config().seed_max_tries && run.balls_left() > 0) {
    const int n = static_cast<int>(std::min<std::uint64_t>(kSeedBatch, run.balls_left()));
    std::vector<control::ControllerSpec> candidates(static_cast<std::size_t>(n), prototype);
    std::vector<BallTask> tasks;
    for (auto& c : candidates) {
      c.action_function.randomise(run.rng());
      tasks.push_back({&c, run.fresh_seed()});
    }
    const std::vector<BallOutcome> out = run.play(tasks);
    for (int i = 0; i < n; ++i) {
      if (out[static_cast<std::size_t>(i)].score > best_score) {
        best_score = out[static_cast<std::size_t>(i)].score;
        best = candidates[static_cast<std::size_t>(i)];
      }
      if (out[static_cast<std::size_t>(i)].score >= run.config().seed_min_score) {
        return candidates[static_cast<std::size_t>(i)];
      }
    }
    tried += n;
  }
  return best;
}

}  // namespace pinball::learn
