#include "pinball/sim/thesis_stepper.h"

#include <gtest/gtest.h>

#include "common/ball_radius.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "pinball/sim/game_rules.h"
#include "pinball/sim/collision.h"
#include "pinball/sim/penetration.h"
#include "pinball/table/board_loader.h"
#include "test_boards.h"

namespace pinball::sim {
namespace {

using namespace pinball::sim::testing;

using pinball::testing::kR;

TEST(ThesisStepper, FreeFlightIsSemiImplicitEuler) {
  const double g = 1.11;
  const double dt = 5e-4;
  table::Board b = empty_board(10.0, 10.0, g, dt);
  const ThesisStepper stepper(b);
  const Vec2 p0{2.0, 5.0};
  const Vec2 v0{0.3, 1.2};
  GameState s = state_with_ball(b, p0, v0);
  for (int n = 1; n <= 4000; ++n) {
    const StepEvents ev = stepper.step(s);
    ASSERT_EQ(ev.flags, 0u);
    const double nn = n;
    const double x = p0.x() + v0.x() * nn * dt;
    const double y = p0.y() + v0.y() * nn * dt - g * dt * dt * nn * (nn + 1.0) / 2.0;
    ASSERT_NEAR(s.ball.position_m.x(), x, 1e-12) << n;
    ASSERT_NEAR(s.ball.position_m.y(), y, 1e-12) << n;
    ASSERT_NEAR(s.ball.velocity_mps.y(), v0.y() - g * nn * dt, 1e-12) << n;
    // Against the true parabola the error is exactly g·dt·t/2 (below it).
    const double t = nn * dt;
    const double y_true = p0.y() + v0.y() * t - 0.5 * g * t * t;
    ASSERT_NEAR(y_true - s.ball.position_m.y(), g * dt * t / 2.0, 1e-12) << n;
    ASSERT_NEAR(s.time_s, t, 1e-12);
  }
  EXPECT_EQ(s.steps, 4000u);
  EXPECT_TRUE(s.ball_in_play);
}

TEST(ThesisStepper, BallOutOfPlayDoesNotMove) {
  table::Board b = empty_board();
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, 0.5}, {1.0, 1.0});
  s.ball_in_play = false;
  stepper.step(s);
  EXPECT_EQ(s.ball.position_m, Vec2(0.5, 0.5));
  EXPECT_EQ(s.steps, 1u);
}

TEST(ThesisStepper, ReflectionOffHorizontalLineScalesNormalSpeedByRho) {
  for (double rho : {0.5, 1.0, 1.5}) {
    table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
    const int floor = add_line(b, {0.0, 0.2}, {1.0, 0.2}, rho);
    const ThesisStepper stepper(b);
    const double vx = 0.7;
    const double vy = -2.0;
    GameState s = state_with_ball(b, {0.3, 0.26}, {vx, vy});
    bool hit = false;
    for (int i = 0; i < 200 && !hit; ++i) {
      const Vec2 before = s.ball.position_m;
      const StepEvents ev = stepper.step(s);
      if (ev.has(StepEvents::kHitObstacle)) {
        hit = true;
        EXPECT_EQ(ev.obstacle, floor);
        EXPECT_NEAR(s.ball.velocity_mps.y(), -rho * vy, 1e-14) << rho;
        EXPECT_NEAR(s.ball.velocity_mps.x(), vx, 1e-14) << rho;
        // The ball moved to one separation short of the surface (along the
        // normal), reflected, and spent the rest of the step on the new
        // velocity (docs/physics.md: the step continues after a contact).
        const double dt = stepper.dt_s();
        const double y_contact = 0.2 + kR + stepper.options().separation_m;
        const double t_move = (before.y() - y_contact) / -vy;
        ASSERT_GT(t_move, 0.0);
        ASSERT_LT(t_move, dt);
        EXPECT_NEAR(s.ball.position_m.y(), y_contact + (dt - t_move) * (-rho * vy), 1e-12);
        EXPECT_NEAR(s.ball.position_m.x(), before.x() + vx * dt, 1e-12);
      } else {
        EXPECT_EQ(s.ball.velocity_mps, Vec2(vx, vy));
      }
    }
    ASSERT_TRUE(hit) << rho;
    for (int i = 0; i < 50; ++i) stepper.step(s);
    EXPECT_NEAR(s.ball.velocity_mps.y(), -rho * vy, 1e-14);
    EXPECT_GT(s.ball.position_m.y(), 0.2 + kR);
  }
}

TEST(ThesisStepper, AThickWallBouncesTheBallOffItsFaceOnBothSides) {
  for (const double side : {1.0, -1.0}) {
    table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
    add_wall(b, {0.1, 0.5}, {0.9, 0.5}, 1.0);
    table::set_wall_thickness(b, 0.006);
    const ThesisStepper stepper(b);
    GameState s = state_with_ball(b, {0.5, 0.5 + side * 0.1}, {0.0, -side * 1.0});
    double closest_m = INFINITY;
    for (int i = 0; i < 400; ++i) {
      stepper.step(s);
      closest_m = std::min(closest_m, side * (s.ball.position_m.y() - 0.5));
    }
    // It turned round one radius off the face, 3 mm from the line, and kept its speed.
    EXPECT_NEAR(closest_m, 0.003 + kR, 1e-5) << side;
    EXPECT_NEAR(s.ball.velocity_mps.y(), side * 1.0, 1e-12);
  }
}

TEST(ThesisStepper, ReflectionUsesVelocityAfterGravityUpdate) {
  const double g = 9.81;
  const double dt = 1e-3;
  table::Board b = empty_board(1.0, 1.0, g, dt);
  add_line(b, {0.0, 0.0}, {1.0, 0.0}, 0.5);
  const ThesisStepper stepper(b);
  // Reaches the line within the first step: incoming vy = -1 - g·dt.
  GameState s = state_with_ball(b, {0.5, kR + 5e-4}, {0.0, -1.0});
  const StepEvents ev = stepper.step(s);
  ASSERT_TRUE(ev.has(StepEvents::kHitObstacle));
  EXPECT_NEAR(s.ball.velocity_mps.y(), 0.5 * (1.0 + g * dt), 1e-14);
}

