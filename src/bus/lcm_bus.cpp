#include "pinball/bus/lcm_bus.h"

#include <pthread.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <optional>
#include <set>
#include <stdexcept>
#include <vector>

#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/message_convert.h"
#include "pinball/core/clock.h"

namespace pinball::bus {

namespace {

constexpr double kStopGraceS = 1.0;  // what stop() gives a log file that takes nothing (a pipe nobody reads)

// The file:// log of `url` opened, or nullptr for every URL that liblcm serves.
std::unique_ptr<FileSink> open_log(const std::string& url) {
  const std::optional<LcmLogTarget> target = lcm_log_target(url);
  if (!target) return nullptr;
  try {
    return std::make_unique<FileSink>(target->path, target->append);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("lcm: cannot open '" + url + "': " + e.what());
  }
}

extern "C" void raw_callback(const lcm_recv_buf_t* rbuf, const char*, void* user_data) {
  (*static_cast<RawHandler*>(user_data))(rbuf->data, static_cast<int>(rbuf->data_size));
}

}  // namespace

std::optional<LcmLogTarget> lcm_log_target(const std::string& url) {
  const std::string scheme = "file://";
  if (url.rfind(scheme, 0) != 0) return std::nullopt;
  const std::size_t query = url.find('?');
  LcmLogTarget t;
  t.path = url.substr(scheme.size(), query == std::string::npos ? std::string::npos : query - scheme.size());
  std::string mode = "r";  // liblcm's default: a log to play
  for (std::size_t at = query; at != std::string::npos && at < url.size();) {
    const std::size_t end = url.find('&', at + 1);
    const std::string arg = url.substr(at + 1, end == std::string::npos ? std::string::npos : end - at - 1);
    if (arg.rfind("mode=", 0) == 0) mode = arg.substr(5);
    at = end;
  }
  if (mode != "w" && mode != "a") return std::nullopt;
  t.append = mode == "a";
  return t;
}

std::optional<std::string> lcm_log_source(const std::string& url) {
  if (url.rfind("file://", 0) != 0 || lcm_log_target(url)) return std::nullopt;
  const std::string rest = url.substr(std::string("file://").size());
  return rest.substr(0, rest.find('?'));
}

std::string lcm_url_problem(const std::string& url) {
  static const std::set<std::string> kProviders = {"udpm", "mpudpm", "file", "memq", "tcpq"};
  const std::size_t scheme_end = url.find("://");
  if (scheme_end != std::string::npos && kProviders.count(url.substr(0, scheme_end)) == 1) return "";
  return "'" + url + "' names no LCM provider: it starts with udpm://, mpudpm://, file://, memq:// or tcpq://";
}

void subscribe_raw(lcm::LCM& lcm, const char* channel, RawHandler& handler) {
  lcm_subscribe(lcm.getUnderlyingLCM(), channel, &raw_callback, &handler);
}

int handle_lcm_timeout(lcm_t* lcm, int timeout_ms) {
  if (lcm_get_fileno(lcm) < 0) return -1;
  return lcm_handle_timeout(lcm, timeout_ms);
}

void require_lcm_connected(lcm_t* lcm, const std::string& url) {
  if (lcm_get_fileno(lcm) < 0) {
    throw std::runtime_error("lcm: cannot open '" + url +
                             "': the provider has no connection (tcpq://: is the server listening? "
                             "udpm://: is the port a real one, and multicast routed?)");
  }
}

void check_lcm_url_connects(const std::string& url) {
  if (url.rfind("file://", 0) == 0 || url.rfind("memq://", 0) == 0) return;
  lcm::LCM probe(url);
  if (!probe.good()) throw std::runtime_error("lcm: cannot open '" + url + "'");
  require_lcm_connected(probe.getUnderlyingLCM(), url);
}

LcmBus::LcmBus(const std::string& url)
    : lcm_(std::make_unique<lcm::LCM>(lcm_log_target(url) ? std::string("memq://") : url)),
      url_(url),
      log_(open_log(url)),
      observations_{{}, kObservationChannel},
      projections_{{}, kProjectionChannel},
      commands_{{}, kFlipperCommandChannel},
      statuses_{{}, kDriverStatusChannel},
      games_{{}, kGameChannel} {
  log_anchor_us_ = to_utime(epoch_now_s() - steady_now_s());
  if (!lcm_->good()) throw std::runtime_error("lcm: cannot open '" + url + "'");
  require_lcm_connected(lcm_->getUnderlyingLCM(), url);
}

LcmBus::~LcmBus() { stop(); }

void LcmBus::start(std::function<void(lcm::LCM&)> periodic, double period_s, std::function<void()> on_start,
                   std::function<void(const std::string&)> on_failure) {
  if (running_.exchange(true)) throw std::logic_error("lcm bus already running");
  thread_ = std::thread([this, periodic = std::move(periodic), period_s, on_start = std::move(on_start),
                         on_failure = std::move(on_failure)] {
    pthread_setname_np(pthread_self(), "pb-lcm");
    block_sigpipe_in_this_thread();  // a log's reader that leaves is a failed publish, not death
    try {
      if (on_start) on_start();
      run(periodic, period_s);
    } catch (const std::exception& e) {
      if (on_failure) on_failure(e.what());
    } catch (...) {
      if (on_failure) on_failure("unknown exception");
    }
  });
}

void LcmBus::stop() {
  stop_deadline_s_.store(steady_now_s() + kStopGraceS, std::memory_order_relaxed);  // seen once running_ is
  if (!running_.exchange(false)) return;
  if (thread_.joinable()) thread_.join();
  // Some file systems (NFS) report a failed write only at close: the log may miss anything.
  if (log_) {
    if (const int err = log_->close(); err != 0) on_publish_failed("(closing the log)", err);
  }
}

template <class T, std::size_t N>
bool LcmBus::push(Outbox<T, N>& box, const T& m) {
  if (box.ring.try_push(m)) return true;
  overflows_.fetch_add(1, std::memory_order_relaxed);
  dropped_queue_full_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

double LcmBus::outbox_fill() const {
  const auto fill = [](const auto& box) {
    return static_cast<double>(box.ring.size()) / static_cast<double>(box.ring.capacity());
  };
  return std::max({fill(observations_), fill(projections_), fill(commands_), fill(statuses_), fill(games_)});
}

bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_observation& m) { return push(observations_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_projection& m) { return push(projections_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_flipper_command& m) { return push(commands_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_driver_status& m) { return push(statuses_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_game_event& m) { return push(games_, m); }

void LcmBus::subscribe_observations(ObservationRing& ring) {
  inbox_ = &ring;
  observation_handler_ = [this](const void* data, int size) { on_observation(data, size); };
  subscribe_raw(*lcm_, kObservationChannel, observation_handler_);
}

void LcmBus::on_observation(const void* data, int size) {
  pinball_lcm::lcmt_pinball_observation m{};
  bool found = false;
  track::Observation o;
  track::ContactSensors c;
  if (decode_observation(data, static_cast<std::size_t>(size), m) == ObservationLayout::kMalformed ||
      !from_lcm_observation(m, found, o, c)) {
    malformed_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (inbox_->try_push(m)) {
    received_.fetch_add(1, std::memory_order_relaxed);
  } else {
    overflows_.fetch_add(1, std::memory_order_relaxed);
  }
}

bool LcmBus::publish_encoded(const char* channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) {
  int err = 0;
  bool ok = false;
  if (log_) {
    err = write_log_event(channel, data, size, utime);
    ok = err == 0;
  } else {
    errno = 0;
    ok = lcm_->publish(channel, data, static_cast<unsigned>(size)) == 0;
    err = errno;
  }
  if (ok) {
    published_.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  on_publish_failed(channel, err);
  return false;
}

// One event appended to the log; 0, or the errno that stopped it (ETIMEDOUT: given up after stop()).
// The event is stamped on the run's clock: the message's utime plus the anchor.
int LcmBus::write_log_event(const char* channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) {
  const std::int64_t event_utime = std::max(last_event_utime_, utime + log_anchor_us_);
  log_event_.clear();
  append_lcm_event(log_event_, log_events_, event_utime, channel, data, size);
  const SinkWrite w = log_->write(log_event_.data(), log_event_.size(), [this] {
    return !running_.load(std::memory_order_acquire) && steady_now_s() > stop_deadline_s_.load(std::memory_order_relaxed);
  });
  if (w.bytes == log_event_.size()) {
    ++log_events_;
    last_event_utime_ = event_utime;
    return 0;
  }
  return w.error != 0 ? w.error : EIO;
}

// True when `box` has a message to publish (its head), taken from its ring if need be.
template <class T, std::size_t N>
bool LcmBus::refill(Outbox<T, N>& box) {
  if (!box.has_head) box.has_head = box.ring.try_pop(box.head);
  return box.has_head;
}

// Publishes everything queued, the earliest utime first across the channels
// (each ring is in order already): a log's events then follow the game.
// Returns the messages published or refused.
int LcmBus::drain() {
  int n = 0;
  for (;;) {
    std::int64_t earliest = 0;
    int which = -1;
    int i = 0;
    const auto consider = [&](auto& box) {
      if (refill(box) && (which < 0 || box.head.utime < earliest)) {
        earliest = box.head.utime;
        which = i;
      }
      ++i;
    };
    consider(observations_);
    consider(projections_);
    consider(commands_);
    consider(statuses_);
    consider(games_);
    if (which < 0) return n;
    i = 0;
    const auto publish_chosen = [&](auto& box) {
      if (i++ != which) return;
      publish_now(box.channel, box.head);
      box.has_head = false;
    };
    publish_chosen(observations_);
    publish_chosen(projections_);
    publish_chosen(commands_);
    publish_chosen(statuses_);
    publish_chosen(games_);
    ++n;
  }
}

// A refused publish is a hole in every recording of the bus (a file:// log on a full disk):
// counted, and the first one said at once.
void LcmBus::on_publish_failed(const char* channel, int err) {
  publish_failed_.fetch_add(1, std::memory_order_relaxed);
  if (has_first_failure_.load(std::memory_order_relaxed)) return;
  const std::string why = err == ETIMEDOUT ? std::string(": the log took nothing in the grace stop() gives it")
                          : err != 0       ? std::string(": ") + std::strerror(err)
                                           : std::string();
  first_failure_ = "lcm: publishing " + std::string(channel) + " on '" + url_ + "' failed" + why;
  has_first_failure_.store(true, std::memory_order_release);
  std::fprintf(stderr, "%s; refused messages are counted (publish_failed)\n", first_failure_.c_str());
}

void LcmBus::run(const std::function<void(lcm::LCM&)>& periodic, double period_s) {
  using clock = std::chrono::steady_clock;
  auto next = clock::now() + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(period_s));
  while (running_.load(std::memory_order_acquire)) {
    const int n = drain();
    // Said here, on this ordinary thread: the producers that drop are real-time ones.
    if (!said_dropped_ && dropped_queue_full_.load(std::memory_order_relaxed) > 0) {
      said_dropped_ = true;
      std::fprintf(stderr,
                   "lcm: the LCM thread fell behind on '%s' (an outbox was full); the messages that do not fit are "
                   "dropped (counted, dropped_queue_full)\n",
                   url_.c_str());
    }
    // Dispatch what arrived (and, for memq://, empty its queue of our own messages).
    while (handle_lcm_timeout(lcm_->getUnderlyingLCM(), 0) > 0) {
    }
    if (periodic && clock::now() >= next) {
      periodic(*lcm_);
      next += std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(period_s));
    }
    // Publishing is not on anyone's critical path: a short nap when idle.
    if (n == 0 && handle_lcm_timeout(lcm_->getUnderlyingLCM(), 1) < 0) {
      // A provider that cannot receive (file://...?mode=w), or whose connection is gone: what
      // it is given is refused and counted (publish_failed).
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  }
  drain();
  if (periodic) periodic(*lcm_);
  while (handle_lcm_timeout(lcm_->getUnderlyingLCM(), 0) > 0) {
  }
}

LcmBusCounters LcmBus::counters() const {
  LcmBusCounters c;
  c.published = published_.load(std::memory_order_relaxed);
  c.publish_failed = publish_failed_.load(std::memory_order_relaxed);
  c.overflows = overflows_.load(std::memory_order_relaxed);
  c.dropped_queue_full = dropped_queue_full_.load(std::memory_order_relaxed);
  c.received = received_.load(std::memory_order_relaxed);
  c.malformed = malformed_.load(std::memory_order_relaxed);
  if (has_first_failure_.load(std::memory_order_acquire)) c.first_failure = first_failure_;
  return c;
}

}  // namespace pinball::bus
