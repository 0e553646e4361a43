#include "pinball/sim/collision.h"

#include <gtest/gtest.h>

#include "common/ball_radius.h"

#include <cmath>
#include <numbers>

#include "pinball/core/rng.h"
#include "test_boards.h"

namespace pinball::sim {
namespace {

using testing::add_flipper;
using testing::add_line;
using testing::empty_board;

using pinball::testing::kR;

table::Shape floor_line() { return table::make_line_shape({0.0, 0.0}, {1.0, 0.0}); }

TEST(LineTimeOfImpact, FallingBallHitsAtHeightMinusRadiusOverSpeed) {
  const table::Shape line = floor_line();
  ASSERT_NEAR(line.normal.y(), 1.0, 1e-15);
  const double h = 0.2;
  const double speed = 1.7;
  Contact c;
  ASSERT_TRUE(line_time_of_impact(line, {0.4, h}, {0.0, -speed}, kR, 1.0, c));
  EXPECT_NEAR(c.t_s, (h - kR) / speed, 1e-15);
  EXPECT_NEAR(c.normal.x(), 0.0, 1e-15);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-15);
  EXPECT_NEAR(c.point.x(), 0.4, 1e-15);
  EXPECT_NEAR(c.point.y(), 0.0, 1e-15);
  // Oblique: the time depends only on the normal speed; the point moves along.
  ASSERT_TRUE(line_time_of_impact(line, {0.4, h}, {0.5, -speed}, kR, 1.0, c));
  const double t = (h - kR) / speed;
  EXPECT_NEAR(c.t_s, t, 1e-15);
  EXPECT_NEAR(c.point.x(), 0.4 + 0.5 * t, 1e-15);
}

TEST(LineTimeOfImpact, SlantedLine) {
  // Line through the origin at 30 degrees; ball on its normal at distance d moving straight at it.
  const double a = std::numbers::pi / 6.0;
  const table::Shape line = table::make_line_shape({0.0, 0.0}, {std::cos(a), std::sin(a)});
  const Vec2 n = line.normal;
  const Vec2 foot = 0.5 * Vec2{std::cos(a), std::sin(a)};
  const double d = 0.3;
  Contact c;
  ASSERT_TRUE(line_time_of_impact(line, foot + d * n, -2.0 * n, kR, 1.0, c));
  EXPECT_NEAR(c.t_s, (d - kR) / 2.0, 1e-14);
  EXPECT_NEAR((c.point - foot).norm(), 0.0, 1e-14);
}

TEST(LineTimeOfImpact, OutsideTimeWindowIsNoHit) {
  Contact c;
  EXPECT_FALSE(line_time_of_impact(floor_line(), {0.4, 0.2}, {0.0, -1.0}, kR, 0.1, c));
  EXPECT_TRUE(line_time_of_impact(floor_line(), {0.4, 0.2}, {0.0, -1.0}, kR, 0.2, c));
}

TEST(LineTimeOfImpact, BackSidePassesThrough) {
  Contact c;
  // Below the line moving up: behind the one-sided line.
  EXPECT_FALSE(line_time_of_impact(floor_line(), {0.4, -0.2}, {0.0, 1.0}, kR, 1.0, c));
  // Below it and moving down (away from the back): nothing either.
  EXPECT_FALSE(line_time_of_impact(floor_line(), {0.4, -0.005}, {0.0, -1.0}, kR, 1.0, c));
  // The reversed line (normal -y) is hit by the ball from below.
  const table::Shape back = table::make_line_shape({1.0, 0.0}, {0.0, 0.0});
  ASSERT_TRUE(line_time_of_impact(back, {0.4, -0.2}, {0.0, 1.0}, kR, 1.0, c));
  EXPECT_NEAR(c.t_s, 0.2 - kR, 1e-15);
  EXPECT_NEAR(c.normal.y(), -1.0, 1e-15);
}

TEST(LineTimeOfImpact, ParallelOrAwayIsNoHit) {
  Contact c;
  EXPECT_FALSE(line_time_of_impact(floor_line(), {0.4, 0.02}, {3.0, 0.0}, kR, 1.0, c));
  EXPECT_FALSE(line_time_of_impact(floor_line(), {0.4, 0.01}, {-3.0, 0.0}, kR, 1.0, c));  // even overlapping
  EXPECT_FALSE(line_time_of_impact(floor_line(), {0.4, 0.02}, {1.0, 0.5}, kR, 1.0, c));
}

TEST(LineTimeOfImpact, OverlapWhileApproachingIsImmediate) {
  Contact c;
  ASSERT_TRUE(line_time_of_impact(floor_line(), {0.3, 0.5 * kR}, {0.2, -1.0}, kR, 1.0, c));
  EXPECT_EQ(c.t_s, 0.0);
  EXPECT_NEAR(c.point.x(), 0.3, 1e-15);
  EXPECT_NEAR(c.point.y(), 0.0, 1e-15);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-15);
  // Exactly touching also collides now.
  ASSERT_TRUE(line_time_of_impact(floor_line(), {0.3, kR}, {0.0, -1.0}, kR, 1.0, c));
  EXPECT_EQ(c.t_s, 0.0);
}