TEST(ThesisStepper, BallBouncesUpOffTheTipOfAVerticalWall) {
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  add_wall(b, {0.5, 0.0}, {0.5, 0.3}, 1.0);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, 0.4}, {0.0, -1.0});
  bool hit = false;
  for (int i = 0; i < 400; ++i) {
    const StepEvents ev = stepper.step(s);
    ASSERT_LT(max_penetration_m(b, s), 1e-6);
    if (ev.has(StepEvents::kHitObstacle) && !hit) {
      hit = true;
      EXPECT_EQ(b.shapes[ev.obstacle].kind, table::ShapeKind::kCircle);  // the end point, not the faces
      EXPECT_GT(s.ball.velocity_mps.y(), 0.9);
      EXPECT_NEAR(s.ball.velocity_mps.x(), 0.0, 1e-12);
    }
    ASSERT_GT(s.ball.position_m.y(), 0.3 + kR - 1e-6) << "fell past the tip at step " << i;
  }
  EXPECT_TRUE(hit);
  EXPECT_GT(s.ball.position_m.y(), 0.3);
}

TEST(ThesisStepper, BallLeftOfTheTipBouncesLeft) {
  for (double side : {-1.0, 1.0}) {
    table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
    add_wall(b, {0.5, 0.0}, {0.5, 0.3}, 1.0);
    const ThesisStepper stepper(b);
    GameState s = state_with_ball(b, {0.5 + side * 0.004, 0.4}, {0.0, -1.0});
    for (int i = 0; i < 600; ++i) {
      stepper.step(s);
      ASSERT_LT(max_penetration_m(b, s), 1e-6);
      // Never on the wrong side of the wall.
      if (s.ball.position_m.y() < 0.3) {
        ASSERT_GT(side * (s.ball.position_m.x() - 0.5), kR - 1e-6);
      }
    }
    EXPECT_GT(side * s.ball.velocity_mps.x(), 0.2);
    EXPECT_GT(side * (s.ball.position_m.x() - 0.5), 0.05);
  }
}

TEST(ThesisStepper, BallBehindOneSidedLinePassesThrough) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  add_line(b, {0.0, 0.5}, {1.0, 0.5}, 1.0);  // normal +y: hit from above only
  const ThesisStepper stepper(b);
  const Vec2 v{0.2, 1.5};
  GameState s = state_with_ball(b, {0.4, 0.4}, v);
  for (int i = 0; i < 200; ++i) {
    const StepEvents ev = stepper.step(s);
    ASSERT_FALSE(ev.has(StepEvents::kHitObstacle));
  }
  EXPECT_EQ(s.ball.velocity_mps, v);
  EXPECT_NEAR(s.ball.position_m.y(), 0.4 + 1.5 * 200 * 5e-4, 1e-12);
  EXPECT_GT(s.ball.position_m.y(), 0.5 + kR);
}

TEST(ThesisStepper, SpeedClampHoldsEveryStep) {
  table::Board b = empty_board(1.0, 50.0, 9.81, 5e-4);
  b.ball.speed_max_mps = 2.0;
  add_line(b, {0.0, 0.0}, {1.0, 0.0}, 1.0);
  add_line(b, {1.0, 0.0}, {1.0, 50.0}, 1.0);
  add_line(b, {0.0, 50.0}, {0.0, 0.0}, 1.0);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, 45.0}, {3.0 * 2.0 * 0.6, -3.0 * 2.0 * 0.8});
  double max_speed_seen = 0.0;
  for (int i = 0; i < 60000; ++i) {  // 30 s: falls 45 m at the clamp, then bounces
    stepper.step(s);
    const double speed = s.ball.velocity_mps.norm();
    ASSERT_LE(speed, 2.0 + 1e-12) << "step " << i;
    max_speed_seen = std::max(max_speed_seen, speed);
  }
  EXPECT_GT(max_speed_seen, 2.0 - 1e-9);  // it did reach the clamp
  EXPECT_TRUE(s.ball_in_play);
}

// A ball bouncing across a slot 1 µm wider than itself meets more walls in
// one step than the step resolves; the rest of the step is dropped, and the
// speed into the walls goes with it (an inelastic rest on both), while the
// speed along them is kept: it falls down the slot as if the walls were not there.
TEST(ThesisStepperWedged, BallInASlotKeepsOnlyTheSpeedAlongTheWalls) {
  const double g = 1.11, dt = 1e-3;
  table::Board b = empty_board(1.0, 2.0, g, dt);
  const double left = 0.5 - kR - 0.5e-6, right = 0.5 + kR + 0.5e-6;
  add_line(b, {left, 1.9}, {left, 0.1}, 1.0);    // normal +x: faces the slot
  add_line(b, {right, 0.1}, {right, 1.9}, 1.0);  // normal -x: faces the slot
  const ThesisStepper stepper(b, ThesisStepperOptions{.dt_s = dt});
  GameState s = state_with_ball(b, {0.5, 1.5}, {2.0, -0.5});
  stepper.step(s);
  EXPECT_EQ(s.ball.velocity_mps.x(), 0.0);
  EXPECT_NEAR(s.ball.velocity_mps.y(), -0.5 - g * dt, 1e-12);
  for (int i = 0; i < 100; ++i) {
    stepper.step(s);
    ASSERT_LE(s.ball.velocity_mps.norm(), 0.5 + g * dt * (i + 2) + 1e-12) << "step " << i;
  }
  EXPECT_NEAR(s.ball.velocity_mps.y(), -0.5 - 101 * g * dt, 1e-9);
  EXPECT_LT(s.ball.position_m.y(), 1.5 - 0.5 * 100 * dt);  // it fell
  EXPECT_LT(max_penetration_m(b, s), 1e-6);
}

// In a V of 1.2° the contacts run out in every step; before the fix the ball
// was held in place while gravity fed its velocity (issue 17: |v| ≈ 3720·dt).
TEST(ThesisStepperWedged, BallWedgedInANarrowVStaysSlow) {
  const double g = 1.11, dt = 1e-3;
  const double half = 0.6 * M_PI / 180.0;
  const double wedge_h = kR / std::sin(half);
  table::Board b = empty_board(1.0, wedge_h + 0.5, g, dt);
  const Vec2 apex{0.5, 0.05};
  add_wall(b, apex, apex + (wedge_h + 0.3) * Vec2{-std::sin(half), std::cos(half)}, 0.5);
  add_wall(b, apex, apex + (wedge_h + 0.3) * Vec2{std::sin(half), std::cos(half)}, 0.5);
  const ThesisStepper stepper(b, ThesisStepperOptions{.dt_s = dt});
  GameState s = state_with_ball(b, apex + Vec2{0.0, wedge_h + 1e-4}, Vec2::Zero());
  const double e0 = 0.5 * s.ball.velocity_mps.squaredNorm() + g * s.ball.position_m.y();
  for (int i = 0; i < 10000; ++i) {
    stepper.step(s);
    ASSERT_LT(s.ball.velocity_mps.norm(), 0.05) << "step " << i;
    ASSERT_LE(0.5 * s.ball.velocity_mps.squaredNorm() + g * s.ball.position_m.y(), e0 + 1e-9) << "step " << i;
  }
  EXPECT_LT(max_penetration_m(b, s), 1e-6);
}

