#include "pinball/learn/identification.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/thesis_board.h"
#include "pinball/core/rng.h"
#include "pinball/sim/collision.h"
#include "model_recording.h"

namespace pinball::learn {
namespace {

// The thesis table as it "really" is in these tests: a flatter slope, deader
// walls with friction, 3 mm thick guides, weaker bumpers, a weaker launch.
table::Board recorded_table() {
  table::Board world = pinball::testing::thesis_board();
  world.gravity_mps2 = 0.95;
  for (table::Obstacle& o : world.obstacles) {
    if (o.rho == 0.6 && o.action.kick_mps == 0.0) o.rho = 0.5, o.friction = 0.12;
    if (o.action.kick_mps == 0.8) o.action.kick_mps = 0.6;
  }
  world.launcher.pull = 0.9;
  world.launcher.noise_max = 0.05;
  table::set_wall_thickness(world, 0.003);
  return world;
}

const std::vector<bus::RecordedPlay>& recordings() {
  static const std::vector<bus::RecordedPlay> plays = [] {
    static const table::Board world = recorded_table();
    return std::vector<bus::RecordedPlay>{pinball::testing::record_model_play(world, 60, 0.0005, 21)};
  }();
  return plays;
}

const GroupResult* group_with(const IdentificationResult& r, double board_rho, double board_kick) {
  for (const GroupResult& g : r.groups)
    if (g.overlay.board_rho == board_rho && g.overlay.board_kick_mps == board_kick) return &g;
  return nullptr;
}

TEST(Identification, MaterialGroupsAreTheBoardsDistinctRhoAndKick) {
  const std::vector<table::ObstacleGroupOverlay> groups = material_groups(pinball::testing::thesis_board());
  const auto has = [&](double rho, double kick, const std::string& name) {
    return std::any_of(groups.begin(), groups.end(), [&](const auto& g) {
      return g.board_rho == rho && g.board_kick_mps == kick &&
             std::find(g.obstacles.begin(), g.obstacles.end(), name) != g.obstacles.end();
    });
  };
  EXPECT_TRUE(has(0.6, 0.0, "left_wall_low"));
  EXPECT_TRUE(has(0.6, 0.0, "top_right_arc"));
  EXPECT_TRUE(has(1.1, 0.8, "bumper_low"));
  EXPECT_TRUE(has(1.4, 0.6, "left_sling"));
  EXPECT_TRUE(has(0.9, 0.0, "post_right"));
  for (const auto& g : groups) {
    EXPECT_EQ(std::count(g.obstacles.begin(), g.obstacles.end(), "top_right_arc"), g.board_rho == 0.6 ? 1 : 0);
    EXPECT_EQ(std::count(g.obstacles.begin(), g.obstacles.end(), "drain"), 0);  // eats the ball
  }
}

TEST(Identification, RecoversTheRecordedTablesGravityRhoKickAndLaunch) {
  IdentifyOptions options;
  options.flights.sigma_m = 0.0005;
  options.bootstrap = 20;
  const IdentificationResult r = identify_table(pinball::testing::thesis_board(), recordings(), options);
  ASSERT_TRUE(r.overlay.gravity_mps2.has_value());
  const table::IdentifiedValue& g = *r.overlay.gravity_mps2;
  EXPECT_NEAR(g.value, 0.95, std::max(4.0 * g.stderr_, 0.01));
  EXPECT_GT(g.stderr_, 0.0);
  EXPECT_GT(g.events, 50);
  EXPECT_LT(r.gravity_no_drag.rms_fitted_m, r.gravity_no_drag.rms_nominal_m);
  EXPECT_NEAR(r.gravity.drag_per_s, 0.0, std::max(4.0 * r.gravity.drag_stderr_per_s, 0.02));  // the model has none

  const GroupResult* walls = group_with(r, 0.6, 0.0);
  ASSERT_NE(walls, nullptr);
  ASSERT_TRUE(walls->identified) << walls->why_not;
  EXPECT_NEAR(walls->overlay.rho.value, 0.5, std::max(4.0 * walls->overlay.rho.stderr_, 0.03));
  EXPECT_LT(walls->rms_fitted_mps, walls->rms_nominal_mps);
  EXPECT_FALSE(walls->overlay.kick_mps.has_value());
  ASSERT_TRUE(walls->overlay.friction.has_value());
  EXPECT_NEAR(walls->overlay.friction->value, 0.12, std::max(4.0 * walls->overlay.friction->stderr_, 0.03));
  EXPECT_GT(walls->overlay.friction->stderr_, 0.0);
  EXPECT_LT(walls->friction.rms_fitted_mps, walls->friction.rms_frictionless_mps);

  const GroupResult* bumpers = group_with(r, 1.1, 0.8);
  ASSERT_NE(bumpers, nullptr);
  if (bumpers->identified) {
    ASSERT_TRUE(bumpers->overlay.kick_mps.has_value());
    EXPECT_NEAR(bumpers->overlay.kick_mps->value, 0.6, std::max(4.0 * bumpers->overlay.kick_mps->stderr_, 0.1));
  }

  // The guides' thickness, from the model's own predictions of the moments.
  ASSERT_TRUE(r.wall_thickness.identified) << r.wall_thickness.why_not;
  ASSERT_TRUE(r.overlay.wall_thickness_m.has_value());
  EXPECT_NEAR(r.overlay.wall_thickness_m->value, 0.003, std::max(4.0 * r.overlay.wall_thickness_m->stderr_, 0.0005));
  EXPECT_LT(r.wall_thickness.error_fitted_m, r.wall_thickness.error_at_zero_m);
  EXPECT_EQ(r.wall_thickness.scan.size(), 9u);

  ASSERT_TRUE(r.overlay.launcher.has_value());
  EXPECT_EQ(r.overlay.launcher->pull.events, 60);
  EXPECT_NEAR(r.overlay.launcher->pull.value, 0.9, 0.02);
  EXPECT_NEAR(r.overlay.launcher->noise_max.value, 0.05, 0.02);
  EXPECT_EQ(r.overlay.recordings, std::vector<std::string>{"model"});
  EXPECT_EQ(r.overlay.board, pinball::testing::thesis_board().source);
}

// Rebounds whose tangential speed out is exactly the model's, plus noise.
std::vector<Rebound> rebounds_with_friction(double rho, double kick_mps, double friction, double noise_mps, int count) {
  Rng rng(5);
  std::vector<Rebound> out;
  for (int i = 0; i < count; ++i) {
    Rebound r;
    r.speed_in_mps = rng.uniform(0.2, 2.0);
    r.tangent_in_mps = rng.uniform(0.0, 3.0);
    r.speed_out_mps = rho * r.speed_in_mps + kick_mps;
    const double loss = sim::wall_friction_loss_mps(r.tangent_in_mps, r.speed_in_mps,
                                                    (1.0 + rho) * r.speed_in_mps + kick_mps, friction);
    r.tangent_out_mps = r.tangent_in_mps - loss + noise_mps * rng.normal();
    out.push_back(r);
  }
  return out;
}

// A slingshot (ρ 1.4, kick 0.6 m/s) as the thesis model plays it: the
// response, then the ball's speed clamped to the board's (thesis 3.3).
TEST(MaterialGroupFit, ReboundsThatLeftAtTheSpeedClampAreLeftOut) {
  const table::Board board = pinball::testing::thesis_board();
  table::Obstacle sling;
  sling.rho = 1.4;
  sling.action.kick_mps = 0.6;
  const double clamp_mps = board.ball.speed_max_mps;
  Rng rng(11);
  std::vector<Rebound> rebounds;
  int clamped = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec2 n(0.0, 1.0);
    const Vec2 v_in(rng.uniform(-2.0, 2.0), -rng.uniform(0.3, 4.0));
    Vec2 v_out = sim::obstacle_response(sling, n, v_in);
    if (v_out.norm() > clamp_mps) v_out *= clamp_mps / v_out.norm(), ++clamped;
    Rebound r;
    r.speed_in_mps = -v_in.y();
    r.speed_out_mps = v_out.y() + 0.01 * rng.normal();
    r.tangent_in_mps = std::abs(v_in.x());
    r.tangent_out_mps = v_in.x() >= 0.0 ? v_out.x() : -v_out.x();
    rebounds.push_back(r);
  }
  ASSERT_GT(clamped, 30) << "the test needs balls thrown out at the clamp";
  GroupResult group;
  group.overlay.board_rho = 1.4;
  group.overlay.board_kick_mps = 0.6;
  fit_material_group(rebounds, IdentifyOptions{}, clamp_mps, group);
  ASSERT_TRUE(group.identified) << group.why_not;
  EXPECT_EQ(group.rebounds, 300);
  EXPECT_GE(group.at_speed_clamp, clamped);  // those at it, and those the noise put a hair under it
  EXPECT_LE(group.at_speed_clamp, clamped + 10);
  EXPECT_NEAR(group.overlay.rho.value, 1.4, 0.01);
  ASSERT_TRUE(group.overlay.kick_mps.has_value());
  EXPECT_NEAR(group.overlay.kick_mps->value, 0.6, 0.02);
  EXPECT_LT(group.rms_fitted_mps, 0.02);

