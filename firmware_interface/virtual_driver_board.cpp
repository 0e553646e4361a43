#include "pinball/firmware/virtual_driver_board.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core_bridge.h"

namespace pinball::firmware {
namespace {

constexpr double kNsPerS = 1e9;

BoardCounters from_core(const pbfw_board_counters& c) {
  BoardCounters out;
  out.frames = c.frames;
  out.bad_frames = c.bad_frames;
  out.bad_checksum = c.bad_checksum;
  out.version_mismatch = c.version_mismatch;
  out.foreign = c.foreign;
  out.hellos = c.hellos;
  out.fires_accepted = c.fires_accepted;
  out.refused_not_configured = c.refused_not_configured;
  out.refused_not_armed = c.refused_not_armed;
  out.refused_recycle = c.refused_recycle;
  out.refused_busy = c.refused_busy;
  out.refused_locked = c.refused_locked;
  out.stale = c.stale;
  out.pulse_clamps = c.pulse_clamps;
  out.hold_cap_trips = c.hold_cap_trips;
  out.watchdog_trips = c.watchdog_trips;
  out.tx_dropped = c.tx_dropped;
  return out;
}

pbfw_time_ns to_ns(double t_s) { return static_cast<pbfw_time_ns>(std::llround(t_s * kNsPerS)); }

}  // namespace

VirtualDriverBoard::VirtualDriverBoard(VirtualDriverBoardOptions options) : options_(options) {
  if (options.board_id >= kMaxBoards) throw std::invalid_argument("VirtualDriverBoard: board_id must be 0..15");
  if (options.driver_count < 1 || options.driver_count > kMaxDrivers) {
    throw std::invalid_argument("VirtualDriverBoard: driver_count must be 1..8, got " + std::to_string(options.driver_count));
  }
  if (!(options.status_period_s > 0.0) || !(options.status_period_s < 1e3)) {
    throw std::invalid_argument("VirtualDriverBoard: status_period_s must be in (0, 1000) s");
  }
  pbfw_board_options core{};
  core.board_id = options.board_id;
  core.driver_count = static_cast<std::uint8_t>(options.driver_count);
  core.status_period_ns = std::max<pbfw_time_ns>(1, to_ns(options.status_period_s));
  core.fw_major = options.fw_major;
  core.fw_minor = options.fw_minor;
  core.set_coil = &VirtualDriverBoard::on_core_coil;
  core.set_coil_context = this;
  if (pbfw_board_init(&core_, &core) != PBFW_INIT_OK) throw std::invalid_argument("VirtualDriverBoard: options refused by the core");
  sync_counters();
  sync_configs();
}

void VirtualDriverBoard::add_listener(CoilListener* listener) {
  if (listener == nullptr || listener_count_ >= kMaxListeners) {
    throw std::invalid_argument("VirtualDriverBoard: null listener or more than 4 listeners");
  }
  listeners_[static_cast<std::size_t>(listener_count_++)] = listener;
}

void VirtualDriverBoard::set_end_of_stroke(int d, bool closed) {
  if (d >= 0 && d < options_.driver_count) pbfw_board_set_end_of_stroke(&core_, static_cast<unsigned>(d), closed);
}

pbfw_time_ns VirtualDriverBoard::enter(double now_s) {
  if (!started_ || now_s > now_s_) {
    started_ = true;
    now_s_ = now_s;
    now_us_ = std::max(now_us_, to_ns(now_s));
  }
  return now_us_;
}

void VirtualDriverBoard::on_core_coil(void* self, unsigned driver, pbfw_coil_state state, std::uint8_t duty_pct,
                                      pbfw_time_ns at_ns) {
  auto* board = static_cast<VirtualDriverBoard*>(self);
  // A change at the call's own nanosecond happened at the caller's time; a
  // timer's, at its deadline, which rounding may put past the caller's time.
  const double at_s = at_ns >= board->now_us_ ? board->now_s_ : std::min(at_ns / kNsPerS, board->now_s_);
  CoilOutput& out = board->outputs_[driver];
  out = CoilOutput{static_cast<CoilState>(state), duty_pct / 100.0, at_s};
  for (int i = 0; i < board->listener_count_; ++i) {
    board->listeners_[static_cast<std::size_t>(i)]->on_coil_change(static_cast<int>(driver), out);
  }
}

void VirtualDriverBoard::sync_counters() { counters_ = from_core(core_.counters); }

void VirtualDriverBoard::sync_configs() {
  for (int d = 0; d < kMaxDrivers; ++d) configs_[static_cast<std::size_t>(d)] = from_core(core_.drivers[d].config);
}

void VirtualDriverBoard::advance(double now_s) {
  pbfw_board_advance(&core_, enter(now_s));
  sync_counters();  // timers change no configuration
}

void VirtualDriverBoard::on_frame(const CanFrame& frame, double now_s) {
  const pbfw_frame f = to_core(frame);
  pbfw_board_on_frame(&core_, &f, enter(now_s));
  sync_counters();
  sync_configs();
}

bool VirtualDriverBoard::pop_tx(CanFrame& frame) {
  pbfw_frame f;
  if (!pbfw_board_pop_tx(&core_, &f)) return false;
  frame = from_core(f);
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

Status VirtualDriverBoard::status() const {
  const pbfw_status s = pbfw_board_status(&core_);
  return Status{s.coil_states, s.end_of_stroke, s.configured, s.faults, s.last_seq};
}

}  // namespace pinball::firmware
