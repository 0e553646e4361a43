// The MuJoCo lab twin checked against physics (ctest -L twin): closed forms
// (a rolling ball's 5/7 g sin α, a rubber's restitution, the solenoid's
// stroke), the extreme cases (no tunnelling at 5 and 8 m/s, no energy from
// nowhere, no NaN) and the game (the same seed, the same game).

#include "pinball/simlab/twin_world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/thesis_board.h"
#include "common/twin_params.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/table/board_loader.h"

namespace pinball::simlab {
namespace {

// A board of the given elements on the standard playfield (mm, deg).
table::Board scene(const std::string& elements) {
  return table::parse_board("pinball-board 1\nunits mm\nangles deg\nsize 510 1070\nball 13.5 5000\ngravity 1110\n"
                            "dt 0.0005\nballs 1\nlauncher 255 100 noise=0\n" +
                                elements,
                            "scene");
}

// A ball on the playfield at (x, y) mm moving at (vx, vy) m/s, rolling.
TwinBall rolling_at(double x_mm, double y_mm, double vx, double vy, double r = 0.0135) {
  TwinBall b;
  b.position_m = {x_mm / 1000.0, y_mm / 1000.0, r};
  b.velocity_mps = {vx, vy, 0.0};
  b.angular_velocity_rad_s = {-vy / r, vx / r, 0.0};
  return b;
}

TEST(TwinWorld, ARollingBallAcceleratesAtFiveSeventhsOfGSinAlpha) {
  const table::Board board = scene("");
  TwinWorld world(board, testing::shipped_twin_params());
  sim::GameState state = sim::make_game_state(board, 1);
  world.place_ball(state, rolling_at(255, 900, 0.0, 0.0));
  const double y0 = world.ball().position_m.y();
  const double t_s = 0.4;
  const int steps = static_cast<int>(std::lround(t_s / world.dt_s()));
  for (int i = 0; i < steps; ++i) world.step(state);
  const double a = 2.0 * (y0 - world.ball().position_m.y()) / (t_s * t_s);
  const double expected = 5.0 / 7.0 * board.gravity_mps2;
  EXPECT_NEAR(a, expected, 0.02 * expected);
  EXPECT_NEAR(world.ball().position_m.z(), board.ball.radius_m, 1e-4) << "rolls on the playfield, never sinks";
}

TEST(TwinWorld, ASlidingBallEndsRollingAtFiveSevenths) {
  // A ball struck at its centre slides, friction spins it up, and it rolls at
  // 5/7 of its speed (the classic cue-ball result), less what the slope took.
  const table::Board board = scene("");
  TwinWorld world(board, testing::shipped_twin_params());
  sim::GameState state = sim::make_game_state(board, 1);
  TwinBall b;
  b.position_m = {0.1, 0.5, board.ball.radius_m};
  b.velocity_mps = {1.0, 0.0, 0.0};  // across the slope, no spin
  world.place_ball(state, b);
  for (int i = 0; i < 400; ++i) world.step(state);
  const TwinBall now = world.ball();
  EXPECT_NEAR(now.velocity_mps.x(), 5.0 / 7.0, 0.02);
  EXPECT_NEAR(now.angular_velocity_rad_s.y() * board.ball.radius_m, now.velocity_mps.x(), 0.01) << "rolling";
}

// Restitutions of a ball without spin thrown across the slope (along x) at a
// surface whose face is at x = face_x_m: normal speed just after the bounce
// over just before, for slow to fast impacts, each from a few starting
// points so that the first contact falls at different phases of a step. A
// rolling ball's spin would drive it on into the surface.
std::vector<double> rebounds(const table::Board& board, double start_x_m, double face_x_m) {
  const double dir = face_x_m > start_x_m ? 1.0 : -1.0;
  const double r = board.ball.radius_m;
  std::vector<double> out;
  for (const double speed : {0.5, 1.0, 2.0, 3.0, 5.0}) {
    for (int k = 0; k < 4; ++k) {
      TwinWorld world(board, testing::shipped_twin_params());
      sim::GameState state = sim::make_game_state(board, 1);
      TwinBall b;
      b.position_m = {start_x_m + dir * k * 0.25 * speed * world.dt_s(), 0.5, r};
      b.velocity_mps = {dir * speed, 0.0, 0.0};
      world.place_ball(state, b);
      double v_in = 0.0, v_out = 0.0;
      for (int i = 0; i < 2000 && v_out == 0.0; ++i) {
        const double vx = dir * world.ball().velocity_mps.x();
        world.step(state);
        const double gap = dir * (face_x_m - world.ball().position_m.x()) - r;
        if (vx > 0.0 && gap > 0.0) v_in = vx;                                           // approaching, not touching
        if (dir * world.ball().velocity_mps.x() < 0.0 && gap > 0.0) v_out = -dir * world.ball().velocity_mps.x();  // let go
      }
      EXPECT_GT(v_in, 0.0);
      out.push_back(v_out / v_in);
    }
  }
  return out;
}

// The configured restitution on average (within 5 %), and every bounce within
// 15 % of it: with six steps a bounce, where in a step it starts moves it.
void expect_restitution(const std::vector<double>& e_measured, double e) {
  double sum = 0.0;
  for (const double x : e_measured) {
    sum += x;
    EXPECT_NEAR(x, e, 0.15 * e);
    EXPECT_LT(x, 1.0) << "no energy from nowhere";
  }
  EXPECT_NEAR(sum / static_cast<double>(e_measured.size()), e, 0.05 * e);
}

TEST(TwinWorld, ABallReboundsOffARubberPostWithTheConfiguredRestitution) {
  const table::Board board = scene("circle 255 500 20 rho=0.9 name=post\n");
  expect_restitution(rebounds(board, 0.255 - 0.06, 0.255 - 0.02), testing::shipped_twin_params().rubber_restitution.value);
}

TEST(TwinWorld, ABallReboundsOffARailWithTheConfiguredRestitution) {
  const table::Board board = scene("wall 100 300 100 700 rho=0.6 name=rail\n");
  const double face = 0.1 + testing::shipped_twin_params().pin_radius_m.value;
  expect_restitution(rebounds(board, 0.2, face), testing::shipped_twin_params().rail_restitution.value);
}

TEST(TwinWorld, TheFlipperStrokeFollowsTheSolenoidModel) {
  // Unloaded stroke from θ_min to θ_max: I θ̈ = τ_p (1 − e^(−t/τ_r)) − τ_s, so
  // θ(t) − θ_min = [τ_p (t²/2 − τ_r t + τ_r² (1 − e^(−t/τ_r))) − τ_s t²/2] / I.
  // Left out of the closed form: gravity on the bat and the pivot's damping
  // (each under 1 % of the torque here).
  const table::Board board = scene("flipper left 150 200 76 -25 30 2000 rho=0.6 mu=1.6 name=f\n");
  const TwinParams& p = testing::shipped_twin_params();
  TwinWorld world(board, p);
  sim::GameState state = sim::make_game_state(board, 1);
  for (int i = 0; i < 100; ++i) world.step(state);  // settle at the stop
  const double sweep = board.flippers[0].theta_max_rad - board.flippers[0].theta_min_rad;
  const double theta0 = state.flippers[0].theta_rad;
  state.flippers[0].energized = true;
  double t_stroke = -1.0;
  for (int i = 0; i < 400 && t_stroke < 0.0; ++i) {
    const double before = state.flippers[0].theta_rad;
    world.step(state);
    const double after = state.flippers[0].theta_rad;
    if (after >= theta0 + sweep - 1e-9 || after < before - 1e-9) {
      // Interpolate the crossing of θ_max inside the step.
      const double f = std::clamp((theta0 + sweep - before) / std::max(after - before, 1e-12), 0.0, 1.0);
      t_stroke = (i + f) * world.dt_s();
    }
  }
  ASSERT_GT(t_stroke, 0.0);
  const double tp = p.coil_pulse_torque_nm.value, ts = p.return_spring_torque_nm.value, tr = p.coil_rise_s.value;
  const double inertia = p.flipper_inertia_kgm2.value;
  auto theta = [&](double t) {
    return (tp * (0.5 * t * t - tr * t + tr * tr * (1.0 - std::exp(-t / tr))) - 0.5 * ts * t * t) / inertia;
  };
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 100; ++i) (theta(0.5 * (lo + hi)) < sweep ? lo : hi) = 0.5 * (lo + hi);
  EXPECT_NEAR(t_stroke, lo, 0.02 * lo) << "closed form " << lo << " s";
  EXPECT_LT(t_stroke, 0.04) << "the design's stroke is about 30 ms";
}

TEST(TwinWorld, NoBallTunnelsThroughARailAPostOrAFlipperAt5And8MetresPerSecond) {
  // Every element faced head-on and at a glance, at 5 and 8 m/s: the ball's
  // centre never reaches the far side.
  const table::Board board = scene(
      "wall 100 600 400 600 name=wall\n"
      "line 100 300 400 300 name=floor\n"  // one-sided, normal +y
      "circle 255 850 10 name=post\n"
      "flipper left 150 150 76 -25 30 2000 rho=0.6 mu=1.6 name=f\n");
  struct Shot {
    double x_mm, y_mm, angle_deg;
    const char* what;
    double far_y_m;  // the centre must stay on this side
    bool below;      // far side is below far_y_m
  };
  const Shot shots[] = {
      {255, 700, -90, "wall from above", 0.600, true},      {255, 500, 90, "wall from below", 0.600, false},
      {255, 400, -90, "one-sided line", 0.300, true},       {150, 680, -60, "wall at a glance", 0.600, true},
      {255, 950, -90, "post", 0.850, true},                 {190, 300, -90, "flipper", 0.1313, true},
  };
  for (const double speed : {5.0, 8.0}) {
    for (const Shot& s : shots) {
      TwinWorld world(board, testing::shipped_twin_params());
      sim::GameState state = sim::make_game_state(board, 1);
      const double a = s.angle_deg * M_PI / 180.0;
      world.place_ball(state, rolling_at(s.x_mm, s.y_mm, speed * std::cos(a), speed * std::sin(a)));
      for (int i = 0; i < 300 && state.ball_in_play; ++i) {
        world.step(state);
        const double y = world.ball().position_m.y();
        if (s.below) {
          ASSERT_GT(y, s.far_y_m - 0.002) << s.what << " at " << speed << " m/s, step " << i;
        } else {
          ASSERT_LT(y, s.far_y_m + 0.002) << s.what << " at " << speed << " m/s, step " << i;
        }
      }
      EXPECT_EQ(world.warnings().instability, 0u) << s.what;
    }
  }
}

TEST(TwinWorld, ABallFromBehindAOneSidedLinePassesThroughIt) {
  const table::Board board = scene("line 100 500 400 500 name=gate\n");  // normal +y: solid from above only
  TwinWorld world(board, testing::shipped_twin_params());
  sim::GameState state = sim::make_game_state(board, 1);
  world.place_ball(state, rolling_at(255, 420, 0.0, 0.8));
  for (int i = 0; i < 400; ++i) world.step(state);
  EXPECT_GT(world.ball().position_m.y(), 0.52) << "passed the gate upwards";
  // Coming back down it meets the line's front and stays above it.
  for (int i = 0; i < 4000; ++i) world.step(state);
  EXPECT_GT(world.ball().position_m.y(), 0.5 + 0.0135 - 0.002);
}

TEST(TwinWorld, EnergyNeverGrowsWithoutAKickerOrAFlipper) {
  // A passive box with posts and a one-sided line; gravity along the table:
  // kinetic plus potential energy of the ball never exceeds its start.
  const table::Board board = scene(
      "wall 20 20 490 20 name=bottom\nwall 490 20 490 1050 name=right\nwall 490 1050 20 1050 name=top\n"
      "wall 20 1050 20 20 name=left\ncircle 150 600 20 rho=0.9 name=p1\ncircle 350 700 20 rho=0.9 name=p2\n"
      "point 250 400\nline 100 300 300 250 name=slope\n");
  TwinWorld world(board, testing::shipped_twin_params());
  sim::GameState state = sim::make_game_state(board, 1);
  world.place_ball(state, rolling_at(255, 200, 2.0, 4.0));
  const double e0 = world.ball_energy_j();
  double e_max = e0;
  for (int i = 0; i < 40000; ++i) {  // 20 s
    world.step(state);
    e_max = std::max(e_max, world.ball_energy_j());
    ASSERT_TRUE(std::isfinite(world.ball_energy_j()));
  }
  EXPECT_LE(e_max, e0 * (1.0 + 1e-3)) << "start " << e0 << " J";
  EXPECT_LT(world.ball_energy_j(), 0.5 * e0) << "it loses energy";
}

TEST(TwinWorld, APopBumperKicksAfterItsDelay) {
  const TwinParams& p = testing::shipped_twin_params();
  const table::Board passive = scene("circle 255 500 20 rho=0.9 name=post\n");
  const table::Board bumper = scene("circle 255 500 20 rho=1.1 kick=800 score=1000 name=bumper\n");
  auto rebound = [&](const table::Board& board, double& score) {
    TwinWorld world(board, p);
    sim::GameState state = sim::make_game_state(board, 1);
    world.place_ball(state, rolling_at(255 - 60, 500, 1.0, 0.0));
    for (int i = 0; i < 100; ++i) world.step(state);  // 50 ms: bounced, kicked, still on the table
    score = state.score;
    return -world.ball().velocity_mps.x();
  };
  double s_passive = 0.0, s_bumper = 0.0;
  const double passive_out = rebound(passive, s_passive);
  const double bumper_out = rebound(bumper, s_bumper);
  EXPECT_GT(bumper_out, passive_out + 0.5 * p.bumper_kick_mps.value);
  EXPECT_EQ(s_bumper, 1000.0) << "scored once per hit";
}

TEST(TwinWorld, AHiddenFlagLetsTheBallThrough) {
  const table::Board board = scene("bank b bonus=100\nwall 100 500 400 500 score=10 bank=b name=flag\n"
                                   "wall 100 700 400 700 score=10 bank=b name=flag2\n");
  TwinWorld world(board, testing::shipped_twin_params());
  sim::GameState state = sim::make_game_state(board, 1);
  world.place_ball(state, rolling_at(255, 420, 0.0, 2.5));
  for (int i = 0; i < 100; ++i) world.step(state);
  EXPECT_EQ(state.score, 10.0) << "the first flag was hit and fell";
  EXPECT_LT(world.ball().velocity_mps.y(), 0.0) << "it bounced back";
  world.place_ball(state, rolling_at(255, 420, 0.0, 2.5));
  for (int i = 0; i < 200; ++i) world.step(state);
  EXPECT_GT(world.ball().position_m.y(), 0.55) << "the fallen flag no longer stops it";
}

TEST(TwinWorld, AHoppingBallReportsItsHeightAndComesBackDown) {
  const table::Board board = scene("");
  TwinWorld world(board, testing::shipped_twin_params());
  sim::GameState state = sim::make_game_state(board, 1);
  TwinBall b = rolling_at(255, 500, 0.0, 0.0);
  b.velocity_mps.z() = 0.5;
  world.place_ball(state, b);
  double top = 0.0;
  for (int i = 0; i < 400; ++i) {
    world.step(state);
    top = std::max(top, state.ball.height_m);
  }
  const double g_normal = testing::shipped_twin_params().gravity_mps2.value * std::cos(world.model_text().slope_rad);
  EXPECT_NEAR(top, 0.25 / (2.0 * g_normal), 0.002);
  EXPECT_LT(state.ball.height_m, 0.002);
}

TEST(TwinWorld, TheSameSeedGivesTheSameGame) {
  const table::Board& board = testing::thesis_board();
  auto play = [&](std::uint64_t seed) {
    TwinWorld prototype(board, testing::shipped_twin_params());
    const std::unique_ptr<sim::World> world = prototype.fork();
    sim::GameState state = sim::make_game_state(board, seed);
    sim::BallLimits limits;
    limits.max_ball_time_s = 20.0;
    double total = 0.0;
    for (int i = 0; i < 2; ++i) {
      const sim::BallResult r = sim::play_ball(*world, state, limits, [&](sim::GameState& st) { oracle_spastic_policy(board, st); }, [](const auto&, const auto&) {});
      total += r.score + r.duration_s;
    }
    return std::pair{total, state.ball.position_m.x()};
  };
  EXPECT_EQ(play(5), play(5));
  EXPECT_NE(play(5).first, play(6).first);
}

TEST(TwinWorld, TheFullTablePlaysWithoutNaNOrWarnings) {
  const table::Board& board = testing::thesis_board();
  TwinWorld prototype(board, testing::shipped_twin_params());
  sim::BallLimits limits;
  limits.max_ball_time_s = 30.0;
  int lost_off_table = 0;
  double highest_m = 0.0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const std::unique_ptr<sim::World> world = prototype.fork();
    sim::GameState state = sim::make_game_state(board, seed);
    const sim::BallResult r = sim::play_ball(*world, state, limits, [&](sim::GameState& st) { oracle_spastic_policy(board, st); },
                                             [&](const sim::GameState& s, const sim::StepEvents&) {
                                               ASSERT_TRUE(s.ball.position_m.allFinite());
                                               ASSERT_TRUE(s.ball.velocity_mps.allFinite());
                                               highest_m = std::max(highest_m, s.ball.height_m);
                                             });
    if (r.left_table) ++lost_off_table;
  }
  EXPECT_EQ(lost_off_table, 0) << "every ball drains; none leaves the table";
  EXPECT_LT(highest_m, testing::shipped_twin_params().glass_height_m.value) << "under the glass";
  std::printf("highest hop %.1f mm\n", highest_m * 1000.0);
  EXPECT_EQ(prototype.warnings().instability, 0u);
  EXPECT_EQ(prototype.warnings().overflow, 0u);
}

TEST(TwinWorld, RefusesABoardItCannotRepresent) {
  table::Board steep = scene("");
  steep.gravity_mps2 = 9.0;  // a 66° playfield
  EXPECT_THROW(TwinWorld(steep, testing::shipped_twin_params()), std::invalid_argument);
  EXPECT_THROW(TwinWorld(scene(""), testing::shipped_twin_params(), 0.0007), std::invalid_argument) << "not a whole number of steps";
}

TEST(TwinRestitution, TheSoftnessFoundGivesTheRestitutionAsked) {
  for (const double e : {0.1, 0.5, 0.8, 0.95}) {
    const TwinSolref c = twin_solref_for_restitution(e, 0.002, 0.0005);
    EXPECT_NEAR(twin_restitution_of(c, 0.0005), e, 0.005) << e;
    EXPECT_GE(c.timeconst_s, 2.0 * 0.0005) << "MuJoCo's least time constant";
  }
  EXPECT_THROW(twin_solref_for_restitution(0.0, 0.002, 0.0005), std::invalid_argument)
      << "a soft contact at this step always returns something";
}


}  // namespace
}  // namespace pinball::simlab
