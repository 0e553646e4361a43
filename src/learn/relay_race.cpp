#include "pinball/learn/relay_race.h"

#include <stdexcept>

#include "pinball/core/running_stats.h"
#include "pinball/learn/statistics.h"

namespace pinball::learn {

SearchResult run_relay_race(const BallObjective& objective, const SearchConfig& config, const RelayConfig& r) {
  if (r.population < 2 || r.eval_balls < 1 || r.eval_every < 1 || !(r.confidence > 0.0 && r.confidence < 1.0)) {
    throw std::invalid_argument("relay race: population >= 2, eval balls >= 1, eval every >= 1, 0 < c < 1");
  }
  // Each of the population's seeds costs a batch at least, then a generation n + eval balls: a budget
  // below that played every ball of it before saying so (2000 balls for --population 1000).
  const std::uint64_t least_balls = static_cast<std::uint64_t>(r.population) * (kSeedBatch + 1) +
                                    static_cast<std::uint64_t>(r.eval_balls);
  if (config.budget_balls < least_balls) {
    throw std::invalid_argument("relay race: --budget-balls " + std::to_string(config.budget_balls) +
                                " pays for no generation: the seed search plays at least " +
                                std::to_string(kSeedBatch) + " balls for each of " + std::to_string(r.population) +
                                " controllers (--population), and a generation " + std::to_string(r.population) +
                                " + " + std::to_string(r.eval_balls) + " more: at least " +
                                std::to_string(least_balls) + "; nothing played");
  }
  SearchRun run(objective, config, "relay");
  const control::ControllerSpec prototype = objective.prototype();
  const int k = prototype.action_function.partitions();
  const std::size_t n = static_cast<std::size_t>(r.population);
  // Seed the population with controllers that scored on their first ball (6.3.3).
  std::vector<control::ControllerSpec> pop;
  for (std::size_t i = 0; i < n; ++i) pop.push_back(seed_controller(run, prototype));
  std::vector<std::vector<RunningStats>> stats(n, std::vector<RunningStats>(static_cast<std::size_t>(k)));

  auto summed_best = [&] {
    control::ControllerSpec best = pop[0];
    for (int p = 0; p < k; ++p) {
      std::size_t arg = 0;
      double m = -1e300;
      for (std::size_t i = 0; i < n; ++i) {
        const RunningStats& s = stats[i][static_cast<std::size_t>(p)];
        if (s.count() > 0 && s.mean() > m) {
          m = s.mean();
          arg = i;
        }
      }
      best.action_function.minicontroller(p) = pop[arg].action_function.minicontroller(p);
    }
    return best;
  };

  int generation = 0;
  const std::uint64_t eval_balls = static_cast<std::uint64_t>(r.eval_balls);
  run.set_generation_balls(n + eval_balls);
  while (run.balls_left() >= n + eval_balls) {
    ++generation;
    // 2(a): every controller plays one ball; flip opportunities update its minicontrollers' statistics.
    std::vector<BallTask> tasks;
    for (const auto& c : pop) tasks.push_back({&c, run.fresh_seed()});
    const std::vector<BallOutcome> out = run.play(tasks);
    for (std::size_t i = 0; i < n; ++i) {
      for (const Opportunity& o : out[i].opportunities) {
        if (o.partition >= 0 && o.partition < k) stats[i][static_cast<std::size_t>(o.partition)].add(o.value);
      }
    }
    // 2(b): per partition, the Hoeffding race and the zero rule.
    for (int p = 0; p < k; ++p) {
      const std::size_t pp = static_cast<std::size_t>(p);
      double l_star = -1e300;
      std::vector<Interval> iv(n);
      for (std::size_t i = 0; i < n; ++i) {
        iv[i] = hoeffding_interval(stats[i][pp], r.confidence);
        l_star = std::max(l_star, iv[i].low);
      }
      for (std::size_t i = 0; i < n; ++i) {
        const RunningStats& s = stats[i][pp];
        const bool zero = s.count() >= r.zero_after && s.mean() == 0.0 && s.variance() == 0.0;
        const bool behind = iv[i].high < l_star;
        if (zero || behind) {
          auto& af = pop[i].action_function;
          af.minicontroller(p) = af.random_minicontroller(run.rng());
          stats[i][pp] = RunningStats{};
          run.count(zero ? "randomised_zero" : "randomised_hoeffding", 1.0);
        }
      }
    }
    // 2(c), 2(d): the summed best controller, estimated every eval_every generations.
    double generation_best = run.best_mean();
    const bool last = run.balls_left() < 2 * (n + eval_balls);
    if (generation % r.eval_every == 0 || last) {
      const control::ControllerSpec best = summed_best();
      std::vector<BallTask> eval;
      for (std::uint64_t j = 0; j < eval_balls; ++j) eval.push_back({&best, run.fresh_seed()});
      const std::vector<BallOutcome> e = run.play(eval);
      generation_best = mean_score(e, 0, e.size());
      run.offer(best, generation_best, eval_balls);
    }
    const RunningStats population = score_stats(out, 0, out.size());
    run.end_generation(population.mean(), generation_best, population.ci95_half_width());
  }
  return run.finish();
}

}  // namespace pinball::learn
