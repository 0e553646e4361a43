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
#include "pinball/firmware/liveness.h"

namespace pinball::firmware {

namespace {
constexpr int kCounterCount = sizeof(DriverBusCounters) / sizeof(std::uint64_t);
static_assert(sizeof(DriverBusCounters) == kCounterCount * sizeof(std::uint64_t), "DriverBusCounters: uint64 fields only");

}  // namespace

std::string describe(const BusFault& f, const Liveness* liveness) {
  const std::string driver = f.driver == kBoardDriver ? std::string("the board") : "driver " + std::to_string(f.driver);
  switch (f.kind) {
    case BusFaultKind::kBoard: {
      std::string s = std::string("board fault: ") + to_string(f.code) + " (" + driver + ", detail " +
                      std::to_string(f.detail) + ")";
      if (f.code == FaultCode::kWatchdogExpired) s += ": every coil is off";
      if (f.code == FaultCode::kHoldCapReached || f.code == FaultCode::kLocked) s += ": released to unlock it";
      return s;
    }
    case BusFaultKind::kReleaseEscalated:
      return driver + " stayed on after its Release: ReleaseAll sent";
    case BusFaultKind::kLivenessStall: {
      const std::string who = liveness != nullptr && f.detail < liveness->count()
                                  ? std::string(liveness->name(f.detail)) + " thread"
                                  : "watched thread " + std::to_string(f.detail);
      return "the " + who + " stopped making progress: every coil released, heartbeats withheld";
    }
    case BusFaultKind::kStatusTimeout:
      return "no Status from the board: every coil released, session restarted";
    case BusFaultKind::kBusOff:
      return "CAN bus-off: the board's watchdog switches the coils off; reopening";
    case BusFaultKind::kTxFailure:
      return "a CAN frame could not be sent: ReleaseAll attempted";
  }
  return "?";
}

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
  check_input(std::isfinite(options.release_retry_s) && options.release_retry_s > 0.0, "DriverBusOptions",
              "release_retry_s must be > 0");
  check_input(std::isfinite(options.release_deadline_s) && options.release_deadline_s >= options.release_retry_s,
              "DriverBusOptions", "release_deadline_s must be >= release_retry_s");
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

DriverBus::Sent DriverBus::send(const Payload& p, double now_s, WhenFull when_full) {
  const bool may_wait = when_full == WhenFull::kBackOff;
  const CanFrame frame = encode(options_.board_id, p);
  const TxStatus s = may_wait ? transport_.send(frame) : transport_.send_without_waiting(frame);
  if (s == TxStatus::kBufferFull && !may_wait) {
    bump(&DriverBusCounters::sends_left_queued);
    return Sent::kLeftQueued;  // the caller leaves the command queued; the bus thread sends it, backing off
  }
  // What the host wants is decided here, whether or not the frame left.
  if (const auto* fire = std::get_if<Fire>(&p)) {
    Intent& i = intent_[fire->driver];
    i.on = true;
    i.seen_on_since_s = -1.0;
  } else if (const auto* rel = std::get_if<Release>(&p)) {
    Intent& i = intent_[rel->driver];
    i.on = false;
    i.off_seq = rel->seq;
    i.off_sent_s = now_s;
  } else if (const auto* all = std::get_if<ReleaseAll>(&p)) {
    for (Intent& i : intent_) {
      i.on = false;
      i.off_seq = all->seq;
      i.off_sent_s = now_s;
    }
  }
  if (options_.log != nullptr) options_.log->record(frame);
  if (s == TxStatus::kOk) {
    bump(&DriverBusCounters::frames_sent);
    return Sent::kOk;
  }
  bump(&DriverBusCounters::tx_failures);
  if (s == TxStatus::kDown) {
    bump(&DriverBusCounters::bus_off);
    set_state(BusState::kBusOff);
    bus_off_s_ = now_s;
    note_fault(BusFaultKind::kBusOff, now_s);
    return Sent::kFailed;
  }
  note_fault(BusFaultKind::kTxFailure, now_s, kBoardDriver, static_cast<std::uint16_t>(s));
  // Safe first: whatever failed, try to switch every coil off (once).
  if (!std::holds_alternative<ReleaseAll>(p)) {
    const std::uint16_t off_seq = ++seq_;
    const bool any_on = std::any_of(intent_.begin(), intent_.end(), [](const Intent& i) { return i.on; });
    for (Intent& i : intent_) {
      i.on = false;
      i.off_seq = off_seq;
      i.off_sent_s = now_s;
    }
    // A coil the controller holds goes off behind its back: it must know to fire again.
    if (any_on) bump(&DriverBusCounters::coils_dropped);
    const CanFrame off = encode(options_.board_id, ReleaseAll{off_seq});
    if ((may_wait ? transport_.send(off) : transport_.send_without_waiting(off)) == TxStatus::kOk) {
      bump(&DriverBusCounters::frames_sent);
    } else {
      bump(&DriverBusCounters::tx_failures);
      release_all_pending_.store(true, std::memory_order_release);  // try again next iteration
    }
  }
  return Sent::kFailed;
}

DriverBus::Sent DriverBus::make_safe(double now_s, WhenFull when_full) {
  if (state() == BusState::kBusOff) return Sent::kFailed;  // nothing reaches the bus; the board's watchdog acts
  return send(ReleaseAll{++seq_}, now_s, when_full);
}

void DriverBus::begin_session(double now_s) {
  // Off first, whatever the board kept; and only a Release or ReleaseAll
  // unlocks a hold-capped driver (PROTOCOL.md rule 6), so the new session
  // starts with none locked.
  if (state() != BusState::kBusOff) send(ReleaseAll{++seq_}, now_s);
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
    note_fault(BusFaultKind::kBusOff, now_s);
  }
}

