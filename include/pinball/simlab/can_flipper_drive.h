#pragma once
// The simulator's flippers driven through the real CAN path, in lockstep with
// the simulated clock: the controller's commands go through DriverBus, CAN
// frames over a socket pair, the reference VirtualDriverBoard, and the
// solenoid's actuation delay before they move a simulated flipper (the
// design's embedded simulation: same code, same frames as the lab).

#include <memory>
#include <vector>

#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/firmware/virtual_driver_board.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"

namespace pinball::simlab {

/// Flipper i of the board is driver i of one virtual driver board.
class CanFlipperDrive {
 public:
  /// Throws std::invalid_argument for a board with no flipper or more than
  /// the protocol's drivers per board, or a negative delay.
  CanFlipperDrive(const table::Board& board, double actuation_delay_s);

  /// Call once per step, after the controller has set the commands in
  /// state.flippers[i].energized: sends the changes through the bus, runs the
  /// bus and the board up to state.time_s, and replaces every command with
  /// what the flipper does: its coil's output, `actuation_delay_s` later.
  void apply(sim::GameState& state);

  /// The board's counters (bad frames, refused commands, watchdog trips).
  const firmware::BoardCounters& board_counters() const { return board_.counters(); }
  /// The bus's counters.
  firmware::DriverBusCounters bus_counters() const { return bus_->counters(); }
  /// True once the bus has configured the board and heartbeats flow.
  bool running() const { return bus_->state() == firmware::BusState::kRunning; }

 private:
  std::unique_ptr<firmware::StreamTransport> host_end_;
  std::unique_ptr<firmware::StreamTransport> board_end_;
  std::unique_ptr<firmware::DriverBus> bus_;
  firmware::VirtualDriverBoard board_;
  std::vector<std::unique_ptr<firmware::FlipperActuation>> actuation_;
  std::vector<bool> commanded_;     // last command sent per flipper
  std::vector<double> theta_max_;   // up stop per flipper, for the end-of-stroke switches
};

}  // namespace pinball::simlab
