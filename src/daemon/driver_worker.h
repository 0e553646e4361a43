#pragma once
// The driver thread (pb-driver): polls the CAN host (commands the controller
// thread left, heartbeats, Status and Faults, bus-off recovery), books the
// command->CAN and frame->CAN latencies, publishes the driver status on LCM
// ten times a second, and in lockstep tells the simulator that the frame's
// commands are on the bus.

#include <array>

#include "handoffs.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/firmware/driver_bus.h"

namespace pinball::daemon {

/// One run() per daemon run, on its own thread.
class DriverWorker {
 public:
  /// Borrows everything; `driver_of_flipper` maps tracker flippers to drivers.
  DriverWorker(Handoffs& handoffs, firmware::DriverBus& bus, bus::LcmBus& lcm, const PipelineClock& clock,
               const std::array<int, 2>& driver_of_flipper)
      : h_(handoffs), bus_(bus), lcm_(lcm), clock_(clock), driver_of_flipper_(driver_of_flipper) {}
  /// Until the controller thread is done and every command is booked, or the daemon stops.
  void run();

 private:
  Handoffs& h_;
  firmware::DriverBus& bus_;
  bus::LcmBus& lcm_;
  const PipelineClock& clock_;
  std::array<int, 2> driver_of_flipper_;
};

}  // namespace pinball::daemon
