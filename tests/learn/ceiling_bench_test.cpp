#include "ceiling_bench.h"

#include "pinball/sim/model_world.h"

#include <gtest/gtest.h>

#include "common/thesis_board.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

learn::LookaheadConfig short_planner() {
  learn::LookaheadConfig c;
  c.fire_frames = 3;
  c.hold_frames = {6, 20};
  c.horizon_s = 1.0;
  return c;
}

CeilingBenchOptions tiny_bench() {
  CeilingBenchOptions o;
  o.balls = 3;
  o.seed = 5;
  o.max_ball_time_s = 8.0;
  o.planner = short_planner();
  return o;
}

TEST(CeilingBench, SameSeedSameBallWhateverTheThreads) {
  const sim::ThesisStepper model(thesis_board());
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  const CeilingBenchOptions o = tiny_bench();
  const CeilingBall a = play_ceiling_bench_ball(*world, model, o, CeilingPlayerKind::kCeiling, 17);
  const CeilingBall b = play_ceiling_bench_ball(*world->fork(), model, o, CeilingPlayerKind::kCeiling, 17);
  EXPECT_EQ(a.score, b.score);
  EXPECT_EQ(a.duration_s, b.duration_s);
  EXPECT_EQ(a.flips, b.flips);
  EXPECT_EQ(a.branch_steps, b.branch_steps);
  EXPECT_GT(a.decisions, 0);

  CeilingBenchOptions one = o;
  one.threads = 1;
  const CeilingReport r1 = run_ceiling_bench(thesis_board(), one, {});
  const CeilingReport r2 = run_ceiling_bench(thesis_board(), o, {});
  for (const auto& [p, q] : {std::pair{&r1.ceiling, &r2.ceiling}, std::pair{&r1.spastic, &r2.spastic},
                             std::pair{&r1.no_flipping, &r2.no_flipping},
                             std::pair{&r1.tracker_spastic, &r2.tracker_spastic}}) {
    EXPECT_EQ(p->score.mean(), q->score.mean()) << p->name;
    EXPECT_EQ(p->flips.mean(), q->flips.mean()) << p->name;
    EXPECT_EQ(p->cut, q->cut) << p->name;
  }
}

