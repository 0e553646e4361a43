#pragma once
// What every search method shares: a budget in simulated balls, a seed, a
// thread count, progress on a stream, the learning curve, the best controller
// seen so far (the thesis could not keep it, 6.3.5), and cycle detection (a
// ball alive past the time limit), with that controller handed out at once.

#include <chrono>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "pinball/core/rng.h"
#include "pinball/core/running_stats.h"
#include "pinball/learn/evaluator.h"
#include "pinball/learn/parallel_runner.h"

namespace pinball::learn {

/// Settings common to all methods.
struct SearchConfig {
  std::uint64_t budget_balls = 1000;  ///< simulated balls the search may play, seeding included
  std::uint64_t seed = 1;             ///< the only source of randomness
  int threads = 1;                    ///< worker threads; results do not depend on it
  std::ostream* progress = nullptr;   ///< one line per generation (or nullptr)
  double seed_min_score = 1.0;        ///< a seed controller must score at least this on its one ball (6.2.1)
  int seed_max_tries = 400;           ///< random controllers tried before taking the best of them
  /// Called at once with a controller whose ball was cut at the time limit (a cycle).
  std::function<void(const control::ControllerSpec&, const BallOutcome&)> on_cycle;
};

/// One row of the learning curve.
struct CurvePoint {
  int generation = 0;                ///< 1-based
  std::uint64_t balls = 0;           ///< balls played so far
  double population_mean = 0.0;      ///< mean score per ball over this generation's balls
  double generation_best = 0.0;      ///< the generation's best controller's estimated mean
  double best_so_far = 0.0;          ///< the best controller's estimated mean so far
  double wall_s = 0.0;               ///< wall time since the start (s)
  double population_ci95 = 0.0;      ///< half-width of population_mean's 95 % interval (Student's t; 0: unknown)
};

/// What a search returns.
struct SearchResult {
  std::string method;                   ///< method name
  control::ControllerSpec best;         ///< the best controller seen
  double best_mean = 0.0;               ///< its estimated mean score per ball
  std::uint64_t best_balls = 0;         ///< balls behind that estimate
  std::vector<CurvePoint> curve;        ///< per generation
  std::uint64_t balls_used = 0;         ///< balls played
  int generations = 0;                  ///< generations completed
  std::uint64_t generation_balls = 0;   ///< balls the budget must still hold to start a generation
  bool cycle_found = false;             ///< some ball was cut at the time limit
  control::ControllerSpec cycle_controller;  ///< the first controller that cycled
  double wall_s = 0.0;                  ///< wall time (s)
  std::vector<std::pair<std::string, double>> counters;  ///< method-specific counts (eliminations, ...)
};

/// Bookkeeping shared by the methods.
class SearchRun {
 public:
  SearchRun(const BallObjective& objective, const SearchConfig& config, std::string method);

  /// Balls left in the budget.
  std::uint64_t balls_left() const { return config_.budget_balls - std::min(config_.budget_balls, balls_); }
  /// A fresh ball seed (never repeats within a run).
  std::uint64_t fresh_seed() { return ball_seed(config_.seed, seeds_++); }
  /// The run's random stream (for mutations and sampling).
  Rng& rng() { return rng_; }
  /// The objective and settings.
  const BallObjective& objective() const { return objective_; }
  const SearchConfig& config() const { return config_; }

  /// Plays the tasks (in parallel), counts them, and reports any cycle.
  std::vector<BallOutcome> play(const std::vector<BallTask>& tasks);
  /// Keeps `spec` if its mean beats the best so far.
  void offer(const control::ControllerSpec& spec, double mean, std::uint64_t balls);
  /// Makes `spec` the best so far unconditionally (a comparison on common random numbers decided it).
  void set_best(const control::ControllerSpec& spec, double mean, std::uint64_t balls);
  /// Closes a generation: a curve row and a progress line. `population_ci95`:
  /// half-width of the population mean's 95 % interval (0 when unknown).
  void end_generation(double population_mean, double generation_best, double population_ci95 = 0.0);
  /// Records what a generation needs of the budget (for the report of a budget too small).
  void set_generation_balls(std::uint64_t balls) { result_.generation_balls = balls; }
  /// Adds a method-specific counter.
  void count(const std::string& name, double value);
  /// The best estimated mean so far (0 before any).
  double best_mean() const { return result_.best_mean; }
  /// The best controller so far (the prototype before any).
  const control::ControllerSpec& best() const { return result_.best; }
  /// True once a best controller exists.
  bool has_best() const { return has_best_; }
  /// The result so far.
  SearchResult finish();

 private:
  const BallObjective& objective_;
  SearchConfig config_;
  Rng rng_;
  std::uint64_t balls_ = 0;
  std::uint64_t seeds_ = 0;
  bool has_best_ = false;
  SearchResult result_;
  std::chrono::steady_clock::time_point start_;
};

/// The balls the quick random search plays at a time: the least one seed costs.
inline constexpr int kSeedBatch = 8;

/// The quick random search of 6.2.1: random controllers of the prototype's
/// shape, one ball each, until one scores at least config.seed_min_score
/// (tried in batches of kSeedBatch whatever the thread count; the first in
/// order wins), or the best of seed_max_tries.
control::ControllerSpec seed_controller(SearchRun& run, const control::ControllerSpec& prototype);

/// Mean score per ball of a set of outcomes.
double mean_score(const std::vector<BallOutcome>& outcomes, std::size_t begin, std::size_t end);

/// Mean, spread and 95 % interval of the scores of a set of outcomes.
RunningStats score_stats(const std::vector<BallOutcome>& outcomes, std::size_t begin, std::size_t end);

}  // namespace pinball::learn
