#pragma once
// Wakes a sleeping thread: an eventfd that one side rings and the other waits
// on with a timeout. Ringing is one write(2), async-signal-safe, no lock and
// no allocation, so signal handlers and real-time threads may ring it.

namespace pinball::daemon {

/// A counting wake-up signal.
class Doorbell {
 public:
  /// Throws std::runtime_error when no eventfd can be made.
  Doorbell();
  ~Doorbell();
  Doorbell(const Doorbell&) = delete;
  Doorbell& operator=(const Doorbell&) = delete;

  /// Wakes the waiter (async-signal-safe).
  void ring() const;
  /// Waits until rung or `timeout_s` passed (negative: forever); consumes the rings.
  /// True when it was rung.
  bool wait(double timeout_s) const;

 private:
  int fd_ = -1;
};

}  // namespace pinball::daemon
