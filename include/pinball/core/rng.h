#pragma once
// Deterministic random numbers: xoshiro256** seeded through splitmix64.
// The standard library's distributions differ between implementations, so we
// draw our own to keep "same seed, same bits" on every platform.

#include <cstdint>

namespace pinball {

/// A small, fast, reproducible generator; copying it forks the stream.
class Rng {
 public:
  /// Seeds all 256 bits of state from one 64-bit seed.
  explicit Rng(std::uint64_t seed = 0);

  /// Next 64 random bits.
  std::uint64_t next_u64();

  /// Uniform double in [0, 1) with 53 random bits.
  double uniform01() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

  /// Uniform double in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }

  /// Standard normal deviate (Box–Muller; deterministic, no cached second value).
  double normal();

 private:
  std::uint64_t s_[4];
};

/// Mixes a run seed and a ball index into a ball seed (splitmix64): ball i of
/// a run plays ball_seed(seed, i) wherever it is played (any thread, world or command).
std::uint64_t ball_seed(std::uint64_t run_seed, std::uint64_t index);

}  // namespace pinball
