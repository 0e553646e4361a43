#pragma once
// The CAN protocol between the host and the solenoid driver boards: frame ids,
// message kinds, limits and the packed wire structs, shared by the host
// (DriverBus) and the reference board (VirtualDriverBoard). PROTOCOL.md is the
// prose version of this file; the two change together.
//
// Byte order on the wire: every multi-byte field is little-endian and stored as
// bytes (Le16), so the structs mean the same on every host. The last byte of
// every frame is a CRC-8 over the 11-bit id and the bytes before it.

#include <cstdint>

namespace pinball::firmware {

/// Protocol version; exchanged in Hello/HelloAck and carried by every Heartbeat.
/// 2: Fault codes 8 (stale) and 9 (locked); a driver's sequence reference
/// follows the session's newest (rule 9); only Release/ReleaseAll unlock a
/// hold-capped driver (rule 6).
inline constexpr std::uint8_t kProtocolVersion = 2;

/// Classic CAN 2.0: at most 8 data bytes.
inline constexpr int kMaxFrameBytes = 8;
/// Drivers (coils) on one board.
inline constexpr int kMaxDrivers = 8;
/// Boards on one bus (the low nibble of the id).
inline constexpr int kMaxBoards = 16;

/// The bus's bit rate (bit/s): every board and host on it runs at this one.
inline constexpr std::uint32_t kBitrate_bps = 500'000;

/// 11-bit id layout: 0b001 KKKK BBBB (K = message kind, B = board).
inline constexpr std::uint32_t kIdBase = 0x100;
/// Mask selecting the fixed bits of our ids (for receive filters).
inline constexpr std::uint32_t kIdMask = 0x700;

/// Message kinds (the id's middle nibble). Lower ids win bus arbitration, so
/// the commands that switch coils off come first.
enum class MessageKind : std::uint8_t {
  kReleaseAll = 0x0,  ///< host -> board: every driver off
  kRelease = 0x1,     ///< host -> board: one driver off
  kFire = 0x2,        ///< host -> board: pulse, then optionally PWM hold
  kHeartbeat = 0x3,   ///< host -> board: keeps the watchdog alive
  kConfigure = 0x4,   ///< host -> board: one driver's timings and caps
  kHello = 0x5,       ///< host -> board: start of a session, version, watchdog timeout
  kFault = 0x8,       ///< board -> host: one fault event
  kStatus = 0x9,      ///< board -> host: periodic state of every driver
  kHelloAck = 0xA,    ///< board -> host: answer to Hello with the board's version
};

/// The 11-bit id of `kind` for board `board` (0..15).
constexpr std::uint32_t make_id(MessageKind kind, std::uint8_t board) {
  return kIdBase | (static_cast<std::uint32_t>(kind) << 4) | (board & 0x0Fu);
}

// ---- limits (the firmware enforces the absolute ones whatever it is told) ----

/// Absolute cap on a full-power pulse (ms).
inline constexpr std::uint8_t kAbsMaxPulseMs = 100;
/// Absolute cap on the hold PWM duty (percent of full power).
inline constexpr std::uint8_t kAbsMaxHoldDutyPct = 50;
/// Absolute cap on one continuous hold (ms).
inline constexpr std::uint16_t kAbsMaxHoldMs = 10'000;
/// Shortest and longest heartbeat watchdog timeout a Hello may ask for (ms).
inline constexpr std::uint16_t kMinWatchdogMs = 10;
inline constexpr std::uint16_t kMaxWatchdogMs = 1'000;

/// Defaults for a flipper coil (MPF-like: ~30 ms pulse, ~25 % hold).
inline constexpr std::uint8_t kDefaultPulseMs = 30;
inline constexpr std::uint8_t kDefaultMaxPulseMs = 40;
inline constexpr std::uint8_t kDefaultHoldDutyPct = 25;
inline constexpr std::uint16_t kDefaultMaxHoldMs = 5'000;
inline constexpr std::uint8_t kDefaultRecycleMs = 10;
inline constexpr std::uint16_t kDefaultWatchdogMs = 100;

/// Coil state of one driver as reported in Status (2 bits per driver).
enum class CoilState : std::uint8_t {
  kOff = 0,    ///< no current
  kPulse = 1,  ///< full power
  kHold = 2,   ///< PWM hold at the configured duty
};

/// Fire modes.
enum class FireMode : std::uint8_t {
  kPulseOnly = 0,  ///< pulse, then off
  kPulseHold = 1,  ///< pulse, then hold until Release (or the hold cap)
};

/// Fault codes carried by Fault frames.
enum class FaultCode : std::uint8_t {
  kWatchdogExpired = 1,  ///< heartbeats stopped: every driver switched off
  kHoldCapReached = 2,   ///< a hold hit its cap: driver off and locked until Release
  kPulseClamped = 3,     ///< a Fire asked for a longer pulse than the cap allows
  kBadFrame = 4,         ///< a frame failed to decode (detail: DecodeError)
  kVersionMismatch = 5,  ///< Hello or Heartbeat with another version (detail: that version)
  kNotConfigured = 6,    ///< a command before Hello/Configure (detail: message kind)
  kNotArmed = 7,         ///< Fire while the watchdog is not alive
  kStale = 8,            ///< a Fire whose seq was not newer than the driver's reference (detail: that seq)
  kLocked = 9,           ///< a Fire on a driver locked by its hold cap (detail: 0)
};
/// Largest valid FaultCode value.
inline constexpr std::uint8_t kMaxFaultCode = 9;

/// Bits of Status::faults: what happened since the previous Status.
enum FaultBits : std::uint8_t {
  kFaultBitWatchdog = 1u << 0,  ///< watchdog expired
  kFaultBitHoldCap = 1u << 1,   ///< a hold cap tripped
  kFaultBitPulseClamp = 1u << 2,  ///< a pulse was clamped
  kFaultBitBadFrame = 1u << 3,  ///< a bad frame was received
  kFaultBitVersion = 1u << 4,   ///< version mismatch seen
  kFaultBitRefused = 1u << 5,   ///< a command was refused (not configured / not armed)
  kFaultBitArmed = 1u << 7,     ///< not a fault: the watchdog is alive right now
};

// ---- wire structs ----

/// A little-endian 16-bit field stored as two bytes.
struct [[gnu::packed]] Le16 {
  std::uint8_t lo = 0;  ///< bits 0..7
  std::uint8_t hi = 0;  ///< bits 8..15
  /// The value.
  constexpr std::uint16_t get() const { return static_cast<std::uint16_t>(lo | (hi << 8)); }
  /// The field holding `v`.
  static constexpr Le16 of(std::uint16_t v) {
    return Le16{static_cast<std::uint8_t>(v & 0xFF), static_cast<std::uint8_t>(v >> 8)};
  }
};
static_assert(sizeof(Le16) == 2);

/// Hello (host -> board), 4 bytes.
struct [[gnu::packed]] HelloWire {
  std::uint8_t version;  ///< kProtocolVersion
  Le16 watchdog_ms;      ///< heartbeat timeout (ms), kMinWatchdogMs..kMaxWatchdogMs
  std::uint8_t crc;      ///< CRC-8
};
static_assert(sizeof(HelloWire) == 4);

/// HelloAck (board -> host), 5 bytes.
struct [[gnu::packed]] HelloAckWire {
  std::uint8_t version;       ///< the board's protocol version
  std::uint8_t driver_count;  ///< drivers fitted, 1..kMaxDrivers
  std::uint8_t fw_major;      ///< firmware version, major
  std::uint8_t fw_minor;      ///< firmware version, minor
  std::uint8_t crc;           ///< CRC-8
};
static_assert(sizeof(HelloAckWire) == 5);

/// Configure one driver (host -> board), 8 bytes.
struct [[gnu::packed]] ConfigureWire {
  std::uint8_t driver;         ///< 0..kMaxDrivers-1
  std::uint8_t pulse_ms;       ///< default pulse (ms), 1..max_pulse_ms
  std::uint8_t hold_duty_pct;  ///< hold PWM duty (%), 0..kAbsMaxHoldDutyPct; 0 = no hold
  std::uint8_t max_pulse_ms;   ///< per-driver pulse cap (ms), 1..kAbsMaxPulseMs
  std::uint8_t recycle_ms;     ///< minimum off time before the next Fire (ms)
  Le16 max_hold_ms;            ///< per-driver hold cap (ms), 1..kAbsMaxHoldMs
  std::uint8_t crc;            ///< CRC-8
};
static_assert(sizeof(ConfigureWire) == 8);

/// Fire: pulse then optionally hold (host -> board), 6 bytes.
struct [[gnu::packed]] FireWire {
  std::uint8_t driver;    ///< 0..kMaxDrivers-1
  std::uint8_t mode;      ///< FireMode
  std::uint8_t pulse_ms;  ///< pulse override (ms), 0 = configured, <= kAbsMaxPulseMs
  Le16 seq;               ///< command sequence number
  std::uint8_t crc;       ///< CRC-8
};
static_assert(sizeof(FireWire) == 6);

/// Release one driver (host -> board), 4 bytes.
struct [[gnu::packed]] ReleaseWire {
  std::uint8_t driver;  ///< 0..kMaxDrivers-1
  Le16 seq;             ///< command sequence number
  std::uint8_t crc;     ///< CRC-8
};
static_assert(sizeof(ReleaseWire) == 4);

/// Release every driver (host -> board), 3 bytes.
struct [[gnu::packed]] ReleaseAllWire {
  Le16 seq;           ///< command sequence number
  std::uint8_t crc;   ///< CRC-8
};
static_assert(sizeof(ReleaseAllWire) == 3);

/// Heartbeat (host -> board), 4 bytes.
struct [[gnu::packed]] HeartbeatWire {
  std::uint8_t version;  ///< kProtocolVersion
  Le16 seq;              ///< command sequence number
  std::uint8_t crc;      ///< CRC-8
};
static_assert(sizeof(HeartbeatWire) == 4);

/// Status (board -> host), 8 bytes.
struct [[gnu::packed]] StatusWire {
  Le16 coil_states;            ///< 2 bits per driver (driver d at bits 2d..2d+1), CoilState
  std::uint8_t end_of_stroke;  ///< bit d: driver d's end-of-stroke switch closed
  std::uint8_t configured;     ///< bit d: driver d configured
  std::uint8_t faults;         ///< FaultBits
  Le16 last_seq;               ///< newest command sequence number accepted
  std::uint8_t crc;            ///< CRC-8
};
static_assert(sizeof(StatusWire) == 8);

/// Fault (board -> host), 7 bytes.
struct [[gnu::packed]] FaultWire {
  std::uint8_t code;    ///< FaultCode
  std::uint8_t driver;  ///< driver concerned, 0xFF = the board
  Le16 detail;          ///< code-specific (see PROTOCOL.md)
  Le16 count;           ///< faults reported since Hello (wraps)
  std::uint8_t crc;     ///< CRC-8
};
static_assert(sizeof(FaultWire) == 7);

/// Driver value meaning "the whole board" in Fault frames.
inline constexpr std::uint8_t kBoardDriver = 0xFF;

/// True when sequence number `a` is newer than `b` (serial-number arithmetic, RFC 1982).
constexpr bool seq_newer(std::uint16_t a, std::uint16_t b) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(a - b)) > 0;
}

/// How far a driver's sequence reference may trail the newest sequence
/// number of the session (rule 9): half of serial arithmetic's window, so
/// that heartbeats alone can never make a later command look old.
inline constexpr std::uint16_t kSeqReferenceLag = 1u << 14;

}  // namespace pinball::firmware
