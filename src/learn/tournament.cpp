#include "pinball/learn/tournament.h"

#include <stdexcept>

namespace pinball::learn {

SearchResult run_tournament(const BallObjective& objective, const SearchConfig& config,
                            const TournamentConfig& t) {
  if (t.balls_per_controller < 1) throw std::invalid_argument("tournament: balls per controller must be >= 1");
  SearchRun run(objective, config, "tournament");
  control::ControllerSpec parent = seed_controller(run, objective.prototype());
  const int k = parent.action_function.partitions();
  const std::uint64_t b = static_cast<std::uint64_t>(t.balls_per_controller);
  const std::uint64_t per_generation = static_cast<std::uint64_t>(k + 1) * b;
  run.set_generation_balls(per_generation);
  while (run.balls_left() >= per_generation) {
    // 2(a): child i = the parent with minicontroller i replaced by a random one (eq. 6.1).
    std::vector<control::ControllerSpec> family(static_cast<std::size_t>(k + 1), parent);
    for (int i = 0; i < k; ++i) {
      auto& af = family[static_cast<std::size_t>(i + 1)].action_function;
      af.minicontroller(i) = af.random_minicontroller(run.rng());
    }
    // 2(b): mean over b balls each.
    std::vector<BallTask> tasks;
    for (const auto& c : family) {
      for (std::uint64_t j = 0; j < b; ++j) tasks.push_back({&c, run.fresh_seed()});
    }
    const std::vector<BallOutcome> out = run.play(tasks);
    std::size_t winner = 0;
    double winner_mean = -1e300;
    for (std::size_t c = 0; c < family.size(); ++c) {
      const double m = mean_score(out, c * b, (c + 1) * b);
      run.offer(family[c], m, b);
      if (m > winner_mean) {  // ties keep the earlier (the parent first)
        winner_mean = m;
        winner = c;
      }
    }
    run.count("parent_replaced", winner != 0 ? 1.0 : 0.0);
    parent = family[winner];  // 2(c)
    const RunningStats population = score_stats(out, 0, out.size());
    run.end_generation(population.mean(), winner_mean, population.ci95_half_width());
  }
  return run.finish();
}

}  // namespace pinball::learn
