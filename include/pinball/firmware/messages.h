#pragma once
// The meaning of each message (Drake's split: bytes in protocol.h, meaning
// here). Fields are in the protocol's own units (ms, percent) as the names say.

#include <cstdint>
#include <variant>

#include "pinball/core/name_value.h"
#include "pinball/firmware/protocol.h"

namespace pinball::firmware {

/// Timings and caps of one driver (Configure's payload).
struct DriverConfig {
  std::uint8_t pulse_ms = kDefaultPulseMs;            ///< default full-power pulse (ms)
  std::uint8_t hold_duty_pct = kDefaultHoldDutyPct;   ///< hold PWM duty (%)
  std::uint8_t max_pulse_ms = kDefaultMaxPulseMs;     ///< per-driver pulse cap (ms)
  std::uint16_t max_hold_ms = kDefaultMaxHoldMs;      ///< per-driver hold cap (ms)
  std::uint8_t recycle_ms = kDefaultRecycleMs;        ///< off time required before the next Fire (ms)

  /// The fields under their own names (pinballd's `coils` section).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(pulse_ms));
    a->Visit(PINBALL_NVP(hold_duty_pct));
    a->Visit(PINBALL_NVP(max_pulse_ms));
    a->Visit(PINBALL_NVP(max_hold_ms));
    a->Visit(PINBALL_NVP(recycle_ms));
  }
};

/// Start of a session.
struct Hello {
  std::uint8_t version = kProtocolVersion;       ///< the host's protocol version
  std::uint16_t watchdog_ms = kDefaultWatchdogMs;  ///< heartbeat timeout (ms)
};
/// Answer to Hello.
struct HelloAck {
  std::uint8_t version = kProtocolVersion;  ///< the board's protocol version
  std::uint8_t driver_count = kMaxDrivers;  ///< drivers fitted
  std::uint8_t fw_major = 1;                ///< firmware version, major
  std::uint8_t fw_minor = 0;                ///< firmware version, minor
};
/// Configure one driver.
struct Configure {
  std::uint8_t driver = 0;  ///< driver index
  DriverConfig config;      ///< its timings and caps
};
/// Pulse, then optionally hold.
struct Fire {
  std::uint8_t driver = 0;               ///< driver index
  FireMode mode = FireMode::kPulseHold;  ///< hold after the pulse or not
  std::uint8_t pulse_ms = 0;             ///< pulse override (ms), 0 = configured
  std::uint16_t seq = 0;                 ///< command sequence number
};
/// Release one driver.
struct Release {
  std::uint8_t driver = 0;  ///< driver index
  std::uint16_t seq = 0;    ///< command sequence number
};
/// Release every driver.
struct ReleaseAll {
  std::uint16_t seq = 0;  ///< command sequence number
};
/// Keep-alive.
struct Heartbeat {
  std::uint8_t version = kProtocolVersion;  ///< the host's protocol version
  std::uint16_t seq = 0;                    ///< command sequence number
};
/// Periodic board state.
struct Status {
  std::uint16_t coil_states = 0;   ///< 2 bits per driver, CoilState
  std::uint8_t end_of_stroke = 0;  ///< bit per driver
  std::uint8_t configured = 0;     ///< bit per driver
  std::uint8_t faults = 0;         ///< FaultBits
  std::uint16_t last_seq = 0;      ///< newest command sequence number accepted

  /// Driver d's coil state.
  CoilState coil(int d) const { return static_cast<CoilState>((coil_states >> (2 * d)) & 3u); }
};
/// One fault event.
struct Fault {
  FaultCode code = FaultCode::kBadFrame;  ///< what happened
  std::uint8_t driver = kBoardDriver;     ///< driver concerned or kBoardDriver
  std::uint16_t detail = 0;               ///< code-specific value
  std::uint16_t count = 0;                ///< faults since Hello (wraps)
};

/// Any message.
using Payload = std::variant<Hello, HelloAck, Configure, Fire, Release, ReleaseAll, Heartbeat, Status, Fault>;

/// A decoded message: which board and what.
struct Message {
  std::uint8_t board = 0;  ///< board id from the frame id
  Payload payload;         ///< the message
};

/// The kind of a payload.
MessageKind kind_of(const Payload& payload);

}  // namespace pinball::firmware
