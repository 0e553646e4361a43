#include "pinball/learn/lookahead_player.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/thesis_board.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/state_hash.h"

namespace pinball::learn {
namespace {

using pinball::testing::thesis_board;

// A ball falling onto the left flipper near its tip, towards the gap between the flippers.
sim::GameState ball_on_left_flipper(const table::Board& board) {
  sim::GameState s = sim::make_game_state(board, 3);
  s.ball_in_play = true;
  s.ball.position_m = Vec2(0.235, 0.190);
  s.ball.velocity_mps = Vec2(0.5, -1.5);
  return s;
}

LookaheadConfig short_planner() {
  LookaheadConfig c;
  c.fire_frames = 3;
  c.hold_frames = {6, 20};
  c.horizon_s = 1.0;
  return c;
}

TEST(LookaheadPlanner, CandidatesAreDontFireThenEveryFireFrameAndHold) {
  const sim::ThesisStepper stepper(thesis_board());
  LookaheadPlanner planner(stepper, short_planner());
  const sim::GameState s = ball_on_left_flipper(thesis_board());
  ASSERT_EQ(planner.decision_flipper(s), 0);
  const simlab::DelayLine delay(s.flippers.size(), 0.004);
  const auto& c = planner.evaluate(s, delay, 0);
  ASSERT_EQ(c.size(), 1u + 4u * 2u);
  EXPECT_EQ(c[0].fire_frame, -1);
  EXPECT_EQ(c[1].fire_frame, 0);
  EXPECT_EQ(c[1].hold_frames, 6);
  EXPECT_EQ(c[2].hold_frames, 20);
  EXPECT_EQ(c.back().fire_frame, 3);
  for (const LookaheadCandidate& k : c) {
    EXPECT_GT(k.length_s, 0.0);
    EXPECT_LE(k.length_s, 1.0 + 1e-9);
    EXPECT_DOUBLE_EQ(k.value, k.score - (k.lost ? short_planner().drain_penalty : 0.0));
  }
}

TEST(LookaheadPlanner, UnflippedBallOnTheFlipperDrainsAndTheBestPlanSavesIt) {
  const sim::ThesisStepper stepper(thesis_board());
  LookaheadPlanner planner(stepper, short_planner());
  const sim::GameState s = ball_on_left_flipper(thesis_board());
  const std::uint64_t before = sim::hash_state(s);
  const simlab::DelayLine delay(s.flippers.size(), 0.004);
  const auto& c = planner.evaluate(s, delay, 0);
  EXPECT_EQ(sim::hash_state(s), before) << "evaluate() must play on copies";
  EXPECT_TRUE(c[0].lost) << "a ball left on the resting flipper rolls off into the drain";
  const LookaheadCandidate& best = c[planner.best()];
  EXPECT_FALSE(best.lost);
  EXPECT_GE(best.fire_frame, 0);
  EXPECT_GT(best.value, c[0].value);
  for (const LookaheadCandidate& k : c) EXPECT_LE(k.value, best.value);
  EXPECT_GT(planner.branch_steps(), 0u);
}

// Each fire plan reads its shot where the ball rises off the bat through the
// shot line; with a shot-value table, a plan is worth its points to the shot
// plus the table's value there, and the best plan is the one whose shot the
// table prefers.
TEST(LookaheadPlanner, ReadsEachPlansShotAndValuesItByTheTable) {
  const sim::ThesisStepper stepper(thesis_board());
  LookaheadPlanner plain(stepper, short_planner());
  const sim::GameState s = ball_on_left_flipper(thesis_board());
  const simlab::DelayLine delay(s.flippers.size(), 0.004);
  const std::vector<LookaheadCandidate> c = plain.evaluate(s, delay, 0);
  std::vector<std::size_t> shots;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (c[i].shot_flipper < 0) continue;
    shots.push_back(i);
    EXPECT_EQ(c[i].shot_flipper, 0) << "the left bat shot";
    EXPECT_GT(c[i].shot_direction_deg, 0.0);
    EXPECT_LT(c[i].shot_direction_deg, 180.0);
    EXPECT_GT(c[i].shot_speed_mps, 0.0);
    EXPECT_LE(c[i].score_at_shot, c[i].score);
    EXPECT_FALSE(c[i].valued_by_table);
  }
  ASSERT_GE(shots.size(), 2u) << "several fire plans shoot";
  // The table likes only the last shooting plan's direction (within a bin).
  const LookaheadCandidate& liked = c[shots.back()];
  auto table = std::make_shared<ShotValueTable>(make_shot_value_table(2));
  table->min_weight = 1e-9;
  table->kernel_direction_deg = 0.5;
  for (double d = 1.0; d < 180.0; d += 2.0) {
    const bool near_liked = std::abs(d - liked.shot_direction_deg) < 1.0;
    add_shot(*table, 0, d, liked.shot_speed_mps, near_liked ? 100000.0 : -100000.0);
  }
  add_shot(*table, 0, liked.shot_direction_deg, liked.shot_speed_mps, 100000.0);
  smooth(*table);
  LookaheadConfig config = short_planner();
  config.shot_values = table;
  LookaheadPlanner valued(stepper, config);
  const auto& v = valued.evaluate(s, delay, 0);
  const LookaheadCandidate& best = v[valued.best()];
  EXPECT_TRUE(best.valued_by_table);
  EXPECT_NEAR(best.shot_direction_deg, liked.shot_direction_deg, 2.0);
  EXPECT_GT(best.value, 50000.0);
  EXPECT_DOUBLE_EQ(best.score, best.score_at_shot) << "a valued branch ends at its shot";
  EXPECT_LT(best.length_s, liked.length_s);
}

TEST(LookaheadPlanner, NoDecisionForARisingOrFarBall) {
  const sim::ThesisStepper stepper(thesis_board());
  const LookaheadPlanner planner(stepper, short_planner());
  sim::GameState s = ball_on_left_flipper(thesis_board());
  s.ball.velocity_mps = Vec2(0.0, 1.0);
  EXPECT_EQ(planner.decision_flipper(s), -1) << "rising";
  s.ball.velocity_mps = Vec2(0.0, -1.0);
  s.ball.position_m = Vec2(0.255, 0.8);
  EXPECT_EQ(planner.decision_flipper(s), -1) << "far up the table";
  s.ball.position_m = Vec2(0.310, 0.20);
  EXPECT_EQ(planner.decision_flipper(s), 1) << "over the right flipper";
}

TEST(LookaheadPlanner, AStepBudgetShortensEveryBranchAlikeAndBoundsTheDecision) {
  const sim::ThesisStepper stepper(thesis_board());
  const sim::GameState s = ball_on_left_flipper(thesis_board());
  const simlab::DelayLine delay(s.flippers.size(), 0.004);
  LookaheadPlanner unbounded(stepper, short_planner());
  EXPECT_EQ(unbounded.max_branch_steps(), 2000u) << "1 s of 0.5 ms steps";
  LookaheadConfig c = short_planner();
  c.step_budget = 9 * 100 + 5;  // 9 candidates: 100 steps (50 ms) each, the rest unused
  LookaheadPlanner bounded(stepper, c);
  ASSERT_EQ(bounded.max_branch_steps(), 100u);
  const auto& k = bounded.evaluate(s, delay, 0);
  EXPECT_LE(bounded.branch_steps(), 900u);
  for (const LookaheadCandidate& b : k) EXPECT_LE(b.length_s, 0.050 + 1e-9);
  EXPECT_FALSE(k[0].lost) << "50 ms is too short to see the ball drain";
  // A budget above what the horizon needs changes nothing.
  c.step_budget = 1'000'000;
  LookaheadPlanner roomy(stepper, c);
  EXPECT_EQ(roomy.max_branch_steps(), 2000u);
  const auto& a = roomy.evaluate(s, delay, 0);
  const auto& b = unbounded.evaluate(s, delay, 0);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].value, b[i].value);
  c.step_budget = 8;  // less than a step per candidate
  EXPECT_THROW(LookaheadPlanner(stepper, c), std::invalid_argument);
}