TEST(LineTimeOfImpact, MissBeyondSegmentEnds) {
  Contact c;
  // Contact point would be at x = 1 + 1e-3 and x = -1e-3: outside [0, 1].
  EXPECT_FALSE(line_time_of_impact(floor_line(), {1.001, 0.2}, {0.0, -1.0}, kR, 1.0, c));
  EXPECT_FALSE(line_time_of_impact(floor_line(), {-0.001, 0.2}, {0.0, -1.0}, kR, 1.0, c));
  // Oblique approach that lands beyond the end even though it starts above the segment.
  EXPECT_FALSE(line_time_of_impact(floor_line(), {0.9, 0.2}, {1.0, -1.0}, kR, 1.0, c));
  // Just inside the end is a hit.
  EXPECT_TRUE(line_time_of_impact(floor_line(), {0.999, 0.2}, {0.0, -1.0}, kR, 1.0, c));
}

TEST(CircleTimeOfImpact, HeadOnClosedForm) {
  const Vec2 centre{0.5, 0.5};
  const double big_r = 0.03;
  Contact c;
  ASSERT_TRUE(circle_time_of_impact(centre, big_r, {0.5, 0.9}, {0.0, -2.0}, kR, 1.0, c));
  EXPECT_NEAR(c.t_s, (0.4 - big_r - kR) / 2.0, 1e-15);
  EXPECT_NEAR(c.normal.x(), 0.0, 1e-15);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-15);
  EXPECT_NEAR(c.point.y(), 0.5 + big_r, 1e-15);
}

TEST(CircleTimeOfImpact, OffsetClosedFormAndNormalThroughContact) {
  // Ball moving along -y with lateral offset b from the centre: contact when
  // the centres are R + r apart, i.e. at y = cy + sqrt((R + r)² - b²).
  const Vec2 centre{0.2, 0.1};
  const double big_r = 0.025;
  const double reach = big_r + kR;
  const double b = 0.6 * reach;
  const Vec2 p{centre.x() + b, centre.y() + 0.5};
  const double speed = 3.0;
  Contact c;
  ASSERT_TRUE(circle_time_of_impact(centre, big_r, p, {0.0, -speed}, kR, 1.0, c));
  const double y_contact = centre.y() + std::sqrt(reach * reach - b * b);
  EXPECT_NEAR(c.t_s, (p.y() - y_contact) / speed, 1e-14);
  const Vec2 at = p + c.t_s * Vec2{0.0, -speed};
  EXPECT_NEAR((at - centre).norm(), reach, 1e-14);
  const Vec2 expected_n = (at - centre) / (at - centre).norm();
  EXPECT_NEAR((c.normal - expected_n).norm(), 0.0, 1e-13);
  EXPECT_NEAR(c.normal.x(), 0.6, 1e-13);
  EXPECT_NEAR(c.normal.y(), 0.8, 1e-13);
  EXPECT_NEAR((c.point - (centre + big_r * expected_n)).norm(), 0.0, 1e-13);
}

TEST(CircleTimeOfImpact, TangentGrazeAndMissAreNoHit) {
  const Vec2 centre{0.0, 0.0};
  const double big_r = 0.02;
  Contact c;
  // Exactly tangent: offset == R + r (0.0335 is not exact in binary; use powers of two).
  EXPECT_FALSE(circle_time_of_impact(centre, 0.25, {0.5, 2.0}, {0.0, -1.0}, 0.25, 5.0, c));
  EXPECT_FALSE(circle_time_of_impact(centre, big_r, {big_r + kR + 1e-6, 1.0}, {0.0, -1.0}, kR, 5.0, c));
  EXPECT_TRUE(circle_time_of_impact(centre, big_r, {big_r + kR - 1e-6, 1.0}, {0.0, -1.0}, kR, 5.0, c));
  // Moving away.
  EXPECT_FALSE(circle_time_of_impact(centre, big_r, {0.0, 0.5}, {0.0, 1.0}, kR, 5.0, c));
  // Hit beyond the time window.
  EXPECT_FALSE(circle_time_of_impact(centre, big_r, {0.0, 0.5}, {0.0, -1.0}, kR, 0.1, c));
}