TEST(CeilingBench, ReportCountsEveryBallAndPrintsOneJsonObject) {
  int lines = 0;
  // A controller file's player through the tracker: an action function that fires early on every approach.
  control::ControllerSpec spec;
  for (int i = 0; i < spec.action_function.partitions(); ++i) {
    spec.action_function.minicontroller(i) = control::Minicontroller{{0.0, 0.0, 0.0, 0.05}, i < 4 ? 0 : 1};
  }
  CeilingBenchOptions o = tiny_bench();
  o.controller = &spec;
  o.controller_name = "early.json";
  const CeilingReport r = run_ceiling_bench(thesis_board(), o, [&](const std::string&) { ++lines; });
  EXPECT_EQ(lines, 15) << "3 balls x 5 players";
  ASSERT_TRUE(r.controller.has_value());
  for (const CeilingPlayerReport* p : {&r.ceiling, &r.spastic, &r.no_flipping, &r.tracker_spastic, &*r.controller}) {
    EXPECT_EQ(p->score.count(), 3) << p->name;
    EXPECT_EQ(p->cut + p->drains.total(), 3) << p->name;
    EXPECT_LE(p->drains.left_table, p->drains.total()) << p->name;
    EXPECT_LE(p->duration_s.max(), 8.0 + 1e-9) << p->name;
  }
  EXPECT_EQ(r.no_flipping.flips.mean(), 0.0);
  EXPECT_EQ(r.no_flipping.decisions_per_ball, 0.0);
  EXPECT_GT(r.ceiling.branch_steps_per_ball, 0.0);
  EXPECT_DOUBLE_EQ(r.ceiling_over_spastic, r.ceiling.score.mean() / r.spastic.score.mean());
  EXPECT_DOUBLE_EQ(r.ceiling_over_tracker_spastic, r.ceiling.score.mean() / r.tracker_spastic.score.mean());
  EXPECT_DOUBLE_EQ(r.controller_over_tracker_spastic, r.controller->score.mean() / r.tracker_spastic.score.mean());
  EXPECT_GT(r.controller->flips.mean(), 0.0);
  const nlohmann::json j = to_json(r);
  for (const char* k : {"benchmark", "board", "balls", "seed", "planner", "players", "ceiling_over_spastic"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  EXPECT_EQ(j.at("controller"), "early.json");
  EXPECT_DOUBLE_EQ(j.at("controller_over_tracker_spastic").get<double>(), r.controller_over_tracker_spastic);
  EXPECT_TRUE(j.at("controller_true_state_over_tracker_spastic").is_null()) << "not played: no ratio of 0";
  for (const char* p : {"ceiling", "spastic", "no_flipping", "tracker_spastic", "controller"}) {
    for (const char* k : {"mean_score_per_ball", "score_ci95_half_width", "mean_ball_time_s", "flips_per_ball",
                          "balls_cut_at_time_limit", "drains_left_outlane", "drains_elsewhere", "drains_centre", "wall_s"}) {
      EXPECT_TRUE(j.at("players").at(p).contains(k)) << p << "." << k;
    }
  }
  EXPECT_NE(to_text(r).find("CHEATS"), std::string::npos);
  EXPECT_NE(to_text(r).find("controller (early.json) / spastic through the tracker"), std::string::npos);
}

TEST(CeilingBench, ThePlannerFedTheTrueStatePlaysBesideItAndItsNoiseMatters) {
  control::ControllerSpec spec;
  spec.planner = control::PlannerSettings{};
  spec.planner->fire_frames = 3;
  spec.planner->horizon_s = 1.0;
  CeilingBenchOptions o = tiny_bench();
  o.controller = &spec;
  o.controller_name = "planner.json";
  o.true_state_feed = CeilingBenchOptions::TrueStateFeed{};
  const CeilingReport exact = run_ceiling_bench(thesis_board(), o, {});
  ASSERT_TRUE(exact.controller_true_state.has_value());
  EXPECT_EQ(exact.controller_true_state->score.count(), 3);
  EXPECT_GT(exact.controller_true_state->flips.mean(), 0.0);
  EXPECT_DOUBLE_EQ(exact.controller_true_state_over_tracker_spastic,
                   exact.controller_true_state->score.mean() / exact.tracker_spastic.score.mean());
  const nlohmann::json j = to_json(exact);
  EXPECT_TRUE(j.at("players").contains("controller_true_state"));
  EXPECT_EQ(j.at("true_state_feed").at("position_noise_m"), 0.0);
  EXPECT_NE(to_text(exact).find("controller fed the true state"), std::string::npos);

  // The same balls again: the same play; with 5 mm and 0.1 m/s of noise: another.
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  const sim::ThesisStepper model(thesis_board());
  const CeilingBall a = play_ceiling_bench_ball(*world, model, o, CeilingPlayerKind::kControllerTrueState, 17);
  const CeilingBall b = play_ceiling_bench_ball(*world->fork(), model, o, CeilingPlayerKind::kControllerTrueState, 17);
  EXPECT_EQ(a.score, b.score);
  EXPECT_EQ(a.duration_s, b.duration_s);
  CeilingBenchOptions noisy = o;
  noisy.true_state_feed = CeilingBenchOptions::TrueStateFeed{0.005, 0.1};
  bool differs = false;
  for (std::uint64_t seed = 17; seed < 27 && !differs; ++seed) {
    const CeilingBall x = play_ceiling_bench_ball(*world->fork(), model, o, CeilingPlayerKind::kControllerTrueState, seed);
    const CeilingBall y = play_ceiling_bench_ball(*world->fork(), model, noisy, CeilingPlayerKind::kControllerTrueState, seed);
    differs = x.score != y.score || x.duration_s != y.duration_s || x.flips != y.flips;
  }
  EXPECT_TRUE(differs) << "the noise reached the controller";

  CeilingBenchOptions bad = o;
  bad.true_state_feed->velocity_noise_mps = -1.0;
  EXPECT_THROW(run_ceiling_bench(thesis_board(), bad, {}), std::invalid_argument);
  bad = o;
  bad.controller = nullptr;
  EXPECT_THROW(run_ceiling_bench(thesis_board(), bad, {}), std::invalid_argument) << "nothing to feed";
  // A controller that acts on the projection would never fire on the feed: refused, not scored.
  control::ControllerSpec table_spec;
  table_spec.spastic = control::SpasticConfig{};
  bad = o;
  bad.controller = &table_spec;
  EXPECT_THROW(run_ceiling_bench(thesis_board(), bad, {}), std::invalid_argument) << "not a planner";
}

}  // namespace
}  // namespace pinball::bench
