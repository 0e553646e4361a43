#include "pinball/vision/ball_detector.h"

#include <algorithm>
#include <vector>

#include <gtest/gtest.h>

#include "pinball/core/rng.h"
#include "pinball/table/board_loader.h"
#include "pinball/sim/game_state.h"
#include "pinball/simlab/sim_camera_source.h"
#include "common/thesis_board.h"

namespace pinball::vision {
namespace {

using pinball::testing::thesis_board;

// A simulated camera and a detector whose background was learned from 16
// ball-free frames (lamps still, glare off). Lamps stay as learned unless a
// test lets them blink.
struct Scene {
  explicit Scene(simlab::SimCameraConfig c = {}, BallDetectorConfig d = {})
      : camera(thesis_board(), c), detector(camera.homography(), camera.frame_size(), d) {
    detector.set_occluder_mask(camera.occluder_mask());
    camera.set_lamps_blinking(false);
    camera.set_glare(false);
    for (int i = 0; i < 16; ++i) {
      camera.render({}, t_s, frame);
      t_s += 0.005;
      detector.background().add_training_frame(frame.gray);
    }
    detector.background().finish_training();
  }

  // Renders the ball moving at v (m/s) through p at mid-exposure and detects it.
  Detection shoot(const Vec2& p, const Vec2& v = Vec2::Zero(), bool keep_track = false) {
    std::vector<Vec2> path;
    for (int k = 0; k < 32; ++k) path.push_back(p + v * (camera.config().exposure_s * ((k + 0.5) / 32 - 0.5)));
    camera.render(path, t_s, frame);
    t_s += 0.005;
    if (!keep_track) detector.forget_track();
    return detector.detect(frame);
  }

  double error_px(const Detection& d) const { return cv::norm(d.uv_px - camera.truth().uv_px_mid); }

