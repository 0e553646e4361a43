#pragma once
// The clocks of the daemon and its stand-ins. Latencies are differences of
// the steady clock; LCM's utime in the lab is it in microseconds. Recordings
// (LCM and CAN logs) are stamped on the epoch, as candump and lcm-logger
// do: docs/daemon.md, "One clock for a run's recordings".

#include <chrono>
#include <cstdint>

#include "pinball/core/utime.h"

namespace pinball {

/// Steady clock now (s).
inline double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// The system (epoch) clock now (s since 1970): what candump and lcm-logger stamp with.
inline double epoch_now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace pinball
