// Stiff cases for the thesis stepper: fast balls, wedges, jams, resting
// contact, extreme time steps and a long random run. Every step must leave a
// finite state, no ball inside an obstacle (max_penetration_m < 1e-6) and no
// ball on the far side of a wall it cannot pass.

#include <gtest/gtest.h>

#include "common/ball_radius.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "pinball/core/rng.h"
#include "pinball/sim/model_world.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/table/board_loader.h"
#include "pinball/sim/penetration.h"
#include "pinball/sim/thesis_stepper.h"
#include "invariants.h"
#include "test_boards.h"

namespace pinball::sim {
namespace {

using namespace pinball::sim::testing;

using pinball::testing::kR;
constexpr double kMaxDepth = kDefaultMaxDepth_m;

TEST(StiffCases, FastBallAgainstThinWall) {
  // A vertical two-sided wall at x = 0.5; the ball at 50 m/s (10x a real
  // table's speeds) moves 2.5 cm per step, nearly its own diameter.
  for (double deg : {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, -40.0}) {
    table::Board b = empty_board(1.0, 2.0, 1.11, 5e-4);
    b.ball.speed_max_mps = 50.0;
    add_wall(b, {0.5, 0.2}, {0.5, 1.8}, 1.0);
    const ThesisStepper stepper(b);
    const double a = deg * std::numbers::pi / 180.0;
    GameState s = state_with_ball(b, {0.3, 1.0}, 50.0 * Vec2{std::cos(a), std::sin(a)});
    bool hit = false;
    for (int i = 0; i < 40 && s.ball_in_play; ++i) {
      const StepEvents ev = stepper.step(s);
      hit = hit || ev.has(StepEvents::kHitObstacle);
      ASSERT_TRUE(invariants_hold(b, s, i)) << deg << " deg";
      // Never past the wall where the wall is.
      const Vec2& p = s.ball.position_m;
      if (p.y() > 0.2 && p.y() < 1.8) {
        ASSERT_LT(p.x(), 0.5 - kR + kMaxDepth) << deg << " deg, step " << i;
      }
    }
    EXPECT_TRUE(hit) << deg << " deg";
  }
}

TEST(StiffCases, FastBallAtWallEndPoints) {
  // Aimed near the wall's ends, where the end points must catch it.
  for (double offset : {-0.012, -0.005, 0.0, 0.005, 0.012}) {
    table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
    b.ball.speed_max_mps = 50.0;
    add_wall(b, {0.2, 0.5}, {0.8, 0.5}, 1.0);  // horizontal thin wall
    const ThesisStepper stepper(b);
    GameState s = state_with_ball(b, {0.8 + offset, 0.9}, {0.0, -50.0});
    for (int i = 0; i < 30 && s.ball_in_play; ++i) {
      stepper.step(s);
      ASSERT_TRUE(invariants_hold(b, s, i)) << offset;
      const Vec2& p = s.ball.position_m;
      if (p.x() > 0.2 && p.x() < 0.8) {
        ASSERT_GT(p.y(), 0.5) << offset << " step " << i;
      }
    }
  }
}

TEST(StiffCases, BallWedgedInNarrowV) {
  for (double rho : {0.5, 1.0}) {
    table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
    b.ball.speed_max_mps = 5.0;
    const double a = 10.0 * std::numbers::pi / 180.0;
    const Vec2 apex{0.5, 0.1};
    const double len = 0.6;
    const Vec2 left_top = apex + len * Vec2{-std::sin(a), std::cos(a)};
    const Vec2 right_top = apex + len * Vec2{std::sin(a), std::cos(a)};
    add_wall(b, apex, left_top, rho);
    add_wall(b, apex, right_top, rho);
    const ThesisStepper stepper(b);
    // Dropped off-centre with some sideways speed.
    GameState s = state_with_ball(b, {0.51, 0.5}, {0.3, 0.0});
    // Unit normals pointing into the V.
    const Vec2 n_left = Vec2{std::cos(a), std::sin(a)};
    const Vec2 n_right = Vec2{-std::cos(a), std::sin(a)};
    double lowest = 1.0;
    for (int i = 0; i < 20000; ++i) {
      stepper.step(s);
      ASSERT_TRUE(s.ball_in_play);
      ASSERT_TRUE(invariants_hold(b, s, i)) << "rho " << rho;
      const Vec2 rel = s.ball.position_m - apex;
      ASSERT_GT(rel.dot(n_left), kR - kMaxDepth) << "through the left wall at step " << i;
      ASSERT_GT(rel.dot(n_right), kR - kMaxDepth) << "through the right wall at step " << i;
      lowest = std::min(lowest, s.ball.position_m.y());
    }
    // The wedge point: where the V is one ball wide, r / sin(10 deg) above the apex.
    EXPECT_GT(lowest, apex.y() + kR / std::sin(a) - 1e-6) << rho;
  }
}

TEST(StiffCases, FlipperStallsAgainstWallAbove) {
  // Ball resting on the upper face of a left flipper at rest; a two-sided
  // wall above it, clear of the flipper's own sweep (the tip at the up stop
  // stays 7 mm below it) but too low for the ball to pass between the raised
  // face and the wall near the tip. Energising the flipper squeezes the ball
  // into the wall: the flipper must stall (hold its angle) rather than push
  // the ball through. Frictionless, the ball may then squirt out sideways.
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  const int fl = add_flipper(b, table::Side::kLeft, {0.3, 0.3}, 0.076, -0.4, 0.6, 33.0, 0.5, 1.0);
  const table::Flipper& f = b.flippers[fl];
  const Vec2 p = f.pivot + 0.05 * table::flipper_direction(f, f.theta_min_rad) +
                 (kR + 1e-6) * table::flipper_up_normal(f, f.theta_min_rad);
  const double wall_y = table::flipper_tip(f, f.theta_max_rad).y() + 0.007;
  ASSERT_GT(wall_y - p.y(), kR + 0.03);  // the ball starts well clear of it
  add_wall(b, {0.2, wall_y}, {0.5, wall_y}, 0.5);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, p, Vec2::Zero());
  s.flippers[fl].energized = true;
  for (int i = 0; i < 4000; ++i) {
    const double theta_before = s.flippers[fl].theta_rad;
    const StepEvents ev = stepper.step(s);
    if (ev.has(StepEvents::kFlipperStall)) {
      EXPECT_EQ(ev.flipper, fl);
      EXPECT_EQ(s.flippers[fl].theta_rad, theta_before) << "a stalled flipper must not move";
      EXPECT_EQ(s.flippers[fl].omega_rad_s, 0.0);
    }
    ASSERT_TRUE(invariants_hold(b, s, i));
    ASSERT_LT(s.ball.position_m.y(), wall_y - kR + kMaxDepth) << "ball pushed through the wall at step " << i;
  }
  // Whether it stalls here or the ball squirts out sideways first depends on
  // the bounce; the closed pocket below forces the stall.
}

TEST(StiffCases, FlipperJammedInClosedPocketStaysStalled) {
  // The ball is shut in a pocket above a left flipper: a wall parallel to the
  // raised flipper 20 mm above its face (less than the ball's 27 mm
  // diameter), and walls at the pivot and just beyond the tip. The flipper
  // can never reach its up stop; it must stall every time it tries.
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  const int fl = add_flipper(b, table::Side::kLeft, {0.3, 0.3}, 0.076, -0.4, 0.6, 33.0, 0.5, 1.0);
  const FlipperPocket pocket = add_flipper_pocket(b, fl);
  const table::Flipper& f = b.flippers[fl];
  const double left_x = pocket.left_x, right_x = pocket.right_x;
  const Vec2 roof0 = pocket.roof0, roof1 = pocket.roof1;
  const Vec2 p = f.pivot + 0.05 * table::flipper_direction(f, f.theta_min_rad) +
                 (kR + 1e-6) * table::flipper_up_normal(f, f.theta_min_rad);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, p, Vec2::Zero());
  ASSERT_EQ(max_penetration_m(b, s), 0.0);
  int stalls = 0;
  for (int i = 0; i < 6000; ++i) {
    s.flippers[fl].energized = (i / 1500) % 2 == 0;  // press, release, press, release
    const StepEvents ev = stepper.step(s);
    stalls += ev.has(StepEvents::kFlipperStall) ? 1 : 0;
    ASSERT_TRUE(invariants_hold(b, s, i));
    ASSERT_LT(s.flippers[fl].theta_rad, f.theta_max_rad) << "the flipper rose through the ball at step " << i;
    const Vec2& q = s.ball.position_m;
    ASSERT_GT(q.x(), left_x) << "escaped at step " << i;
    ASSERT_LT(q.x(), right_x) << "escaped at step " << i;
    ASSERT_LT((q - roof0).dot(perp_left(roof1 - roof0).normalized()), 0.0) << "through the roof at step " << i;
  }
  EXPECT_GT(stalls, 100);
}