// The wedge rule takes the velocity into every surface the ball still touches when a step's contacts
// run out. "Touches" had been judged on each contact's infinite plane: a 1 mm ball at 100 m/s, dt 10 ms,
// that rattled on 0.1 m past a needle's end counted as still on it and lost 99.6 % of its energy in
// one step (t = 0.44 s here). The surface itself must be near too.
TEST(ThesisStepperWedged, ABallThatRattledAwayFromAContactIsNotHeldByIt) {
  const table::Board b = table::parse_board(R"(pinball-board 1
size 1 2
ball 0.001 100
gravity 10
dt 0.01
balls 1
launcher 0.05 0.05 noise=0
start 0.5 1.9 73 -68.3
defaults rho=1
wall 0.01 0.01 0.99 0.01 name=bottom
wall 0.99 0.01 0.99 1.99 name=right
wall 0.99 1.99 0.01 1.99 name=top
wall 0.01 1.99 0.01 0.01 name=left
polygon 0.280907047 1.556844979 0.207203571 1.624430463 0.207202895 1.624429726 0.280906371 1.556844242 name=needle0
polygon 0.320648139 0.942867721 0.336449484 1.041611417 0.336448497 1.041611575 0.320647152 0.942867879 name=needle1
polygon 0.558273209 1.476298513 0.653957243 1.505359924 0.653956953 1.505360881 0.558272919 1.476299470 name=needle2
polygon 0.159361149 1.521911763 0.180326296 1.619689381 0.180325318 1.619689591 0.159360172 1.521911972 name=needle3
polygon 0.675060016 0.104314319 0.692133084 0.202846092 0.692132099 0.202846263 0.675059031 0.104314489 name=needle4
polygon 0.704340867 0.530341704 0.605815349 0.547450833 0.605815178 0.547449848 0.704340696 0.530340719 name=needle5
polygon 0.731158937 0.198009702 0.830839583 0.205995243 0.830839503 0.205996240 0.731158858 0.198010699 name=needle6
polygon 0.510758978 1.699995268 0.547219415 1.793111521 0.547218484 1.793111885 0.510758047 1.699995633 name=needle7
polygon 0.251827572 0.863042290 0.351411675 0.872153071 0.351411584 0.872154067 0.251827481 0.863043286 name=needle8
polygon 0.304526874 0.844413230 0.305842459 0.944404576 0.305841459 0.944404589 0.304525874 0.844413243 name=needle9
polygon 0.274512003 0.510749301 0.351806862 0.574196167 0.351806228 0.574196940 0.274511368 0.510750074 name=needle10
polygon 0.421836363 0.639255215 0.521608557 0.646001277 0.521608489 0.646002275 0.421836295 0.639256212 name=needle11
polygon 0.3 1.0 0.299127330 0.800000000 0.300872670 0.800000000 name=spike0
polygon 0.7 0.5 0.699127330 0.300000000 0.700872670 0.300000000 name=spike1
)", "needles.board");
  const ThesisStepper stepper(b);
  GameState s = make_game_state(b, 1);
  s.ball_in_play = true;
  s.ball.position_m = b.start->position;
  s.ball.velocity_mps = b.start->velocity_mps;
  auto energy = [&] { return 0.5 * s.ball.velocity_mps.squaredNorm() + b.gravity_mps2 * s.ball.position_m.y(); };
  for (int i = 0; i < 100 && s.ball_in_play; ++i) {  // 1 s
    const double before = energy();
    stepper.step(s);
    // The thesis's Euler step moves energy by up to 2·g·|v|·dt = 20 J/kg here; a held ball loses ~5000.
    ASSERT_GT(energy(), before - 100.0) << "step " << i;
  }
}

TEST(LaunchBall, SpeedWithinNoiseBand) {
  table::Board b = empty_board();
  b.ball.speed_max_mps = 5.0;
  b.launcher.noise_max = 0.03;
  GameState s = make_game_state(b, 17);
  const double pull = 0.9;
  const double hi = pull * b.ball.speed_max_mps;
  const double lo = pull * (1.0 - b.launcher.noise_max) * b.ball.speed_max_mps;
  double vmin = INFINITY;
  double vmax = -INFINITY;
  for (int i = 0; i < 1000; ++i) {
    s.ball.position_m = {0.1, 0.1};
    launch_ball(b, s, pull);
    ASSERT_TRUE(s.ball_in_play);
    ASSERT_EQ(s.ball.position_m, b.launcher.position);
    ASSERT_EQ(s.ball.velocity_mps.x(), 0.0);
    const double vy = s.ball.velocity_mps.y();
    ASSERT_GE(vy, lo - 1e-12);
    ASSERT_LE(vy, hi + 1e-12);
    vmin = std::min(vmin, vy);
    vmax = std::max(vmax, vy);
  }
  // 1000 uniform draws: the extremes lie within 1 % of the band from its ends
  // unless something has gone wrong (probability 0.99^1000 = 4e-5 each).
  EXPECT_LT(vmin - lo, 0.01 * (hi - lo));
  EXPECT_LT(hi - vmax, 0.01 * (hi - lo));
}

// A ball falling onto a horizontal line at y = 0.2 with the given action.
struct DropOnLine {
  explicit DropOnLine(table::Action action, double rho = 1.0) : board(empty_board(1.0, 1.0, 0.0, 5e-4)) {
    line = add_line(board, {0.0, 0.2}, {1.0, 0.2}, rho, action);
  }
  table::Board board;
  int line = -1;
};

