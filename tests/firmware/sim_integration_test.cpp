// The whole path on the simulator: DriverBus::fire -> StreamTransport
// (socketpair) -> VirtualDriverBoard -> coil output -> actuation delay ->
// GameState::flippers[0].energized -> ThesisStepper raises the flipper.

#include <gtest/gtest.h>

#include "board_harness.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/table/board_loader.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::firmware {
namespace {

using SimIntegrationTest = testing::BoardTest;

TEST_F(SimIntegrationTest, FireRaisesTheSimulatedFlipperAfterTheActuationDelay) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/scenes/flipper.board");
  ASSERT_EQ(board.flippers.size(), 1u);
  const sim::ThesisStepper stepper(board);
  sim::GameState state = sim::make_game_state(board, 1);
  const double dt = stepper.dt_s();

  DriverBusOptions o;
  o.driver_count = 1;
  monitor_.set_caps(0, testing::caps_of(o.drivers[0]));
  DriverBus bus(*host_, o);
  constexpr double kDelay = 0.004;  // solenoid rise
  FlipperActuation actuation(0, kDelay);
  board_.add_listener(&actuation);

  // One lockstep loop on the simulator's clock: bus, board, actuation, physics.
  double fire_at = -1.0;
  double coil_on_at = -1.0;
  double raised_at = -1.0;
  const double theta_min = board.flippers[0].theta_min_rad;
  const double theta_max = board.flippers[0].theta_max_rad;
  for (int k = 0; k < 1000; ++k) {
    t_ = state.time_s;
    if (fire_at < 0.0 && bus.state() == BusState::kRunning && t_ >= 0.1) {
      ASSERT_TRUE(bus.fire(0));
      fire_at = t_;
    }
    bus.poll_once(t_);
    board_.service(*link_, t_);
    if (coil_on_at < 0.0 && board_.coil(0).state != CoilState::kOff) coil_on_at = board_.coil(0).since_s;
    state.flippers[0].energized = actuation.energized(t_);
    if (fire_at >= 0.0 && state.time_s < coil_on_at + kDelay - 1e-9) {
      ASSERT_NEAR(state.flippers[0].theta_rad, theta_min, 1e-12) << "moved before the actuation delay";
    }
    stepper.step(state);
    board_.set_end_of_stroke(0, state.flippers[0].theta_rad >= theta_max);
    if (raised_at < 0.0 && state.flippers[0].theta_rad >= theta_max) raised_at = state.time_s;
  }
  ASSERT_GE(fire_at, 0.0) << "the bus never reached kRunning";
  ASSERT_GE(coil_on_at, fire_at);
  EXPECT_LE(coil_on_at - fire_at, 2 * dt);  // the frame is handled on the next tick
  ASSERT_GT(raised_at, 0.0) << "the flipper never reached its up stop";
  // Full stroke: (θmax - θmin)/ω after the delay.
  const double stroke_s = (theta_max - theta_min) / board.flippers[0].omega_rad_s;
  EXPECT_NEAR(raised_at - coil_on_at, kDelay + stroke_s, 3 * dt);
  EXPECT_EQ(state.flips, 1u);
  EXPECT_EQ(board_.coil(0).state, CoilState::kHold);  // held up while the button is held
  EXPECT_TRUE(bus.board().status.end_of_stroke & 1u);  // the switch made it back to the host
}

}  // namespace
}  // namespace pinball::firmware