TEST(CircleTimeOfImpact, PointIsRadiusZero) {
  const Vec2 pt{0.3, 0.3};
  Contact c;
  ASSERT_TRUE(circle_time_of_impact(pt, 0.0, {0.3, 0.6}, {0.0, -1.5}, kR, 1.0, c));
  EXPECT_NEAR(c.t_s, (0.3 - kR) / 1.5, 1e-15);
  EXPECT_EQ(c.point, pt);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-15);
  // Off-centre: normal at 45 degrees when the offset is r / sqrt(2).
  const double b = kR / std::sqrt(2.0);
  ASSERT_TRUE(circle_time_of_impact(pt, 0.0, {0.3 - b, 0.6}, {0.0, -1.5}, kR, 1.0, c));
  EXPECT_NEAR(c.normal.x(), -std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(c.normal.y(), std::sqrt(0.5), 1e-12);
  // shape_time_of_impact dispatches on the kind.
  table::Shape s;
  s.kind = table::ShapeKind::kCircle;
  s.p0 = pt;
  Contact d;
  ASSERT_TRUE(shape_time_of_impact(s, {0.3, 0.6}, {0.0, -1.5}, kR, 1.0, d));
  EXPECT_NEAR(d.t_s, (0.3 - kR) / 1.5, 1e-15);
}

TEST(CircleTimeOfImpact, OverlapWhileApproachingIsImmediate) {
  Contact c;
  ASSERT_TRUE(circle_time_of_impact({0.0, 0.0}, 0.02, {0.0, 0.025}, {0.1, -1.0}, kR, 1.0, c));
  EXPECT_EQ(c.t_s, 0.0);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-15);
  // Overlapping but separating: no contact.
  EXPECT_FALSE(circle_time_of_impact({0.0, 0.0}, 0.02, {0.0, 0.025}, {0.0, 1.0}, kR, 1.0, c));
}

TEST(Reflect, AngleInEqualsAngleOutForRhoOne) {
  const Vec2 n{0.0, 1.0};
  for (double deg : {10.0, 30.0, 45.0, 80.0}) {
    const double a = deg * std::numbers::pi / 180.0;
    const Vec2 v{std::cos(a), -std::sin(a)};
    const Vec2 out = reflect(v, n, 1.0);
    EXPECT_NEAR(out.x(), std::cos(a), 1e-15);
    EXPECT_NEAR(out.y(), std::sin(a), 1e-15);
    EXPECT_NEAR(out.norm(), 1.0, 1e-15);
  }
  // Slanted normal: energy kept and the angle to the normal mirrored.
  const Vec2 m = Vec2{1.0, 2.0}.normalized();
  const Vec2 v{-0.3, -1.1};
  const Vec2 out = reflect(v, m, 1.0);
  EXPECT_NEAR(out.norm(), v.norm(), 1e-15);
  EXPECT_NEAR(out.dot(m), -v.dot(m), 1e-15);
  EXPECT_NEAR(cross(m, out), cross(m, v), 1e-15);
}

TEST(Reflect, NormalSpeedScaledByRhoTangentialUnchanged) {
  const Vec2 n = Vec2{-1.0, 3.0}.normalized();
  const Vec2 t = perp_left(n);
  const Vec2 v = -2.0 * n + 0.7 * t;
  for (double rho : {0.5, 1.0, 1.5}) {
    const Vec2 out = reflect(v, n, rho);
    EXPECT_NEAR(out.dot(n), 2.0 * rho, 1e-14) << rho;
    EXPECT_NEAR(out.dot(t), 0.7, 1e-14) << rho;
    // Kinetic energy: tangential part kept, normal part scaled by rho².
    EXPECT_NEAR(out.squaredNorm(), 0.49 + 4.0 * rho * rho, 1e-13) << rho;
  }
}

TEST(WallFriction, SlidingLossIsMuTimesImpulseTimesTheSlipsTangentialShare) {
  // Slip (0.6 along, 0.8 across): 3.5·μ·J = 0.35 < 1, so the contact slides
  // all through the hit and the loss is μ·J·0.6/1.
  EXPECT_NEAR(wall_friction_loss_mps(0.6, 0.8, 1.0, 0.1), 0.1 * 1.0 * 0.6, 1e-15);
  // A grazing ball (little normal speed) loses the whole μ·J.
  EXPECT_NEAR(wall_friction_loss_mps(2.0, 1e-9, 0.1, 0.2), 0.02, 1e-9);
  // A head-on ball has no tangential speed to lose.
  EXPECT_EQ(wall_friction_loss_mps(0.0, 1.0, 1.5, 0.3), 0.0);
}

