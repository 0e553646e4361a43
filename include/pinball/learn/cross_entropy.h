#pragma once
// The modern method: the cross-entropy method over the whole controller
// (every minicontroller's gains, scaled to their ranges, as a diagonal
// Gaussian; every flipper choice as a Bernoulli), with candidates compared on
// common random numbers (all candidates of a round play the same ball seeds)
// and selected by sequential halving instead of Hoeffding elimination. The
// incumbent best races in every generation, so the best is never lost.
// A generation's winner rests on a few dozen balls, too few for balls whose
// scores spread wider than their mean: the last part of the budget is kept
// for a final race (sequential halving again, hundreds of balls per
// candidate) among the recent generations' winners and the distribution's
// mean, whose winner is the result.

#include "pinball/learn/search.h"

namespace pinball::learn {

/// Settings of the cross-entropy search.
struct CrossEntropyConfig {
  int population = 16;           ///< candidates per generation (the incumbent included)
  int first_round_balls = 2;     ///< balls per candidate in the first halving round; doubled each round
  double elite_fraction = 0.25;  ///< share of the ranking that updates the distribution
  double smoothing = 0.7;        ///< weight of the elites in the update (1: replace)
  double initial_sigma = 0.5;    ///< initial standard deviation, as a fraction of each gain range
  double min_sigma = 0.03;       ///< floor of the standard deviation (fraction of the range)
  double final_race_fraction = 0.1;  ///< share of the budget kept for the final race (0: none)
  int final_race_size = 15;      ///< recent generation winners in the final race (plus the mean)
};

/// Balls a sequential-halving race of `candidates` costs when its first
/// round plays `first_round_balls` each (doubled every round).
std::uint64_t halving_race_balls(int candidates, std::uint64_t first_round_balls);

/// Balls one generation costs with these settings.
std::uint64_t cross_entropy_generation_balls(const CrossEntropyConfig& config);

/// Runs generations until the budget cannot pay for another one.
SearchResult run_cross_entropy(const BallObjective& objective, const SearchConfig& config,
                               const CrossEntropyConfig& cem = {});

}  // namespace pinball::learn
