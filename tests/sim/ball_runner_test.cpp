#include "pinball/sim/model_world.h"
#include "pinball/sim/ball_runner.h"

#include <gtest/gtest.h>

#include "common/ball_radius.h"

#include <cmath>

#include "test_boards.h"

namespace pinball::sim {
namespace {

using namespace pinball::sim::testing;

using pinball::testing::kR;

auto none_policy = [](GameState&) {};
auto no_observer = [](const GameState&, const StepEvents&) {};

// A small closed table whose floor eats the ball; launcher in the middle.
table::Board drain_board() {
  table::Board b = empty_board(0.4, 0.6, 1.11, 5e-4);
  b.ball.speed_max_mps = 2.0;
  table::Action drain;
  drain.eats_ball = true;
  add_line(b, {0.0, 0.0}, {0.4, 0.0}, 1.0, drain, "drain");
  add_line(b, {0.4, 0.0}, {0.4, 0.6}, 1.0);
  add_line(b, {0.4, 0.6}, {0.0, 0.6}, 1.0);
  add_line(b, {0.0, 0.6}, {0.0, 0.0}, 1.0);
  b.launcher.position = {0.2, 0.1};
  b.launcher.pull = 0.5;
  return b;
}

TEST(PlayBall, NonePolicyLosesBallInDrain) {
  const table::Board b = drain_board();
  const std::unique_ptr<World> world = make_model_world(b);
  GameState s = make_game_state(b, 5);
  BallLimits limits;
  limits.max_ball_time_s = 60.0;
  int observed_steps = 0;
  bool saw_loss = false;
  const BallResult r = play_ball(*world, s, limits, none_policy, [&](const GameState&, const StepEvents& ev) {
    if (ev.has(StepEvents::kLaunch)) return;  // launches are reported to the observer too
    ++observed_steps;
    saw_loss = saw_loss || ev.has(StepEvents::kBallLost);
  });
  EXPECT_FALSE(r.cut);
  EXPECT_FALSE(r.left_table);
  EXPECT_TRUE(saw_loss);
  EXPECT_EQ(r.launches, 1);
  EXPECT_EQ(r.flips, 0);
  EXPECT_EQ(static_cast<std::uint64_t>(observed_steps), r.steps);
  EXPECT_FALSE(s.ball_in_play);
  EXPECT_EQ(s.balls_left, b.balls_per_game - 1);
  // Launched up at ~1 m/s from 0.1 m: up and back down to the drain, t = (v + sqrt(v² + 2 g (0.1 - r))) / g.
  const double v = s.ball.velocity_mps.y();  // reset to zero at loss
  EXPECT_EQ(v, 0.0);
  const double v_lo = 0.5 * (1.0 - 0.03) * 2.0;
  const double v_hi = 0.5 * 2.0;
  const double g = 1.11;
  const double h = 0.1 - kR;
  EXPECT_GT(r.duration_s, (v_lo + std::sqrt(v_lo * v_lo + 2.0 * g * h)) / g - 0.01);
  EXPECT_LT(r.duration_s, (v_hi + std::sqrt(v_hi * v_hi + 2.0 * g * h)) / g + 0.01);
  EXPECT_NEAR(r.duration_s, r.steps * world->dt_s(), 1e-9);
  EXPECT_EQ(r.score, 0.0);
}

TEST(PlayBall, BouncyFloorWithoutDrainIsCut) {
  table::Board b = drain_board();
  b.obstacles[0].action.eats_ball = false;  // a plain floor, rho 1
  const std::unique_ptr<World> world = make_model_world(b);
  GameState s = make_game_state(b, 5);
  BallLimits limits;
  limits.max_ball_time_s = 3.0;
  GameState last;  // the state the last step left, before the cut
  const BallResult r = play_ball(*world, s, limits, none_policy, [&](const GameState& st, const StepEvents&) {
    last = st;
  });
  EXPECT_TRUE(r.cut);
  EXPECT_FALSE(r.left_table);
  EXPECT_NEAR(r.duration_s, 3.0, world->dt_s() + 1e-9);
  EXPECT_GE(r.duration_s, 3.0);
  EXPECT_FALSE(s.ball_in_play);
  EXPECT_EQ(s.balls_left, b.balls_per_game - 1);
  EXPECT_EQ(s.ball.position_m, b.launcher.position);
  // Where the ball was when it was cut, not where the cut put it.
  EXPECT_EQ(r.end_position_m, last.ball.position_m);
  EXPECT_EQ(r.end_velocity_mps, last.ball.velocity_mps);
  EXPECT_NE(r.end_position_m, b.launcher.position);
}

TEST(PlayBall, WeakLaunchRollsBackAndIsRelaunched) {
  // A vertical chute with a damped floor just under the launcher: a weak
  // launch rises 3 cm and falls back to rest in the launcher.
  table::Board b = empty_board(0.4, 0.6, 1.11, 5e-4);
  b.ball.speed_max_mps = 5.0;
  add_line(b, {0.25, 0.0}, {0.35, 0.0}, 0.2, {}, "chute floor");
  add_wall(b, {0.2865 - 0.001, 0.0}, {0.2865 - 0.001, 0.5}, 0.5);
  add_wall(b, {0.3135 + 0.001, 0.0}, {0.3135 + 0.001, 0.5}, 0.5);
  b.launcher.position = {0.3, kR + 1e-6};
  b.launcher.pull = 0.05;  // 0.25 m/s
  const std::unique_ptr<World> world = make_model_world(b);
  GameState s = make_game_state(b, 5);
  BallLimits limits;
  limits.max_ball_time_s = 5.0;
  const BallResult r = play_ball(*world, s, limits, none_policy, no_observer);
  EXPECT_GT(r.launches, 1);
  EXPECT_TRUE(r.cut);
  // Each launch lasts at least the flight 2·v/g = 0.44 s, so at most ~12 in 5 s.
  EXPECT_LE(r.launches, 13);
}

TEST(PlayBall, FlipsCountRisingEdges) {
  table::Board b = drain_board();
  b.obstacles[0].action.eats_ball = false;
  add_flipper(b, table::Side::kLeft, {0.1, 0.3}, 0.076, -0.5, 0.5, 33.0, 0.5, 1.0);
  add_flipper(b, table::Side::kRight, {0.3, 0.3}, 0.076, -0.5, 0.5, 33.0, 0.5, 1.0);
  const std::unique_ptr<World> world = make_model_world(b);
  GameState s = make_game_state(b, 5);
  BallLimits limits;
  limits.max_ball_time_s = 2.0;
  int step = 0;
  int rising = 0;
  bool prev0 = false;
  bool prev1 = false;
  const BallResult r = play_ball(
      *world, s, limits,
      [&](GameState& st) {
        // Left: pressed 30 steps of every 100. Right: held from step 500 on, never released.
        const bool on0 = step % 100 < 30;
        const bool on1 = step >= 500;
        rising += (on0 && !prev0) ? 1 : 0;
        rising += (on1 && !prev1) ? 1 : 0;
        prev0 = on0;
        prev1 = on1;
        st.flippers[0].energized = on0;
        st.flippers[1].energized = on1;
        ++step;
      },
      no_observer);
  ASSERT_TRUE(r.cut);
  EXPECT_EQ(static_cast<std::uint64_t>(step), r.steps);
  // 2 s of 5e-4 s steps: 4000 (4001 if the summed clock rounds just under 2 s).
  ASSERT_GE(step, 4000);
  ASSERT_LE(step, 4001);
  EXPECT_EQ(rising, 40 + 1 + (step == 4001 ? 1 : 0));
  EXPECT_EQ(r.flips, rising);
  for (const FlipperState& f : s.flippers) EXPECT_FALSE(f.energized);  // released at the end
}

TEST(BallRunner, BeginBallStartsNewGameWhenNoneLeft) {
  const table::Board b = drain_board();
  GameState s = make_game_state(b, 1);
  s.balls_left = 0;
  s.score = 99.0;
  begin_ball(*make_model_world(b), s, 0.5);
  EXPECT_EQ(s.balls_left, b.balls_per_game);
  EXPECT_EQ(s.score, 0.0);
  EXPECT_TRUE(s.ball_in_play);
  EXPECT_GT(s.ball.velocity_mps.y(), 0.0);
}

TEST(BallRunner, RestingInLauncher) {
  const table::Board b = drain_board();
  GameState s = make_game_state(b, 1);
  s.ball_in_play = true;
  s.ball.position_m = b.launcher.position + Vec2{0.005, 0.0};
  s.ball.velocity_mps = {0.0, 0.01};
  EXPECT_TRUE(resting_in_launcher(b, s));
  s.ball.velocity_mps = {0.0, 0.5};
  EXPECT_FALSE(resting_in_launcher(b, s));
  s.ball.velocity_mps = Vec2::Zero();
  s.ball.position_m = b.launcher.position + Vec2{0.05, 0.0};
  EXPECT_FALSE(resting_in_launcher(b, s));
  s.ball.position_m = b.launcher.position;
  s.ball_in_play = false;
  EXPECT_FALSE(resting_in_launcher(b, s));
}

}  // namespace
}  // namespace pinball::sim
