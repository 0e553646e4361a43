#include "pinball/control/spastic_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace pinball::control {
namespace {

using track::kLeftFlipper;
using track::kRightFlipper;

// A tracker output whose projection says: flipper f, d_m away.
track::TrackerOutput heading_for(int flipper, double d_m, bool valid = true, bool hittable = true) {
  track::TrackerOutput out;
  out.projection.valid = valid;
  out.projection.reason = valid ? track::NoProjection::kNone : track::NoProjection::kNoImpact;
  out.projection.hittable = hittable;
  out.projection.flipper = flipper;
  out.projection.d_m = d_m;
  return out;
}

track::TrackerOutput nothing() { return track::TrackerOutput{}; }

// Settings spelled out, so the tests do not hang on the defaults.
SpasticConfig settings(double reach_m = 0.05, double max_hold_s = 1.0) {
  SpasticConfig c;
  c.reach_m = reach_m;
  c.max_hold_s = max_hold_s;
  return c;
}

TEST(SpasticController, FiresTheProjectedFlipperWithinReach) {
  SpasticController c(settings(0.05));
  std::array<bool, 2> on{false, false};
  c.update(heading_for(kRightFlipper, 0.06), 0.0, on);
  EXPECT_FALSE(on[kLeftFlipper] || on[kRightFlipper]);  // not yet
  c.update(heading_for(kRightFlipper, 0.05), 0.005, on);
  EXPECT_TRUE(on[kRightFlipper]);  // d <= reach
  EXPECT_FALSE(on[kLeftFlipper]);

  SpasticController c2(settings(0.05));
  std::array<bool, 2> on2{false, false};
  c2.update(heading_for(kLeftFlipper, 0.01), 0.0, on2);
  EXPECT_TRUE(on2[kLeftFlipper]);
  EXPECT_FALSE(on2[kRightFlipper]);
}

TEST(SpasticController, IgnoresInvalidOrUnhittableProjections) {
  SpasticController c(settings());
  std::array<bool, 2> on{false, false};
  c.update(heading_for(kLeftFlipper, 0.01, false, true), 0.0, on);
  c.update(heading_for(kLeftFlipper, 0.01, true, false), 0.0, on);
  c.update(nothing(), 0.0, on);
  EXPECT_FALSE(on[kLeftFlipper] || on[kRightFlipper]);
}

TEST(SpasticController, HoldsUntilLaunchOrLoss) {
  for (const bool launched : {true, false}) {
    SpasticController c(settings());
    std::array<bool, 2> on{false, false};
    c.update(heading_for(kLeftFlipper, 0.02), 0.0, on);
    ASSERT_TRUE(on[kLeftFlipper]);
    for (int i = 1; i < 100; ++i) {  // half a second of nothing: still up
      c.update(nothing(), 0.005 * i, on);
      ASSERT_TRUE(on[kLeftFlipper]) << i;
    }
    c.update(heading_for(kRightFlipper, 0.02), 0.5, on);  // the other one too
    EXPECT_TRUE(on[kLeftFlipper] && on[kRightFlipper]);
    track::TrackerOutput ev = nothing();
    (launched ? ev.launch.launched : ev.launch.lost) = true;
    c.update(ev, 0.505, on);
    EXPECT_FALSE(on[kLeftFlipper] || on[kRightFlipper]) << launched;
  }
}

TEST(SpasticController, LaunchWinsOverAProjectionInTheSameUpdate) {
  SpasticController c(settings());
  std::array<bool, 2> on{false, false};
  track::TrackerOutput out = heading_for(kLeftFlipper, 0.01);
  out.launch.launched = true;
  c.update(out, 0.0, on);
  EXPECT_FALSE(on[kLeftFlipper]);
}

TEST(SpasticController, ReleasesAfterMaxHold) {
  SpasticController c(settings(0.05, 1.0));
  std::array<bool, 2> on{false, false};
  c.update(heading_for(kRightFlipper, 0.03), 10.0, on);
  ASSERT_TRUE(on[kRightFlipper]);
  c.update(nothing(), 10.99, on);
  EXPECT_TRUE(on[kRightFlipper]);
  c.update(nothing(), 11.01, on);
  EXPECT_FALSE(on[kRightFlipper]);  // a cradled ball: let go
  // It may fire again on a new projection, and the hold clock restarts.
  c.update(heading_for(kRightFlipper, 0.03), 11.5, on);
  EXPECT_TRUE(on[kRightFlipper]);
  c.update(nothing(), 12.3, on);
  EXPECT_TRUE(on[kRightFlipper]);
  c.update(nothing(), 12.6, on);
  EXPECT_FALSE(on[kRightFlipper]);
}

TEST(SpasticController, SettingsOutOfRangeAreRefused) {
  EXPECT_FALSE(check_spastic_config(settings()));
  EXPECT_FALSE(check_spastic_config(settings(1.0, kMaxHold_s)));
  EXPECT_EQ(check_spastic_config(settings(0.0)).key, "reach_m");
  EXPECT_EQ(check_spastic_config(settings(1.5)).key, "reach_m");
  EXPECT_EQ(check_spastic_config(settings(std::nan(""))).key, "reach_m");
  // 0 would drop the coil on every update: no hold at all, not "no limit".
  EXPECT_EQ(check_spastic_config(settings(0.05, 0.0)).key, "max_hold_s");
  EXPECT_EQ(check_spastic_config(settings(0.05, kMaxHold_s + 1.0)).key, "max_hold_s");
  EXPECT_THROW(SpasticController(settings(-0.01)), std::invalid_argument);
}

TEST(SpasticController, ResetReleasesEverything) {
  SpasticController c(settings());
  std::array<bool, 2> on{false, false};
  c.update(heading_for(kLeftFlipper, 0.0), 0.0, on);
  c.update(heading_for(kRightFlipper, 0.0), 0.0, on);
  ASSERT_TRUE(on[kLeftFlipper] && on[kRightFlipper]);
  c.reset(on);
  EXPECT_FALSE(on[kLeftFlipper] || on[kRightFlipper]);
}

}  // namespace
}  // namespace pinball::control
