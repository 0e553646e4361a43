#include "detector_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pinball/core/statistics.h"
#include "pinball/core/rng.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/sim/model_world.h"

namespace pinball::bench {

simlab::SimCameraConfig DetectorBenchOptions::default_camera() {
  simlab::SimCameraConfig c;
  c.glare.enabled = true;
  c.glare.toggle_probability = 0.01;
  return c;
}

DetectorBenchOptions quick_detector_bench_options() {
  DetectorBenchOptions o;
  o.play_frames = 400;
  o.ball_free_frames = 300;
  o.occlusion_frames = 60;
  o.timing_frames = 60;
  o.timing_repeats = 1;
  o.timing_sizes = {{640, 480}};
  return o;
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

ErrorSummary summarise_errors(std::vector<double> v) {
  ErrorSummary s;
  s.count = v.size();
  if (v.empty()) return s;
  s.median = quantile(v, 0.5);
  s.p99 = quantile(v, 0.99);
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

void learn_background(simlab::SimCameraSource& camera, vision::BallDetector& detector, int frames, double& t_s) {
  camera.set_lamps_blinking(false);
  camera.set_glare(false);
  vision::Frame frame;
  for (int i = 0; i < frames; ++i) {
    camera.render({}, t_s, frame);
    t_s += 1.0 / camera.fps();
    detector.background().add_training_frame(frame.gray);
  }
  detector.background().finish_training();
  camera.set_lamps_blinking(true);
  camera.set_glare(true);
}

namespace {

// Plays the board with the oracle spastic player and hands every delivered
// frame (with the camera's truth) to `on_frame` until it returns false.
template <class OnFrame>
void play_frames(const table::Board& board, std::uint64_t seed, simlab::SimCameraSource& camera, OnFrame&& on_frame) {
  const std::unique_ptr<sim::World> world = sim::make_model_world(board);
  sim::GameState state = sim::make_game_state(board, seed);
  sim::BallLimits limits;
  limits.max_ball_time_s = 60.0;
  vision::Frame frame;
  bool more = true;
  double last_t = -1.0;
  for (int ball = 0; more && ball < 1000; ++ball) {
    sim::play_ball(
        *world, state, limits, [&](sim::GameState& s) { simlab::oracle_spastic_policy(board, s); },
        [&](const sim::GameState& s, const sim::StepEvents&) {
          if (!more) return;
          if (s.time_s < last_t) camera.reset(s.time_s);
          last_t = s.time_s;
          camera.observe(s);
          while (more && camera.read(frame)) more = on_frame(frame, camera.truth());
        });
  }
}

simlab::SimCameraConfig sized(const simlab::SimCameraConfig& c, cv::Size size) {
  simlab::SimCameraConfig out = c;
  out.width_px = size.width;
  out.height_px = size.height;
  return out;
}

void measure_accuracy(const table::Board& board, const DetectorBenchOptions& o, DetectorReport& r) {
  simlab::SimCameraSource camera(board, o.camera);
  vision::BallDetector detector(camera.homography(), camera.frame_size(), o.detector);
  detector.set_occluder_mask(camera.occluder_mask());
  double t_s = -1000.0;
  learn_background(camera, detector, o.background_frames, t_s);
  AccuracyFigures& a = r.accuracy;
  std::vector<double> err_px, err_mm, naive_px, blur_px, radius_px;
  cv::Mat naive_binary;
  play_frames(board, o.seed, camera, [&](const vision::Frame& frame, const simlab::FrameTruth& truth) {
    ++a.frames;
    const vision::Detection d = detector.detect(frame);
    const double e_px = d.found ? cv::norm(d.uv_px - truth.uv_px_mid) : 0.0;
    if (!truth.ball_present) {
      ++a.no_ball_frames;
      if (d.found) ++a.no_ball_detections;
      return true;
    }
    if (!truth.ball_whole_exposure) return true;
    ++a.ball_frames;
    if (truth.in_glare && truth.occluded_fraction == 0.0) {
      ++a.in_glare;
      if (d.found) ++a.in_glare_detected;
      if (d.found && e_px > o.wrong_px) ++a.in_glare_wrong;
    }
    if (truth.occluded_fraction > 0.0 || truth.in_glare) return true;
    ++a.unoccluded;
    blur_px.push_back(truth.blur_px);
    radius_px.push_back(truth.radius_px);
    if (d.found) {
      ++a.detected;
      err_px.push_back(e_px);
      err_mm.push_back((d.observation.p_board - truth.p_board_mid).norm() * 1e3);
      if (e_px > o.wrong_px) ++a.wrong;
    } else {
      ++a.missed;
    }
    // Baseline: plain threshold and moments of the whole frame, no background.
    cv::threshold(frame.gray, naive_binary, o.naive_threshold, 255, cv::THRESH_BINARY);
    const cv::Moments m = cv::moments(naive_binary, true);
    if (m.m00 > 0.0) {
      ++a.naive_found;
      naive_px.push_back(cv::norm(cv::Point2d(m.m10 / m.m00, m.m01 / m.m00) - truth.uv_px_mid));
    }
    return a.unoccluded < static_cast<std::size_t>(o.play_frames);
  });
  a.error_px = summarise_errors(err_px);
  a.error_mm = summarise_errors(err_mm);
  a.naive_error_px = summarise_errors(naive_px);
  a.median_blur_px = quantile(blur_px, 0.5);
  a.p99_blur_px = quantile(blur_px, 0.99);
  a.median_radius_px = quantile(radius_px, 0.5);
}

void measure_ball_free(const table::Board& board, const DetectorBenchOptions& o, DetectorReport& r) {
  simlab::SimCameraConfig c = o.camera;
  c.seed = o.camera.seed + 1000;
  simlab::SimCameraSource camera(board, c);
  vision::BallDetector detector(camera.homography(), camera.frame_size(), o.detector);
  detector.set_occluder_mask(camera.occluder_mask());
  double t_s = 0.0;
  learn_background(camera, detector, o.background_frames, t_s);
  vision::Frame frame;
  for (int i = 0; i < o.ball_free_frames; ++i) {
    camera.render({}, t_s, frame);
    t_s += 1.0 / camera.fps();
    const vision::Detection d = detector.detect(frame);
    ++r.ball_free_frames;
    if (camera.truth().glare_on) ++r.ball_free_glare_frames;
    if (d.found) ++r.false_detections;
  }
  const vision::DetectorCounters& k = detector.counters();
  r.ball_free_rejected_blobs = k.rejected_size + k.rejected_shape + k.rejected_occluded + k.rejected_edge;
}

void measure_occlusion(const table::Board& board, const DetectorBenchOptions& o, DetectorReport& r) {
  if (o.camera.plastics.empty()) return;
  simlab::SimCameraConfig c = o.camera;
  c.seed = o.camera.seed + 2000;
  c.glare.enabled = false;
  simlab::SimCameraSource camera(board, c);
  vision::BallDetector detector(camera.homography(), camera.frame_size(), o.detector);
  detector.set_occluder_mask(camera.occluder_mask());
  double t_s = 0.0;
  learn_background(camera, detector, o.background_frames, t_s);
  Rng rng(o.seed ^ 0x0cc1u);
  vision::Frame frame;
  std::vector<Vec2> path(16);
  const double reach = board.ball.radius_m;
  int attempts = 0;
  while (r.occlusion.frames < static_cast<std::size_t>(o.occlusion_frames) && attempts < 50 * o.occlusion_frames) {
    ++attempts;
    const simlab::SimPlastic& plastic = c.plastics[rng.next_u64() % c.plastics.size()];
    Vec2 lo = plastic.polygon_board.front();
    Vec2 hi = lo;
    for (const Vec2& p : plastic.polygon_board) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Vec2 p{rng.uniform(lo.x() - reach, hi.x() + reach), rng.uniform(lo.y() - reach, hi.y() + reach)};
    const double speed = rng.uniform(0.0, 4.0);
    const double angle = rng.uniform(0.0, 2.0 * std::numbers::pi);
    const Vec2 v = speed * Vec2{std::cos(angle), std::sin(angle)};
    for (std::size_t k = 0; k < path.size(); ++k) {
      path[k] = p + v * (c.exposure_s * ((k + 0.5) / path.size() - 0.5));
    }
    detector.forget_track();
    camera.render(path, t_s, frame);
    t_s += 1.0 / camera.fps();
    if (!(camera.truth().occluded_fraction > 0.0)) continue;
    ++r.occlusion.frames;
    const vision::Detection d = detector.detect(frame);
    if (!d.found) {
      ++r.occlusion.no_observation;
    } else if (cv::norm(d.uv_px - camera.truth().uv_px_mid) > o.wrong_px) {
      ++r.occlusion.wrong;
    } else {
      ++r.occlusion.close;
    }
  }
}

void measure_timing(const table::Board& board, const DetectorBenchOptions& o, cv::Size size, DetectorReport& r) {
  DetectorTiming timing;
  timing.size = size;
  simlab::SimCameraSource camera(board, sized(o.camera, size));
  std::vector<cv::Mat> frames;
  std::vector<double> times;
  std::size_t with_ball = 0;
  play_frames(board, o.seed + 7, camera, [&](const vision::Frame& frame, const simlab::FrameTruth& truth) {
    frames.push_back(frame.gray.clone());
    times.push_back(frame.t_s);
    if (truth.ball_present) ++with_ball;
    return frames.size() < static_cast<std::size_t>(o.timing_frames);
  });
  timing.frames = frames.size();
  timing.ball_fraction = frames.empty() ? 0.0 : static_cast<double>(with_ball) / frames.size();
  // Rendering alone (no simulation), for the daemon's frame budget.
  {
    vision::Frame frame;
    std::vector<Vec2> path(12, Vec2{0.25, 0.5});
    for (std::size_t k = 0; k < path.size(); ++k) path[k] += Vec2{0.0, 0.006 * k / path.size()};
    const int n = std::max(20, o.timing_frames);
    const auto t0 = Clock::now();
    for (int i = 0; i < n; ++i) camera.render(path, i / camera.fps(), frame);
    timing.render_fps = n / seconds_since(t0);
  }
  for (int mode = 0; mode < 2; ++mode) {
    vision::BallDetectorConfig dc = o.detector;
    dc.use_roi = mode == 1;
    vision::BallDetector detector(camera.homography(), camera.frame_size(), dc);
    detector.set_occluder_mask(camera.occluder_mask());
    double t_s = -1000.0;
    learn_background(camera, detector, o.background_frames, t_s);
    vision::Frame frame;
    std::size_t answered = 0;
    std::size_t from_roi = 0;
    const auto t0 = Clock::now();
    for (int rep = 0; rep < o.timing_repeats; ++rep) {
      detector.forget_track();
      for (std::size_t i = 0; i < frames.size(); ++i) {
        frame.gray = frames[i];
        frame.t_s = times[i];
        const vision::Detection d = detector.detect(frame);
        if (d.found) ++answered;
        if (d.from_roi) ++from_roi;
      }
    }
    const double s = seconds_since(t0);
    const double fps = static_cast<double>(frames.size()) * o.timing_repeats / s;
    if (mode == 0) {
      timing.full_frame_fps = fps;
    } else {
      timing.roi_fps = fps;
      timing.roi_found_fraction = answered > 0 ? static_cast<double>(from_roi) / answered : 0.0;
    }
  }
  timing.roi_speedup = timing.full_frame_fps > 0.0 ? timing.roi_fps / timing.full_frame_fps : 0.0;
  r.timing.push_back(timing);
}

}  // namespace

DetectorReport run_detector_bench(const table::Board& board, const DetectorBenchOptions& options,
                                  const std::function<void(const std::string&)>& progress) {
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  const auto t0 = Clock::now();
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);  // one core, as the targets say
  DetectorReport r;
  r.board = board.source;
  r.options = options;
  try {
    measure_accuracy(board, options, r);
    std::ostringstream s;
    s << "accuracy: " << r.accuracy.unoccluded << " frames, median " << r.accuracy.error_px.median << " px, p99 "
      << r.accuracy.error_px.p99 << " px";
    say(s.str());
    measure_ball_free(board, options, r);
    say("ball-free: " + std::to_string(r.ball_free_frames) + " frames, " + std::to_string(r.false_detections) +
        " false detections");
    measure_occlusion(board, options, r);
    say("occlusion: " + std::to_string(r.occlusion.frames) + " frames, " + std::to_string(r.occlusion.wrong) +
        " wrong");
    for (const cv::Size& size : options.timing_sizes) {
      measure_timing(board, options, size, r);
      std::ostringstream t;
      t << "timing " << size.width << "x" << size.height << ": full " << r.timing.back().full_frame_fps << " fps, roi "
        << r.timing.back().roi_fps << " fps";
      say(t.str());
    }
  } catch (...) {
    cv::setNumThreads(threads);
    throw;
  }
  cv::setNumThreads(threads);
  DetectorHeadline& h = r.headline;
  h.median_met = r.accuracy.error_px.count > 0 && r.accuracy.error_px.median <= kTargetMedianErrorPx;
  h.p99_met = r.accuracy.error_px.count > 0 && r.accuracy.error_px.p99 <= kTargetP99ErrorPx;
  h.no_false_met = r.false_detections == 0 && r.accuracy.no_ball_detections == 0;
  h.occlusion_met = r.occlusion.wrong == 0;
  for (const DetectorTiming& t : r.timing) {
    if (t.size == cv::Size(640, 480)) {
      h.roi_fps_met = t.roi_fps >= kTargetRoiFps640;
      h.full_fps_met = t.full_frame_fps >= kTargetFullFrameFps640;
    }
  }
  h.all_met = h.median_met && h.p99_met && h.no_false_met && h.occlusion_met && h.roi_fps_met && h.full_fps_met;
  r.wall_s = seconds_since(t0);
  return r;
}

}  // namespace pinball::bench
