#include "pinball/firmware/frame_log.h"

#include <linux/can.h>
#include <pthread.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "pinball/core/check.h"
#include "pinball/core/clock.h"

namespace pinball::firmware {
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string format_log_line(const CanFrame& frame, double time_s, std::string_view interface) {
  // A stamp no clock gives (NaN, negative, past the year 30000) is written as
  // 0 rather than overflowing the cast (UBSan float-cast-overflow).
  if (!(time_s >= 0.0 && time_s < 1e12)) time_s = 0.0;
  const auto whole = static_cast<long long>(time_s);
  long long micros = std::llround((time_s - static_cast<double>(whole)) * 1e6);
  long long secs = whole;
  if (micros >= 1'000'000) {
    micros -= 1'000'000;
    ++secs;
  }
  char stamp[40];
  std::snprintf(stamp, sizeof stamp, "(%lld.%06lld) ", secs, micros);
  std::string line = stamp;
  line.append(interface);
  line.push_back(' ');
  line += to_candump(frame);
  return line;
}

std::optional<LogEntry> parse_log_line(std::string_view line) {
  // (SECONDS.MICROS) IFACE ID#HEX
  if (line.size() < 4 || line.front() != '(') return std::nullopt;
  const std::size_t close = line.find(") ");
  if (close == std::string_view::npos) return std::nullopt;
  LogEntry e;
  const std::string stamp(line.substr(1, close - 1));
  char* end = nullptr;
  e.time_s = std::strtod(stamp.c_str(), &end);
  if (end == stamp.c_str() || *end != '\0') return std::nullopt;
  const std::string_view rest = line.substr(close + 2);
  const std::size_t space = rest.find(' ');
  if (space == std::string_view::npos || space == 0) return std::nullopt;
  e.interface = std::string(rest.substr(0, space));
  std::string_view body = rest.substr(space + 1);
  while (!body.empty() && (body.back() == '\n' || body.back() == '\r' || body.back() == ' ')) body.remove_suffix(1);
  const std::size_t hash = body.find('#');
  if (hash == std::string_view::npos || (hash != 3 && hash != 8)) return std::nullopt;
  std::uint32_t id = 0;
  for (std::size_t i = 0; i < hash; ++i) {
    const int d = hex_digit(body[i]);
    if (d < 0) return std::nullopt;
    id = (id << 4) | static_cast<std::uint32_t>(d);
  }
  const std::string_view hex = body.substr(hash + 1);
  if (hex.size() % 2 != 0 || hex.size() > 16) return std::nullopt;
  if (hash == 8) {
    if ((id & CAN_ERR_FLAG) == 0) return std::nullopt;  // extended data frames are not ours
    e.frame.error = true;
    e.frame.id = id & CAN_ERR_MASK;
  } else {
    e.frame.id = id;
  }
  e.frame.len = static_cast<std::uint8_t>(hex.size() / 2);
  for (std::size_t i = 0; i < e.frame.len; ++i) {
    const int hi = hex_digit(hex[2 * i]);
    const int lo = hex_digit(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) return std::nullopt;
    e.frame.data[i] = static_cast<std::uint8_t>((hi << 4) | lo);
  }
  e.frame.rx_time_ns = static_cast<std::int64_t>(e.time_s * 1e9);
  return e;
}

namespace {

constexpr std::size_t kBatchLines = 512;  // lines formatted before one write(2)
constexpr auto kIdle = std::chrono::milliseconds(5);  // the writer's nap when the queue is empty
constexpr int kQueueFullKind = -1;  // report kinds beside errno values
constexpr int kCloseKind = -2;

}  // namespace

// The lines of one write(2): text, and where each line ends in it.
struct FrameLog::Batch {
  std::string text;
  std::vector<std::size_t> ends;  // offset one past each line's newline
  std::size_t prefix = 0;         // 1 when text starts with the newline that ends a partial line
};

FrameLog::FrameLog(const std::string& path, std::string interface, double close_timeout_s)
    : interface_(std::move(interface)),
      close_timeout_s_(close_timeout_s),
      sink_(FileSink(path)),
      queue_(std::make_unique<Queue>()) {
  check_input(close_timeout_s >= 0.0, "FrameLog", "close_timeout_s must be >= 0");
  writer_ = std::thread([this] { run(); });
}

FrameLog::~FrameLog() { close(); }

void FrameLog::record(const CanFrame& frame, double time_s) {
  if (!queue_->try_push(Entry{frame, time_s})) dropped_queue_full_.add();
}

void FrameLog::record(const CanFrame& frame) {
  if (clock_s_) {
    record(frame, clock_s_());
    return;
  }
  record(frame, frame.rx_time_ns != 0 ? static_cast<double>(frame.rx_time_ns) * 1e-9 : epoch_now_s());
}

bool FrameLog::flush() {
  const std::uint64_t target = queue_->pushed();
  wake_.notify_one();
  const double deadline_s = steady_now_s() + close_timeout_s_;
  while (resolved_.load() < target) {
    if (writer_done_.load(std::memory_order_acquire) || steady_now_s() > deadline_s) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

void FrameLog::close() {
  if (!writer_.joinable()) return;
  deadline_s_ = steady_now_s() + close_timeout_s_;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_.store(true, std::memory_order_release);
  }
  wake_.notify_all();
  writer_.join();
  const std::uint64_t left = dropped_at_close_.load() + queue_->size();
  if (left > 0) {
    char why[96];
    std::snprintf(why, sizeof why, "%llu frames not written within %.1f s at close were dropped",
                  static_cast<unsigned long long>(left), close_timeout_s_);
    report(why, kCloseKind);
  }
  // Some file systems (NFS) report a failed write only here.
  if (const int err = sink_.close(); err != 0) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (first_errno_ == 0) first_errno_ = err;
    }
    report(std::string("close failed: ") + std::strerror(err), err);
  }
}