TEST(StiffCases, BallComesToRestOnFlatLine) {
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  add_line(b, {0.0, 0.1}, {1.0, 0.1}, 0.5);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, 0.3}, {0.0, 0.0});
  const int n = 20000;  // 10 s
  for (int i = 0; i < n; ++i) {
    stepper.step(s);
    ASSERT_TRUE(invariants_hold(b, s, i));
    ASSERT_GE(s.ball.position_m.y() - 0.1, kR - kMaxDepth) << "sank in at step " << i;
  }
  EXPECT_NEAR(s.ball.position_m.y() - 0.1, kR, 1e-4);
  // At rest: a few g·dt at most.
  EXPECT_LT(std::abs(s.ball.velocity_mps.y()), 5.0 * 1.11 * 5e-4);
  EXPECT_NEAR(s.ball.position_m.x(), 0.5, 1e-12);
}

// A small table: box, walls, a bumper and a left flipper at the bottom.
table::Board dt_sweep_board(double dt) {
  table::Board b = box_board(0.8, 1.11, dt);
  b.ball.speed_max_mps = 5.0;
  add_wall(b, {0.0, 0.25}, {0.12, 0.18}, 0.5);  // inlane guide down to the flipper
  add_wall(b, {0.51, 0.25}, {0.35, 0.18}, 0.5);
  add_circle(b, {0.25, 0.7}, 0.03, 1.2);
  add_wall(b, {0.1, 0.85}, {0.2, 0.95}, 0.9);
  add_flipper(b, table::Side::kLeft, {0.13, 0.17}, 0.076, -0.5, 0.5, 33.0, 0.5, 1.0);
  add_flipper(b, table::Side::kRight, {0.34, 0.17}, 0.076, -0.5, 0.5, 33.0, 0.5, 1.0);
  return b;
}

