#include "pinball/track/tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "pinball/core/rng.h"
#include "pinball/table/board_loader.h"
#include "common/thesis_board.h"

namespace pinball::track {
namespace {

constexpr double kFrame_s = 0.005;  // 200 fps
constexpr ContactSensors kNoContact{};

using pinball::testing::thesis_board;

FlipperGeometry geometry() { return flipper_geometry_from_board(thesis_board()); }
TrackerConfig config() { return default_tracker_config(thesis_board(), CameraModelConfig{}); }

Observation obs(double t_s, const Vec2& p) {
  Observation o;
  o.t_s = t_s;
  o.p_board = p;
  return o;
}

// Free flight under gravity g along −y.
struct Flight {
  double t0_s;
  Vec2 p0;
  Vec2 v0;
  double g;
  Vec2 at(double t_s) const {
    const double tau = t_s - t0_s;
    return {p0.x() + v0.x() * tau, p0.y() + v0.y() * tau - 0.5 * g * tau * tau};
  }
  Vec2 velocity(double t_s) const { return {v0.x(), v0.y() - g * (t_s - t0_s)}; }
};

// The first time after t_from at which the flight leaves the region above
// both flipper lines, found by scanning and bisection (not by the tracker's
// quadratic), and the line it crosses there.
struct Impact {
  double t_s = 0.0;
  int flipper = -1;
  double h = 0.0;
  Vec2 point = Vec2::Zero();
};

Impact analytic_impact(const Flight& f, const FlipperGeometry& g, double t_from) {
  auto margin = [&](double t, int line) {
    const FlipperLine& l = g.lines[static_cast<std::size_t>(line)];
    const double c = cross(l.axis(), f.at(t) - l.pivot) / l.axis().norm();
    return line == kLeftFlipper ? c : -c;  // > 0 above the line
  };
  auto inside = [&](double t) { return margin(t, kLeftFlipper) > 0.0 && margin(t, kRightFlipper) > 0.0; };
  double lo = t_from;
  double hi = t_from;
  while (inside(hi)) {
    lo = hi;
    hi += 1e-4;
    if (hi > t_from + 100.0) return {};
  }
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double mid = 0.5 * (lo + hi);
    (inside(mid) ? lo : hi) = mid;
  }
  Impact im;
  im.t_s = hi;
  im.point = f.at(hi);
  im.flipper = std::abs(margin(hi, kLeftFlipper)) < std::abs(margin(hi, kRightFlipper)) ? kLeftFlipper
                                                                                         : kRightFlipper;
  const FlipperLine& l = g.lines[static_cast<std::size_t>(im.flipper)];
  im.h = (im.point - l.pivot).dot(l.axis()) / l.axis().squaredNorm();
  return im;
}

// The window of eq. 4.5 over `points` (oldest first), written out again.
int expected_window(const std::vector<Vec2>& points, double d, int max_window, int min_window) {
  const int size = static_cast<int>(points.size());
  const int limit = std::min(size, max_window);
  const int floor = std::min(limit, min_window);
  const Vec2& b0 = points.back();
  for (int n = 1; n < limit; ++n) {
    if ((points[static_cast<std::size_t>(size - 1 - n)] - b0).norm() >= d) return std::max(n + 1, floor);
  }
  return limit;
}

void expect_finite(const TrackerOutput& out) {
  const TrajectoryProjection& p = out.projection;
  ASSERT_TRUE(std::isfinite(p.speed_mps) && std::isfinite(p.angle_rad) && std::isfinite(p.h) &&
              std::isfinite(p.d_m) && std::isfinite(p.t_impact_s) && std::isfinite(p.t_observation_s) &&
              std::isfinite(p.impact_point.x()) && std::isfinite(p.impact_point.y()));
  ASSERT_TRUE(std::isfinite(out.fit.p_ref.x()) && std::isfinite(out.fit.p_ref.y()) &&
              std::isfinite(out.fit.v_ref.x()) && std::isfinite(out.fit.v_ref.y()) &&
              std::isfinite(out.fit.g_mps2) && !std::isnan(out.fit.chi2));
}

TEST(DefaultTrackerConfig, FromBoardAndCamera) {
  CameraModelConfig cam;
  cam.noise_px = 1.0;
  const TrackerConfig c = default_tracker_config(thesis_board(), cam);
  EXPECT_EQ(c.g_mps2, thesis_board().gravity_mps2);
  EXPECT_NEAR(c.window_distance_m, 0.038, 1e-12);   // half a 76 mm flipper
  EXPECT_NEAR(c.rolling_epsilon_m, 0.0076, 1e-12);  // a tenth of it
  EXPECT_EQ(c.sigma_m, observation_sigma_m(cam));
  EXPECT_NEAR(c.critical_y_m, 0.16 + 0.35, 1e-12);
  EXPECT_EQ(c.max_gap_s, 0.05);  // ten frames at 200 fps
  cam.fps = 30.0;
  EXPECT_NEAR(default_tracker_config(thesis_board(), cam).max_gap_s, 0.1, 1e-12);  // three at 30
}

TEST(Tracker, BadConfigThrows) {
  const FlipperGeometry g = geometry();
  TrackerConfig c = config();
  c.sigma_m = 0.0;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
  c = config();
  c.window_distance_m = -1.0;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
  c = config();
  c.max_window = 2;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
  c = config();
  c.max_window = 513;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
  c = config();
  c.g_mps2 = NAN;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
  c = config();
  c.max_push_mps2 = -1.0;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
  c.max_push_mps2 = NAN;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
  c = config();
  c.max_gap_s = 0.0;
  EXPECT_THROW(Tracker(g, c), std::invalid_argument);
}

// Feeds 80 noiseless frames of a flight that ends at (0.25, 0.40) moving at
// (vx, 0) and returns the last output's window. min_window 0 is the thesis
// rule alone.
int window_for_speed(double vx, int max_window = 64, int min_window = 0) {
  TrackerConfig c = config();
  c.max_window = max_window;
  c.min_window = min_window;
  Tracker tracker(geometry(), c);
  const Flight f{50.0, {0.25, 0.40}, {vx, 0.0}, c.g_mps2};
  std::vector<Vec2> points;
  int window = -1;
  for (int k = -79; k <= 0; ++k) {
    const double t = 50.0 + k * kFrame_s;
    points.push_back(f.at(t));
    const TrackerOutput& out = tracker.update(obs(t, points.back()), kNoContact);
    EXPECT_FALSE(out.flushed) << vx << " " << k;
    window = out.window;
  }
  EXPECT_EQ(window, expected_window(points, c.window_distance_m, c.max_window, c.min_window)) << vx;
  return window;
}

TEST(Tracker, WindowIsTheFirstPointHalfAFlipperAway) {
  // By hand, d = 0.038 m, frames 5 ms apart, the ball at the top of its arc:
  // 2 m/s:    B_3 is 0.030 m back, B_4 0.040 m: window 5 points.
  // 0.25 m/s: B_28 is √(0.035² + 0.0109²) = 0.0367 m back, B_29 0.0381 m: 30 points.
  // 0.01 m/s: the fall under gravity does it: B_52 is 0.0376 m back, B_53 0.0391 m: 54 points,
  // or the cap when that is lower.
  const int fast = window_for_speed(2.0);
  const int slow = window_for_speed(0.25);
  EXPECT_EQ(fast, 5);
  EXPECT_EQ(slow, 30);
  EXPECT_GT(slow, 5 * fast);
  EXPECT_EQ(window_for_speed(0.01), 54);
  EXPECT_EQ(window_for_speed(0.01, 40), 40);
}

TEST(Tracker, MinimumWindowFloorsTheThesisRuleForFastBalls) {
  EXPECT_EQ(config().min_window, 24);
  EXPECT_EQ(window_for_speed(2.0, 64, 24), 24);  // the thesis rule alone says 5
  EXPECT_EQ(window_for_speed(0.25, 64, 24), 30);  // slow balls already use more
  EXPECT_EQ(window_for_speed(2.0, 16, 24 > 16 ? 16 : 24), 16);
}

TEST(Tracker, NoiselessFreeFallProjectsToTheAnalyticImpact) {
  const FlipperGeometry g = geometry();
  const TrackerConfig c = config();
  Tracker tracker(g, c);
  // Thrown gently up and left from the middle of the table at t = 1000 s.
  const Flight f{1000.0, {0.27, 0.45}, {-0.05, 0.25}, c.g_mps2};
  const Impact im = analytic_impact(f, g, f.t0_s);
  ASSERT_EQ(im.flipper, kLeftFlipper);
  ASSERT_GT(im.h, 0.2);
  ASSERT_LT(im.h, 1.0);  // on the flipper itself
  int valid = 0;
  for (int k = 0; f.t0_s + k * kFrame_s < im.t_s - 0.02; ++k) {
    const double t = f.t0_s + k * kFrame_s;
    const TrackerOutput& out = tracker.update(obs(t, f.at(t)), kNoContact);
    EXPECT_FALSE(out.flushed);
    if (k < 2) {
      EXPECT_FALSE(out.projection.valid);
      EXPECT_EQ(out.projection.reason, NoProjection::kTooFewPoints);
      continue;
    }
    const TrajectoryProjection& p = out.projection;
    ASSERT_TRUE(p.valid) << k;
    ++valid;
    EXPECT_EQ(p.flipper, kLeftFlipper);
    EXPECT_TRUE(p.hittable);
    EXPECT_NEAR(p.h, im.h, 1e-6) << k;
    EXPECT_NEAR(p.t_impact_s, im.t_s - t, 1e-6) << k;
    EXPECT_EQ(p.t_observation_s, t);
    EXPECT_NEAR(p.d_m, (im.point - f.at(t)).norm(), 1e-6) << k;
    EXPECT_NEAR(p.speed_mps, f.velocity(im.t_s).norm(), 1e-6) << k;
    EXPECT_NEAR(p.angle_rad, std::atan(f.velocity(im.t_s).y() / f.velocity(im.t_s).x()), 1e-6) << k;
  }
  EXPECT_GT(valid, 50);
}

// A synthetic collision halfway between two frames: the ball arrives at
// p_break with v_in and leaves with v_out.
struct Collision {
  Vec2 p_break;
  Vec2 v_in;
  Vec2 v_out;
};

TEST(Tracker, Chi2FlushesThePointsBeforeACollision) {
  const FlipperGeometry g = geometry();
  const TrackerConfig c = config();
  const Collision cases[] = {
      {{0.28, 0.30}, {-0.05, -0.6}, {-0.05, 0.6}},  // falling, bounced up (vy reflected)
      {{0.30, 0.40}, {-0.1, 1.5}, {-0.1, -1.5}},    // rising fast, knocked down (vy reflected)
      {{0.45, 0.30}, {0.6, -0.5}, {-0.6, -0.5}},    // off a side wall (vx reflected)
  };
  for (const Collision& cs : cases) {
    SCOPED_TRACE(::testing::Message() << "v_in " << cs.v_in.transpose() << " v_out " << cs.v_out.transpose());
    Tracker tracker(g, c);
    const double t_break = 200.0 + 10.5 * kFrame_s;  // between frames 10 and 11
    const Flight before{t_break, cs.p_break, cs.v_in, c.g_mps2};
    const Flight after{t_break, cs.p_break, cs.v_out, c.g_mps2};
    const Impact im = analytic_impact(after, g, t_break);
    ASSERT_GT(im.t_s, t_break + 0.1);
    ASSERT_GT(im.h, 0.0);  // the new flight lands on the 'V'
    ASSERT_LT(im.h, g.h_apex[static_cast<std::size_t>(im.flipper)]);
    int k = 0;
    for (; 200.0 + k * kFrame_s < t_break; ++k) {
      const double t = 200.0 + k * kFrame_s;
      ASSERT_LT(before.at(t).y(), c.critical_y_m);
      ASSERT_FALSE(tracker.update(obs(t, before.at(t)), kNoContact).flushed) << k;
    }
    int post = 0;
    int flushed_at = -1;
    int checked = 0;
    int flushed_again = 0;
    double worst_h = 0.0;
    double worst_t = 0.0;
    for (; 200.0 + k * kFrame_s < im.t_s - 0.02; ++k) {
      const double t = 200.0 + k * kFrame_s;
      ASSERT_LT(after.at(t).y(), c.critical_y_m);
      ++post;
      const TrackerOutput& out = tracker.update(obs(t, after.at(t)), kNoContact);
      if (out.flushed && flushed_at < 0) {
        flushed_at = post;
        // Only points from after the collision are left.
        EXPECT_LE(tracker.history_size(), static_cast<std::size_t>(post))
            << "points from before the collision survived the flush " << post << " points after it";
      }
      if (flushed_at > 0 && post >= flushed_at + 3) {
        // On the new trajectory now: the projection is the new flight's.
        ASSERT_TRUE(out.projection.valid) << post;
        ++checked;
        if (out.flushed) ++flushed_again;
        EXPECT_EQ(out.projection.flipper, im.flipper);
        worst_h = std::max(worst_h, std::abs(out.projection.h - im.h));
        worst_t = std::max(worst_t, std::abs(out.projection.t_impact_s - (im.t_s - t)));
      }
    }
    EXPECT_LT(worst_h, 1e-6) << "h off the new trajectory's";
    EXPECT_LT(worst_t, 1e-6) << "t_impact off the new trajectory's";
    EXPECT_EQ(flushed_again, 0);
    EXPECT_GE(flushed_at, 1);
    EXPECT_LE(flushed_at, 3);
    EXPECT_EQ(tracker.flushes(), 1u);
    EXPECT_GT(checked, 5);
  }
}

// Flushes over 4 s of a ball falling in the critical area, seen with noise
// `noise_m` per coordinate, by a tracker calibrated for c.sigma_m.
std::size_t flushes_with_noise(const TrackerConfig& c, double noise_m, Tracker& tracker) {
  Rng rng(7);
  for (int k = 0; k < 800; ++k) {
    const double t = (k % 100) * kFrame_s;  // a fresh drop every 0.5 s
    if (k % 100 == 0) tracker.reset();
    const Flight f{0.0, {0.2, 0.45}, {0.05, 0.4}, c.g_mps2};
    tracker.update(obs(k * kFrame_s, f.at(t) + noise_m * Vec2(rng.normal(), rng.normal())), kNoContact);
  }
  return tracker.flushes();
}

TEST(Tracker, ACameraNoisierThanItsCalibrationIsMeasuredAndFlushesFarLess) {
  const TrackerConfig c = config();
  TrackerConfig thesis = c;
  thesis.estimate_noise = false;
  Tracker measuring(geometry(), c);
  Tracker believing(geometry(), thesis);
  const double noise = 5.0 * c.sigma_m;
  const std::size_t measured = flushes_with_noise(c, noise, measuring);
  const std::size_t believed = flushes_with_noise(thesis, noise, believing);
  ASSERT_TRUE(measuring.measured_sigma_m().has_value());
  EXPECT_NEAR(measuring.sigma_m(), noise, 0.15 * noise);
  EXPECT_DOUBLE_EQ(believing.sigma_m(), c.sigma_m);
  // Believing its calibration, the tracker flushes at about one frame in five
  // (a flush leaves 3 points, which pass for a while); measuring, it flushes
  // while it learns (the first 34 frames) and seldom after.
  EXPECT_GT(believed, 100u);
  EXPECT_LT(measured, believed / 5);
}

TEST(Tracker, ACameraAsGoodAsItsCalibrationIsTrackedWithTheCalibration) {
  const TrackerConfig c = config();
  Tracker tracker(geometry(), c);
  flushes_with_noise(c, c.sigma_m, tracker);
  ASSERT_TRUE(tracker.measured_sigma_m().has_value());
  EXPECT_NEAR(*tracker.measured_sigma_m(), c.sigma_m, 0.15 * c.sigma_m);
  EXPECT_DOUBLE_EQ(tracker.sigma_m(), c.sigma_m);
}

TEST(Tracker, WithoutChi2FlushTheOldPointsLinger) {
  // The same collision with the test off: the first fits after it are wrong
  // (the thesis's "prediction may be incorrect for a few steps").
  const FlipperGeometry g = geometry();
  TrackerConfig c = config();
  c.chi2_flush = false;
  Tracker tracker(g, c);
  const double t_break = 10.5 * kFrame_s;
  const Flight pre{t_break, {0.30, 0.43}, {-0.25, -1.0}, c.g_mps2};
  const Flight after{t_break, pre.p0, {-0.25, 1.0}, c.g_mps2};
  int k = 0;
  for (; k * kFrame_s < t_break; ++k) tracker.update(obs(k * kFrame_s, pre.at(k * kFrame_s)), kNoContact);
  for (int post = 0; post < 3; ++post, ++k) {
    const TrackerOutput& out = tracker.update(obs(k * kFrame_s, after.at(k * kFrame_s)), kNoContact);
    EXPECT_FALSE(out.flushed);
  }
  EXPECT_GT(tracker.history_size(), 10u);
  EXPECT_EQ(tracker.flushes(), 0u);
}

// Feeds 60 frames of a ball pushed by `push` (m/s²) besides g and measures
// the fits' velocity at the newest frame against the truth.
struct PushRun {
  std::size_t flushes = 0;
  std::size_t pushes = 0;
  double worst_pushed_velocity_mps = 0.0;  // over the pushed fits
  double rms_late_velocity_mps = 0.0;      // over every fit from frame 30 on (long windows)
};

PushRun run_pushed(const TrackerConfig& c, const Vec2& push, double sigma_m, std::uint64_t seed = 5) {
  Tracker tracker(geometry(), c);
  Rng rng(seed);
  const Vec2 a = Vec2(0.0, -c.g_mps2) + push;
  const Vec2 p0{0.25, 0.30};
  const Vec2 v0{0.3, 0.4};
  PushRun run;
  double sum_sq = 0.0;
  int late = 0;
  for (int k = 0; k < 60; ++k) {
    const double tau = k * kFrame_s;
    const Vec2 p = p0 + v0 * tau + 0.5 * tau * tau * a + sigma_m * Vec2(rng.normal(), rng.normal());
    const TrackerOutput& out = tracker.update(obs(300.0 + tau, p), kNoContact);
    if (!out.fit.valid) continue;
    const double error = (out.fit.velocity_at(300.0 + tau) - (v0 + tau * a)).norm();
    if (out.pushed) run.worst_pushed_velocity_mps = std::max(run.worst_pushed_velocity_mps, error);
    if (k >= 30) {
      sum_sq += error * error;
      ++late;
    }
  }
  run.flushes = tracker.flushes();
  run.pushes = tracker.pushes();
  run.rms_late_velocity_mps = late > 0 ? std::sqrt(sum_sq / late) : INFINITY;
  return run;
}

TEST(Tracker, ASkiddingBallKeepsItsWindowAndGetsItsVelocityRight) {
  // A ball skidding after a bounce: sliding friction 1.95 m/s² against its
  // slip, plus the slope's fuller pull on a sliding ball (0.44 m/s²).
  const Vec2 skid = Vec2(0.0, -0.44) + 1.95 * Vec2(-0.6, -0.8);
  const TrackerConfig c = config();
  const PushRun noiseless = run_pushed(c, skid, 0.0);
  EXPECT_EQ(noiseless.flushes, 0u);
  EXPECT_GT(noiseless.pushes, 20u);  // once the window is long enough to see the push
  EXPECT_LT(noiseless.worst_pushed_velocity_mps, 1e-6);  // the own acceleration's fit is exact
  // With the camera's noise: the path is held, and the velocity is better
  // than what g forced on short windows, flush after flush, gives.
  TrackerConfig flush_only = c;
  flush_only.max_push_mps2 = 0.0;
  double pushed_sq = 0.0, flushed_sq = 0.0;
  std::size_t pushed_flushes = 0, flush_only_flushes = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const PushRun noisy = run_pushed(c, skid, c.sigma_m, seed);
    const PushRun flushed = run_pushed(flush_only, skid, c.sigma_m, seed);
    EXPECT_EQ(flushed.pushes, 0u);
    pushed_flushes += noisy.flushes;
    flush_only_flushes += flushed.flushes;
    pushed_sq += noisy.rms_late_velocity_mps * noisy.rms_late_velocity_mps;
    flushed_sq += flushed.rms_late_velocity_mps * flushed.rms_late_velocity_mps;
  }
  // Seen when written: 3 flushes against 47; velocity RMS 0.030 against 0.094 m/s.
  EXPECT_LE(pushed_flushes * 5, flush_only_flushes);
  EXPECT_LT(std::sqrt(pushed_sq), 0.5 * std::sqrt(flushed_sq));
}

