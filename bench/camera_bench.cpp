#include "camera_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>

#include "pinball/calibration/latency_calibration.h"
#include "pinball/core/rng.h"
#include "pinball/simlab/sim_latency_lab.h"
#include "pinball/simlab/sim_target_view.h"
#include "pinball/core/statistics.h"
#include "pinball/track/tracker.h"
#include "tracker_bench.h"

namespace pinball::bench {
namespace {

using Clock = std::chrono::steady_clock;

double wall_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The camera is fed the ball's path at this step (s): fine enough that its
// linear interpolation cuts a bounce's corner by under 0.3 mm at 5 m/s.
constexpr double kFeedStep_s = 1e-4;
// Frames a camera runs before anything is scored: the steady clock's window fills.
constexpr double kWarmUp_s = 0.4;

// A ball crossing a rectangle of the table in straight lines at constant
// speed, bouncing off its sides: known exactly at any time.
struct StraightMotion {
  Vec2 p0;
  Vec2 v;
  Vec2 lo;
  Vec2 hi;

  static double fold(double x, double a, double b) {
    const double span = b - a;
    double u = std::fmod(x - a, 2.0 * span);
    if (u < 0.0) u += 2.0 * span;
    return a + (u <= span ? u : 2.0 * span - u);
  }
  Vec2 at(double t_s) const {
    const Vec2 p = p0 + v * t_s;
    return {fold(p.x(), lo.x(), hi.x()), fold(p.y(), lo.y(), hi.y())};
  }
};

StraightMotion random_motion(const table::Board& board, double speed_mps, Rng& rng) {
  StraightMotion m;
  // Clear of the flippers below and the image's edge around the table.
  m.lo = Vec2{0.06, 0.30};
  m.hi = Vec2{board.width_m - 0.06, board.height_m - 0.08};
  m.p0 = Vec2{rng.uniform(m.lo.x(), m.hi.x()), rng.uniform(m.lo.y(), m.hi.y())};
  // Away from the axes, so that the ball crosses rows as well as columns.
  const double a = rng.uniform(0.15, 0.35) * std::numbers::pi + (rng.uniform01() < 0.5 ? 0.0 : 0.5 * std::numbers::pi);
  m.v = speed_mps * Vec2{std::cos(a), std::sin(a)};
  return m;
}

// A camera with one scenario's faults and a detector with its corrections,
// its background learned.
struct CameraRig {
  simlab::SimCameraSource camera;
  vision::BallDetector detector;
  double t_s = 0.0;

