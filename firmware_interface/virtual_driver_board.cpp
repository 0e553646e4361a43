#include "pinball/firmware/virtual_driver_board.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace pinball::firmware {
namespace {

constexpr double kMs = 1e-3;

}  // namespace

VirtualDriverBoard::VirtualDriverBoard(VirtualDriverBoardOptions options) : options_(options) {
  if (options.board_id >= kMaxBoards) throw std::invalid_argument("VirtualDriverBoard: board_id must be 0..15");
  if (options.driver_count < 1 || options.driver_count > kMaxDrivers) {
    throw std::invalid_argument("VirtualDriverBoard: driver_count must be 1..8, got " + std::to_string(options.driver_count));
  }
  if (!(options.status_period_s > 0.0)) throw std::invalid_argument("VirtualDriverBoard: status_period_s must be > 0");
}

void VirtualDriverBoard::add_listener(CoilListener* listener) {
  if (listener == nullptr || listener_count_ >= kMaxListeners) {
    throw std::invalid_argument("VirtualDriverBoard: null listener or more than 4 listeners");
  }
  listeners_[static_cast<std::size_t>(listener_count_++)] = listener;
}

void VirtualDriverBoard::set_end_of_stroke(int d, bool closed) {
  if (d >= 0 && d < options_.driver_count) drivers_[static_cast<std::size_t>(d)].eos = closed;
}

void VirtualDriverBoard::set_output(int d, CoilState state, double duty, double t_s) {
  Driver& drv = drivers_[static_cast<std::size_t>(d)];
  drv.out = CoilOutput{state, duty, t_s};
  if (state == CoilState::kOff) drv.off_since_s = t_s;
  for (int i = 0; i < listener_count_; ++i) listeners_[static_cast<std::size_t>(i)]->on_coil_change(d, drv.out);
}

void VirtualDriverBoard::all_off(double t_s) {
  for (int d = 0; d < options_.driver_count; ++d) {
    if (drivers_[static_cast<std::size_t>(d)].out.state != CoilState::kOff) set_output(d, CoilState::kOff, 0.0, t_s);
  }
}

void VirtualDriverBoard::push_tx(const Payload& p) {
  if (out_count_ >= kOutboxSize) {
    ++counters_.tx_dropped;
    return;
  }
  outbox_[static_cast<std::size_t>((out_head_ + out_count_) % kOutboxSize)] = encode(options_.board_id, p);
  ++out_count_;
}

bool VirtualDriverBoard::pop_tx(CanFrame& frame) {
  if (out_count_ == 0) return false;
  frame = outbox_[static_cast<std::size_t>(out_head_)];
  out_head_ = (out_head_ + 1) % kOutboxSize;
  --out_count_;
  return true;
}

int VirtualDriverBoard::flush(CanTransport& link) {
  int sent = 0;
  CanFrame f;
  while (pop_tx(f)) {
    if (link.send(f) == TxStatus::kOk) ++sent;
  }
  return sent;
}

int VirtualDriverBoard::service(CanTransport& link, double now_s) {
  int handled = 0;
  CanFrame f;
  while (link.receive(f, 0) == RxStatus::kFrame) {
    on_frame(f, now_s);
    ++handled;
  }
  advance(now_s);
  flush(link);
  return handled;
}

void VirtualDriverBoard::fault(FaultCode code, std::uint8_t driver, std::uint16_t detail, std::uint8_t bit) {
  fault_bits_ |= bit;
  ++fault_count_;
  push_tx(Fault{code, driver, detail, fault_count_});
}

Status VirtualDriverBoard::status() const {
  Status s;
  for (int d = 0; d < options_.driver_count; ++d) {
    const Driver& drv = drivers_[static_cast<std::size_t>(d)];
    s.coil_states |= static_cast<std::uint16_t>(static_cast<unsigned>(drv.out.state) << (2 * d));
    if (drv.eos) s.end_of_stroke |= static_cast<std::uint8_t>(1u << d);
    if (drv.configured) s.configured |= static_cast<std::uint8_t>(1u << d);
  }
  s.faults = static_cast<std::uint8_t>(fault_bits_ | (armed_ ? kFaultBitArmed : 0));
  s.last_seq = last_seq_;
  return s;
}