TEST(Tracker, APushBeyondTheLimitIsFlushedAsACollision) {
  const TrackerConfig c = config();
  const PushRun run = run_pushed(c, Vec2(6.0, 0.0), 0.0);
  EXPECT_EQ(run.pushes, 0u);
  EXPECT_GT(run.flushes, 0u);
}

TEST(Tracker, OutsideTheCriticalAreaThereIsNoProjection) {
  Tracker tracker(geometry(), config());
  for (int k = 0; k < 10; ++k) {
    const double t = k * kFrame_s;
    const TrackerOutput& out = tracker.update(obs(t, {0.25, 0.60 - 0.001 * k}), kNoContact);
    EXPECT_FALSE(out.projection.valid);
    EXPECT_EQ(out.projection.reason, NoProjection::kOutsideCritical);
    EXPECT_EQ(out.projection.t_observation_s, t);
    EXPECT_FALSE(out.fit.valid);
  }
  // Coming down into it, the points from above are still history to fit.
  const TrackerOutput& in = tracker.update(obs(10 * kFrame_s, {0.25, 0.50}), kNoContact);
  EXPECT_NE(in.projection.reason, NoProjection::kOutsideCritical);
}

TEST(Tracker, FewerThanThreePointsHaveNoProjection) {
  Tracker tracker(geometry(), config());
  for (int k = 0; k < 2; ++k) {
    const TrackerOutput& out = tracker.update(obs(k * kFrame_s, {0.2, 0.3 - 0.003 * k}), kNoContact);
    EXPECT_FALSE(out.projection.valid);
    EXPECT_EQ(out.projection.reason, NoProjection::kTooFewPoints);
    EXPECT_FALSE(out.fit.valid);
  }
  const TrackerOutput& out = tracker.update(obs(2 * kFrame_s, {0.2, 0.294}), kNoContact);
  EXPECT_TRUE(out.fit.valid);
  EXPECT_NE(out.projection.reason, NoProjection::kTooFewPoints);
}

