#include "pinball/firmware/liveness.h"

#include <cmath>
#include <stdexcept>

#include "pinball/core/check.h"

namespace pinball::firmware {

Liveness::Liveness(double timeout_s) : timeout_s_(timeout_s) {
  check_input(std::isfinite(timeout_s) && timeout_s > 0.0, "Liveness", "timeout_s must be > 0");
  for (auto& b : beats_) b.store(-1e300, std::memory_order_relaxed);
}

int Liveness::watch(const char* name) {
  if (count_ >= kMaxWatched) throw std::length_error("Liveness: at most 4 watched threads");
  names_[static_cast<std::size_t>(count_)] = name;
  return count_++;
}

int Liveness::stalled(double now_s) const {
  for (int i = 0; i < count_; ++i) {
    if (age_s(i, now_s) >= timeout_s_) return i;
  }
  return -1;
}

}  // namespace pinball::firmware
