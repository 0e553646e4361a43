#include "pinball/track/launch_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "pinball/core/rng.h"
#include "pinball/table/board_loader.h"

namespace pinball::track {
namespace {



FlipperEllipse mit1993_ellipse() {
  static const FlipperEllipse e =
      flipper_ellipse(flipper_geometry_from_board(table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board")));
  return e;
}

// The point at `scale` times the ellipse in direction phi (level = scale²).
Vec2 on_ellipse(const FlipperEllipse& e, double scale, double phi) {
  return e.centre + scale * Vec2(e.a_m * std::cos(phi), e.b_m * std::sin(phi));
}

// Position only: no fit, not rolling.
LaunchEvent at(LaunchDetector& d, const Vec2& p) { return d.update(p, false, 0.0, false); }

TEST(FlipperEllipse, Mit1993ByHand) {
  const FlipperEllipse e = mit1993_ellipse();
  const double s = std::sin(25.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(e.centre.x(), 0.255, 1e-12);
  EXPECT_NEAR(e.centre.y(), 0.160 - 0.5 * 0.076 * s, 1e-12);  // midway between pivots and tips
  EXPECT_NEAR(e.a_m, 0.09 + 0.076, 1e-12);                      // a flipper length past each pivot
  EXPECT_NEAR(e.b_m, 0.076, 1e-12);
  EXPECT_DOUBLE_EQ(e.level(on_ellipse(e, 1.0, 0.7)), 1.0);
  EXPECT_DOUBLE_EQ(e.level(on_ellipse(e, 0.5, -2.0)), 0.25);
}

TEST(LaunchDetector, EnteringNeedsTheInnerEllipse) {
  const FlipperEllipse e = mit1993_ellipse();
  LaunchDetector d(e);  // inner 0.85, outer 1.15
  for (const double phi : {std::numbers::pi / 2.0, 0.3, std::numbers::pi}) {
    d.reset();
    EXPECT_FALSE(at(d, on_ellipse(e, 1.0, phi)).entered);
    EXPECT_FALSE(at(d, on_ellipse(e, 0.86, phi)).entered);  // between inner and the ellipse: not yet
    EXPECT_FALSE(d.inside());
    const LaunchEvent in = at(d, on_ellipse(e, 0.84, phi));
    EXPECT_TRUE(in.entered);
    EXPECT_FALSE(in.launched || in.lost);
    EXPECT_TRUE(d.inside());
    EXPECT_FALSE(at(d, on_ellipse(e, 0.5, phi)).entered);  // once
  }
}

TEST(LaunchDetector, LeavingNeedsTheOuterEllipse) {
  const FlipperEllipse e = mit1993_ellipse();
  LaunchDetector d(e);
  at(d, e.centre);
  ASSERT_TRUE(d.inside());
  for (const double s : {0.9, 1.0, 1.1, 1.14}) {
    const LaunchEvent ev = at(d, on_ellipse(e, s, std::numbers::pi / 2.0));
    EXPECT_FALSE(ev.launched || ev.lost) << s;
    EXPECT_TRUE(d.inside()) << s;
  }
  const LaunchEvent out = at(d, on_ellipse(e, 1.16, std::numbers::pi / 2.0));
  EXPECT_TRUE(out.launched);
  EXPECT_FALSE(out.lost);
  EXPECT_FALSE(d.inside());
  // Outside now: going further out is no second launch.
  EXPECT_FALSE(at(d, on_ellipse(e, 2.0, std::numbers::pi / 2.0)).launched);
}

TEST(LaunchDetector, LeavingUpwardIsALaunchDownwardALoss) {
  const FlipperEllipse e = mit1993_ellipse();
  for (const double phi : {std::numbers::pi / 2.0, 0.2, std::numbers::pi - 0.2, 1e-3}) {  // up, up-right, up-left, sideways a hair up
    LaunchDetector d(e);
    at(d, e.centre);
    const LaunchEvent ev = at(d, on_ellipse(e, 1.3, phi));
    EXPECT_TRUE(ev.launched) << phi;
    EXPECT_FALSE(ev.lost) << phi;
  }
  for (const double phi : {-std::numbers::pi / 2.0, -0.2, -std::numbers::pi + 0.2}) {  // through the drain gap or past a pivot
    LaunchDetector d(e);
    at(d, e.centre);
    const LaunchEvent ev = at(d, on_ellipse(e, 1.3, phi));
    EXPECT_TRUE(ev.lost) << phi;
    EXPECT_FALSE(ev.launched) << phi;
  }
  // Passing by outside the ellipse is nothing.
  LaunchDetector d(e);
  for (double phi = 0.0; phi < 2.0 * std::numbers::pi; phi += 0.1) {
    const LaunchEvent ev = at(d, on_ellipse(e, 0.9, phi));
    EXPECT_FALSE(ev.launched || ev.lost || ev.entered) << phi;
  }
}

// Jitters a ball resting at scale 1 of the ellipse in several directions.
// Returns the number of launch or loss events.
int jitter_events(const FlipperEllipse& e, const LaunchDetectorConfig& config, double noise_m, bool start_inside) {
  Rng rng(77);
  int events = 0;
  for (const double phi : {std::numbers::pi / 2.0, 0.0, std::numbers::pi, 0.4, -0.4, -std::numbers::pi / 2.0}) {
    LaunchDetector d(e, config);
    if (start_inside) at(d, e.centre);
    const Vec2 rest = on_ellipse(e, 1.0, phi);
    for (int i = 0; i < 2000; ++i) {
      const LaunchEvent ev = at(d, rest + noise_m * Vec2(rng.normal(), rng.normal()));
      if (ev.launched || ev.lost) ++events;
    }
  }
  return events;
}

TEST(LaunchDetector, CameraJitterAtTheBoundaryIsNoLaunch) {
  const FlipperEllipse e = mit1993_ellipse();
  for (const double noise : {0.001, 0.002}) {
    EXPECT_EQ(jitter_events(e, {}, noise, true), 0) << noise;
    EXPECT_EQ(jitter_events(e, {}, noise, false), 0) << noise;
  }
  // Without the hysteresis the same jitter would flip on and off: the test bites.
  LaunchDetectorConfig none;
  none.inner_scale = 1.0;
  none.outer_scale = 1.0;
  EXPECT_GT(jitter_events(e, none, 0.001, true), 100);
}

TEST(LaunchDetector, VelocityReversalInsideIsALaunch) {
  const FlipperEllipse e = mit1993_ellipse();
  const Vec2 p = e.centre + Vec2(0.03, 0.02);
  LaunchDetector d(e);  // reversal at ±0.15 m/s after 3 falling updates
  at(d, p);
  ASSERT_TRUE(d.inside());
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(d.update(p, true, -0.5, false).launched);
  const LaunchEvent ev = d.update(p, true, 0.6, false);
  EXPECT_TRUE(ev.launched);
  EXPECT_FALSE(ev.lost);
  // The count restarted: one more rise is nothing; a new fall then a rise is.
  EXPECT_FALSE(d.update(p, true, 0.6, false).launched);
  for (int i = 0; i < 3; ++i) d.update(p, true, -0.5, false);
  EXPECT_TRUE(d.update(p, true, 0.6, false).launched);
}

TEST(LaunchDetector, ReversalNeedsEnoughFallingUpdatesAndTheEllipse) {
  const FlipperEllipse e = mit1993_ellipse();
  const Vec2 inside = e.centre + Vec2(0.03, 0.02);
  {
    LaunchDetector d(e);
    at(d, inside);
    d.update(inside, true, -0.5, false);
    d.update(inside, true, -0.5, false);
    EXPECT_FALSE(d.update(inside, true, 0.6, false).launched);  // two falling updates are not enough
  }
  {
    LaunchDetector d(e);
    at(d, inside);
    for (int i = 0; i < 5; ++i) d.update(inside, true, -0.1, false);  // too slow to count as falling
    EXPECT_FALSE(d.update(inside, true, 0.6, false).launched);
  }
  {
    LaunchDetector d(e);
    at(d, inside);
    for (int i = 0; i < 5; ++i) d.update(inside, true, -0.5, false);
    EXPECT_FALSE(d.update(inside, true, 0.1, false).launched);  // a slow rise is not a reversal
    EXPECT_FALSE(d.update(inside, false, 0.6, false).launched); // nor a rise without a valid fit
    EXPECT_TRUE(d.update(inside, true, 0.6, false).launched);
  }
  {
    const Vec2 far = on_ellipse(e, 3.0, std::numbers::pi / 2.0);  // a bounce high on the table is no flip
    LaunchDetector d(e);
    for (int i = 0; i < 5; ++i) d.update(far, true, -0.5, false);
    EXPECT_FALSE(d.update(far, true, 0.6, false).launched);
  }
}

TEST(LaunchDetector, NoReversalLaunchWhileRolling) {
  const FlipperEllipse e = mit1993_ellipse();
  const Vec2 p = e.centre + Vec2(-0.04, 0.01);
  {
    LaunchDetector d(e);
    at(d, p);
    for (int i = 0; i < 4; ++i) d.update(p, true, -0.5, false);
    EXPECT_FALSE(d.update(p, true, 0.6, true).launched);   // rolling: the fitted vy means nothing
    EXPECT_FALSE(d.update(p, true, 0.6, false).launched);  // and rolling cleared the falling count
  }
  {
    LaunchDetector d(e);
    at(d, p);
    for (int i = 0; i < 6; ++i) d.update(p, true, -0.5, true);  // falling while rolling does not count
    EXPECT_FALSE(d.update(p, true, 0.6, false).launched);
  }
  {
    // A rolling ball is launched by leaving the ellipse upward.
    LaunchDetector d(e);
    d.update(p, false, 0.0, true);
    ASSERT_TRUE(d.inside());
    EXPECT_TRUE(d.update(on_ellipse(e, 1.2, 1.0), false, 0.0, true).launched);
  }
}

TEST(LaunchDetector, ResetForgetsTheBall) {
  const FlipperEllipse e = mit1993_ellipse();
  LaunchDetector d(e);
  at(d, e.centre);
  for (int i = 0; i < 3; ++i) d.update(e.centre, true, -0.5, false);
  d.reset();
  EXPECT_FALSE(d.inside());
  const LaunchEvent out = at(d, on_ellipse(e, 1.5, std::numbers::pi / 2.0));
  EXPECT_FALSE(out.launched || out.lost);
  at(d, e.centre);
  EXPECT_FALSE(d.update(e.centre, true, 0.6, false).launched);  // the falling count went too
}

}  // namespace
}  // namespace pinball::track
