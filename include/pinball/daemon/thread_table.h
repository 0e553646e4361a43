#pragma once
// pinballd's threads, their SCHED_FIFO priorities and periods, in one place.
// The driver thread outranks the controller, which outranks the camera: a
// late frame costs one projection, a late CAN frame costs a flip, a late
// heartbeat costs every coil.

#include <array>
#include <string>

namespace pinball::daemon {

/// One thread of the daemon.
struct ThreadSpec {
  const char* name;      ///< thread name (pthread_setname_np, at most 15 characters)
  int fifo_priority;     ///< SCHED_FIFO priority when real-time scheduling is on (0: stays SCHED_OTHER)
  const char* period;    ///< how it runs
  const char* job;       ///< what it does
};

/// Index of each thread in kThreadTable.
enum ThreadId : int { kDriverThread = 0, kControllerThread, kCameraThread, kSimThread, kLcmThread, kThreadCount };

/// The table (README and `pinballd --threads` print it).
inline constexpr std::array<ThreadSpec, kThreadCount> kThreadTable{{
    {"pb-driver", 90, "1 ms, or at once when a command is queued",
     "DriverBus: send commands, heartbeat, read Status and Faults, bus-off recovery"},
    {"pb-controller", 85, "per projection; stall check every frame period",
     "action function + actuator controller -> DriverBus fire/release; fail-safe releases"},
    {"pb-camera", 80, "per frame (5 ms at 200 fps)", "grab -> detect -> track -> project"},
    {"pb-sim", 70, "per simulator step (sim mode only)",
     "simulated table, rendered camera frames, the virtual driver board on the far end of CAN"},
    {"pb-lcm", 0, "0.5 ms idle poll; stats once a second",
     "encode and publish LCM messages, receive observations, count malformed ones"},
}};

/// Names the calling thread and, when `realtime`, gives it SCHED_FIFO at
/// `priority` (the table's when negative; 0 leaves it SCHED_OTHER). Returns
/// false (with `why`) when the system refuses.
bool configure_current_thread(ThreadId id, bool realtime, std::string& why, int priority = -1);

/// Locks all current and future memory (mlockall). False (with `why`) when refused.
bool lock_memory(std::string& why);

}  // namespace pinball::daemon
