#pragma once
// What pinballd's threads share, and nothing else (docs/daemon.md,
// "Hand-offs"): the frame pool and its queue (simulator -> camera), the
// projection ring (camera -> controller), the command ring (controller ->
// driver), the doorbells that wake each thread, the end-of-run flags, the
// lockstep counters, and the latency histograms every stage records into.
// Every member is a lock-free ring, an atomic or a doorbell; a worker keeps
// the rest of its state to itself. Private to src/daemon.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "pinball/core/spsc_ring.h"
#include "pinball/daemon/daemon.h"
#include "pinball/daemon/doorbell.h"
#include "pinball/daemon/latency_histogram.h"
#include "pinball/daemon/pipeline.h"
#include "pinball/daemon/thread_table.h"
#include "pinball/firmware/liveness.h"
#include "pinball/firmware/protocol.h"
#include "pinball/track/observation.h"
#include "pinball/vision/frame.h"

namespace pinball::daemon {

/// A frame and what was read with it, handed from the frame producer to the camera thread.
struct FrameSlot {
  vision::Frame frame;             ///< the image; its buffer is reused
  track::ContactSensors contacts;  ///< the flipper contact switches during its exposure
  double capture_wall_s = 0.0;     ///< steady clock when it was handed over (s)
};

inline constexpr std::size_t kFrameQueue = 4;               ///< frames waiting for the camera thread
inline constexpr std::size_t kFramePool = kFrameQueue + 2;  ///< + one being processed + one being written

/// A fault a test asks one worker to suffer at the top of its next loop
/// (Daemon::inject_fault): the fault-injection suite's frozen and failing threads.
struct InjectedFault {
  std::atomic<double> freeze_s{0.0};  ///< sleep this long once (s)
  std::atomic<bool> fail{false};      ///< throw once
};

/// The chain's threads whose progress the CAN heartbeat vouches for (their
/// indices in Handoffs::liveness).
enum ChainBeat : int { kCameraBeat = 0, kControllerBeat = 1 };

/// The shared state of the daemon's threads.
struct Handoffs {
  std::array<FrameSlot, kFramePool> pool;    ///< frames, written by the producer, read by the camera thread
  SpscRing<int, kFrameQueue> frames;         ///< indices into `pool`, producer -> camera
  SpscRing<ProjectionRecord, 64> records;    ///< camera -> controller
  SpscRing<CommandRecord, 64> commands;      ///< controller -> driver (for the latency table)
  Doorbell camera_bell, controller_bell, driver_bell, sim_bell, main_bell;  ///< wake each thread
  std::atomic<bool> stop{false};             ///< every thread ends its loop
  std::atomic<bool> producer_done{false};    ///< the simulator played every ball
  std::atomic<bool> camera_done{false};      ///< the camera thread left its loop
  std::atomic<bool> controller_done{false};  ///< the controller thread left its loop
  std::atomic<std::uint64_t> frames_pushed{0};   ///< frames handed to the camera thread
  std::atomic<std::uint64_t> records_done{0};    ///< records the controller finished
  std::atomic<std::uint64_t> driver_done{0};     ///< records whose commands the driver sent (lockstep)
  std::atomic<std::uint64_t> frames_dropped{0};  ///< frames lost because the camera thread was behind
  std::atomic<std::uint64_t> ring_overflows{0};  ///< records or commands lost to a full ring
  std::atomic<double> virtual_now_s{0.0};        ///< lockstep: exposure time of the latest record (s)
  std::atomic<double> sim_time_s{0.0};           ///< the simulator's time (s)
  std::atomic<double> wall_offset_s{0.0};        ///< sim in real time: wall = simulated + offset (s)
  std::array<std::atomic<double>, firmware::kMaxDrivers> can_written_wall_s{};  ///< per driver: last Fire written
  std::array<LatencyHistogram, kStageCount> latency;  ///< per stage of the latency table
  firmware::Liveness* liveness = nullptr;    ///< camera and controller beats, read by the DriverBus (ChainBeat)
  std::atomic<std::uint64_t> camera_read_failures{0};  ///< failed grabs of a lab camera (each backed off)
  std::array<InjectedFault, kThreadCount> injected{};  ///< per ThreadId; one relaxed load per loop when unused

  /// Suffers the fault injected for thread `id`, if any: sleeps, or throws std::runtime_error.
  void take_injected_fault(ThreadId id);
};

/// The pipeline's clock: the steady clock in the lab; in simulation the
/// simulator's time, stepped by the records in lockstep and paced to the wall
/// clock otherwise.
class PipelineClock {
 public:
  PipelineClock(const Handoffs& handoffs, bool sim_mode, bool lockstep)
      : handoffs_(handoffs), sim_mode_(sim_mode), lockstep_(lockstep) {}
  /// Now on the pipeline's clock (s).
  double now_s() const;
  /// True on the lockstep (virtual) clock.
  bool lockstep() const { return lockstep_; }

 private:
  const Handoffs& handoffs_;
  bool sim_mode_;
  bool lockstep_;
};

}  // namespace pinball::daemon