void DriverBus::note_fault(BusFaultKind kind, double now_s, std::uint8_t driver, std::uint16_t detail, FaultCode code) {
  if (!faults_.try_push(BusFault{now_s, kind, code, driver, detail})) bump(&DriverBusCounters::faults_unreported);
}

void DriverBus::send_release(std::uint8_t driver, double now_s) {
  if (driver < options_.driver_count) send(Release{driver, ++seq_}, now_s);
}

// The board's faults change what is true about the coils; act on them.
void DriverBus::on_board_fault(const Fault& f, double now_s) {
  bump(&DriverBusCounters::faults);
  note_fault(BusFaultKind::kBoard, now_s, f.driver, f.detail, f.code);
  switch (f.code) {
    case FaultCode::kWatchdogExpired:
      bump(&DriverBusCounters::watchdog_faults);
      bump(&DriverBusCounters::coils_dropped);
      for (Intent& i : intent_) i.on = false;  // the board switched every coil off
      break;
    case FaultCode::kHoldCapReached:
      bump(&DriverBusCounters::hold_cap_faults);
      bump(&DriverBusCounters::coils_dropped);
      send_release(f.driver, now_s);  // acknowledges the cap: the driver may fire again
      break;
    case FaultCode::kLocked:
      bump(&DriverBusCounters::locked_faults);
      bump(&DriverBusCounters::coils_dropped);
      send_release(f.driver, now_s);
      break;
    case FaultCode::kStale:
      bump(&DriverBusCounters::stale_faults);
      break;
    case FaultCode::kNotConfigured:
    case FaultCode::kNotArmed:
      bump(&DriverBusCounters::refused_faults);
      break;
    default:
      break;
  }
}

// The closed loop: a coil the host wants off and the board reports on gets
// its Release again once the board has had time to act on the last one (or
// has accepted a later frame, so the Release was lost), and a ReleaseAll
// once it has stayed on for release_deadline_s.
void DriverBus::check_coils(const Status& st, double now_s) {
  bool escalate = false;
  for (int d = 0; d < options_.driver_count; ++d) {
    Intent& i = intent_[static_cast<std::size_t>(d)];
    const auto state = static_cast<CoilState>((st.coil_states >> (2 * d)) & 0x3u);
    if (i.on || state == CoilState::kOff) {
      i.seen_on_since_s = -1.0;
      continue;
    }
    const bool overtaken = !seq_newer(i.off_seq, st.last_seq);  // the board accepted it or something later
    if (!overtaken && now_s - i.off_sent_s < options_.release_retry_s) continue;  // still on its way
    if (i.seen_on_since_s < 0.0) i.seen_on_since_s = now_s;
    if (now_s - i.seen_on_since_s >= options_.release_deadline_s) {
      escalate = true;
      note_fault(BusFaultKind::kReleaseEscalated, now_s, static_cast<std::uint8_t>(d));
      i.seen_on_since_s = now_s;  // the next escalation, if any, one deadline later
      continue;
    }
    bump(&DriverBusCounters::release_retries);
    send_release(static_cast<std::uint8_t>(d), now_s);
  }
  if (escalate) {
    bump(&DriverBusCounters::release_escalations);
    bump(&DriverBusCounters::coils_dropped);
    make_safe(now_s);
  }
}

// Heartbeats only while every watched thread makes progress. On the first
// stall the coils go off at once; the missing heartbeats are the second line.
bool DriverBus::chain_alive(double now_s) {
  const Liveness* live = options_.liveness;
  if (live == nullptr) return true;
  const int stalled = live->stalled(now_s);
  if (stalled < 0) {
    chain_stalled_ = false;
    return true;
  }
  if (!chain_stalled_ && live->started(stalled)) {  // a thread still starting up is not a stall
    chain_stalled_ = true;
    bump(&DriverBusCounters::liveness_stalls);
    bump(&DriverBusCounters::coils_dropped);
    note_fault(BusFaultKind::kLivenessStall, now_s, kBoardDriver, static_cast<std::uint16_t>(stalled));
    make_safe(now_s);
  }
  return false;
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
    if (chain_alive(now_s)) {  // arm the watchdog at once, if the chain runs
      last_heartbeat_s_ = now_s;
      bump(&DriverBusCounters::heartbeats);
      send(Heartbeat{kProtocolVersion, ++seq_}, now_s);
    }
    return;
  }
  if (const auto* st = std::get_if<Status>(&m.payload)) {
    bump(&DriverBusCounters::statuses);
    last_status_s_ = now_s;
    if (options_.verify_coils) check_coils(*st, now_s);
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
  if (const auto* fault = std::get_if<Fault>(&m.payload)) on_board_fault(*fault, now_s);
}

