#include "pinball/calibration/latency_calibration.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "pinball/core/rng.h"
#include "pinball/simlab/sim_latency_lab.h"
#include "pinball/table/board_loader.h"

namespace pinball::calibration {
namespace {

const table::Board& thesis_board() {
  static const table::Board b = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  return b;
}

simlab::SimLatencyOptions few_events(int events = 8) {
  simlab::SimLatencyOptions o;
  o.events = events;
  return o;
}

// Measures a simulated run and checks it against the camera's true minimum latency.
LatencyEstimate measure_and_compare(const simlab::SimLatencyOptions& o, const char* what) {
  const simlab::SimLatencyRun run = simlab::simulate_latency_run(thesis_board(), o);
  const LatencyEstimate e = measure_latency(run.recording, run.region, run.timing);
  EXPECT_NEAR(e.latency_s, run.true_latency_s, 0.0005) << what;
  EXPECT_EQ(e.events_used + e.events_rejected, o.events) << what;
  EXPECT_GE(e.events_used, o.events - 1) << what;
  EXPECT_LT(e.spread_s, 0.001) << what;
  for (std::size_t i = 0; i < e.events.size(); ++i) {
    if (e.events[i].used()) {
      EXPECT_NEAR(e.events[i].latency_s, run.true_latency_s, 0.0015) << what << " event " << i;
    }
  }
  return e;
}

TEST(LatencyCalibration, TheTypicalCameraIsMeasuredWithinHalfAMillisecond) {
  // 7 ms of minimum latency, 1 ms of mean jitter, a rolling shutter (the
  // flipper's rows are exposed ~4 ms after row 0), lens, flicker, drift.
  const LatencyEstimate e = measure_and_compare(few_events(), "typical camera");
  EXPECT_GT(e.motion_row_px * 1e-5, 0.0015) << "the flipper's rows are exposed well after row 0: the row time matters";
  EXPECT_EQ(e.camera_timing().events_used, e.events_used);
  EXPECT_EQ(e.camera_timing().latency_s, e.latency_s);
  EXPECT_GT(e.camera_timing().row_time_s, 0.0);
}

TEST(LatencyCalibration, ALongLatencyAndAGlobalShutterAreMeasuredToo) {
  simlab::SimLatencyOptions slow = few_events();
  slow.camera.realism.latency_min_s = 0.020;
  slow.seed = 2;
  measure_and_compare(slow, "20 ms camera");

  simlab::SimLatencyOptions global = few_events();
  global.camera.realism.row_time_s = 0.0;
  global.seed = 3;
  const simlab::SimLatencyRun run = simlab::simulate_latency_run(thesis_board(), global);
  EXPECT_EQ(run.timing.row_time_s, 0.0);
  const LatencyEstimate e = measure_latency(run.recording, run.region, run.timing);
  EXPECT_NEAR(e.latency_s, run.true_latency_s, 0.0005) << "global shutter";
}

TEST(LatencyCalibration, AWrongRowTimeOrActuationDelayShowsInTheResult) {
  // The two figures the lab gives are not decoration: each moves the answer by what it should.
  const simlab::SimLatencyRun run = simlab::simulate_latency_run(thesis_board(), few_events());
  LatencyOptions o = run.timing;
  const double right = measure_latency(run.recording, run.region, o).latency_s;
  o.actuation_delay_s += 0.002;
  EXPECT_NEAR(measure_latency(run.recording, run.region, o).latency_s, right - 0.002, 1e-9);
  o = run.timing;
  o.row_time_s = 0.0;
  const LatencyEstimate global = measure_latency(run.recording, run.region, o);
  const LatencyEstimate rolling = measure_latency(run.recording, run.region, run.timing);
  for (std::size_t i = 0; i < global.events.size(); ++i) {
    ASSERT_TRUE(global.events[i].used() && rolling.events[i].used());
    // Each fit frame has its own row; the line's zero crossing moves by about their mean (~2 ms).
    EXPECT_NEAR(global.events[i].latency_s, rolling.events[i].latency_s - rolling.events[i].motion_row_px * 1e-5, 1e-4);
  }
  // The rows that count are those of the flipper's region.
  EXPECT_GT(rolling.motion_row_px, run.region.roi.y);
  EXPECT_LT(rolling.motion_row_px, run.region.roi.y + run.region.roi.height);
}

TEST(LatencyCalibration, AnEventWithoutMotionIsRejectedByName) {
  simlab::SimLatencyOptions o = few_events();
  o.dead_events = {2};
  const simlab::SimLatencyRun run = simlab::simulate_latency_run(thesis_board(), o);
  const LatencyEstimate e = measure_latency(run.recording, run.region, run.timing);
  ASSERT_EQ(e.events.size(), 8u);
  EXPECT_EQ(e.events[2].rejection, LatencyRejection::kNoMotion);
  EXPECT_STREQ(to_string(e.events[2].rejection), "no motion seen");
  EXPECT_EQ(e.events_rejected, 1);
  EXPECT_NEAR(e.latency_s, run.true_latency_s, 0.0005);
}

TEST(LatencyCalibration, DroppedFramesAndAnUnsettledClockAreRejectedByName) {
  simlab::SimLatencyOptions o = few_events(5);
  o.lead_in_s = 0.2;  // 40 frames before the first command: the 100-frame envelope is not full
  simlab::SimLatencyRun run = simlab::simulate_latency_run(thesis_board(), o);
  // Lose one frame just after the fourth command.
  auto& frames = run.recording.frames;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].t_s > run.recording.command_t_s[3] + 0.01) {
      frames.erase(frames.begin() + static_cast<std::ptrdiff_t>(k));
      break;
    }
  }
  const LatencyEstimate e = measure_latency(run.recording, run.region, run.timing);
  EXPECT_EQ(e.events[0].rejection, LatencyRejection::kClockNotSettled);
  EXPECT_EQ(e.events[3].rejection, LatencyRejection::kFramesDropped);
  EXPECT_STREQ(to_string(LatencyRejection::kFramesDropped), "frames dropped around it");
  EXPECT_EQ(e.events_used, 3);
}

