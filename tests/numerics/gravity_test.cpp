// Gravity 0 (straight lines: the impact polynomials lose their leading
// coefficient) and 10x the table's (faster bounces, deeper steps into
// surfaces): a box with bumpers of ρ ≤ 1, a Zeno bounce and a slide.

#include <cmath>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

table::Board gravity_board(double g) {
  table::Board b = box_board(0.9, g, 5e-4);
  b.ball.speed_max_mps = 50.0;
  add_circle(b, {0.15, 0.70}, 0.03, 1.0);
  add_circle(b, {0.35, 0.72}, 0.03, 0.8);
  add_point(b, {0.40, 0.45}, 0.9);
  add_wall(b, {0.05, 0.40}, {0.15, 0.30}, 0.7);
  add_wall(b, {0.46, 0.40}, {0.36, 0.30}, 0.7);
  add_line(b, {0.0, 0.2}, {0.51, 0.1}, 0.6);  // a sloping floor above the box's own
  return b;
}

template <class S>
class GravityTest : public ::testing::Test {};
TYPED_TEST_SUITE(GravityTest, Steppers, StepperNames);

TYPED_TEST(GravityTest, ZeroAndTenTimesGravity) {
  using Traits = StepperTraits<TypeParam>;
  for (double g : {0.0, 11.1}) {
    const table::Board b = gravity_board(g);
    const auto stepper = Traits::make(b, 5e-4);
    GameState s = state_with_ball(b, {0.25, 0.9}, {1.3, -0.7});
    Checker<TypeParam> check(stepper, s, false, 5000);
    const long n = static_cast<long>(5.0 / 5e-4);
    double min_y = INFINITY;
    ASSERT_TRUE(run_checked(stepper, s, n, check, [](GameState&, long) {},
                            [&](const GameState& st, long) { min_y = std::min(min_y, st.ball.position_m.y()); }))
        << Traits::kName << " g " << g;
    ASSERT_TRUE(s.ball_in_play);
    const double e0 = 0.5 * (1.3 * 1.3 + 0.7 * 0.7) + g * 0.9;
    if (g > 0.0) {
      // Under 10 g the ball loses its energy to ρ < 1 and ends on the sloping floor's low end.
      EXPECT_GT(min_y, 0.1 + kBallR - Traits::kMaxDepth_m - 1e-3) << "below the sloping floor";
    }
    note("gravity %s g %.2f: after 5 s energy %.3e of %.3e J/kg, largest gain %.2e J/kg, %llu events", Traits::kName,
         g, energy(b, s), e0, check.max_energy_gain(), static_cast<unsigned long long>(s.events));
  }
}

}  // namespace
}  // namespace pinball::sim::testing
