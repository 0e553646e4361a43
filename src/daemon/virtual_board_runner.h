#pragma once
// The virtual driver board on a thread of its own, on the steady clock: the
// far end of the `sim` CAN link when no simulated world plays it. That is
// mode sim with camera.source lcm: recorded or replayed observations (LCM,
// e.g. lcm-logplayer) drive the tracker and the controller as in the lab, and
// their coil commands reach this board, so the whole chain runs, CAN frames
// and all, without hardware and without a simulated table.

#include <atomic>
#include <cstdint>
#include <thread>

#include "pinball/firmware/can_transport.h"
#include "pinball/firmware/virtual_driver_board.h"

namespace pinball::daemon {

/// Services a VirtualDriverBoard on `link` every 0.5 ms until destroyed.
class VirtualBoardRunner {
 public:
  /// Starts the thread (pb-vboard, SCHED_OTHER: it stands in for hardware).
  VirtualBoardRunner(firmware::CanTransport& link, firmware::VirtualDriverBoardOptions options);
  /// Stops and joins the thread.
  ~VirtualBoardRunner();
  VirtualBoardRunner(const VirtualBoardRunner&) = delete;
  VirtualBoardRunner& operator=(const VirtualBoardRunner&) = delete;

  /// Stops and joins the thread; the board may be read afterwards.
  void stop();
  /// The board's counters; call after stop().
  const firmware::BoardCounters& counters() const { return board_.counters(); }

 private:
  void run();

  firmware::CanTransport& link_;
  firmware::VirtualDriverBoard board_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace pinball::daemon
