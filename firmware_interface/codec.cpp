#include "pinball/firmware/codec.h"

#include <cstring>
#include <type_traits>

namespace pinball::firmware {
namespace {

constexpr std::uint8_t kind_byte(MessageKind k) { return static_cast<std::uint8_t>(k); }

// Copies a wire struct into a frame and seals it with the CRC (its last byte).
template <typename Wire>
CanFrame seal(std::uint32_t id, Wire wire) {
  static_assert(std::is_trivially_copyable_v<Wire> && sizeof(Wire) <= kMaxFrameBytes);
  CanFrame f;
  f.id = id;
  f.len = sizeof(Wire);
  std::memcpy(f.data.data(), &wire, sizeof(Wire));
  f.data[sizeof(Wire) - 1] = frame_crc(id, std::span<const std::uint8_t>(f.data.data(), sizeof(Wire) - 1));
  return f;
}

template <typename Wire>
Wire unpack(const CanFrame& f) {
  Wire w;
  std::memcpy(&w, f.data.data(), sizeof(Wire));
  return w;
}

DecodeResult fail(DecodeError e, const char* reason) {
  DecodeResult r;
  r.error = e;
  r.reason = reason;
  return r;
}

DecodeResult success(std::uint8_t board, Payload p) {
  DecodeResult r;
  r.message.board = board;
  r.message.payload = p;
  return r;
}

}  // namespace

std::uint8_t frame_crc(std::uint32_t id, std::span<const std::uint8_t> bytes) {
  std::uint8_t crc = 0xFF;
  auto feed = [&crc](std::uint8_t b) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) crc = (crc & 0x80) ? static_cast<std::uint8_t>((crc << 1) ^ 0x2F) : static_cast<std::uint8_t>(crc << 1);
  };
  feed(static_cast<std::uint8_t>(id & 0xFF));
  feed(static_cast<std::uint8_t>((id >> 8) & 0x07));
  for (std::uint8_t b : bytes) feed(b);
  return static_cast<std::uint8_t>(crc ^ 0xFF);
}

int frame_length(std::uint8_t kind) {
  switch (static_cast<MessageKind>(kind)) {
    case MessageKind::kReleaseAll: return sizeof(ReleaseAllWire);
    case MessageKind::kRelease: return sizeof(ReleaseWire);
    case MessageKind::kFire: return sizeof(FireWire);
    case MessageKind::kHeartbeat: return sizeof(HeartbeatWire);
    case MessageKind::kConfigure: return sizeof(ConfigureWire);
    case MessageKind::kHello: return sizeof(HelloWire);
    case MessageKind::kFault: return sizeof(FaultWire);
    case MessageKind::kStatus: return sizeof(StatusWire);
    case MessageKind::kHelloAck: return sizeof(HelloAckWire);
  }
  return -1;
}

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
  if (c.max_pulse_ms < 1 || c.max_pulse_ms > kAbsMaxPulseMs) return "max_pulse_ms outside 1..kAbsMaxPulseMs (100)";
  if (c.pulse_ms < 1 || c.pulse_ms > c.max_pulse_ms) return "pulse_ms outside 1..max_pulse_ms";
  if (c.hold_duty_pct > kAbsMaxHoldDutyPct) return "hold_duty_pct above kAbsMaxHoldDutyPct (50)";
  if (c.max_hold_ms < 1 || c.max_hold_ms > kAbsMaxHoldMs) return "max_hold_ms outside 1..kAbsMaxHoldMs (10000)";
  return nullptr;
}

CanFrame encode(std::uint8_t board, const Payload& payload) {
  const std::uint32_t id = make_id(kind_of(payload), board);
  struct Visitor {
    std::uint32_t id;
    CanFrame operator()(const Hello& m) const { return seal(id, HelloWire{m.version, Le16::of(m.watchdog_ms), 0}); }
    CanFrame operator()(const HelloAck& m) const {
      return seal(id, HelloAckWire{m.version, m.driver_count, m.fw_major, m.fw_minor, 0});
    }
    CanFrame operator()(const Configure& m) const {
      const DriverConfig& c = m.config;
      return seal(id, ConfigureWire{m.driver, c.pulse_ms, c.hold_duty_pct, c.max_pulse_ms, c.recycle_ms,
                                    Le16::of(c.max_hold_ms), 0});
    }
    CanFrame operator()(const Fire& m) const {
      return seal(id, FireWire{m.driver, static_cast<std::uint8_t>(m.mode), m.pulse_ms, Le16::of(m.seq), 0});
    }
    CanFrame operator()(const Release& m) const { return seal(id, ReleaseWire{m.driver, Le16::of(m.seq), 0}); }
    CanFrame operator()(const ReleaseAll& m) const { return seal(id, ReleaseAllWire{Le16::of(m.seq), 0}); }
    CanFrame operator()(const Heartbeat& m) const { return seal(id, HeartbeatWire{m.version, Le16::of(m.seq), 0}); }
    CanFrame operator()(const Status& m) const {
      return seal(id, StatusWire{Le16::of(m.coil_states), m.end_of_stroke, m.configured, m.faults,
                                 Le16::of(m.last_seq), 0});
    }
    CanFrame operator()(const Fault& m) const {
      return seal(id, FaultWire{static_cast<std::uint8_t>(m.code), m.driver, Le16::of(m.detail), Le16::of(m.count), 0});
    }
  };
  return std::visit(Visitor{id}, payload);
}