TEST(WallFriction, StickingCapsTheLossAtATangential3Point5th) {
  // 3.5·μ·J = 3.5·0.5·2 = 3.5 > slip 1: the contact sticks.
  EXPECT_NEAR(wall_friction_loss_mps(0.6, 0.8, 2.0, 0.5), 0.6 / 3.5, 1e-15);
  // The loss grows with μ up to the cap, continuously, and never past it.
  double last = 0.0;
  for (double mu = 0.0; mu <= 3.0; mu += 0.01) {
    const double loss = wall_friction_loss_mps(0.6, 0.8, 2.0, mu);
    EXPECT_GE(loss, last - 1e-15);
    EXPECT_LE(loss, 0.6 / 3.5 + 1e-15);
    EXPECT_LT(loss - last, 0.02);
    last = loss;
  }
}

TEST(WallFriction, NoFrictionNoImpulseOrNoSpeedIsNoLoss) {
  EXPECT_EQ(wall_friction_loss_mps(1.0, 1.0, 1.0, 0.0), 0.0);
  EXPECT_EQ(wall_friction_loss_mps(1.0, 1.0, 0.0, 0.4), 0.0);
  EXPECT_EQ(wall_friction_loss_mps(0.0, 0.0, 1.0, 0.4), 0.0);
}

TEST(ObstacleResponse, FrictionlessIsTheThesisReflectionPlusKick) {
  const Vec2 n = Vec2{1.0, 2.0}.normalized();
  const Vec2 v = -1.5 * n + 0.4 * perp_left(n);
  table::Obstacle o;
  o.rho = 0.7;
  o.action.kick_mps = 0.3;
  const Vec2 out = obstacle_response(o, n, v);
  EXPECT_NEAR((out - (reflect(v, n, 0.7) + 0.3 * n)).norm(), 0.0, 1e-15);
}

TEST(ObstacleResponse, FrictionTakesTangentialSpeedAndNeverAddsEnergy) {
  const Vec2 n{0.0, 1.0};
  const Vec2 t{1.0, 0.0};
  table::Obstacle o;
  o.rho = 0.5;
  o.friction = 0.1;
  const Vec2 v = 2.0 * t - 1.0 * n;  // fast along the wall, 1 m/s into it
  const Vec2 out = obstacle_response(o, n, v);
  const double impulse = 1.5;  // (1 + ρ)·1
  EXPECT_NEAR(out.dot(n), 0.5, 1e-15);  // the normal part is the thesis's
  EXPECT_NEAR(out.dot(t), 2.0 - 0.1 * impulse * 2.0 / std::sqrt(5.0), 1e-14);
  // Turned round: the same loss against the other way along the wall.
  const Vec2 back = obstacle_response(o, n, Vec2(-2.0 * t - 1.0 * n));
  EXPECT_NEAR(back.dot(t), -out.dot(t), 1e-15);
  // Random hits: never faster than the frictionless response, never turned back along the wall.
  Rng rng(7);
  for (int i = 0; i < 10000; ++i) {
    o.rho = rng.uniform(0.0, 1.5);
    o.friction = rng.uniform(0.0, 2.0);
    const Vec2 in = rng.uniform(-2.0, 2.0) * t - rng.uniform(1e-6, 3.0) * n;
    const Vec2 free = reflect(in, n, o.rho);
    const Vec2 with = obstacle_response(o, n, in);
    ASSERT_LE(with.squaredNorm(), free.squaredNorm() + 1e-15);
    ASSERT_GE(with.dot(t) * in.dot(t), 0.0);
    ASSERT_NEAR(with.dot(n), free.dot(n), 1e-15);
  }
}

class FlipperResponseTest : public ::testing::Test {
 protected:
  FlipperResponseTest() {
    board_ = empty_board();
    add_flipper(board_, table::Side::kLeft, {0.1, 0.2}, 0.08, -0.5, 0.5, 30.0, 0.5, 0.8);
    add_flipper(board_, table::Side::kRight, {0.4, 0.2}, 0.08, -0.5, 0.5, 30.0, 0.5, 0.8);
  }
  table::Board board_;
};

