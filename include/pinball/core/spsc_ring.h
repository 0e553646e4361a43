#pragma once
// A bounded single-producer / single-consumer queue of plain values: one
// thread pushes, one thread pops, neither blocks nor allocates. The hand-off
// between the daemon's real-time threads (camera -> controller -> driver) and
// to the LCM publisher, where a lock or a malloc would add jitter.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace pinball {

/// Fixed-capacity SPSC ring; Capacity must be a power of two.
template <class T, std::size_t Capacity>
class SpscRing {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "capacity must be a power of two");

 public:
  /// Copies `value` in; false (and nothing stored) when the ring is full.
  bool try_push(const T& value) {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_.load(std::memory_order_acquire) >= Capacity) return false;
    slots_[tail & (Capacity - 1)] = value;
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Moves the oldest value out; false when the ring is empty.
  bool try_pop(T& out) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return false;
    out = slots_[head & (Capacity - 1)];
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Values waiting (a snapshot; exact only from the consumer's thread).
  std::size_t size() const {
    return static_cast<std::size_t>(tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_acquire));
  }
  /// True when nothing waits.
  bool empty() const { return size() == 0; }
  /// Values pushed since construction (for waiting on progress).
  std::uint64_t pushed() const { return tail_.load(std::memory_order_acquire); }
  /// The capacity.
  static constexpr std::size_t capacity() { return Capacity; }

 private:
  std::array<T, Capacity> slots_{};
  alignas(64) std::atomic<std::uint64_t> head_{0};  // next slot to pop
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // next slot to push
};

}  // namespace pinball