FrameLogCounters FrameLog::counters() const {
  FrameLogCounters c;
  c.written = written_.load();
  c.dropped_queue_full = dropped_queue_full_.load();
  c.dropped_write_error = dropped_write_error_.load();
  // Once the writer is gone nothing leaves the queue: what is in it was recorded too late.
  c.dropped_at_close = dropped_at_close_.load() + (writer_done_.load(std::memory_order_acquire) ? queue_->size() : 0);
  const std::lock_guard<std::mutex> lock(mutex_);
  c.first_errno = first_errno_;
  c.first_error = first_error_;
  return c;
}

void FrameLog::run() {
  pthread_setname_np(pthread_self(), "pb-canlog");
  block_sigpipe_in_this_thread();
  Batch batch;
  batch.text.reserve(kBatchLines * 64);
  batch.ends.reserve(kBatchLines);
  for (;;) {
    report_queue_full();
    if (fill(batch)) {
      write_batch(batch);
      if (past_deadline()) break;
      continue;
    }
    if (stopping_.load(std::memory_order_acquire)) break;  // empty: everything recorded before close() is out
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait_for(lock, kIdle, [this] { return stopping_.load(std::memory_order_acquire); });
  }
  report_queue_full();
  writer_done_.store(true, std::memory_order_release);
}

// Formats up to kBatchLines queued frames; false when none waited.
bool FrameLog::fill(Batch& b) {
  b.text.clear();
  b.ends.clear();
  b.prefix = mid_line_ ? 1 : 0;
  if (mid_line_) b.text.push_back('\n');
  Entry e;
  while (b.ends.size() < kBatchLines && queue_->try_pop(e)) {
    b.text += format_log_line(e.frame, e.time_s, interface_);
    b.text.push_back('\n');
    b.ends.push_back(b.text.size());
  }
  return !b.ends.empty();
}

void FrameLog::write_batch(const Batch& b) {
  // A blocked sink is waited on until close()'s time runs out; meanwhile the queue fills and says so.
  const SinkWrite w = sink_.write(b.text.data(), b.text.size(), [this] {
    report_queue_full();
    return past_deadline();
  });
  if (w.error != 0 && w.error != ETIMEDOUT) on_write_error(w.error);
  std::size_t done = 0;
  while (done < b.ends.size() && b.ends[done] <= w.bytes) ++done;
  written_.add(done);
  const std::size_t lost = b.ends.size() - done;
  if (lost > 0) (w.error == ETIMEDOUT ? dropped_at_close_ : dropped_write_error_).add(lost);
  // A partial line left in the sink would run into the next one: the next batch starts with a newline.
  if (w.bytes > 0) mid_line_ = w.bytes != (done == 0 ? b.prefix : b.ends[done - 1]);
  resolved_.add(b.ends.size());
}

bool FrameLog::past_deadline() const {
  return stopping_.load(std::memory_order_acquire) && steady_now_s() > deadline_s_;
}

void FrameLog::on_write_error(int err) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (first_errno_ == 0) first_errno_ = err;
  }
  report(std::string("write failed: ") + std::strerror(err), err,
         sink_.gone() ? "every further frame is dropped (counted)" : "frames are dropped (counted) while it fails");
}

// Once per kind (an errno, a full queue, the close): the first goes to stderr at once, with
// what follows from it; the first of all is kept.
void FrameLog::report(const std::string& problem, int kind, const char* consequence) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!reported_kinds_.insert(kind).second) return;
  const std::string line = "CAN log " + sink_.path() + ": " + problem;
  if (first_error_.empty()) first_error_ = line;
  std::fprintf(stderr, "%s%s%s\n", line.c_str(), *consequence != '\0' ? "; " : "", consequence);
}

void FrameLog::report_queue_full() {
  const std::uint64_t n = dropped_queue_full_.load();
  if (n == queue_full_reported_) return;
  queue_full_reported_ = n;
  report("the writer fell behind (queue of " + std::to_string(kQueueFrames) + " frames full)", kQueueFullKind,
         "frames are dropped (counted)");
}

}  // namespace pinball::firmware
