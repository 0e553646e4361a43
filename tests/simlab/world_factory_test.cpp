#include "pinball/simlab/world_factory.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/thesis_board.h"
#include "pinball/sim/game_state.h"
#include "pinball/table/board_loader.h"
#include "pinball/table/board_overlay.h"

namespace pinball::simlab {
namespace {

using pinball::testing::thesis_board;

// A board file written for the test: the thesis table with one line replaced.
std::string variant_board(const std::string& name, const std::string& from, const std::string& to) {
  std::ifstream in(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(WorldFactory, TheWorldDefaultsToTheBelief) {
  const OwnedWorld w = make_world(WorldSpec{}, thesis_board());
  EXPECT_EQ(w.board->source, thesis_board().source);
  EXPECT_EQ(w.board->gravity_mps2, thesis_board().gravity_mps2);
  EXPECT_EQ(&w->board(), w.board.get());
  EXPECT_EQ(w->name(), "thesis");
  EXPECT_EQ(w->dt_s(), thesis_board().dt_s);
}

TEST(WorldFactory, TheWorldMayBeAnotherBoardOnAnotherStepper) {
  const std::string path = variant_board("world_factory_g.board", "gravity 1110", "gravity 1000");
  WorldSpec spec;
  spec.board_path = path;
  spec.stepper = sim::StepperKind::kEvent;
  spec.dt_s = 0.001;
  const OwnedWorld w = make_world(spec, thesis_board());
  EXPECT_DOUBLE_EQ(w.board->gravity_mps2, 1.0);
  EXPECT_DOUBLE_EQ(thesis_board().gravity_mps2, 1.11);  // the belief is untouched
  EXPECT_EQ(w->name(), "event");
  EXPECT_EQ(w->dt_s(), 0.001);
  std::remove(path.c_str());
}

TEST(WorldFactory, TheTwinIsAWorldOfItsOwnWithTheShippedParameters) {
  WorldSpec spec;
  spec.kind = WorldKind::kTwin;
  if (!twin_available()) {
    EXPECT_THROW(make_world(spec, thesis_board()), std::invalid_argument) << "says it is not built";
    GTEST_SKIP() << "this build has no MuJoCo twin";
  }
  const OwnedWorld w = make_world(spec, thesis_board());
  EXPECT_EQ(w->name(), "twin");
  EXPECT_EQ(world_name(spec), "twin");
  EXPECT_EQ(w->dt_s(), 0.0005);
  sim::GameState state = sim::make_game_state(*w.board, 3);
  w->launch(state, 0.95);
  for (int i = 0; i < 400; ++i) w->step(state);
  EXPECT_TRUE(state.ball_in_play);
  EXPECT_GT(state.ball.position_m.y(), 0.3) << "the launch sent it up the chute";
  EXPECT_EQ(w->warnings().total(), 0u);
}

TEST(WorldFactory, WorldKindsAreSpelledModelAndTwin) {
  EXPECT_EQ(parse_world_kind("twin"), WorldKind::kTwin);
  EXPECT_EQ(parse_world_kind("model"), WorldKind::kModel);
  EXPECT_EQ(world_kind_name(WorldKind::kTwin), "twin");
  EXPECT_THROW(parse_world_kind("mujoco"), std::invalid_argument);
}

TEST(WorldFactory, AWorldWithOtherFlippersIsRefused) {
  const std::string path = variant_board("world_factory_flip.board", "flipper left", "flipper right");
  WorldSpec spec;
  spec.board_path = path;
  EXPECT_THROW(make_world(spec, thesis_board()), std::invalid_argument);
  spec.board_path = "/nonexistent/world.board";
  EXPECT_THROW(make_world(spec, thesis_board()), table::BoardError);
  std::remove(path.c_str());
}

// The rule for worlds (docs/identification.md): the overlay is the belief's
// alone; a model world defaulting to the belief plays it, the twin never does.
TEST(WorldFactory, TheTwinPlaysTheBoardFileNotTheIdentifiedBelief) {
  const std::string board = PINBALL_SOURCE_DIR "/boards/mit1993.board";
  table::BoardOverlay o;
  table::ObstacleGroupOverlay bumpers;
  bumpers.board_rho = 1.1;
  bumpers.board_kick_mps = 0.8;
  bumpers.obstacles = {"bumper_left", "bumper_right", "bumper_low"};
  bumpers.rho = {0.9, 0.05, 30};
  o.obstacle_groups = {bumpers};
  const std::string overlay = (std::filesystem::temp_directory_path() / "world_factory_overlay.yaml").string();
  table::write_board_overlay(o, overlay);
  const table::Board belief = table::load_belief_board(board, overlay);
  const auto rho_of = [](const table::Board& b, const std::string& name) {
    for (const table::Obstacle& x : b.obstacles) {
      if (x.name == name) return x.rho;
    }
    return -1.0;
  };
  ASSERT_EQ(rho_of(belief, "bumper_left"), 0.9);

  WorldSpec twin;
  twin.kind = WorldKind::kTwin;
  EXPECT_EQ(world_for_belief(twin, board, overlay).board_path, board) << "the twin gets the file";
  EXPECT_EQ(world_for_belief(twin, board, "").board_path, "") << "no overlay: the belief is the file";
  EXPECT_EQ(world_for_belief(WorldSpec{}, board, overlay).board_path, "") << "a model world plays the belief";
  WorldSpec own = twin;
  own.board_path = "world.board";
  EXPECT_EQ(world_for_belief(own, board, overlay).board_path, "world.board") << "a world board is kept";

  const OwnedWorld model = make_world(world_for_belief(WorldSpec{}, board, overlay), belief);
  EXPECT_EQ(rho_of(*model.board, "bumper_left"), 0.9) << "the model world plays the identified belief";
  if (!twin_available()) {
    std::remove(overlay.c_str());
    GTEST_SKIP() << "this build has no MuJoCo twin: the rule is tested on world_for_belief alone";
  }
  const OwnedWorld t = make_world(world_for_belief(twin, board, overlay), belief);
  EXPECT_EQ(&t->board(), t.board.get());
  EXPECT_EQ(rho_of(*t.board, "bumper_left"), 1.1) << "the twin is built from the file's rho";
  std::remove(overlay.c_str());
}

}  // namespace
}  // namespace pinball::simlab
