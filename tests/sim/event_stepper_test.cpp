// The event stepper against closed-form answers: free flight, a ball
// bouncing to rest, sliding down an incline, an elastic box, a bounce off a
// circle; flippers (rolling off a raised one, striking a resting ball); the
// energy invariant; and agreement with the thesis stepper at a tiny dt.

#include "pinball/sim/model_world.h"
#include "pinball/sim/event_stepper.h"
#include "pinball/sim/game_rules.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "common/ball_radius.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/table/board_loader.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/sim/penetration.h"
#include "pinball/sim/thesis_stepper.h"
#include "test_boards.h"

namespace pinball::sim {
namespace {

using namespace pinball::sim::testing;
using pinball::testing::kR;

double energy(const table::Board& b, const GameState& s) {
  return 0.5 * s.ball.velocity_mps.squaredNorm() + b.gravity_mps2 * s.ball.position_m.y();
}

TEST(EventStepper, RejectsBadSettings) {
  const table::Board b = box_board();
  EventStepperOptions o;
  o.dt_s = -1.0;
  EXPECT_THROW(EventStepper(b, o), std::invalid_argument);
  o = {};
  o.relative_tolerance = 0.0;
  EXPECT_THROW(EventStepper(b, o), std::invalid_argument);
  o = {};
  o.rest_height_m = NAN;
  EXPECT_THROW(EventStepper(b, o), std::invalid_argument);
  EXPECT_EQ(EventStepper(b).dt_s(), b.dt_s);
}

TEST(EventStepper, FreeFlightIsTheParabola) {
  // The step horizon is not an integration step: the only error is the
  // round-off of storing the state once per step.
  table::Board b = empty_board(10.0, 30.0, 1.11, 1e-2);
  const Vec2 p0{5.0, 5.0}, v0{0.3, 5.55};
  for (const double dt : {1e-2, 5e-4}) {
    EventStepperOptions o;
    o.dt_s = dt;
    const EventStepper stepper(b, o);
    GameState s = state_with_ball(b, p0, v0);
    const int steps = static_cast<int>(std::lround(10.0 / dt));
    double worst = 0.0;
    for (int i = 0; i < steps; ++i) {
      stepper.step(s);
      const double t = (i + 1) * dt;
      const Vec2 exact = p0 + t * v0 - Vec2{0.0, 0.5 * b.gravity_mps2 * t * t};
      worst = std::max(worst, (s.ball.position_m - exact).norm());
    }
    // 1000 state updates: 1e-12 m; 20000: their round-off adds up to a few 1e-12.
    EXPECT_LT(worst, dt > 1e-3 ? 1e-12 : 1e-11) << "dt " << dt;
    EXPECT_NEAR(s.time_s, 10.0, 1e-9);
    EXPECT_EQ(s.events, 0u);
    EXPECT_EQ(s.steps, static_cast<std::uint64_t>(steps));
  }
}

TEST(EventStepper, BouncesOnAFloorFollowTheGeometricSeriesThenRest) {
  const double g = 1.11, rho = 0.8, h0 = 0.3;
  table::Board b = empty_board(1.0, 1.0, g, 5e-4);
  add_line(b, {-1.0, 0.0}, {2.0, 0.0}, rho);
  const EventStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, kR + h0}, Vec2::Zero());
  // Impact k happens at t1·(1 + 2ρ + ... + 2ρ^(k−1)), t1 = sqrt(2 h0 / g);
  // the apex after it is h0·ρ^(2k).
  const double t1 = std::sqrt(2.0 * h0 / g);
  int bounces = 0;
  double next_impact = t1;
  for (int i = 0; i < 20000 && bounces < 30; ++i) {
    const StepEvents e = stepper.step(s);
    if (!e.has(StepEvents::kHitObstacle)) continue;
    const double y = s.ball.position_m.y() - kR;
    const double vy = s.ball.velocity_mps.y();
    if (vy <= 0.0) break;  // came to rest on this bounce
    ++bounces;
    // Back out the impact time and the apex from the parabola after it.
    const double w = std::sqrt(vy * vy + 2.0 * g * y);
    const double impact = s.time_s - (w - vy) / g;
    const double apex = y + vy * vy / (2.0 * g);
    EXPECT_NEAR(impact, next_impact, 1e-9) << "bounce " << bounces;
    EXPECT_NEAR(apex, h0 * std::pow(rho, 2 * bounces), 1e-9) << "bounce " << bounces;
    next_impact += 2.0 * t1 * std::pow(rho, bounces);
  }
  // Rest once the apex would be below rest_height (1e-5 m): 23 bounces from 0.3 m.
  EXPECT_GE(bounces, 20);
  EXPECT_LE(bounces, 25);
  for (int i = 0; i < 20000; ++i) stepper.step(s);  // 10 more seconds
  const std::uint64_t events = s.events;
  EXPECT_LT(events, 40u);
  for (int i = 0; i < 2000; ++i) stepper.step(s);
  EXPECT_EQ(s.events, events) << "a resting ball has no more events";
  EXPECT_NEAR(s.ball.position_m.y(), kR, 1e-9);
  EXPECT_EQ(s.ball.velocity_mps.norm(), 0.0);
}