TEST(Tracker, RollingOnTheLeftFlipperHeadsForTheRightAtTheEpsilonSpeed) {
  const FlipperGeometry g = geometry();
  const TrackerConfig c = config();  // ε = 7.6 mm
  Tracker tracker(g, c);
  const FlipperLine& left = g.lines[kLeftFlipper];
  const Vec2 dir = left.axis().normalized();
  const Vec2 up{-dir.y(), dir.x()};
  const Vec2 start = left.pivot + 0.0135 * up;  // ball centre resting on the flipper
  // 20 frames at 0.1 m/s (0.5 mm a frame), then 8 at 0.4 m/s (2 mm a frame).
  double s = 0.0;
  double t = 5.0;
  TrackerOutput out;
  for (int k = 0; k < 28; ++k, t += kFrame_s) {
    s += k < 20 ? 0.0005 : 0.002;
    out = tracker.update(obs(t, start + s * dir), ContactSensors{true, false});
    EXPECT_TRUE(out.projection.rolling);
    EXPECT_FALSE(out.fit.valid);
  }
  const Vec2 p = start + s * dir;
  const TrajectoryProjection& r = out.projection;
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.hittable);
  EXPECT_EQ(r.flipper, kRightFlipper);
  EXPECT_EQ(r.h, g.h_apex[kRightFlipper]);
  EXPECT_NEAR(r.angle_rad, -25.0 * std::numbers::pi / 180.0, 1e-12);  // the left flipper's slope
  // B_3 is 6 mm back, B_4 8 mm >= ε: speed = 0.008 m / 0.020 s, not the slow start.
  EXPECT_NEAR(r.speed_mps, 0.4, 1e-9);
  EXPECT_NEAR(r.d_m, (g.apex - p).norm(), 1e-12);
  EXPECT_NEAR(r.t_impact_s, r.d_m / 0.4, 1e-6);
  EXPECT_EQ(r.impact_point, g.apex);
  EXPECT_EQ(tracker.history_size(), 28u);

  // Rolling on the right flipper heads for the left one.
  Tracker other(g, c);
  const TrackerOutput& o = other.update(obs(0.0, g.lines[kRightFlipper].pivot + Vec2(0.0, 0.02)), {false, true});
  EXPECT_EQ(o.projection.flipper, kLeftFlipper);
  EXPECT_TRUE(o.projection.rolling);
  EXPECT_EQ(o.projection.speed_mps, 0.0);  // one point: no speed yet
  EXPECT_TRUE(std::isfinite(o.projection.t_impact_s));

  // Rolling ends: the history restarts at the first free point.
  const Flight f{t, p + Vec2(0.0, 0.01), {0.1, 0.5}, c.g_mps2};
  for (int k = 0; k < 3; ++k, t += kFrame_s) {
    const TrackerOutput& free = tracker.update(obs(t, f.at(t)), kNoContact);
    EXPECT_FALSE(free.projection.rolling);
    EXPECT_EQ(tracker.history_size(), static_cast<std::size_t>(k + 1));
    EXPECT_EQ(free.fit.valid, k == 2) << k;
    if (k < 2) {
      EXPECT_EQ(free.projection.reason, NoProjection::kTooFewPoints);
    } else {
      EXPECT_NEAR(free.fit.v_ref.x(), 0.1, 1e-9);  // the rolling points are not in the fit
    }
  }
}

