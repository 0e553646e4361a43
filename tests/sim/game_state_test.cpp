#include "pinball/sim/game_state.h"

#include <gtest/gtest.h>

#include "test_boards.h"

namespace pinball::sim {
namespace {

using namespace pinball::sim::testing;

table::Board small_board() {
  table::Board b = box_board();
  add_circle(b, {0.2, 0.6}, 0.03);
  add_circle(b, {0.3, 0.6}, 0.03);
  b.obstacles.back().visible = false;
  add_flipper(b, table::Side::kLeft, {0.15, 0.2}, 0.076, -0.4, 0.5);
  add_flipper(b, table::Side::kRight, {0.36, 0.2}, 0.076, -0.45, 0.5);
  table::Sensor s;
  s.kind = table::SensorKind::kProximity;
  s.shape.kind = table::ShapeKind::kCircle;
  s.shape.p0 = {0.25, 0.8};
  s.shape.radius_m = 0.02;
  b.sensors.push_back(s);
  b.balls_per_game = 5;
  b.launcher.position = {0.48, 0.04};
  return b;
}

TEST(MakeGameState, SizesAndInitialValues) {
  const table::Board b = small_board();
  const GameState s = make_game_state(b, 9);
  ASSERT_EQ(s.flippers.size(), 2u);
  ASSERT_EQ(s.visible.size(), b.obstacles.size());
  ASSERT_EQ(s.sensor_inside.size(), 1u);
  EXPECT_EQ(s.flippers[0].theta_rad, -0.4);
  EXPECT_EQ(s.flippers[1].theta_rad, -0.45);
  for (const FlipperState& f : s.flippers) {
    EXPECT_FALSE(f.energized);
    EXPECT_FALSE(f.was_energized);
    EXPECT_FALSE(f.ball_contact);
    EXPECT_EQ(f.omega_rad_s, 0.0);
  }
  for (std::size_t i = 0; i + 1 < s.visible.size(); ++i) EXPECT_EQ(s.visible[i], 1) << i;
  EXPECT_EQ(s.visible.back(), 0);
  EXPECT_EQ(s.sensor_inside[0], 0);
  EXPECT_EQ(s.balls_left, 5);
  EXPECT_EQ(s.score, 0.0);
  EXPECT_FALSE(s.ball_in_play);
  EXPECT_EQ(s.ball.position_m, b.launcher.position);
  EXPECT_EQ(s.ball.velocity_mps, Vec2(Vec2::Zero()));
  EXPECT_EQ(s.time_s, 0.0);
  EXPECT_EQ(s.steps, 0u);
  EXPECT_EQ(s.flips, 0u);
  // The seed is the stream's seed.
  GameState copy = s;
  Rng ref(9);
  EXPECT_EQ(copy.rng.next_u64(), ref.next_u64());
}

TEST(ResetGame, RestoresVisibilityBallsScoreAndFlippers) {
  const table::Board b = small_board();
  GameState s = make_game_state(b, 3);
  s.score = 1234.0;
  s.balls_left = 1;
  s.ball_in_play = true;
  s.ball.position_m = {0.1, 0.9};
  s.ball.velocity_mps = {1.0, -2.0};
  s.visible[4] = 0;
  s.visible[5] = 1;
  s.sensor_inside[0] = 1;
  s.flippers[0] = FlipperState{0.5, 33.0, true, true, true};
  s.rng.next_u64();
  Rng expected_stream = s.rng;
  reset_game(b, s);
  EXPECT_EQ(s.score, 0.0);
  EXPECT_EQ(s.balls_left, 5);
  EXPECT_FALSE(s.ball_in_play);
  EXPECT_EQ(s.ball.position_m, b.launcher.position);
  EXPECT_EQ(s.ball.velocity_mps, Vec2(Vec2::Zero()));
  EXPECT_EQ(s.visible[4], 1);
  EXPECT_EQ(s.visible[5], 0);
  EXPECT_EQ(s.sensor_inside[0], 0);
  EXPECT_EQ(s.flippers[0].theta_rad, -0.4);
  EXPECT_EQ(s.flippers[0].omega_rad_s, 0.0);
  EXPECT_FALSE(s.flippers[0].energized);
  EXPECT_FALSE(s.flippers[0].ball_contact);
  // The random stream keeps going rather than restarting.
  EXPECT_EQ(s.rng.next_u64(), expected_stream.next_u64());
}

TEST(LaunchBall, PlacesBallAndDrawsSpeed) {
  const table::Board b = small_board();
  GameState s = make_game_state(b, 3);
  s.ball.position_m = {0.2, 0.2};
  Rng mirror = s.rng;
  launch_ball(b, s, 0.8);
  EXPECT_TRUE(s.ball_in_play);
  EXPECT_EQ(s.ball.position_m, b.launcher.position);
  EXPECT_EQ(s.ball.velocity_mps.x(), 0.0);
  const double r = mirror.uniform(0.0, b.launcher.noise_max);
  EXPECT_DOUBLE_EQ(s.ball.velocity_mps.y(), 0.8 * (1.0 - r) * b.ball.speed_max_mps);
}

}  // namespace
}  // namespace pinball::sim
