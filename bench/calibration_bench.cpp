#include "calibration_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>

#include "pinball/core/statistics.h"
#include "pinball/calibration/camera_calibration.h"
#include "pinball/calibration/flipper_calibration.h"
#include "pinball/calibration/gravity_calibration.h"
#include "pinball/simlab/sim_lab.h"
#include "pinball/track/tracker.h"
#include "pinball/track/trajectory_fit.h"
#include "tracker_bench.h"

namespace pinball::bench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kDeg = 180.0 / std::numbers::pi;

FlipperErrors errors_of(const calibration::FlipperCalibration& c, const table::Flipper& truth) {
  FlipperErrors e;
  e.flipper = truth.name;
  e.method = calibration::to_string(c.method);
  e.pivot_mm = (c.pivot_m - truth.pivot).norm() * 1e3;
  e.tip_mm = (c.tip_m - table::flipper_tip(truth, truth.theta_min_rad)).norm() * 1e3;
  e.length_mm = (c.length_m - truth.length_m) * 1e3;
  e.theta_min_deg = (c.theta_min_rad - truth.theta_min_rad) * kDeg;
  e.theta_max_deg = (c.theta_max_rad - truth.theta_max_rad) * kDeg;
  e.points = c.points;
  e.met = e.pivot_mm <= kTargetPivotTipError_m * 1e3 && e.tip_mm <= kTargetPivotTipError_m * 1e3 &&
          std::abs(e.theta_min_deg) <= kTargetThetaError_deg && std::abs(e.theta_max_deg) <= kTargetThetaError_deg;
  return e;
}

// h of point p along flipper line `l` (0 at the pivot, 1 at the tip).
double h_on(const track::FlipperLine& l, const Vec2& p) { return (p - l.pivot).dot(l.axis()) / l.axis().squaredNorm(); }

TrackerEffect tracker_effect(const std::string& name, const std::vector<TrackerApproach>& approaches,
                             const table::Board& truth, const track::FlipperGeometry& true_geometry,
                             const track::FlipperGeometry& geometry, double g_mps2, std::uint64_t seed) {
  const track::CameraModelConfig camera = TrackerBenchOptions{}.headline_camera;
  track::TrackerConfig config = track::default_tracker_config(truth, camera);
  config.g_mps2 = g_mps2;
  track::Tracker tracker(geometry, config);
  std::vector<double> impact_mm, dt_ms, dh;
  TrackerEffect e;
  e.geometry = name;
  std::size_t valid = 0;
  for (std::size_t i = 0; i < approaches.size(); ++i) {
    const TrackerApproach& a = approaches[i];
    const track::TrajectoryFit exact = track::exact_trajectory(a.p0, a.v0, a.g_mps2, 0.0);
    track::CameraModel cam(camera, seed + i);  // the same noise for every geometry
    tracker.reset();
    track::Observation o;
    for (std::size_t k = 0;; ++k) {
      const double t = static_cast<double>(k) * 5e-4;
      if (t >= a.truth.t_impact_s) break;
      cam.expose(t, exact.position_at(t));
      while (cam.deliver(t, o)) {
        const track::TrackerOutput& out = tracker.update(o, track::ContactSensors{});
        if ((exact.position_at(o.t_s) - a.truth.impact_point).norm() < kTrackerHeadlineDistance_m) continue;
        ++e.observations;
        const track::TrajectoryProjection& p = out.projection;
        if (!p.valid) continue;
        ++valid;
        impact_mm.push_back((p.impact_point - a.truth.impact_point).norm() * 1e3);
        dt_ms.push_back(std::abs(p.t_observation_s + p.t_impact_s - a.truth.t_impact_s) * 1e3);
        dh.push_back(std::abs(h_on(true_geometry.lines[static_cast<std::size_t>(a.truth.flipper)], p.impact_point) -
                              a.truth.h));
      }
    }
  }
  e.valid_fraction = e.observations ? static_cast<double>(valid) / static_cast<double>(e.observations) : 0.0;
  e.median_impact_mm = quantile(impact_mm, 0.5);
  e.p90_impact_mm = quantile(impact_mm, 0.9);
  e.median_dt_ms = quantile(dt_ms, 0.5);
  e.median_abs_dh = quantile(dh, 0.5);
  return e;
}

track::FlipperGeometry geometry_of(const std::vector<calibration::FlipperCalibration>& flippers) {
  calibration::Calibration c;
  c.flippers = flippers;
  return calibration::flipper_geometry_from_calibration(c, "bench");
}

}  // namespace

