#include "pinball/calibration/gravity_calibration.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pinball/core/rng.h"

namespace pinball::calibration {
namespace {

// A ball resting at y0 for `hold` s, then rolling down at g, then bouncing back up at t_hit.
GravityRoll roll(double g, double noise_m, std::uint64_t seed, double hold = 0.1, double t_hit = 0.8) {
  Rng rng(seed);
  GravityRoll r;
  r.source = "roll " + std::to_string(seed);
  const double y0 = 0.9;
  for (int k = 0; k < 240; ++k) {
    const double t = k / 200.0;
    const double tau = std::max(0.0, t - hold);
    double y = y0 - 0.5 * g * tau * tau;
    if (tau > t_hit) y = y0 - 0.5 * g * t_hit * t_hit + 0.5 * g * t_hit * (tau - t_hit);  // bounced
    r.observations.push_back({t, Vec2{0.2 + noise_m * rng.normal(), y + noise_m * rng.normal()}, 1.0});
  }
  return r;
}

TEST(GravityCalibration, ExactRollGivesExactG) {
  const RollFit f = fit_roll(roll(1.11, 0.0, 1));
  ASSERT_TRUE(f.usable) << f.why;
  EXPECT_NEAR(f.accel_mps2, 1.11, 1e-9);
  EXPECT_NEAR(f.lateral_mps2, 0.0, 1e-9);
  // The bounce is cut off, the rest before release too.
  EXPECT_GT(f.first, 20u);
  EXPECT_LT(f.last, 185u);
  EXPECT_GT(f.last, 170u);
}

TEST(GravityCalibration, NoisyRollsWithAnOutlierRejected) {
  std::vector<GravityRoll> rolls;
  for (std::uint64_t s = 1; s <= 6; ++s) rolls.push_back(roll(1.11, 0.0007, s));
  rolls.push_back(roll(1.30, 0.0007, 99));  // a roll that was pushed
  const GravityCalibration c = calibrate_gravity(rolls);
  EXPECT_EQ(c.estimate.rolls_used, 6);
  EXPECT_EQ(c.estimate.rolls_rejected, 1);
  EXPECT_TRUE(c.rolls.back().outlier);
  EXPECT_NEAR(c.estimate.g_mps2, 1.11, 0.005);
  EXPECT_LE(c.estimate.ci_low_mps2, c.estimate.g_mps2);
  EXPECT_GE(c.estimate.ci_high_mps2, c.estimate.g_mps2);
  EXPECT_LT(c.estimate.ci_high_mps2 - c.estimate.ci_low_mps2, 0.02);
  EXPECT_EQ(c.estimate.per_roll_mps2.size(), 7u);
}

TEST(GravityCalibration, UnusableRollsAreReportedNotFatal) {
  GravityRoll still;
  still.source = "still";
  for (int k = 0; k < 100; ++k) still.observations.push_back({k / 200.0, Vec2{0.2, 0.5}, 1.0});
  const RollFit f = fit_roll(still);
  EXPECT_FALSE(f.usable);
  EXPECT_FALSE(f.why.empty());
  const std::vector<GravityRoll> only_still{still};
  EXPECT_THROW(calibrate_gravity(only_still), std::runtime_error);
  const std::vector<GravityRoll> mixed{still, roll(1.11, 0.0, 2), roll(1.11, 0.0, 3)};
  const GravityCalibration c = calibrate_gravity(mixed);
  EXPECT_EQ(c.estimate.rolls_used, 2);
  EXPECT_EQ(c.estimate.rolls_rejected, 1);
}

// What no roll down this table gives: more than g itself, or a ball that was
// launched, not let go (a whole game's trace fitted its launch). Every roll's
// reason is in the error.
TEST(GravityCalibration, ImpossibleAccelerationsAndLaunchesAreNoRolls) {
  const RollFit steep = fit_roll(roll(1e6, 0.0, 4));
  EXPECT_FALSE(steep.usable);
  EXPECT_EQ(steep.why, "the ball sped up at 1000000 m/s^2 down the table, more than g itself (10 at most): not a ball "
                       "rolling on this table");
  GravityRoll launched;  // shot up the table at 3 m/s, falling back at 1.11
  launched.source = "launched";
  for (int k = 0; k < 200; ++k) {
    const double t = k / 200.0;
    launched.observations.push_back({t, Vec2{0.2, 0.1 + 3.0 * t - 0.5 * 1.11 * t * t}, 1.0});
  }
  const RollFit shot = fit_roll(launched);
  EXPECT_FALSE(shot.usable);
  EXPECT_NE(shot.why.find("a roll starts from rest, let go, not launched"), std::string::npos) << shot.why;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    EXPECT_TRUE(fit_roll(roll(1.11, 0.001, seed)).usable) << "a noisy roll from rest is still one";
  }
  const std::vector<GravityRoll> bad{roll(1e6, 0.0, 4), launched};
  try {
    calibrate_gravity(bad);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no usable roll of 2 (roll 4: the ball sped up"), std::string::npos) << what;
    EXPECT_NE(what.find("; launched: the ball moved at "), std::string::npos) << what;
  }
}

TEST(GravityCalibration, StudentT) {
  EXPECT_NEAR(student_t_quantile(0.95, 4), 2.776, 1e-3);
  EXPECT_NEAR(student_t_quantile(0.95, 60), 2.000, 2e-3);
  EXPECT_NEAR(student_t_quantile(0.99, 120), 2.617, 2e-3);
  EXPECT_THROW(student_t_quantile(0.8, 4), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::calibration