TEST(StiffCases, TimeStepSweep) {
  const double dt_max = table::max_stable_dt_s(dt_sweep_board(1e-4));
  ASSERT_TRUE(std::isfinite(dt_max));
  for (double dt : {1e-5, 1e-4, 5e-4, 2e-3, 0.99 * dt_max}) {
    if (dt > 0.99 * dt_max) continue;
    const table::Board b = dt_sweep_board(dt);
    const ThesisStepper stepper(b);
    GameState s = state_with_ball(b, {0.2, 0.9}, {0.8, -0.5});
    const double seconds = dt < 5e-5 ? 2.0 : 4.0;
    const long n = static_cast<long>(seconds / dt);
    const long toggle = std::max(1L, static_cast<long>(0.15 / dt));
    for (long i = 0; i < n; ++i) {
      const bool up = (i / toggle) % 2 == 1;
      for (auto& fs : s.flippers) fs.energized = up;
      stepper.step(s);
      ASSERT_TRUE(s.ball_in_play) << "dt " << dt;
      ASSERT_TRUE(invariants_hold(b, s, i)) << "dt " << dt;
      const Vec2& p = s.ball.position_m;
      ASSERT_TRUE(p.x() > 0.0 && p.x() < b.width_m && p.y() > 0.0 && p.y() < b.height_m)
          << "left the closed box at dt " << dt << " step " << i;
    }
  }
}