TEST(LookaheadPlanner, RejectsBadSettings) {
  const sim::ThesisStepper stepper(thesis_board());
  LookaheadConfig c = short_planner();
  c.hold_frames.clear();
  EXPECT_THROW(LookaheadPlanner(stepper, c), std::invalid_argument);
  c = short_planner();
  c.frame_steps = 0;
  EXPECT_THROW(LookaheadPlanner(stepper, c), std::invalid_argument);
  c = short_planner();
  c.step_budget = -1;
  EXPECT_THROW(LookaheadPlanner(stepper, c), std::invalid_argument);
}

TEST(LookaheadPlayer, ReportsEachFireWithItsHoldAndReleasesAfterIt) {
  const sim::ThesisStepper stepper(thesis_board());
  LookaheadPlayer player(stepper, short_planner(), 0.004);
  sim::GameState s = ball_on_left_flipper(thesis_board());
  int fires = 0;
  int steps_held = 0;
  for (int i = 0; i < 400 && s.ball_in_play; ++i) {
    player.act(s);
    if (player.fired_flipper() >= 0) {
      ++fires;
      EXPECT_EQ(player.fired_flipper(), 0);
      EXPECT_TRUE(std::abs(player.fired_hold_s() - 0.030) < 1e-12 || std::abs(player.fired_hold_s() - 0.100) < 1e-12)
          << player.fired_hold_s();
    }
    if (s.flippers[0].energized) ++steps_held;
    stepper.step(s);
  }
  EXPECT_GE(fires, 1) << "the ball on the flipper must be saved";
  EXPECT_GT(steps_held, 0);
  EXPECT_GT(player.decisions(), 0);
}

}  // namespace
}  // namespace pinball::learn
