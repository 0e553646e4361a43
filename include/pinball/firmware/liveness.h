#pragma once
// Progress beats of the threads whose work keeps the coils meaningful (the
// camera and the controller): each watched thread calls beat() as it makes
// progress, lock-free; DriverBus sends the board's heartbeat only while every
// one has beaten within the timeout. A stalled chain therefore stops the
// heartbeats, and the board switches every coil off within its watchdog, even
// when the thread that would have noticed the stall is the one that stalled.

#include <array>
#include <atomic>
#include <string>

namespace pinball::firmware {

/// The watched threads' last beats, on the same clock as the DriverBus polls.
class Liveness {
 public:
  /// Threads one Liveness can watch.
  static constexpr int kMaxWatched = 4;

  /// A thread whose last beat is older than `timeout_s` (s, > 0) has stalled.
  /// Throws std::invalid_argument for a bad timeout.
  explicit Liveness(double timeout_s);

  /// Adds a watched thread named `name` (static string) before any beat;
  /// returns its index. It counts as stalled until its first beat. Throws
  /// std::length_error past kMaxWatched.
  int watch(const char* name);
  /// Thread `index` made progress at `now_s`. Lock-free, allocation-free.
  void beat(int index, double now_s) { beats_[static_cast<std::size_t>(index)].store(now_s, std::memory_order_release); }
  /// Thread `index` finished its work on purpose: it never counts as stalled again.
  void retire(int index) { beat(index, 1e300); }
  /// The first watched thread without a beat in (now_s - timeout_s, ...], or -1.
  int stalled(double now_s) const;
  /// True once thread `index` has beaten (before that it is starting, not stalled).
  bool started(int index) const { return beats_[static_cast<std::size_t>(index)].load(std::memory_order_acquire) > -1e299; }
  /// The name given to watch().
  const char* name(int index) const { return names_[static_cast<std::size_t>(index)]; }
  /// Age of thread `index`'s last beat at `now_s` (s).
  double age_s(int index, double now_s) const {
    return now_s - beats_[static_cast<std::size_t>(index)].load(std::memory_order_acquire);
  }
  /// Threads watched.
  int count() const { return count_; }
  /// The timeout (s).
  double timeout_s() const { return timeout_s_; }

 private:
  double timeout_s_;
  int count_ = 0;
  std::array<const char*, kMaxWatched> names_{};
  std::array<std::atomic<double>, kMaxWatched> beats_{};
};

}  // namespace pinball::firmware
