#pragma once
// The host side of the CAN link: the controller calls fire/release/release_all,
// which only enqueue and return (no socket I/O, no allocation, no lock); the
// bus's own thread sends the frames, the heartbeat at its period, runs the
// session (Hello, Configure, running, bus-off recovery) and tracks the board's
// Status and Faults. On any failure it makes the coils safe first (ReleaseAll)
// and counts. Without start(), poll_once(now) runs one iteration on the
// caller's clock (the simulator's lockstep and deterministic tests).
// A controller in a hurry may call send_queued(now) after enqueueing: it
// writes the queue on its own thread unless the bus thread is busy at that
// moment (a try-lock: it never waits), which saves one thread wake-up
// between a decision and its CAN frame.
//
// The host proves the coils are off rather than hoping so: every Status is
// compared with what the host commanded, and a coil it wants off but sees on
// gets its Release again and, past a deadline, a ReleaseAll. The board's
// faults are acted on (a hold-capped driver is released, which unlocks it)
// and handed to one reader as BusFault events. With a Liveness, heartbeats
// flow only while the watched threads make progress: a stalled chain makes
// the board switch every coil off within its watchdog.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "pinball/core/spsc_ring.h"
#include "pinball/firmware/can_transport.h"
#include "pinball/firmware/codec.h"

