#pragma once
// The stochastic hill-climbing tournament (thesis 6.2, Fig. 6-2): each
// generation the parent and k children (each with one minicontroller
// replaced by a random one) play b balls; the best mean becomes the parent.

#include "pinball/learn/search.h"

namespace pinball::learn {

/// Settings of the tournament.
struct TournamentConfig {
  int balls_per_controller = 5;  ///< b: balls per controller per generation
};

/// Runs generations until the budget cannot pay for another one.
SearchResult run_tournament(const BallObjective& objective, const SearchConfig& config,
                            const TournamentConfig& tournament = {});

}  // namespace pinball::learn
