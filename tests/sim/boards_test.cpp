// The shipped board files: they load, and the reconstructed thesis table
// behaves as its text says (thesis 2.2, 5.1).

#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "pinball/core/running_stats.h"
#include "pinball/sim/model_world.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/table/board_loader.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/sim/penetration.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::sim {
namespace {

const std::string kBoards = PINBALL_SOURCE_DIR "/boards";

TEST(Boards, EveryShippedBoardLoads) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(kBoards)) {
    if (entry.path().extension() != ".board") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(table::load_board(entry.path().string()));
    ++loaded;
  }
  EXPECT_GE(loaded, 5);
}

TEST(Boards, ThesisTableHasARealPlayfield) {
  const table::Board b = table::load_board(kBoards + "/mit1993.board");
  EXPECT_DOUBLE_EQ(b.width_m, 0.51);
  EXPECT_DOUBLE_EQ(b.height_m, 1.07);
  EXPECT_DOUBLE_EQ(b.ball.radius_m, 0.0135);
  EXPECT_NEAR(b.gravity_mps2, 1.11, 1e-12);
  ASSERT_EQ(b.flippers.size(), 2u);
  EXPECT_NEAR(b.flippers[0].length_m, 0.076, 1e-12);
  EXPECT_EQ(b.flippers[0].side, table::Side::kLeft);
  EXPECT_EQ(b.flippers[1].side, table::Side::kRight);
  EXPECT_LT(b.dt_s, table::max_stable_dt_s(b));
  EXPECT_DOUBLE_EQ(b.launcher.pull, 0.95);
  bool has_drain = false;
  bool has_contact_score = false;
  bool has_kicker = false;
  for (const table::Obstacle& o : b.obstacles) {
    has_drain |= o.action.eats_ball;
    has_contact_score |= o.action.contact_score_per_s > 0.0;
    has_kicker |= o.rho > 1.0;
  }
  EXPECT_TRUE(has_drain);
  EXPECT_TRUE(has_contact_score) << "the left passage scores for contact time";
  EXPECT_TRUE(has_kicker) << "slingshots kick";
  EXPECT_FALSE(b.banks.empty());
}

// Thesis 5.1: the 95 % launch sends the ball round to the flippers every time.
// Found by a planner in the identified belief: a ball that came to rest on
// the caret's apex scored 200 points a step for 5 s (1.16 million). At rest
// there it touches the caret and scores nothing.
TEST(Boards, ABallBalancedOnTheCaretScoresNothing) {
  const table::Board b = table::load_board(kBoards + "/mit1993.board");
  const ThesisStepper stepper(b);
  GameState s = make_game_state(b, 1);
  s.ball_in_play = true;
  s.ball.position_m = Vec2(0.2553, 0.980 + b.ball.radius_m + 1e-5);
  s.ball.velocity_mps = Vec2::Zero();
  int touches = 0;
  for (int i = 0; i < 1000; ++i) touches += stepper.step(s).has(StepEvents::kHitObstacle) ? 1 : 0;  // 0.5 s
  EXPECT_GT(touches, 10) << "it rests on the caret";
  EXPECT_EQ(s.score, 0.0);
}

TEST(Boards, TheNinetyFivePercentLaunchReachesTheFlippers) {
  const table::Board b = table::load_board(kBoards + "/mit1993.board");
  const ThesisStepper stepper(b);
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    GameState s = make_game_state(b, seed);
    launch_ball(b, s, 0.95);
    bool touched_flipper = false;
    while (s.ball_in_play && s.time_s < 5.0) {
      stepper.step(s);
      for (const FlipperState& f : s.flippers) touched_flipper |= f.ball_contact;
      ASSERT_LT(max_penetration_m(b, s), 1e-6);
    }
    EXPECT_TRUE(touched_flipper) << "seed " << seed;
  }
}

TEST(Boards, TheSpasticFlipperOutscoresDoingNothing) {
  const table::Board b = table::load_board(kBoards + "/mit1993.board");
  const std::unique_ptr<World> world = make_model_world(b);
  BallLimits limits;
  limits.max_ball_time_s = 120.0;
  auto mean_score = [&](bool spastic) {
    GameState s = make_game_state(b, 5);
    RunningStats score;
    for (int ball = 0; ball < 40; ++ball) {
      const BallResult r = play_ball(
          *world, s, limits, [&](GameState& st) { if (spastic) simlab::oracle_spastic_policy(b, st); },
          [](const GameState&, const StepEvents&) {});
      score.add(r.score);
    }
    return score.mean();
  };
  const double spastic = mean_score(true);
  const double none = mean_score(false);
  std::printf("mean score per ball: spastic %.0f, none %.0f\n", spastic, none);
  EXPECT_GT(spastic, 1.3 * none);
}