DecodeResult decode(const CanFrame& f) {
  if (f.error) return fail(DecodeError::kErrorFrame, "controller error frame");
  if (f.id > 0x7FF || (f.id & kIdMask) != kIdBase) return fail(DecodeError::kForeignId, "id outside 0x100..0x1FF");
  const std::uint8_t kind = static_cast<std::uint8_t>((f.id >> 4) & 0x0F);
  const std::uint8_t board = static_cast<std::uint8_t>(f.id & 0x0F);
  const int expected = frame_length(kind);
  if (expected < 0) return fail(DecodeError::kUnknownKind, "unknown message kind");
  if (f.len != expected) return fail(DecodeError::kWrongLength, "length differs from the kind's length");
  if (frame_crc(f.id, std::span<const std::uint8_t>(f.data.data(), f.len - 1u)) != f.data[f.len - 1u]) {
    return fail(DecodeError::kBadChecksum, "CRC-8 mismatch");
  }
  switch (static_cast<MessageKind>(kind)) {
    case MessageKind::kHello: {
      const auto w = unpack<HelloWire>(f);
      if (w.version != kProtocolVersion) return fail(DecodeError::kWrongVersion, "Hello: protocol version differs");
      const std::uint16_t wd = w.watchdog_ms.get();
      if (wd < kMinWatchdogMs || wd > kMaxWatchdogMs) return fail(DecodeError::kOutOfRange, "Hello: watchdog_ms outside 10..1000");
      return success(board, Hello{w.version, wd});
    }
    case MessageKind::kHelloAck: {
      const auto w = unpack<HelloAckWire>(f);
      if (w.version != kProtocolVersion) return fail(DecodeError::kWrongVersion, "HelloAck: protocol version differs");
      if (w.driver_count < 1 || w.driver_count > kMaxDrivers) return fail(DecodeError::kOutOfRange, "HelloAck: driver_count outside 1..8");
      return success(board, HelloAck{w.version, w.driver_count, w.fw_major, w.fw_minor});
    }
    case MessageKind::kConfigure: {
      const auto w = unpack<ConfigureWire>(f);
      if (w.driver >= kMaxDrivers) return fail(DecodeError::kOutOfRange, "Configure: driver >= 8");
      const DriverConfig c{w.pulse_ms, w.hold_duty_pct, w.max_pulse_ms, w.max_hold_ms.get(), w.recycle_ms};
      if (validate(c) != nullptr) return fail(DecodeError::kOutOfRange, "Configure: timing or cap out of range");
      return success(board, Configure{w.driver, c});
    }
    case MessageKind::kFire: {
      const auto w = unpack<FireWire>(f);
      if (w.driver >= kMaxDrivers) return fail(DecodeError::kOutOfRange, "Fire: driver >= 8");
      if (w.mode > 1) return fail(DecodeError::kOutOfRange, "Fire: mode not 0 or 1");
      if (w.pulse_ms > kAbsMaxPulseMs) return fail(DecodeError::kOutOfRange, "Fire: pulse_ms above 100");
      return success(board, Fire{w.driver, static_cast<FireMode>(w.mode), w.pulse_ms, w.seq.get()});
    }
    case MessageKind::kRelease: {
      const auto w = unpack<ReleaseWire>(f);
      if (w.driver >= kMaxDrivers) return fail(DecodeError::kOutOfRange, "Release: driver >= 8");
      return success(board, Release{w.driver, w.seq.get()});
    }
    case MessageKind::kReleaseAll: {
      const auto w = unpack<ReleaseAllWire>(f);
      return success(board, ReleaseAll{w.seq.get()});
    }
    case MessageKind::kHeartbeat: {
      const auto w = unpack<HeartbeatWire>(f);
      if (w.version != kProtocolVersion) return fail(DecodeError::kWrongVersion, "Heartbeat: protocol version differs");
      return success(board, Heartbeat{w.version, w.seq.get()});
    }
    case MessageKind::kStatus: {
      const auto w = unpack<StatusWire>(f);
      const std::uint16_t states = w.coil_states.get();
      for (int d = 0; d < kMaxDrivers; ++d) {
        if (((states >> (2 * d)) & 3u) == 3u) return fail(DecodeError::kOutOfRange, "Status: coil state 3 is undefined");
      }
      if (w.faults & 0x40u) return fail(DecodeError::kOutOfRange, "Status: reserved fault bit 6 set");
      return success(board, Status{states, w.end_of_stroke, w.configured, w.faults, w.last_seq.get()});
    }
    case MessageKind::kFault: {
      const auto w = unpack<FaultWire>(f);
      if (w.code < 1 || w.code > kMaxFaultCode) return fail(DecodeError::kOutOfRange, "Fault: unknown fault code");
      if (w.driver >= kMaxDrivers && w.driver != kBoardDriver) return fail(DecodeError::kOutOfRange, "Fault: driver neither 0..7 nor 0xFF");
      return success(board, Fault{static_cast<FaultCode>(w.code), w.driver, w.detail.get(), w.count.get()});
    }
  }
  return fail(DecodeError::kUnknownKind, "unknown message kind");
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