TEST(ThesisStepperActions, KickAddsSpeedAlongNormal) {
  table::Action a;
  a.kick_mps = 1.25;
  DropOnLine d(a, 0.8);
  const ThesisStepper stepper(d.board);
  GameState s = state_with_ball(d.board, {0.5, 0.25}, {0.3, -1.0});
  for (int i = 0; i < 200; ++i) {
    if (stepper.step(s).has(StepEvents::kHitObstacle)) break;
  }
  EXPECT_NEAR(s.ball.velocity_mps.y(), 0.8 * 1.0 + 1.25, 1e-14);
  EXPECT_NEAR(s.ball.velocity_mps.x(), 0.3, 1e-14);
}

TEST(ThesisStepperActions, ScoreEachHit) {
  table::Action a;
  a.score = 50.0;
  DropOnLine d(a, 1.0);
  table::Board& b = d.board;
  add_line(b, {1.0, 0.5}, {0.0, 0.5}, 1.0);  // ceiling (normal -y), no score
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, 0.35}, {0.0, -1.0});
  int hits = 0;
  double gained = 0.0;
  for (int i = 0; i < 4000; ++i) {  // 2 s: period of a round trip is 2·(0.3 - 2r) / 1 = 0.546 s
    const StepEvents ev = stepper.step(s);
    if (ev.has(StepEvents::kHitObstacle) && ev.obstacle == d.line) ++hits;
    gained += ev.score_gained;
  }
  EXPECT_EQ(hits, 4);
  EXPECT_EQ(s.score, 50.0 * hits);
  EXPECT_EQ(gained, s.score);
}

// A hit scores when the ball strikes, not while it rests or rolls on the
// obstacle: a ball dropped on a scoring floor scores its bounces down to the
// strike speed, then nothing while it rolls along it for 5 s.
TEST(ThesisStepperActions, ARestingOrRollingBallScoresNothing) {
  const double g = 1.11, rho = 0.5, h0 = 0.05;
  table::Board b = empty_board(4.0, 1.0, g, 5e-4);
  table::Action a;
  a.score = 200.0;
  add_line(b, {-1.0, 0.1}, {5.0, 0.1}, rho, a);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, 0.1 + kR + h0}, {0.2, 0.0});
  const int strikes = scoring_bounces(g, h0, rho, sim::rules::kMinStrikeSpeed_mps);
  int touches = 0;
  for (int i = 0; i < 10000; ++i) touches += stepper.step(s).has(StepEvents::kHitObstacle) ? 1 : 0;
  EXPECT_EQ(s.score, 200.0 * strikes);
  EXPECT_GT(touches, 100) << "the rolling ball keeps touching the floor";
  EXPECT_NEAR(s.ball.position_m.y(), 0.1 + kR, 1e-3);
  EXPECT_GT(s.ball.position_m.x(), 1.0) << "and rolls on";
}

// An eating obstacle eats a ball that only rolls onto it.
TEST(ThesisStepperActions, AnEaterEatsARollingBall) {
  table::Board b = empty_board(2.0, 1.0, 1.11, 5e-4);
  add_line(b, {-1.0, 0.1}, {3.0, 0.1}, 0.5);  // a floor
  table::Action eat;
  eat.eats_ball = true;
  add_line(b, {1.0, 0.1}, {1.0, 0.3}, 0.0, eat);  // a wall across it, facing the ball (normal -x)
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.8, 0.1 + kR + 1e-6}, {0.01, 0.0});
  bool lost = false;
  for (int i = 0; i < 100000 && !lost; ++i) lost = stepper.step(s).has(StepEvents::kBallLost);
  EXPECT_TRUE(lost);
}

TEST(ThesisStepperActions, EatsBallEndsIt) {
  table::Action a;
  a.eats_ball = true;
  DropOnLine d(a);
  const ThesisStepper stepper(d.board);
  GameState s = state_with_ball(d.board, {0.5, 0.25}, {0.0, -1.0});
  ASSERT_EQ(s.balls_left, 3);
  bool lost = false;
  for (int i = 0; i < 200 && !lost; ++i) lost = stepper.step(s).has(StepEvents::kBallLost);
  EXPECT_TRUE(lost);
  EXPECT_FALSE(s.ball_in_play);
  EXPECT_EQ(s.balls_left, 2);
  EXPECT_EQ(s.ball.position_m, d.board.launcher.position);
  const Vec2 rest = s.ball.position_m;
  stepper.step(s);
  EXPECT_EQ(s.ball.position_m, rest);  // out of play: does not move
}

TEST(ThesisStepperActions, LeavingTheTableLosesTheBall) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, 0.5}, {0.0, -3.0});
  StepEvents last;
  for (int i = 0; i < 1000 && s.ball_in_play; ++i) last = stepper.step(s);
  EXPECT_FALSE(s.ball_in_play);
  EXPECT_TRUE(last.has(StepEvents::kLeftTable));
  EXPECT_TRUE(last.has(StepEvents::kBallLost));
  EXPECT_EQ(s.balls_left, 2);
}

TEST(ThesisStepperActions, BankFlagsHideAndReappearWithBonus) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  table::Action flag_action;
  flag_action.score = 10.0;
  const int f0 = add_line(b, {0.1, 0.2}, {0.3, 0.2}, 1.0, flag_action, "flag0");
  const int f1 = add_line(b, {0.6, 0.2}, {0.8, 0.2}, 1.0, flag_action, "flag1");
  b.obstacles[f0].bank = 0;
  b.obstacles[f1].bank = 0;
  // Each flag is its own statement of the board file (a flag falls as a whole statement).
  b.obstacles[f0].source_line = 11;
  b.obstacles[f1].source_line = 12;
  table::Bank bank;
  bank.name = "bank";
  bank.bonus = 500.0;
  bank.members = {f0, f1};
  b.banks.push_back(bank);
  const ThesisStepper stepper(b);
  GameState s = make_game_state(b, 1);
  s.ball_in_play = true;

  auto drop_at = [&](double x) {
    s.ball.position_m = {x, 0.3};
    s.ball.velocity_mps = {0.0, -1.0};
    for (int i = 0; i < 400; ++i) {
      const StepEvents ev = stepper.step(s);
      if (ev.flags != 0) return ev;
    }
    return StepEvents{};
  };

  StepEvents ev = drop_at(0.2);
  ASSERT_TRUE(ev.has(StepEvents::kHitObstacle));
  EXPECT_EQ(ev.obstacle, f0);
  EXPECT_FALSE(ev.has(StepEvents::kBankComplete));
  EXPECT_EQ(s.visible[f0], 0);
  EXPECT_EQ(s.visible[f1], 1);
  EXPECT_EQ(s.score, 10.0);
  // A hidden flag is not hit: the ball falls through where it was.
  s.ball.position_m = {0.2, 0.3};
  s.ball.velocity_mps = {0.0, -1.0};
  for (int i = 0; i < 400; ++i) ASSERT_FALSE(stepper.step(s).has(StepEvents::kHitObstacle));
  EXPECT_LT(s.ball.position_m.y(), 0.2);

  ev = drop_at(0.7);
  ASSERT_TRUE(ev.has(StepEvents::kHitObstacle));
  EXPECT_EQ(ev.obstacle, f1);
  EXPECT_TRUE(ev.has(StepEvents::kBankComplete));
  EXPECT_EQ(s.visible[f0], 1);
  EXPECT_EQ(s.visible[f1], 1);
  EXPECT_EQ(s.score, 10.0 + 10.0 + 500.0);
  EXPECT_EQ(ev.score_gained, 510.0);
}

