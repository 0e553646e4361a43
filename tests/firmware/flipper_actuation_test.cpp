#include "pinball/firmware/flipper_actuation.h"

#include <gtest/gtest.h>

namespace pinball::firmware {
namespace {

TEST(FlipperActuation, FollowsTheCoilAfterTheDelay) {
  FlipperActuation a(1, 0.004);
  EXPECT_FALSE(a.energized(0.0));
  a.on_coil_change(1, {CoilState::kPulse, 1.0, 1.000});
  a.on_coil_change(0, {CoilState::kPulse, 1.0, 1.000});  // another driver: ignored
  EXPECT_FALSE(a.energized(1.0039));
  EXPECT_TRUE(a.energized(1.0040));
  a.on_coil_change(1, {CoilState::kHold, 0.25, 1.030});
  EXPECT_TRUE(a.energized(1.040));
  a.on_coil_change(1, {CoilState::kOff, 0.0, 1.100});
  EXPECT_TRUE(a.energized(1.103));
  EXPECT_FALSE(a.energized(1.105));
}

TEST(FlipperActuation, ZeroDelayAndBadArguments) {
  FlipperActuation a(0, 0.0);
  a.on_coil_change(0, {CoilState::kPulse, 1.0, 2.0});
  EXPECT_TRUE(a.energized(2.0));
  EXPECT_THROW(FlipperActuation(0, -0.001), std::invalid_argument);
  EXPECT_THROW(FlipperActuation(8, 0.001), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::firmware
