#include "pinball/sim/state_hash.h"

#include <cmath>

#include <gtest/gtest.h>

#include "test_boards.h"

namespace pinball::sim {
namespace {

using namespace pinball::sim::testing;

TEST(StateHash, EqualStatesHashEqualAndEveryFieldCounts) {
  table::Board b = box_with_bumpers_and_flippers();
  const GameState base = state_with_ball(b, {0.3, 0.5}, {1.0, -0.5});
  const std::uint64_t h = hash_state(base);
  EXPECT_EQ(h, hash_state(GameState(base)));

  auto differs = [&](auto mutate) {
    GameState s = base;
    mutate(s);
    return hash_state(s) != h;
  };
  EXPECT_TRUE(differs([](GameState& s) { s.ball.position_m.x() = std::nextafter(s.ball.position_m.x(), 1.0); }));
  EXPECT_TRUE(differs([](GameState& s) { s.ball.velocity_mps.y() += 1e-12; }));
  EXPECT_TRUE(differs([](GameState& s) { s.time_s += 5e-4; }));
  EXPECT_TRUE(differs([](GameState& s) { s.score += 1.0; }));
  EXPECT_TRUE(differs([](GameState& s) { s.flippers[0].theta_rad += 1e-9; }));
  EXPECT_TRUE(differs([](GameState& s) { s.flippers[1].energized = true; }));
  EXPECT_TRUE(differs([](GameState& s) { s.visible[0] = kHidden; }));
  EXPECT_TRUE(differs([](GameState& s) { s.ball_in_play = false; }));
}

TEST(StateHash, CombiningIsOrderSensitive) {
  table::Board b = box_board();
  const GameState a = state_with_ball(b, {0.3, 0.5}, {1.0, 0.0});
  const GameState c = state_with_ball(b, {0.4, 0.5}, {1.0, 0.0});
  EXPECT_NE(hash_combine_state(hash_state(a), c), hash_combine_state(hash_state(c), a));
}

// A cut puts the ball back in the launcher: two runs cut at the same moment
// with the same score left the same state, and `sim` printed one hash for
// every seed. The ball's end tells them apart.
TEST(StateHash, TheBallsEndTellsApartBallsCutAtTheSameMoment) {
  BallResult a;
  a.cut = true;
  a.end_position_m = {0.3, 0.5};
  a.end_velocity_mps = {1.0, -0.5};
  BallResult b = a;
  EXPECT_EQ(hash_combine_ball_end(1, a), hash_combine_ball_end(1, b));
  b.end_position_m.y() = std::nextafter(0.5, 1.0);
  EXPECT_NE(hash_combine_ball_end(1, a), hash_combine_ball_end(1, b));
  b = a;
  b.end_velocity_mps.x() += 1e-12;
  EXPECT_NE(hash_combine_ball_end(1, a), hash_combine_ball_end(1, b));
  b = a;
  b.cut = false;
  EXPECT_NE(hash_combine_ball_end(1, a), hash_combine_ball_end(1, b));
}

}  // namespace
}  // namespace pinball::sim
