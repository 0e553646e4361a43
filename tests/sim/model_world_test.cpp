#include "pinball/sim/model_world.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "common/thesis_board.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/state_hash.h"
#include "pinball/simlab/oracle_policy.h"

namespace pinball::sim {
namespace {

using pinball::testing::thesis_board;

// Ten seconds of the spastic flipper, relaunching lost balls, folded into one hash.
template <class Step>
std::uint64_t play_hash(const table::Board& board, std::uint64_t seed, Step&& step) {
  GameState s = make_game_state(board, seed);
  std::uint64_t h = hash_state(s);
  while (s.time_s < 10.0) {
    if (!s.ball_in_play) {
      if (s.balls_left <= 0) reset_game(board, s);
      launch_ball(board, s, board.launcher.pull);
    }
    simlab::oracle_spastic_policy(board, s);
    step(s);
    h = hash_combine_state(h, s);
  }
  return h;
}

TEST(ModelWorld, PlaysTheSameBitsAsItsStepper) {
  const table::Board& b = thesis_board();
  const ThesisStepper thesis(b);
  const std::unique_ptr<World> thesis_world = make_model_world(b);
  EXPECT_EQ(play_hash(b, 5, [&](GameState& s) { thesis.step(s); }),
            play_hash(b, 5, [&](GameState& s) { thesis_world->step(s); }));
  const EventStepper event(b);
  ModelWorldOptions o;
  o.stepper = StepperKind::kEvent;
  const std::unique_ptr<World> event_world = make_model_world(b, o);
  EXPECT_EQ(play_hash(b, 5, [&](GameState& s) { event.step(s); }),
            play_hash(b, 5, [&](GameState& s) { event_world->step(s); }));
  EXPECT_EQ(thesis_world->name(), "thesis");
  EXPECT_EQ(event_world->name(), "event");
}

TEST(ModelWorld, AForkIsTheSameWorldWithoutHistory) {
  ModelWorldOptions o;
  o.dt_s = 0.00025;
  const std::unique_ptr<World> world = make_model_world(thesis_board(), o);
  const std::unique_ptr<World> fork = world->fork();
  EXPECT_EQ(&fork->board(), &world->board());
  EXPECT_EQ(fork->dt_s(), 0.00025);
  EXPECT_EQ(fork->name(), world->name());
  EXPECT_EQ(play_hash(thesis_board(), 9, [&](GameState& s) { world->step(s); }),
            play_hash(thesis_board(), 9, [&](GameState& s) { fork->step(s); }));
}

TEST(ModelWorld, LaunchIsTheThesisLaunch) {
  const table::Board& b = thesis_board();
  const std::unique_ptr<World> world = make_model_world(b);
  GameState a = make_game_state(b, 3);
  GameState c = make_game_state(b, 3);
  world->launch(a, 0.7);
  launch_ball(b, c, 0.7);
  EXPECT_EQ(hash_state(a), hash_state(c));
  EXPECT_TRUE(a.ball_in_play);
}

TEST(ModelWorld, BadTimeStepsAreRefused) {
  ModelWorldOptions o;
  o.dt_s = 0.05;  // the flippers would jump over the ball
  EXPECT_THROW(make_model_world(thesis_board(), o), std::invalid_argument);
  o.stepper = StepperKind::kEvent;
  o.dt_s = -1.0;
  EXPECT_THROW(make_model_world(thesis_board(), o), std::invalid_argument);
}

TEST(World, StepperNamesParseBothWays) {
  EXPECT_EQ(parse_stepper_kind("thesis"), StepperKind::kThesis);
  EXPECT_EQ(parse_stepper_kind("event"), StepperKind::kEvent);
  EXPECT_EQ(stepper_kind_name(StepperKind::kEvent), "event");
  EXPECT_THROW(parse_stepper_kind("euler"), std::invalid_argument);
}

TEST(World, WorldAndBeliefMustWireTheSameFlippers) {
  table::Board world = thesis_board();
  world.gravity_mps2 *= 0.97;  // a different table with the same flippers is fine
  EXPECT_NO_THROW(check_same_flippers(world, thesis_board()));
  table::Board swapped = thesis_board();
  std::swap(swapped.flippers[0], swapped.flippers[1]);
  EXPECT_THROW(check_same_flippers(swapped, thesis_board()), std::invalid_argument);
  table::Board one = thesis_board();
  one.flippers.pop_back();
  EXPECT_THROW(check_same_flippers(one, thesis_board()), std::invalid_argument);
}

TEST(BallRunner, PlaysABallInAnyWorld) {
  const table::Board& b = thesis_board();
  for (StepperKind kind : {StepperKind::kThesis, StepperKind::kEvent}) {
    ModelWorldOptions o;
    o.stepper = kind;
    const std::unique_ptr<World> world = make_model_world(b, o);
    GameState s = make_game_state(b, 4);
    BallLimits limits;
    limits.max_ball_time_s = 30.0;
    const BallResult r = play_ball(*world, s, limits, [](GameState&) {}, [](const GameState&, const StepEvents&) {});
    EXPECT_GT(r.steps, 100u) << stepper_kind_name(kind);
    EXPECT_FALSE(s.ball_in_play) << stepper_kind_name(kind);
  }
}

}  // namespace
}  // namespace pinball::sim