namespace pinball::firmware {

class FrameLog;
class Liveness;

/// Settings of a DriverBus; checked by the constructor.
struct DriverBusOptions {
  std::uint8_t board_id = 0;                          ///< board to talk to, 0..15
  int driver_count = 2;                               ///< drivers used (flipper i = driver i), 1..8
  std::array<DriverConfig, kMaxDrivers> drivers{};    ///< per-driver timings and caps
  double heartbeat_period_s = 0.02;                   ///< heartbeat period (s)
  double watchdog_timeout_s = 0.1;                    ///< board switches all off after this silence (s); >= 3 periods
  double reply_timeout_s = 0.05;                      ///< resend Hello / Configure after this (s)
  double status_timeout_s = 0.25;                     ///< no Status for this long: restart the session (s)
  double bus_off_holdoff_s = 0.1;                     ///< wait after bus-off before reopening (s)
  /// A Status still showing a coil on this long after its Release was sent
  /// (or after the board accepted a later frame) gets the Release again (s).
  double release_retry_s = 0.003;
  /// A coil still on this long after a Status first showed it on against the
  /// host's wish gets a ReleaseAll (s).
  double release_deadline_s = 0.05;
  /// The closed loop on Status above; false only for a benchmark's baseline
  /// (the protocol v1 host, which never compared).
  bool verify_coils = true;
  FrameLog* log = nullptr;                            ///< optional candump log of every frame (borrowed)
  Liveness* liveness = nullptr;                       ///< heartbeat only while these threads progress (borrowed; null: always)
};

/// Session state.
enum class BusState : std::uint8_t {
  kStopped = 0,   ///< not started
  kHandshake,     ///< Hello sent, waiting for HelloAck
  kConfiguring,   ///< Configure sent, waiting for a Status with every driver configured
  kRunning,       ///< commands flow
  kBusOff,        ///< the controller went bus-off: waiting to reopen
};

/// Counters (monotonic).
struct DriverBusCounters {
  std::uint64_t fires = 0;             ///< fire() calls accepted into the queue
  std::uint64_t releases = 0;          ///< release() calls accepted into the queue
  std::uint64_t release_alls = 0;      ///< release_all() calls
  std::uint64_t queue_full = 0;        ///< commands refused because the queue was full
  std::uint64_t dropped_not_running = 0;  ///< commands discarded because the session was not running
  std::uint64_t frames_sent = 0;       ///< frames sent successfully
  std::uint64_t tx_failures = 0;       ///< sends that failed (each followed by a ReleaseAll attempt)
  /// Commands send_queued left for the bus thread because the kernel's queue
  /// was full (WhenFull::kLeaveQueued: the caller must not sleep in a back-off).
  std::uint64_t sends_left_queued = 0;
  std::uint64_t heartbeats = 0;        ///< heartbeats sent
  std::uint64_t hellos = 0;            ///< Hello frames sent
  std::uint64_t sessions = 0;          ///< times the session reached kRunning
  std::uint64_t rx_frames = 0;         ///< frames received and decoded
  std::uint64_t rx_bad = 0;            ///< frames received that failed to decode
  std::uint64_t version_mismatch = 0;  ///< HelloAck with another protocol version
  std::uint64_t statuses = 0;          ///< Status frames received
  std::uint64_t faults = 0;            ///< Fault frames received
  std::uint64_t watchdog_faults = 0;   ///< of which the board's watchdog expired
  std::uint64_t hold_cap_faults = 0;   ///< of which a hold cap tripped
  std::uint64_t error_frames = 0;      ///< controller error frames
  std::uint64_t bus_off = 0;           ///< bus-off events
  std::uint64_t reconnects = 0;        ///< transport reopened after bus-off
  std::uint64_t status_timeouts = 0;   ///< sessions restarted for lack of Status
  std::uint64_t release_retries = 0;   ///< Releases sent again because a Status still showed the coil on
  std::uint64_t release_escalations = 0;  ///< ReleaseAlls because a coil outlived release_deadline_s
  std::uint64_t stale_faults = 0;      ///< Fires the board refused as not newer (Fault 8)
  std::uint64_t locked_faults = 0;     ///< Fires the board refused on a hold-capped driver (Fault 9)
  std::uint64_t refused_faults = 0;    ///< other refused commands (Faults 6 not configured, 7 not armed)
  std::uint64_t liveness_stalls = 0;   ///< a watched thread stopped progressing: coils released, heartbeats withheld
  std::uint64_t heartbeats_withheld = 0;  ///< heartbeats not sent while a watched thread was stalled
  /// The coils went off behind the controller's back (watchdog, hold cap,
  /// stall, escalation): the commands in force are void.
  std::uint64_t coils_dropped = 0;
  std::uint64_t faults_unreported = 0;  ///< BusFault events lost because nobody read them in time
  std::uint64_t thread_failures = 0;    ///< the bus thread ended by an exception (after a ReleaseAll)
};

/// What a BusFault event is about.
enum class BusFaultKind : std::uint8_t {
  kBoard,             ///< a Fault frame from the board (code, driver, detail)
  kReleaseEscalated,  ///< a coil stayed on past release_deadline_s: ReleaseAll (driver)
  kLivenessStall,     ///< a watched thread stopped progressing (detail: its Liveness index)
  kStatusTimeout,     ///< the board fell silent: coils released, session restarted
  kBusOff,            ///< the CAN controller went bus-off
  kTxFailure,         ///< a frame could not be sent: ReleaseAll attempted
};

/// One fault the bus saw or acted on, for the daemon to report.
struct BusFault {
  double t_s = 0.0;                            ///< bus time (s)
  BusFaultKind kind = BusFaultKind::kBoard;    ///< what
  FaultCode code = FaultCode::kBadFrame;       ///< the board's code (kBoard only)
  std::uint8_t driver = kBoardDriver;          ///< driver concerned, kBoardDriver: all / the board
  std::uint16_t detail = 0;                    ///< code-specific (PROTOCOL.md's Fault detail)
};

/// One line naming `f` and what the host did about it; `liveness` names stalled threads (may be null).
std::string describe(const BusFault& f, const Liveness* liveness = nullptr);

/// The board's last Status as the host saw it.
struct BoardView {
  bool valid = false;   ///< a Status has arrived in this session
  Status status;        ///< its content
};

/// The host side of the link to one driver board.
class DriverBus {
 public:
  /// Borrows `transport`. Throws std::invalid_argument naming the bad option.
  DriverBus(CanTransport& transport, DriverBusOptions options);
  /// Stops the thread (switching every coil off first).
  ~DriverBus();
  DriverBus(const DriverBus&) = delete;
  DriverBus& operator=(const DriverBus&) = delete;

  /// Starts the bus thread (steady clock). Throws std::logic_error if running.
  void start();
  /// Sends ReleaseAll, then stops the thread. Safe to call twice.
  void stop();
  /// Stops the thread without sending anything, as a crashed or hung host
  /// would (for fault-injection tests: the board's watchdog must act).
  void simulate_hang();

  /// Pulse then hold flipper i. Never blocks; false when refused (bad index, queue full).
  bool fire(int flipper);
  /// Release flipper i. Never blocks; false when refused.
  bool release(int flipper);
  /// Release every flipper; takes priority over queued commands. Never blocks.
  void release_all();

  /// Records every frame from now on in `log` (borrowed; null: none), as
  /// DriverBusOptions::log does from the start: for a log opened only once
  /// the caller's start-up has succeeded (pinballd: a start that fails leaves
  /// the last run's log as it was). Waits for a poll in progress.
  void attach_log(FrameLog* log);

