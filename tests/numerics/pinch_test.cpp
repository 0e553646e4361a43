// A flipper pinching the ball against a wall: the ball is shut in a pocket
// whose roof is closer to the raised flipper than the ball's diameter, and the
// flipper is pressed and released. It must stall (or stop) rather than push
// the ball through the roof, and the squeeze must not blow up the event count
// (a ball bouncing between a moving face and a wall is a classic Zeno trap).

#include <cmath>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class PinchTest : public ::testing::Test {};
TYPED_TEST_SUITE(PinchTest, Steppers, StepperNames);

TYPED_TEST(PinchTest, FlipperPinchesTheBallAgainstAWall) {
  using Traits = StepperTraits<TypeParam>;
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  b.ball.speed_max_mps = 5.0;
  const int fl = add_flipper(b, table::Side::kLeft, {0.3, 0.3}, 0.076, -0.4, 0.6, 33.0, 0.5, 1.0);
  const FlipperPocket pocket = add_flipper_pocket(b, fl);
  const table::Flipper& f = b.flippers[fl];
  const auto stepper = Traits::make(b, 5e-4);
  GameState s = state_with_ball(
      b, f.pivot + 0.05 * table::flipper_direction(f, f.theta_min_rad) + (kBallR + 1e-6) * table::flipper_up_normal(f, f.theta_min_rad),
      Vec2::Zero());
  // The flipper supplies energy; the bound is on events: 3 s of squeezing.
  Checker<TypeParam> check(stepper, s, true, 30000);
  const Vec2 roof_n = perp_left(pocket.roof1 - pocket.roof0).normalized();  // points away from the pocket
  double max_theta = -INFINITY, max_speed = 0.0, closest_roof = INFINITY;
  ASSERT_TRUE(run_checked(
      stepper, s, static_cast<long>(3.0 / 5e-4), check,
      [](GameState& st, long i) { st.flippers[0].energized = (i / 1500) % 2 == 0; },
      [&](const GameState& st, long i) {
        max_theta = std::max(max_theta, st.flippers[0].theta_rad);
        max_speed = std::max(max_speed, st.ball.velocity_mps.norm());
        const Vec2& q = st.ball.position_m;
        closest_roof = std::min(closest_roof, -(q - pocket.roof0).dot(roof_n));
        ASSERT_GT(q.x(), pocket.left_x) << "escaped at step " << i;
        ASSERT_LT(q.x(), pocket.right_x) << "escaped at step " << i;
      }))
      << Traits::kName;
  EXPECT_LT(max_theta, f.theta_max_rad) << "the flipper rose through the ball";
  EXPECT_GT(closest_roof, kBallR - Traits::kMaxDepth_m) << "pushed into the roof";
  EXPECT_LE(max_speed, b.ball.speed_max_mps * (1.0 + 1e-12)) << "the clamp caps what the flipper supplies";
  note("pinch %s: highest flipper angle %.4f rad (up stop %.1f), closest to the roof %.2e m past contact, top speed "
       "%.2f m/s, %llu events in 3 s",
       Traits::kName, max_theta, f.theta_max_rad, closest_roof - kBallR, max_speed,
       static_cast<unsigned long long>(s.events));
}

}  // namespace
}  // namespace pinball::sim::testing
