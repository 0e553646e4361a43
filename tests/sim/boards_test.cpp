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

}  // namespace
}  // namespace pinball::sim