  /// One iteration at time `now_s` (s, any monotonic clock): receive, run the
  /// session, send commands and the heartbeat. For use without start().
  void poll_once(double now_s);

  /// What a send does when the kernel's queue is full: back off and retry
  /// (the transport's policy, up to 750 us a frame on SocketCAN), or leave
  /// the command and those after it queued for the bus thread.
  enum class WhenFull : std::uint8_t { kBackOff, kLeaveQueued };

  /// Sends what is queued (ReleaseAll first) on the calling thread, unless
  /// poll_once is running elsewhere at this moment: never blocks on another
  /// thread. True when the queue was sent (or discarded because the session
  /// is not running, or left for the bus thread on a full kernel queue with
  /// kLeaveQueued, which a real-time caller passes); false when the bus was
  /// busy, and the next poll_once sends it. At most one caller besides the
  /// bus's own thread.
  bool send_queued(double now_s, WhenFull when_full = WhenFull::kBackOff);

  /// Session state.
  BusState state() const { return state_.load(std::memory_order_acquire); }
  /// Counters so far.
  DriverBusCounters counters() const;
  /// The board's last Status (lock-free snapshot).
  BoardView board() const;
  /// The options in force.
  const DriverBusOptions& options() const { return options_; }
  /// Takes the oldest unread fault event; false when none. One reader thread.
  bool pop_fault(BusFault& out) { return faults_.try_pop(out); }

  /// Commands that fit in the queue between two bus iterations.
  static constexpr int kQueueSize = 64;

 private:
  enum class Op : std::uint8_t { kFire, kRelease };
  struct Command {
    Op op;
    std::uint8_t driver;
  };

  // What the host last commanded one driver, for the closed loop on Status.
  struct Intent {
    bool on = false;                // Fire sent, no Release since
    std::uint16_t off_seq = 0;      // seq of the last Release / ReleaseAll covering it
    double off_sent_s = -1e300;     // when that was sent
    double seen_on_since_s = -1.0;  // first Status showing it on against our wish (< 0: none)
  };

  bool push(Op op, int flipper);
  void note_fault(BusFaultKind kind, double now_s, std::uint8_t driver = kBoardDriver, std::uint16_t detail = 0,
                  FaultCode code = FaultCode::kBadFrame);
  void on_board_fault(const Fault& f, double now_s);
  void check_coils(const Status& st, double now_s);
  void send_release(std::uint8_t driver, double now_s);
  bool chain_alive(double now_s);
  void run();
  void loop();
  void wake();
  enum class Sent : std::uint8_t { kOk, kFailed, kLeftQueued };
  Sent send(const Payload& p, double now_s, WhenFull when_full = WhenFull::kBackOff);
  void bump(std::uint64_t DriverBusCounters::*field, std::uint64_t n = 1);
  Sent make_safe(double now_s, WhenFull when_full = WhenFull::kBackOff);
  void begin_session(double now_s);
  void on_message(const Message& m, double now_s);
  void on_error_frame(const CanFrame& f, double now_s);
  void set_state(BusState s) { state_.store(s, std::memory_order_release); }
  void send_commands(double now_s, WhenFull when_full);

  CanTransport& transport_;
  DriverBusOptions options_;
  std::atomic<BusState> state_{BusState::kStopped};

  // Single-producer (controller) / single-consumer (bus thread) ring.
  std::array<Command, kQueueSize> queue_{};
  std::atomic<std::uint32_t> head_{0};
  std::atomic<std::uint32_t> tail_{0};
  std::atomic<bool> release_all_pending_{false};

  // Serialises every send and the bus-thread state below between poll_once
  // and send_queued, so that frames leave in the order they were decided.
  std::mutex io_mutex_;

  // Bus-thread state.
  std::uint16_t seq_ = 0;
  double last_heartbeat_s_ = -1e300;
  double last_withheld_s_ = -1e300;
  double last_request_s_ = -1e300;
  double last_status_s_ = 0.0;
  double bus_off_s_ = 0.0;
  std::uint8_t board_drivers_ = 0;
  std::array<Intent, kMaxDrivers> intent_{};
  bool chain_stalled_ = false;
  SpscRing<BusFault, 64> faults_;  // written under io_mutex_, read by one reporter

  std::atomic<std::uint64_t> status_word_{0};  // bit 63: valid; then the Status fields
  struct AtomicCounters;
  std::unique_ptr<AtomicCounters> counters_;

  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> hang_{false};
  int wake_fd_ = -1;
};

}  // namespace pinball::firmware