TEST(ThesisStepperSensors, ProximityFiresOncePerEntryWithoutChangingVelocity) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  table::Sensor sensor;
  sensor.kind = table::SensorKind::kProximity;
  sensor.shape.kind = table::ShapeKind::kCircle;
  sensor.shape.p0 = {0.5, 0.5};
  sensor.shape.radius_m = 0.03;
  sensor.action.score = 7.0;
  b.sensors.push_back(sensor);
  const ThesisStepper stepper(b);
  const Vec2 v{1.0, 0.0};
  GameState s = state_with_ball(b, {0.3, 0.51}, v);
  int fired = 0;
  int steps_inside = 0;
  for (int i = 0; i < 800; ++i) {  // passes the sensor, 0.4 m in 0.4 s
    const StepEvents ev = stepper.step(s);
    if (ev.has(StepEvents::kSensor)) {
      ++fired;
      EXPECT_EQ(ev.sensor, 0);
    }
    steps_inside += s.sensor_inside[0];
    ASSERT_EQ(s.ball.velocity_mps, v);
  }
  EXPECT_EQ(fired, 1);
  EXPECT_GT(steps_inside, 50);  // it was inside for many steps but fired once
  EXPECT_EQ(s.score, 7.0);
  // Coming back is a new entry.
  s.ball.velocity_mps = -v;
  for (int i = 0; i < 800; ++i) fired += stepper.step(s).has(StepEvents::kSensor) ? 1 : 0;
  EXPECT_EQ(fired, 2);
  EXPECT_EQ(s.score, 14.0);
}

TEST(ThesisStepperSensors, FastBallCannotSkipALineSensor) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 1e-3);
  b.ball.speed_max_mps = 50.0;
  table::Sensor sensor;
  sensor.kind = table::SensorKind::kProximity;
  sensor.shape.kind = table::ShapeKind::kLine;
  sensor.shape.p0 = {0.5, 0.0};
  sensor.shape.p1 = {0.5, 1.0};
  sensor.shape.normal = {-1.0, 0.0};
  b.sensors.push_back(sensor);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.2137, 0.5}, {40.0, 0.0});  // 4 cm per step, past the 2.7 cm band
  int fired = 0;
  for (int i = 0; i < 15; ++i) fired += stepper.step(s).has(StepEvents::kSensor) ? 1 : 0;
  EXPECT_EQ(fired, 1);
}

TEST(ThesisStepperSensors, HoleWithKickoutPlacesBallAtCentre) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  table::Sensor hole = exact_kickout_hole({0.5, 0.5}, 0.01, {-0.8, 1.5});  // the spread has its own test below
  hole.action.score = 100.0;
  b.sensors.push_back(hole);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.3, 0.505}, {1.0, 0.0});
  const Rng rng_before = s.rng;
  int fired = 0;
  bool checked = false;
  for (int i = 0; i < 1000; ++i) {
    const StepEvents ev = stepper.step(s);
    if (ev.has(StepEvents::kSensor)) {
      ++fired;
      if (!checked) {
        checked = true;
        EXPECT_EQ(s.ball.position_m, hole.shape.p0);
        EXPECT_EQ(s.ball.velocity_mps, hole.kickout_mps);
        EXPECT_TRUE(s.ball_in_play);
        EXPECT_EQ(s.score, 100.0);
      }
    }
  }
  EXPECT_EQ(fired, 1);  // the kicked-out ball leaves without re-entering
  Rng a = rng_before, b2 = s.rng;
  EXPECT_EQ(a.next_u64(), b2.next_u64()) << "an exact kickout draws nothing from the game's stream";
  EXPECT_TRUE(checked);
  EXPECT_LT(s.ball.position_m.x(), 0.5 - 0.1);
}

// A saucer's kickout scatters (issue 17): each kickout is the nominal one
// turned by U[−spread, spread] and slowed by U[0, noise], drawn from the
// game's stream, so the same seed gives the same kickouts and different seeds
// different ones.
TEST(ThesisStepperSensors, HoleKickoutScattersWithinItsSpreadFromTheGameSeed) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  table::Sensor hole;
  hole.kind = table::SensorKind::kHole;
  hole.shape = table::make_circle_shape({0.5, 0.5}, 0.01);
  hole.has_kickout = true;
  hole.kickout_mps = {-0.8, 1.5};
  hole.kickout_spread_rad = 0.1;
  hole.kickout_noise = 0.2;
  b.sensors.push_back(hole);
  const ThesisStepper stepper(b);
  const double nominal_angle = std::atan2(1.5, -0.8), nominal_speed = std::hypot(0.8, 1.5);
  auto kickout = [&](std::uint64_t seed) {
    GameState s = state_with_ball(b, {0.3, 0.505}, {1.0, 0.0}, seed);
    for (int i = 0; i < 1000; ++i) {
      if (stepper.step(s).has(StepEvents::kSensor)) return s.ball.velocity_mps;
    }
    ADD_FAILURE() << "the ball never reached the hole";
    return Vec2(Vec2::Zero());
  };
  double min_da = INFINITY, max_da = -INFINITY, min_f = INFINITY, max_f = -INFINITY;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const Vec2 v = kickout(seed);
    EXPECT_EQ(v, kickout(seed)) << "same seed, same kickout";
    const double da = std::remainder(std::atan2(v.y(), v.x()) - nominal_angle, 2.0 * M_PI);
    const double f = v.norm() / nominal_speed;
    ASSERT_LE(std::abs(da), 0.1 + 1e-12) << seed;
    ASSERT_GT(f, 0.8 - 1e-12) << seed;
    ASSERT_LE(f, 1.0 + 1e-12) << seed;
    min_da = std::min(min_da, da), max_da = std::max(max_da, da);
    min_f = std::min(min_f, f), max_f = std::max(max_f, f);
  }
  // 200 draws cover most of each band.
  EXPECT_LT(min_da, -0.08);
  EXPECT_GT(max_da, 0.08);
  EXPECT_LT(min_f, 0.84);
  EXPECT_GT(max_f, 0.96);
}

