#include "pinball/table/board.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "sim/test_boards.h"

namespace pinball::table {
namespace {

using sim::testing::add_flipper;
using sim::testing::empty_board;

TEST(FlipperGeometry, DirectionAtZeroAndUpNormal) {
  Board b = empty_board();
  add_flipper(b, Side::kLeft, {0.1, 0.2});
  add_flipper(b, Side::kRight, {0.4, 0.2});
  const Flipper& left = b.flippers[0];
  const Flipper& right = b.flippers[1];
  EXPECT_EQ(flipper_direction(left, 0.0), Vec2(1.0, 0.0));
  EXPECT_EQ(flipper_direction(right, 0.0), Vec2(-1.0, 0.0));
  EXPECT_EQ(flipper_up_normal(left, 0.0), Vec2(0.0, 1.0));
  EXPECT_EQ(flipper_up_normal(right, 0.0), Vec2(0.0, 1.0));
  for (double theta : {-0.6, -0.2, 0.3, 0.7}) {
    for (const Flipper* f : {&left, &right}) {
      const Vec2 d = flipper_direction(*f, theta);
      const Vec2 n = flipper_up_normal(*f, theta);
      EXPECT_NEAR(d.norm(), 1.0, 1e-15);
      EXPECT_NEAR(n.norm(), 1.0, 1e-15);
      EXPECT_NEAR(d.dot(n), 0.0, 1e-15);
      EXPECT_GT(n.y(), 0.0);                        // the upper face points up the table
      EXPECT_NEAR(d.y(), std::sin(theta), 1e-15);   // elevation is the same for both sides
      // The up normal is the direction the flipper's points move as theta grows.
      const double h = 1e-6;
      const Vec2 dd = (flipper_direction(*f, theta + h) - flipper_direction(*f, theta - h)) / (2.0 * h);
      EXPECT_NEAR((dd - n).norm(), 0.0, 1e-9);
    }
    EXPECT_GT(flipper_direction(left, theta).x(), 0.0);
    EXPECT_LT(flipper_direction(right, theta).x(), 0.0);
  }
  EXPECT_NEAR((flipper_tip(left, 0.5) - (left.pivot + 0.076 * Vec2{std::cos(0.5), std::sin(0.5)})).norm(), 0.0,
              1e-15);
  EXPECT_NEAR((flipper_tip(right, -0.5) - (right.pivot + 0.076 * Vec2{-std::cos(0.5), -std::sin(0.5)})).norm(), 0.0,
              1e-15);
}

TEST(WallThickness, MovesEachTwoSidedWallsFacesHalfOfItEitherSideOfItsLine) {
  Board b = empty_board();
  sim::testing::add_wall(b, {0.1, 0.5}, {0.4, 0.5});       // two faces, two end points
  sim::testing::add_line(b, {0.0, 0.2}, {1.0, 0.2});       // one-sided: stays
  b.shapes.push_back(make_circle_shape({0.7, 0.7}, 0.02)); // a post: stays
  b.obstacles.push_back({});
  const Board file = b;
  set_wall_thickness(b, 0.004);
  EXPECT_EQ(b.wall_thickness_m, 0.004);
  // Faces: the line's normal side moved up 2 mm, the reverse down 2 mm, normals kept.
  for (int face = 0; face < 2; ++face) {
    const Shape& s = b.shapes[static_cast<std::size_t>(face)];
    const Shape& was = file.shapes[static_cast<std::size_t>(face)];
    EXPECT_TRUE(s.normal.isApprox(was.normal));
    EXPECT_NEAR((s.p0 - was.p0).dot(was.normal), 0.002, 1e-15);
    EXPECT_NEAR((s.p1 - was.p1).dot(was.normal), 0.002, 1e-15);
    EXPECT_NEAR(cross(s.p1 - s.p0, was.normal), cross(was.p1 - was.p0, was.normal), 1e-15);  // same length
  }
  EXPECT_NEAR(distance_to_shape(b.shapes[0], {0.25, 0.5}), 0.002, 1e-15);
  // End points stay on the centre line (a square end); the rest stays.
  for (std::size_t i = 2; i < b.shapes.size(); ++i) {
    EXPECT_EQ(b.shapes[i].p0, file.shapes[i].p0) << i;
    EXPECT_EQ(b.shapes[i].p1, file.shapes[i].p1) << i;
    EXPECT_EQ(b.shapes[i].radius_m, file.shapes[i].radius_m) << i;
  }
  // Set again: from the centre lines, not on top of the last thickness.
  Board again = b;
  set_wall_thickness(again, 0.001);
  EXPECT_NEAR((again.shapes[0].p0 - file.shapes[0].p0).dot(file.shapes[0].normal), 0.0005, 1e-15);
  set_wall_thickness(again, 0.0);
  for (std::size_t i = 0; i < b.shapes.size(); ++i) EXPECT_LT((again.shapes[i].p0 - file.shapes[i].p0).norm(), 1e-15);
  EXPECT_THROW(set_wall_thickness(b, -0.001), std::invalid_argument);
  EXPECT_THROW(set_wall_thickness(b, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(Side, IsSpelledLeftOrRightBothWays) {
  EXPECT_EQ(side_name(Side::kLeft), "left");
  EXPECT_EQ(side_name(Side::kRight), "right");
  EXPECT_EQ(parse_side("left"), Side::kLeft);
  EXPECT_EQ(parse_side("right"), Side::kRight);
  EXPECT_FALSE(parse_side("Left").has_value());
  EXPECT_FALSE(parse_side("").has_value());
}

TEST(NearestFlipperAtRest, IsTheClosestRestSegment) {
  Board b = empty_board();
  const auto none = nearest_flipper_at_rest(b, {0.2, 0.2});
  EXPECT_EQ(none.first, -1);
  EXPECT_EQ(none.second, std::numeric_limits<double>::infinity());
  add_flipper(b, Side::kLeft, {0.1, 0.2}, 0.076, 0.0, 0.5, 33.0);   // rest segment (0.1..0.176, 0.2)
  add_flipper(b, Side::kRight, {0.4, 0.2}, 0.076, 0.0, 0.5, 33.0);  // rest segment (0.324..0.4, 0.2)
  const auto left = nearest_flipper_at_rest(b, {0.15, 0.25});
  EXPECT_EQ(left.first, 0);
  EXPECT_NEAR(left.second, 0.05, 1e-12);
  const auto right = nearest_flipper_at_rest(b, {0.33, 0.1});
  EXPECT_EQ(right.first, 1);
  EXPECT_NEAR(right.second, 0.1, 1e-12);
}

TEST(FlippersBySide, LeftThenRightWhateverTheFileOrder) {
  Board b = empty_board();
  EXPECT_EQ(flippers_by_side(b), (std::array<int, 2>{-1, -1}));
  add_flipper(b, Side::kRight, {0.4, 0.2}, 0.076, 0.0, 0.5, 33.0);
  EXPECT_EQ(flippers_by_side(b), (std::array<int, 2>{-1, 0}));
  add_flipper(b, Side::kLeft, {0.1, 0.2}, 0.076, 0.0, 0.5, 33.0);
  EXPECT_EQ(flippers_by_side(b), (std::array<int, 2>{1, 0}));
}

TEST(MaxStableDt, FormulaAndSmallestOverFlippers) {
  Board b = empty_board();
  EXPECT_EQ(max_stable_dt_s(b), std::numeric_limits<double>::infinity());
  add_flipper(b, Side::kLeft, {0.1, 0.2}, 0.076, -0.5, 0.5, 33.0);
  const double r = b.ball.radius_m;
  const double dt1 = 2.0 * std::asin(r / 0.076) / 33.0;
  EXPECT_NEAR(max_stable_dt_s(b), dt1, 1e-15);
  // At that step the tip's chord equals the radius.
  EXPECT_NEAR(0.076 * std::sin(33.0 * dt1 / 2.0), r, 1e-15);
  add_flipper(b, Side::kRight, {0.4, 0.2}, 0.1, -0.5, 0.5, 40.0);  // longer and faster: the binding one
  const double dt2 = 2.0 * std::asin(r / 0.1) / 40.0;
  ASSERT_LT(dt2, dt1);
  EXPECT_NEAR(max_stable_dt_s(b), dt2, 1e-15);
  // A flipper shorter than the ball radius imposes no limit.
  Board c = empty_board();
  add_flipper(c, Side::kLeft, {0.1, 0.2}, 0.01, -0.5, 0.5, 1000.0);
  EXPECT_EQ(max_stable_dt_s(c), std::numeric_limits<double>::infinity());
}

TEST(CheckFlipperTimeStep, ThrowsAboveTheLimitNamingTheFlipper) {
  Board b = empty_board();
  add_flipper(b, Side::kLeft, {0.1, 0.2}, 0.076, -0.5, 0.5, 33.0);
  b.flippers[0].name = "lefty";
  const double dt_max = max_stable_dt_s(b);
  EXPECT_NO_THROW(check_flipper_time_step(b, 0.99 * dt_max));
  EXPECT_NO_THROW(check_flipper_time_step(b, 1e-6));
  EXPECT_THROW(check_flipper_time_step(b, 1.01 * dt_max), std::invalid_argument);
  // A sweep past a half turn (sin no longer monotonic) is refused too.
  EXPECT_THROW(check_flipper_time_step(b, 4.0 * M_PI / 33.0), std::invalid_argument);
  try {
    check_flipper_time_step(b, 2.0 * dt_max);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lefty"), std::string::npos) << e.what();
  }
}

TEST(MinLaunchSpeed, RisesAboveOneRadiusAgainstGravityPlusOneEulerStep) {
  Board b = empty_board(0.51, 1.07, 1.11, 5e-4);
  const double v_still = kLauncherStillSpeed_mps;
  EXPECT_DOUBLE_EQ(min_launch_speed_mps(b), std::sqrt(2 * 1.11 * 0.0135 + v_still * v_still) + 1.11 * 5e-4);
  b.gravity_mps2 = 0.0;
  EXPECT_DOUBLE_EQ(min_launch_speed_mps(b), v_still);
}

TEST(CheckLaunchPull, RefusesAPullThatCannotLeaveTheLauncher) {
  Board b = empty_board(0.51, 1.07, 1.11, 5e-4);
  b.ball.speed_max_mps = 5.0;
  b.launcher.noise_max = 0.03;
  EXPECT_DOUBLE_EQ(slowest_launch_mps(b, 0.5), 0.5 * 0.97 * 5.0);
  EXPECT_NO_THROW(check_launch_pull(b, 0.95));
  EXPECT_NO_THROW(check_launch_pull(b, 0.04));  // 0.194 m/s
  try {
    check_launch_pull(b, 0.03);  // 0.1455 m/s, below 0.1807
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("launch pull 0.03"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("relaunched at its apex for ever"), std::string::npos) << e.what();
  }
  b.start = BallStart{{0.2, 0.5}, {0.0, 0.0}};  // served, never launched
  EXPECT_NO_THROW(check_launch_pull(b, 0.01));
}

}  // namespace
}  // namespace pinball::table
