#include "pinball/control/actuator_controller.h"

#include <gtest/gtest.h>

namespace pinball::control {
namespace {

track::TrackerOutput approach(double d_m, int flipper = track::kLeftFlipper) {
  track::TrackerOutput o;
  o.projection.valid = true;
  o.projection.reason = track::NoProjection::kNone;
  o.projection.hittable = true;
  o.projection.flipper = flipper;
  o.projection.angle_rad = -1.2;
  o.projection.h = 0.5;
  o.projection.speed_mps = 1.0;
  o.projection.d_m = d_m;
  return o;
}

ActuatorController make(double a4, int flipper, double max_hold_s = 1.0) {
  ActionFunction af(uniform_partition(2));
  for (int i = 0; i < af.partitions(); ++i) af.minicontroller(i) = Minicontroller{{0.0, 0.0, 0.0, a4}, flipper};
  ActuatorConfig config;
  config.max_hold_s = max_hold_s;
  return ActuatorController(af, config);
}

TEST(ActuatorController, FiresExactlyOncePerApproachAndReleasesOnLaunch) {
  ActuatorController c = make(0.05, track::kRightFlipper);
  std::array<bool, 2> e{};
  double t = 0.0;
  for (double d = 0.3; d > 0.0; d -= 0.01, t += 0.005) c.update(approach(d), t, e);
  EXPECT_TRUE(e[track::kRightFlipper]);
  EXPECT_FALSE(e[track::kLeftFlipper]);
  EXPECT_EQ(c.fires(), 1);
  EXPECT_EQ(c.responsible_partition(), 0);
  // The flipper stays up (no re-fire) until a launch.
  track::TrackerOutput launch;
  launch.launch.launched = true;
  c.update(launch, t, e);
  EXPECT_FALSE(e[0]);
  EXPECT_FALSE(e[1]);
  EXPECT_EQ(c.responsible_partition(), -1);
  // A new approach fires again, once.
  for (double d = 0.3; d > 0.0; d -= 0.01, t += 0.005) c.update(approach(d), t, e);
  EXPECT_EQ(c.fires(), 2);
}

TEST(ActuatorController, ReleasesOnLossAndNeverFiresWithNegativeCritical) {
  ActuatorController c = make(0.05, track::kLeftFlipper);
  std::array<bool, 2> e{};
  c.update(approach(0.01), 0.0, e);
  EXPECT_TRUE(e[track::kLeftFlipper]);
  track::TrackerOutput lost;
  lost.launch.lost = true;
  c.update(lost, 0.01, e);
  EXPECT_FALSE(e[track::kLeftFlipper]);

  ActuatorController never = make(-0.01, track::kLeftFlipper);
  for (double d = 0.3; d >= 0.0; d -= 0.01) never.update(approach(d), 0.0, e);
  EXPECT_EQ(never.fires(), 0);
}

TEST(ActuatorController, IgnoresUnhittableAndInvalidProjections) {
  ActuatorController c = make(0.5, track::kLeftFlipper);
  std::array<bool, 2> e{};
  track::TrackerOutput o = approach(0.01);
  o.projection.hittable = false;
  c.update(o, 0.0, e);
  o = approach(0.01);
  o.projection.valid = false;
  c.update(o, 0.0, e);
  EXPECT_EQ(c.fires(), 0);
  EXPECT_FALSE(e[0]);
}

TEST(ActuatorController, ReleasesACradledBallAfterMaxHold) {
  ActuatorController c = make(0.05, track::kLeftFlipper, 0.5);
  std::array<bool, 2> e{};
  c.update(approach(0.01), 0.0, e);
  track::TrackerOutput none;  // no projection while cradled
  c.update(none, 0.4, e);
  EXPECT_TRUE(e[0]);
  c.update(none, 0.6, e);
  EXPECT_FALSE(e[0]);
  c.update(approach(0.01), 0.7, e);  // a new approach after the release
  EXPECT_TRUE(e[0]);
  EXPECT_EQ(c.fires(), 2);
}

TEST(ActuatorController, WithALeadItFiresWhereTheBallWillBeWhenTheCoilActs) {
  // d_critical 0.05 m; the ball approaches at 1 m/s; 10 ms of latency plus
  // 20 ms of actuation delay put it 0.03 m further on when the coil acts.
  ActionFunction af(uniform_partition(2));
  for (int i = 0; i < af.partitions(); ++i) af.minicontroller(i) = Minicontroller{{0.0, 0.0, 0.0, 0.05}, 0};
  ActuatorConfig led_config;
  led_config.lead_actuation_delay_s = 0.02;
  ActuatorController led(af, led_config);
  ActuatorController plain(af, ActuatorConfig{});
  std::array<bool, 2> e_led{}, e_plain{};
  track::TrackerOutput o = approach(0.075);
  o.projection.t_impact_s = 0.075;  // 1 m/s
  o.projection.latency_s = 0.01;
  o.projection.rolling = true;      // advances at its speed (no fit needed)
  led.update(o, 0.0, e_led);
  plain.update(o, 0.0, e_plain);
  EXPECT_TRUE(e_led[0]);    // 0.075 − 0.03 = 0.045 <= 0.05
  EXPECT_FALSE(e_plain[0]); // 0.075 > 0.05
  ActuatorConfig bad;
  bad.lead_actuation_delay_s = 0.5;
  EXPECT_THROW(ActuatorController(af, bad), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::control