TEST(ThesisStepperSensors, HoleWithoutKickoutEatsBall) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  table::Sensor hole;
  hole.kind = table::SensorKind::kHole;
  hole.shape.kind = table::ShapeKind::kCircle;
  hole.shape.p0 = {0.5, 0.5};
  hole.shape.radius_m = 0.01;
  hole.action.eats_ball = true;
  b.sensors.push_back(hole);
  const ThesisStepper stepper(b);
  // Passing 15 mm from the centre: the ball's edge overlaps but its centre never enters.
  GameState miss = state_with_ball(b, {0.3, 0.515}, {1.0, 0.0});
  for (int i = 0; i < 800; ++i) ASSERT_FALSE(stepper.step(miss).has(StepEvents::kSensor));
  GameState s = state_with_ball(b, {0.3, 0.505}, {1.0, 0.0});
  bool lost = false;
  for (int i = 0; i < 800 && !lost; ++i) lost = stepper.step(s).has(StepEvents::kBallLost);
  EXPECT_TRUE(lost);
  EXPECT_FALSE(s.ball_in_play);
  EXPECT_EQ(s.balls_left, 2);
}

TEST(ThesisStepperActions, ContactScoreAccumulatesWhileRolling) {
  table::Board b = empty_board(2.0, 1.0, 1.11, 5e-4);
  table::Action a;
  a.contact_score_per_s = 40.0;
  add_line(b, {0.0, 0.1}, {2.0, 0.1}, 0.5, a);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.2, 0.1 + kR + 1e-6}, {0.3, 0.0});
  const int n = 4000;  // 2 s, rolls 0.6 m
  for (int i = 0; i < n; ++i) stepper.step(s);
  EXPECT_NEAR(s.score, 40.0 * n * 5e-4, 1e-9);
  // Away from the line: nothing.
  GameState far = state_with_ball(b, {0.2, 0.6}, {0.3, 0.0});
  for (int i = 0; i < 100; ++i) stepper.step(far);
  EXPECT_EQ(far.score, 0.0);
}

// A ball in resting contact with a line must keep its tangential motion:
// sliding along a flat floor, and sliding down a slope under gravity. The
// speed clamp stands in for friction, so over a short run the motion along
// the surface is that of a frictionless slide (thesis eq. 3.1-3.2 between
// contacts, the reflection only touching the normal component).
TEST(ThesisStepperResting, BallSlidesAlongFlatLine) {
  table::Board b = empty_board(2.0, 1.0, 1.11, 5e-4);
  add_line(b, {0.0, 0.1}, {2.0, 0.1}, 0.5);
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.2, 0.1 + kR + 1e-6}, {0.3, 0.0});
  const int n = 4000;  // 2 s
  for (int i = 0; i < n; ++i) {
    stepper.step(s);
    ASSERT_LT(max_penetration_m(b, s), 1e-6);
  }
  EXPECT_NEAR(s.ball.velocity_mps.x(), 0.3, 1e-12);
  // The ball's velocity says 0.3 m/s along the floor, so its position must follow.
  EXPECT_NEAR(s.ball.position_m.x(), 0.2 + 0.3 * n * 5e-4, 1e-3);
}

TEST(ThesisStepperResting, BallSlidesDownSlope) {
  const double a = 20.0 * M_PI / 180.0;
  const double g = 1.11;
  table::Board b = empty_board(3.0, 3.0, g, 5e-4);
  const Vec2 p0{0.1, 2.0};
  const Vec2 p1{2.9, 2.0 - 2.8 * std::tan(a)};
  add_line(b, p0, p1, 0.5);
  const ThesisStepper stepper(b);
  const Vec2 along = (p1 - p0).normalized();
  const Vec2 start = p0 + 0.2 * along + (kR + 1e-6) * b.shapes[0].normal;
  GameState s = state_with_ball(b, start, Vec2::Zero());
  const int n = 2000;  // 1 s: a frictionless slide covers g·sin(a)·t²/2 = 0.19 m
  for (int i = 0; i < n; ++i) {
    stepper.step(s);
    ASSERT_LT(max_penetration_m(b, s), 1e-6);
  }
  const double t = n * 5e-4;
  const double expected = 0.5 * g * std::sin(a) * t * t;
  EXPECT_NEAR((s.ball.position_m - start).dot(along), expected, 0.05 * expected);
  // Its velocity must match the distance it covered: speed ~ g·sin(a)·t.
  EXPECT_NEAR(s.ball.velocity_mps.dot(along), g * std::sin(a) * t, 0.05 * g * std::sin(a) * t);
}

// --- Flippers ---------------------------------------------------------------

struct FlipperBoard {
  FlipperBoard(double gravity = 0.0, double theta_min = -0.5) : board(empty_board(1.0, 1.0, gravity, 5e-4)) {
    add_flipper(board, table::Side::kLeft, {0.3, 0.3}, 0.076, theta_min, 0.5, 33.0, 0.5, 1.0);
  }
  table::Board board;
};

