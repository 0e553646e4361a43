#include "pinball/track/trajectory_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "pinball/core/rng.h"

namespace pinball::track {
namespace {

constexpr double kG = 1.11;       // m/s², along the table
constexpr double kSigma = 0.0007;  // m, one coordinate

// n observations every dt_s ending at t_end_s on the parabola that passes
// p_end with velocity v_end at t_end_s (τ computed exactly as the fit does).
std::vector<Observation> parabola(int n, double t_end_s, double dt_s, const Vec2& p_end, const Vec2& v_end,
                                  double g) {
  std::vector<Observation> obs(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Observation& o = obs[static_cast<std::size_t>(i)];
    o.t_s = t_end_s - (n - 1 - i) * dt_s;
  }
  obs.back().t_s = t_end_s;
  for (Observation& o : obs) {
    const double tau = o.t_s - t_end_s;
    o.p_board = {p_end.x() + v_end.x() * tau, p_end.y() + v_end.y() * tau - 0.5 * g * tau * tau};
  }
  return obs;
}

void add_noise(std::vector<Observation>& obs, Rng& rng, double sigma) {
  for (Observation& o : obs) o.p_board += sigma * Vec2{rng.normal(), rng.normal()};
}

TEST(FitFixedGravity, RecoversANoiselessParabolaExactlyAtLargeAbsoluteTimes) {
  // 1e5 s is 28 hours of uptime: raw t² would be 1e10 and swamp the
  // millisecond spacing; centring on the newest sample keeps it exact.
  for (const double t_end : {0.0, 1e5, 3.7e5 + 0.123}) {
    const Vec2 p{0.21, 0.43};
    const Vec2 v{0.8, -1.3};
    const std::vector<Observation> obs = parabola(20, t_end, 0.005, p, v, kG);
    const TrajectoryFit fit = fit_fixed_gravity(obs, kG, kSigma);
    ASSERT_TRUE(fit.valid) << t_end;
    EXPECT_EQ(fit.t_ref_s, obs.back().t_s);
    EXPECT_NEAR(fit.p_ref.x(), p.x(), 1e-9) << t_end;
    EXPECT_NEAR(fit.p_ref.y(), p.y(), 1e-9) << t_end;
    EXPECT_NEAR(fit.v_ref.x(), v.x(), 1e-9) << t_end;
    EXPECT_NEAR(fit.v_ref.y(), v.y(), 1e-9) << t_end;
    EXPECT_EQ(fit.g_mps2, kG);
    EXPECT_EQ(fit.points, 20);
    EXPECT_EQ(fit.dof, 36);
    EXPECT_LT(fit.chi2, 1e-6);
    // The fitted curve reproduces the oldest point and its velocity too.
    const double tau0 = obs.front().t_s - t_end;
    EXPECT_NEAR((fit.position_at(obs.front().t_s) - obs.front().p_board).norm(), 0.0, 1e-9);
    EXPECT_NEAR(fit.velocity_at(obs.front().t_s).y(), v.y() - kG * tau0, 1e-9);
  }
}

TEST(FitFixedGravity, UsesTheGivenGravityNotTheData) {
  // Data made with g = 1.11, fitted with g 50 % high: the fit is still valid
  // and reports the g it was given, but the residuals grow.
  const std::vector<Observation> obs = parabola(30, 10.0, 0.005, {0.2, 0.3}, {0.1, -0.4}, kG);
  const TrajectoryFit right = fit_fixed_gravity(obs, kG, kSigma);
  const TrajectoryFit wrong = fit_fixed_gravity(obs, 1.5 * kG, kSigma);
  ASSERT_TRUE(right.valid);
  ASSERT_TRUE(wrong.valid);
  EXPECT_EQ(wrong.g_mps2, 1.5 * kG);
  EXPECT_GT(wrong.chi2, 1000.0 * right.chi2 + 1e-3);
}

TEST(FitFreeGravity, RecoversGravity) {
  for (const double g : {1.11, 9.81 * std::sin(7.0 * std::numbers::pi / 180.0), 0.5}) {
    const Vec2 p{0.3, 0.2};
    const Vec2 v{-0.4, 0.9};
    const std::vector<Observation> obs = parabola(40, 1e5, 0.005, p, v, g);
    const TrajectoryFit fit = fit_free_gravity(obs, kSigma);
    ASSERT_TRUE(fit.valid);
    EXPECT_NEAR(fit.g_mps2, g, 1e-6) << g;
    EXPECT_NEAR((fit.p_ref - p).norm(), 0.0, 1e-9) << g;
    EXPECT_NEAR((fit.v_ref - v).norm(), 0.0, 1e-8) << g;
    EXPECT_EQ(fit.points, 40);
    EXPECT_EQ(fit.dof, 75);
  }
}

TEST(FitFreeAcceleration, RecoversAnAccelerationInBothCoordinatesExactly) {
  // A skidding ball: g along −y plus a sliding friction of 1.95 m/s² against
  // its slip, at large absolute times (τ keeps the system well conditioned).
  const Vec2 a{1.2, -1.11 - 1.5};
  const Vec2 p{0.3, 0.2};
  const Vec2 v{-0.4, 0.9};
  std::vector<Observation> obs = parabola(24, 1e5, 0.005, p, v, 0.0);
  for (Observation& o : obs) {
    const double tau = o.t_s - 1e5;
    o.p_board += 0.5 * tau * tau * a;
  }
  const AccelerationFit fit = fit_free_acceleration(obs, kSigma);
  ASSERT_TRUE(fit.valid);
  EXPECT_NEAR((fit.a_mps2 - a).norm(), 0.0, 1e-6);
  EXPECT_NEAR((fit.p_ref - p).norm(), 0.0, 1e-9);
  EXPECT_NEAR((fit.v_ref - v).norm(), 0.0, 1e-8);
  EXPECT_DOUBLE_EQ(fit.t_ref_s, 1e5);
  EXPECT_EQ(fit.points, 24);
  EXPECT_EQ(fit.dof, 42);
  EXPECT_NEAR(fit.chi2, 0.0, 1e-6);
}

TEST(FitFreeAcceleration, TellsASkiddingBallFromARollingOneByItsChi2Drop) {
  // The likelihood-ratio test a held-out prediction uses: the χ² the free
  // acceleration saves over g alone is χ²(2) for a ball under g, so it stays
  // under the 99.9 % point; a 2 m/s² push is far over it.
  Rng rng(11);
  constexpr int kTrials = 2000;
  int rolling_flagged = 0;
  int skidding_flagged = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Vec2 p{rng.uniform(0.1, 0.4), rng.uniform(0.2, 0.8)};
    const Vec2 v{rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)};
    std::vector<Observation> rolling = parabola(24, 10.0 + trial, 0.005, p, v, kG);
    std::vector<Observation> skidding = rolling;
    const double heading = rng.uniform(0.0, 2.0 * std::numbers::pi);
    for (Observation& o : skidding) {
      const double tau = o.t_s - skidding.back().t_s;
      o.p_board += 0.5 * tau * tau * 2.0 * Vec2{std::cos(heading), std::sin(heading)};
    }
    add_noise(rolling, rng, kSigma);
    add_noise(skidding, rng, kSigma);
    const auto drop = [](const std::vector<Observation>& obs) {
      return fit_fixed_gravity(obs, kG, kSigma).chi2 - fit_free_acceleration(obs, kSigma).chi2;
    };
    if (drop(rolling) > chi2_threshold(2)) ++rolling_flagged;
    if (drop(skidding) > chi2_threshold(2)) ++skidding_flagged;
  }
  EXPECT_LE(rolling_flagged, 10);  // about 2 false alarms in 2000
  // 24 frames over 115 ms measure the acceleration to about 0.3 m/s² at this
  // noise: the push is some 7 σ, missed in about 1 % of trials.
  EXPECT_GE(skidding_flagged, kTrials * 97 / 100);
}