CalibrationReport run_calibration_bench(const table::Board& board, const CalibrationBenchOptions& options,
                                        const std::function<void(const std::string&)>& progress) {
  const auto start = Clock::now();
  const auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  CalibrationReport r;
  r.board = board.source;
  r.options = options;
  simlab::SimLabOptions lab_options = simlab::with_mounting_error({});  // the routines must find the machine, not the drawing
  lab_options.seed = options.seed;
  simlab::SimLab lab(board, lab_options);
  const table::Board& truth = lab.truth();
  r.true_g_mps2 = truth.gravity_mps2;

  // Camera.
  const std::vector<Vec2> layout = calibration::default_marker_layout(board);
  const calibration::HomographyFit cam = calibration::calibrate_camera(lab.camera_image(), layout);
  r.markers_detected = cam.detections;
  r.markers_used = cam.calibration.markers_used;
  r.reprojection_rms_px = cam.calibration.reprojection_rms_px;
  const vision::CameraHomography h(cam.calibration.image_from_board);
  double ss = 0.0;
  int n = 0;
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 40; ++j) {
      const Vec2 p{board.width_m * i / 20.0, board.height_m * j / 40.0};
      const double e = (h.board_from_image(lab.true_homography().image_from_board(p)) - p).norm() * 1e3;
      r.homography_max_error_mm = std::max(r.homography_max_error_mm, e);
      ss += e * e;
      ++n;
    }
  }
  r.homography_rms_error_mm = std::sqrt(ss / n);
  say("camera: " + std::to_string(r.markers_used) + " markers, reprojection rms " +
      std::to_string(r.reprojection_rms_px) + " px, homography max error " + std::to_string(r.homography_max_error_mm) +
      " mm");

  // Flippers, both methods, through the calibrated homography.
  std::vector<Vec2> down, up;
  for (const calibration::DetectedMarker& m : calibration::detect_markers(lab.flipper_markers_image(false))) {
    down.push_back(h.board_from_image(m.uv_px));
  }
  for (const calibration::DetectedMarker& m : calibration::detect_markers(lab.flipper_markers_image(true))) {
    up.push_back(h.board_from_image(m.uv_px));
  }
  std::vector<calibration::FlipperCalibration> by_markers, markerless;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    by_markers.push_back(calibration::calibrate_flipper_markers(board.flippers[i], down, up));
    markerless.push_back(
        calibration::calibrate_flipper_sweep([&] { return lab.sweep_video(i); }, h, board.flippers[i]));
    r.flippers.push_back(errors_of(by_markers.back(), truth.flippers[i]));
    r.flippers.push_back(errors_of(markerless.back(), truth.flippers[i]));
    r.disagreement_pivot_mm.push_back((by_markers.back().pivot_m - markerless.back().pivot_m).norm() * 1e3);
    for (std::size_t k = r.flippers.size() - 2; k < r.flippers.size(); ++k) {
      const FlipperErrors& e = r.flippers[k];
      std::ostringstream s;
      s << e.flipper << " " << e.method << ": pivot " << e.pivot_mm << " mm, tip " << e.tip_mm << " mm, theta "
        << e.theta_min_deg << " / " << e.theta_max_deg << " deg";
      say(s.str());
    }
  }
  r.flippers_met = std::all_of(r.flippers.begin(), r.flippers.end(), [](const FlipperErrors& e) { return e.met; });

  // Gravity: independent sets of n rolls.
  double g5 = truth.gravity_mps2;
  for (const int rolls : options.roll_counts) {
    GravityErrors g;
    g.rolls = rolls;
    std::vector<double> err, half;
    int covered = 0;
    for (int s = 0; s < options.gravity_sets; ++s) {
      const std::vector<calibration::GravityRoll> set =
          lab.rolls(rolls, static_cast<std::uint64_t>(rolls) * 100003u + static_cast<std::uint64_t>(s));
      const calibration::GravityCalibration c = calibration::calibrate_gravity(set);
      const calibration::GravityEstimate& e = c.estimate;
      if (rolls == 5 && s == 0) g5 = e.g_mps2;
      err.push_back(std::abs(e.g_mps2 - truth.gravity_mps2) / truth.gravity_mps2 * 100.0);
      half.push_back(0.5 * (e.ci_high_mps2 - e.ci_low_mps2) / truth.gravity_mps2 * 100.0);
      covered += e.ci_low_mps2 <= truth.gravity_mps2 && truth.gravity_mps2 <= e.ci_high_mps2 ? 1 : 0;
      g.outliers_rejected += e.rolls_rejected;
      ++g.sets;
    }
    g.median_abs_error_pct = quantile(err, 0.5);
    g.max_abs_error_pct = *std::max_element(err.begin(), err.end());
    g.coverage = static_cast<double>(covered) / g.sets;
    g.median_half_width_pct = quantile(half, 0.5);
    g.met = g.max_abs_error_pct <= kTargetGravityError * 100.0;
    if (rolls == 5) r.gravity_met = g.met;
    std::ostringstream s;
    s << "gravity, " << rolls << " rolls x " << g.sets << " sets: median error " << g.median_abs_error_pct
      << " %, max " << g.max_abs_error_pct << " %, interval coverage " << g.coverage;
    say(s.str());
    r.gravity.push_back(g);
  }

  // The tracker with true and calibrated geometry on the same observations.
  TrackerBenchOptions to;
  to.approaches = options.approaches;
  to.seed = options.seed;
  const std::vector<TrackerApproach> approaches = collect_tracker_approaches(truth, to);
  const track::FlipperGeometry true_geometry = track::flipper_geometry_from_board(truth);
  r.tracker.push_back(tracker_effect("true", approaches, truth, true_geometry, true_geometry, truth.gravity_mps2, options.seed));
  r.tracker.push_back(tracker_effect("markers", approaches, truth, true_geometry, geometry_of(by_markers), g5, options.seed));
  r.tracker.push_back(
      tracker_effect("markerless", approaches, truth, true_geometry, geometry_of(markerless), g5, options.seed));
  for (const TrackerEffect& t : r.tracker) {
    std::ostringstream s;
    s << "tracker with " << t.geometry << " geometry: median impact error " << t.median_impact_mm << " mm, |dh| "
      << t.median_abs_dh;
    say(s.str());
  }
  r.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

}  // namespace pinball::bench