TEST(Tracker, OutOfOrderAndRepeatedFramesAreIgnored) {
  Tracker tracker(geometry(), config());
  const Flight f{0.0, {0.22, 0.40}, {0.05, -0.3}, 1.11};
  for (int k = 0; k < 6; ++k) tracker.update(obs(k * kFrame_s, f.at(k * kFrame_s)), kNoContact);
  const TrackerOutput before = tracker.update(obs(6 * kFrame_s, f.at(6 * kFrame_s)), kNoContact);
  ASSERT_TRUE(before.projection.valid);
  for (const double t : {6 * kFrame_s, 5.5 * kFrame_s, 0.0, -1.0}) {
    const TrackerOutput& out = tracker.update(obs(t, {0.4, 0.1}), kNoContact);  // a wild point
    EXPECT_EQ(tracker.history_size(), 7u) << t;
    EXPECT_EQ(out.projection.valid, before.projection.valid);
    EXPECT_EQ(out.projection.h, before.projection.h) << t;
    EXPECT_EQ(out.projection.t_impact_s, before.projection.t_impact_s) << t;
    EXPECT_EQ(out.window, before.window);
    EXPECT_FALSE(out.launch.launched || out.launch.lost || out.launch.entered);
  }
  const TrackerOutput& next = tracker.update(obs(7 * kFrame_s, f.at(7 * kFrame_s)), kNoContact);
  EXPECT_EQ(tracker.history_size(), 8u);
  EXPECT_NEAR(next.projection.h, before.projection.h, 1e-9);  // the wild point left no trace
}

