// Two kickers of ρ = 1.5 facing each other, no gravity: each bounce returns
// the ball 1.5x faster, so only the speed clamp bounds its energy (a model
// choice of both steppers). The state must stay finite and outside the
// kickers, the speed at the clamp, and the event count bounded.

#include <cmath>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class KickersTest : public ::testing::Test {};
TYPED_TEST_SUITE(KickersTest, Steppers, StepperNames);

TYPED_TEST(KickersTest, TwoKickersFacingEachOther) {
  using Traits = StepperTraits<TypeParam>;
  for (const bool circles : {false, true}) {
    table::Board b = empty_board(1.0, 1.0, 0.0, 5e-4);
    b.ball.speed_max_mps = 5.0;
    if (circles) {
      add_circle(b, {0.3, 0.5}, 0.03, 1.5);
      add_circle(b, {0.7, 0.5}, 0.03, 1.5);
    } else {
      add_wall(b, {0.3, 0.3}, {0.3, 0.7}, 1.5);
      add_wall(b, {0.7, 0.3}, {0.7, 0.7}, 1.5);
    }
    const auto stepper = Traits::make(b, 5e-4);
    GameState s = state_with_ball(b, {0.5, 0.5}, {0.5, 0.0});
    // At the clamp the ball crosses the ~0.35 m gap 14 times a second: 3 s
    // need ~50 impacts; allow a wide margin, but not a runaway.
    Checker<TypeParam> check(stepper, s, true, 2000);
    double max_speed = 0.0;
    ASSERT_TRUE(run_checked(stepper, s, static_cast<long>(3.0 / 5e-4), check, [](GameState&, long) {},
                            [&](const GameState& st, long) {
                              max_speed = std::max(max_speed, st.ball.velocity_mps.norm());
                            }))
        << Traits::kName << (circles ? " circles" : " lines");
    ASSERT_TRUE(s.ball_in_play);
    EXPECT_LE(max_speed, 5.0 * (1.0 + 1e-12));
    EXPECT_NEAR(s.ball.velocity_mps.norm(), 5.0, 1e-9) << "kicked up to the clamp and held there";
    EXPECT_NEAR(s.ball.position_m.y(), 0.5, 1e-9) << "head-on kicks keep it on the axis";
    EXPECT_GT(s.ball.position_m.x(), 0.3) << "between the kickers";
    EXPECT_LT(s.ball.position_m.x(), 0.7) << "between the kickers";
    note("kickers %s %s: top speed %.6f m/s after 3 s, %llu events", Traits::kName, circles ? "circles" : "lines",
         max_speed, static_cast<unsigned long long>(s.events));
  }
}

}  // namespace
}  // namespace pinball::sim::testing
