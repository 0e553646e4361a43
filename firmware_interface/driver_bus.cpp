#include "pinball/firmware/driver_bus.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "pinball/core/check.h"
#include "pinball/core/clock.h"
#include "pinball/firmware/frame_log.h"

namespace pinball::firmware {

namespace {
constexpr int kCounterCount = sizeof(DriverBusCounters) / sizeof(std::uint64_t);
static_assert(sizeof(DriverBusCounters) == kCounterCount * sizeof(std::uint64_t), "DriverBusCounters: uint64 fields only");

}  // namespace

struct DriverBus::AtomicCounters {
  std::array<std::atomic<std::uint64_t>, kCounterCount> v{};
};

void DriverBus::bump(std::uint64_t DriverBusCounters::*field, std::uint64_t n) {
  static const DriverBusCounters probe{};
  const auto index = static_cast<std::size_t>(reinterpret_cast<const char*>(&(probe.*field)) -
                                              reinterpret_cast<const char*>(&probe)) / sizeof(std::uint64_t);
  counters_->v[index].fetch_add(n, std::memory_order_relaxed);
}

DriverBusCounters DriverBus::counters() const {
  std::array<std::uint64_t, kCounterCount> raw{};
  for (int i = 0; i < kCounterCount; ++i) raw[static_cast<std::size_t>(i)] = counters_->v[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);
  DriverBusCounters c;
  std::memcpy(static_cast<void*>(&c), raw.data(), sizeof c);
  return c;
}

DriverBus::DriverBus(CanTransport& transport, DriverBusOptions options)
    : transport_(transport), options_(options), counters_(std::make_unique<AtomicCounters>()) {
  check_input(options.board_id < kMaxBoards, "DriverBusOptions", "board_id must be 0..15");
  check_input(options.driver_count >= 1 && options.driver_count <= kMaxDrivers, "DriverBusOptions", "driver_count must be 1..8");
  for (int d = 0; d < options.driver_count; ++d) {
    const char* why = validate(options.drivers[static_cast<std::size_t>(d)]);
    check_input(why == nullptr, "DriverBusOptions", "drivers[" + std::to_string(d) + "]: " + (why ? why : ""));
  }
  check_input(std::isfinite(options.heartbeat_period_s) && options.heartbeat_period_s > 0.0, "DriverBusOptions", "heartbeat_period_s must be > 0");
  const double wd_ms = options.watchdog_timeout_s * 1e3;
  check_input(wd_ms >= kMinWatchdogMs && wd_ms <= kMaxWatchdogMs, "DriverBusOptions", "watchdog_timeout_s must be 0.01..1 s");
  check_input(options.watchdog_timeout_s >= 3.0 * options.heartbeat_period_s, "DriverBusOptions",
          "watchdog_timeout_s must be at least 3 heartbeat periods (one lost heartbeat must not trip it)");
  check_input(options.reply_timeout_s > 0.0, "DriverBusOptions", "reply_timeout_s must be > 0");
  check_input(options.status_timeout_s > 0.0, "DriverBusOptions", "status_timeout_s must be > 0");
  check_input(options.bus_off_holdoff_s >= 0.0, "DriverBusOptions", "bus_off_holdoff_s must be >= 0");
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
}

DriverBus::~DriverBus() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void DriverBus::start() {
  if (thread_.joinable()) throw std::logic_error("DriverBus::start: already running");
  running_.store(true);
  hang_.store(false);
  thread_ = std::thread([this] { run(); });
}

void DriverBus::stop() {
  if (!thread_.joinable()) return;
  running_.store(false);
  wake();
  thread_.join();
  if (!hang_.load()) {
    const std::lock_guard<std::mutex> lock(io_mutex_);
    make_safe(steady_now_s());
    set_state(BusState::kStopped);
  }
}

void DriverBus::simulate_hang() {
  hang_.store(true);
  running_.store(false);
  wake();
  if (thread_.joinable()) thread_.join();
}

void DriverBus::wake() {
  if (wake_fd_ < 0) return;
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);  // non-blocking; a full counter already means "wake"
}

bool DriverBus::push(Op op, int flipper) {
  if (flipper < 0 || flipper >= options_.driver_count) return false;
  const std::uint32_t tail = tail_.load(std::memory_order_relaxed);
  const std::uint32_t head = head_.load(std::memory_order_acquire);
  if (tail - head >= static_cast<std::uint32_t>(kQueueSize)) {
    bump(&DriverBusCounters::queue_full);
    return false;
  }
  queue_[tail % kQueueSize] = Command{op, static_cast<std::uint8_t>(flipper)};
  tail_.store(tail + 1, std::memory_order_release);
  wake();
  return true;
}

bool DriverBus::fire(int flipper) {
  const bool ok = push(Op::kFire, flipper);
  if (ok) bump(&DriverBusCounters::fires);
  return ok;
}

bool DriverBus::release(int flipper) {
  const bool ok = push(Op::kRelease, flipper);
  if (ok) bump(&DriverBusCounters::releases);
  return ok;
}

