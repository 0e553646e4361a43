#include "pinball/firmware/flipper_actuation.h"

#include <cmath>
#include <stdexcept>

namespace pinball::firmware {

FlipperActuation::FlipperActuation(int driver, double delay_s) : driver_(driver), delay_s_(delay_s) {
  if (!std::isfinite(delay_s) || delay_s < 0.0) throw std::invalid_argument("FlipperActuation: delay_s must be finite and >= 0");
  if (driver < 0 || driver >= kMaxDrivers) throw std::invalid_argument("FlipperActuation: driver must be 0..7");
}

void FlipperActuation::on_coil_change(int driver, const CoilOutput& output) {
  if (driver != driver_) return;
  const bool on = output.state != CoilState::kOff;
  if (count_ == kCapacity) {  // more changes than fit in one delay: apply the oldest now
    state_ = pending_[static_cast<std::size_t>(head_)].on;
    head_ = (head_ + 1) % kCapacity;
    --count_;
  }
  pending_[static_cast<std::size_t>((head_ + count_) % kCapacity)] = Change{output.since_s, on};
  ++count_;
}

bool FlipperActuation::energized(double now_s) {
  // A picosecond of slack: simulated time is a sum of steps and lands a hair
  // short of the exact due time.
  while (count_ > 0 && pending_[static_cast<std::size_t>(head_)].t_s + delay_s_ <= now_s + 1e-12) {
    state_ = pending_[static_cast<std::size_t>(head_)].on;
    head_ = (head_ + 1) % kCapacity;
    --count_;
  }
  return state_;
}

}  // namespace pinball::firmware