  simlab::SimCameraSource camera;
  BallDetector detector;
  Frame frame;
  double t_s = 0.0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double p99(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(0.99 * (v.size() - 1))];
}

// Random points on the table clear of the plastics (and their neighbourhood).
template <class F>
void for_clear_points(Scene& s, int n, std::uint64_t seed, F&& f) {
  Rng rng(seed);
  const table::Board& b = thesis_board();
  int done = 0;
  while (done < n) {
    const Vec2 p{rng.uniform(0.02, b.width_m - 0.02), rng.uniform(0.02, b.height_m - 0.02)};
    const cv::Point2d uv = s.camera.homography().image_from_board(p);
    const int r = 14;
    const cv::Rect box(static_cast<int>(uv.x) - r, static_cast<int>(uv.y) - r, 2 * r, 2 * r);
    if (cv::countNonZero(s.camera.occluder_mask()(box)) > 0) continue;
    f(p, rng);
    ++done;
  }
}

// A prediction far outside any int (a wild homography or velocity) must not
// overflow a cast (UBSan float-cast-overflow in the asan preset): it is
// ignored and the whole frame is searched.
TEST(BallDetector, APredictionFarOffTheImageFallsBackToAFullSearch) {
  Scene s;
  const Vec2 p{0.3, 0.6};
  std::vector<Vec2> path(8, p);
  s.camera.render(path, s.t_s, s.frame);
  for (const cv::Point2d far : {cv::Point2d{1e12, -1e12}, cv::Point2d{-3e9, 5.0}}) {
    const Detection d = s.detector.detect(s.frame, &far);
    EXPECT_TRUE(d.found);
    EXPECT_FALSE(d.from_roi);
    EXPECT_LT(s.error_px(d), 0.5);
  }
}

TEST(BallDetector, StaticBallCentroidIsSubPixel) {
  Scene s;
  std::vector<double> errors;
  for_clear_points(s, 150, 1, [&](const Vec2& p, Rng&) {
    const Detection d = s.shoot(p);
    if (d.found) errors.push_back(s.error_px(d));
  });
  ASSERT_GE(errors.size(), 140u);  // a few land on walls or flippers the same brightness as the ball
  EXPECT_LT(median(errors), 0.1);
  EXPECT_LT(p99(errors), 0.5);
}

TEST(BallDetector, MovingBallWithMotionBlurMeetsTheTargets) {
  Scene s;
  std::vector<double> errors;
  std::vector<double> errors_mm;
  for_clear_points(s, 300, 2, [&](const Vec2& p, Rng& rng) {
    const double speed = rng.uniform(0.5, 5.0);
    const double a = rng.uniform(0.0, 6.283);
    const Detection d = s.shoot(p, speed * Vec2{std::cos(a), std::sin(a)});
    if (!d.found) return;
    errors.push_back(s.error_px(d));
    errors_mm.push_back((d.observation.p_board - s.camera.truth().p_board_mid).norm() * 1e3);
    EXPECT_GT(d.observation.confidence, 0.0);
    EXPECT_LE(d.observation.confidence, 1.0);
    EXPECT_EQ(d.observation.t_s, s.frame.t_s);
  });
  ASSERT_GE(errors.size(), 280u);
  EXPECT_LT(median(errors), 0.3);
  EXPECT_LT(p99(errors), 1.0);
  EXPECT_LT(median(errors_mm), 0.6);
}

TEST(BallDetector, BallNearTheTableEdgeIsFoundAccurately) {
  Scene s;
  const table::Board& b = thesis_board();
  const double r = b.ball.radius_m;
  int found = 0;
  for (const Vec2& p : {Vec2{r, 0.5}, Vec2{b.width_m - r, 0.45}, Vec2{0.3, r + 0.001}, Vec2{0.2, b.height_m - r},
                        Vec2{r, b.height_m - r}, Vec2{b.width_m - r, 0.2}}) {
    const Detection d = s.shoot(p, Vec2{0.0, 1.0});
    if (!d.found) continue;  // the table's walls are drawn as bright as the ball: a miss is allowed, a wrong answer not
    ++found;
    EXPECT_LT(s.error_px(d), 0.6) << p.transpose();
  }
  EXPECT_GE(found, 4);
}

TEST(BallDetector, NeedsALearnedBackgroundAndRefusesBadFrames) {
  simlab::SimCameraSource camera(thesis_board(), simlab::SimCameraConfig{});
  BallDetector detector(camera.homography(), camera.frame_size());
  camera.set_lamps_blinking(false);
  Frame frame;
  const Vec2 p{0.25, 0.3};
  camera.render({&p, 1}, 0.0, frame);
  const cv::Point2d truth_uv_px = camera.truth().uv_px_mid;
  EXPECT_EQ(detector.detect(frame).miss, DetectionMiss::kNoBackground);
  // Learning from ball-free frames makes the same frame readable.
  Frame empty;
  for (int i = 0; i < 8; ++i) {
    camera.render({}, 0.0, empty);
    detector.background().add_training_frame(empty.gray);
  }
  detector.background().finish_training();
  const Detection d = detector.detect(frame);
  ASSERT_TRUE(d.found);
  EXPECT_LT(cv::norm(d.uv_px - truth_uv_px), 0.3);
  Frame wrong;
  wrong.gray = cv::Mat(100, 100, CV_8U, cv::Scalar(0));
  EXPECT_EQ(detector.detect(wrong).miss, DetectionMiss::kBadFrame);
  EXPECT_EQ(detector.counters().bad_frames, 1u);
}

TEST(BallDetector, BlinkingLampsAreNeverTakenForTheBall) {
  simlab::SimCameraConfig c;
  c.lamp_toggle_probability = 0.2;
  Scene s(c);
  s.camera.set_lamps_blinking(true);
  int lit_changes = 0;
  for (int i = 0; i < 300; ++i) {
    s.camera.render({}, s.t_s, s.frame);
    s.t_s += 0.005;
    const Detection d = s.detector.detect(s.frame);
    EXPECT_FALSE(d.found) << "frame " << i;
    if (d.blobs > 0) ++lit_changes;
  }
  EXPECT_GT(lit_changes, 250);  // the lamps did show up as blobs
  EXPECT_GT(s.detector.counters().rejected_size + s.detector.counters().rejected_shape, 300u);
}

TEST(BallDetector, GlareIsRejectedAndTheBallElsewhereStillFound) {
  simlab::SimCameraConfig c;
  c.glare.enabled = true;
  Scene s(c);
  s.camera.set_glare(true);
  s.camera.render({}, s.t_s, s.frame);
  ASSERT_TRUE(s.camera.truth().glare_on);
  Detection d = s.detector.detect(s.frame);
  EXPECT_FALSE(d.found);
  EXPECT_EQ(d.miss, DetectionMiss::kWrongSize);
  // A ball far from the glare is found and placed right.
  d = s.shoot(Vec2{0.4, 0.85}, Vec2{1.0, 2.0});
  ASSERT_TRUE(s.camera.truth().glare_on);
  ASSERT_TRUE(d.found);
  EXPECT_LT(s.error_px(d), 0.5);
  // A ball inside the glare is not reported wrongly.
  d = s.shoot(c.glare.centre_board + Vec2{0.01, 0.0});
  if (d.found) {
    EXPECT_LT(s.error_px(d), 1.0);
  }
}

TEST(BallDetector, OccludedBallGivesNoObservationNeverAWrongOne) {
  Scene s;
  const simlab::SimPlastic& plastic = s.camera.config().plastics.at(0);
  Vec2 centre = Vec2::Zero();
  for (const Vec2& q : plastic.polygon_board) centre += q;
  centre /= static_cast<double>(plastic.polygon_board.size());
  // Wholly under it.
  EXPECT_FALSE(s.shoot(centre).found);
  // Sliding out from under its edge: no observation while any of it is hidden, a right one once clear.
  const Vec2 edge = 0.5 * (plastic.polygon_board[0] + plastic.polygon_board[1]);
  const Vec2 out = (edge - centre).normalized();
  int hidden_frames = 0;
  int clear_found = 0;
  for (double along = -0.01; along < 0.04; along += 0.002) {
    const Detection d = s.shoot(edge + along * out);
    if (s.camera.truth().occluded_fraction > 0.0) {
      ++hidden_frames;
      EXPECT_FALSE(d.found) << "along " << along << " hidden " << s.camera.truth().occluded_fraction;
    } else if (d.found) {
      ++clear_found;
      EXPECT_LT(s.error_px(d), 0.5);
    }
  }
  EXPECT_GE(hidden_frames, 8);
  EXPECT_GE(clear_found, 5);
}

TEST(BallDetector, RoiFollowsTheBallThenTheWholeFrameRecoversIt) {
  Scene s;
  const Vec2 v{0.4, 2.0};
  Vec2 p{0.2, 0.3};
  int from_roi = 0;
  for (int i = 0; i < 20; ++i) {
    const Detection d = s.shoot(p, v, true);
    ASSERT_TRUE(d.found) << i;
    EXPECT_LT(s.error_px(d), 0.5);
    if (d.from_roi) ++from_roi;
    p += v * 0.005;
  }
  EXPECT_GE(from_roi, 19);  // all but the first
  // The ball vanishes (drained, hidden): lost.
  for (int i = 0; i < 3; ++i) {
    s.camera.render({}, s.t_s, s.frame);
    s.t_s += 0.005;
    EXPECT_FALSE(s.detector.detect(s.frame).found);
  }
  // It reappears far away: the whole-frame search finds it, then the ROI takes over again.
  const std::uint64_t full_before = s.detector.counters().full_searches;
  p = Vec2{0.4, 0.9};
  Detection d = s.shoot(p, -v, true);
  ASSERT_TRUE(d.found);
  EXPECT_FALSE(d.from_roi);
  EXPECT_GT(s.detector.counters().full_searches, full_before);
  d = s.shoot(p - v * 0.005, -v, true);
  ASSERT_TRUE(d.found);
  EXPECT_TRUE(d.from_roi);
  // A wrong outside prediction costs a whole-frame search, not the ball.
  const cv::Point2d wrong{50.0, 50.0};
  s.camera.render(std::vector<Vec2>{Vec2{0.3, 0.6}}, s.t_s, s.frame);
  d = s.detector.detect(s.frame, &wrong);
  ASSERT_TRUE(d.found);
  EXPECT_FALSE(d.from_roi);
  EXPECT_LT(s.error_px(d), 0.5);
}

TEST(BallDetector, ARaisedFlipperIsNeverTakenForTheBall) {
  Scene s;  // background learned with the flippers down
  sim::GameState state = sim::make_game_state(thesis_board(), 1);
  state.ball_in_play = false;
  for (auto& f : state.flippers) f.theta_rad = thesis_board().flippers[0].theta_max_rad;
  int frames = 0;
  double changed = 0.0;
  for (int step = 1; step <= 200; ++step) {
    state.time_s = s.t_s + step * 0.0005;
    s.camera.observe(state);
    while (s.camera.read(s.frame)) {
      ++frames;
      const Detection d = s.detector.detect(s.frame);
      EXPECT_FALSE(d.found) << "a raised flipper reported as the ball at frame " << frames;
      changed = std::max(changed, cv::norm(s.frame.gray, s.detector.background().image(), cv::NORM_L1));
    }
  }
  EXPECT_GT(frames, 10);
  EXPECT_GT(changed, 1e4) << "the raised flippers must show in the image";
}

// Board point `off_m` from flipper `f` (at theta) on its upper side, `along`
// of the way from the pivot to the tip.
Vec2 beside_flipper(const table::Flipper& f, double theta_rad, double along, double off_m) {
  const Vec2 tip = table::flipper_tip(f, theta_rad);
  const Vec2 d = (tip - f.pivot).normalized();
  Vec2 n{-d.y(), d.x()};
  if (n.y() < 0.0) n = -n;
  return f.pivot + (tip - f.pivot) * along + n * off_m;
}

TEST(BallDetector, ABallTouchingARaisedFlipperIsFoundAndCentred) {
  Scene s;  // background learned with the flippers down
  const table::Board& b = thesis_board();
  std::vector<double> up;
  for (const table::Flipper& f : b.flippers) up.push_back(f.theta_max_rad);
  s.camera.set_flipper_angles(up);
  const double touch_m = b.ball.radius_m + 0.5 * s.camera.config().flipper_width_m;
  std::vector<double> errors;
  for (const table::Flipper& f : b.flippers) {
    for (double along : {0.35, 0.5, 0.65, 0.8}) {
      const Detection d = s.shoot(beside_flipper(f, f.theta_max_rad, along, touch_m));
      if (!d.found) continue;  // a miss is allowed, a wrong centre is not
      EXPECT_TRUE(d.separated) << f.name << " at " << along << ": the merged blob itself is not a ball";
      EXPECT_LT(s.error_px(d), 1.0) << f.name << " at " << along;
      errors.push_back(s.error_px(d));
    }
  }
  // Found only by the separation: the whole blob (ball plus flipper) is not a ball.
  EXPECT_GE(errors.size(), 4u);  // of 8; the others are missed, never misplaced
  EXPECT_LT(median(errors), 0.3);
  EXPECT_EQ(s.detector.counters().found_separated, errors.size());
}

TEST(BallDetector, ABlurredBallTouchingAMovingFlipperIsFound) {
  Scene s;
  const table::Board& b = thesis_board();
  std::vector<double> mid;  // half way up: the flippers are moving
  for (const table::Flipper& f : b.flippers) mid.push_back(0.5 * (f.theta_min_rad + f.theta_max_rad));
  s.camera.set_flipper_angles(mid);
  const double touch_m = b.ball.radius_m + 0.5 * s.camera.config().flipper_width_m;
  std::vector<double> errors;
  for (std::size_t i = 0; i < b.flippers.size(); ++i) {
    for (double along : {0.4, 0.6, 0.8}) {
      // Rolling down onto the flipper at 2 m/s: blurred along its path.
      const Detection d = s.shoot(beside_flipper(b.flippers[i], mid[i], along, touch_m), Vec2{0.3, -2.0});
      EXPECT_GT(s.camera.truth().blur_px, 2.0);
      if (!d.found) continue;
      EXPECT_TRUE(d.separated);
      EXPECT_LT(s.error_px(d), 1.0) << b.flippers[i].name << " at " << along;
      errors.push_back(s.error_px(d));
    }
  }
  EXPECT_GE(errors.size(), 1u);  // of 6; the others are missed, never misplaced
  EXPECT_LT(median(errors), 0.3);
}

TEST(BallDetector, AFlipperAloneIsNeverTakenForTheBallAtAnyAngle) {
  Scene s;  // background learned with the flippers down
  const table::Board& b = thesis_board();
  std::vector<double> theta(b.flippers.size());
  for (int k = 1; k <= 40; ++k) {
    for (std::size_t i = 0; i < theta.size(); ++i) {
      const table::Flipper& f = b.flippers[i];
      theta[i] = f.theta_min_rad + (f.theta_max_rad - f.theta_min_rad) * (k / 40.0);
    }
    s.camera.set_flipper_angles(theta);
    s.camera.render({}, s.t_s, s.frame);
    s.t_s += 0.005;
    s.detector.forget_track();
    EXPECT_FALSE(s.detector.detect(s.frame).found) << "a flipper alone reported as the ball at step " << k;
  }
  EXPECT_GT(s.detector.counters().separations, 20u) << "the flippers' blobs must have been opened and tested";
  EXPECT_EQ(s.detector.counters().found_separated, 0u);
}

TEST(BallDetector, RejectsBadSettings) {
  const CameraHomography h = CameraHomography::default_view(thesis_board(), {640, 480});
  BallDetectorConfig c;
  c.threshold = 0;
  EXPECT_THROW(BallDetector(h, {640, 480}, c), std::invalid_argument);
  c = BallDetectorConfig{};
  c.min_area_ratio = 1.5;
  EXPECT_THROW(BallDetector(h, {640, 480}, c), std::invalid_argument);
  c = BallDetectorConfig{};
  c.separation_radius_fraction = 1.0;  // would open the ball itself away
  EXPECT_THROW(BallDetector(h, {640, 480}, c), std::invalid_argument);
  BallDetector ok(h, {640, 480});
  EXPECT_THROW(ok.set_occluder_mask(cv::Mat(10, 10, CV_8U)), std::invalid_argument);
}

TEST(BallDetector, ALensIsCorrectedByUndistortingTheCentroid) {
  simlab::SimCameraConfig c;
  c.realism.lens = typical_wide_lens();
  BallDetectorConfig corrected;
  corrected.lens = c.realism.lens;
  Scene with_lens(c, corrected);
  Scene without_lens(c);
  const table::Board& b = thesis_board();
  double worst_corrected_m = 0.0;
  double worst_uncorrected_m = 0.0;
  for (const Vec2& p : {Vec2{0.06, 0.25}, Vec2{b.width_m - 0.06, b.height_m - 0.06}, Vec2{0.25, 0.55}}) {
    const Detection a = with_lens.shoot(p);
    const Detection u = without_lens.shoot(p);
    ASSERT_TRUE(a.found) << p.transpose();
    worst_corrected_m = std::max(worst_corrected_m, (a.observation.p_board - p).norm());
    // Uncorrected, a ball far out may also be refused for looking too small.
    if (u.found) worst_uncorrected_m = std::max(worst_uncorrected_m, (u.observation.p_board - p).norm());
    // The image centre is the sensor's, the ideal one where the pinhole would have seen it.
    EXPECT_LT(cv::norm(a.uv_px - with_lens.camera.truth().uv_px_mid), 0.5);
  }
  EXPECT_LT(worst_corrected_m, 0.0005);
  EXPECT_GT(worst_uncorrected_m, 0.005);  // a centimetre and more at the table's corners
}

TEST(BallDetector, ObservationsAreDatedAtTheBallsRowLessTheLatency) {
  simlab::SimCameraConfig c;
  c.realism.row_time_s = 1e-5;
  c.realism.latency_min_s = 0.009;
  BallDetectorConfig d;
  d.row_time_s = 1e-5;
  d.latency_s = 0.009;
  Scene s(c, d);
  s.camera.reset(s.t_s);
  vision::Frame frame;
  int found = 0;
  for (int step = 1; step <= 600; ++step) {
    const double t = s.t_s + step * 1e-4;
    s.camera.observe_ball(t, Vec2{0.1 + 2.0 * (t - s.t_s), 0.3 + 3.0 * (t - s.t_s)}, true);
    while (s.camera.read(frame)) {
      const Detection det = s.detector.detect(frame);
      if (!det.found) continue;
      ++found;
      EXPECT_NEAR(det.observation.t_s, s.camera.truth().t_ball_exposure_s, 2e-5);
      EXPECT_NEAR(det.observation.latency_s, frame.t_s - det.observation.t_s, 1e-12);
      EXPECT_GT(det.observation.latency_s, 0.004);  // 9 ms less the row's few milliseconds
    }
  }
  EXPECT_GE(found, 8);
}

TEST(BallDetector, RefusesALensOfAnotherImageSize) {
  simlab::SimCameraSource camera(thesis_board(), simlab::SimCameraConfig{});
  BallDetectorConfig d;
  d.lens = typical_wide_lens(1280, 960);
  EXPECT_THROW(BallDetector(camera.homography(), camera.frame_size(), d), std::invalid_argument);
  d = BallDetectorConfig{};
  d.latency_s = -0.001;
  EXPECT_THROW(BallDetector(camera.homography(), camera.frame_size(), d), std::invalid_argument);
  d = BallDetectorConfig{};
  d.dejitter_frames = 1000;
  EXPECT_THROW(BallDetector(camera.homography(), camera.frame_size(), d), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::vision
