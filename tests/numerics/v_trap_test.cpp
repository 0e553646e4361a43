// A ball wedged in a narrow V (issue 17, item 8): two walls 1.2° apart under
// gravity, the ball released at rest where the V is one ball wide, 1 ms steps.
// The thesis stepper used to hold the position (its contacts per step ran out
// and it dropped the rest of every step) while gravity kept feeding the
// velocity: |v| grew to about 3720·dt and the energy ½v² + g·y rose 2.4 J/kg
// above the start. The ball must stay put, slow and below its starting energy.

#include <cmath>
#include <numbers>

#include "numerics.h"

namespace pinball::sim::testing {
namespace {

template <class S>
class VTrapTest : public ::testing::Test {};
TYPED_TEST_SUITE(VTrapTest, Steppers, StepperNames);

// An empty table holding a V of two walls from `apex`, each `half_rad` off
// the vertical, reaching 0.3 m past the height where the V is one ball wide.
table::Board v_board(const Vec2& apex, double half_rad, double dt_s) {
  const double wedge_h = kBallR / std::sin(half_rad);
  table::Board b = empty_board(1.0, wedge_h + 0.5, 1.11, dt_s);
  const double len = wedge_h + 0.3;
  add_wall(b, apex, apex + len * Vec2{-std::sin(half_rad), std::cos(half_rad)}, 0.5);
  add_wall(b, apex, apex + len * Vec2{std::sin(half_rad), std::cos(half_rad)}, 0.5);
  return b;
}

TYPED_TEST(VTrapTest, BallWedgedInANarrowVNeitherSpeedsUpNorGainsEnergy) {
  using Traits = StepperTraits<TypeParam>;
  constexpr double kDt_s = 1e-3;
  for (const double opening_deg : {1.2, 0.6, 3.0}) {
    const double half = 0.5 * opening_deg * std::numbers::pi / 180.0;
    const double wedge_h = kBallR / std::sin(half);  // where the V is one ball wide, above the apex
    const Vec2 apex{0.5, 0.05};
    const table::Board b = v_board(apex, half, kDt_s);
    const auto stepper = Traits::make(b, kDt_s);
    // At rest, 0.1 mm above the wedge point: the walls are 1 µm (at 1.2°) either side.
    GameState s = state_with_ball(b, apex + Vec2{0.0, wedge_h + 1e-4}, Vec2::Zero());
    const double e0 = energy(b, s);
    // The ball only falls the last 0.1 mm: no contact can supply energy, so
    // the energy is held to the start plus Euler's offset at twice the speed
    // that fall gives (√(2g·1e-4) ≈ 15 mm/s), nothing per contact.
    const double slack = b.gravity_mps2 * (0.03 + b.gravity_mps2 * kDt_s) * kDt_s + 1e-12;
    Checker<TypeParam> check(stepper, s, /*energy_supplied=*/true, 200000);
    double max_gain = -INFINITY, max_speed = 0.0, lowest = INFINITY;
    std::uint64_t events_before = s.events, most_events = 0;
    ASSERT_TRUE(run_checked(stepper, s, static_cast<long>(20.0 / kDt_s), check, [](GameState&, long) {},
                            [&](const GameState& st, long i) {
                              most_events = std::max(most_events, st.events - events_before);
                              events_before = st.events;
                              ASSERT_TRUE(st.ball_in_play) << "lost at step " << i;
                              max_gain = std::max(max_gain, energy(b, st) - e0);
                              max_speed = std::max(max_speed, st.ball.velocity_mps.norm());
                              lowest = std::min(lowest, st.ball.position_m.y() - apex.y());
                            }))
        << Traits::kName << " " << opening_deg << " deg";
    EXPECT_LE(max_gain, slack) << Traits::kName << " " << opening_deg << " deg: energy from nowhere";
    EXPECT_LT(max_speed, 0.05) << Traits::kName << " " << opening_deg << " deg: the wedged ball sped up";
    EXPECT_GT(lowest, wedge_h - 2.0 * Traits::kMaxDepth_m / std::sin(half))
        << Traits::kName << " " << opening_deg << " deg: below the wedge point";
    note("v-trap %s %.1f deg dt 1 ms: largest energy gain %.2e J/kg, top speed %.2e m/s, final |v| %.2e m/s, "
         "lowest %.2e m from the wedge point, %llu events in 20 s (at most %llu in one step)",
         Traits::kName, opening_deg, max_gain, max_speed, s.ball.velocity_mps.norm(), lowest - wedge_h,
         static_cast<unsigned long long>(s.events), static_cast<unsigned long long>(most_events));
  }
}

TYPED_TEST(VTrapTest, BallDroppedIntoANarrowVComesToRest) {
  using Traits = StepperTraits<TypeParam>;
  constexpr double kDt_s = 1e-3;
  const double half = 0.5 * 1.2 * std::numbers::pi / 180.0;
  const double wedge_h = kBallR / std::sin(half);
  const Vec2 apex{0.5, 0.05};
  const table::Board b = v_board(apex, half, kDt_s);
  const auto stepper = Traits::make(b, kDt_s);
  // Dropped 0.2 m above the wedge point, a little off the centre line: it
  // arrives at about 0.67 m/s and rattles down between the walls.
  const double drop_h = wedge_h + 0.2;
  const double room = drop_h * std::tan(half) - kBallR / std::cos(half);
  GameState s = state_with_ball(b, apex + Vec2{0.5 * room, drop_h}, Vec2::Zero());
  const double e0 = energy(b, s);
  Checker<TypeParam> check(stepper, s, false, 200000);
  ASSERT_TRUE(run_checked(stepper, s, static_cast<long>(20.0 / kDt_s), check)) << Traits::kName;
  // Whatever it did on the way down, it ends near the wedge point, slow, with
  // most of the drop's energy gone.
  EXPECT_LT(s.ball.velocity_mps.norm(), 0.05) << Traits::kName;
  EXPECT_LT(s.ball.position_m.y() - apex.y() - wedge_h, 0.01) << Traits::kName;
  EXPECT_LT(energy(b, s) - e0, -0.5 * b.gravity_mps2 * 0.2) << Traits::kName;
  note("v-trap drop %s 1.2 deg dt 1 ms: largest energy gain %.2e J/kg, final |v| %.2e m/s, final height above the "
       "wedge point %.2e m, %llu events",
       Traits::kName, check.max_energy_gain(), s.ball.velocity_mps.norm(),
       s.ball.position_m.y() - apex.y() - wedge_h, static_cast<unsigned long long>(s.events));
}

}  // namespace
}  // namespace pinball::sim::testing
