#pragma once
// Encoding and decoding of frames. Decoding checks everything (id, length,
// kind, CRC, ranges, version) and always returns a verdict with a reason; it
// never throws and never allocates.

#include <cstdint>
#include <span>

#include "pinball/firmware/can_frame.h"
#include "pinball/firmware/messages.h"

namespace pinball::firmware {

/// Why a frame was rejected.
enum class DecodeError : std::uint8_t {
  kOk = 0,           ///< decoded
  kErrorFrame,       ///< a controller error frame, not a message
  kForeignId,        ///< the id is not one of ours
  kUnknownKind,      ///< our id range but no such message kind
  kWrongLength,      ///< length differs from the kind's fixed length
  kBadChecksum,      ///< CRC-8 mismatch (corrupted frame)
  kOutOfRange,       ///< a field's value is outside its range
  kWrongVersion,     ///< protocol version differs from kProtocolVersion
};

/// The result of decode(): the error (kOk on success), a reason, the message.
struct DecodeResult {
  DecodeError error = DecodeError::kOk;  ///< verdict
  const char* reason = "";               ///< static string naming the failed check
  Message message;                       ///< valid only when error == kOk

  /// True on success.
  bool ok() const { return error == DecodeError::kOk; }
};

/// CRC-8 (polynomial 0x2F, AUTOSAR; init 0xFF, final xor 0xFF) over the
/// id's two bytes (little-endian) and `bytes`.
std::uint8_t frame_crc(std::uint32_t id, std::span<const std::uint8_t> bytes);

/// Encodes a message for board `board` (0..15). The caller guarantees valid
/// field values; an invalid one (driver >= kMaxDrivers, ...) is encoded as
/// given so that tests can build bad frames, and the receiver rejects it.
CanFrame encode(std::uint8_t board, const Payload& payload);

/// Decodes and validates one frame.
DecodeResult decode(const CanFrame& frame);

/// Checks a driver configuration; returns nullptr when valid, else the reason.
const char* validate(const DriverConfig& config);

/// Name of a decode error ("wrong length", ...).
const char* to_string(DecodeError error);
/// Name of a board fault code ("watchdog expired", ...).
const char* to_string(FaultCode code);

/// Fixed data length of a message kind, or -1 for an unknown kind.
int frame_length(std::uint8_t kind);

}  // namespace pinball::firmware
