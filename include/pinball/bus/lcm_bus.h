#pragma once
// The daemon's LCM endpoint. Real-time threads never touch LCM: they hand
// fixed-size messages to lock-free rings (try_publish: no lock, no
// allocation, no system call) and the bus's own thread encodes and publishes
// them. liblcm's publish allocates and, for memq://, writes a pipe, so it has
// no place on the camera or controller thread. The bus thread also receives
// (observations from an external camera process or lcm-logplayer) and counts
// what it cannot decode instead of passing it on.
//
// A recording is only as good as its failures are visible: every message
// liblcm refuses is counted (publish_failed) and the first is said on stderr
// at once. A file:// URL in write or append mode (`file:///tmp/game.lcmlog?mode=w`)
// is written by the bus itself in LCM's log format (lcm_log_format.h),
// because liblcm's file provider ignores its write errors: a full disk, a
// pipe whose reader left, or one that stopped reading past stop()'s second
// are publish failures like any other, and never hold the bus thread for good.
//
// One clock for a run's recordings: an event of such a log is stamped with
// its message's utime plus the run's anchor (set_log_anchor_us), never with
// the time the bus thread happened to write it, so lcm-logplayer replays a
// lockstep run at the game's pace and the events line up with the CAN log's
// stamps. The bus publishes the queued messages in utime order.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "pinball/core/file_sink.h"
#include "pinball/core/spsc_ring.h"
#include "pinball_lcm/lcmt_pinball_daemon_stats.hpp"
#include "pinball_lcm/lcmt_pinball_driver_status.hpp"
#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"
#include "pinball_lcm/lcmt_pinball_game_event.hpp"
#include "pinball_lcm/lcmt_pinball_observation.hpp"
#include "pinball_lcm/lcmt_pinball_projection.hpp"

namespace pinball::bus {

/// Counters of the bus (monotonic).
struct LcmBusCounters {
  std::uint64_t published = 0;       ///< messages liblcm accepted
  std::uint64_t publish_failed = 0;  ///< messages refused (a send error, a full disk under file://): lost
  std::uint64_t overflows = 0;       ///< messages dropped because their ring was full (to publish or received)
  std::uint64_t dropped_queue_full = 0;  ///< of those, messages to publish: lost to every recording
  std::uint64_t received = 0;        ///< messages received and accepted
  std::uint64_t malformed = 0;       ///< messages received that failed to decode or check, ignored
  std::string first_failure;         ///< the first refused publish, for people ("" when none)
};

/// Where a file:// URL in write ("mode=w") or append ("mode=a") mode writes.
struct LcmLogTarget {
  std::string path;     ///< the file
  bool append = false;  ///< mode=a
};

/// The log file of a file:// URL that writes; std::nullopt for every other
/// URL (other providers, file:// in read mode, which is liblcm's default).
std::optional<LcmLogTarget> lcm_log_target(const std::string& url);

/// The log a file:// URL plays (read mode, liblcm's default); std::nullopt
/// for every other URL. liblcm trusts a log's lengths: its reader must be
/// checked first (require_lcm_log).
std::optional<std::string> lcm_log_source(const std::string& url);

/// Why `url` names no provider liblcm has ("" when it does): empty, or a
/// scheme other than udpm, mpudpm, file, memq and tcpq. liblcm would print a
/// line of its own and fail; the programs say this one instead.
std::string lcm_url_problem(const std::string& url);

/// lcm_handle_timeout for a provider that may have no descriptor (a tcpq://
/// server that is gone, a udpm:// socket that failed): liblcm would select on
/// -1, which glibc's checks abort. Returns -1 then, as for an error.
int handle_lcm_timeout(lcm_t* lcm, int timeout_ms);
/// Throws "lcm: cannot open 'url': ..." when `lcm` has no descriptor to
/// receive on, so a provider that failed to connect is refused at start.
void require_lcm_connected(lcm_t* lcm, const std::string& url);
/// Opens `url` as the start would and closes it again, throwing as LcmBus
/// does when it cannot connect (a tcpq:// server that is not listening). A
/// file:// URL is not opened (that would create or replace the log); memq://
/// has nothing to connect to.
void check_lcm_url_connects(const std::string& url);

/// A handler of raw messages: the encoded bytes of one message.
using RawHandler = std::function<void(const void* data, int size)>;

/// Subscribes `handler` to `channel` through LCM's C API. LCM 1.3's C++
/// subscription templates fail UBSan's vptr check (their callback reaches the
/// subscription through a pointer UBSan cannot verify), so neither the daemon
/// nor its tests use them. `handler` is borrowed and must outlive `lcm`.
void subscribe_raw(lcm::LCM& lcm, const char* channel, RawHandler& handler);

/// Decodes into T and calls `on(message)`; counts nothing, drops undecodable bytes.
template <class T, class On>
RawHandler typed_handler(On on) {
  return [on](const void* data, int size) {
    T m{};
    if (m.decode(data, 0, size) >= 0) on(static_cast<const T&>(m));
  };
}

/// Observations arriving over LCM, for the camera thread.
using ObservationRing = SpscRing<pinball_lcm::lcmt_pinball_observation, 1024>;

/// One LCM instance and the thread that serves it.
class LcmBus {
 public:
  /// Opens LCM at `url` ("memq://", "udpm://239.255.76.67:7667?ttl=0",
  /// "file:///tmp/game.lcmlog?mode=w", ...). Throws std::runtime_error naming
  /// the URL when LCM or the log file cannot be opened.
  explicit LcmBus(const std::string& url);
  ~LcmBus();
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  /// Starts the bus thread. `periodic` (may be empty) runs on it every
  /// `period_s` with the LCM instance (the daemon's stats); `on_start` (may be
  /// empty) runs first on the new thread (naming and scheduling it). An
  /// exception on the thread ends it and goes to `on_failure` (may be empty)
  /// with its what(), on that thread: the daemon makes the coils safe.
  void start(std::function<void(lcm::LCM&)> periodic = {}, double period_s = 1.0,
             std::function<void()> on_start = {}, std::function<void(const std::string&)> on_failure = {});
  /// The offset from a message's utime to its event's timestamp in a file://
  /// log (us): the run's epoch anchor. The default maps the steady clock (the
  /// lab's utime) onto the epoch as of construction. Before start().
  void set_log_anchor_us(std::int64_t anchor_us) { log_anchor_us_ = anchor_us; }
  /// Publishes what is queued, runs `periodic` once more, stops the thread.
  void stop();