// One parabola pushed across a gap had fitted the old path and the new one together, and
// named the wrong flipper (a camera that stalled, then saw the ball again, in pinballd).
TEST(Tracker, AfterAGapTheNewPathIsTrackedAsAFreshTrackerTracksIt) {
  const TrackerConfig c = config();
  const Flight before{0.0, {0.30, 0.45}, {-0.2, -0.3}, c.g_mps2};
  const Flight after{2.2, {0.20, 0.45}, {0.1, -0.5}, c.g_mps2};
  Tracker tracker(geometry(), c);
  Tracker fresh(geometry(), c);
  for (int k = 0; k < 40; ++k) tracker.update(obs(k * kFrame_s, before.at(k * kFrame_s)), kNoContact);
  ASSERT_EQ(tracker.history_size(), 40u);
  for (int k = 0; k < 6; ++k) {
    const double t = 2.2 + k * kFrame_s;
    const TrackerOutput& out = tracker.update(obs(t, after.at(t)), kNoContact);
    const TrackerOutput& alone = fresh.update(obs(t, after.at(t)), kNoContact);
    EXPECT_EQ(tracker.history_size(), static_cast<std::size_t>(k + 1));
    EXPECT_EQ(out.projection.valid, alone.projection.valid) << k;
    EXPECT_EQ(out.projection.flipper, alone.projection.flipper) << k;
    EXPECT_EQ(out.projection.h, alone.projection.h) << k;
    EXPECT_FALSE(out.pushed) << k;
  }
  EXPECT_EQ(tracker.gap_restarts(), 1u);
  // Within the gap allowed, one trajectory: 8 frames missed at 200 fps (45 ms between two seen) are no new path.
  Tracker dropped(geometry(), c);
  for (int k = 0; k < 40; ++k) {
    if (k < 20 || k >= 28) dropped.update(obs(k * kFrame_s, before.at(k * kFrame_s)), kNoContact);
  }
  EXPECT_EQ(dropped.gap_restarts(), 0u);
  EXPECT_EQ(dropped.history_size(), 32u);
}

