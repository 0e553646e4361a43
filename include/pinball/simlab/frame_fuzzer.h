#pragma once
// Random and mutated CAN frame streams for the protocol property test and
// `pinball bench protocol`: mostly plausible host traffic (Hello, Configure
// with extreme but valid settings, Fire, Release, heartbeats with fresh,
// repeated and wild sequence numbers), some of it with bits flipped (half of
// those with the CRC made right again, so the range checks are reached), and
// some pure noise in our id range. Deterministic by seed.

#include <cstdint>

#include "pinball/core/rng.h"
#include "pinball/firmware/can_frame.h"

namespace pinball::simlab {

/// What the stream holds.
struct FrameFuzzerOptions {
  std::uint64_t seed = 1;       ///< random stream
  std::uint8_t board_id = 0;    ///< the board under test (3 % of frames go to another)
  int driver_count = 2;         ///< drivers fitted (Fires also name one past them)
  double mutate_p = 0.25;       ///< a plausible frame gets 1 to 3 bits flipped
  double noise_p = 0.05;        ///< a frame is random bytes on a random id of ours
};

/// Counts of what was generated.
struct FrameFuzzerCounters {
  std::uint64_t frames = 0;   ///< all
  std::uint64_t mutated = 0;  ///< bits flipped
  std::uint64_t noise = 0;    ///< random bytes
};

/// The generator.
class FrameFuzzer {
 public:
  /// Throws std::invalid_argument for probabilities outside [0, 1] or a bad board or driver count.
  explicit FrameFuzzer(FrameFuzzerOptions options);
  /// The next frame, and the board time that passes before it arrives (s).
  firmware::CanFrame next(double& dt_s);
  /// What was generated so far.
  const FrameFuzzerCounters& counters() const { return counters_; }

 private:
  firmware::CanFrame plausible();
  double time_step_s();
  int below(int n) { return static_cast<int>(rng_.uniform01() * n); }
  std::uint16_t next_seq();

  FrameFuzzerOptions options_;
  Rng rng_;
  std::uint16_t seq_ = 0;
  FrameFuzzerCounters counters_;
};

}  // namespace pinball::simlab
