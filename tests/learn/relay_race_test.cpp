#include "pinball/learn/relay_race.h"

#include <gtest/gtest.h>

#include "toy_objective.h"

namespace pinball::learn {
namespace {

using testing_support::ToyObjective;

RelayConfig relay_config(int population, int eval_balls) {
  RelayConfig r;
  r.population = population;
  r.eval_balls = eval_balls;
  return r;
}

TEST(RelayRace, ImprovesAToyObjective) {
  const ToyObjective toy(2);
  SearchConfig c;
  c.budget_balls = 4000;
  c.seed = 2;
  c.seed_min_score = -1e9;
  const SearchResult r = run_relay_race(toy, c, relay_config(10, 10));
  ASSERT_GT(r.generations, 50);
  EXPECT_GT(toy.expected(r.best), r.curve.front().generation_best + 50.0);
  EXPECT_GT(toy.expected(r.best), 0.5 * toy.optimum());
  double hoeffding = 0.0;
  for (const auto& [name, v] : r.counters) {
    if (name == "randomised_hoeffding") hoeffding = v;
  }
  EXPECT_GT(hoeffding, 0.0) << "the race eliminated someone by its intervals";
}

// --budget-balls 2000 with --population 1000 played every ball before saying no generation fitted.
TEST(RelayRace, ABudgetBelowOneGenerationIsRefusedBeforeAnyBall) {
  const ToyObjective toy(2);
  SearchConfig c;
  c.budget_balls = 9 * 10 + 9;  // seeds (8 a controller) and one generation of 10 + 10 need 100
  try {
    run_relay_race(toy, c, relay_config(10, 10));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("relay race: --budget-balls 99 pays for no generation"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("at least 100; nothing played"), std::string::npos) << e.what();
  }
  c.budget_balls = 100;
  c.seed_min_score = -1e9;
  EXPECT_EQ(run_relay_race(toy, c, relay_config(10, 10)).generations, 1);
}

// Minicontroller 0 never earns anything: the zero rule replaces it after 3 opportunities.
struct ZeroToy final : BallObjective {
  BallOutcome play(const control::ControllerSpec&, std::uint64_t) const override {
    BallOutcome o;
    o.opportunities.push_back({0, 0.0});
    o.opportunities.push_back({1, 10.0});
    o.score = 10.0;
    return o;
  }
  control::ControllerSpec prototype() const override {
    control::ControllerSpec s;
    s.action_function = control::ActionFunction(control::uniform_partition(1));
    return s;
  }
};

TEST(RelayRace, ZeroMeanAfterThreeIsRandomised) {
  const ZeroToy toy;
  SearchConfig c;
  c.budget_balls = 2 * 8 + 3 * 3;  // seeding (a batch of 8 each) + three generations of 2 balls + 1 evaluation
  c.seed_min_score = -1.0;
  RelayConfig rc = relay_config(2, 1);
  rc.eval_every = 1;
  const SearchResult r = run_relay_race(toy, c, rc);
  EXPECT_EQ(r.generations, 3);
  double zero = 0.0;
  for (const auto& [name, v] : r.counters) {
    if (name == "randomised_zero") zero = v;
  }
  EXPECT_EQ(zero, 2.0) << "both controllers' minicontroller 0, at generation 3";
}

TEST(RelayRace, SameSeedSameResultWhateverTheThreads) {
  const ToyObjective toy(2);
  SearchConfig c;
  c.budget_balls = 400;
  c.seed = 8;
  const SearchResult a = run_relay_race(toy, c);
  c.threads = 4;
  const SearchResult b = run_relay_race(toy, c);
  EXPECT_EQ(a.best_mean, b.best_mean);
  EXPECT_EQ(a.counters, b.counters);
}

}  // namespace
}  // namespace pinball::learn
