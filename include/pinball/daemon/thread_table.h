#pragma once
// pinballd's threads, their SCHED_FIFO priorities and periods, in one place.
// The driver thread outranks the controller, which outranks the camera: a
// late frame costs one projection, a late CAN frame costs a flip, a late
// heartbeat costs every coil. The LCM thread runs at niceness 10 so that,
// on a machine with fewer cores than threads, its publishing yields the CPU
// to the frame -> CAN chain (without SCHED_FIFO it would take its fair share).
// The chain's three threads share one CPU: they run one after the other, so
// a second core gains them nothing, and a hand-off to a sleeping core costs a
// cross-core wake-up (hundreds of microseconds on a virtual machine, where an
// idle core is halted). The other threads get the other cores.

#include <array>
#include <string>
#include <vector>

namespace pinball::daemon {

/// One thread of the daemon.
struct ThreadSpec {
  const char* name;      ///< thread name (pthread_setname_np, at most 15 characters)
  int fifo_priority;     ///< SCHED_FIFO priority when real-time scheduling is on (0: stays SCHED_OTHER)
  int nice;              ///< niceness while SCHED_OTHER (always applied: raising it needs no privilege)
  bool chain;            ///< on the frame -> CAN chain: shares the chain's CPU (threads.chain_cpu)
  const char* cpu;       ///< where it runs, in words (the simulator joins the chain in lockstep)
  const char* period;    ///< how it runs
  const char* job;       ///< what it does
};

/// Index of each thread in kThreadTable.
enum ThreadId : int { kDriverThread = 0, kControllerThread, kCameraThread, kSimThread, kLcmThread, kThreadCount };

/// The table (README and `pinballd --threads` print it).
inline constexpr std::array<ThreadSpec, kThreadCount> kThreadTable{{
    {"pb-driver", 90, 0, true, "chain", "1 ms, or at once when a command is queued",
     "DriverBus: send commands, heartbeat, read Status and Faults, bus-off recovery"},
    {"pb-controller", 85, 0, true, "chain", "per projection; stall check every frame period",
     "action function + actuator controller -> DriverBus fire/release, writes the CAN frame itself; fail-safe "
     "releases"},
    {"pb-camera", 80, 0, true, "chain", "per frame (5 ms at 200 fps)", "grab -> detect -> track -> project"},
    {"pb-sim", 70, 0, false, "chain in lockstep, else others", "per simulator step (sim mode only)",
     "the simulated table (a world), its rendered camera frames, the virtual driver board on the far end of CAN"},
    {"pb-lcm", 0, 10, false, "others", "1 ms idle poll; stats once a second",
     "encode and publish LCM messages, receive observations, count malformed ones"},
}};

/// The table as Markdown (`pinballd --threads`; docs/daemon.md holds this very text).
std::string thread_table_markdown();

/// Names the calling thread, sets its niceness from the table and, when
/// `realtime`, gives it SCHED_FIFO at `priority` (the table's when negative;
/// 0 leaves it SCHED_OTHER). Returns false (with `why`) when the system refuses.
bool configure_current_thread(ThreadId id, bool realtime, std::string& why, int priority = -1);

/// Whether the system gives `id`'s thread SCHED_FIFO at `priority` (see
/// configure_current_thread): tried on a throw-away thread, so that a refusal
/// is known before anything runs. "" when allowed, else why not.
std::string probe_sched_fifo(ThreadId id, int priority);

/// Which CPUs the threads may use (empty: not pinned).
struct CpuPlan {
  std::vector<int> chain;   ///< the chain's threads (ThreadSpec::chain)
  std::vector<int> others;  ///< every other thread
  std::string describe;     ///< e.g. "chain on CPU 1, others on 0"
};

/// The plan for threads.chain_cpu ("auto", "off" or a CPU number) within the
/// CPUs this process may use. "auto" takes the highest of them and pins
/// nothing when there is only one. Throws ConfigError (threads.chain_cpu) when
/// the named CPU is not one the process may use.
CpuPlan plan_cpus(const std::string& chain_cpu);

/// Pins the calling thread to `cpus` (nothing when empty). False (with `why`) when refused.
bool pin_current_thread(const std::vector<int>& cpus, std::string& why);

/// A PM QoS request on /dev/cpu_dma_latency, held while the object lives:
/// no core enters an idle state whose exit takes longer than the limit.
class CpuLatencyRequest {
 public:
  /// Asks for `limit_us` (>= 0); `ok()` false (with `why()`) when refused.
  explicit CpuLatencyRequest(int limit_us);
  ~CpuLatencyRequest();
  CpuLatencyRequest(const CpuLatencyRequest&) = delete;
  CpuLatencyRequest& operator=(const CpuLatencyRequest&) = delete;
  bool ok() const { return fd_ >= 0; }
  const std::string& why() const { return why_; }

 private:
  int fd_ = -1;
  std::string why_;
};

/// Locks all current and future memory (mlockall). False (with `why`) when refused.
bool lock_memory(std::string& why);

/// Whether lock_memory would succeed, leaving memory unlocked: "" when it
/// would, else why not (pinballd --check).
std::string probe_lock_memory();

}  // namespace pinball::daemon
