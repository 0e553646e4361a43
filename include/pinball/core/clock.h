#pragma once
// The wall clock of the daemon and its stand-ins: seconds on std::chrono::steady_clock. Latencies are
// differences of it; LCM's utime is it in microseconds.

#include <chrono>
#include <cstdint>

#include "pinball/core/utime.h"

namespace pinball {

/// Steady clock now (s).
inline double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace pinball