TEST_F(FlipperResponseTest, BallAtRestGetsMuOmegaArm) {
  for (const table::Flipper& f : board_.flippers) {
    const double theta = 0.2;
    const Vec2 dir = table::flipper_direction(f, theta);
    const Vec2 up = table::flipper_up_normal(f, theta);
    for (double arm : {0.01, 0.04, 0.079}) {
      const Vec2 q = f.pivot + arm * dir;
      const Vec2 out = flipper_response(f, theta, f.omega_rad_s, q, up, Vec2::Zero());
      EXPECT_NEAR((out - f.mu * f.omega_rad_s * arm * up).norm(), 0.0, 1e-14) << arm;
    }
  }
}

TEST_F(FlipperResponseTest, ImpulseGrowsWithMomentArm) {
  const table::Flipper& f = board_.flippers[0];
  const double theta = -0.3;
  const Vec2 dir = table::flipper_direction(f, theta);
  const Vec2 up = table::flipper_up_normal(f, theta);
  const Vec2 v_in = -0.4 * up + 0.2 * dir;  // falling onto the face
  const Vec2 near_pivot = flipper_response(f, theta, f.omega_rad_s, f.pivot + 0.01 * dir, up, v_in);
  const Vec2 near_tip = flipper_response(f, theta, f.omega_rad_s, f.pivot + 0.075 * dir, up, v_in);
  EXPECT_GT(near_tip.dot(up), near_pivot.dot(up));
  // Both: reflect with rho (0.4 -> 0.2), then add mu·omega·arm.
  EXPECT_NEAR(near_pivot.dot(up), f.rho * 0.4 + f.mu * f.omega_rad_s * 0.01, 1e-14);
  EXPECT_NEAR(near_tip.dot(up), f.rho * 0.4 + f.mu * f.omega_rad_s * 0.075, 1e-14);
  EXPECT_NEAR(near_tip.dot(dir), 0.2, 1e-14);
  // The material velocity of the flipper itself is omega·arm along the up normal.
  const Vec2 vq = flipper_point_velocity(f, theta, f.omega_rad_s, f.pivot + 0.05 * dir);
  EXPECT_NEAR((vq - f.omega_rad_s * 0.05 * up).norm(), 0.0, 1e-14);
}

TEST_F(FlipperResponseTest, NoImpulseWhenFaceMovesAway) {
  for (const table::Flipper& f : board_.flippers) {
    const double theta = 0.1;
    const Vec2 dir = table::flipper_direction(f, theta);
    const Vec2 up = table::flipper_up_normal(f, theta);
    const Vec2 q = f.pivot + 0.06 * dir;
    // Flipper falling, ball at rest on the upper face: unchanged.
    EXPECT_EQ(flipper_response(f, theta, -f.omega_rad_s, q, up, Vec2::Zero()), Vec2(Vec2::Zero()));
    // Ball moving into the falling face: plain reflection with rho, no added speed.
    const Vec2 v{0.1, -0.6};
    const Vec2 out = flipper_response(f, theta, -f.omega_rad_s, q, up, v);
    EXPECT_NEAR((out - reflect(v, up, f.rho)).norm(), 0.0, 1e-15);
    // Ball on the lower face of a rising flipper: the face moves away, no impulse.
    EXPECT_EQ(flipper_response(f, theta, f.omega_rad_s, q, -up, Vec2::Zero()), Vec2(Vec2::Zero()));
    // Resting flipper (omega 0): reflection only.
    const Vec2 still = flipper_response(f, theta, 0.0, q, up, v);
    EXPECT_NEAR((still - reflect(v, up, f.rho)).norm(), 0.0, 1e-15);
  }
}

TEST_F(FlipperResponseTest, FlipperFacePicksTheBallsSide) {
  const table::Flipper& f = board_.flippers[1];
  const double theta = 0.25;
  const Vec2 up = table::flipper_up_normal(f, theta);
  const Vec2 mid = f.pivot + 0.04 * table::flipper_direction(f, theta);
  const table::Shape above = flipper_face(f, theta, mid + 0.02 * up);
  const table::Shape below = flipper_face(f, theta, mid - 0.02 * up);
  EXPECT_NEAR((above.normal - up).norm(), 0.0, 1e-15);
  EXPECT_NEAR((below.normal + up).norm(), 0.0, 1e-15);
  EXPECT_EQ(above.p0, f.pivot);
  EXPECT_NEAR((above.p1 - table::flipper_tip(f, theta)).norm(), 0.0, 1e-15);
}

}  // namespace
}  // namespace pinball::sim