// The event stepper scores by the same rule: strikes, not rest.
TEST(EventStepper, ARestingBallScoresOnlyItsStrikes) {
  const double g = 1.11, rho = 0.8, h0 = 0.3;
  table::Board b = empty_board(1.0, 1.0, g, 5e-4);
  table::Action a;
  a.score = 200.0;
  add_line(b, {-1.0, 0.0}, {2.0, 0.0}, rho, a);
  const EventStepper stepper(b);
  GameState s = state_with_ball(b, {0.5, kR + h0}, Vec2::Zero());
  const int strikes = scoring_bounces(g, h0, rho, sim::rules::kMinStrikeSpeed_mps);
  for (int i = 0; i < 40000; ++i) stepper.step(s);  // 20 s: at rest for most of it
  EXPECT_EQ(s.score, 200.0 * strikes);
}

TEST(EventStepper, LooseTolerancesCostPrecisionNotPhysics) {
  // The root tolerance may only move impacts by about tolerance·size: the
  // same bounces must happen. (A touch speed once derived from it reached
  // metres per second at 1e-6 and turned real bounces into slides.)
  const double g = 1.11, h0 = 0.3, rho = 0.8;
  table::Board floor = empty_board(1.0, 1.0, g, 5e-4);
  add_line(floor, {0.0, 0.0}, {1.0, 0.0}, rho);  // size: 1 m
  const table::Board box = box_board(1.0, g, 5e-4);    // elastic, 0.51 x 1.07 m
  for (const double tol : {1e-6, 1e-8, 1e-10}) {
    EventStepperOptions o;
    o.relative_tolerance = tol;
    const EventStepper bouncing(floor, o);
    GameState s = state_with_ball(floor, {0.5, kR + h0}, Vec2::Zero());
    int bounces = 0;
    double worst_apex = 0.0;
    for (int i = 0; i < 20000 && bounces < 30; ++i) {
      if (!bouncing.step(s).has(StepEvents::kHitObstacle)) continue;
      const double y = s.ball.position_m.y() - kR;
      const double vy = s.ball.velocity_mps.y();
      if (vy <= 0.0) break;
      ++bounces;
      const double apex = y + vy * vy / (2.0 * g);
      worst_apex = std::max(worst_apex, std::abs(apex - h0 * std::pow(rho, 2 * bounces)));
    }
    EXPECT_GE(bounces, 20) << "tolerance " << tol;  // as at the default: the series, then rest
    EXPECT_LE(bounces, 25) << "tolerance " << tol;
    EXPECT_LT(worst_apex, 10.0 * tol) << "tolerance " << tol;

    // rho = 1 walls: every bounce keeps the energy; none may become a slide.
    const EventStepper elastic(box, o);
    const GameState start = state_with_ball(box, {0.2, 0.5}, {1.3, 0.7});
    GameState d = start;
    for (int i = 0; i < 4000; ++i) elastic.step(d);
    EXPECT_NEAR(energy(box, d), energy(box, start), 100.0 * tol) << "tolerance " << tol;
    EXPECT_GT(d.events, 4u) << "tolerance " << tol;
  }
}

