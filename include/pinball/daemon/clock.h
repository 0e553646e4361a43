#pragma once
// The daemon's wall clock: seconds on std::chrono::steady_clock. Latencies are
// differences of it; LCM's utime is it in microseconds.

#include <chrono>
#include <cstdint>

namespace pinball::daemon {

/// Steady clock now (s).
inline double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Seconds to LCM's microseconds.
inline std::int64_t to_utime(double t_s) { return static_cast<std::int64_t>(t_s * 1e6 + (t_s >= 0 ? 0.5 : -0.5)); }

}  // namespace pinball::daemon
