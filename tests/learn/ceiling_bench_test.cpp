#include "ceiling_bench.h"

#include <gtest/gtest.h>

#include "common/thesis_board.h"
#include "pinball/sim/state_hash.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

// A ball falling onto the left flipper near its tip, towards the gap between the flippers.
sim::GameState ball_on_left_flipper(const sim::Board& board) {
  sim::GameState s = sim::make_game_state(board, 3);
  s.ball_in_play = true;
  s.ball.position_m = Vec2(0.235, 0.190);
  s.ball.velocity_mps = Vec2(0.5, -1.5);
  return s;
}

CeilingPlannerConfig short_planner() {
  CeilingPlannerConfig c;
  c.fire_frames = 3;
  c.hold_frames = {6, 20};
  c.horizon_s = 1.0;
  return c;
}

TEST(CeilingPlanner, CandidatesAreDontFireThenEveryFireFrameAndHold) {
  const sim::ThesisStepper stepper(thesis_board());
  CeilingPlanner planner(stepper, short_planner());
  const sim::GameState s = ball_on_left_flipper(thesis_board());
  ASSERT_EQ(planner.decision_flipper(s), 0);
  const learn::DelayLine delay(s.flippers.size(), 0.004);
  const auto& c = planner.evaluate(s, delay, 0);
  ASSERT_EQ(c.size(), 1u + 4u * 2u);
  EXPECT_EQ(c[0].fire_frame, -1);
  EXPECT_EQ(c[1].fire_frame, 0);
  EXPECT_EQ(c[1].hold_frames, 6);
  EXPECT_EQ(c[2].hold_frames, 20);
  EXPECT_EQ(c.back().fire_frame, 3);
  for (const CeilingCandidate& k : c) {
    EXPECT_GT(k.length_s, 0.0);
    EXPECT_LE(k.length_s, 1.0 + 1e-9);
    EXPECT_DOUBLE_EQ(k.value, k.score - (k.lost ? short_planner().drain_penalty : 0.0));
  }
}

TEST(CeilingPlanner, UnflippedBallOnTheFlipperDrainsAndTheBestPlanSavesIt) {
  const sim::ThesisStepper stepper(thesis_board());
  CeilingPlanner planner(stepper, short_planner());
  const sim::GameState s = ball_on_left_flipper(thesis_board());
  const std::uint64_t before = sim::hash_state(s);
  const learn::DelayLine delay(s.flippers.size(), 0.004);
  const auto& c = planner.evaluate(s, delay, 0);
  EXPECT_EQ(sim::hash_state(s), before) << "evaluate() must play on copies";
  EXPECT_TRUE(c[0].lost) << "a ball left on the resting flipper rolls off into the drain";
  const CeilingCandidate& best = c[planner.best()];
  EXPECT_FALSE(best.lost);
  EXPECT_GE(best.fire_frame, 0);
  EXPECT_GT(best.value, c[0].value);
  for (const CeilingCandidate& k : c) EXPECT_LE(k.value, best.value);
  EXPECT_GT(planner.branch_steps(), 0u);
}

TEST(CeilingPlanner, NoDecisionForARisingOrFarBall) {
  const sim::ThesisStepper stepper(thesis_board());
  const CeilingPlanner planner(stepper, short_planner());
  sim::GameState s = ball_on_left_flipper(thesis_board());
  s.ball.velocity_mps = Vec2(0.0, 1.0);
  EXPECT_EQ(planner.decision_flipper(s), -1) << "rising";
  s.ball.velocity_mps = Vec2(0.0, -1.0);
  s.ball.position_m = Vec2(0.255, 0.8);
  EXPECT_EQ(planner.decision_flipper(s), -1) << "far up the table";
  s.ball.position_m = Vec2(0.310, 0.20);
  EXPECT_EQ(planner.decision_flipper(s), 1) << "over the right flipper";
}

TEST(CeilingPlanner, RejectsBadSettings) {
  const sim::ThesisStepper stepper(thesis_board());
  CeilingPlannerConfig c = short_planner();
  c.hold_frames.clear();
  EXPECT_THROW(CeilingPlanner(stepper, c), std::invalid_argument);
  c = short_planner();
  c.frame_steps = 0;
  EXPECT_THROW(CeilingPlanner(stepper, c), std::invalid_argument);
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
  const sim::ThesisStepper stepper(thesis_board());
  const CeilingBenchOptions o = tiny_bench();
  const CeilingBall a = play_ceiling_bench_ball(stepper, o, CeilingPlayerKind::kCeiling, 17);
  const CeilingBall b = play_ceiling_bench_ball(stepper, o, CeilingPlayerKind::kCeiling, 17);
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
                             std::pair{&r1.no_flipping, &r2.no_flipping}}) {
    EXPECT_EQ(p->score.mean(), q->score.mean()) << p->name;
    EXPECT_EQ(p->flips.mean(), q->flips.mean()) << p->name;
    EXPECT_EQ(p->cut, q->cut) << p->name;
  }
}

TEST(CeilingBench, ReportCountsEveryBallAndPrintsOneJsonObject) {
  int lines = 0;
  const CeilingReport r = run_ceiling_bench(thesis_board(), tiny_bench(), [&](const std::string&) { ++lines; });
  EXPECT_EQ(lines, 9) << "3 balls x 3 players";
  for (const CeilingPlayerReport* p : {&r.ceiling, &r.spastic, &r.no_flipping}) {
    EXPECT_EQ(p->score.count(), 3) << p->name;
    EXPECT_EQ(p->cut + p->drains_left_outlane + p->drains_elsewhere, 3) << p->name;
    EXPECT_LE(p->left_table, p->drains_left_outlane + p->drains_elsewhere) << p->name;
    EXPECT_LE(p->duration_s.max(), 8.0 + 1e-9) << p->name;
  }
  EXPECT_EQ(r.no_flipping.flips.mean(), 0.0);
  EXPECT_EQ(r.no_flipping.decisions_per_ball, 0.0);
  EXPECT_GT(r.ceiling.branch_steps_per_ball, 0.0);
  EXPECT_DOUBLE_EQ(r.ceiling_over_spastic, r.ceiling.score.mean() / r.spastic.score.mean());
  const nlohmann::json j = to_json(r);
  for (const char* k : {"benchmark", "board", "balls", "seed", "planner", "players", "ceiling_over_spastic"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  for (const char* p : {"ceiling", "spastic", "no_flipping"}) {
    for (const char* k : {"mean_score_per_ball", "score_ci95_half_width", "mean_ball_time_s", "flips_per_ball",
                          "balls_cut_at_time_limit", "drains_left_outlane", "drains_elsewhere", "wall_s"}) {
      EXPECT_TRUE(j.at("players").at(p).contains(k)) << p << "." << k;
    }
  }
  EXPECT_NE(to_text(r).find("CHEATS"), std::string::npos);
}

}  // namespace
}  // namespace pinball::bench
