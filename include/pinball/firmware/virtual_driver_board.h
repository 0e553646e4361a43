#pragma once
// The reference solenoid driver board: a thin C++ face on the firmware core
// (include/pinball/firmware/core/board.h, portable C11), the same code the
// STM32 board runs. A plain class with explicit time: the caller
// hands it frames and the current time (the simulator's virtual clock, a
// test's, or the daemon's steady clock) and reads its coil outputs. It never
// allocates after construction and never throws on bad input; it counts.

#include <array>
#include <cstdint>

#include "pinball/firmware/can_transport.h"
#include "pinball/firmware/codec.h"
#include "pinball/firmware/coil_output.h"
#include "pinball/firmware/core/board.h"

namespace pinball::firmware {

/// Settings of the board itself (the caps come from the protocol).
struct VirtualDriverBoardOptions {
  std::uint8_t board_id = 0;        ///< board number 0..15 (the id's low nibble)
  int driver_count = kMaxDrivers;   ///< drivers fitted, 1..8
  double status_period_s = 0.01;    ///< Status frame period (s)
  std::uint8_t fw_major = 1;        ///< reported in HelloAck
  std::uint8_t fw_minor = 0;        ///< reported in HelloAck
};

/// What the board counted (never reset except by construction).
struct BoardCounters {
  std::uint64_t frames = 0;              ///< frames offered
  std::uint64_t bad_frames = 0;          ///< failed to decode (corrupt, wrong length, range, ...)
  std::uint64_t bad_checksum = 0;        ///< of which CRC mismatches
  std::uint64_t version_mismatch = 0;    ///< of which wrong protocol version
  std::uint64_t foreign = 0;             ///< for another board, or a board->host kind
  std::uint64_t hellos = 0;              ///< sessions started
  std::uint64_t fires_accepted = 0;      ///< Fire commands that energised a coil
  std::uint64_t refused_not_configured = 0;  ///< commands before Hello / Configure
  std::uint64_t refused_not_armed = 0;   ///< Fire while the watchdog was not alive
  std::uint64_t refused_recycle = 0;     ///< Fire within the recycle time
  std::uint64_t refused_busy = 0;        ///< Fire on a driver already on
  std::uint64_t refused_locked = 0;      ///< Fire on a driver locked by its hold cap
  std::uint64_t stale = 0;               ///< Fire / Heartbeat whose sequence number was not newer
  std::uint64_t pulse_clamps = 0;        ///< pulses shortened to the cap
  std::uint64_t hold_cap_trips = 0;      ///< holds ended by the cap
  std::uint64_t watchdog_trips = 0;      ///< all-off because heartbeats stopped
  std::uint64_t tx_dropped = 0;          ///< outgoing frames lost because the outbox was full
};

/// The reference driver board.
class VirtualDriverBoard {
 public:
  /// Throws std::invalid_argument for a board id or driver count out of range.
  explicit VirtualDriverBoard(VirtualDriverBoardOptions options = {});

  /// Handles one received frame at board time `now_s` (advances to now first).
  void on_frame(const CanFrame& frame, double now_s);
  /// Runs the output timers up to `now_s`: pulse end, hold cap, watchdog, status.
  /// Time never goes backwards: an earlier now_s is treated as the last one.
  /// The core counts whole nanoseconds: a change made by the call itself is
  /// stamped with `now_s` exactly, one at a timer's deadline with that
  /// nanosecond (never later than `now_s`).
  void advance(double now_s);

  /// Receives every frame waiting on `link`, advances to `now_s`, sends the
  /// outbox; returns the frames handled.
  int service(CanTransport& link, double now_s);
  /// Takes the next outgoing frame (Status, Fault, HelloAck); false when none.
  bool pop_tx(CanFrame& frame);
  /// Sends the whole outbox on `link`; returns the frames sent.
  int flush(CanTransport& link);

  /// Driver `d`'s output now.
  const CoilOutput& coil(int d) const { return outputs_[static_cast<std::size_t>(d)]; }
  /// True when driver `d` has a configuration in this session.
  bool configured(int d) const { return core_.drivers[d].configured; }
  /// Driver `d`'s configuration (meaningful when configured).
  const DriverConfig& config(int d) const { return configs_[static_cast<std::size_t>(d)]; }
  /// True while heartbeats arrive in time.
  bool armed() const { return core_.armed; }
  /// True after a valid Hello.
  bool in_session() const { return core_.session; }
  /// Sets driver `d`'s end-of-stroke switch (the simulator: flipper at its up stop).
  void set_end_of_stroke(int d, bool closed);
  /// The Status the board would send now.
  Status status() const;
  /// The counters.
  const BoardCounters& counters() const { return counters_; }
  /// Board time of the last advance (s).
  double now_s() const { return now_s_; }
  /// Registers an observer of output changes (at most kMaxListeners; borrowed).
  void add_listener(CoilListener* listener);

  /// Most observers.
  static constexpr int kMaxListeners = 4;
  /// Outbox capacity (frames).
  static constexpr int kOutboxSize = 32;

 private:
  static void on_core_coil(void* self, unsigned driver, pbfw_coil_state state, std::uint8_t duty_pct,
                           pbfw_time_ns at_ns);
  // Converts the caller's time to the core's nanoseconds and remembers both,
  // so that a change "now" carries the caller's exact time.
  pbfw_time_ns enter(double now_s);
  // Copy what the core changed into the C++ views.
  void sync_counters();
  void sync_configs();

  VirtualDriverBoardOptions options_;
  pbfw_board core_{};
  double now_s_ = 0.0;          // board time of the last call (s), never backwards
  pbfw_time_ns now_us_ = 0;     // the same on the core's clock
  bool started_ = false;
  std::array<CoilOutput, kMaxDrivers> outputs_{};
  std::array<DriverConfig, kMaxDrivers> configs_{};
  std::array<CoilListener*, kMaxListeners> listeners_{};
  int listener_count_ = 0;
  BoardCounters counters_;
};

}  // namespace pinball::firmware
