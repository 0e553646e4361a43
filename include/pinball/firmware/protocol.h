#pragma once
// The CAN protocol between the host and the solenoid driver boards, for C++:
// frame ids, message kinds and limits, each taken from the firmware core's C
// header (core/wire.h), whose wire.c lays out and checks every frame. The
// host (DriverBus) and the boards (VirtualDriverBoard, the STM32 firmware)
// share those numbers. PROTOCOL.md is the prose version; they change together.

#include <cstdint>

#include "pinball/firmware/core/wire.h"

namespace pinball::firmware {

/// Protocol version; exchanged in Hello/HelloAck and carried by every Heartbeat.
/// 2: Fault codes 8 (stale) and 9 (locked); a driver's sequence reference
/// follows the session's newest (rule 9); only Release/ReleaseAll unlock a
/// hold-capped driver (rule 6).
inline constexpr std::uint8_t kProtocolVersion = PBFW_PROTOCOL_VERSION;

/// Classic CAN 2.0: at most 8 data bytes.
inline constexpr int kMaxFrameBytes = PBFW_MAX_FRAME_BYTES;
/// Drivers (coils) on one board.
inline constexpr int kMaxDrivers = PBFW_MAX_DRIVERS;
/// Boards on one bus (the low nibble of the id).
inline constexpr int kMaxBoards = PBFW_MAX_BOARDS;

/// The bus's bit rate (bit/s): every board and host on it runs at this one.
inline constexpr std::uint32_t kBitrate_bps = PBFW_BITRATE_BPS;

/// 11-bit id layout: 0b001 KKKK BBBB (K = message kind, B = board).
inline constexpr std::uint32_t kIdBase = PBFW_ID_BASE;
/// Mask selecting the fixed bits of our ids (for receive filters).
inline constexpr std::uint32_t kIdMask = PBFW_ID_MASK;

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
inline constexpr std::uint8_t kAbsMaxPulseMs = PBFW_ABS_MAX_PULSE_MS;
/// Absolute cap on the hold PWM duty (percent of full power).
inline constexpr std::uint8_t kAbsMaxHoldDutyPct = PBFW_ABS_MAX_HOLD_DUTY_PCT;
/// Absolute cap on one continuous hold (ms).
inline constexpr std::uint16_t kAbsMaxHoldMs = PBFW_ABS_MAX_HOLD_MS;
/// Shortest and longest heartbeat watchdog timeout a Hello may ask for (ms).
inline constexpr std::uint16_t kMinWatchdogMs = PBFW_MIN_WATCHDOG_MS;
inline constexpr std::uint16_t kMaxWatchdogMs = PBFW_MAX_WATCHDOG_MS;

/// Defaults for a flipper coil (MPF-like: ~30 ms pulse, ~25 % hold).
inline constexpr std::uint8_t kDefaultPulseMs = 30;
inline constexpr std::uint8_t kDefaultMaxPulseMs = 40;
inline constexpr std::uint8_t kDefaultHoldDutyPct = 25;
inline constexpr std::uint16_t kDefaultMaxHoldMs = 5'000;
inline constexpr std::uint8_t kDefaultRecycleMs = 10;
inline constexpr std::uint16_t kDefaultWatchdogMs = PBFW_DEFAULT_WATCHDOG_MS;

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
inline constexpr std::uint8_t kMaxFaultCode = PBFW_MAX_FAULT_CODE;

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

/// Driver value meaning "the whole board" in Fault frames.
inline constexpr std::uint8_t kBoardDriver = PBFW_BOARD_DRIVER;

/// True when sequence number `a` is newer than `b` (serial-number arithmetic, RFC 1982).
inline bool seq_newer(std::uint16_t a, std::uint16_t b) { return pbfw_seq_newer(a, b); }

/// How far a driver's sequence reference may trail the newest sequence
/// number of the session (rule 9): half of serial arithmetic's window, so
/// that heartbeats alone can never make a later command look old.
inline constexpr std::uint16_t kSeqReferenceLag = PBFW_SEQ_REFERENCE_LAG;

}  // namespace pinball::firmware