void DriverBus::release_all() {
  bump(&DriverBusCounters::release_alls);
  release_all_pending_.store(true, std::memory_order_release);
  wake();
}

BoardView DriverBus::board() const {
  const std::uint64_t w = status_word_.load(std::memory_order_acquire);
  BoardView v;
  v.valid = (w >> 63) != 0;
  v.status.coil_states = static_cast<std::uint16_t>(w);
  v.status.end_of_stroke = static_cast<std::uint8_t>(w >> 16);
  v.status.configured = static_cast<std::uint8_t>(w >> 24);
  v.status.faults = static_cast<std::uint8_t>(w >> 32);
  v.status.last_seq = static_cast<std::uint16_t>(w >> 40);
  return v;
}

bool DriverBus::send(const Payload& p, double now_s) {
  const CanFrame frame = encode(options_.board_id, p);
  const TxStatus s = transport_.send(frame);
  if (options_.log != nullptr) options_.log->record(frame);
  if (s == TxStatus::kOk) {
    bump(&DriverBusCounters::frames_sent);
    return true;
  }
  bump(&DriverBusCounters::tx_failures);
  if (s == TxStatus::kDown) {
    bump(&DriverBusCounters::bus_off);
    set_state(BusState::kBusOff);
    bus_off_s_ = now_s;
    return false;
  }
  // Safe first: whatever failed, try to switch every coil off (once).
  if (!std::holds_alternative<ReleaseAll>(p)) {
    const CanFrame off = encode(options_.board_id, ReleaseAll{++seq_});
    if (transport_.send(off) == TxStatus::kOk) {
      bump(&DriverBusCounters::frames_sent);
    } else {
      bump(&DriverBusCounters::tx_failures);
      release_all_pending_.store(true, std::memory_order_release);  // try again next iteration
    }
  }
  return false;
}

void DriverBus::make_safe(double now_s) {
  if (state() == BusState::kBusOff) return;  // nothing reaches the bus; the board's watchdog acts
  send(ReleaseAll{++seq_}, now_s);
}

void DriverBus::begin_session(double now_s) {
  set_state(BusState::kHandshake);
  status_word_.store(0, std::memory_order_release);
  last_request_s_ = now_s;
  last_status_s_ = now_s;
  bump(&DriverBusCounters::hellos);
  send(Hello{kProtocolVersion, static_cast<std::uint16_t>(std::lround(options_.watchdog_timeout_s * 1e3))}, now_s);
}

void DriverBus::on_error_frame(const CanFrame& f, double now_s) {
  bump(&DriverBusCounters::error_frames);
  if (is_bus_off(f) && state() != BusState::kBusOff) {
    bump(&DriverBusCounters::bus_off);
    set_state(BusState::kBusOff);
    bus_off_s_ = now_s;
  }
}

void DriverBus::on_message(const Message& m, double now_s) {
  if (m.board != options_.board_id) return;
  if (const auto* ack = std::get_if<HelloAck>(&m.payload)) {
    if (state() != BusState::kHandshake) return;
    if (ack->driver_count < options_.driver_count) {
      bump(&DriverBusCounters::rx_bad);  // a board with fewer drivers than configured: keep asking
      return;
    }
    board_drivers_ = ack->driver_count;
    set_state(BusState::kConfiguring);
    last_request_s_ = now_s;
    for (int d = 0; d < options_.driver_count; ++d) {
      send(Configure{static_cast<std::uint8_t>(d), options_.drivers[static_cast<std::size_t>(d)]}, now_s);
    }
    last_heartbeat_s_ = now_s;
    bump(&DriverBusCounters::heartbeats);
    send(Heartbeat{kProtocolVersion, ++seq_}, now_s);  // arm the watchdog at once
    return;
  }
  if (const auto* st = std::get_if<Status>(&m.payload)) {
    bump(&DriverBusCounters::statuses);
    last_status_s_ = now_s;
    const std::uint64_t w = (1ull << 63) | st->coil_states | (std::uint64_t{st->end_of_stroke} << 16) |
                            (std::uint64_t{st->configured} << 24) | (std::uint64_t{st->faults} << 32) |
                            (std::uint64_t{st->last_seq} << 40);
    status_word_.store(w, std::memory_order_release);
    const auto need = static_cast<std::uint8_t>((1u << options_.driver_count) - 1u);
    const bool all_configured = (st->configured & need) == need;
    if (state() == BusState::kConfiguring && all_configured) {
      set_state(BusState::kRunning);
      bump(&DriverBusCounters::sessions);
    } else if (state() == BusState::kRunning && !all_configured) {
      begin_session(now_s);  // the board lost its configuration (reset): start again
    }
    return;
  }
  if (const auto* fault = std::get_if<Fault>(&m.payload)) {
    bump(&DriverBusCounters::faults);
    if (fault->code == FaultCode::kWatchdogExpired) bump(&DriverBusCounters::watchdog_faults);
    if (fault->code == FaultCode::kHoldCapReached) bump(&DriverBusCounters::hold_cap_faults);
  }
}