TEST(EventStepper, SlidesDownAnInclineUniformlyAccelerated) {
  const double g = 1.11, alpha = 0.3;
  table::Board b = empty_board(2.0, 2.0, g, 5e-4);
  const Vec2 a{0.0, 1.5}, c{2.0, 1.5 - 2.0 * std::tan(alpha)};
  add_line(b, a, c, 0.5);
  const EventStepper stepper(b);
  const table::Shape& line = b.shapes[0];
  const Vec2 tangent = (c - a).normalized();
  const Vec2 start = a + 0.1 * tangent + kR * line.normal;
  GameState s = state_with_ball(b, start, Vec2::Zero());
  for (int i = 0; i < 2000; ++i) {
    stepper.step(s);
    const double t = (i + 1) * 5e-4;
    const double along = 0.5 * g * std::sin(alpha) * t * t;
    const Vec2 exact = start + along * tangent;
    ASSERT_LT((s.ball.position_m - exact).norm(), 1e-9) << "t = " << t;
  }
  EXPECT_LT(s.events, 5u);
}

TEST(EventStepper, ElasticBoxIsPeriodic) {
  const double g = 1.11;
  table::Board b = box_board(1.0, g, 5e-4);
  const EventStepper stepper(b);
  // Dropped from rest 0.5 m above the floor: period 2·sqrt(2h/g).
  const double h = 0.5;
  const Vec2 start{0.2, kR + h};
  GameState s = state_with_ball(b, start, Vec2::Zero());
  const double period = 2.0 * std::sqrt(2.0 * h / g);
  const double e0 = energy(b, s);
  double t_next = period;
  int periods = 0;
  while (periods < 5) {
    // Step exactly to the period's end with a shorter last step.
    EventStepperOptions o;
    const double left = t_next - s.time_s;
    o.dt_s = std::min(5e-4, left);
    const EventStepper part(b, o);
    part.step(s);
    if (std::abs(s.time_s - t_next) < 1e-12) {
      ++periods;
      EXPECT_LT((s.ball.position_m - start).norm(), 1e-9) << "period " << periods;
      EXPECT_LT(s.ball.velocity_mps.norm(), 1e-8);
      t_next += period;
    }
  }
  // Diagonal motion: energy is kept to round-off over 10 s of bounces.
  GameState d = state_with_ball(b, {0.2, 0.5}, {1.3, 0.7});
  for (int i = 0; i < 20000; ++i) {
    stepper.step(d);
    ASSERT_NEAR(energy(b, d), energy(b, state_with_ball(b, {0.2, 0.5}, {1.3, 0.7})), 1e-11);
  }
  EXPECT_GT(d.events, 20u);
  (void)e0;
}

TEST(EventStepper, BounceOffACircleIsTheReflectedRay) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  const Vec2 c{0.5, 0.5};
  const double radius = 0.05;
  add_circle(b, c, radius, 1.0);
  const EventStepper stepper(b);
  const Vec2 p0{0.2, 0.52}, v0{1.0, 0.0};
  GameState s = state_with_ball(b, p0, v0);
  // Closed form: |p0 + v0·t − c| = R + r.
  const double reach = radius + kR;
  const Vec2 d = p0 - c;
  const double bq = d.dot(v0), cq = d.squaredNorm() - reach * reach;
  const double t_hit = cq / (-bq + std::sqrt(bq * bq - cq));
  const Vec2 hit = p0 + t_hit * v0;
  const Vec2 n = (hit - c) / reach;
  const Vec2 v1 = v0 - 2.0 * v0.dot(n) * n;
  for (int i = 0; i < 800; ++i) stepper.step(s);
  const double t = 800 * 5e-4;
  EXPECT_LT((s.ball.position_m - (hit + (t - t_hit) * v1)).norm(), 1e-12);
  EXPECT_LT((s.ball.velocity_mps - v1).norm(), 1e-12);
  EXPECT_EQ(s.events, 1u);
}

