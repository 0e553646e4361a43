// A ball at 500 m/s (100x a table's 5 m/s) in a closed box split by a thin
// wall of zero thickness (two one-sided lines on top of each other): it moves
// 25 cm per 0.5 ms step, ten ball diameters, and must never cross the wall.

#include <cmath>
#include <numbers>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class FastBallTest : public ::testing::Test {};
TYPED_TEST_SUITE(FastBallTest, Steppers, StepperNames);

TYPED_TEST(FastBallTest, NeverCrossesAZeroThicknessWallAt500mps) {
  using Traits = StepperTraits<TypeParam>;
  for (double deg : {0.0, 17.0, 45.0, 80.0, -33.0}) {
    table::Board b = box_board(1.0, 1.11, 5e-4);
    b.ball.speed_max_mps = 1000.0;
    add_wall(b, {0.3, 0.0}, {0.3, b.height_m}, 1.0);  // floor to roof: no way round
    const auto stepper = Traits::make(b, 5e-4);
    const double a = deg * std::numbers::pi / 180.0;
    GameState s = state_with_ball(b, {0.15, 0.5}, 500.0 * Vec2{std::cos(a), std::sin(a)});
    // Elastic everywhere: about 700 wall hits in 0.1 s; the event count may not run away.
    Checker<TypeParam> check(stepper, s, false, 5000);
    double max_x = -INFINITY;
    ASSERT_TRUE(run_checked(stepper, s, 200, check, [](GameState&, long) {},
                            [&](const GameState& st, long) { max_x = std::max(max_x, st.ball.position_m.x()); }))
        << Traits::kName << " " << deg << " deg";
    ASSERT_TRUE(s.ball_in_play);
    EXPECT_LT(max_x, 0.3 - kBallR + Traits::kMaxDepth_m) << Traits::kName << " " << deg << " deg: crossed the wall";
    // Elastic walls keep the speed, up to g·Δy / v ≈ 2e-3 m/s from the height it ends at.
    EXPECT_NEAR(s.ball.velocity_mps.norm(), 500.0, 0.01);
    note("fast_ball %s %.0f deg: 0.1 s at 500 m/s, closest approach to the wall %.2e m, speed change %.2e m/s, %llu "
         "events",
         Traits::kName, deg, 0.3 - kBallR - max_x, s.ball.velocity_mps.norm() - 500.0,
         static_cast<unsigned long long>(s.events));
  }
}

}  // namespace
}  // namespace pinball::sim::testing
