#pragma once
// The controller thread (pb-controller): for each projection the camera
// thread hands over, the controller stage decides (fire, hold, release) and
// the thread writes the commands' CAN frames itself when the driver thread is
// not busy; between projections it runs the stall and ball-lost checks off
// the real-time clock. Publishes each command on LCM. Every iteration is a
// beat of the liveness the driver bus's heartbeat depends on.

#include "handoffs.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/firmware/driver_bus.h"

namespace pinball::daemon {

/// One run() per daemon run, on its own thread.
class ControllerWorker {
 public:
  /// Borrows everything; `frame_period_s` paces the idle checks.
  ControllerWorker(Handoffs& handoffs, ControllerStage& stage, firmware::DriverBus& bus, bus::LcmBus& lcm,
                   const PipelineClock& clock, double frame_period_s)
      : h_(handoffs), stage_(stage), bus_(bus), lcm_(lcm), clock_(clock), frame_period_s_(frame_period_s) {}
  /// Until the camera thread is done and every record is handled, or the daemon stops.
  void run();

  /// Hands `n` commands to the driver thread's ring and to LCM (also for the shutdown's ReleaseAll).
  void publish(const ControllerStage::Commands& cmds, int n);

 private:
  // Writes the commands' CAN frames on this thread when the driver thread is not sending.
  void send_now(ControllerStage::Commands& cmds, int n, double now_s);
  // Progress, for the CAN heartbeat (the driver thread watches it; this thread cannot watch itself).
  void beat(double now_s) {
    if (h_.liveness != nullptr) h_.liveness->beat(kControllerBeat, now_s);
  }

  Handoffs& h_;
  ControllerStage& stage_;
  firmware::DriverBus& bus_;
  bus::LcmBus& lcm_;
  const PipelineClock& clock_;
  double frame_period_s_;
};

}  // namespace pinball::daemon
