#include "pinball/firmware/codec.h"

#include "core_bridge.h"

namespace pinball::firmware {

// The enums are C++'s names for the core's numbers.
static_assert(static_cast<int>(DecodeError::kWrongVersion) == PBFW_DECODE_WRONG_VERSION &&
              static_cast<int>(DecodeError::kBadChecksum) == PBFW_DECODE_BAD_CHECKSUM &&
              static_cast<int>(DecodeError::kErrorFrame) == PBFW_DECODE_ERROR_FRAME);
static_assert(static_cast<int>(MessageKind::kReleaseAll) == PBFW_RELEASE_ALL &&
              static_cast<int>(MessageKind::kFire) == PBFW_FIRE && static_cast<int>(MessageKind::kHelloAck) == PBFW_HELLO_ACK);
static_assert(static_cast<int>(FaultCode::kWatchdogExpired) == PBFW_FAULT_WATCHDOG_EXPIRED &&
              static_cast<int>(FaultCode::kLocked) == PBFW_FAULT_LOCKED);
static_assert(kFaultBitWatchdog == PBFW_FAULT_BIT_WATCHDOG && kFaultBitArmed == PBFW_FAULT_BIT_ARMED &&
              kFaultBitRefused == PBFW_FAULT_BIT_REFUSED);
static_assert(static_cast<int>(CoilState::kHold) == PBFW_COIL_HOLD && static_cast<int>(FireMode::kPulseHold) == PBFW_PULSE_HOLD);

std::uint8_t frame_crc(std::uint32_t id, std::span<const std::uint8_t> bytes) {
  return pbfw_crc8(id, bytes.data(), static_cast<unsigned>(bytes.size()));
}

int frame_length(std::uint8_t kind) { return pbfw_frame_length(kind); }

MessageKind kind_of(const Payload& payload) {
  struct Visitor {
    MessageKind operator()(const Hello&) const { return MessageKind::kHello; }
    MessageKind operator()(const HelloAck&) const { return MessageKind::kHelloAck; }
    MessageKind operator()(const Configure&) const { return MessageKind::kConfigure; }
    MessageKind operator()(const Fire&) const { return MessageKind::kFire; }
    MessageKind operator()(const Release&) const { return MessageKind::kRelease; }
    MessageKind operator()(const ReleaseAll&) const { return MessageKind::kReleaseAll; }
    MessageKind operator()(const Heartbeat&) const { return MessageKind::kHeartbeat; }
    MessageKind operator()(const Status&) const { return MessageKind::kStatus; }
    MessageKind operator()(const Fault&) const { return MessageKind::kFault; }
  };
  return std::visit(Visitor{}, payload);
}

const char* validate(const DriverConfig& c) {
  const pbfw_driver_config core = to_core(c);
  return pbfw_validate_config(&core);
}

CanFrame encode(std::uint8_t board, const Payload& payload) {
  const pbfw_message m = to_core(board, payload);
  pbfw_frame f;
  pbfw_encode(&m, &f);
  return from_core(f);
}

DecodeResult decode(const CanFrame& frame) {
  const pbfw_frame f = to_core(frame);
  pbfw_message m;
  DecodeResult r;
  r.error = static_cast<DecodeError>(pbfw_decode(&f, &m, &r.reason));
  if (r.ok()) r.message = from_core(m);
  return r;
}

const char* to_string(DecodeError e) {
  switch (e) {
    case DecodeError::kOk: return "ok";
    case DecodeError::kErrorFrame: return "error frame";
    case DecodeError::kForeignId: return "foreign id";
    case DecodeError::kUnknownKind: return "unknown kind";
    case DecodeError::kWrongLength: return "wrong length";
    case DecodeError::kBadChecksum: return "bad checksum";
    case DecodeError::kOutOfRange: return "out of range";
    case DecodeError::kWrongVersion: return "wrong version";
  }
  return "?";
}

const char* to_string(FaultCode code) {
  switch (code) {
    case FaultCode::kWatchdogExpired: return "watchdog expired";
    case FaultCode::kHoldCapReached: return "hold cap reached";
    case FaultCode::kPulseClamped: return "pulse clamped";
    case FaultCode::kBadFrame: return "bad frame";
    case FaultCode::kVersionMismatch: return "version mismatch";
    case FaultCode::kNotConfigured: return "not configured";
    case FaultCode::kNotArmed: return "not armed";
    case FaultCode::kStale: return "stale command";
    case FaultCode::kLocked: return "driver locked by its hold cap";
  }
  return "?";
}

}  // namespace pinball::firmware