TEST(EventStepper, AThickWallAndWallFrictionAreTheClosedForm) {
  // A 6 mm guide along y = 0.5 with friction 0.1: the ball, 0.5 m/s along it
  // and 1 m/s into it, turns round one radius off the face, 3 mm from the
  // line, and leaves along it at 0.5 − 0.1·2·0.5/√1.25 m/s.
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  add_wall(b, {0.1, 0.5}, {0.9, 0.5}, 1.0);
  for (table::Obstacle& o : b.obstacles) o.friction = 0.1;
  table::set_wall_thickness(b, 0.006);
  const EventStepper stepper(b);
  GameState s = state_with_ball(b, {0.3, 0.6}, {0.5, -1.0});
  double closest_m = INFINITY;
  for (int i = 0; i < 400; ++i) {
    stepper.step(s);
    closest_m = std::min(closest_m, s.ball.position_m.y() - 0.5);
  }
  EXPECT_NEAR(closest_m, 0.003 + kR, 1e-5);
  EXPECT_NEAR(s.ball.velocity_mps.y(), 1.0, 1e-12);
  EXPECT_NEAR(s.ball.velocity_mps.x(), 0.5 - 0.1 * 2.0 * 0.5 / std::sqrt(1.25), 1e-12);
  EXPECT_EQ(s.events, 1u);
}

table::Board flipper_board() {
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  add_line(b, {-1.0, 0.0}, {2.0, 0.0}, 0.5);  // a floor far below
  add_flipper(b, table::Side::kLeft, {0.3, 0.4}, 0.076, -0.5, 0.5, 33.0, 0.6, 1.6);
  return b;
}

TEST(EventStepper, BallOnARaisedFlipperRollsOff) {
  const table::Board b = flipper_board();
  const table::Flipper& f = b.flippers[0];
  const EventStepper stepper(b);
  GameState s = make_game_state(b, 1);
  s.flippers[0].theta_rad = f.theta_max_rad;
  s.flippers[0].energized = s.flippers[0].was_energized = true;
  const Vec2 start = f.pivot + 0.06 * table::flipper_direction(f, f.theta_max_rad) +
                     kR * table::flipper_up_normal(f, f.theta_max_rad);
  s.ball_in_play = true;
  s.ball.position_m = start;
  s.ball.velocity_mps = Vec2::Zero();
  const double e0 = energy(b, s);
  bool left_flipper = false;
  for (int i = 0; i < 4000 && s.ball_in_play; ++i) {
    stepper.step(s);
    ASSERT_LT(max_penetration_m(b, s), 1e-9) << "step " << i;
    ASSERT_LE(energy(b, s), e0 + 1e-12) << "step " << i;
    if (s.ball.position_m.x() < f.pivot.x() - kR) left_flipper = true;
  }
  EXPECT_TRUE(left_flipper) << "the ball rolls down the raised flipper past its pivot";
  EXPECT_LT(s.ball.position_m.y(), f.pivot.y());
  EXPECT_LT(s.events, 2000u);
}

TEST(EventStepper, FlipperStrikesARestingBallWithTheThesisImpulse) {
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  add_flipper(b, table::Side::kLeft, {0.3, 0.4}, 0.076, 0.0, 0.5, 33.0, 0.6, 1.6);  // rests horizontal
  const table::Flipper& f = b.flippers[0];
  const EventStepper stepper(b);
  GameState s = make_game_state(b, 1);
  const double arm = 0.05;
  s.ball_in_play = true;
  s.ball.position_m = f.pivot + Vec2{arm, kR};
  s.ball.velocity_mps = Vec2::Zero();
  stepper.step(s);  // rests on the horizontal face
  EXPECT_LT(s.ball.velocity_mps.norm(), 1e-12);
  s.flippers[0].energized = true;
  const StepEvents e = stepper.step(s);
  EXPECT_TRUE(e.has(StepEvents::kFlipperPush));
  // Struck at t = 0 at rest: v = μ·θ̇·l·n with n straight up, then a step of gravity.
  const Vec2 v = s.ball.velocity_mps + Vec2{0.0, b.gravity_mps2 * stepper.dt_s()};
  EXPECT_NEAR(v.x(), 0.0, 1e-12);
  EXPECT_NEAR(v.y(), f.mu * f.omega_rad_s * arm, 1e-9);
  EXPECT_EQ(s.events, 1u);
}

