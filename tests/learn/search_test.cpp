#include "pinball/learn/search.h"

#include <gtest/gtest.h>

#include "toy_objective.h"

namespace pinball::learn {
namespace {

using testing_support::ToyObjective;

// Balls are cut (a cycle) whenever partition 0 fires the right flipper.
struct CyclingToy final : BallObjective {
  BallOutcome play(const control::ControllerSpec& s, std::uint64_t) const override {
    BallOutcome o;
    o.cut = s.action_function.minicontroller(0).flipper == 1;
    o.score = o.cut ? 1e6 : 1.0;
    return o;
  }
  control::ControllerSpec prototype() const override { return {}; }
};

TEST(SearchRun, CountsBallsKeepsTheBestAndReportsCyclesAtOnce) {
  const CyclingToy toy;
  int reported = 0;
  SearchConfig c;
  c.budget_balls = 10;
  c.on_cycle = [&](const control::ControllerSpec& s, const BallOutcome& o) {
    ++reported;
    EXPECT_EQ(s.action_function.minicontroller(0).flipper, 1);
    EXPECT_TRUE(o.cut);
  };
  SearchRun run(toy, c, "test");
  control::ControllerSpec plain = toy.prototype();
  control::ControllerSpec cycling = plain;
  cycling.action_function.minicontroller(0).flipper = 1;
  run.play({{&plain, run.fresh_seed()}, {&cycling, run.fresh_seed()}, {&plain, run.fresh_seed()}});
  EXPECT_EQ(reported, 1);
  EXPECT_EQ(run.balls_left(), 7u);
  run.offer(plain, 5.0, 1);
  run.offer(cycling, 3.0, 1);
  EXPECT_EQ(run.best_mean(), 5.0);
  run.end_generation(4.0, 5.0);
  const SearchResult r = run.finish();
  EXPECT_TRUE(r.cycle_found);
  EXPECT_EQ(r.cycle_controller.action_function.minicontroller(0).flipper, 1);
  EXPECT_EQ(r.balls_used, 3u);
  ASSERT_EQ(r.curve.size(), 1u);
  EXPECT_EQ(r.curve[0].best_so_far, 5.0);
}

TEST(SearchRun, SeedControllerFindsOneThatScores) {
  const ToyObjective toy(2, 0.0);
  SearchConfig c;
  c.budget_balls = 1000;
  c.seed_min_score = 0.0;  // better than the typical random controller
  SearchRun run(toy, c, "seed");
  const control::ControllerSpec s = seed_controller(run, toy.prototype());
  EXPECT_GE(toy.expected(s), 0.0);
  EXPECT_LE(run.balls_left(), 1000u);
}

}  // namespace
}  // namespace pinball::learn
