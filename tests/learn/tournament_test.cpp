#include "pinball/learn/tournament.h"

#include <gtest/gtest.h>

#include "toy_objective.h"

namespace pinball::learn {
namespace {

using testing_support::ToyObjective;

TEST(Tournament, ImprovesAToyObjective) {
  const ToyObjective toy(2);
  SearchConfig c;
  c.budget_balls = 3000;
  c.seed = 3;
  c.seed_min_score = -1e9;  // take the first random controller
  const SearchResult r = run_tournament(toy, c, TournamentConfig{3});
  ASSERT_GT(r.generations, 10);
  const double first = r.curve.front().generation_best;
  EXPECT_GT(toy.expected(r.best), first + 100.0);
  EXPECT_GT(toy.expected(r.best), 0.6 * toy.optimum());
  EXPECT_LE(r.balls_used, c.budget_balls);
}

TEST(Tournament, SameSeedSameResultWhateverTheThreads) {
  const ToyObjective toy(2);
  SearchConfig c;
  c.budget_balls = 300;
  c.seed = 5;
  const SearchResult a = run_tournament(toy, c);
  c.threads = 3;
  const SearchResult b = run_tournament(toy, c);
  EXPECT_EQ(a.best_mean, b.best_mean);
  ASSERT_EQ(a.curve.size(), b.curve.size());
  for (std::size_t i = 0; i < a.curve.size(); ++i) EXPECT_EQ(a.curve[i].population_mean, b.curve[i].population_mean);
}

}  // namespace
}  // namespace pinball::learn