// A ball at rest with no acceleration (g = 0; a corner) has no speed of its own: the certified
// search's least step had come from the ball's speed alone, jumped the whole horizon and let the
// blade's tip sweep 3.5 mm deep through the ball. Struck, the ball then overlapped the blade while it
// separated and crept 1e-13 s per step, frozen with its 3 m/s until the ball was cut.
TEST(EventStepper, ATurningBladeStrikesABallAtRestAndTheBallFliesOff) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  add_flipper(b, table::Side::kLeft, {0.3, 0.3}, 0.08, -0.5, 0.5, 35.0, 0.6, 1.6);
  const table::Flipper& f = b.flippers[0];
  const EventStepper stepper(b);
  GameState s = make_game_state(b, 1);
  s.ball_in_play = true;
  s.ball.position_m = {0.39, 0.300001};  // the tip passes 10 mm from its centre, inside r = 13.5 mm
  s.ball.velocity_mps = Vec2::Zero();
  s.flippers[0].theta_rad = f.theta_min_rad;
  s.flippers[0].energized = true;
  bool struck = false;
  for (int i = 0; i < 200 && s.ball_in_play; ++i) {
    const Vec2 before = s.ball.position_m;
    const StepEvents e = stepper.step(s);
    ASSERT_LT(max_penetration_m(b, s), 1e-9) << "step " << i << ", blade at " << s.flippers[0].theta_rad;
    struck = struck || e.has(StepEvents::kFlipperPush) || e.has(StepEvents::kHitFlipper);
    if (struck && e.flags == 0) {  // free flight at g = 0: it moves as fast as it says
      EXPECT_NEAR((s.ball.position_m - before).norm(), s.ball.velocity_mps.norm() * stepper.dt_s(), 1e-9)
          << "step " << i;
    }
  }
  EXPECT_TRUE(struck);
  EXPECT_GT(s.ball.velocity_mps.norm(), 1.0);
  EXPECT_GT((s.ball.position_m - Vec2(0.39, 0.300001)).norm(), 0.1) << "it left where it was struck";
}

// A ball pushed by one flipper into another's blade, and a ball resting against a pivot: the pinch rule
// had ignored other flippers (the guard alone held the ball, 177597 events) and taken a pivot, which
// never moves, for a closing face (the flipper stalled for as long as it was held).
TEST(EventStepper, AnotherFlipperPinchesAndAPivotDoesNot) {
  const table::Board two = ball_between_two_flippers();
  const EventStepper with_two(two);
  GameState s = state_with_ball(two, two.start->position, Vec2::Zero());
  s.flippers[0].energized = true;
  for (int i = 0; i < 400; ++i) {
    const std::uint64_t before = s.events;
    with_two.step(s);
    ASSERT_LT(s.events - before, 64u) << "step " << i;
    ASSERT_LT(max_penetration_m(two, s), 1e-9) << "step " << i;
  }
  const table::Board pivot = table::parse_board(R"(pinball-board 1
size 1 1
ball 0.0135 5
gravity 1.11
dt 0.0005
balls 1
launcher 0.9 0.9 noise=0
start 0.5105 0.4915 0 0
flipper right 0.5 0.5 0.08 -0.5 0.5 35 rho=0.6 mu=1.6 name=rf
line 0.49 0.4775 0.7 0.4800 name=floor
wall 0.7 0.48 0.7 0.6 name=back
)", "pivot.board");  // the ball rests in the corner of the floor and the pivot, behind the blade
  const EventStepper at_pivot(pivot);
  s = state_with_ball(pivot, pivot.start->position, Vec2::Zero());
  s.flippers[0].energized = true;
  for (int i = 0; i < 200; ++i) at_pivot.step(s);
  EXPECT_EQ(s.flippers[0].theta_rad, pivot.flippers[0].theta_max_rad) << "the stroke is 29 ms";
}

