#pragma once
// Dates frames by the camera's own steady frame clock instead of the host's
// jittery arrival stamps. A camera exposes frame k at t0 + k·T (a crystal
// clock: microseconds of jitter), but the host stamps it on arrival, after a
// delay that varies by a millisecond or more with USB and scheduling. The
// delay is never below its minimum, so over a window of frames the smallest
// stamp − k·T is t0 + the minimum delay: the lower envelope, which a few dozen
// frames find to within tens of microseconds. Frames are then dated
// envelope + k·T: steady, and late by exactly the minimum latency, which the
// latency calibration measures on the same dates. Allocates nothing.

#include <array>
#include <cstdint>

namespace pinball::vision {

/// The window the detector dates frames over when a camera's timing is known:
/// 64 frames (0.32 s at 200 fps) leave about mean jitter / 64 (16 µs for 1 ms)
/// and a 50 ppm clock drift between camera and host moves the envelope by
/// 16 µs across it; a longer window would gain on the first and lose on the second.
inline constexpr int kDefaultDejitterFrames = 64;

/// The lower envelope of (host stamp − sequence · period) over recent frames.
class FrameDejitter {
 public:
  static constexpr int kMaxWindow = 256;  ///< longest window (frames)

  /// `period_s`: the camera's frame period; `window_frames`: frames in the envelope (1..kMaxWindow).
  /// Throws std::invalid_argument for a period <= 0 or a window out of range.
  FrameDejitter(double period_s, int window_frames);

  /// The steady stamp of frame `sequence` that the host stamped `host_stamp_s`
  /// (s). A sequence that goes backwards or jumps by more than the window
  /// restarts the envelope.
  double steady_stamp(std::uint64_t sequence, double host_stamp_s);

  /// Forgets every frame.
  void reset() { size_ = 0; }

  /// The frame period (s).
  double period_s() const { return period_s_; }

 private:
  double period_s_;
  int window_;
  std::array<double, kMaxWindow> offset_s_{};  // host stamp − (sequence − base) · period, ring
  std::uint64_t base_ = 0;                     // sequence the offsets are counted from
  std::uint64_t last_sequence_ = 0;
  int head_ = 0;
  int size_ = 0;
};

}  // namespace pinball::vision
