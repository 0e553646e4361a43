#pragma once
// The simulator thread (pb-sim): steps the simulated machine until the camera
// delivers a frame, hands the frame to the camera thread, publishes the game's
// events, closes the latency chain at the virtual board's coils, and paces
// itself to the wall clock or, in lockstep, waits for the chain to finish the
// frame and for the LCM thread to keep up. Sim mode only.

#include <cstdint>

#include "handoffs.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/simlab/sim_world.h"

namespace pinball::daemon {

/// One run() per daemon run, on its own thread.
class SimWorker {
 public:
  /// Borrows everything; `drivers` is the number of flipper drivers.
  SimWorker(Handoffs& handoffs, simlab::SimWorld& world, bus::LcmBus& lcm, bool lockstep, int drivers)
      : h_(handoffs), world_(world), lcm_(lcm), lockstep_(lockstep), drivers_(drivers) {}
  /// Until every ball is played or the daemon stops.
  void run();

 private:
  // Lockstep: waits while the LCM thread's outboxes are over half full, so that a
  // recording keeps up with the virtual clock; gives up waiting for the rest of the
  // run once they stop emptying for kLcmStallS (a sink that blocks).
  void wait_for_lcm_backlog();

  Handoffs& h_;
  simlab::SimWorld& world_;
  bus::LcmBus& lcm_;
  bool lockstep_;
  int drivers_;
  std::uint64_t last_coil_on_count_ = 0;
  bool lcm_stalled_ = false;
};

}  // namespace pinball::daemon
