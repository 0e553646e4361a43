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

double counter(const SearchResult& r, const std::string& name) {
  for (const auto& [n, v] : r.counters) {
    if (n == name) return v;
  }
  return -1.0;
}

TEST(CrossEntropy, HalvingRaceCost) {
  EXPECT_EQ(halving_race_balls(16, 250), 16u * 250 + 8 * 500 + 4 * 1000 + 2 * 2000);
  EXPECT_EQ(halving_race_balls(1, 100), 0u);
}

TEST(CrossEntropy, TheFinalRaceSpendsTheKeptShareOnFewCandidates) {
  const ToyObjective toy(2, 50.0);
  SearchConfig c;
  c.budget_balls = 6000;
  c.seed = 3;
  CrossEntropyConfig cem;
  cem.final_race_fraction = 0.2;
  cem.final_race_size = 7;
  const SearchResult r = run_cross_entropy(toy, c, cem);
  EXPECT_LE(r.balls_used, c.budget_balls);
  EXPECT_EQ(counter(r, "final_race_candidates"), 8.0);  // 7 winners + the mean
  // 8 candidates with f first-round balls cost 8f + 4*2f + 2*4f = 24f; the
  // winner plays 7f. The race gets at least the kept 1200 balls and spends
  // all but less than one more f.
  const auto winner_balls = static_cast<std::uint64_t>(counter(r, "final_race_winner_balls"));
  EXPECT_EQ(winner_balls % 7, 0u);
  EXPECT_GE(winner_balls / 7, 1200u / 24);
  EXPECT_LT(c.budget_balls - r.balls_used, 24u);
  EXPECT_EQ(r.best_balls, static_cast<std::uint64_t>(counter(r, "final_race_winner_balls")));
  cem.final_race_fraction = 0.0;
  const SearchResult none = run_cross_entropy(toy, c, cem);
  EXPECT_EQ(counter(none, "final_race_candidates"), -1.0);
}

// Scores spread far wider than the differences between candidates: the final
// race picks a better controller than the last generation's 30-ball winner.
TEST(CrossEntropy, TheFinalRaceBeatsTheLastWinnerOnANoisyToy) {
  const ToyObjective toy(2, 400.0);
  double with_race = 0.0, without = 0.0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    SearchConfig c;
    c.budget_balls = 20000;
    c.seed = seed;
    c.seed_min_score = -1e9;
    CrossEntropyConfig cem;
    with_race += toy.expected(run_cross_entropy(toy, c, cem).best);
    cem.final_race_fraction = 0.0;
    without += toy.expected(run_cross_entropy(toy, c, cem).best);
  }
  EXPECT_GT(with_race, without);
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
