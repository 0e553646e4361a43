#include "pinball/control/cradle_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace pinball::control {
namespace {

using track::kLeftFlipper;
using track::kRightFlipper;

constexpr double kFrame_s = 0.005;  // 200 fps

// The ball on bat `bat` (its contact switch closed) at `p`: the tracker's rolling projection,
// which aims at the other bat.
track::TrackerOutput on_bat(int bat, const Vec2& p) {
  track::TrackerOutput out;
  out.projection.valid = true;
  out.projection.reason = track::NoProjection::kNone;
  out.projection.rolling = true;
  out.projection.flipper = 1 - bat;
  out.ball_m = p;
  return out;
}

// The ball in flight, up the table.
track::TrackerOutput in_flight(const Vec2& p) {
  track::TrackerOutput out;
  out.projection.reason = track::NoProjection::kOutsideCritical;
  out.ball_m = p;
  return out;
}

CradleConfig cradle_settings() {
  CradleConfig c;
  c.drop_s = 0.09;
  c.rest_s = 0.3;
  c.still_band_m = 0.006;
  c.max_hold_s = 4.0;
  return c;
}

TEST(CradleController, HoldsBothBatsUpAndDropsTheCradlingOneForTheDropTime) {
  CradleController c(cradle_settings());
  std::array<bool, 2> on{false, false};
  double t = 0.0;
  c.update(in_flight({0.25, 0.6}), t, on);
  EXPECT_TRUE(on[kLeftFlipper] && on[kRightFlipper]) << "both up, for whatever comes down";
  // The ball lands on the left bat, rolls into the crook and lies still (2 mm jitter: the camera's pixels).
  for (int k = 0; k < 10; ++k) c.update(on_bat(kLeftFlipper, {0.19 + 0.008 * (10 - k), 0.15}), t += kFrame_s, on);
  const double still_from = t + kFrame_s;
  double dropped_at = -1.0;
  for (int k = 0; k < 100 && dropped_at < 0.0; ++k) {
    c.update(on_bat(kLeftFlipper, {0.19 + (k % 2 ? 0.002 : 0.0), 0.15 + (k % 3 ? 0.002 : 0.0)}), t += kFrame_s, on);
    if (!on[kLeftFlipper]) dropped_at = t;
  }
  ASSERT_GT(dropped_at, 0.0) << "never dropped";
  EXPECT_NEAR(dropped_at - still_from, 0.3, kFrame_s + 1e-9) << "after rest_s still";
  EXPECT_TRUE(on[kRightFlipper]) << "the other bat stays up";
  EXPECT_EQ(c.drops(), 1);
  // Down for the drop time, whatever the ball does meanwhile; up on the first frame after it.
  double raised_at = -1.0;
  for (int k = 0; k < 40 && raised_at < 0.0; ++k) {
    c.update(on_bat(kLeftFlipper, {0.22, 0.14}), t += kFrame_s, on);
    if (on[kLeftFlipper]) raised_at = t;
  }
  EXPECT_GE(raised_at - dropped_at, 0.09 - 1e-9);
  EXPECT_LT(raised_at - dropped_at, 0.09 + kFrame_s);
}

TEST(CradleController, ABallStillMovingOnTheBatIsNotCradled) {
  CradleController c(cradle_settings());
  std::array<bool, 2> on{false, false};
  double t = 0.0;
  for (int k = 0; k < 400; ++k) {  // 2 s rocking 8 mm either way: never still within 6 mm for 0.3 s
    c.update(on_bat(kRightFlipper, {0.31 + 0.008 * std::sin(k * 0.2), 0.15}), t += kFrame_s, on);
    ASSERT_TRUE(on[kLeftFlipper] && on[kRightFlipper]) << k;
  }
  EXPECT_EQ(c.drops(), 0);
}

TEST(CradleController, ABatUpForMaxHoldIsDroppedOneUpdateUnderTheBoardsHoldCap) {
  CradleController c(cradle_settings());
  std::array<bool, 2> on{false, false};
  double t = 0.0;
  int down_updates = 0;
  double first_down = -1.0;
  for (int k = 0; k < 1000; ++k) {  // 5 s of a ball up the table
    c.update(in_flight({0.25, 0.7}), t += kFrame_s, on);
    if (!on[kLeftFlipper]) {
      ++down_updates;
      if (first_down < 0.0) first_down = t;
    }
  }
  EXPECT_EQ(down_updates, 1);
  EXPECT_NEAR(first_down, kFrame_s + 4.0, kFrame_s + 1e-9);
  EXPECT_TRUE(on[kLeftFlipper] && on[kRightFlipper]);
}

TEST(CradleController, ALostBallReleasesEverything) {
  CradleController c(cradle_settings());
  std::array<bool, 2> on{false, false};
  c.update(in_flight({0.25, 0.6}), 0.0, on);
  track::TrackerOutput lost;
  lost.launch.lost = true;
  c.update(lost, 0.005, on);
  EXPECT_FALSE(on[kLeftFlipper] || on[kRightFlipper]);
}

TEST(CradleController, SettingsOutOfRangeAreRefused) {
  EXPECT_FALSE(check_cradle_config(cradle_settings()));
  CradleConfig c = cradle_settings();
  c.drop_s = 0.0;
  EXPECT_EQ(check_cradle_config(c).key, "drop_s");
  c = cradle_settings();
  c.still_band_m = NAN;
  EXPECT_EQ(check_cradle_config(c).key, "still_band_m");
  c = cradle_settings();
  c.max_hold_s = 11.0;
  EXPECT_EQ(check_cradle_config(c).key, "max_hold_s");
  c = cradle_settings();
  c.max_hold_s = 0.35;  // re-raised before a resting ball could be dropped
  EXPECT_EQ(check_cradle_config(c).key, "max_hold_s");
  EXPECT_THROW(CradleController{c}, std::invalid_argument);
}

}  // namespace
}  // namespace pinball::control
