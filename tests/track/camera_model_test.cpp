#include "pinball/track/camera_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace pinball::track {
namespace {

constexpr double kStep_s = 0.0005;  // the thesis stepper's time step

// A camera that delivers each frame at its exposure: the tests of rate, pixel
// grid, noise and drops look at what is delivered, not when (latency has its own test).
CameraModelConfig delivered_at_once() {
  CameraModelConfig c;
  c.latency_s = 0.0;
  return c;
}

// Steps a camera for `duration_s` at kStep_s, time summed the way the stepper
// sums it, delivering after every exposure. Returns the delivered frames.
std::vector<Observation> run_camera(CameraModel& camera, double duration_s, const Vec2& p_true,
                                    bool visible = true) {
  std::vector<Observation> out;
  double t = 0.0;
  const int steps = static_cast<int>(std::lround(duration_s / kStep_s));
  for (int k = 0; k < steps; ++k, t += kStep_s) {
    camera.expose(t, p_true, visible);
    Observation o;
    while (camera.deliver(t, o)) out.push_back(o);
  }
  return out;
}

TEST(CameraModel, FramesAtTheConfiguredRate) {
  for (const double fps : {200.0, 300.0, 1000.0}) {
    CameraModelConfig c = delivered_at_once();
    c.fps = fps;
    CameraModel camera(c, 1);
    const std::vector<Observation> obs = run_camera(camera, 1.0, {0.2, 0.3});
    EXPECT_EQ(camera.frames(), static_cast<std::uint64_t>(fps)) << fps << " fps";
    EXPECT_EQ(obs.size(), static_cast<std::size_t>(fps)) << fps << " fps";
    // Frames are exposed on the first step at or after they fall due: never
    // more than one simulation step late, never early, never drifting.
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const double due = static_cast<double>(i) / fps;
      EXPECT_GE(obs[i].t_s, due - 1e-9) << fps << " fps, frame " << i;
      EXPECT_LT(obs[i].t_s, due + kStep_s - 1e-9) << fps << " fps, frame " << i;
    }
  }
}

TEST(CameraModel, FrameCountDoesNotDriftOverALongRun) {
  CameraModelConfig c;
  c.fps = 200.0;
  CameraModel camera(c, 2);
  double t = 0.0;
  for (int k = 0; k < 200000; ++k, t += kStep_s) camera.expose(t, {0.1, 0.1});  // 100 s
  EXPECT_EQ(camera.frames(), 20000u);
}

TEST(CameraModel, NoiselessObservationsLieOnThePixelGridWithinHalfAPixel) {
  CameraModelConfig c = delivered_at_once();
  c.noise_px = 0.0;
  c.m_per_px = 0.002;
  CameraModel camera(c, 3);
  Rng rng(33);
  double t = 0.0;
  int seen = 0;
  double max_err = 0.0;
  for (int k = 0; k < 20000; ++k, t += kStep_s) {
    const Vec2 p{rng.uniform(0.0, 0.51), rng.uniform(0.0, 1.07)};
    camera.expose(t, p);
    Observation o;
    while (camera.deliver(t, o)) {
      ++seen;
      EXPECT_EQ(o.t_s, t);  // latency 0: delivered on the step it was exposed
      EXPECT_EQ(o.confidence, 1.0);
      for (int i = 0; i < 2; ++i) {
        const double px = o.p_board[i] / c.m_per_px;
        EXPECT_NEAR(px, std::round(px), 1e-9);
        const double err = std::abs(o.p_board[i] - p[i]);
        EXPECT_LE(err, 0.5 * c.m_per_px + 1e-12);
        max_err = std::max(max_err, err);
      }
    }
  }
  EXPECT_EQ(seen, 2000);
  EXPECT_GT(max_err, 0.45 * c.m_per_px);  // it does quantise: errors reach nearly half a pixel
  // With no noise the predicted σ is the quantisation's alone.
  EXPECT_DOUBLE_EQ(observation_sigma_m(c), c.m_per_px / std::sqrt(12.0));
}

