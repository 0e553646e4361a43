#include "pinball/control/flipper_controller.h"

#include <gtest/gtest.h>

#include <limits>

#include "common/projections.h"

namespace pinball::control {
namespace {

// A ball rolling on the left flipper at 2 m/s, 0.1 m from its impact, seen 8 ms late.
track::TrackerOutput rolling_at(double d_m) {
  track::TrackerOutput o;
  o.projection = pinball::testing::hittable_projection(track::kLeftFlipper, -0.3, 0.5, 2.0, d_m);
  o.projection.rolling = true;  // advances at its speed: no fit needed
  o.projection.t_impact_s = d_m / 2.0;
  o.projection.latency_s = 0.008;
  return o;
}

TEST(ProjectionToActOn, WithoutALeadItIsTheNewestFramesProjection) {
  const track::TrackerOutput o = rolling_at(0.1);
  const track::TrajectoryProjection p = projection_to_act_on(o, std::nullopt);
  EXPECT_EQ(p.d_m, 0.1);
  EXPECT_EQ(p.t_impact_s, 0.05);
}

TEST(ProjectionToActOn, ALeadAdvancesByTheFramesLatencyPlusTheDelay) {
  // 8 ms of latency + 12 ms of delay at 2 m/s: 40 mm nearer, 20 ms sooner; θ, h and s stay.
  const track::TrajectoryProjection p = projection_to_act_on(rolling_at(0.1), 0.012);
  EXPECT_NEAR(p.d_m, 0.06, 1e-12);
  EXPECT_NEAR(p.t_impact_s, 0.03, 1e-12);
  EXPECT_EQ(p.angle_rad, -0.3);
  EXPECT_EQ(p.h, 0.5);
  EXPECT_EQ(p.speed_mps, 2.0);
  // Sooner than the lead: the coil is already late, d = 0.
  EXPECT_EQ(projection_to_act_on(rolling_at(0.01), 0.012).d_m, 0.0);
}

TEST(CheckLeadActuationDelay, AbsentAndZeroToATenthOfASecondAreInRange) {
  EXPECT_FALSE(check_lead_actuation_delay(std::nullopt));
  EXPECT_FALSE(check_lead_actuation_delay(0.0));
  EXPECT_FALSE(check_lead_actuation_delay(0.1));
  const RangeViolation v = check_lead_actuation_delay(0.5);
  EXPECT_EQ(v.key, "lead_actuation_delay_s");
  EXPECT_EQ(v.rule, "must be in [0, 0.1] s");
  EXPECT_TRUE(check_lead_actuation_delay(-0.001));
  EXPECT_TRUE(check_lead_actuation_delay(std::numeric_limits<double>::quiet_NaN()));
}

}  // namespace
}  // namespace pinball::control