  /// Queue a message for publication; false (counted) when its ring is full.
  /// One producer thread per message type.
  bool try_publish(const pinball_lcm::lcmt_pinball_observation& m);
  bool try_publish(const pinball_lcm::lcmt_pinball_projection& m);
  bool try_publish(const pinball_lcm::lcmt_pinball_flipper_command& m);
  bool try_publish(const pinball_lcm::lcmt_pinball_driver_status& m);
  bool try_publish(const pinball_lcm::lcmt_pinball_game_event& m);

  /// Publishes `m` at once and counts it like the queued messages; false when
  /// it was refused. For the bus thread only (start()'s `periodic`).
  template <class T>
  bool publish_now(const char* channel, const T& m) {
    encoded_.resize(static_cast<std::size_t>(m.getEncodedSize()));
    m.encode(encoded_.data(), 0, static_cast<int>(encoded_.size()));
    return publish_encoded(channel, encoded_.data(), encoded_.size(), m.utime);
  }

  /// Receive PINBALL_OBSERVATION into `ring` (call before start()). Messages
  /// that do not decode, or carry bad fields, are counted as malformed.
  void subscribe_observations(ObservationRing& ring);

  /// Counters so far.
  LcmBusCounters counters() const;
  /// How full the fullest outbox is, 0..1: how far the bus thread is behind.
  /// Any thread.
  double outbox_fill() const;
  /// The LCM instance (subscriptions; for a file:// URL that writes, an
  /// in-process memq:// one that nothing reaches the log through).
  lcm::LCM& lcm() { return *lcm_; }

 private:
  template <class T, std::size_t N>
  struct Outbox {
    SpscRing<T, N> ring;
    const char* channel;
    T head{};               // taken from the ring, not yet published (bus thread)
    bool has_head = false;
  };
  void run(const std::function<void(lcm::LCM&)>& periodic, double period_s);
  int drain();
  template <class T, std::size_t N>
  bool refill(Outbox<T, N>& box);
  template <class T, std::size_t N>
  bool push(Outbox<T, N>& box, const T& m);
  void on_observation(const void* data, int size);
  bool publish_encoded(const char* channel, const std::uint8_t* data, std::size_t size, std::int64_t utime);
  int write_log_event(const char* channel, const std::uint8_t* data, std::size_t size, std::int64_t utime);
  void on_publish_failed(const char* channel, int err);

  std::unique_ptr<lcm::LCM> lcm_;
  std::string url_;
  std::unique_ptr<FileSink> log_;  // file:// that writes: the log, written by the bus thread
  std::int64_t log_events_ = 0;    // events whole in the log (the next event number)
  std::int64_t log_anchor_us_ = 0;  // event timestamp = message utime + this (us)
  std::int64_t last_event_utime_ = 0;  // event timestamps never go back (lcm-logplayer waits on differences)
  std::string log_event_;          // scratch: one event's bytes
  std::vector<std::uint8_t> encoded_;  // scratch: one encoded message
  std::atomic<double> stop_deadline_s_{0.0};  // steady clock: a blocked log is given up after it
  Outbox<pinball_lcm::lcmt_pinball_observation, 1024> observations_;
  Outbox<pinball_lcm::lcmt_pinball_projection, 1024> projections_;
  Outbox<pinball_lcm::lcmt_pinball_flipper_command, 256> commands_;
  Outbox<pinball_lcm::lcmt_pinball_driver_status, 64> statuses_;
  Outbox<pinball_lcm::lcmt_pinball_game_event, 1024> games_;
  ObservationRing* inbox_ = nullptr;
  RawHandler observation_handler_;
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> publish_failed_{0};
  std::string first_failure_;                  // written once by the bus thread, before...
  std::atomic<bool> has_first_failure_{false};  // ...this is set
  std::atomic<std::uint64_t> overflows_{0};
  std::atomic<std::uint64_t> dropped_queue_full_{0};
  bool said_dropped_ = false;  // bus thread: the first dropped message is said on stderr
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> malformed_{0};
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace pinball::bus
