#include "pinball/simlab/sim_camera_source.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pinball/sim/game_state.h"
#include "pinball/table/board_loader.h"
#include "common/thesis_board.h"

namespace pinball::simlab {
namespace {

using pinball::testing::thesis_board;

TEST(SimCameraSource, SameSeedSameBitsOtherSeedOtherNoise) {
  SimCameraConfig c;
  SimCameraSource a(thesis_board(), c);
  SimCameraSource b(thesis_board(), c);
  c.seed = 2;
  SimCameraSource other(thesis_board(), c);
  vision::Frame fa, fb, fo;
  const std::vector<Vec2> path{Vec2{0.2, 0.4}, Vec2{0.21, 0.41}};
  for (int i = 0; i < 5; ++i) {
    a.render(path, i * 0.005, fa);
    b.render(path, i * 0.005, fb);
    other.render(path, i * 0.005, fo);
    EXPECT_EQ(cv::norm(fa.gray, fb.gray, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(fa.gray, fo.gray, cv::NORM_L1), 0.0);
  }
  EXPECT_EQ(fa.gray.type(), CV_8UC1);
  EXPECT_EQ(fa.gray.size(), cv::Size(640, 480));
}

TEST(SimCameraSource, DeliversFramesAtItsRateStampedAtMidExposure) {
  SimCameraConfig c;
  c.fps = 200.0;
  c.exposure_s = 0.002;
  SimCameraSource camera(thesis_board(), c);
  vision::Frame frame;
  EXPECT_FALSE(camera.read(frame));  // nothing observed yet
  std::vector<double> stamps;
  for (int step = 1; step <= 200; ++step) {  // 0.1 s at 0.5 ms
    const double t = step * 0.0005;
    camera.observe_ball(t, Vec2{0.25, 0.3 + t}, true);
    while (camera.read(frame)) {
      stamps.push_back(frame.t_s);
      EXPECT_EQ(frame.sequence + 1, stamps.size());
      EXPECT_TRUE(camera.truth().ball_present);
      EXPECT_NEAR(camera.truth().p_board_mid.y(), 0.3 + frame.t_s, 1e-9);
    }
  }
  ASSERT_EQ(stamps.size(), 20u);  // exposures starting at 0, 5, ..., 95 ms, all ended by 100 ms
  for (std::size_t i = 0; i < stamps.size(); ++i) EXPECT_NEAR(stamps[i], 0.001 + 0.005 * i, 1e-12);
  EXPECT_EQ(camera.counters().frames, 20u);
  EXPECT_EQ(camera.counters().dropped, 0u);
}

TEST(SimCameraSource, AHoppingBallLooksFartherFromTheCentreAndLarger) {
  // The twin's ball hops: the lens (0.9 m above the playfield's centre) sees
  // it along the line from the centre, 30 mm nearer: out by (H − r)/(H − r − h).
  const table::Board& board = thesis_board();
  auto seen = [&](double height_m) {
    SimCameraConfig c;
    SimCameraSource camera(board, c);
    sim::GameState state = sim::make_game_state(board, 1);
    state.ball_in_play = true;
    state.ball.position_m = {0.1, 0.2};
    state.ball.height_m = height_m;
    vision::Frame frame;
    for (int step = 1; step <= 20; ++step) {
      state.time_s = step * 0.0005;
      camera.observe(state);
      if (camera.read(frame)) break;
    }
    return camera.truth();
  };
  const FrameTruth flat = seen(0.0), hop = seen(0.03);
  const Vec2 centre(0.5 * board.width_m, 0.5 * board.height_m);
  const double k = (0.9 - board.ball.radius_m) / (0.9 - board.ball.radius_m - 0.03);
  EXPECT_NEAR((flat.p_board_mid - Vec2(0.1, 0.2)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((hop.p_board_mid - (centre + k * (Vec2(0.1, 0.2) - centre))).norm(), 0.0, 1e-9);
  EXPECT_NEAR(hop.radius_px / flat.radius_px, k, 0.02);
}

TEST(SimCameraSource, MotionBlurSpreadsTheBallAlongItsPath) {
  SimCameraConfig c;
  c.noise_sigma = 0.0;
  c.lamp_toggle_probability = 0.0;
  SimCameraSource camera(thesis_board(), c);
  vision::Frame still, moving, empty;
  camera.render({}, 0.0, empty);
  const Vec2 p{0.25, 0.3};
  const Vec2 v{0.0, 5.0};  // 5 m/s up the table: 10 mm in 2 ms
  std::vector<Vec2> path;
  for (int k = 0; k < 40; ++k) path.push_back(p + v * (c.exposure_s * ((k + 0.5) / 40 - 0.5)));
  camera.render({&p, 1}, 0.0, still);
  camera.render(path, 0.0, moving);
  const double blur = camera.truth().blur_px;
  EXPECT_NEAR(blur, 0.0098 * camera.homography().px_per_m_at(p), 0.5);
  auto extent_u = [&](const vision::Frame& f) {
    cv::Mat diff;
    cv::absdiff(f.gray, empty.gray, diff);
    cv::threshold(diff, diff, 3, 255, cv::THRESH_BINARY);
    return cv::boundingRect(diff).width;
  };
  // Up the table is along u: the blurred ball is longer by about the blur.
  EXPECT_NEAR(extent_u(moving) - extent_u(still), blur, 1.5);
  // ... and dimmer at its ends than a still ball: the peak stays, the sum spreads.
  EXPECT_GT(cv::norm(moving.gray, empty.gray, cv::NORM_L1), 0.0);
}

// A frame is drawn as its rows were exposed, not as the table stands when it
// is delivered: a flipper raised at t_up shows up only in rows exposed after
// t_up, and frames delivered 10 ms later still show it down if exposed before.
TEST(SimCameraSource, AFlipperIsDrawnWhereItWasWhenItsRowsWereExposed) {
  const table::Board& board = thesis_board();
  const table::Flipper& f = board.flippers[0];
  SimCameraConfig c;
  c.noise_sigma = 0.0;
  c.exposure_s = 0.001;
  c.realism.row_time_s = 1e-5;
  c.realism.latency_min_s = 0.010;
  SimCameraSource camera(board, c);
  camera.set_lamps_blinking(false);
  // A pixel the raised bat covers and the lowered one does not.
  const cv::Point2d probe = camera.image_from_board(f.pivot + 0.7 * (table::flipper_tip(f, f.theta_max_rad) - f.pivot));
  const int row = static_cast<int>(std::lround(probe.y));
  ASSERT_GT(row * c.realism.row_time_s, 0.0015) << "the probe's row must be exposed well after row 0";
  // Raised 0.5 ms before the probe's row of the frame starting at 45 ms begins its exposure, after row 0 ended.
  const double t_up = 0.045 + row * c.realism.row_time_s - 0.0005;
  std::vector<double> theta{f.theta_min_rad, board.flippers[1].theta_min_rad};
  vision::Frame frame;
  int before = 0, after = 0;
  for (int step = 1; step <= 1600; ++step) {
    const double t = step * 0.0001;
    theta[0] = t >= t_up ? f.theta_max_rad : f.theta_min_rad;
    camera.set_flipper_angles(theta);
    camera.observe_ball(t, Vec2{-1.0, -1.0}, false);
    while (camera.read(frame)) {
      const double row_start = frame.driver_t_s + row * c.realism.row_time_s;
      const int gray = frame.gray.at<std::uint8_t>(cv::Point(probe));
      if (row_start + c.exposure_s < t_up) {
        EXPECT_LT(gray, 120) << "exposed before the flipper rose, delivered at " << frame.t_s;
        ++before;
      } else if (row_start > t_up) {
        EXPECT_GT(gray, 170) << "exposed after the flipper rose";
        ++after;
      }
    }
  }
  EXPECT_GE(before, 8);
  EXPECT_GE(after, 10);
  EXPECT_NEAR(frame.t_s - camera.truth().t_row0_exposure_s, 0.010, 1e-12);
}

TEST(SimCameraSource, PlasticHidesTheBallAndTheTruthSaysSo) {
  SimCameraConfig c;
  c.noise_sigma = 0.0;
  SimCameraSource camera(thesis_board(), c);
  ASSERT_FALSE(c.plastics.empty());
  Vec2 centre = Vec2::Zero();
  for (const Vec2& q : c.plastics[0].polygon_board) centre += q;
  centre /= static_cast<double>(c.plastics[0].polygon_board.size());
  vision::Frame under, empty;
  camera.set_lamps_blinking(false);
  camera.render({}, 0.0, empty);
  camera.render({&centre, 1}, 0.0, under);
  EXPECT_GT(camera.truth().occluded_fraction, 0.95);
  const cv::Point2d uv = camera.homography().image_from_board(centre);
  EXPECT_EQ(under.gray.at<std::uint8_t>(cv::Point(uv)), empty.gray.at<std::uint8_t>(cv::Point(uv)));
  EXPECT_GT(cv::countNonZero(camera.occluder_mask()), 1000);
}

TEST(SimCameraSource, RejectsBadSettings) {
  SimCameraConfig c;
  c.fps = 0.0;
  EXPECT_THROW(SimCameraSource(thesis_board(), c), std::invalid_argument);
  c = SimCameraConfig{};
  c.exposure_s = 0.01;  // longer than a frame at 200 fps
  EXPECT_THROW(SimCameraSource(thesis_board(), c), std::invalid_argument);
  c = SimCameraConfig{};
  c.plastics.push_back(SimPlastic{{Vec2{0.1, 0.1}, Vec2{0.2, 0.1}}, 90.0, 1.0});
  EXPECT_THROW(SimCameraSource(thesis_board(), c), std::invalid_argument);
}

TEST(SimCameraSource, RealismIsOffByDefaultAndTypicalIsAStatedCamera) {
  const SimCameraRealism off;
  EXPECT_FALSE(off.lens.has_value());
  EXPECT_EQ(off.row_time_s, 0.0);
  EXPECT_EQ(off.latency_mean_s(), 0.0);
  EXPECT_EQ(off.flicker_amplitude, 0.0);
  EXPECT_EQ(off.gain_drift_sigma, 0.0);
  const SimCameraRealism typical = SimCameraRealism::typical();
  ASSERT_TRUE(typical.lens.has_value());
  EXPECT_LT(typical.lens->k1, 0.0);                         // barrel
  EXPECT_NEAR(typical.row_time_s * 480, 4.8e-3, 1e-9);      // read out within a 5 ms frame
  EXPECT_NEAR(typical.latency_mean_s(), 0.008, 1e-12);
  EXPECT_EQ(typical.flicker_hz, 100.0);
  // Switching it on keeps the scene: the same seed draws the same table art.
  SimCameraConfig plain;
  plain.noise_sigma = 0.0;
  SimCameraConfig timed = plain;
  timed.realism.latency_min_s = 0.004;
  EXPECT_EQ(cv::norm(SimCameraSource(thesis_board(), plain).static_scene(),
                     SimCameraSource(thesis_board(), timed).static_scene(), cv::NORM_INF), 0.0);
}

TEST(SimCameraSource, ALensBendsTheTableTowardsTheImageCentre) {
  SimCameraConfig c;
  c.realism.lens = vision::typical_wide_lens();
  const SimCameraSource camera(thesis_board(), c);
  const cv::Point2d centre(c.realism.lens->cx_px, c.realism.lens->cy_px);
  const Vec2 corner{0.0, thesis_board().height_m};
  const cv::Point2d ideal = camera.homography().image_from_board(corner);
  const cv::Point2d seen = camera.image_from_board(corner);
  EXPECT_LT(cv::norm(seen - centre), cv::norm(ideal - centre) - 10.0);
  // The static scene was drawn through it: the table's edge is where the lens puts it, not the homography.
  const cv::Mat diff = camera.static_scene() != SimCameraSource(thesis_board(), SimCameraConfig{}).static_scene();
  EXPECT_GT(cv::countNonZero(diff), 10000);
}

TEST(SimCameraSource, LatencyDelaysDeliveryAndTheStampSaysWhenTheFrameArrived) {
  SimCameraConfig c;
  c.realism.latency_min_s = 0.010;
  c.realism.latency_jitter_mean_s = 0.002;
  SimCameraSource camera(thesis_board(), c);
  vision::Frame frame;
  double sum_latency = 0.0;
  int frames = 0;
  for (int step = 1; step <= 4000; ++step) {  // 2 s at 0.5 ms
    const double t = step * 0.0005;
    camera.observe_ball(t, Vec2{0.25, 0.5}, true);
    while (camera.read(frame)) {
      const FrameTruth& truth = camera.truth();
      EXPECT_LE(frame.t_s, t + 1e-12);  // never delivered before it arrived
      EXPECT_NEAR(frame.t_s - truth.t_row0_exposure_s, truth.latency_s, 1e-12);
      EXPECT_GE(truth.latency_s, 0.010 - 1e-12);
      EXPECT_NEAR(frame.driver_t_s, truth.t_row0_exposure_s - 0.5 * c.exposure_s, 1e-12);
      sum_latency += truth.latency_s;
      ++frames;
    }
  }
  ASSERT_GT(frames, 380);
  EXPECT_NEAR(sum_latency / frames, 0.012, 0.0005);
}

TEST(SimCameraSource, ARollingShutterExposesEachRowLater) {
  SimCameraConfig c;
  c.realism.row_time_s = 1e-5;
  SimCameraSource camera(thesis_board(), c);
  vision::Frame frame;
  int frames = 0;
  for (int step = 1; step <= 400; ++step) {  // a ball crossing the table at 4 m/s
    const double t = step * 0.0001;
    camera.observe_ball(t, Vec2{0.1 + 2.0 * t, 0.3 + 3.4 * t}, true);
    while (camera.read(frame)) {
      const FrameTruth& truth = camera.truth();
      // The ball was caught by the row it lies on, that row's time later than row 0.
      EXPECT_NEAR(truth.t_ball_exposure_s - truth.t_row0_exposure_s, truth.uv_px_mid.y * 1e-5, 2e-7);
      EXPECT_GT(truth.t_ball_exposure_s - truth.t_row0_exposure_s, 5e-4);
      ++frames;
    }
  }
  EXPECT_GE(frames, 6);
}

TEST(SimCameraSource, FlickerBandsTheRowsOfARollingShutterButNotOfAGlobalOne) {
  // Row by row gain of a flickering frame against the same frame unlit by flicker.
  const auto row_gain_spread = [](double row_time_s) {
    SimCameraConfig c;
    c.noise_sigma = 0.0;
    c.lamps = 0;
    c.realism.row_time_s = row_time_s;
    SimCameraConfig flickering = c;
    flickering.realism.flicker_amplitude = 0.08;
    SimCameraSource steady(thesis_board(), c);
    SimCameraSource lit(thesis_board(), flickering);
    vision::Frame a, b;
    steady.render({}, 0.0123, a);
    lit.render({}, 0.0123, b);
    double lo = 1e9, hi = -1e9;
    for (int v = 0; v < a.gray.rows; v += 8) {
      const double gain = cv::mean(b.gray.row(v))[0] / cv::mean(a.gray.row(v))[0];
      lo = std::min(lo, gain);
      hi = std::max(hi, gain);
    }
    return hi - lo;
  };
  const double rolling = row_gain_spread(1e-5);
  EXPECT_GT(rolling, 0.03);
  EXPECT_LT(row_gain_spread(0.0), rolling / 3.0);  // what remains is 8-bit rounding of dark rows
}

TEST(SimCameraSource, RejectsRealismItCannotRender) {
  SimCameraConfig c;
  c.realism.lens = vision::typical_wide_lens(1280, 960);  // not the 640x480 camera's
  EXPECT_THROW(SimCameraSource(thesis_board(), c), std::invalid_argument);
  c = SimCameraConfig{};
  c.realism.row_time_s = 2e-5;  // 9.6 ms readout: longer than a frame at 200 fps
  EXPECT_THROW(SimCameraSource(thesis_board(), c), std::invalid_argument);
  c = SimCameraConfig{};
  c.realism.latency_min_s = -0.001;
  EXPECT_THROW(SimCameraSource(thesis_board(), c), std::invalid_argument);
  c = SimCameraConfig{};
  c.realism.flicker_amplitude = 1.0;
  EXPECT_THROW(SimCameraSource(thesis_board(), c), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::simlab
