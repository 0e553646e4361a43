#pragma once
// A counter that one thread increments and any thread may read, without a
// lock and without a read-modify-write (there is one writer): the counters
// of the daemon's stages, which the LCM thread reports once a second while
// the stages run.

#include <atomic>
#include <cstdint>

namespace pinball {

/// Incremented by its owning thread only; read from anywhere.
class SingleWriterCounter {
 public:
  /// Adds `n` (the owning thread only).
  void add(std::uint64_t n = 1) { value_.store(value_.load(std::memory_order_relaxed) + n, std::memory_order_relaxed); }
  /// The count (any thread).
  std::uint64_t load() const { return value_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> value_{0};
};

}  // namespace pinball
