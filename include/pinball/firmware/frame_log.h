#pragma once
// A frame log in candump's log format, one frame a line:
//   (1700000000.123456) can0 123#DEADBEEF
// so that lab engineers read it with their eyes and replay it with
// `canplayer -I FILE` (can-utils).
//
// DriverBus records every frame from the driver and controller threads,
// inside its bus lock, so recording must never wait on the file: record()
// only copies the frame into a fixed-size lock-free queue, and a writer
// thread of the FrameLog formats and writes the lines. Whatever the sink
// does (fills a disk, a pipe whose reader stopped reading or went away), the
// bus carries on; the frames that could not be written are dropped and
// counted, and the first error of each kind is reported on stderr at once.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>

#include "pinball/core/file_sink.h"
#include "pinball/core/single_writer_counter.h"
#include "pinball/core/spsc_ring.h"
#include "pinball/firmware/can_frame.h"

namespace pinball::firmware {

/// One parsed log line.
struct LogEntry {
  double time_s = 0.0;    ///< timestamp (s since the epoch, as candump writes it)
  std::string interface;  ///< interface name
  CanFrame frame;         ///< the frame (rx_time_ns set from time_s)
};

/// Formats one line (without the newline).
std::string format_log_line(const CanFrame& frame, double time_s, std::string_view interface);

/// Parses one line; std::nullopt when it is not a candump log line.
std::optional<LogEntry> parse_log_line(std::string_view line);

/// What a FrameLog did with the frames it was given (monotonic). Every
/// recorded frame ends up written or in exactly one of the dropped counts
/// (frames still queued while the log runs are in neither).
struct FrameLogCounters {
  std::uint64_t written = 0;              ///< lines the sink accepted
  std::uint64_t dropped_queue_full = 0;   ///< dropped by record(): the queue was full (the sink fell behind)
  std::uint64_t dropped_write_error = 0;  ///< dropped because a write failed (ENOSPC, EPIPE, EIO, ...)
  std::uint64_t dropped_at_close = 0;     ///< still queued when close()'s time ran out (a blocked sink)
  int first_errno = 0;                    ///< errno of the first failed write or close, 0 when none
  std::string first_error;                ///< the first problem, naming the file ("" when none)

  /// Frames recorded but not written.
  std::uint64_t dropped() const { return dropped_queue_full + dropped_write_error + dropped_at_close; }
  /// Every frame recorded is in the sink (a failed close may have lost written ones).
  bool complete() const { return dropped() == 0 && first_errno == 0; }
};

/// Writes frames to a file, a pipe or a device without ever blocking the caller.
class FrameLog {
 public:
  /// Frames the queue holds: about two seconds of a saturated 500 kbit/s bus.
  static constexpr std::size_t kQueueFrames = 8192;

  /// Opens (truncates) `path` and starts the writer thread; throws
  /// std::runtime_error naming the file when it cannot be opened. A named
  /// pipe waits here, as with any open, until its reader comes. close() and
  /// the destructor give the sink at most `close_timeout_s` to take the rest.
  FrameLog(const std::string& path, std::string interface = "can0", double close_timeout_s = 1.0);
  /// close().
  ~FrameLog();
  FrameLog(const FrameLog&) = delete;
  FrameLog& operator=(const FrameLog&) = delete;

  /// Queues one frame stamped `time_s` (s since the epoch). Real-time safe: no
  /// lock, no allocation, no system call; a full queue drops the frame
  /// (counted). One caller at a time: callers on several threads serialise
  /// (DriverBus records under its own mutex).
  void record(const CanFrame& frame, double time_s);
  /// Queues one frame stamped on the log's clock (stamp_with), else with its
  /// rx_time_ns, or the epoch clock when that is 0.
  void record(const CanFrame& frame);
  /// Stamps every frame record(frame) takes with `clock_s()` (s since the
  /// epoch): the daemon's one clock for a run's recordings, so that a lockstep
  /// run's log plays back at the game's pace. Before the first record();
  /// `clock_s` is called on the recording thread and must not block.
  void stamp_with(std::function<double()> clock_s) { clock_s_ = std::move(clock_s); }
  /// Waits until every frame recorded so far is written or dropped, at most
  /// close_timeout_s; false when the time ran out (not a real-time call).
  bool flush();
  /// Writes what it can within close_timeout_s, counts the rest as dropped,
  /// stops the writer and closes the file. Frames recorded afterwards are
  /// counted as dropped at close. Idempotent.
  void close();
  /// The counters so far (any thread).
  FrameLogCounters counters() const;

 private:
  struct Entry {
    CanFrame frame;
    double time_s = 0.0;
  };
  using Queue = SpscRing<Entry, kQueueFrames>;
  struct Batch;

  void run();
  bool fill(Batch& batch);
  void write_batch(const Batch& batch);
  bool past_deadline() const;
  void on_write_error(int err);
  void report(const std::string& problem, int kind, const char* consequence = "");
  void report_queue_full();

  std::string interface_;
  double close_timeout_s_;
  std::function<double()> clock_s_;  // empty: the frames' own stamps
  FileSink sink_;  // the writer thread's, and close()'s once it is joined
  std::unique_ptr<Queue> queue_;  // on the heap: 256 KiB
  // Written by the producer (one at a time) and by the writer thread respectively.
  SingleWriterCounter dropped_queue_full_;
  SingleWriterCounter written_, dropped_write_error_, dropped_at_close_, resolved_;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> writer_done_{false};
  double deadline_s_ = 0.0;  // steady clock; set before stopping_ is
  bool mid_line_ = false;    // the writer's: a failed write left a partial line
  std::uint64_t queue_full_reported_ = 0;  // the writer's
  // The writer's idle wait, and the reports (never touched by record()).
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  int first_errno_ = 0;
  std::string first_error_;
  std::set<int> reported_kinds_;  // errno values and the kinds below zero
  std::thread writer_;
};

}  // namespace pinball::firmware