TEST(CameraModel, NoiseStatisticsMatchObservationSigma) {
  for (const double noise_px : {0.3, 1.0}) {
    CameraModelConfig c = delivered_at_once();
    c.noise_px = noise_px;
    c.m_per_px = 0.002;
    c.fps = 2000.0;  // a frame every step
    CameraModel camera(c, 4);
    Rng rng(44);
    double t = 0.0;
    double sum = 0.0;
    double sum2 = 0.0;
    int n = 0;
    for (int k = 0; k < 40000; ++k, t += kStep_s) {
      // True positions spread over the pixel so quantisation averages out.
      const Vec2 p{rng.uniform(0.1, 0.4), rng.uniform(0.1, 0.9)};
      camera.expose(t, p);
      Observation o;
      while (camera.deliver(t, o)) {
        for (int i = 0; i < 2; ++i) {
          const double e = o.p_board[i] - p[i];
          sum += e;
          sum2 += e * e;
          ++n;
        }
      }
    }
    ASSERT_EQ(n, 80000);
    const double mean = sum / n;
    const double sd = std::sqrt(sum2 / n - mean * mean);
    const double sigma = observation_sigma_m(c);
    EXPECT_NEAR(sigma, c.m_per_px * std::sqrt(noise_px * noise_px + 1.0 / 12.0), 1e-15);
    EXPECT_NEAR(sd, sigma, 0.1 * sigma) << noise_px << " px";
    EXPECT_NEAR(mean, 0.0, 0.05 * sigma) << noise_px << " px";  // unbiased
  }
}

TEST(CameraModel, LatencyDelaysDeliveryAndKeepsTheExposureTime) {
  CameraModelConfig c;
  c.latency_s = 0.01;
  c.noise_px = 0.0;
  c.m_per_px = 0.001;
  CameraModel camera(c, 5);
  double t = 0.0;
  int delivered = 0;
  for (int k = 0; k < 2000; ++k, t += kStep_s) {
    const Vec2 p{0.1 + 0.3 * t, 0.5 - 0.2 * t};  // a moving ball: the position tells the time
    camera.expose(t, p);
    Observation o;
    while (camera.deliver(t, o)) {
      ++delivered;
      EXPECT_GE(t, o.t_s + c.latency_s - 1e-9);             // never early
      EXPECT_LT(t, o.t_s + c.latency_s + kStep_s - 1e-9);   // and on the first step it may
      EXPECT_NEAR(o.p_board.x(), 0.1 + 0.3 * o.t_s, 0.5 * c.m_per_px + 1e-12);  // the exposure's position
      EXPECT_NEAR(o.p_board.y(), 0.5 - 0.2 * o.t_s, 0.5 * c.m_per_px + 1e-12);
    }
  }
  // 200 frames exposed in the second; those of the last 10 ms are still in flight.
  EXPECT_EQ(camera.frames(), 200u);
  EXPECT_EQ(delivered, 198);
}

TEST(CameraModel, DropsFramesWithTheConfiguredProbability) {
  CameraModelConfig c = delivered_at_once();
  c.drop_probability = 0.2;
  c.fps = 2000.0;
  CameraModel camera(c, 6);
  const std::vector<Observation> obs = run_camera(camera, 20.0, {0.2, 0.3});  // 40000 frames
  ASSERT_EQ(camera.frames(), 40000u);
  const double rate = static_cast<double>(camera.dropped()) / static_cast<double>(camera.frames());
  EXPECT_NEAR(rate, 0.2, 0.01);  // 5 standard errors
  EXPECT_EQ(obs.size() + camera.dropped(), camera.frames());
}

TEST(CameraModel, InvisibleBallGivesNoObservation) {
  CameraModel camera(CameraModelConfig{}, 7);
  const std::vector<Observation> obs = run_camera(camera, 0.5, {0.49, 0.05}, false);
  EXPECT_TRUE(obs.empty());
  EXPECT_EQ(camera.frames(), 100u);  // the camera kept running
  EXPECT_EQ(camera.dropped(), 0u);
}