// A frame stamped far ahead had made every later frame "out of order": the tracker stopped for good.
TEST(Tracker, AClockThatJumpsIsFollowedAndBadTimesAndPlacesAreIgnored) {
  const TrackerConfig c = config();
  const Flight f{10.0, {0.30, 0.45}, {-0.2, -0.3}, c.g_mps2};
  Tracker tracker(geometry(), c);
  for (int k = 0; k < 10; ++k) tracker.update(obs(10.0 + k * kFrame_s, f.at(10.0 + k * kFrame_s)), kNoContact);
  tracker.update(obs(1e6, f.at(10.05)), kNoContact);  // one damaged stamp, far ahead: a gap, a fresh path
  EXPECT_EQ(tracker.history_size(), 1u);
  EXPECT_EQ(tracker.gap_restarts(), 1u);
  for (int k = 11; k < 13; ++k) {  // the true clock again: stale, at first
    tracker.update(obs(10.0 + k * kFrame_s, f.at(10.0 + k * kFrame_s)), kNoContact);
    EXPECT_EQ(tracker.history_size(), 1u) << k;
  }
  for (int k = 13; k < 20; ++k) tracker.update(obs(10.0 + k * kFrame_s, f.at(10.0 + k * kFrame_s)), kNoContact);
  EXPECT_EQ(tracker.gap_restarts(), 2u);
  EXPECT_EQ(tracker.history_size(), 7u) << "tracking on the true clock from its third frame";
  EXPECT_EQ(tracker.ignored(), 2u);

  Tracker nan_first(geometry(), c);
  nan_first.update(obs(NAN, {0.3, 0.4}), kNoContact);
  nan_first.update(obs(1.0, {NAN, 0.4}), kNoContact);
  nan_first.update(obs(1.0 + kFrame_s, {0.3, INFINITY}), kNoContact);
  EXPECT_EQ(nan_first.history_size(), 0u);
  EXPECT_EQ(nan_first.ignored(), 3u);
  for (int k = 0; k < 5; ++k) nan_first.update(obs(10.0 + k * kFrame_s, f.at(10.0 + k * kFrame_s)), kNoContact);
  EXPECT_EQ(nan_first.history_size(), 5u);
}

