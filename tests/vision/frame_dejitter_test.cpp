#include "pinball/vision/frame_dejitter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pinball/core/rng.h"

namespace pinball::vision {
namespace {

constexpr double kPeriod_s = 0.005;

TEST(FrameDejitter, FindsTheSteadyClockUnderExponentialArrivalJitter) {
  // Exposed at 12.3 s + k·T, stamped 7 ms plus an exponential delay of mean 1 ms later.
  FrameDejitter dejitter(kPeriod_s, 64);
  Rng rng(3);
  double worst_after_window = 0.0;
  double raw_mean_error = 0.0;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    const double exposure = 12.3 + static_cast<double>(k) * kPeriod_s;
    const double stamp = exposure + 0.007 - 0.001 * std::log1p(-rng.uniform01());
    const double steady = dejitter.steady_stamp(1000 + k, stamp);
    EXPECT_LE(steady, stamp + 1e-12);  // never later than the frame's own stamp
    if (k >= 64) {
      worst_after_window = std::max(worst_after_window, std::abs(steady - (exposure + 0.007)));
      raw_mean_error += (stamp - (exposure + 0.007)) / 1936.0;
    }
  }
  EXPECT_LT(worst_after_window, 2e-4);  // the raw stamps are off by 1 ms on average
  EXPECT_NEAR(raw_mean_error, 0.001, 1e-4);
}

TEST(FrameDejitter, DroppedFramesKeepTheClockAndARestartForgetsIt) {
  FrameDejitter dejitter(kPeriod_s, 16);
  for (std::uint64_t k = 0; k < 20; ++k) dejitter.steady_stamp(k, 1.0 + k * kPeriod_s + (k % 3) * 1e-3);
  // Frames 20 and 21 dropped: frame 22 is still on the same clock.
  EXPECT_NEAR(dejitter.steady_stamp(22, 1.0 + 22 * kPeriod_s + 2e-3), 1.0 + 22 * kPeriod_s, 1e-12);
  // The camera restarts (its sequence goes back): a new clock, not the old one's.
  EXPECT_NEAR(dejitter.steady_stamp(0, 50.0), 50.0, 1e-12);
  // A gap longer than the window restarts it too.
  EXPECT_NEAR(dejitter.steady_stamp(100, 60.0), 60.0, 1e-12);
}

TEST(FrameDejitter, RefusesAPeriodOrWindowItCannotUse) {
  EXPECT_THROW(FrameDejitter(0.0, 8), std::invalid_argument);
  EXPECT_THROW(FrameDejitter(kPeriod_s, 0), std::invalid_argument);
  EXPECT_THROW(FrameDejitter(kPeriod_s, FrameDejitter::kMaxWindow + 1), std::invalid_argument);
  EXPECT_NO_THROW(FrameDejitter(kPeriod_s, FrameDejitter::kMaxWindow));
}

}  // namespace
}  // namespace pinball::vision
