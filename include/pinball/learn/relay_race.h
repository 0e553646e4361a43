#pragma once
// The parallel Hoeffding relay race (thesis 6.3.3, Fig. 6-5): n controllers
// each play one ball per generation; per partition, a minicontroller whose
// Hoeffding upper bound falls below the best lower bound, or whose mean and
// variance are still 0 after 3 flip opportunities, is replaced by a random
// one; the per-partition best means make the "summed best" controller.

#include "pinball/learn/search.h"

namespace pinball::learn {

/// Settings of the relay race.
struct RelayConfig {
  int population = 20;        ///< n controllers (the thesis: 20)
  double confidence = 0.90;   ///< c of the Hoeffding intervals (the thesis: 90 %)
  int zero_after = 3;         ///< randomise a minicontroller with mean = variance = 0 after this many opportunities
  int eval_balls = 10;        ///< balls to estimate the summed best controller
  int eval_every = 5;         ///< estimate it every this many generations (and at the end)
};

/// Runs generations until the budget cannot pay for another one.
SearchResult run_relay_race(const BallObjective& objective, const SearchConfig& config, const RelayConfig& relay = {});

}  // namespace pinball::learn