// A controller that waits for a ball at rest (the cradle cycle) reads where it lies from the output.
TEST(Tracker, TheOutputSaysWhereTheNewestObservationPutTheBall) {
  Tracker tracker(geometry(), config());
  EXPECT_EQ(tracker.update(obs(1.0, {0.3, 0.7}), kNoContact).ball_m, Vec2(0.3, 0.7));  // outside the critical area
  EXPECT_EQ(tracker.update(obs(1.005, {0.31, 0.18}), {false, true}).ball_m, Vec2(0.31, 0.18));  // rolling on a bat
  EXPECT_EQ(tracker.update(obs(1.01, {0.31, 0.4}), kNoContact).ball_m, Vec2(0.31, 0.4));
}

TEST(Tracker, ResetForgetsTheBall) {
  Tracker tracker(geometry(), config());
  const Flight f{100.0, {0.22, 0.40}, {0.05, -0.3}, 1.11};
  for (int k = 0; k < 10; ++k) tracker.update(obs(100.0 + k * kFrame_s, f.at(100.0 + k * kFrame_s)), kNoContact);
  ASSERT_EQ(tracker.history_size(), 10u);
  tracker.reset();
  EXPECT_EQ(tracker.history_size(), 0u);
  // A new ball on a clock that went back (a restarted camera) is accepted.
  const TrackerOutput& out = tracker.update(obs(1.0, {0.3, 0.3}), kNoContact);
  EXPECT_EQ(tracker.history_size(), 1u);
  EXPECT_EQ(out.projection.reason, NoProjection::kTooFewPoints);
}