// boards/scenes/start.board serves its ball from `start`: the first state in
// play is the start, the ball flies the parabola to the post and drains,
// launched once.
TEST(Boards, TheStartSceneServesTheBallFromItsStart) {
  const table::Board b = table::load_board(kBoards + "/scenes/start.board");
  ASSERT_TRUE(b.start.has_value());
  const std::unique_ptr<World> world = make_model_world(b);
  GameState s = make_game_state(b, 1);
  bool first = true;
  std::int32_t first_hit = -1;
  BallLimits limits;
  limits.max_ball_time_s = 20.0;
  const BallResult r = play_ball(
      *world, s, limits, [](GameState&) {},
      [&](const GameState& st, const StepEvents& ev) {
        if (first) {
          EXPECT_TRUE(ev.has(StepEvents::kLaunch));
          EXPECT_EQ(st.ball.position_m, b.start->position);
          EXPECT_EQ(st.ball.velocity_mps, b.start->velocity_mps);
          first = false;
        }
        if (first_hit < 0 && ev.has(StepEvents::kHitObstacle)) first_hit = ev.obstacle;
      });
  EXPECT_FALSE(r.cut);
  EXPECT_EQ(r.launches, 1);
  ASSERT_GE(first_hit, 0);
  EXPECT_EQ(b.obstacles[first_hit].name, "post");
  EXPECT_GE(r.score, 100.0);  // the post pays 100 a hit
}

// A launch too slow to rise above one ball radius would be relaunched at its
// apex for ever; play_ball refuses it before launching.
TEST(Boards, PlayBallRefusesALaunchTooSlowToLeaveTheLauncher) {
  const table::Board b = table::load_board(kBoards + "/mit1993.board");
  const std::unique_ptr<World> world = make_model_world(b);
  GameState s = make_game_state(b, 1);
  BallLimits limits;
  limits.pull = 0.02;  // at most 0.1 m/s; 0.18 m/s are needed
  EXPECT_THROW(play_ball(*world, s, limits, [](GameState&) {}, [](const GameState&, const StepEvents&) {}),
               std::invalid_argument);
  EXPECT_FALSE(s.ball_in_play);
}

// Issue 17: with g changed by 5–10 % the reconstructed table held the ball in
// a scoring loop without a flip (saucer kickout -> bumpers -> saucer, exact to
// the bit). With the saucer's kickout spread no g in [0.9, 1.1] x the board's
// may keep a ball that nobody flips: every ball drains within the cap.
TEST(Boards, NoFlipperFreeLoopOnTheThesisTableOverGravityPlusMinusTenPercent) {
  const table::Board base = table::load_board(kBoards + "/mit1993.board");
  constexpr double kCap_s = 120.0;  // a drained ball takes ~10 s; a loop runs to the cap
  for (const StepperKind kind : {StepperKind::kThesis, StepperKind::kEvent}) {
    RunningStats ball_time;
    for (int k = -4; k <= 4; ++k) {
      table::Board b = base;
      b.gravity_mps2 = base.gravity_mps2 * (1.0 + 0.025 * k);
      ModelWorldOptions options;
      options.stepper = kind;
      const std::unique_ptr<World> world = make_model_world(b, options);
      const int seeds = kind == StepperKind::kThesis ? 4 : 2;
      for (int seed = 1; seed <= seeds; ++seed) {
        GameState s = make_game_state(b, static_cast<std::uint64_t>(seed));
        BallLimits limits;
        limits.max_ball_time_s = kCap_s;
        for (int ball = 0; ball < b.balls_per_game; ++ball) {
          const BallResult r =
              play_ball(*world, s, limits, [](GameState&) {}, [](const GameState&, const StepEvents&) {});
          EXPECT_FALSE(r.cut) << stepper_kind_name(kind) << " g x " << 1.0 + 0.025 * k << " seed " << seed
                              << " ball " << ball << ": still in play after " << kCap_s << " s, score "
                              << r.score;
          EXPECT_EQ(r.flips, 0);
          ball_time.add(r.duration_s);
        }
      }
    }
    std::printf("no-flip balls on %s over g x [0.9, 1.1]: %lld balls, mean time %.1f s, longest %.1f s\n",
                std::string(stepper_kind_name(kind)).c_str(), static_cast<long long>(ball_time.count()),
                ball_time.mean(), ball_time.max());
  }
}

}  // namespace
}  // namespace pinball::sim
