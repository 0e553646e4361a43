// A ball resting on a raised flipper rolls down it and off over the pivot
// end. The flipper sits on its up stop (θ̇ = 0), so it supplies no energy.

#include <cmath>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class FlipperRestTest : public ::testing::Test {};
TYPED_TEST_SUITE(FlipperRestTest, Steppers, StepperNames);

TYPED_TEST(FlipperRestTest, RollsDownARaisedFlipperAndOff) {
  using Traits = StepperTraits<TypeParam>;
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  const int fl = add_flipper(b, table::Side::kLeft, {0.3, 0.3}, 0.076, -0.5, 0.5, 33.0, 0.5, 1.0);
  const table::Flipper& f = b.flippers[fl];
  const auto stepper = Traits::make(b, 5e-4);
  const double start_along = 0.06;
  GameState s = state_with_ball(
      b, f.pivot + start_along * table::flipper_direction(f, f.theta_max_rad) + kBallR * table::flipper_up_normal(f, f.theta_max_rad),
      Vec2::Zero());
  s.flippers[fl].theta_rad = f.theta_max_rad;
  s.flippers[fl].energized = true;
  s.flippers[fl].was_energized = true;
  Checker<TypeParam> check(stepper, s, false, 2000);
  // Frictionless sliding from rest: s = ½ g sinθ t² reaches the pivot at t_pivot.
  const double t_pivot = std::sqrt(2.0 * start_along / (1.11 * std::sin(f.theta_max_rad)));
  double left_at = -1.0;
  double max_gap_on_face = 0.0;
  ASSERT_TRUE(run_checked(stepper, s, static_cast<long>(1.5 / 5e-4), check, [](GameState&, long) {},
                          [&](const GameState& st, long i) {
                            const Vec2 rel = st.ball.position_m - f.pivot;
                            const double along = rel.dot(table::flipper_direction(f, f.theta_max_rad));
                            const double height = rel.dot(table::flipper_up_normal(f, f.theta_max_rad)) - kBallR;
                            if (along > 0.0 && left_at < 0.0) max_gap_on_face = std::max(max_gap_on_face, height);
                            if (along < -kBallR && left_at < 0.0) left_at = (i + 1) * 5e-4;
                          }));
  ASSERT_GT(left_at, 0.0) << Traits::kName << ": the ball never rolled off the flipper";
  // It leaves over the pivot end, about when frictionless sliding says.
  EXPECT_NEAR(left_at, t_pivot, 0.15) << Traits::kName;
  EXPECT_LT(s.ball.position_m.y(), f.pivot.y()) << "it falls after leaving the flipper";
  EXPECT_LT(max_gap_on_face, Traits::kExact ? 1e-9 : 1e-4) << Traits::kName << ": bounced off the face";
  note("flipper_rest %s: left the face past the pivot at %.4f s (frictionless slide to the pivot %.4f s), largest gap "
       "above the face while on it %.2e m, %llu events",
       Traits::kName, left_at, t_pivot, max_gap_on_face, static_cast<unsigned long long>(s.events));
}

TYPED_TEST(FlipperRestTest, SlidesOffTheFreeEndOfAnIncline) {
  // The static counterpart: a ball sliding down a 10° line leaves its free
  // lower end and falls; it must not stop at the edge.
  using Traits = StepperTraits<TypeParam>;
  table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
  add_box(b, 1.0, 1.0, 0.5);  // catches it afterwards
  const double slope = 0.1745;  // 10°
  const Vec2 p0{0.0, 0.5}, p1{0.9, 0.5 - 0.9 * std::tan(slope)};
  add_line(b, p0, p1, 0.5);
  const auto stepper = Traits::make(b, 5e-4);
  // On the line at rest, its centre r above the surface along the normal.
  GameState s = state_with_ball(b, {0.05, 0.5 - 0.05 * std::tan(slope) + kBallR / std::cos(slope)}, Vec2::Zero());
  Checker<TypeParam> check(stepper, s, false, 2000);
  // Frictionless: the centre passes the end at t = sqrt(2 s / (g sin α)).
  const double t_end = std::sqrt(2.0 * (0.85 / std::cos(slope)) / (1.11 * std::sin(slope)));
  double passed_at = -1.0;
  ASSERT_TRUE(run_checked(stepper, s, static_cast<long>((t_end + 0.5) / 5e-4), check, [](GameState&, long) {},
                          [&](const GameState& st, long i) {
                            if (passed_at < 0.0 && st.ball.position_m.x() > p1.x() + kBallR) passed_at = (i + 1) * 5e-4;
                          }))
      << Traits::kName;
  ASSERT_GT(passed_at, 0.0) << Traits::kName << ": stopped at the end of the line";
  EXPECT_NEAR(passed_at, t_end, 0.1) << Traits::kName;
  note("incline_end %s: passed the free end at %.4f s (frictionless %.4f s), %llu events", Traits::kName, passed_at,
       t_end, static_cast<unsigned long long>(s.events));
}

}  // namespace
}  // namespace pinball::sim::testing
