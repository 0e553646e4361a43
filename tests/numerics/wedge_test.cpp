// A ball dropped into a V of two thin walls of opening 1°, 45° and 179°: it
// must settle where the V is one ball wide (r / sin(half angle) above the
// apex) and never pass through either wall.

#include <cmath>
#include <numbers>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class WedgeTest : public ::testing::Test {};
TYPED_TEST_SUITE(WedgeTest, Steppers, StepperNames);

TYPED_TEST(WedgeTest, SettlesInVCornersWithoutEscaping) {
  using Traits = StepperTraits<TypeParam>;
  for (double opening_deg : {1.0, 45.0, 179.0}) {
    const double half = 0.5 * opening_deg * std::numbers::pi / 180.0;
    const double wedge_h = kBallR / std::sin(half);  // centre height above the apex where the V is one ball wide
    const double len = opening_deg < 10.0 ? 2.0 : 0.4;
    table::Board b = empty_board(1.0, 2.5, 1.11, 5e-4);
    const Vec2 apex{0.5, 0.1};
    add_wall(b, apex, apex + len * Vec2{-std::sin(half), std::cos(half)}, 0.5);
    add_wall(b, apex, apex + len * Vec2{std::sin(half), std::cos(half)}, 0.5);
    const auto stepper = Traits::make(b, 5e-4);
    // Dropped off-centre, inside the V, a little above the wedge point (in the
    // 1° V the walls are 3 mm either side of the ball where it starts).
    const double drop_h = opening_deg < 10.0 ? 1.9 : wedge_h + 0.1;
    const double room = drop_h * std::tan(half) - kBallR / std::cos(half);
    GameState s = state_with_ball(b, apex + Vec2{0.3 * std::min(room, 0.05), drop_h}, Vec2::Zero());
    const Vec2 n_left{std::cos(half), std::sin(half)};  // into the V
    const Vec2 n_right{-std::cos(half), std::sin(half)};
    Checker<TypeParam> check(stepper, s, false, 20000);
    double lowest = INFINITY;
    double min_side = INFINITY;
    ASSERT_TRUE(run_checked(stepper, s, static_cast<long>(5.0 / 5e-4), check, [](GameState&, long) {},
                            [&](const GameState& st, long) {
                              const Vec2 rel = st.ball.position_m - apex;
                              min_side = std::min({min_side, rel.dot(n_left), rel.dot(n_right)});
                              lowest = std::min(lowest, rel.y());
                            }))
        << Traits::kName << " " << opening_deg << " deg";
    EXPECT_GT(min_side, kBallR - Traits::kMaxDepth_m) << Traits::kName << " " << opening_deg << " deg: through a wall";
    EXPECT_GT(lowest, wedge_h - 2.0 * Traits::kMaxDepth_m / std::sin(half))
        << Traits::kName << " " << opening_deg << " deg: below the wedge point";
    note("wedge %s %.0f deg: lowest %.3e m above the wedge point, final |v| %.2e m/s, final height above it %.2e m, "
         "%llu events",
         Traits::kName, opening_deg, lowest - wedge_h, s.ball.velocity_mps.norm(),
         s.ball.position_m.y() - apex.y() - wedge_h, static_cast<unsigned long long>(s.events));
  }
}

}  // namespace
}  // namespace pinball::sim::testing