void VirtualDriverBoard::advance(double now_s) {
  if (!started_) {
    started_ = true;
    now_s_ = now_s;
    next_status_s_ = now_s;
  }
  now_s = std::max(now_s, now_s_);
  // Apply every timer that expired up to now, earliest first, each at its own time.
  for (;;) {
    double t = now_s;
    int which = -2;  // -1: watchdog, >= 0: driver
    if (armed_ && last_heartbeat_s_ + watchdog_s_ <= t) {
      t = last_heartbeat_s_ + watchdog_s_;
      which = -1;
    }
    for (int d = 0; d < options_.driver_count; ++d) {
      const Driver& drv = drivers_[static_cast<std::size_t>(d)];
      const double end = drv.out.state == CoilState::kPulse ? drv.pulse_end_s
                         : drv.out.state == CoilState::kHold ? drv.hold_end_s
                                                             : now_s + 1.0;
      if (end < t || (end <= t && which == -2)) {
        t = end;
        which = d;
      }
    }
    if (which == -2) break;
    if (which == -1) {
      armed_ = false;
      ++counters_.watchdog_trips;
      all_off(t);
      fault(FaultCode::kWatchdogExpired, kBoardDriver, static_cast<std::uint16_t>(watchdog_s_ / kMs + 0.5), kFaultBitWatchdog);
      continue;
    }
    Driver& drv = drivers_[static_cast<std::size_t>(which)];
    if (drv.out.state == CoilState::kPulse) {
      const double duty = std::min<double>(drv.config.hold_duty_pct, kAbsMaxHoldDutyPct) / 100.0;
      if (drv.hold_after_pulse && duty > 0.0) {
        drv.hold_end_s = t + std::min<double>(drv.config.max_hold_ms, kAbsMaxHoldMs) * kMs;
        set_output(which, CoilState::kHold, duty, t);
      } else {
        set_output(which, CoilState::kOff, 0.0, t);
      }
    } else {
      ++counters_.hold_cap_trips;
      drv.locked = true;
      set_output(which, CoilState::kOff, 0.0, t);
      fault(FaultCode::kHoldCapReached, static_cast<std::uint8_t>(which), drv.config.max_hold_ms, kFaultBitHoldCap);
    }
  }
  now_s_ = now_s;
  if (now_s >= next_status_s_) {
    push_tx(status());
    fault_bits_ = 0;
    next_status_s_ += options_.status_period_s;
    if (next_status_s_ <= now_s) next_status_s_ = now_s + options_.status_period_s;
  }
}

void VirtualDriverBoard::on_frame(const CanFrame& frame, double now_s) {
  advance(now_s);
  now_s = now_s_;
  ++counters_.frames;
  const DecodeResult r = decode(frame);
  if (!r.ok()) {
    if (r.error == DecodeError::kErrorFrame || r.error == DecodeError::kForeignId) {
      ++counters_.foreign;
      return;
    }
    ++counters_.bad_frames;
    if (r.error == DecodeError::kBadChecksum) ++counters_.bad_checksum;
    if ((frame.id & 0x0Fu) != options_.board_id) return;  // someone else's garbage
    if (r.error == DecodeError::kWrongVersion) {
      ++counters_.version_mismatch;
      fault(FaultCode::kVersionMismatch, kBoardDriver, frame.data[0], kFaultBitVersion);
    } else {
      fault(FaultCode::kBadFrame, kBoardDriver, static_cast<std::uint16_t>(r.error), kFaultBitBadFrame);
    }
    return;
  }
  if (r.message.board != options_.board_id) {
    ++counters_.foreign;
    return;
  }
  handle(r.message, now_s);
}

void VirtualDriverBoard::handle(const Message& m, double now_s) {
  const MessageKind kind = kind_of(m.payload);
  switch (kind) {
    case MessageKind::kHello:
      on_hello(std::get<Hello>(m.payload), now_s);
      return;
    case MessageKind::kRelease: {
      const auto& r = std::get<Release>(m.payload);
      if (r.driver < options_.driver_count) on_release(r.driver, r.seq, now_s);
      note_seq(r.seq);
      return;
    }
    case MessageKind::kReleaseAll: {
      const auto& r = std::get<ReleaseAll>(m.payload);
      for (int d = 0; d < options_.driver_count; ++d) on_release(d, r.seq, now_s);
      note_seq(r.seq);
      return;
    }
    case MessageKind::kHeartbeat:
    case MessageKind::kConfigure:
    case MessageKind::kFire:
      if (!session_) {
        ++counters_.refused_not_configured;
        fault(FaultCode::kNotConfigured, kBoardDriver, static_cast<std::uint16_t>(kind), kFaultBitRefused);
        return;
      }
      if (kind == MessageKind::kHeartbeat) on_heartbeat(std::get<Heartbeat>(m.payload), now_s);
      if (kind == MessageKind::kConfigure) on_configure(std::get<Configure>(m.payload), now_s);
      if (kind == MessageKind::kFire) on_fire(std::get<Fire>(m.payload), now_s);
      return;
    default:
      ++counters_.foreign;  // a board -> host message: not for us
      return;
  }
}

void VirtualDriverBoard::on_hello(const Hello& m, double now_s) {
  ++counters_.hellos;
  all_off(now_s);
  // A hold-cap lock survives the new session: only Release or ReleaseAll
  // acknowledge it (rule 6).
  for (Driver& d : drivers_) {
    d.configured = false;
    d.has_seq = false;
  }
  session_ = true;
  armed_ = false;
  watchdog_s_ = m.watchdog_ms * kMs;
  has_hb_seq_ = false;
  has_seq_ = false;
  last_seq_ = 0;
  fault_count_ = 0;
  push_tx(HelloAck{kProtocolVersion, static_cast<std::uint8_t>(options_.driver_count), options_.fw_major,
                   options_.fw_minor});
  push_tx(status());
}

