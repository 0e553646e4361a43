#include "core_bridge.h"

#include <algorithm>

namespace pinball::firmware {

pbfw_frame to_core(const CanFrame& frame) {
  pbfw_frame f{};
  f.id = frame.id;
  f.len = frame.len;
  f.error = frame.error;
  std::copy(frame.data.begin(), frame.data.end(), f.data);
  return f;
}

CanFrame from_core(const pbfw_frame& frame) {
  CanFrame f;
  f.id = frame.id;
  f.len = frame.len;
  f.error = frame.error;
  std::copy(frame.data, frame.data + PBFW_MAX_FRAME_BYTES, f.data.begin());
  return f;
}

pbfw_driver_config to_core(const DriverConfig& c) {
  return pbfw_driver_config{c.pulse_ms, c.hold_duty_pct, c.max_pulse_ms, c.max_hold_ms, c.recycle_ms};
}

DriverConfig from_core(const pbfw_driver_config& c) {
  return DriverConfig{c.pulse_ms, c.hold_duty_pct, c.max_pulse_ms, c.max_hold_ms, c.recycle_ms};
}

pbfw_message to_core(std::uint8_t board, const Payload& payload) {
  pbfw_message m{};
  m.board = board;
  m.kind = static_cast<pbfw_kind>(kind_of(payload));
  struct Visitor {
    pbfw_message& m;
    void operator()(const Hello& h) const { m.u.hello = {h.version, h.watchdog_ms}; }
    void operator()(const HelloAck& a) const { m.u.hello_ack = {a.version, a.driver_count, a.fw_major, a.fw_minor}; }
    void operator()(const Configure& c) const { m.u.configure = {c.driver, to_core(c.config)}; }
    void operator()(const Fire& f) const {
      m.u.fire = {f.driver, static_cast<std::uint8_t>(f.mode), f.pulse_ms, f.seq};
    }
    void operator()(const Release& r) const { m.u.release = {r.driver, r.seq}; }
    void operator()(const ReleaseAll& r) const { m.u.release_all = {r.seq}; }
    void operator()(const Heartbeat& h) const { m.u.heartbeat = {h.version, h.seq}; }
    void operator()(const Status& s) const {
      m.u.status = {s.coil_states, s.end_of_stroke, s.configured, s.faults, s.last_seq};
    }
    void operator()(const Fault& f) const {
      m.u.fault = {static_cast<std::uint8_t>(f.code), f.driver, f.detail, f.count};
    }
  };
  std::visit(Visitor{m}, payload);
  return m;
}

Message from_core(const pbfw_message& m) {
  Message out;
  out.board = m.board;
  switch (m.kind) {
    case PBFW_HELLO: out.payload = Hello{m.u.hello.version, m.u.hello.watchdog_ms}; break;
    case PBFW_HELLO_ACK:
      out.payload = HelloAck{m.u.hello_ack.version, m.u.hello_ack.driver_count, m.u.hello_ack.fw_major,
                             m.u.hello_ack.fw_minor};
      break;
    case PBFW_CONFIGURE: out.payload = Configure{m.u.configure.driver, from_core(m.u.configure.config)}; break;
    case PBFW_FIRE:
      out.payload = Fire{m.u.fire.driver, static_cast<FireMode>(m.u.fire.mode), m.u.fire.pulse_ms, m.u.fire.seq};
      break;
    case PBFW_RELEASE: out.payload = Release{m.u.release.driver, m.u.release.seq}; break;
    case PBFW_RELEASE_ALL: out.payload = ReleaseAll{m.u.release_all.seq}; break;
    case PBFW_HEARTBEAT: out.payload = Heartbeat{m.u.heartbeat.version, m.u.heartbeat.seq}; break;
    case PBFW_STATUS:
      out.payload = Status{m.u.status.coil_states, m.u.status.end_of_stroke, m.u.status.configured, m.u.status.faults,
                           m.u.status.last_seq};
      break;
    case PBFW_FAULT:
      out.payload = Fault{static_cast<FaultCode>(m.u.fault.code), m.u.fault.driver, m.u.fault.detail, m.u.fault.count};
      break;
  }
  return out;
}

}  // namespace pinball::firmware
