#include "pinball/learn/cross_entropy.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/Core>

#include "pinball/core/running_stats.h"

namespace pinball::learn {

std::uint64_t halving_race_balls(int candidates, std::uint64_t first_round_balls) {
  std::uint64_t total = 0;
  std::uint64_t balls = first_round_balls;
  for (int alive = candidates; alive > 1; alive = (alive + 1) / 2) {
    total += static_cast<std::uint64_t>(alive) * balls;
    balls *= 2;
  }
  return total;
}

std::uint64_t cross_entropy_generation_balls(const CrossEntropyConfig& c) {
  return halving_race_balls(c.population, static_cast<std::uint64_t>(c.first_round_balls));
}

namespace {

// What a sequential-halving race on common random numbers found.
struct RaceResult {
  std::vector<std::size_t> ranking;  // best first
  std::vector<RunningStats> stats;   // per candidate
  double balls_sum = 0.0;            // sum of every ball's score
  std::uint64_t balls = 0;           // balls played
};

// Half-width of the 95 % interval of the mean over every ball of a race.
double population_ci95(const RaceResult& race) {
  RunningStats all;
  for (const RunningStats& s : race.stats) all.merge(s);
  return all.ci95_half_width();
}

// Each round, every candidate still in plays the same fresh balls; the better
// half goes on with twice the balls.
RaceResult halving_race(SearchRun& run, const std::vector<control::ControllerSpec>& cand,
                        std::uint64_t first_round_balls) {
  RaceResult r;
  r.stats.resize(cand.size());
  std::vector<std::size_t> alive(cand.size());
  std::iota(alive.begin(), alive.end(), 0);
  std::uint64_t balls = first_round_balls;
  while (alive.size() > 1) {
    std::vector<std::uint64_t> seeds;
    for (std::uint64_t b = 0; b < balls; ++b) seeds.push_back(run.fresh_seed());
    std::vector<BallTask> tasks;
    for (std::size_t j : alive) {
      for (std::uint64_t sd : seeds) tasks.push_back({&cand[j], sd});
    }
    const std::vector<BallOutcome> out = run.play(tasks);
    for (std::size_t a = 0; a < alive.size(); ++a) {
      for (std::uint64_t b = 0; b < balls; ++b) {
        const double score = out[a * balls + b].score;
        r.stats[alive[a]].add(score);
        r.balls_sum += score;
        ++r.balls;
      }
    }
    std::stable_sort(alive.begin(), alive.end(),
                     [&](std::size_t x, std::size_t y) { return r.stats[x].mean() > r.stats[y].mean(); });
    const std::size_t keep = (alive.size() + 1) / 2;
    for (std::size_t a = alive.size(); a-- > keep;) r.ranking.push_back(alive[a]);
    alive.resize(keep);
    balls *= 2;
  }
  r.ranking.push_back(alive[0]);
  std::reverse(r.ranking.begin(), r.ranking.end());
  return r;
}

}  // namespace

SearchResult run_cross_entropy(const BallObjective& objective, const SearchConfig& config,
                               const CrossEntropyConfig& c) {
  if (c.population < 2 || c.first_round_balls < 1 || !(c.elite_fraction > 0.0 && c.elite_fraction <= 1.0) ||
      !(c.smoothing > 0.0 && c.smoothing <= 1.0) || !(c.initial_sigma > 0.0) || !(c.min_sigma >= 0.0) ||
      !(c.final_race_fraction >= 0.0 && c.final_race_fraction < 1.0) || c.final_race_size < 1) {
    throw std::invalid_argument(
        "cross-entropy: population >= 2, first round balls >= 1, 0 < elite, smoothing <= 1, "
        "0 <= final race fraction < 1, final race size >= 1");
  }
  SearchRun run(objective, config, "cem");
  const control::ControllerSpec prototype = objective.prototype();
  const int k = prototype.action_function.partitions();
  const auto& range = prototype.action_function.config().gain_range;
  const Eigen::Index dims = 4 * k;
  Eigen::VectorXd mu = Eigen::VectorXd::Zero(dims);              // gains / range, in [-1, 1]
  Eigen::VectorXd sigma = Eigen::VectorXd::Constant(dims, c.initial_sigma);
  Eigen::VectorXd p_right = Eigen::VectorXd::Constant(k, 0.5);    // P(flipper = right) per partition

  auto decode = [&](const Eigen::VectorXd& x, const std::vector<int>& flippers) {
    control::ControllerSpec s = prototype;
    for (int p = 0; p < k; ++p) {
      auto& m = s.action_function.minicontroller(p);
      for (int i = 0; i < 4; ++i) m.a[static_cast<std::size_t>(i)] = x(4 * p + i) * range[static_cast<std::size_t>(i)];
      m.flipper = flippers[static_cast<std::size_t>(p)];
    }
    return s;
  };
  auto encode = [&](const control::ControllerSpec& s, Eigen::VectorXd& x, std::vector<int>& flippers) {
    x.resize(dims);
    flippers.assign(static_cast<std::size_t>(k), 0);
    for (int p = 0; p < k; ++p) {
      const auto& m = s.action_function.minicontroller(p);
      for (int i = 0; i < 4; ++i) {
        const double r = range[static_cast<std::size_t>(i)];
        x(4 * p + i) = r > 0.0 ? m.a[static_cast<std::size_t>(i)] / r : 0.0;
      }
      flippers[static_cast<std::size_t>(p)] = m.flipper;
    }
  };

  const std::uint64_t per_generation = cross_entropy_generation_balls(c);
  const std::size_t n = static_cast<std::size_t>(c.population);
  const std::size_t elites = std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(c.elite_fraction * c.population)));
  const auto final_race_budget =
      static_cast<std::uint64_t>(c.final_race_fraction * static_cast<double>(config.budget_balls));
  run.set_generation_balls(per_generation + final_race_budget);
  std::vector<control::ControllerSpec> winners;  // the latest generations' winners, oldest first
  while (run.balls_left() >= per_generation + final_race_budget) {
    // Sample the population; the incumbent (best so far) is candidate 0.
    std::vector<Eigen::VectorXd> xs(n);
    std::vector<std::vector<int>> fs(n);
    std::vector<control::ControllerSpec> cand;
    const bool incumbent = run.has_best();
    for (std::size_t j = 0; j < n; ++j) {
      if (j == 0 && incumbent) {
        encode(run.best(), xs[j], fs[j]);
      } else {
        xs[j].resize(dims);
        for (Eigen::Index d = 0; d < dims; ++d) xs[j](d) = std::clamp(mu(d) + sigma(d) * run.rng().normal(), -1.0, 1.0);
        fs[j].resize(static_cast<std::size_t>(k));
        for (int p = 0; p < k; ++p) fs[j][static_cast<std::size_t>(p)] = run.rng().uniform01() < p_right(p) ? 1 : 0;
      }
      cand.push_back(decode(xs[j], fs[j]));
    }
    const RaceResult race = halving_race(run, cand, static_cast<std::uint64_t>(c.first_round_balls));
    const std::vector<std::size_t>& ranking = race.ranking;
    const std::vector<RunningStats>& stats = race.stats;
    const std::size_t winner = ranking[0];
    run.set_best(cand[winner], stats[winner].mean(), static_cast<std::uint64_t>(stats[winner].count()));
    run.count("incumbent_kept", winner == 0 && incumbent ? 1.0 : 0.0);
    // Update the distribution from the elites.
    Eigen::VectorXd mean_e = Eigen::VectorXd::Zero(dims);
    Eigen::VectorXd var_e = Eigen::VectorXd::Zero(dims);
    Eigen::VectorXd right_e = Eigen::VectorXd::Zero(k);
    for (std::size_t e = 0; e < elites; ++e) mean_e += xs[ranking[e]];
    mean_e /= static_cast<double>(elites);
    for (std::size_t e = 0; e < elites; ++e) {
      var_e += (xs[ranking[e]] - mean_e).array().square().matrix();
      for (int p = 0; p < k; ++p) right_e(p) += fs[ranking[e]][static_cast<std::size_t>(p)];
    }
    var_e /= static_cast<double>(elites);
    right_e /= static_cast<double>(elites);
    mu = (1.0 - c.smoothing) * mu + c.smoothing * mean_e;
    sigma = ((1.0 - c.smoothing) * sigma + c.smoothing * var_e.cwiseSqrt()).cwiseMax(c.min_sigma);
    p_right = ((1.0 - c.smoothing) * p_right + c.smoothing * right_e).cwiseMax(0.05).cwiseMin(0.95);
    winners.push_back(cand[winner]);
    if (winners.size() > static_cast<std::size_t>(c.final_race_size)) winners.erase(winners.begin());
    run.end_generation(race.balls > 0 ? race.balls_sum / static_cast<double>(race.balls) : 0.0,
                       stats[winner].mean(), population_ci95(race));
  }
  // The final race: the recent winners and the distribution's mean (every
  // gain at mu, each flipper the likelier one), on as many balls as the rest
  // of the budget pays for.
  if (c.final_race_fraction > 0.0 && !winners.empty()) {
    std::vector<control::ControllerSpec> finalists = winners;
    std::vector<int> likelier(static_cast<std::size_t>(k));
    for (int p = 0; p < k; ++p) likelier[static_cast<std::size_t>(p)] = p_right(p) > 0.5 ? 1 : 0;
    finalists.push_back(decode(mu, likelier));
    const std::uint64_t unit = halving_race_balls(static_cast<int>(finalists.size()), 1);
    const std::uint64_t first_round = unit > 0 ? run.balls_left() / unit : 0;
    if (first_round >= 1) {
      const RaceResult race = halving_race(run, finalists, first_round);
      const std::size_t winner = race.ranking[0];
      run.set_best(finalists[winner], race.stats[winner].mean(),
                   static_cast<std::uint64_t>(race.stats[winner].count()));
      run.count("final_race_candidates", static_cast<double>(finalists.size()));
      run.count("final_race_winner_balls", static_cast<double>(race.stats[winner].count()));
      run.count("final_race_mean_won", winner + 1 == finalists.size() ? 1.0 : 0.0);
      run.end_generation(race.balls_sum / static_cast<double>(race.balls), race.stats[winner].mean(),
                         population_ci95(race));
    }
  }
  return run.finish();
}

}  // namespace pinball::learn