TEST(TrajectoryFit, TooFewPointsOrEqualTimesAreInvalid) {
  const std::vector<Observation> obs = parabola(5, 2.0, 0.005, {0.2, 0.3}, {0.1, -0.4}, kG);
  for (std::size_t n = 0; n < 3; ++n) {
    const std::span<const Observation> few(obs.data(), n);
    EXPECT_FALSE(fit_fixed_gravity(few, kG, kSigma).valid) << n;
    EXPECT_FALSE(fit_free_gravity(few, kSigma).valid) << n;
    EXPECT_FALSE(fit_free_acceleration(few, kSigma).valid) << n;
  }
  EXPECT_TRUE(fit_free_acceleration(std::span<const Observation>(obs.data(), 3), kSigma).valid);
  EXPECT_TRUE(fit_fixed_gravity(std::span<const Observation>(obs.data(), 3), kG, kSigma).valid);
  EXPECT_TRUE(fit_free_gravity(std::span<const Observation>(obs.data(), 3), kSigma).valid);

  std::vector<Observation> same = obs;
  for (Observation& o : same) o.t_s = 2.0;  // one frame reported five times
  const TrajectoryFit fixed = fit_fixed_gravity(same, kG, kSigma);
  const TrajectoryFit free_g = fit_free_gravity(same, kSigma);
  EXPECT_FALSE(fixed.valid);
  EXPECT_FALSE(free_g.valid);
  EXPECT_FALSE(fit_free_acceleration(same, kSigma).valid);
  EXPECT_TRUE(std::isfinite(fixed.p_ref.x()) && std::isfinite(fixed.v_ref.y()));
}