TEST(ThesisStepperFlippers, EnergisedRisesAtOmegaAndStops) {
  FlipperBoard fb;
  const table::Flipper& f = fb.board.flippers[0];
  const ThesisStepper stepper(fb.board);
  GameState s = make_game_state(fb.board, 1);
  const double dt = stepper.dt_s();
  s.flippers[0].energized = true;
  const int n_up = static_cast<int>(std::ceil((f.theta_max_rad - f.theta_min_rad) / (f.omega_rad_s * dt)));
  for (int n = 1; n <= n_up + 20; ++n) {
    stepper.step(s);
    const double expected = std::min(f.theta_min_rad + n * f.omega_rad_s * dt, f.theta_max_rad);
    ASSERT_NEAR(s.flippers[0].theta_rad, expected, 1e-12) << n;
    if (n <= n_up) {
      ASSERT_EQ(s.flippers[0].omega_rad_s, f.omega_rad_s) << n;
    } else {
      ASSERT_EQ(s.flippers[0].omega_rad_s, 0.0) << n;
    }
  }
  EXPECT_EQ(s.flippers[0].theta_rad, f.theta_max_rad);
  EXPECT_EQ(s.flips, 1u);
  s.flippers[0].energized = false;
  for (int n = 1; n <= n_up + 20; ++n) {
    stepper.step(s);
    const double expected = std::max(f.theta_max_rad - n * f.omega_rad_s * dt, f.theta_min_rad);
    ASSERT_NEAR(s.flippers[0].theta_rad, expected, 1e-12) << n;
    if (n <= n_up) {
      ASSERT_EQ(s.flippers[0].omega_rad_s, -f.omega_rad_s) << n;
    }
  }
  EXPECT_EQ(s.flippers[0].theta_rad, f.theta_min_rad);
  EXPECT_EQ(s.flippers[0].omega_rad_s, 0.0);
  EXPECT_EQ(s.flips, 1u);
}

// Speed of a ball that starts at rest on the upper face at `arm` from the pivot
// after the flipper fires (no gravity, no obstacles).
double launch_speed(double arm) {
  FlipperBoard fb;
  const table::Flipper& f = fb.board.flippers[0];
  const ThesisStepper stepper(fb.board);
  const double theta = f.theta_min_rad;
  const Vec2 p = f.pivot + arm * table::flipper_direction(f, theta) + (kR + 1e-6) * table::flipper_up_normal(f, theta);
  GameState s = state_with_ball(fb.board, p, Vec2::Zero());
  s.flippers[0].energized = true;
  bool pushed = false;
  for (int i = 0; i < 100; ++i) {
    const StepEvents ev = stepper.step(s);
    pushed = pushed || ev.has(StepEvents::kFlipperPush) || ev.has(StepEvents::kHitFlipper);
    EXPECT_LT(max_penetration_m(fb.board, s), 1e-6);
  }
  EXPECT_TRUE(pushed);
  return s.ball.velocity_mps.norm();
}

TEST(ThesisStepperFlippers, BallNearTipLaunchedFasterThanNearPivot) {
  const double near_pivot = launch_speed(0.02);
  const double middle = launch_speed(0.045);
  const double near_tip = launch_speed(0.07);
  EXPECT_GT(middle, near_pivot);
  EXPECT_GT(near_tip, middle);
  // The first push imparts mu·omega·arm; later pushes can only add.
  EXPECT_GE(near_pivot, 1.0 * 33.0 * 0.02 * 0.99);
  EXPECT_GE(near_tip, 1.0 * 33.0 * 0.07 * 0.99);
}

// The thesis's chord rule (l·sin(ω·dt/2) < r) keeps the tip's chord between two steps below 2r, not
// the depth its arc reaches: at dt 9.5 ms (the largest stable one is 9.69 ms) the tip stepped from
// 17 mm one side of a resting ball to 17 mm the other, its arc 3.5 mm deep inside, and the ball was
// never struck. The blade now stops where its tip first touches the ball, and strikes it.
TEST(ThesisStepperFlippers, ATipWhoseArcCrossesTheBallBetweenStepsStrikesIt) {
  const double dt = 0.0095;
  table::Board b = empty_board(1.0, 1.5, 1.11, dt);
  add_flipper(b, table::Side::kLeft, {0.3, 0.3}, 0.08, -0.5, 0.5, 35.0, 0.6, 1.6);
  add_line(b, {0.385, 0.2865}, {0.45, 0.2865}, 0.6);  // a floor the ball rests on, under the tip's path
  ASSERT_LT(dt, table::max_stable_dt_s(b));
  const ThesisStepper stepper(b);
  GameState s = state_with_ball(b, {0.39, 0.300001}, Vec2::Zero());  // 9 cm from the pivot: 1 cm beyond the tip
  s.flippers[0].energized = true;
  bool struck = false;
  for (int i = 0; i < 10 && !struck; ++i) {
    const StepEvents e = stepper.step(s);
    ASSERT_LT(max_penetration_m(b, s), 1e-6) << "step " << i;
    struck = e.has(StepEvents::kFlipperPush);
    if (struck) {
      const table::Flipper& f = b.flippers[0];
      EXPECT_LT(s.flippers[0].theta_rad, 0.0) << "the blade stops short of the ball's direction, at the touch";
      const Vec2 from_tip = s.ball.position_m - table::flipper_tip(f, s.flippers[0].theta_rad);
      EXPECT_GT(from_tip.dot(s.ball.velocity_mps), 0.0) << "it flies off the tip (and has moved a step since)";
      EXPECT_GT(s.ball.velocity_mps.norm(), 1.0) << "struck by a tip moving at 2.8 m/s";
    }
  }
  EXPECT_TRUE(struck);
}

// A ball served at rest where the board's `start` puts it, then flipper 0 held energised.
GameState served(const table::Board& b) {
  GameState s = state_with_ball(b, b.start->position, b.start->velocity_mps);
  s.flippers[0].energized = true;
  return s;
}

// The sweep's push was checked for overlap at its end only: a long fast blade carried the ball's centre
// past a one-sided roof in one push (y 0.220 -> 0.266 through the roof at 0.236), where no overlap is
// counted, and pushed it through another flipper's blade. The flipper now stalls there.
TEST(ThesisStepperFlippers, ASweepPushesTheBallThroughNothing) {
  const table::Board roof = table::parse_board(R"(pinball-board 1
size 1 1.5
ball 0.0135 100
gravity 1.11
dt 0.0005
balls 1
launcher 0.9 1.4 noise=0
start 0.276787020527 0.220756600009 0 0
flipper right 0.45 0.3 0.2 -0.5 0.5 200.0 rho=0.6 mu=1.6 name=rf
line 0.326787021 0.236256600 0.226787021 0.236256600 name=roof
)", "roof.board");
  const ThesisStepper on_roof(roof);
  GameState s = served(roof);
  for (int i = 0; i < 200; ++i) {
    on_roof.step(s);
    const bool under = s.ball.position_m.x() > 0.2268 && s.ball.position_m.x() < 0.3268;
    ASSERT_FALSE(under && s.ball.position_m.y() > 0.2362566 - kR + 1e-6) << "step " << i << " crossed the roof";
  }
  const table::Board two = ball_between_two_flippers();  // the ball rests on rf, 5 mm under lf's blade
  const ThesisStepper with_two(two);
  s = served(two);
  for (int i = 0; i < 400; ++i) {
    with_two.step(s);
    ASSERT_LT(flipper_penetration_m(two, s, s.ball.position_m), 1e-6) << "step " << i;
  }
}