TEST(LatencyCalibration, TooFewUsableEventsIsAnErrorThatSaysWhy) {
  simlab::SimLatencyOptions o = few_events(4);
  o.dead_events = {0, 2};
  const simlab::SimLatencyRun run = simlab::simulate_latency_run(thesis_board(), o);
  try {
    measure_latency(run.recording, run.region, run.timing);
    FAIL() << "two usable events must not give a latency";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "latency: only 2 of 4 events usable (event 1: no motion seen, event 3: no motion seen)");
  }
  LatencyRecording none;
  EXPECT_THROW(measure_latency(none, run.region, run.timing), std::runtime_error);
}

TEST(LatencyCalibration, TheFramePeriodIsFoundFromTheStampsLowerEnvelope) {
  // A camera 100 ppm slower than its nominal 200 fps, stamped with 1 ms of exponential jitter.
  Rng rng(4);
  LatencyRecording rec;
  const double period = 0.005 * 1.0001;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    if (k == 700) continue;  // a dropped frame changes nothing
    rec.frames.push_back({cv::Mat(), 3.0 + k * period + 0.007 - 0.001 * std::log1p(-rng.uniform01()), k + 5});
  }
  EXPECT_NEAR(estimate_frame_period_s(rec, 0.005), period, 2e-8);
  rec.frames.resize(150);
  EXPECT_EQ(estimate_frame_period_s(rec, 0.005), 0.005) << "too few frames: the nominal period";
  EXPECT_THROW(estimate_frame_period_s(rec, 0.0), std::invalid_argument);
}

TEST(LatencyCalibration, TheRegionCoversTheSweepAndBadSettingsAreRefused) {
  const table::Flipper& f = thesis_board().flippers[0];
  // A plain scale: 500 px per m, y down.
  const ImageFromBoard map = [](const Vec2& p) { return cv::Point2d(500.0 * p.x(), 600.0 - 500.0 * p.y()); };
  const FlipperRegion r = flipper_region(f, map, {400, 600});
  EXPECT_NEAR(r.sweep_rad, std::abs(f.theta_max_rad - f.theta_min_rad), 1e-12);
  for (const double theta : {f.theta_min_rad, 0.5 * (f.theta_min_rad + f.theta_max_rad), f.theta_max_rad}) {
    for (const double along : {0.3, 0.6, 0.95}) {
      const cv::Point2d px = map(f.pivot + along * (table::flipper_tip(f, theta) - f.pivot));
      const cv::Point at(static_cast<int>(std::lround(px.x)) - r.roi.x, static_cast<int>(std::lround(px.y)) - r.roi.y);
      ASSERT_TRUE(cv::Rect(0, 0, r.roi.width, r.roi.height).contains(at));
      EXPECT_EQ(r.mask.at<std::uint8_t>(at), 255);
      const double expected = std::abs(theta - f.theta_min_rad);
      // Within about a pixel's angular size at that radius.
      EXPECT_NEAR(r.angle_rad.at<double>(at), expected, 1.0 / (along * f.length_m * 500.0))
          << "theta " << theta << " along " << along;
      EXPECT_NEAR(r.area_m2.at<double>(at), 1.0 / (500.0 * 500.0), 1e-9);
    }
  }
  // The pixel of the pivot itself is left out; the region is about the size of the sector swept.
  const cv::Point2d pivot = map(f.pivot);
  EXPECT_EQ(r.mask.at<std::uint8_t>(static_cast<int>(std::lround(pivot.y)) - r.roi.y,
                                    static_cast<int>(std::lround(pivot.x)) - r.roi.x),
            0);
  const double sector_px = 0.5 * r.sweep_rad * std::pow((f.length_m + 0.018) * 500.0, 2);
  EXPECT_GT(r.pixels, sector_px);
  EXPECT_LT(r.pixels, 2.0 * sector_px);

  EXPECT_THROW(flipper_region(f, map, {100, 100}), std::invalid_argument);  // outside the image
  table::Flipper still = f;
  still.theta_max_rad = still.theta_min_rad;
  EXPECT_THROW(flipper_region(still, map, {400, 600}), std::invalid_argument);
  LatencyOptions o;
  o.frame_period_s = 0.0;
  EXPECT_THROW(measure_latency({}, r, o), std::invalid_argument);
  o = LatencyOptions{};
  o.fit_low = 0.7;
  EXPECT_THROW(measure_latency({}, r, o), std::invalid_argument);
  LatencyRecording rec;
  EXPECT_THROW(rec.add_frame(r, cv::Mat(10, 10, CV_8U), 0.0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::calibration
