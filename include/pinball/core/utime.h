#pragma once
// LCM's time convention: int64 microseconds. The daemon rounds every
// timestamp it tracks to a whole microsecond, so that an observation read back
// from a log gives the tracker bit-for-bit the time it had live.

#include <cmath>
#include <cstdint>

namespace pinball {

/// Seconds to microseconds, rounded to the nearest.
inline std::int64_t to_utime(double t_s) { return static_cast<std::int64_t>(std::llround(t_s * 1e6)); }

/// Microseconds to seconds.
inline double from_utime(std::int64_t utime) { return static_cast<double>(utime) / 1e6; }

/// A time rounded to the microsecond, exactly as it comes back from a message.
inline double utime_rounded(double t_s) { return from_utime(to_utime(t_s)); }

}  // namespace pinball