// A kickout faster than the speed clamp is clamped, as the thesis stepper's next step clamps it: the
// event stepper had flown it at 100 m/s under a 5 m/s clamp until its first collision.
TEST(EventStepper, AKickoutFasterThanTheClampIsClamped) {
  table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
  b.ball.speed_max_mps = 5.0;
  b.sensors.push_back(exact_kickout_hole({0.5, 0.5}, 0.01, {0.0, 100.0}));
  const EventStepper stepper(b);
  GameState s = state_with_ball(b, {0.3, 0.5}, {1.0, 0.0});
  bool kicked = false;
  for (int i = 0; i < 1000 && !kicked; ++i) {
    kicked = stepper.step(s).has(StepEvents::kSensor);
    ASSERT_LE(s.ball.velocity_mps.norm(), 5.0 + 1e-12) << "step " << i;
  }
  ASSERT_TRUE(kicked);
  EXPECT_NEAR(s.ball.velocity_mps.y(), 5.0, 1e-12);
}

TEST(EventStepper, EnergyNeverGrowsWithoutKickersOrFlippers) {
  table::Board b = box_board(0.9, 1.11, 5e-4);
  add_circle(b, {0.15, 0.70}, 0.03, 0.95);
  add_circle(b, {0.35, 0.72}, 0.03, 1.0);
  add_point(b, {0.40, 0.45}, 0.9);
  add_wall(b, {0.05, 0.40}, {0.15, 0.30}, 0.7);
  add_wall(b, {0.46, 0.40}, {0.36, 0.30}, 0.7);
  add_line(b, {0.0, 0.25}, {0.255, 0.05}, 0.5);  // a V at the bottom, its joint a point
  add_line(b, {0.255, 0.05}, {0.51, 0.25}, 0.5);
  add_point(b, {0.255, 0.05}, 0.5);
  const EventStepper stepper(b);
  Rng rng(3);
  for (int run = 0; run < 20; ++run) {
    GameState s = state_with_ball(b, {rng.uniform(0.1, 0.4), rng.uniform(0.5, 1.0)},
                                  {rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)});
    bool clear = true;
    for (const table::Shape& shape : b.shapes) clear = clear && table::distance_to_shape(shape, s.ball.position_m) > kR;
    if (!clear) continue;  // a start inside an obstacle
    double e = energy(b, s);
    for (int i = 0; i < 20000; ++i) {
      stepper.step(s);
      ASSERT_TRUE(finite(s.ball.position_m) && finite(s.ball.velocity_mps));
      const double now = energy(b, s);
      ASSERT_LE(now, e + 1e-12) << "run " << run << " step " << i;
      ASSERT_LT(max_penetration_m(b, s), 1e-9) << "run " << run << " step " << i;
      e = now;
    }
    EXPECT_LT(s.ball.velocity_mps.norm(), 1e-6) << "run " << run << ": settled in the V";
    EXPECT_LT(s.events, 20000u) << "run " << run;
  }
}

