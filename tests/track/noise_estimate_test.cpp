#include "pinball/track/noise_estimate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pinball/core/rng.h"

namespace pinball::track {
namespace {

constexpr double kTrackFrame_s = 0.005;  // 200 fps

Observation frame_at(double t_s, const Vec2& p) {
  Observation o;
  o.t_s = t_s;
  o.p_board = p;
  return o;
}

// A ball falling under g from (0.2, 0.8) at (0.6, 1.5) m/s, seen with Gaussian
// noise sigma per coordinate; every `bounce_every` frames (0: never) its
// velocity turns round, as off a wall.
double measured_sigma(double sigma_m, int frames, int bounce_every, std::uint64_t seed = 1) {
  ObservationNoiseEstimator e;
  Rng rng(seed);
  Vec2 p(0.2, 0.8), v(0.6, 1.5);
  for (int k = 0; k < frames; ++k) {
    if (bounce_every > 0 && k > 0 && k % bounce_every == 0) v = -v;
    p += v * kTrackFrame_s;
    v.y() -= 1.11 * kTrackFrame_s;
    e.add(frame_at(k * kTrackFrame_s, p + sigma_m * Vec2(rng.normal(), rng.normal())));
  }
  return e.sigma_m().value_or(-1.0);
}

TEST(ObservationNoiseEstimator, MeasuresTheNoiseOfAFallingBall) {
  for (const double sigma : {0.0007, 0.002, 0.005}) {
    EXPECT_NEAR(measured_sigma(sigma, 2000, 0), sigma, 0.1 * sigma) << sigma;
  }
}

TEST(ObservationNoiseEstimator, BouncesDoNotInflateIt) {
  // A bounce every 10 frames spoils 3 residuals in 10; the smaller half stands.
  EXPECT_NEAR(measured_sigma(0.002, 2000, 10), 0.002, 0.2 * 0.002);
}

TEST(ObservationNoiseEstimator, AStraightPathAtUnevenSpacingHasNoResidual) {
  ObservationNoiseEstimator e;
  double t = 0.0;
  for (int k = 0; k < 200; ++k) {
    t += k % 2 == 0 ? 0.004 : 0.0065;
    e.add(frame_at(t, Vec2(0.1 + 2.0 * t, 0.5 - 1.0 * t)));
  }
  ASSERT_TRUE(e.sigma_m().has_value());
  EXPECT_LT(*e.sigma_m(), 1e-9);
}

TEST(ObservationNoiseEstimator, SaysNothingUntilItHasEnoughResiduals) {
  ObservationNoiseEstimator e;
  // n frames make n − 2 triples, two residuals each.
  const int frames = static_cast<int>(ObservationNoiseEstimator::kMinResiduals / 2) + 2;
  for (int k = 0; k < frames - 1; ++k) e.add(frame_at(k * kTrackFrame_s, Vec2(0.1, 0.1 * k)));
  EXPECT_FALSE(e.sigma_m().has_value());
  e.add(frame_at((frames - 1) * kTrackFrame_s, Vec2(0.1, 0.1 * (frames - 1))));
  EXPECT_TRUE(e.sigma_m().has_value());
  EXPECT_EQ(e.residuals(), ObservationNoiseEstimator::kMinResiduals);
}

TEST(ObservationNoiseEstimator, NoTripleSpansAGapANewTrackOrAnOldFrame) {
  ObservationNoiseEstimator e;
  double t = 0.0;
  auto line = [&](double x0, int n) {
    for (int k = 0; k < n; ++k, t += kTrackFrame_s) e.add(frame_at(t, Vec2(x0 + 0.01 * k, 0.3)));
  };
  line(0.0, 100);
  t += 0.2;  // a gap, then the ball somewhere else
  line(0.4, 100);
  e.restart_track();  // a new ball, elsewhere at once
  line(0.1, 100);
  e.add(frame_at(t - 1.5 * kTrackFrame_s, Vec2(0.9, 0.9)));  // older than the last frame: ignored
  line(0.1 + 0.01 * 100, 2);
  ASSERT_TRUE(e.sigma_m().has_value());
  EXPECT_LT(*e.sigma_m(), 1e-9);
  EXPECT_EQ(e.residuals(), 2u * (98 + 98 + 98 + 2));  // triples within each run of frames only
}

TEST(ObservationNoiseEstimator, KeepsOnlyTheLatestResiduals) {
  ObservationNoiseEstimator e;
  Rng rng(3);
  for (int k = 0; k < 1000; ++k) e.add(frame_at(k * kTrackFrame_s, Vec2(0.2, 0.5) + 0.01 * Vec2(rng.normal(), rng.normal())));
  for (int k = 1000; k < 1600; ++k) e.add(frame_at(k * kTrackFrame_s, Vec2(0.2, 0.5) + 0.001 * Vec2(rng.normal(), rng.normal())));
  EXPECT_NEAR(*e.sigma_m(), 0.001, 0.15 * 0.001);  // the camera got better: the old frames are gone
}

}  // namespace
}  // namespace pinball::track