void VirtualDriverBoard::on_configure(const Configure& m, double now_s) {
  if (m.driver >= options_.driver_count) {
    ++counters_.refused_not_configured;
    fault(FaultCode::kNotConfigured, m.driver, static_cast<std::uint16_t>(MessageKind::kConfigure), kFaultBitRefused);
    return;
  }
  Driver& drv = drivers_[m.driver];
  if (drv.out.state != CoilState::kOff) set_output(m.driver, CoilState::kOff, 0.0, now_s);
  drv.config = m.config;
  drv.configured = true;  // a hold-cap lock stays: only Release or ReleaseAll clear it (rule 6)
  push_tx(status());
}

void VirtualDriverBoard::on_fire(const Fire& m, double now_s) {
  if (m.driver >= options_.driver_count || !drivers_[m.driver].configured) {
    ++counters_.refused_not_configured;
    fault(FaultCode::kNotConfigured, m.driver, static_cast<std::uint16_t>(MessageKind::kFire), kFaultBitRefused);
    return;
  }
  Driver& drv = drivers_[m.driver];
  if (drv.has_seq && !seq_newer(m.seq, drv.last_seq)) {
    ++counters_.stale;  // a duplicate or an old frame overtaken by a newer command
    fault(FaultCode::kStale, m.driver, m.seq, kFaultBitRefused);
    return;
  }
  drv.has_seq = true;
  drv.last_seq = m.seq;
  note_seq(m.seq);
  if (!armed_) {
    ++counters_.refused_not_armed;
    fault(FaultCode::kNotArmed, m.driver, 0, kFaultBitRefused);
    return;
  }
  if (drv.locked) {
    ++counters_.refused_locked;
    fault(FaultCode::kLocked, m.driver, 0, kFaultBitRefused);
    return;
  }
  if (drv.out.state != CoilState::kOff) {
    ++counters_.refused_busy;  // never restart a pulse on an energised coil
    return;
  }
  if (now_s < drv.off_since_s + drv.config.recycle_ms * kMs) {
    ++counters_.refused_recycle;
    return;
  }
  const std::uint8_t wanted = m.pulse_ms != 0 ? m.pulse_ms : drv.config.pulse_ms;
  const std::uint8_t cap = std::min(drv.config.max_pulse_ms, kAbsMaxPulseMs);
  std::uint8_t pulse = wanted;
  if (wanted > cap) {
    pulse = cap;
    ++counters_.pulse_clamps;
    fault(FaultCode::kPulseClamped, m.driver, wanted, kFaultBitPulseClamp);
  }
  ++counters_.fires_accepted;
  drv.hold_after_pulse = m.mode == FireMode::kPulseHold;
  drv.pulse_end_s = now_s + pulse * kMs;
  set_output(m.driver, CoilState::kPulse, 1.0, now_s);
}

void VirtualDriverBoard::on_release(int d, std::uint16_t seq, double now_s) {
  // Switching off is always safe: obeyed whatever the sequence number or session.
  Driver& drv = drivers_[static_cast<std::size_t>(d)];
  if (!drv.has_seq || seq_newer(seq, drv.last_seq)) {
    drv.has_seq = true;
    drv.last_seq = seq;
  }
  drv.locked = false;
  if (drv.out.state != CoilState::kOff) set_output(d, CoilState::kOff, 0.0, now_s);
}

void VirtualDriverBoard::on_heartbeat(const Heartbeat& m, double now_s) {
  if (has_hb_seq_ && !seq_newer(m.seq, hb_seq_)) {
    ++counters_.stale;
    return;
  }
  has_hb_seq_ = true;
  hb_seq_ = m.seq;
  last_heartbeat_s_ = now_s;
  armed_ = true;
  note_seq(m.seq);
}

void VirtualDriverBoard::note_seq(std::uint16_t seq) {
  if (has_seq_ && !seq_newer(seq, last_seq_)) return;
  has_seq_ = true;
  last_seq_ = seq;
  // Rule 9: a driver's reference never trails the session's newest number by
  // more than kSeqReferenceLag. Without this, 2^15 idle heartbeats (11 min at
  // 20 ms) would make the driver's next Fire look older than its last one.
  const auto floor = static_cast<std::uint16_t>(seq - kSeqReferenceLag);
  for (int d = 0; d < options_.driver_count; ++d) {
    Driver& drv = drivers_[static_cast<std::size_t>(d)];
    if (drv.has_seq && seq_newer(floor, drv.last_seq)) drv.last_seq = floor;
  }
}

}  // namespace pinball::firmware