void DriverBus::poll_once(double now_s) {
  const std::lock_guard<std::mutex> lock(io_mutex_);
  // 1. Everything the board said.
  CanFrame f;
  for (int n = 0; n < 256; ++n) {
    const RxStatus rs = transport_.receive(f, 0);
    if (rs == RxStatus::kTimeout) break;
    if (rs == RxStatus::kDown) {
      if (state() != BusState::kBusOff) {
        bump(&DriverBusCounters::bus_off);
        set_state(BusState::kBusOff);
        bus_off_s_ = now_s;
      }
      break;
    }
    if (rs != RxStatus::kFrame) continue;
    if (options_.log != nullptr) options_.log->record(f);
    if (f.error) {
      on_error_frame(f, now_s);
      continue;
    }
    const DecodeResult r = decode(f);
    if (!r.ok()) {
      bump(&DriverBusCounters::rx_bad);
      if (r.error == DecodeError::kWrongVersion) bump(&DriverBusCounters::version_mismatch);
      continue;
    }
    bump(&DriverBusCounters::rx_frames);
    on_message(r.message, now_s);
  }

  // 2. The session.
  switch (state()) {
    case BusState::kStopped:
      begin_session(now_s);
      break;
    case BusState::kHandshake:
      if (now_s - last_request_s_ >= options_.reply_timeout_s) begin_session(now_s);
      break;
    case BusState::kConfiguring:
      if (now_s - last_request_s_ >= options_.reply_timeout_s) {
        last_request_s_ = now_s;
        for (int d = 0; d < options_.driver_count; ++d) {
          send(Configure{static_cast<std::uint8_t>(d), options_.drivers[static_cast<std::size_t>(d)]}, now_s);
        }
      }
      break;
    case BusState::kRunning:
      if (now_s - last_status_s_ > options_.status_timeout_s) {
        bump(&DriverBusCounters::status_timeouts);
        make_safe(now_s);
        begin_session(now_s);
      }
      break;
    case BusState::kBusOff:
      if (now_s - bus_off_s_ >= options_.bus_off_holdoff_s) {
        if (transport_.reopen()) {
          bump(&DriverBusCounters::reconnects);
          release_all_pending_.store(false);
          set_state(BusState::kStopped);
          make_safe(now_s);  // whatever the board kept, off first
          begin_session(now_s);
        } else {
          bus_off_s_ = now_s;
        }
      }
      break;
  }

  // 3. Commands.
  send_commands(now_s);

  // 4. The heartbeat.
  const BusState s = state();
  if ((s == BusState::kConfiguring || s == BusState::kRunning) &&
      now_s - last_heartbeat_s_ >= options_.heartbeat_period_s) {
    last_heartbeat_s_ = now_s;
    bump(&DriverBusCounters::heartbeats);
    send(Heartbeat{kProtocolVersion, ++seq_}, now_s);
  }
}

bool DriverBus::send_queued(double now_s) {
  const std::unique_lock<std::mutex> lock(io_mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return false;  // poll_once is sending: it takes the queue
  send_commands(now_s);
  return true;
}

// ReleaseAll first, and it discards what was queued before it. Called with io_mutex_ held.
void DriverBus::send_commands(double now_s) {
  const std::uint32_t tail = tail_.load(std::memory_order_acquire);
  std::uint32_t head = head_.load(std::memory_order_relaxed);
  if (release_all_pending_.exchange(false, std::memory_order_acq_rel)) {
    head = tail;
    make_safe(now_s);
  }
  for (; head != tail; ++head) {
    const Command c = queue_[head % kQueueSize];
    if (state() != BusState::kRunning) {
      bump(&DriverBusCounters::dropped_not_running);
      continue;
    }
    if (c.op == Op::kFire) {
      send(Fire{c.driver, FireMode::kPulseHold, 0, ++seq_}, now_s);
    } else {
      send(Release{c.driver, ++seq_}, now_s);
    }
  }
  head_.store(head, std::memory_order_release);
}

void DriverBus::run() {
  while (running_.load(std::memory_order_acquire)) {
    const double now = steady_now_s();
    poll_once(now);
    double wait_s = 0.005;
    if (state() == BusState::kConfiguring || state() == BusState::kRunning) {
      wait_s = std::clamp(last_heartbeat_s_ + options_.heartbeat_period_s - now, 0.0, wait_s);
    }
    pollfd fds[2] = {{transport_.poll_fd(), POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    const timespec ts{0, static_cast<long>(wait_s * 1e9)};
    if (::ppoll(fds, 2, &ts, nullptr) > 0 && (fds[1].revents & POLLIN)) {
      std::uint64_t drained = 0;
      (void)!::read(wake_fd_, &drained, sizeof drained);
    }
  }
}

}  // namespace pinball::firmware