TEST(Tracker, LaunchEventsComeThroughTheTracker) {
  const FlipperGeometry g = geometry();
  const TrackerConfig c = config();
  Tracker tracker(g, c);
  const FlipperEllipse e = flipper_ellipse(g);
  // Falls into the ellipse on the left flipper, then is flipped straight up out of it.
  const Flight down{0.0, {0.20, 0.30}, {0.0, -0.8}, c.g_mps2};
  bool entered = false;
  int k = 0;
  for (; down.at(k * kFrame_s).y() > 0.16; ++k) {
    entered = entered || tracker.update(obs(k * kFrame_s, down.at(k * kFrame_s)), kNoContact).launch.entered;
  }
  EXPECT_TRUE(entered);
  const double t_flip = k * kFrame_s;
  const Flight up{t_flip, down.at(t_flip), {0.0, 2.5}, c.g_mps2};
  bool launched = false;
  for (int i = 1; i < 40 && !launched; ++i) {
    const double t = t_flip + i * kFrame_s;
    launched = tracker.update(obs(t, up.at(t)), kNoContact).launch.launched;
  }
  EXPECT_TRUE(launched);
  EXPECT_LT(e.level(down.at(t_flip)), 1.0);
}

TEST(Tracker, LongRandomStreamNeverGivesNaN) {
  const FlipperGeometry g = geometry();
  Tracker tracker(g, config());
  Rng rng(2024);
  double t = 0.0;
  Vec2 p{0.25, 0.3};
  int valid = 0;
  int rolling = 0;
  int flushed = 0;
  for (int i = 0; i < 100000; ++i) {
    // Modes change every few hundred updates: jumps anywhere, a random walk,
    // a ball at rest, frames a nanosecond apart.
    const int mode = (i / 300) % 4;
    switch (mode) {
      case 0: p = {rng.uniform(-0.05, 0.56), rng.uniform(-0.05, 1.1)}; break;
      case 1: p += Vec2(rng.normal(), rng.normal()) * 0.002; break;
      case 2: break;
      default: p += Vec2(rng.normal(), rng.normal()) * 0.0005; break;
    }
    p = p.cwiseMax(Vec2(-0.1, -0.1)).cwiseMin(Vec2(0.6, 1.2));
    t += mode == 3 && rng.uniform01() < 0.5 ? 1e-9 * rng.uniform01() : rng.uniform(0.0, 0.01);
    const bool contact = rng.uniform01() < 0.1;
    const ContactSensors contacts{contact && rng.uniform01() < 0.5, contact && rng.uniform01() < 0.5};
    if (rng.uniform01() < 1e-3) tracker.reset();
    const TrackerOutput& out = tracker.update(obs(t, p), contacts);
    expect_finite(out);
    if (::testing::Test::HasFatalFailure()) FAIL() << "update " << i;
    ASSERT_EQ(out.projection.valid, out.projection.reason == NoProjection::kNone) << i;
    ASSERT_GE(out.window, 0);
    ASSERT_LE(out.window, config().max_window);
    ASSERT_LE(tracker.history_size(), 512u);
    valid += out.projection.valid;
    rolling += out.projection.rolling;
    flushed += out.flushed;
  }
  EXPECT_GT(valid, 1000);
  EXPECT_GT(rolling, 1000);
  EXPECT_GT(flushed, 100);
}

}  // namespace
}  // namespace pinball::track
