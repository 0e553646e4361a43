// Grazing contact: a ball flying over a circle whose parabola's apex passes
// exactly R + r above the circle's centre (a double root of the impact
// quartic), and just inside or outside that. It may hit or miss, but must not
// end inside the circle or gain energy; the exact stepper must hit whenever
// the true path overlaps by 1 µm or more.

#include <cmath>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class GrazeTest : public ::testing::Test {};
TYPED_TEST_SUITE(GrazeTest, Steppers, StepperNames);

TYPED_TEST(GrazeTest, TangentToACircleAtTheApex) {
  using Traits = StepperTraits<TypeParam>;
  const double g = 1.11, vx = 1.0, circle_r = 0.03;
  const Vec2 c{0.5, 0.4};
  for (double offset : {-1e-6, -1e-9, 0.0, 1e-9, 1e-6}) {
    table::Board b = empty_board(1.0, 1.0, g, 5e-4);
    add_circle(b, c, circle_r, 1.0);
    const auto stepper = Traits::make(b, 5e-4);
    // Apex above the centre at height R + r + offset, reached at t = 0.2 s.
    const double apex_y = c.y() + circle_r + kBallR + offset;
    const double t_apex = 0.2;
    GameState s = state_with_ball(b, {c.x() - vx * t_apex, apex_y - 0.5 * g * t_apex * t_apex}, {vx, g * t_apex});
    Checker<TypeParam> check(stepper, s, false, 100);
    const long n = static_cast<long>(0.4 / 5e-4);  // to 0.2 s past the apex
    ASSERT_TRUE(run_checked(stepper, s, n, check)) << Traits::kName << " offset " << offset;
    // Free flight would be back at the start height with vy = −g t_apex.
    const double vy_free = -g * t_apex;
    const bool hit = std::abs(s.ball.velocity_mps.y() - vy_free) > 1e-9 || std::abs(s.ball.velocity_mps.x() - vx) > 1e-9;
    if (Traits::kExact && offset <= -1e-6) {
      EXPECT_TRUE(hit) << "missed a 1 um overlap";
    }
    if (Traits::kExact && offset >= 1e-9) {
      EXPECT_FALSE(hit) << "hit a circle the path clears by " << offset;
    }
    note("graze %s offset %+.0e m: %s, velocity change (%.2e, %.2e) m/s, %llu events", Traits::kName, offset,
         hit ? "hit" : "missed", s.ball.velocity_mps.x() - vx, s.ball.velocity_mps.y() - vy_free,
         static_cast<unsigned long long>(s.events));
  }
}

}  // namespace
}  // namespace pinball::sim::testing