TEST(ThesisStepperFlippers, ContactSensorWhenBallRestsOnFlipper) {
  FlipperBoard fb(1.11, 0.0);  // horizontal at rest
  const table::Flipper& f = fb.board.flippers[0];
  const ThesisStepper stepper(fb.board);
  GameState s = state_with_ball(fb.board, f.pivot + Vec2{0.04, kR + 1e-6}, Vec2::Zero());
  for (int i = 0; i < 2000; ++i) {
    stepper.step(s);
    ASSERT_TRUE(s.flippers[0].ball_contact) << "step " << i;
    ASSERT_LT(max_penetration_m(fb.board, s), 1e-6);
  }
  EXPECT_NEAR(s.ball.position_m.x(), f.pivot.x() + 0.04, 1e-9);
  // Far from it: no contact.
  GameState away = state_with_ball(fb.board, f.pivot + Vec2{0.04, 0.1}, Vec2::Zero());
  stepper.step(away);
  EXPECT_FALSE(away.flippers[0].ball_contact);
}

TEST(ThesisStepperFlippers, FallingFlipperDoesNotPushBallAbove) {
  FlipperBoard fb(0.0);
  const table::Flipper& f = fb.board.flippers[0];
  const ThesisStepper stepper(fb.board);
  const double theta = f.theta_max_rad;
  const Vec2 p = f.pivot + 0.05 * table::flipper_direction(f, theta) + (kR + 1e-6) * table::flipper_up_normal(f, theta);
  GameState s = state_with_ball(fb.board, p, Vec2::Zero());
  s.flippers[0].theta_rad = theta;
  for (int i = 0; i < 100; ++i) {  // a full stroke takes 1 / (33 * 5e-4) = 61 steps
    const StepEvents ev = stepper.step(s);
    ASSERT_FALSE(ev.has(StepEvents::kFlipperPush));
  }
  EXPECT_EQ(s.ball.position_m, p);
  EXPECT_EQ(s.ball.velocity_mps, Vec2(Vec2::Zero()));
  EXPECT_EQ(s.flippers[0].theta_rad, f.theta_min_rad);
}

// --- Grid on / off ----------------------------------------------------------

TEST(ThesisStepper, GridOnAndOffAreBitIdentical) {
  const table::Board b = box_with_bumpers_and_flippers();
  ThesisStepperOptions on;
  on.use_grid = true;
  ThesisStepperOptions off;
  off.use_grid = false;
  const ThesisStepper a(b, on);
  const ThesisStepper c(b, off);
  GameState sa = state_with_ball(b, {0.25, 0.95}, {1.3, -0.4});
  GameState sc = sa;
  int hits = 0;
  int pushes = 0;
  for (int i = 0; i < 20000; ++i) {
    const bool up = (i / 300) % 2 == 1;
    for (auto& f : sa.flippers) f.energized = up;
    for (auto& f : sc.flippers) f.energized = up;
    const StepEvents ea = a.step(sa);
    const StepEvents ec = c.step(sc);
    ASSERT_EQ(ea.flags, ec.flags) << "step " << i;
    ASSERT_EQ(ea.obstacle, ec.obstacle) << "step " << i;
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the same bits is the assertion
    ASSERT_EQ(std::memcmp(sa.ball.position_m.data(), sc.ball.position_m.data(), sizeof(double) * 2), 0)
        << "step " << i;
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the same bits is the assertion
    ASSERT_EQ(std::memcmp(sa.ball.velocity_mps.data(), sc.ball.velocity_mps.data(), sizeof(double) * 2), 0)
        << "step " << i;
    ASSERT_EQ(sa.score, sc.score);
    hits += ea.has(StepEvents::kHitObstacle) ? 1 : 0;
    pushes += (ea.has(StepEvents::kFlipperPush) || ea.has(StepEvents::kHitFlipper)) ? 1 : 0;
    if (!sa.ball_in_play) {
      // Should not happen in a closed box; restart to keep the comparison going.
      ADD_FAILURE() << "ball lost at step " << i;
      break;
    }
  }
  EXPECT_GT(hits, 20);  // the run really exercised collisions
  // The grid really prunes: the largest cell lists fewer than all obstacles.
  EXPECT_LT(a.obstacle_grid().max_candidates(), b.shapes.size());
  EXPECT_EQ(c.obstacle_candidates({0.25, 0.5}).size(), b.shapes.size());
  EXPECT_GT(pushes, 0);  // and the flippers
}

// --- Constructor -------------------------------------------------------------

TEST(ThesisStepper, ConstructorChecksTimeStep) {
  table::Board b = box_with_bumpers_and_flippers();
  const double dt_max = table::max_stable_dt_s(b);
  ASSERT_TRUE(std::isfinite(dt_max));
  // Violates l·sin(omega·dt/2) < r.
  const double dt_bad = 1.01 * dt_max;
  ASSERT_GE(b.flippers[0].length_m * std::sin(b.flippers[0].omega_rad_s * dt_bad / 2.0), b.ball.radius_m);
  ThesisStepperOptions o;
  o.dt_s = dt_bad;
  EXPECT_THROW(ThesisStepper(b, o), std::invalid_argument);
  o.dt_s = 0.99 * dt_max;
  EXPECT_NO_THROW(ThesisStepper(b, o));
  // The board's dt is taken when the option is 0; a bad board dt throws too.
  b.dt_s = 2.0 * dt_max;
  EXPECT_THROW(ThesisStepper{b}, std::invalid_argument);
  o.dt_s = -1e-3;
  EXPECT_THROW(ThesisStepper(b, o), std::invalid_argument);
  o.dt_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(ThesisStepper(b, o), std::invalid_argument);
  b.dt_s = 1e-4;
  const ThesisStepper ok(b);
  EXPECT_EQ(ok.dt_s(), 1e-4);
}

}  // namespace
}  // namespace pinball::sim