TEST(StiffCases, MillionRandomSteps) {
  Rng rng(20240601);
  table::Board b = box_board(0.9, 1.11, 5e-4);
  b.ball.speed_max_mps = 5.0;
  // Random bumpers and short walls in the upper part of the table, clear of the flippers.
  for (int i = 0; i < 12; ++i) {
    add_circle(b, {rng.uniform(0.06, 0.45), rng.uniform(0.45, 1.0)}, rng.uniform(0.0, 0.03), rng.uniform(0.5, 1.4));
  }
  for (int i = 0; i < 6; ++i) {
    const Vec2 a{rng.uniform(0.05, 0.46), rng.uniform(0.40, 1.0)};
    const double ang = rng.uniform(0.0, 2.0 * std::numbers::pi);
    add_wall(b, a, a + rng.uniform(0.02, 0.1) * Vec2{std::cos(ang), std::sin(ang)}, rng.uniform(0.4, 1.0));
  }
  add_flipper(b, table::Side::kLeft, {0.14, 0.15}, 0.076, -0.5, 0.5, 33.0, 0.5, 1.0);
  add_flipper(b, table::Side::kRight, {0.37, 0.15}, 0.076, -0.5, 0.5, 33.0, 0.5, 1.0);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.25, 0.9}, {1.0, 0.3});
  // The box walls are one-sided lines with inward normals: the ball must stay inside.
  int relaunches = 0;
  long events = 0;
  for (long i = 0; i < 1000000; ++i) {
    if (rng.uniform01() < 0.01) {
      for (auto& fs : s.flippers) fs.energized = rng.uniform01() < 0.5;
    }
    if (i % 100000 == 0 && i > 0) {
      // Throw the ball back in somewhere random to cover more of the table.
      Vec2 p{rng.uniform(0.05, 0.46), rng.uniform(0.3, 1.0)};
      s.ball.position_m = p;
      if (max_penetration_m(b, s) == 0.0) {
        s.ball.velocity_mps = {rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0)};
        ++relaunches;
      } else {
        s.ball.position_m = {0.25, 0.9};
      }
    }
    const StepEvents ev = stepper.step(s);
    events += ev.flags != 0 ? 1 : 0;
    ASSERT_TRUE(s.ball_in_play) << "step " << i;
    ASSERT_TRUE(invariants_hold(b, s, i));
    const Vec2& p = s.ball.position_m;
    ASSERT_TRUE(p.x() > kR - kMaxDepth && p.x() < b.width_m - kR + kMaxDepth && p.y() > kR - kMaxDepth &&
                p.y() < b.height_m - kR + kMaxDepth)
        << "escaped the box at step " << i << ": (" << p.x() << ", " << p.y() << ")";
  }
  EXPECT_GT(events, 1000);
  EXPECT_GT(relaunches, 0);
}

// The "a million random steps on the full table": the thesis board,
// flippers pressed at random, balls relaunched as they drain.
TEST(StiffCases, MillionRandomStepsOnTheThesisTable) {
  const table::Board b = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const std::unique_ptr<World> world = make_model_world(b);
  GameState s = make_game_state(b, 99);
  Rng rng(4242);
  long launches = 0;
  for (long i = 0; i < 1000000; ++i) {
    // A fresh launch whenever a ball drains, and every 50 s anyway, so that
    // the million steps cover many different trajectories.
    if (i % 100000 == 0 && s.ball_in_play) cut_ball(b, s);
    if (!s.ball_in_play) {
      begin_ball(*world, s, rng.uniform(0.5, 1.0));
      ++launches;
    }
    if (rng.uniform01() < 0.02) {
      for (auto& fs : s.flippers) fs.energized = rng.uniform01() < 0.5;
    }
    const StepEvents ev = world->step(s);
    ASSERT_FALSE(ev.has(StepEvents::kLeftTable)) << "step " << i;
    ASSERT_TRUE(invariants_hold(b, s, i));
  }
  EXPECT_GE(launches, 10);
}

}  // namespace
}  // namespace pinball::sim
