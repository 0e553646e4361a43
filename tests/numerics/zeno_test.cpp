// Zeno bouncing: a ball dropped on a flat line with ρ < 1 bounces ever lower;
// the exact answer is a geometric series of bounces that ends at a finite
// time, after which the ball rests on the line.

#include <cmath>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class ZenoTest : public ::testing::Test {};
TYPED_TEST_SUITE(ZenoTest, Steppers, StepperNames);

TYPED_TEST(ZenoTest, BouncesToRestOnAFlatLine) {
  using Traits = StepperTraits<TypeParam>;
  for (double rho : {0.5, 0.9}) {
    table::Board b = empty_board(1.0, 1.0, 1.11, 5e-4);
    add_line(b, {0.0, 0.1}, {1.0, 0.1}, rho);
    const auto stepper = Traits::make(b, 5e-4);
    GameState s = state_with_ball(b, {0.5, 0.1 + kBallR + 0.2}, Vec2::Zero());
    // Rest time of the series: t0 + 2 v0 ρ / (g (1 − ρ)).
    const double v0 = std::sqrt(2.0 * 1.11 * 0.2);
    const double t_rest = std::sqrt(2.0 * 0.2 / 1.11) + 2.0 * v0 * rho / (1.11 * (1.0 - rho));
    const long n = static_cast<long>((t_rest + 2.0) / 5e-4);
    Checker<TypeParam> check(stepper, s, false, 2000);
    double y_lo = INFINITY, y_hi = -INFINITY;
    const long last_second = n - static_cast<long>(1.0 / 5e-4);
    ASSERT_TRUE(run_checked(stepper, s, n, check, [](GameState&, long) {},
                            [&](const GameState& st, long i) {
                              if (i < last_second) return;
                              y_lo = std::min(y_lo, st.ball.position_m.y());
                              y_hi = std::max(y_hi, st.ball.position_m.y());
                            }))
        << Traits::kName << " rho " << rho;
    const double rest_y = 0.1 + kBallR;
    EXPECT_GE(y_lo, rest_y - Traits::kMaxDepth_m) << "sank into the line";
    EXPECT_NEAR(s.ball.position_m.x(), 0.5, 1e-12) << "a vertical drop drifted sideways";
    // Over the last second (well past the rest time) the ball stays within
    // 1e-4 m of resting on the line; the exact stepper within 1e-9 m.
    EXPECT_LT(y_hi - rest_y, Traits::kExact ? 1e-9 : 1e-4) << Traits::kName << " rho " << rho;
    note("zeno %s rho %.1f: over the last 1 s height above rest in [%.2e, %.2e] m, |v| %.2e m/s, %llu events",
         Traits::kName, rho, y_lo - rest_y, y_hi - rest_y, s.ball.velocity_mps.norm(),
         static_cast<unsigned long long>(s.events));
  }
}

}  // namespace
}  // namespace pinball::sim::testing
