#include "pinball/vision/frame_dejitter.h"

#include <algorithm>
#include <cmath>

#include "pinball/core/check.h"

namespace pinball::vision {

FrameDejitter::FrameDejitter(double period_s, int window_frames) : period_s_(period_s), window_(window_frames) {
  check_input(std::isfinite(period_s) && period_s > 0.0, "frame dejitter", "period_s must be > 0");
  check_input(window_frames >= 1 && window_frames <= kMaxWindow, "frame dejitter",
              "window_frames must be in [1, " + std::to_string(kMaxWindow) + "]");
}

double FrameDejitter::steady_stamp(std::uint64_t sequence, double host_stamp_s) {
  if (size_ > 0 && (sequence <= last_sequence_ || sequence - last_sequence_ > static_cast<std::uint64_t>(window_))) {
    size_ = 0;
  }
  if (size_ == 0) {
    base_ = sequence;
    head_ = 0;
  }
  last_sequence_ = sequence;
  // Offsets count from base_, so their size stays that of a stamp, however long the run.
  const double k = static_cast<double>(sequence - base_);
  const double offset = host_stamp_s - k * period_s_;
  offset_s_[static_cast<std::size_t>((head_ + size_) % kMaxWindow)] = offset;
  if (size_ < window_) {
    ++size_;
  } else {
    head_ = (head_ + 1) % kMaxWindow;
  }
  double envelope = offset;
  for (int i = 0; i < size_; ++i) envelope = std::min(envelope, offset_s_[static_cast<std::size_t>((head_ + i) % kMaxWindow)]);
  return envelope + k * period_s_;
}

}  // namespace pinball::vision