void DriverBus::attach_log(FrameLog* log) {
  const std::lock_guard<std::mutex> lock(io_mutex_);  // every frame is logged under it
  options_.log = log;
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
        bump(&DriverBusCounters::coils_dropped);
        note_fault(BusFaultKind::kStatusTimeout, now_s);
        begin_session(now_s);  // ReleaseAll first
      }
      break;
    case BusState::kBusOff:
      if (now_s - bus_off_s_ >= options_.bus_off_holdoff_s) {
        if (transport_.reopen()) {
          bump(&DriverBusCounters::reconnects);
          release_all_pending_.store(false);
          set_state(BusState::kStopped);
          begin_session(now_s);  // whatever the board kept, off first
        } else {
          bus_off_s_ = now_s;
        }
      }
      break;
  }

  // 3. Commands.
  send_commands(now_s, WhenFull::kBackOff);

  // 4. The heartbeat, while the chain it vouches for makes progress.
  // Checked on every poll, so that a stall releases the coils at once.
  const BusState s = state();
  const bool alive = chain_alive(now_s);
  if ((s == BusState::kConfiguring || s == BusState::kRunning) &&
      now_s - last_heartbeat_s_ >= options_.heartbeat_period_s) {
    if (alive) {
      last_heartbeat_s_ = now_s;
      bump(&DriverBusCounters::heartbeats);
      send(Heartbeat{kProtocolVersion, ++seq_}, now_s);
    } else if (now_s - last_withheld_s_ >= options_.heartbeat_period_s) {
      last_withheld_s_ = now_s;
      bump(&DriverBusCounters::heartbeats_withheld);
    }
  }
}

bool DriverBus::send_queued(double now_s, WhenFull when_full) {
  const std::unique_lock<std::mutex> lock(io_mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return false;  // poll_once is sending: it takes the queue
  send_commands(now_s, when_full);
  return true;
}

// ReleaseAll first, and it discards what was queued before it. Called with io_mutex_ held.
void DriverBus::send_commands(double now_s, WhenFull when_full) {
  // The request before the tail: a fire() then release_all() landing between the two loads had left
  // that Fire behind the old tail, sent on the next pass, after its ReleaseAll (a coil on after
  // "all off"). The request's acquire makes every command queued before it visible to the tail's load.
  const bool release_all = release_all_pending_.exchange(false, std::memory_order_acq_rel);
  const std::uint32_t tail = tail_.load(std::memory_order_acquire);
  std::uint32_t head = head_.load(std::memory_order_relaxed);
  if (release_all) {
    head = tail;
    if (make_safe(now_s, when_full) == Sent::kLeftQueued) {
      release_all_pending_.store(true, std::memory_order_release);  // the bus thread sends it, first
      head_.store(head, std::memory_order_release);
      wake();
      return;
    }
  }
  for (; head != tail; ++head) {
    const Command c = queue_[head % kQueueSize];
    if (state() != BusState::kRunning) {
      bump(&DriverBusCounters::dropped_not_running);
      continue;
    }
    const Payload p = c.op == Op::kFire ? Payload{Fire{c.driver, FireMode::kPulseHold, 0, ++seq_}}
                                        : Payload{Release{c.driver, ++seq_}};
    if (send(p, now_s, when_full) == Sent::kLeftQueued) {
      wake();  // this command and those after it stay queued, in order
      break;
    }
  }
  head_.store(head, std::memory_order_release);
}

void DriverBus::run() {
  try {
    loop();
  } catch (...) {
    // The bus thread dies: coils off first, from here; no heartbeat follows,
    // so the board's watchdog is the second line.
    bump(&DriverBusCounters::thread_failures);
    release_all();
    send_queued(steady_now_s());
  }
}

void DriverBus::loop() {
  while (running_.load(std::memory_order_acquire)) {
    const double now = steady_now_s();
    poll_once(now);
    double wait_s = 0.005;
    if (state() == BusState::kConfiguring || state() == BusState::kRunning) {
      const double last_slot_s = std::max(last_heartbeat_s_, last_withheld_s_);  // sent or withheld
      wait_s = std::clamp(last_slot_s + options_.heartbeat_period_s - now, 0.0, wait_s);
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