TEST(CameraModel, ResetForgetsFramesInFlight) {
  CameraModelConfig c;
  c.latency_s = 0.05;
  CameraModel camera(c, 8);
  double t = 0.0;
  for (int k = 0; k < 100; ++k, t += kStep_s) camera.expose(t, {0.2, 0.2});
  camera.reset(t);
  Observation o;
  EXPECT_FALSE(camera.deliver(t + 1.0, o));
  camera.expose(t, {0.2, 0.2});  // the frame clock restarts at once
  EXPECT_TRUE(camera.deliver(t + c.latency_s, o));
  EXPECT_EQ(o.t_s, t);
}

TEST(CameraModel, TooManyFramesInFlightAreCountedNotCorrupted) {
  CameraModelConfig c;
  c.latency_s = 10.0;
  CameraModel camera(c, 9);
  double t = 0.0;
  for (int k = 0; k < 3000; ++k, t += kStep_s) camera.expose(t, {0.2, 0.2});  // 300 frames in 1.5 s
  EXPECT_EQ(camera.frames(), 300u);
  EXPECT_EQ(camera.overflowed(), 300u - 256u);
  Observation o;
  EXPECT_FALSE(camera.deliver(t, o));
  int n = 0;
  double last = -1.0;
  while (camera.deliver(100.0, o)) {
    EXPECT_GT(o.t_s, last);  // oldest first
    last = o.t_s;
    ++n;
  }
  EXPECT_EQ(n, 256);
}

TEST(CameraModel, SameSeedSameObservations) {
  CameraModelConfig c;
  c.noise_px = 1.0;
  c.drop_probability = 0.1;
  CameraModel a(c, 42);
  CameraModel b(c, 42);
  const std::vector<Observation> oa = run_camera(a, 1.0, {0.2, 0.3});
  const std::vector<Observation> ob = run_camera(b, 1.0, {0.2, 0.3});
  ASSERT_EQ(oa.size(), ob.size());
  for (std::size_t i = 0; i < oa.size(); ++i) {
    EXPECT_EQ(oa[i].t_s, ob[i].t_s);
    EXPECT_EQ(oa[i].p_board, ob[i].p_board);
  }
}

TEST(CameraModel, BadSettingsThrow) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto with = [](auto edit) {
    CameraModelConfig c;
    edit(c);
    return c;
  };
  EXPECT_NO_THROW(CameraModel(CameraModelConfig{}, 0));
  EXPECT_THROW(CameraModel(with([](auto& c) { c.fps = 0.0; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([](auto& c) { c.fps = -200.0; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([&](auto& c) { c.fps = nan; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([&](auto& c) { c.fps = inf; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([](auto& c) { c.m_per_px = 0.0; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([&](auto& c) { c.m_per_px = nan; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([](auto& c) { c.noise_px = -0.1; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([](auto& c) { c.latency_s = -0.001; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([&](auto& c) { c.latency_s = inf; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([](auto& c) { c.drop_probability = 1.0; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([](auto& c) { c.drop_probability = -0.1; }), 0), std::invalid_argument);
  EXPECT_THROW(CameraModel(with([&](auto& c) { c.drop_probability = nan; }), 0), std::invalid_argument);
  try {
    CameraModel(with([](auto& c) { c.fps = 0.0; }), 0);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fps"), std::string::npos) << e.what();  // names the setting
  }
}

TEST(CameraModel, EachObservationCarriesTheCamerasLatency) {
  CameraModelConfig c;
  c.latency_s = 0.007;
  CameraModel camera(c, 1);
  Observation o;
  bool delivered = false;
  for (double t = 0.0; t < 0.05 && !delivered; t += 0.0005) {
    camera.expose(t, {0.2, 0.5});
    delivered = camera.deliver(t, o);
  }
  ASSERT_TRUE(delivered);
  EXPECT_EQ(o.latency_s, 0.007);  // as a calibrated detector reports it
}

}  // namespace
}  // namespace pinball::track
