#include "pinball/simlab/oracle_policy.h"

#include <gtest/gtest.h>

#include "sim/test_boards.h"

namespace pinball::simlab {
namespace {

using namespace pinball::sim::testing;

table::Board two_flippers() {
  table::Board b = empty_board(0.51, 1.07);
  add_flipper(b, table::Side::kLeft, {0.165, 0.16});
  add_flipper(b, table::Side::kRight, {0.345, 0.16});
  return b;
}

TEST(OracleSpasticPolicy, FlipsOnlyTheNearerFlipperForAFallingBallInReach) {
  const table::Board b = two_flippers();
  sim::GameState s = state_with_ball(b, {0.21, 0.16}, {0.0, -1.0});  // just above the left flipper
  oracle_spastic_policy(b, s);
  EXPECT_TRUE(s.flippers[0].energized);
  EXPECT_FALSE(s.flippers[1].energized);

  s.ball.position_m = {0.30, 0.16};  // just above the right one
  oracle_spastic_policy(b, s);
  EXPECT_FALSE(s.flippers[0].energized);
  EXPECT_TRUE(s.flippers[1].energized);
}

TEST(OracleSpasticPolicy, ReleasesForBallsOutOfReachRisingOrCradled) {
  const table::Board b = two_flippers();
  sim::GameState s = state_with_ball(b, {0.20, 0.60}, {0.0, -1.0});  // far above
  for (auto& f : s.flippers) f.energized = true;
  oracle_spastic_policy(b, s);
  EXPECT_FALSE(s.flippers[0].energized);
  EXPECT_FALSE(s.flippers[1].energized);

  s.ball.position_m = {0.21, 0.16};
  s.ball.velocity_mps = {0.0, 2.0};  // just flipped, going up
  oracle_spastic_policy(b, s);
  EXPECT_FALSE(s.flippers[0].energized);

  s.ball.velocity_mps = {0.0, 0.0};  // cradled: let it roll down instead of holding it forever
  oracle_spastic_policy(b, s);
  EXPECT_FALSE(s.flippers[0].energized);

  s.ball.velocity_mps = {0.0, -1.0};
  s.ball_in_play = false;  // waiting in the launcher
  oracle_spastic_policy(b, s);
  EXPECT_FALSE(s.flippers[0].energized);
}

}  // namespace
}  // namespace pinball::simlab
