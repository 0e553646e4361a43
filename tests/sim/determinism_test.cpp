// Same board, seed and settings give the same bits (Box2D's determinism test):
// a 60-second game on the thesis table is hashed step by step.

#include <gtest/gtest.h>

#include "pinball/sim/model_world.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/table/board_loader.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/sim/state_hash.h"
#include "pinball/sim/thesis_stepper.h"
#include "common/thesis_board.h"

namespace pinball::sim {
namespace {

using pinball::testing::thesis_board;

// Plays `seconds` of game with the spastic flipper, relaunching lost balls,
// and folds every step's state into one hash.
std::uint64_t hash_game(World& world, GameState& state, double seconds) {
  const table::Board& board = world.board();
  std::uint64_t h = hash_state(state);
  while (state.time_s < seconds) {
    if (!state.ball_in_play) begin_ball(world, state, board.launcher.pull);
    simlab::oracle_spastic_policy(board, state);
    world.step(state);
    h = hash_combine_state(h, state);
  }
  return h;
}

TEST(Determinism, SixtySecondGameIsBitIdenticalAcrossRuns) {
  const std::unique_ptr<World> world = make_model_world(thesis_board());
  GameState a = make_game_state(thesis_board(), 7);
  GameState b = make_game_state(thesis_board(), 7);
  const std::uint64_t ha = hash_game(*world, a, 60.0);
  const std::uint64_t hb = hash_game(*world, b, 60.0);
  EXPECT_EQ(ha, hb);
  EXPECT_GE(a.steps, 120'000u);
  EXPECT_GT(a.flips, 0u) << "the spastic flipper should have flipped in a minute of play";
  EXPECT_GT(a.score, 0.0);
}

TEST(Determinism, DifferentSeedsDiverge) {
  const std::unique_ptr<World> world = make_model_world(thesis_board());
  GameState a = make_game_state(thesis_board(), 7);
  GameState b = make_game_state(thesis_board(), 8);
  EXPECT_NE(hash_game(*world, a, 10.0), hash_game(*world, b, 10.0));
}

TEST(Determinism, ACopiedStateContinuesIdentically) {
  const std::unique_ptr<World> world = make_model_world(thesis_board());
  GameState a = make_game_state(thesis_board(), 11);
  hash_game(*world, a, 20.0);
  GameState b = a;  // the random stream is part of the state
  EXPECT_EQ(hash_game(*world, a, 40.0), hash_game(*world, b, 40.0));
}

TEST(Determinism, GridAndLinearScanGiveTheSameGame) {
  ModelWorldOptions linear;
  linear.thesis.use_grid = false;
  const std::unique_ptr<World> with_grid = make_model_world(thesis_board());
  const std::unique_ptr<World> without_grid = make_model_world(thesis_board(), linear);
  GameState a = make_game_state(thesis_board(), 3);
  GameState b = make_game_state(thesis_board(), 3);
  EXPECT_EQ(hash_game(*with_grid, a, 30.0), hash_game(*without_grid, b, 30.0));
}

}  // namespace
}  // namespace pinball::sim