TEST(EventStepper, WedgesHoldTheBallStillWithoutChatter) {
  // V's of 1°, 45° and 179° opening, symmetric about the vertical, lines
  // 2 m long meeting at a point; the ball dropped into them off-centre.
  for (const double opening_deg : {1.0, 45.0, 179.0}) {
    const double half = 0.5 * opening_deg * std::numbers::pi / 180.0;
    table::Board b = empty_board(4.0, 3.0, 1.11, 5e-4);
    const Vec2 vertex{2.0, 0.2};
    const Vec2 left = vertex + 2.0 * Vec2{-std::sin(half), std::cos(half)};
    const Vec2 right = vertex + 2.0 * Vec2{std::sin(half), std::cos(half)};
    add_line(b, left, vertex, 0.6);
    add_line(b, vertex, right, 0.6);
    add_point(b, vertex, 0.6);
    const EventStepper stepper(b);
    // Start inside the V, off its axis, clear of both lines.
    const double dx = opening_deg < 10.0 ? 1e-3 : 0.1;
    const double h0 = std::min(1.9 * std::cos(half), dx / std::tan(half) + 2.0 * kR / std::sin(half));
    GameState s = state_with_ball(b, vertex + Vec2{dx, h0}, Vec2::Zero());
    ASSERT_GT(table::distance_to_shape(b.shapes[0], s.ball.position_m), kR);
    ASSERT_GT(table::distance_to_shape(b.shapes[1], s.ball.position_m), kR);
    double e = energy(b, s);
    std::uint64_t events_at_19s = 0;
    for (int i = 0; i < 40000; ++i) {  // 20 s
      stepper.step(s);
      ASSERT_TRUE(finite(s.ball.position_m) && finite(s.ball.velocity_mps));
      ASSERT_LT(max_penetration_m(b, s), 1e-9) << opening_deg << " deg, step " << i;
      const double now = energy(b, s);
      ASSERT_LE(now, e + 1e-12) << opening_deg << " deg, step " << i;
      e = now;
      if (i == 38000) events_at_19s = s.events;
    }
    EXPECT_TRUE(s.ball_in_play) << opening_deg << " deg";
    EXPECT_LT(s.events, 2000u) << opening_deg << " deg";
    if (opening_deg > 170.0) {
      // Nearly flat and frictionless: the ball slides to and fro across the
      // vertex, losing only the normal speed of the 1° turn there; it stays
      // on the lines and inside its first swing.
      const double d0 = table::distance_to_shape(b.shapes[0], s.ball.position_m);
      const double d1 = table::distance_to_shape(b.shapes[1], s.ball.position_m);
      EXPECT_NEAR(std::min(d0, d1), kR, 1e-9);
      EXPECT_LE(std::abs(s.ball.position_m.x() - vertex.x()), dx + 1e-9);
      continue;
    }
    EXPECT_LT(s.ball.velocity_mps.norm(), 1e-9) << opening_deg << " deg: at rest";
    EXPECT_EQ(s.events, events_at_19s) << opening_deg << " deg: no events while resting";
    // Held by both lines, on the axis.
    EXPECT_NEAR(table::distance_to_shape(b.shapes[0], s.ball.position_m), kR, 1e-9) << opening_deg << " deg";
    EXPECT_NEAR(table::distance_to_shape(b.shapes[1], s.ball.position_m), kR, 1e-9) << opening_deg << " deg";
  }
}

TEST(EventStepper, AgreesWithTheThesisStepperAtTinyDt) {
  const table::Board b = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  ThesisStepperOptions to;
  to.dt_s = 1e-5;
  const ThesisStepper thesis(b, to);
  EventStepperOptions eo;
  eo.dt_s = 1e-3;
  const EventStepper event(b, eo);
  GameState a = make_game_state(b, 5);
  GameState e = make_game_state(b, 5);
  launch_ball(b, a, 0.95);
  launch_ball(b, e, 0.95);
  ASSERT_EQ(a.ball.velocity_mps, e.ball.velocity_mps);
  double worst = 0.0;
  for (int i = 0; i < 330; ++i) {  // 0.33 s: up the chute, round the hook, down the lane
    event.step(e);
    for (int k = 0; k < 100; ++k) thesis.step(a);
    worst = std::max(worst, (a.ball.position_m - e.ball.position_m).norm());
  }
  EXPECT_GT(e.events, 2u);
  // Euler's lag g·dt·t/2 (2 µm) plus the thesis's 1 µm separations; later
  // the bounces off the hook's polyline amplify any difference (chaos).
  EXPECT_LT(worst, 1e-5);
}

TEST(EventStepper, PlaysBallsOnMit1993WithoutPenetration) {
  const table::Board b = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  ModelWorldOptions event;
  event.stepper = StepperKind::kEvent;
  const std::unique_ptr<World> world = make_model_world(b, event);
  GameState s = make_game_state(b, 11);
  BallLimits limits;
  limits.max_ball_time_s = 60.0;
  double worst = 0.0;
  for (int ball = 0; ball < 4; ++ball) {
    play_ball(*world, s, limits, [&](GameState& st) { simlab::oracle_spastic_policy(b, st); },
              [&](const GameState& st, const StepEvents&) {
                ASSERT_TRUE(finite(st.ball.position_m) && finite(st.ball.velocity_mps));
                if (st.ball_in_play) worst = std::max(worst, max_penetration_m(b, st));
              });
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(s.events, 10u);
}

}  // namespace
}  // namespace pinball::sim