TEST(TrajectoryFit, Chi2AveragesItsDegreesOfFreedomOnNoisyData) {
  Rng rng(7);
  constexpr int kTrials = 4000;
  double sum_fixed = 0.0;
  double sum_free = 0.0;
  double sum_own = 0.0;
  int dof_own = 0;
  int over_fixed = 0;
  int dof_fixed = 0;
  int dof_free = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Vec2 p{rng.uniform(0.1, 0.4), rng.uniform(0.2, 0.8)};
    const Vec2 v{rng.uniform(-1.0, 1.0), rng.uniform(-2.0, 1.0)};
    std::vector<Observation> obs = parabola(10, 100.0 + trial, 0.005, p, v, kG);
    add_noise(obs, rng, kSigma);
    const TrajectoryFit fixed = fit_fixed_gravity(obs, kG, kSigma);
    const TrajectoryFit free_g = fit_free_gravity(obs, kSigma);
    const AccelerationFit own = fit_free_acceleration(obs, kSigma);
    ASSERT_TRUE(fixed.valid && free_g.valid && own.valid);
    sum_fixed += fixed.chi2;
    sum_free += free_g.chi2;
    sum_own += own.chi2;
    dof_own = own.dof;
    dof_fixed = fixed.dof;
    dof_free = free_g.dof;
    if (fixed.chi2 > chi2_threshold(fixed.dof)) ++over_fixed;
  }
  EXPECT_EQ(dof_fixed, 16);
  EXPECT_EQ(dof_free, 15);
  EXPECT_NEAR(sum_fixed / kTrials / dof_fixed, 1.0, 0.2);
  EXPECT_NEAR(sum_free / kTrials / dof_free, 1.0, 0.2);
  EXPECT_EQ(dof_own, 14);
  EXPECT_NEAR(sum_own / kTrials / dof_own, 1.0, 0.2);
  // The threshold is the 99.9 % point: about 4 false alarms in 4000.
  EXPECT_LE(over_fixed, 20);
}

TEST(Chi2Threshold, MatchesTheTabulated999PercentPoints) {
  // χ²₀.₉₉₉ from tables: 10.828 (1), 13.816 (2), 29.588 (10), 45.315 (20), 86.661 (50).
  EXPECT_NEAR(chi2_threshold(2), 13.816, 0.03 * 13.816);
  EXPECT_NEAR(chi2_threshold(10), 29.588, 0.03 * 29.588);
  EXPECT_NEAR(chi2_threshold(20), 45.315, 0.03 * 45.315);
  EXPECT_NEAR(chi2_threshold(50), 86.661, 0.01 * 86.661);
  EXPECT_TRUE(std::isinf(chi2_threshold(0)));
  EXPECT_TRUE(std::isinf(chi2_threshold(-3)));
  for (int k = 1; k < 200; ++k) {
    EXPECT_GT(chi2_threshold(k + 1), chi2_threshold(k)) << k;
    EXPECT_GT(chi2_threshold(k), static_cast<double>(k)) << k;  // above the mean
  }
}

}  // namespace
}  // namespace pinball::track