  CameraRig(const table::Board& board, const CameraScenario& s, std::uint64_t seed, int background_frames)
      : camera(board, camera_config(s, seed)), detector(camera.homography(), camera.frame_size(), detector_config(board, s)) {
    detector.set_occluder_mask(camera.occluder_mask());
    learn_background(camera, detector, background_frames, t_s);
    camera.reset(t_s);
  }
  static simlab::SimCameraConfig camera_config(const CameraScenario& s, std::uint64_t seed) {
    simlab::SimCameraConfig c;
    c.seed = seed;
    c.realism = s.camera;
    return c;
  }
  static vision::BallDetectorConfig detector_config(const table::Board& board, const CameraScenario& s) {
    vision::BallDetectorConfig c = s.corrections;
    c.ball_radius_m = board.ball.radius_m;
    return c;
  }
};

double ideal_px_distance(const simlab::SimCameraSource& camera, const Vec2& a, const Vec2& b) {
  return cv::norm(camera.homography().image_from_board(a) - camera.homography().image_from_board(b));
}

// Detector errors for one scenario at one speed; appends the headline errors to `pooled_mm`.
CameraDetectorFigures measure_detector(const table::Board& board, const CameraScenario& s, double speed_mps,
                                       const CameraBenchOptions& o, std::uint64_t seed, std::vector<double>& pooled_mm) {
  CameraDetectorFigures f;
  f.speed_mps = speed_mps;
  CameraRig rig(board, s, seed, o.background_frames);
  Rng rng(seed ^ 0xC0FFEEULL);
  const StraightMotion motion = random_motion(board, speed_mps, rng);
  const double t0 = rig.t_s;
  std::vector<double> err_mm, err_px, pos_mm, abs_dt_ms;
  double sum_dt_ms = 0.0;
  vision::Frame frame;
  const double limit_s = kWarmUp_s + 10.0 * o.frames_per_speed / rig.camera.fps();
  for (double tau = 0.0; static_cast<int>(f.frames) < o.frames_per_speed && tau < limit_s; tau += kFeedStep_s) {
    rig.camera.observe_ball(t0 + tau, motion.at(tau), true);
    while (rig.camera.read(frame)) {
      const vision::Detection d = rig.detector.detect(frame);
      const simlab::FrameTruth& truth = rig.camera.truth();
      if (truth.t_row0_exposure_s - t0 < kWarmUp_s) continue;
      if (!truth.ball_whole_exposure || truth.occluded_fraction > 0.0 || truth.in_glare) continue;
      ++f.frames;
      if (!d.found) continue;
      ++f.detected;
      const Vec2 p_claimed_true = motion.at(d.observation.t_s - t0);
      const double e_mm = 1e3 * (d.observation.p_board - p_claimed_true).norm();
      err_mm.push_back(e_mm);
      pooled_mm.push_back(e_mm);
      err_px.push_back(ideal_px_distance(rig.camera, d.observation.p_board, p_claimed_true));
      pos_mm.push_back(1e3 * (d.observation.p_board - motion.at(truth.t_ball_exposure_s - t0)).norm());
      const double dt_ms = 1e3 * (d.observation.t_s - truth.t_ball_exposure_s);
      abs_dt_ms.push_back(std::abs(dt_ms));
      sum_dt_ms += dt_ms;
    }
  }
  f.error_mm = summarise_errors(err_mm);
  f.error_px = summarise_errors(err_px);
  f.position_mm = summarise_errors(pos_mm);
  f.median_abs_dt_ms = quantile(abs_dt_ms, 0.5);
  f.mean_dt_ms = abs_dt_ms.empty() ? 0.0 : sum_dt_ms / static_cast<double>(abs_dt_ms.size());
  return f;
}

// Tracker errors for one scenario over the approaches, the camera running
// throughout (the ball out of play between approaches).
CameraTrackerFigures measure_tracker(const table::Board& board, const CameraScenario& s,
                                     const std::vector<TrackerApproach>& approaches, const CameraBenchOptions& o) {
  CameraTrackerFigures f;
  CameraRig rig(board, s, o.seed, o.background_frames);
  const track::FlipperGeometry geometry = track::flipper_geometry_from_board(board);
  track::CameraModelConfig nominal;
  nominal.m_per_px = 1.0 / rig.camera.homography().px_per_m_at(Vec2{0.5 * board.width_m, 0.5 * board.height_m});
  nominal.latency_s = 0.0;
  track::Tracker tracker(geometry, track::default_tracker_config(board, nominal));
  std::vector<double> dh, dt_ms;
  std::size_t valid = 0;
  vision::Frame frame;
  double t = rig.t_s;
  for (double end = t + kWarmUp_s; t < end; t += kFeedStep_s) {
    rig.camera.observe_ball(t, approaches.front().p0, false);
    while (rig.camera.read(frame)) rig.detector.detect(frame);
  }
  for (const TrackerApproach& a : approaches) {
    const double base = t;
    tracker.reset();
    rig.detector.forget_track();
    const track::TrajectoryFit path = track::exact_trajectory(a.p0, a.v0, a.g_mps2, 0.0);
    // Until the ball reaches the flippers, then out of play while the frames in flight arrive.
    for (; t < base + a.truth.t_impact_s + 0.05; t += kFeedStep_s) {
      const double tau = t - base;
      rig.camera.observe_ball(t, path.position_at(std::min(tau, a.truth.t_impact_s)), tau < a.truth.t_impact_s);
      while (rig.camera.read(frame)) {
        const vision::Detection d = rig.detector.detect(frame);
        if (!d.found) continue;
        const double true_tau = rig.camera.truth().t_ball_exposure_s - base;
        track::Observation obs = d.observation;
        obs.t_s -= base;
        const track::TrackerOutput& out = tracker.update(obs, track::ContactSensors{});
        if (true_tau < 0.0 || true_tau >= a.truth.t_impact_s) continue;
        if (remaining_distance(a, true_tau) < kTrackerHeadlineDistance_m) continue;
        ++f.observations;
        const ProjectionError e = projection_error(out.projection, a, geometry);
        if (!e.valid) continue;
        ++valid;
        dh.push_back(e.abs_dh);
        dt_ms.push_back(1e3 * e.abs_dt_impact_s);
      }
    }
    ++f.approaches;
  }
  f.valid_fraction = f.observations ? static_cast<double>(valid) / static_cast<double>(f.observations) : 0.0;
  f.median_abs_dh = quantile(dh, 0.5);
  f.median_abs_dt_impact_ms = quantile(dt_ms, 0.5);
  return f;
}

// Detector frames per second, ROI search, on frames of the all-faults camera.
CameraCostFigures measure_cost(const table::Board& board, const std::vector<CameraScenario>& scenarios,
                               const CameraBenchOptions& o) {
  CameraCostFigures c;
  const auto find = [&](const std::string& name) -> const CameraScenario& {
    for (const CameraScenario& s : scenarios) {
      if (s.name == name) return s;
    }
    return scenarios.front();
  };
  const CameraScenario& plain = find("all_uncorrected");
  const CameraScenario& corrected = find("all_corrected");
  CameraRig rig(board, corrected, o.seed, o.background_frames);
  Rng rng(o.seed ^ 0xBEEFULL);
  const StraightMotion motion = random_motion(board, 3.0, rng);
  std::vector<vision::Frame> frames;
  vision::Frame frame;
  const double t0 = rig.t_s;
  for (double tau = 0.0; static_cast<int>(frames.size()) < o.timing_frames && tau < 60.0; tau += kFeedStep_s) {
    rig.camera.observe_ball(t0 + tau, motion.at(tau), true);
    while (rig.camera.read(frame)) {
      frames.push_back(frame);
      frames.back().gray = frame.gray.clone();
    }
  }
  c.frames = frames.size();
  const auto time_fps = [&](const CameraScenario& s) {
    vision::BallDetector detector(rig.camera.homography(), rig.camera.frame_size(), CameraRig::detector_config(board, s));
    detector.set_occluder_mask(rig.camera.occluder_mask());
    detector.background() = rig.detector.background();
    double best = 0.0;
    for (int pass = 0; pass < 3; ++pass) {
      detector.forget_track();
      const auto start = Clock::now();
      for (const vision::Frame& f : frames) detector.detect(f);
      const double wall = wall_since(start);
      if (wall > 0.0) best = std::max(best, static_cast<double>(frames.size()) / wall);
    }
    return best;
  };
  c.plain_roi_fps = time_fps(plain);
  c.corrected_roi_fps = time_fps(corrected);
  return c;
}

}  // namespace

double measure_simulated_latency_s(const table::Board& board, const simlab::SimCameraRealism& camera, int events,
                                   std::uint64_t seed) {
  simlab::SimLatencyOptions o;
  o.seed = seed;
  o.events = events;
  o.camera.realism = camera;
  const simlab::SimLatencyRun run = simlab::simulate_latency_run(board, o);
  return calibration::measure_latency(run.recording, run.region, run.timing).latency_s;
}

vision::CameraIntrinsics calibrate_simulated_lens(const vision::CameraIntrinsics& lens, int views, std::uint64_t seed) {
  const calibration::TargetSpec target;  // the default chessboard
  return calibration::calibrate_intrinsics(simlab::simulated_target_images(lens, target, views, seed), target)
      .calibration.lens;
}

CameraBenchOptions quick_camera_bench_options() {
  CameraBenchOptions o;
  o.speeds_mps = {1.0, 5.0};
  o.frames_per_speed = 60;
  o.approaches = 12;
  o.background_frames = 8;
  o.timing_frames = 40;
  return o;
}

std::vector<CameraScenario> camera_scenarios(const CameraBenchOptions& o) {
  const simlab::SimCameraRealism& t = o.camera;
  simlab::SimCameraRealism lens_only;
  lens_only.lens = t.lens;
  simlab::SimCameraRealism rolling_only;
  rolling_only.row_time_s = t.row_time_s;
  simlab::SimCameraRealism timing_only;
  timing_only.frame_jitter_s = t.frame_jitter_s;
  timing_only.latency_min_s = t.latency_min_s;
  timing_only.latency_jitter_mean_s = t.latency_jitter_mean_s;
  simlab::SimCameraRealism light_only;
  light_only.flicker_hz = t.flicker_hz;
  light_only.flicker_amplitude = t.flicker_amplitude;
  light_only.gain_drift_sigma = t.gain_drift_sigma;
  light_only.gain_drift_time_s = t.gain_drift_time_s;

  vision::BallDetectorConfig none;
  vision::BallDetectorConfig undistort;
  undistort.lens = t.lens;
  vision::BallDetectorConfig calibrated;
  calibrated.lens = o.calibrated_lens;
  vision::BallDetectorConfig row_timed;
  row_timed.row_time_s = t.row_time_s;
  vision::BallDetectorConfig mean_latency;
  mean_latency.latency_s = t.latency_mean_s();
  // The steady clock; the latency is then the minimum one.
  vision::BallDetectorConfig steady;
  steady.dejitter_frames = vision::kDefaultDejitterFrames;
  steady.frame_period_s = 1.0 / simlab::SimCameraConfig{}.fps;
  steady.latency_s = t.latency_min_s;
  vision::BallDetectorConfig all = steady;
  all.lens = t.lens;
  all.row_time_s = t.row_time_s;
  vision::BallDetectorConfig measured = steady;
  if (o.measured_latency_s) measured.latency_s = *o.measured_latency_s;
  // The lab's flow: every correction from its calibration, none from the truth.
  vision::BallDetectorConfig all_calibrated = all;
  if (o.calibrated_lens) all_calibrated.lens = o.calibrated_lens;
  if (o.measured_latency_s) all_calibrated.latency_s = *o.measured_latency_s;

  std::vector<CameraScenario> s;
  s.push_back({"ideal", {}, none, false});
  if (t.lens) {
    s.push_back({"distortion_uncorrected", lens_only, none, false});
    s.push_back({"distortion_corrected", lens_only, undistort, true});
    if (o.calibrated_lens) s.push_back({"distortion_calibrated_lens", lens_only, calibrated, true});
  }
  if (t.row_time_s > 0.0) {
    s.push_back({"rolling_shutter_uncorrected", rolling_only, none, false});
    s.push_back({"rolling_shutter_corrected", rolling_only, row_timed, true});
  }
  if (t.latency_mean_s() > 0.0) {
    s.push_back({"latency_uncompensated", timing_only, none, false});
    s.push_back({"latency_mean_subtracted", timing_only, mean_latency, false});
    s.push_back({"latency_compensated", timing_only, steady, true});
    if (o.measured_latency_s) s.push_back({"latency_compensated_measured", timing_only, measured, true});
  }
  if (t.flicker_amplitude > 0.0 || t.gain_drift_sigma > 0.0) {
    s.push_back({"flicker_and_drift", light_only, none, true});
  }
  s.push_back({"all_uncorrected", t, none, false});
  s.push_back({"all_corrected", t, all, true});
  if ((o.calibrated_lens && t.lens) || o.measured_latency_s) s.push_back({"all_calibrated", t, all_calibrated, true});
  return s;
}

CameraReport run_camera_bench(const table::Board& board, const CameraBenchOptions& options,
                              const std::function<void(const std::string&)>& progress) {
  const auto start = Clock::now();
  CameraReport report;
  report.board = board.source;
  report.options = options;
  report.true_latency_s = options.camera.latency_min_s;
  const std::vector<CameraScenario> scenarios = camera_scenarios(options);

  TrackerBenchOptions to;
  to.approaches = options.approaches;
  to.seed = options.seed;
  const std::vector<TrackerApproach> approaches = collect_tracker_approaches(board, to);
  if (progress) progress(std::to_string(approaches.size()) + " approaches collected");

  for (std::size_t i = 0; i < scenarios.size(); ++i) {
    const CameraScenario& s = scenarios[i];
    CameraScenarioResult r;
    r.scenario = s;
    std::vector<double> pooled;
    for (std::size_t k = 0; k < options.speeds_mps.size(); ++k) {
      // The same motion and camera noise per speed in every scenario: paired comparisons.
      r.detector.push_back(measure_detector(board, s, options.speeds_mps[k], options, options.seed + 17 * k, pooled));
    }
    r.pooled_median_error_mm = quantile(pooled, 0.5);
    if (!approaches.empty()) r.tracker = measure_tracker(board, s, approaches, options);
    report.scenarios.push_back(r);
    if (progress) {
      std::ostringstream line;
      line << s.name << ": detector median " << r.pooled_median_error_mm << " mm, tracker |dh| "
           << r.tracker.median_abs_dh << ", |dt_impact| " << r.tracker.median_abs_dt_impact_ms << " ms ("
           << i + 1 << "/" << scenarios.size() << ", " << wall_since(start) << " s)";
      progress(line.str());
    }
  }
  const CameraScenarioResult& ideal = report.scenarios.front();
  const auto ratio = [](double a, double b) { return b > 0.0 ? a / b : 0.0; };
  report.corrected_within_target = true;
  for (CameraScenarioResult& r : report.scenarios) {
    r.ratio_to_ideal = ratio(r.pooled_median_error_mm, ideal.pooled_median_error_mm);
    r.tracker_dh_ratio_to_ideal = ratio(r.tracker.median_abs_dh, ideal.tracker.median_abs_dh);
    r.tracker_dt_ratio_to_ideal = ratio(r.tracker.median_abs_dt_impact_ms, ideal.tracker.median_abs_dt_impact_ms);
    const double limit = 1.0 + kTargetCorrectedWithinFraction;
    r.within_target = r.ratio_to_ideal <= limit && r.tracker_dh_ratio_to_ideal <= limit &&
                      r.tracker_dt_ratio_to_ideal <= limit;
    if (r.scenario.corrected && !r.within_target) report.corrected_within_target = false;
  }
  if (options.calibrated_lens && options.camera.lens) {
    CalibratedLensFigures& l = report.calibrated_lens;
    l.present = true;
    l.source = options.calibrated_lens_source;
    l.truth = *options.camera.lens;
    l.calibrated = *options.calibrated_lens;
    l.comparison = calibration::compare_lenses(l.calibrated, l.truth);
  }
  report.cost = measure_cost(board, scenarios, options);
  if (progress) progress("detector cost measured");
  report.wall_s = wall_since(start);
  return report;
}

}  // namespace pinball::bench
