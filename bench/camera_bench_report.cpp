// The camera bench's report, JSON and text (the measurement: camera_bench.cpp).
#include <iomanip>
#include <sstream>

#include "camera_bench.h"
#include "pinball/core/json_write_archive.h"

namespace pinball::bench {
namespace {

nlohmann::json corrections_json(const vision::BallDetectorConfig& c) {
  nlohmann::json j{{"latency_s", c.latency_s},
                   {"row_time_s", c.row_time_s},
                   {"dejitter_frames", c.dejitter_frames},
                   {"frame_period_s", c.frame_period_s}};
  j["lens"] = c.lens ? to_json_value(*c.lens) : nlohmann::json();
  return j;
}

}  // namespace

nlohmann::json to_json(const CameraReport& r) {
  const CameraBenchOptions& o = r.options;
  nlohmann::json scenarios = nlohmann::json::array();
  for (const CameraScenarioResult& s : r.scenarios) {
    nlohmann::json detector = nlohmann::json::array();
    for (const CameraDetectorFigures& d : s.detector) {
      detector.push_back({{"speed_mps", d.speed_mps},
                          {"frames", d.frames},
                          {"detected", d.detected},
                          {"error_mm", to_json(d.error_mm)},
                          {"error_px", to_json(d.error_px)},
                          {"position_mm", to_json(d.position_mm)},
                          {"median_abs_dt_ms", d.median_abs_dt_ms},
                          {"mean_dt_ms", d.mean_dt_ms}});
    }
    const CameraTrackerFigures& t = s.tracker;
    scenarios.push_back({{"name", s.scenario.name},
                         {"camera", to_json_value(s.scenario.camera)},
                         {"corrections", corrections_json(s.scenario.corrections)},
                         {"corrected", s.scenario.corrected},
                         {"detector", detector},
                         {"pooled_median_error_mm", s.pooled_median_error_mm},
                         {"ratio_to_ideal", s.ratio_to_ideal},
                         {"tracker",
                          {{"approaches", t.approaches},
                           {"observations", t.observations},
                           {"valid_fraction", t.valid_fraction},
                           {"median_abs_dh", t.median_abs_dh},
                           {"median_abs_dt_impact_ms", t.median_abs_dt_impact_ms}}},
                         {"tracker_dh_ratio_to_ideal", s.tracker_dh_ratio_to_ideal},
                         {"tracker_dt_ratio_to_ideal", s.tracker_dt_ratio_to_ideal},
                         {"within_target", s.within_target}});
  }
  nlohmann::json lens;
  if (r.calibrated_lens.present) {
    const CalibratedLensFigures& l = r.calibrated_lens;
    lens = {{"source", l.source},
            {"truth", to_json_value(l.truth)},
            {"calibrated", to_json_value(l.calibrated)},
            {"fx_error_pct", l.comparison.fx_error_pct},
            {"fy_error_pct", l.comparison.fy_error_pct},
            {"principal_point_error_px", l.comparison.principal_point_error_px},
            {"distortion_max_error_px", l.comparison.distortion_max_error_px},
            {"distortion_sensor_max_error_px", l.comparison.distortion_sensor_max_error_px}};
  }
  return {{"benchmark", "camera"},
          {"board", r.board},
          {"options",
           {{"seed", o.seed},
            {"speeds_mps", o.speeds_mps},
            {"frames_per_speed", o.frames_per_speed},
            {"approaches", o.approaches},
            {"background_frames", o.background_frames},
            {"timing_frames", o.timing_frames},
            {"camera", to_json_value(o.camera)}}},
          {"scenarios", scenarios},
          {"calibrated_lens", lens},
          {"true_latency_s", r.true_latency_s},
          {"measured_latency_s", o.measured_latency_s ? nlohmann::json(*o.measured_latency_s) : nlohmann::json()},
          {"measured_latency_source", o.measured_latency_source},
          {"cost",
           {{"frames", r.cost.frames},
            {"plain_roi_fps", r.cost.plain_roi_fps},
            {"corrected_roi_fps", r.cost.corrected_roi_fps}}},
          {"target_within_fraction", kTargetCorrectedWithinFraction},
          {"corrected_within_target", r.corrected_within_target},
          {"wall_s", r.wall_s}};
}

std::string to_text(const CameraReport& r) {
  std::ostringstream s;
  s << std::fixed;
  s << "bench camera on " << r.board << ": errors of (t, p) against the ball's true place at the time claimed\n";
  s << "detector: median | p99 error (mm), per speed; |dt| = |t claimed - t true| (ms); tracker beyond 5 cm\n";
  s << std::left << std::setw(32) << "scenario";
  for (const double v : r.options.speeds_mps) {
    std::ostringstream h;
    h << std::setprecision(0) << std::fixed << v << " m/s mm | p99 | dt";
    s << std::setw(24) << h.str();
  }
  s << std::setw(10) << "x ideal" << std::setw(16) << "|dh| (x ideal)" << std::setw(23) << "|dt_imp| ms (x ideal)"
    << "valid\n";
  for (const CameraScenarioResult& c : r.scenarios) {
    s << std::left << std::setw(32) << c.scenario.name;
    for (const CameraDetectorFigures& d : c.detector) {
      std::ostringstream cell;
      cell << std::fixed << std::setprecision(2) << d.error_mm.median << " | " << d.error_mm.p99 << " | "
           << d.median_abs_dt_ms;
      s << std::setw(24) << cell.str();
    }
    std::ostringstream ratio, dh, dt, valid;
    ratio << std::fixed << std::setprecision(2) << c.ratio_to_ideal;
    dh << std::fixed << std::setprecision(4) << c.tracker.median_abs_dh << " (" << std::setprecision(2)
       << c.tracker_dh_ratio_to_ideal << ")";
    dt << std::fixed << std::setprecision(3) << c.tracker.median_abs_dt_impact_ms << " (" << std::setprecision(2)
       << c.tracker_dt_ratio_to_ideal << ")";
    valid << std::fixed << std::setprecision(2) << c.tracker.valid_fraction;
    s << std::setw(10) << ratio.str() << std::setw(16) << dh.str() << std::setw(23) << dt.str() << valid.str();
    if (c.scenario.corrected) s << (c.within_target ? "  within 10 % of ideal" : "  NOT within 10 % of ideal");
    s << "\n";
  }
  if (r.calibrated_lens.present) {
    const CalibratedLensFigures& l = r.calibrated_lens;
    s << std::setprecision(3) << "calibrated lens (" << l.source << "): fx " << l.comparison.fx_error_pct << " %, fy "
      << l.comparison.fy_error_pct << " %, principal point " << l.comparison.principal_point_error_px
      << " px, distortion up to " << l.comparison.distortion_max_error_px << " px over the image ("
      << l.comparison.distortion_sensor_max_error_px << " px to the sensor's corners) from the true lens\n";
  }
  if (r.options.measured_latency_s) {
    s << std::setprecision(3) << "measured latency (" << r.options.measured_latency_source << "): "
      << *r.options.measured_latency_s * 1e3 << " ms, true minimum " << r.true_latency_s * 1e3 << " ms\n";
  }
  s << std::setprecision(0) << "detector cost, ROI, one core: " << r.cost.plain_roi_fps << " fps uncorrected, "
    << r.cost.corrected_roi_fps << " fps with every correction (" << r.cost.frames << " frames)\n";
  s << "corrected scenarios within 10 % of the ideal camera: " << (r.corrected_within_target ? "yes" : "no") << "\n";
  s << std::setprecision(1) << "wall " << r.wall_s << " s\n";
  return s.str();
}

}  // namespace pinball::bench