  // Kept, they pull ρ down: the bias the rule removes.
  IdentifyOptions no_rule;
  no_rule.clamp_share = 1e9;
  GroupResult biased;
  biased.overlay = group.overlay;
  fit_material_group(rebounds, no_rule, clamp_mps, biased);
  EXPECT_EQ(biased.at_speed_clamp, 0);
  EXPECT_LT(biased.overlay.rho.value, 1.35);

  // Too few below the clamp: not identified, and the reason says so.
  GroupResult few;
  few.overlay = group.overlay;
  fit_material_group(std::span<const Rebound>(rebounds.data(), 8), IdentifyOptions{}, 0.1, few);
  EXPECT_FALSE(few.identified);
  EXPECT_EQ(few.why_not, "0 clean rebounds (both flights seen, one obstacle near, below the speed clamp), needs 10");

  // Rebounds no material gives (out at 2.5 times in, a kick taken away): not identified, and no
  // overlay a command would refuse to read.
  std::vector<Rebound> wild = rebounds;
  for (Rebound& r : wild) r.speed_out_mps = 2.5 * r.speed_in_mps - 0.4;
  GroupResult out_of_range;
  out_of_range.overlay = group.overlay;
  fit_material_group(wild, IdentifyOptions{}, 1e9, out_of_range);
  EXPECT_FALSE(out_of_range.identified);
  EXPECT_EQ(out_of_range.why_not,
            "the clean rebounds fit rho 2.5 and kick -0.4 m/s, outside the overlay's range (rho in [0, 2], kick in "
            "[0, 10] m/s): they are not one material's; the board's value is kept");
}

TEST(WallFrictionFit, RecoversTheFrictionExactlyWithoutNoiseAndWithinItsUncertaintyWithNoise) {
  for (double friction : {0.0, 0.05, 0.12, 0.4}) {
    SCOPED_TRACE(friction);
    const WallFrictionFit exact = fit_wall_friction(rebounds_with_friction(0.5, 0.0, friction, 0.0, 50), 0.5, 0.0);
    EXPECT_NEAR(exact.friction, friction, 1e-6);
    EXPECT_NEAR(exact.rms_fitted_mps, 0.0, 1e-6);
    const WallFrictionFit noisy = fit_wall_friction(rebounds_with_friction(0.8, 0.9, friction, 0.05, 400), 0.8, 0.9);
    EXPECT_NEAR(noisy.friction, friction, 4.0 * noisy.stderr_ + 1e-3);
    EXPECT_GT(noisy.stderr_, 0.0);
    EXPECT_LT(noisy.stderr_, 0.02);
    EXPECT_GE(noisy.friction, 0.0);  // never a friction that adds speed
    EXPECT_NEAR(noisy.rms_fitted_mps, 0.05, 0.01);
  }
}

TEST(WallFrictionFit, TrimsOutliersAndNeedsTwoRebounds) {
  std::vector<Rebound> rebounds = rebounds_with_friction(0.5, 0.0, 0.1, 0.01, 100);
  for (int i = 0; i < 5; ++i) rebounds[static_cast<std::size_t>(i * 7)].tangent_out_mps = -3.0;  // joined wrongly
  const WallFrictionFit fit = fit_wall_friction(rebounds, 0.5, 0.0);
  // The five and perhaps a few the first, pulled fit put beyond the trim.
  EXPECT_GE(fit.outliers, 5);
  EXPECT_LE(fit.outliers, 8);
  EXPECT_EQ(fit.used + fit.outliers, 100);
  EXPECT_NEAR(fit.friction, 0.1, 0.01);
  EXPECT_THROW(fit_wall_friction(std::span<const Rebound>(rebounds.data(), 1), 0.5, 0.0), std::invalid_argument);
}

// One ball at a circular obstacle: it arrives at the contact (normal n)
// with v_in, lies there dwell_s, then leaves from reach_m further out along
// n with v_out.
struct CircleBounce {
  Vec2 n;
  Vec2 v_in;
  Vec2 v_out;
  double t_contact_s = 0.0;
  double dwell_s = 0.0;
  double reach_m = 0.0;
};

// The bounces off the obstacle named, seen at 200 fps (frames every 5 ms
// from t = 0, so a contact may fall between two) for 60 ms in and 60 ms out.
bus::RecordedPlay circle_bounce_play(const table::Board& board, const std::string& obstacle,
                                     const std::vector<CircleBounce>& bounces) {
  std::size_t index = 0;
  while (board.obstacles[index].name != obstacle) ++index;
  const table::Shape& circle = board.shapes[index];
  const Vec2 g_vec(0.0, -board.gravity_mps2);
  bus::RecordedPlay play;
  play.source = obstacle;
  std::int64_t seq = 0;
  for (const CircleBounce& b : bounces) {
    const Vec2 contact = circle.p0 + (circle.radius_m + board.ball.radius_m) * b.n;
    const double t_out = b.t_contact_s + b.dwell_s;
    for (auto frame = static_cast<std::int64_t>(std::ceil((b.t_contact_s - 0.06) / 0.005));
         frame * 0.005 <= t_out + 0.06 + 1e-9; ++frame) {
      const double t = static_cast<double>(frame) * 0.005;
      const double in = t - b.t_contact_s, out = t - t_out;
      const Vec2 p = in < 0.0    ? contact + b.v_in * in + 0.5 * in * in * g_vec
                     : out < 0.0 ? contact
                                 : contact + b.reach_m * b.n + b.v_out * out + 0.5 * out * out * g_vec;
      play.frames.push_back({t, seq++, true, p, false, false});
    }
  }
  return play;
}

// A pop bumper that holds the ball dwell_s, then throws it from its ring's
// reach at ρ·(normal speed in) + kick: balls from below, 14 of them, at 0.3
// to 1.2 m/s.
bus::RecordedPlay kicker_play(const table::Board& board, double rho, double kick_mps, double dwell_s,
                              double reach_m) {
  std::vector<CircleBounce> bounces;
  for (int k = 0; k < 14; ++k) {
    const double angle = -1.2 + 0.05 * k;  // below the bumper, pointing down and sideways
    const Vec2 n(std::sin(angle), -std::cos(angle));
    const Vec2 tangent(-n.y(), n.x());
    const double speed_in = 0.3 + 0.07 * k;
    bounces.push_back({n, -speed_in * n + 0.1 * tangent, (rho * speed_in + kick_mps) * n + 0.1 * tangent,
                       2.0 * k + 1.0, dwell_s, reach_m});
  }
  return circle_bounce_play(board, "bumper_low", bounces);
}

// What the tests of drawn plays identify with: their noise, no bootstrap.
IdentifyOptions drawn_play_options() {
  IdentifyOptions options;
  options.flights.sigma_m = 0.0005;
  options.bootstrap = 0;
  return options;
}

TEST(Identification, AKickerThatHoldsTheBallAndThrowsItFromItsReachIsIdentified) {
  const table::Board& board = pinball::testing::thesis_board();
  const std::vector<bus::RecordedPlay> plays{kicker_play(board, 0.6, 1.0, 0.008, 0.010)};
  IdentifyOptions options = drawn_play_options();
  const IdentificationResult r = identify_table(board, plays, options);
  const GroupResult* bumpers = group_with(r, 1.1, 0.8);
  ASSERT_NE(bumpers, nullptr);
  ASSERT_TRUE(bumpers->identified) << bumpers->why_not;
  EXPECT_EQ(bumpers->rebounds, 14);
  ASSERT_TRUE(bumpers->overlay.kick_mps.has_value());
  EXPECT_NEAR(bumpers->overlay.rho.value, 0.6, 0.03);
  EXPECT_NEAR(bumpers->overlay.kick_mps->value, 1.0, 0.03);

  // A ball held 20 ms and thrown from 10 mm: its flight out, taken back to
  // the contact, passes 14 mm and more from where it arrived. The kicker's
  // dwell and reach join it; joined at the contact as a wall is, no rebound.
  const std::vector<bus::RecordedPlay> held{kicker_play(board, 0.6, 1.0, 0.020, 0.010)};
  EXPECT_EQ(group_with(identify_table(board, held, options), 1.1, 0.8)->rebounds, 14);
  options.kick_dwell_s = 0.0;
  options.kick_join_tolerance_m = options.join_tolerance_m;
  EXPECT_EQ(group_with(identify_table(board, held, options), 1.1, 0.8)->rebounds, 0);
}

// Balls bouncing off a post at ρ 0.6, coming in at glancing angles, each
// touching it 1.3 ms after a frame.
bus::RecordedPlay post_play(const table::Board& board, double rho) {
  std::vector<CircleBounce> bounces;
  for (int k = 0; k < 12; ++k) {
    const double angle = -1.4 + 0.08 * k;  // below the post, in the open towards the triangle
    const Vec2 n(std::cos(angle), std::sin(angle));
    const Vec2 tangent(-n.y(), n.x());
    const double speed_in = 0.4 + 0.05 * k;
    const Vec2 v_in = -speed_in * n + (k % 2 == 0 ? 1.0 : -1.0) * tangent;  // glancing: fast along the post
    bounces.push_back({n, v_in, v_in + (1.0 + rho) * speed_in * n, 2.0 * k + 1.0013});
  }
  return circle_bounce_play(board, "post_left", bounces);
}

// The contact is where the extrapolated ball touches the post, not the
// first step within reach of it: there the normal, which turns with the
// contact point on a circle, would mix the fast speed along the post into
// the speed at it.
TEST(Identification, AGlancingBounceOffAPostIsMeasuredAtItsContact) {
  const table::Board& board = pinball::testing::thesis_board();
  const std::vector<bus::RecordedPlay> plays{post_play(board, 0.6)};
  const IdentificationResult r = identify_table(board, plays, drawn_play_options());
  const GroupResult* posts = group_with(r, 0.9, 0.0);
  ASSERT_NE(posts, nullptr);
  ASSERT_TRUE(posts->identified) << posts->why_not;
  EXPECT_GE(posts->rebounds, 8);  // of 12: the others' flights pass too near something else to be free
  EXPECT_NEAR(posts->overlay.rho.value, 0.6, 0.01);
  EXPECT_LT(posts->rms_fitted_mps, 0.01);
}

TEST(Identification, SaysWhichParametersItCouldNotIdentifyAndWhy) {
  const table::Board world = recorded_table();
  const std::vector<bus::RecordedPlay> short_play{pinball::testing::record_model_play(world, 2, 0.0005, 5)};
  IdentifyOptions options;
  options.bootstrap = 0;
  const IdentificationResult r = identify_table(pinball::testing::thesis_board(), short_play, options);
  EXPECT_FALSE(r.overlay.launcher.has_value());
  const auto said = [&](const std::string& parameter) {
    return std::any_of(r.not_identified.begin(), r.not_identified.end(), [&](const NotIdentified& n) {
      return n.parameter.find(parameter) != std::string::npos && !n.why.empty();
    });
  };
  EXPECT_TRUE(said("launcher pull and noise"));
  EXPECT_TRUE(said("camera latency"));
  EXPECT_TRUE(said("flipper left_flipper rise delay, stroke speed and mu"));
  EXPECT_TRUE(said("obstacle group rho=1.4 kick=0.6 m/s"));
  for (const GroupResult& g : r.groups) EXPECT_EQ(g.identified, g.why_not.empty());
}

TEST(Identification, RefusesRecordingsWithoutFreeFlights) {
  bus::RecordedPlay resting;
  resting.source = "resting.lcm";
  for (int i = 0; i < 200; ++i) resting.frames.push_back({0.005 * i, i, true, Vec2(0.25, 0.4), false, false});
  const std::vector<bus::RecordedPlay> plays{resting};
  EXPECT_THROW(identify_table(pinball::testing::thesis_board(), plays), std::runtime_error);
}

// A log that cannot be of the board was fitted all the same (sightings 1 km
// off gave g and a wall thickness, exit 0): refused, naming the log.
TEST(RecordingFitsBoard, SightingsOffTheBoardForeignFlippersAndAnotherClockAreRefused) {
  const table::Board& board = pinball::testing::thesis_board();
  bus::RecordedPlay play;
  play.source = "game.lcm";
  for (int k = 0; k < 100; ++k) play.frames.push_back({k * 0.2, k, true, Vec2{0.2, 0.5}, false, false});  // 20 s
  play.commands.push_back({0.1, 0, true, 0});
  EXPECT_NO_THROW(check_recording_fits_board(play, board));
  const auto error_of = [&](const bus::RecordedPlay& p) -> std::string {
    try {
      check_recording_fits_board(p, board);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  bus::RecordedPlay far = play;
  for (int k = 0; k < 6; ++k) far.frames[static_cast<std::size_t>(k)].p_board.x() = 1000.0;
  EXPECT_EQ(
      error_of(far).rfind("game.lcm: 6 of its 100 sightings lie over 5 cm off the 0.51 x 1.07 m playfield of ", 0),
      0u)
      << error_of(far);
  far.frames[5].p_board.x() = 0.2;  // 5 %: a few stray detections are no other table
  EXPECT_EQ(error_of(far), "");
  bus::RecordedPlay foreign = play;
  foreign.commands.push_back({0.2, 2, true, 0});
  EXPECT_NE(error_of(foreign).find("game.lcm: its commands fire flipper 2, and "), std::string::npos);
  bus::RecordedPlay late = play;
  late.commands[0].t_s = 3600.0;
  EXPECT_NE(error_of(late).find("the two were recorded on different clocks"), std::string::npos) << error_of(late);
  late.frames.resize(20);  // 4 s: a short log may hold no command of its own
  EXPECT_EQ(error_of(late), "");
}

}  // namespace
}  // namespace pinball::learn
