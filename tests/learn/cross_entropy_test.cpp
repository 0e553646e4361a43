#include "pinball/learn/cross_entropy.h"

#include <gtest/gtest.h>

#include "toy_objective.h"

namespace pinball::learn {
namespace {

using testing_support::ToyObjective;

TEST(CrossEntropy, GenerationCostIsTheHalvingSchedule) {
  EXPECT_EQ(cross_entropy_generation_balls(CrossEntropyConfig{}), 16u * 2 + 8 * 4 + 4 * 8 + 2 * 16);
  CrossEntropyConfig c;
  c.population = 5;
  c.first_round_balls = 1;
  EXPECT_EQ(cross_entropy_generation_balls(c), 5u * 1 + 3 * 2 + 2 * 4);
}

TEST(CrossEntropy, ApproachesTheToyOptimum) {
  const ToyObjective toy(2);
  SearchConfig c;
  c.budget_balls = 4000;
  c.seed = 4;
  const SearchResult r = run_cross_entropy(toy, c);
  ASSERT_GT(r.generations, 10);
  EXPECT_GT(toy.expected(r.best), 0.9 * toy.optimum());
  for (int p = 0; p < 4; ++p) EXPECT_EQ(r.best.action_function.minicontroller(p).flipper, ToyObjective::target_flipper(p));
}

TEST(CrossEntropy, NearTheOptimumOnANoisierLargerToy) {
  const ToyObjective toy(3, 20.0);
  SearchConfig c;
  c.budget_balls = 3000;
  c.seed = 6;
  c.seed_min_score = -1e9;
  const SearchResult cem = run_cross_entropy(toy, c);
  EXPECT_GT(toy.expected(cem.best), 0.85 * toy.optimum());
}

TEST(CrossEntropy, SameSeedSameResultWhateverTheThreads) {
  const ToyObjective toy(2);
  SearchConfig c;
  c.budget_balls = 500;
  c.seed = 1;
  const SearchResult a = run_cross_entropy(toy, c);
  c.threads = 3;
  const SearchResult b = run_cross_entropy(toy, c);
  EXPECT_EQ(a.best_mean, b.best_mean);
  EXPECT_EQ(control::controller_to_json(a.best), control::controller_to_json(b.best));
}

}  // namespace
}  // namespace pinball::learn
