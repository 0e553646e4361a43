#include "pinball/track/projection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include "pinball/core/rng.h"
#include "pinball/table/board_loader.h"

namespace pinball::track {
namespace {

constexpr double kPi = std::numbers::pi;

// A V with easy numbers: left flipper (-1, 0) -> (-0.5, -0.5) on y = -x - 1,
// right flipper (1, 0) -> (0.5, -0.5) on y = x - 1; apex (0, -1) at h = 2.
FlipperGeometry hand_v() { return make_flipper_geometry({{-1.0, 0.0}, {-0.5, -0.5}}, {{1.0, 0.0}, {0.5, -0.5}}); }

TrajectoryFit fit_of(const Vec2& p, const Vec2& v, double g, double t_ref_s = 10.0) {
  return exact_trajectory(p, v, g, t_ref_s);
}

void expect_finite(const TrajectoryProjection& p) {
  EXPECT_TRUE(std::isfinite(p.speed_mps));
  EXPECT_TRUE(std::isfinite(p.angle_rad));
  EXPECT_TRUE(std::isfinite(p.h));
  EXPECT_TRUE(std::isfinite(p.d_m));
  EXPECT_TRUE(std::isfinite(p.t_impact_s));
  EXPECT_TRUE(std::isfinite(p.t_observation_s));
  EXPECT_TRUE(std::isfinite(p.impact_point.x()) && std::isfinite(p.impact_point.y()));
}

TEST(ProjectTrajectory, VerticalFallOntoTheLeftFlipper) {
  // From (-0.75, 1) at rest, g = 2: falls 1.25 m to (-0.75, -0.25), h = 0.5,
  // in τ = √1.25 at speed g·τ, straight down.
  const TrajectoryProjection p = project_trajectory(fit_of({-0.75, 1.0}, {0.0, 0.0}, 2.0), hand_v());
  ASSERT_TRUE(p.valid);
  EXPECT_EQ(p.reason, NoProjection::kNone);
  EXPECT_EQ(p.flipper, kLeftFlipper);
  EXPECT_TRUE(p.hittable);
  EXPECT_FALSE(p.rolling);
  EXPECT_NEAR(p.t_impact_s, std::sqrt(1.25), 1e-12);
  EXPECT_NEAR(p.h, 0.5, 1e-12);
  EXPECT_NEAR(p.speed_mps, 2.0 * std::sqrt(1.25), 1e-12);
  EXPECT_EQ(p.angle_rad, -kPi / 2.0);  // exactly, vx = 0 is no division by zero
  EXPECT_NEAR(p.d_m, 1.25, 1e-12);
  EXPECT_NEAR((p.impact_point - Vec2(-0.75, -0.25)).norm(), 0.0, 1e-12);
  EXPECT_EQ(p.t_observation_s, 10.0);
  expect_finite(p);
}

TEST(ProjectTrajectory, ImpactOnTheRightFlipperWithSidewaysSpeed) {
  // From (0, 0.5) at (1, 0), g = 2: x = τ, y = 0.5 − τ² meets y = x − 1 at
  // τ² + τ − 1.5 = 0, τ = (√7 − 1)/2, x = τ, h = (1 − x)/0.5.
  const TrajectoryProjection p = project_trajectory(fit_of({0.0, 0.5}, {1.0, 0.0}, 2.0), hand_v());
  const double tau = 0.5 * (std::sqrt(7.0) - 1.0);
  ASSERT_TRUE(p.valid);
  EXPECT_EQ(p.flipper, kRightFlipper);
  EXPECT_NEAR(p.t_impact_s, tau, 1e-12);
  EXPECT_NEAR(p.h, 2.0 * (1.0 - tau), 1e-12);
  EXPECT_NEAR(p.speed_mps, std::sqrt(1.0 + 4.0 * tau * tau), 1e-12);
  EXPECT_NEAR(p.angle_rad, std::atan(-2.0 * tau), 1e-12);  // tan⁻¹(ẏ/ẋ), eq. 4.11
  EXPECT_NEAR((p.impact_point - Vec2(tau, tau - 1.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(p.d_m, std::hypot(tau, 0.5 - (tau - 1.0)), 1e-12);
}

TEST(ProjectTrajectory, ImpactsOnTheExtensionsUpToTheApex) {
  // Vertical falls at x = ∓0.25 meet the extensions at h = 1.5 (past the tips).
  for (const int side : {kLeftFlipper, kRightFlipper}) {
    const double x = side == kLeftFlipper ? -0.25 : 0.25;
    const TrajectoryProjection p = project_trajectory(fit_of({x, 1.0}, {0.0, 0.0}, 2.0), hand_v());
    ASSERT_TRUE(p.valid) << side;
    EXPECT_EQ(p.flipper, side);
    EXPECT_NEAR(p.h, 1.5, 1e-12);
    EXPECT_TRUE(p.hittable);
    EXPECT_NEAR(p.t_impact_s, std::sqrt(1.75), 1e-12);  // down to y = -0.75
    EXPECT_EQ(p.angle_rad, -kPi / 2.0);
  }
  // Just beside the centre line: h just under 2 on the near side.
  const TrajectoryProjection p = project_trajectory(fit_of({-1e-6, 1.0}, {0.0, 0.0}, 2.0), hand_v());
  ASSERT_TRUE(p.valid);
  EXPECT_EQ(p.flipper, kLeftFlipper);
  EXPECT_NEAR(p.h, 2.0, 1e-5);
  EXPECT_LE(p.h, 2.0);
}

TEST(ProjectTrajectory, ChoosesTheNearerImpact) {
  // Falling fast, drifting right, above the left arm: the left line is met
  // first (τ ≈ 0.21, h ≈ 0.93); the right line is crossed later (τ ≈ 0.52),
  // past the apex. Mirrored, the right one is nearer.
  for (const int side : {kLeftFlipper, kRightFlipper}) {
    const double sx = side == kLeftFlipper ? 1.0 : -1.0;
    const TrajectoryProjection p = project_trajectory(fit_of({-0.6 * sx, 0.0}, {0.3 * sx, -2.0}, 2.0), hand_v());
    ASSERT_TRUE(p.valid) << side;
    EXPECT_EQ(p.flipper, side);
    // Left case: x = -0.6 + 0.3τ, y = -2τ - τ² meets y = -x - 1: τ² + 1.7τ - 0.4 = 0.
    const double tau = 0.5 * (-1.7 + std::sqrt(1.7 * 1.7 + 1.6));
    EXPECT_NEAR(p.t_impact_s, tau, 1e-12) << side;
    EXPECT_NEAR(p.h, 2.0 * (0.4 + 0.3 * tau), 1e-12) << side;
  }
}

TEST(ProjectTrajectory, ChoosesTheNearestOfSeveralFutureRoots) {
  // With g pointing the wrong way (a free fit gone bad) the path is convex:
  // from (-1.2, 0.6) at (1, -2.4), g = -2, x = -1.2 + τ, y = 0.6 − 2.4τ + τ²
  // crosses the left arm (y = -x - 1) where τ² − 1.4τ + 0.4 = 0, at τ = 0.4
  // (h = 0.4) and τ = 1 (h = 1.6), then the right arm (y = x − 1) where
  // τ² − 3.4τ + 2.8 = 0, at τ = 1.4 (h = 1.6) and τ = 2 (h = 0.4). Four
  // future roots, all on the V: the nearest is the impact.
  const TrajectoryProjection p = project_trajectory(fit_of({-1.2, 0.6}, {1.0, -2.4}, -2.0), hand_v());
  ASSERT_TRUE(p.valid);
  EXPECT_EQ(p.flipper, kLeftFlipper);
  EXPECT_NEAR(p.t_impact_s, 0.4, 1e-12);
  EXPECT_NEAR(p.h, 0.4, 1e-12);
  EXPECT_NEAR((p.impact_point - Vec2(-0.8, -0.2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(p.speed_mps, std::hypot(1.0, -2.4 + 2.0 * 0.4), 1e-12);
}

TEST(ProjectTrajectory, IgnoresPastRoots) {
  // Rising straight up from (-0.75, 0.5) at 3 m/s, g = 2: the line x = -0.75
  // meets the flipper at y = -0.25 both 0.232 s ago (τ < 0) and, after the
  // ball comes back down, in τ = (3 + √12)/2. Only the future one counts.
  const TrajectoryProjection p = project_trajectory(fit_of({-0.75, 0.5}, {0.0, 3.0}, 2.0), hand_v());
  const double tau = 0.5 * (3.0 + std::sqrt(12.0));
  ASSERT_TRUE(p.valid);
  EXPECT_NEAR(p.t_impact_s, tau, 1e-12);
  EXPECT_GT(p.t_impact_s, 0.0);
  EXPECT_NEAR(p.h, 0.5, 1e-12);
  EXPECT_NEAR(p.speed_mps, 2.0 * tau - 3.0, 1e-12);  // coming down
  EXPECT_EQ(p.angle_rad, -kPi / 2.0);
  EXPECT_NEAR(p.d_m, 0.75, 1e-12);  // from the ball now, not along the path
}

TEST(ProjectTrajectory, TangentTrajectoryGivesADefinedAnswer) {
  // Convex path (g = -2) from (-1.5, 1.5) at (1, -3): y = 1.5 - 3τ + τ² touches
  // y = -x - 1 at τ = 1, at the tip (-0.5, -0.5): a double root (discriminant 0).
  const TrajectoryProjection p = project_trajectory(fit_of({-1.5, 1.5}, {1.0, -3.0}, -2.0), hand_v());
  ASSERT_TRUE(p.valid);
  expect_finite(p);
  EXPECT_EQ(p.flipper, kLeftFlipper);
  EXPECT_NEAR(p.t_impact_s, 1.0, 1e-12);
  EXPECT_NEAR(p.h, 1.0, 1e-12);
  EXPECT_NEAR(p.angle_rad, -kPi / 4.0, 1e-12);  // along the flipper
  EXPECT_NEAR(p.speed_mps, std::sqrt(2.0), 1e-12);

  // With real gravity a parabola lies below its tangents: a path touching a
  // flipper line starts on or below it. Starting at the touching point itself
  // (velocity along the flipper) is "below", defined and finite.
  const TrajectoryProjection q = project_trajectory(fit_of({-0.75, -0.25}, {0.5, -0.5}, 2.0), hand_v());
  EXPECT_FALSE(q.valid);
  EXPECT_EQ(q.reason, NoProjection::kBelowFlippers);
  expect_finite(q);

  // Grazing paths around tangency: each answer is finite, valid or not.
  for (int i = -50; i <= 50; ++i) {
    const double vy = -3.0 + 1e-9 * i;
    const TrajectoryProjection r = project_trajectory(fit_of({-1.5, 1.5}, {1.0, vy}, -2.0), hand_v());
    expect_finite(r);
    if (r.valid) {
      EXPECT_EQ(r.flipper, kLeftFlipper);
    }
  }
}

TEST(ProjectTrajectory, BallBelowTheFlippers) {
  for (const Vec2& p0 : {Vec2(0.0, -1.5), Vec2(-0.75, -0.3), Vec2(0.75, -0.3), Vec2(0.0, -1.0)}) {
    const TrajectoryProjection p = project_trajectory(fit_of(p0, {0.0, 1.0}, 2.0), hand_v());
    EXPECT_FALSE(p.valid);
    EXPECT_FALSE(p.hittable);
    EXPECT_EQ(p.reason, NoProjection::kBelowFlippers) << p0.transpose();
    EXPECT_EQ(p.t_observation_s, 10.0);
  }
}

TEST(ProjectTrajectory, TrajectoriesThatMissTheV) {
  // Going up and away with no gravity to bring it back: both roots are past.
  const TrajectoryProjection up = project_trajectory(fit_of({0.0, 0.5}, {0.0, 1.0}, 0.0), hand_v());
  EXPECT_FALSE(up.valid);
  EXPECT_EQ(up.reason, NoProjection::kNoImpact);
  // Fast sideways: x = 5τ, y = 0.5 + τ - τ² crosses the right line at
  // τ = (-4 + √22)/2, x ≈ 1.73, outside the right pivot (h < 0).
  const TrajectoryProjection out = project_trajectory(fit_of({0.0, 0.5}, {5.0, 1.0}, 2.0), hand_v());
  EXPECT_FALSE(out.valid);
  EXPECT_FALSE(out.hittable);
  EXPECT_EQ(out.reason, NoProjection::kNoImpact);
  // Falling just outside the left pivot (still above the extended left line).
  const TrajectoryProjection side = project_trajectory(fit_of({-1.01, 3.0}, {0.0, 0.0}, 2.0), hand_v());
  EXPECT_FALSE(side.valid);
  EXPECT_EQ(side.reason, NoProjection::kNoImpact);  // meets the left line at h < 0, the right past the apex
  // Moving horizontally with no gravity, parallel to nothing: leaves sideways.
  const TrajectoryProjection flat = project_trajectory(fit_of({0.0, 0.5}, {1.0, 0.0}, 0.0), hand_v());
  EXPECT_EQ(flat.reason, NoProjection::kNoImpact);
  expect_finite(up);
  expect_finite(out);
  expect_finite(flat);
}

TEST(ProjectTrajectory, InvalidFitHasTooFewPoints) {
  TrajectoryFit f = fit_of({0.0, 0.5}, {0.0, 0.0}, 2.0);
  f.valid = false;
  const TrajectoryProjection p = project_trajectory(f, hand_v());
  EXPECT_FALSE(p.valid);
  EXPECT_EQ(p.reason, NoProjection::kTooFewPoints);
}

TEST(ProjectTrajectory, GravityOffByHalfStillProjects) {
  // Thesis 4.1.1: g 50 % off still plays well. On the real flippers, a ball
  // falling at the left flipper projects finitely for g ± 50 %.
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const FlipperGeometry g = flipper_geometry_from_board(board);
  const Vec2 p0{0.20, 0.35};
  const Vec2 v0{0.05, -0.6};
  double t_prev = INFINITY;
  for (const double scale : {0.5, 1.0, 1.5}) {
    const TrajectoryProjection p = project_trajectory(fit_of(p0, v0, scale * board.gravity_mps2), g);
    ASSERT_TRUE(p.valid) << scale;
    expect_finite(p);
    EXPECT_EQ(p.flipper, kLeftFlipper);
    EXPECT_GT(p.h, 0.0);
    EXPECT_LT(p.h, g.h_apex[kLeftFlipper]);
    EXPECT_LT(p.t_impact_s, t_prev);  // stronger gravity arrives sooner
    t_prev = p.t_impact_s;
  }
}

TEST(ProjectTrajectory, RandomFitsNeverGiveNaN) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const FlipperGeometry g = flipper_geometry_from_board(board);
  Rng rng(11);
  int valid = 0;
  for (int i = 0; i < 100000; ++i) {
    const Vec2 p0{rng.uniform(-0.1, 0.6), rng.uniform(-0.1, 1.2)};
    Vec2 v0{rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0)};
    if (i % 7 == 0) v0.x() = 0.0;
    if (i % 11 == 0) v0.y() = 0.0;
    const double gravity = i % 13 == 0 ? 0.0 : rng.uniform(-2.0, 3.0);
    const TrajectoryProjection p = project_trajectory(fit_of(p0, v0, gravity), g);
    ASSERT_TRUE(std::isfinite(p.speed_mps) && std::isfinite(p.angle_rad) && std::isfinite(p.h) &&
                std::isfinite(p.d_m) && std::isfinite(p.t_impact_s))
        << i;
    ASSERT_EQ(p.valid, p.reason == NoProjection::kNone) << i;
    if (p.valid) {
      ++valid;
      ASSERT_GE(p.t_impact_s, 0.0);
      ASSERT_GE(p.h, 0.0);
      ASSERT_LE(p.h, g.h_apex[p.flipper]);
      ASSERT_LE(std::abs(p.angle_rad), kPi / 2.0);
    }
  }
  EXPECT_GT(valid, 1000);
}

TEST(RollingProjection, HeadsForTheOtherFlipperAtTheApex) {
  const FlipperGeometry g = hand_v();
  const Vec2 ball{-0.8, -0.1};
  const TrajectoryProjection p = rolling_projection(g, kLeftFlipper, ball, 0.5, 42.0);
  ASSERT_TRUE(p.valid);
  EXPECT_EQ(p.reason, NoProjection::kNone);
  EXPECT_TRUE(p.rolling);
  EXPECT_TRUE(p.hittable);
  EXPECT_EQ(p.flipper, kRightFlipper);
  EXPECT_EQ(p.h, g.h_apex[kRightFlipper]);
  EXPECT_NEAR(p.angle_rad, -kPi / 4.0, 1e-12);  // the left flipper slopes down to the right
  EXPECT_EQ(p.speed_mps, 0.5);
  EXPECT_NEAR(p.d_m, std::hypot(0.8, 0.9), 1e-12);  // to the apex (0, -1)
  EXPECT_NEAR(p.t_impact_s, p.d_m / 0.5, 1e-12);
  EXPECT_EQ(p.impact_point, g.apex);
  EXPECT_EQ(p.t_observation_s, 42.0);

  const TrajectoryProjection q = rolling_projection(g, kRightFlipper, {0.8, -0.1}, 0.5, 42.0);
  EXPECT_EQ(q.flipper, kLeftFlipper);
  EXPECT_EQ(q.h, g.h_apex[kLeftFlipper]);
  EXPECT_NEAR(q.angle_rad, kPi / 4.0, 1e-12);  // the right flipper's slope, folded into [−π/2, π/2]
}

TEST(RollingProjection, BallAtRestOrBadSpeedStaysFinite) {
  const FlipperGeometry g = hand_v();
  const TrajectoryProjection rest = rolling_projection(g, kLeftFlipper, {-0.8, -0.1}, 0.0, 1.0);
  ASSERT_TRUE(rest.valid);
  expect_finite(rest);
  EXPECT_GT(rest.t_impact_s, 1e3);  // "never", as a large finite number
  const TrajectoryProjection nan = rolling_projection(g, kLeftFlipper, {-0.8, -0.1}, NAN, 1.0);
  expect_finite(nan);
  EXPECT_EQ(nan.speed_mps, 0.0);
}

TEST(FoldToHalfPlane, FoldsDirectionsIntoSlopes) {
  EXPECT_EQ(fold_to_half_plane(0.0), 0.0);
  EXPECT_EQ(fold_to_half_plane(kPi / 2.0), kPi / 2.0);
  EXPECT_EQ(fold_to_half_plane(-kPi / 2.0), -kPi / 2.0);
  EXPECT_NEAR(fold_to_half_plane(kPi), 0.0, 1e-15);
  EXPECT_NEAR(fold_to_half_plane(-kPi), 0.0, 1e-15);
  EXPECT_NEAR(fold_to_half_plane(3.0 * kPi / 4.0), -kPi / 4.0, 1e-15);
  EXPECT_NEAR(fold_to_half_plane(-3.0 * kPi / 4.0), kPi / 4.0, 1e-15);
  EXPECT_NEAR(fold_to_half_plane(0.3), 0.3, 0.0);
  Rng rng(5);
  for (int i = 0; i < 10000; ++i) {
    const double a = rng.uniform(-kPi, kPi);
    const double f = fold_to_half_plane(a);
    ASSERT_LE(std::abs(f), kPi / 2.0);
    ASSERT_NEAR(std::sin(f) * std::cos(a), std::cos(f) * std::sin(a), 1e-12);  // same slope
  }
}

TEST(NoProjectionNames, AreDistinct) {
  std::set<std::string> names;
  for (const NoProjection r : {NoProjection::kNone, NoProjection::kTooFewPoints, NoProjection::kOutsideCritical,
                               NoProjection::kBelowFlippers, NoProjection::kNoImpact, NoProjection::kNumerical}) {
    names.insert(to_string(r));
  }
  EXPECT_EQ(names.size(), 6u);
  EXPECT_STREQ(to_string(NoProjection::kNone), "none");
}

TEST(LeadProjection, AdvancesDistanceAndTimeAlongTheFitToWhenTheCoilActs) {
  // The vertical fall above: impact after √1.25 s, 1.25 m below the start.
  const TrajectoryFit fit = fit_of({-0.75, 1.0}, {0.0, 0.0}, 2.0);
  TrajectoryProjection p = project_trajectory(fit, hand_v());
  p.latency_s = 0.2;
  const TrajectoryProjection led = lead_projection(p, fit, 0.5);
  ASSERT_TRUE(led.valid);
  EXPECT_NEAR(led.t_impact_s, std::sqrt(1.25) - 0.5, 1e-12);
  EXPECT_NEAR(led.d_m, 1.25 - 0.5 * 2.0 * 0.25, 1e-12);  // fallen g·t²/2 = 0.25 m by then
  EXPECT_EQ(led.impact_point, p.impact_point);
  EXPECT_EQ(led.speed_mps, p.speed_mps);
  EXPECT_EQ(led.h, p.h);
  EXPECT_EQ(led.t_observation_s, p.t_observation_s);
  // No lead, or an invalid projection: unchanged.
  EXPECT_EQ(lead_projection(p, fit, 0.0).d_m, p.d_m);
  const TrajectoryProjection none{};
  EXPECT_FALSE(lead_projection(none, fit, 0.5).valid);
  // The impact comes before the coil can act: d and t are 0, never negative.
  const TrajectoryProjection late = lead_projection(p, fit, 2.0);
  EXPECT_EQ(late.d_m, 0.0);
  EXPECT_EQ(late.t_impact_s, 0.0);
  EXPECT_TRUE(late.valid);
}

TEST(LeadProjection, ARollingBallAdvancesAtItsSpeed) {
  const TrajectoryProjection p = rolling_projection(hand_v(), kLeftFlipper, {-0.75, -0.25}, 0.5, 3.0);
  ASSERT_TRUE(p.rolling);
  const TrajectoryProjection led = lead_projection(p, TrajectoryFit{}, 0.1);
  EXPECT_NEAR(led.d_m, p.d_m - 0.05, 1e-12);
  EXPECT_NEAR(led.t_impact_s, p.t_impact_s - 0.1, 1e-12);
}

}  // namespace
}  // namespace pinball::track
