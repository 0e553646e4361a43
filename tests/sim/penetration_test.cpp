#include "pinball/sim/penetration.h"

#include <gtest/gtest.h>

#include "common/ball_radius.h"

#include <cmath>
#include <vector>

#include "test_boards.h"

namespace pinball::sim {
namespace {

using testing::add_circle;
using testing::add_flipper;
using testing::add_line;
using testing::add_point;
using testing::empty_board;

using pinball::testing::kR;

TEST(ShapePenetration, LineFrontFaceOnly) {
  table::Board b = empty_board();
  add_line(b, {0.0, 0.0}, {1.0, 0.0});  // normal +y
  const table::Shape& s = b.shapes[0];
  EXPECT_DOUBLE_EQ(shape_penetration_m(s, {0.5, 0.01}, kR), kR - 0.01);
  EXPECT_DOUBLE_EQ(shape_penetration_m(s, {0.5, 0.0}, kR), kR);
  EXPECT_EQ(shape_penetration_m(s, {0.5, kR}, kR), 0.0);        // touching
  EXPECT_EQ(shape_penetration_m(s, {0.5, 0.5}, kR), 0.0);       // apart
  EXPECT_EQ(shape_penetration_m(s, {0.5, -0.005}, kR), 0.0);    // behind: passing through
  EXPECT_EQ(shape_penetration_m(s, {1.005, 0.005}, kR), 0.0);   // beyond the end (the end point's business)
  EXPECT_EQ(shape_penetration_m(s, {-0.005, 0.005}, kR), 0.0);
}

TEST(ShapePenetration, CircleAndPoint) {
  table::Board b = empty_board();
  add_circle(b, {0.5, 0.5}, 0.03);
  add_point(b, {0.2, 0.2});
  EXPECT_NEAR(shape_penetration_m(b.shapes[0], {0.5, 0.54}, kR), 0.03 + kR - 0.04, 1e-15);
  EXPECT_EQ(shape_penetration_m(b.shapes[0], {0.5, 0.6}, kR), 0.0);
  EXPECT_NEAR(shape_penetration_m(b.shapes[1], {0.2, 0.21}, kR), kR - 0.01, 1e-15);
  EXPECT_NEAR(shape_penetration_m(b.shapes[1], {0.2, 0.2}, kR), kR, 1e-15);
}

TEST(ObstaclePenetration, HiddenObstaclesAndCandidatesOnly) {
  table::Board b = empty_board();
  add_circle(b, {0.5, 0.5}, 0.03);   // 0: depth 0.0135 - 0.005 at the probe
  add_circle(b, {0.5, 0.45}, 0.03);  // 1: deeper
  GameState s = make_game_state(b, 1);
  const Vec2 p{0.5, 0.5 + 0.03 + 0.005};
  const std::vector<std::int32_t> both{0, 1};
  const std::vector<std::int32_t> first{0};
  EXPECT_NEAR(obstacle_penetration_m(b, s, both, p), kR - 0.005, 1e-15);
  EXPECT_NEAR(obstacle_penetration_m(b, s, first, p), kR - 0.005, 1e-15);
  s.visible[0] = 0;
  EXPECT_EQ(obstacle_penetration_m(b, s, both, p), 0.0);
  s.ball.position_m = p;
  EXPECT_EQ(max_penetration_m(b, s), 0.0);
  s.visible[0] = 1;
  EXPECT_NEAR(max_penetration_m(b, s), kR - 0.005, 1e-15);
}

TEST(FlipperPenetration, TwoSidedAtCurrentAngle) {
  table::Board b = empty_board();
  add_flipper(b, table::Side::kLeft, {0.1, 0.2}, 0.08, -0.5, 0.5, 30.0);
  GameState s = make_game_state(b, 1);
  s.flippers[0].theta_rad = 0.0;  // horizontal from (0.1, 0.2) to (0.18, 0.2)
  EXPECT_NEAR(flipper_penetration_m(b, s, {0.14, 0.205}), kR - 0.005, 1e-15);
  EXPECT_NEAR(flipper_penetration_m(b, s, {0.14, 0.195}), kR - 0.005, 1e-15);  // underside too
  EXPECT_NEAR(flipper_penetration_m(b, s, {0.19, 0.2}), kR - 0.01, 1e-15);     // beyond the tip
  EXPECT_LE(flipper_penetration_m(b, s, {0.14, 0.3}), 0.0);
  // Raised: the same probe is now clear of it.
  s.flippers[0].theta_rad = 0.5;
  EXPECT_LE(flipper_penetration_m(b, s, {0.17, 0.2}), 0.0);
  s.ball.position_m = {0.14, 0.205};
  s.flippers[0].theta_rad = 0.0;
  EXPECT_NEAR(max_penetration_m(b, s), kR - 0.005, 1e-15);
}

}  // namespace
}  // namespace pinball::sim
