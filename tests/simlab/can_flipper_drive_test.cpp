#include "pinball/simlab/can_flipper_drive.h"

#include <gtest/gtest.h>

#include "pinball/table/board_loader.h"
#include "pinball/sim/thesis_stepper.h"
#include "common/thesis_board.h"

namespace pinball::simlab {
namespace {

using pinball::testing::thesis_board;

// Holds the left button from t = 0.2 s to 0.5 s and records when the flipper
// command (after the CAN path) turns on and off.
struct Edges {
  double on_s = -1.0;
  double off_s = -1.0;
};

Edges press_left(sim::GameState& state, CanFlipperDrive& drive) {
  const sim::ThesisStepper stepper(thesis_board());
  Edges e;
  while (state.time_s < 0.8) {
    const bool pressed = state.time_s >= 0.2 && state.time_s < 0.5;
    state.flippers[0].energized = pressed;
    state.flippers[1].energized = false;
    drive.apply(state);
    if (e.on_s < 0.0 && state.flippers[0].energized) e.on_s = state.time_s;
    if (e.on_s >= 0.0 && e.off_s < 0.0 && !state.flippers[0].energized) e.off_s = state.time_s;
    EXPECT_FALSE(state.flippers[1].energized);
    stepper.step(state);
  }
  return e;
}

TEST(CanFlipperDrive, CommandsReachTheFlipperThroughTheBoardAfterTheDelay) {
  constexpr double kDelay = 0.004;
  CanFlipperDrive drive(thesis_board(), kDelay);
  sim::GameState state = sim::make_game_state(thesis_board(), 1);
  const Edges e = press_left(state, drive);
  EXPECT_TRUE(drive.running());
  ASSERT_GT(e.on_s, 0.0);
  ASSERT_GT(e.off_s, 0.0);
  // The frame is handled within the step it is sent in; the flipper then waits for the solenoid.
  EXPECT_NEAR(e.on_s, 0.2 + kDelay, 2 * thesis_board().dt_s);
  EXPECT_NEAR(e.off_s, 0.5 + kDelay, 2 * thesis_board().dt_s);
  EXPECT_EQ(state.flips, 1u);
  EXPECT_EQ(drive.board_counters().bad_frames, 0u);
  EXPECT_EQ(drive.board_counters().watchdog_trips, 0u) << "the bus heartbeats on the simulated clock";
}

TEST(CanFlipperDrive, RefusesBoardsItCannotDrive) {
  table::Board none = thesis_board();
  none.flippers.clear();
  EXPECT_THROW(CanFlipperDrive(none, 0.004), std::invalid_argument);
  EXPECT_THROW(CanFlipperDrive(thesis_board(), -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::simlab
