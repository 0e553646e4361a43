// The step from 1e-6 s up to the largest the flippers allow
// (l·sin(θ̇₀·dt/2) < r, max_stable_dt_s) on a small table with bumpers of
// ρ > 1 and two flippers pressed and released: every step keeps the ball
// finite, outside everything and inside the closed box. For the event stepper
// the step is only the horizon between policy calls.

#include <cmath>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class TimeStepTest : public ::testing::Test {};
TYPED_TEST_SUITE(TimeStepTest, Steppers, StepperNames);

TYPED_TEST(TimeStepTest, FromOneMicrosecondToTheLargestLegalStep) {
  using Traits = StepperTraits<TypeParam>;
  const double dt_max = table::max_stable_dt_s(box_with_bumpers_and_flippers());
  ASSERT_TRUE(std::isfinite(dt_max));
  for (double dt : {1e-6, 1e-5, 1e-4, 1e-3, 0.999 * dt_max}) {
    const table::Board b = box_with_bumpers_and_flippers(dt);
    const auto stepper = Traits::make(b, dt);
    GameState s = state_with_ball(b, {0.3, 0.6}, {0.8, -0.5});
    const double seconds = dt < 5e-6 ? 0.2 : 3.0;
    const long n = std::lround(seconds / dt);
    const long toggle = std::max(1L, std::lround(0.15 / dt));
    // Bumpers and flippers supply energy. A busy table sees tens of impacts a second.
    Checker<TypeParam> check(stepper, s, true, static_cast<std::uint64_t>(5000 * seconds));
    double max_speed = 0.0;
    ASSERT_TRUE(run_checked(
        stepper, s, n, check,
        [&](GameState& st, long i) {
          for (auto& fs : st.flippers) fs.energized = (i / toggle) % 2 == 1;
        },
        [&](const GameState& st, long i) {
          const Vec2& p = st.ball.position_m;
          max_speed = std::max(max_speed, st.ball.velocity_mps.norm());
          ASSERT_TRUE(st.ball_in_play && p.x() > 0.0 && p.x() < b.width_m && p.y() > 0.0 && p.y() < b.height_m)
              << "left the closed box at step " << i;
        }))
        << Traits::kName << " dt " << dt;
    EXPECT_LE(max_speed, b.ball.speed_max_mps * (1.0 + 1e-12));
    note("time_step %s dt %.3e s: %.1f s simulated, top speed %.2f m/s, %llu events", Traits::kName, dt, seconds,
         max_speed, static_cast<unsigned long long>(s.events));
  }
}

TEST(TimeStepLimits, ThesisStepperRefusesAStepPastTheFlipperCondition) {
  const table::Board b = box_with_bumpers_and_flippers();
  const double dt_max = table::max_stable_dt_s(b);
  ThesisStepperOptions o;
  o.dt_s = 1.01 * dt_max;
  EXPECT_THROW(ThesisStepper(b, o), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::sim::testing
