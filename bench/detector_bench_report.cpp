// The detector bench's report, JSON and text (the measurement: detector_bench.cpp).
#include "detector_bench.h"

#include <iomanip>
#include <sstream>

namespace pinball::bench {

nlohmann::json to_json(const ErrorSummary& s) {
  return {{"count", s.count}, {"median", s.median}, {"p99", s.p99}, {"max", s.max}};
}

nlohmann::json to_json(const DetectorReport& r) {
  const DetectorBenchOptions& o = r.options;
  const AccuracyFigures& a = r.accuracy;
  nlohmann::json timing = nlohmann::json::array();
  for (const DetectorTiming& t : r.timing) {
    timing.push_back({{"width_px", t.size.width},
                      {"height_px", t.size.height},
                      {"frames", t.frames},
                      {"ball_fraction", t.ball_fraction},
                      {"full_frame_fps", t.full_frame_fps},
                      {"roi_fps", t.roi_fps},
                      {"roi_speedup", t.roi_speedup},
                      {"roi_found_fraction", t.roi_found_fraction},
                      {"render_fps", t.render_fps}});
  }
  return {
      {"benchmark", "detector"},
      {"board", r.board},
      {"options",
       {{"seed", o.seed},
        {"play_frames", o.play_frames},
        {"ball_free_frames", o.ball_free_frames},
        {"occlusion_frames", o.occlusion_frames},
        {"timing_frames", o.timing_frames},
        {"timing_repeats", o.timing_repeats},
        {"wrong_px", o.wrong_px},
        {"camera",
         {{"width_px", o.camera.width_px},
          {"height_px", o.camera.height_px},
          {"fps", o.camera.fps},
          {"exposure_s", o.camera.exposure_s},
          {"noise_sigma", o.camera.noise_sigma},
          {"lamps", o.camera.lamps},
          {"lamp_toggle_probability", o.camera.lamp_toggle_probability},
          {"plastics", o.camera.plastics.size()},
          {"glare", o.camera.glare.enabled}}},
        {"detector_threshold", o.detector.threshold}}},
      {"accuracy",
       {{"frames", a.frames},
        {"ball_frames", a.ball_frames},
        {"unoccluded_frames", a.unoccluded},
        {"detected", a.detected},
        {"missed", a.missed},
        {"wrong", a.wrong},
        {"error_px", to_json(a.error_px)},
        {"error_mm", to_json(a.error_mm)},
        {"baseline_naive_centroid_error_px", to_json(a.naive_error_px)},
        {"baseline_naive_found", a.naive_found},
        {"median_blur_px", a.median_blur_px},
        {"p99_blur_px", a.p99_blur_px},
        {"median_radius_px", a.median_radius_px},
        {"in_glare_frames", a.in_glare},
        {"in_glare_detected", a.in_glare_detected},
        {"in_glare_wrong", a.in_glare_wrong},
        {"no_ball_frames", a.no_ball_frames},
        {"no_ball_detections", a.no_ball_detections}}},
      {"ball_free",
       {{"frames", r.ball_free_frames},
        {"false_detections", r.false_detections},
        {"glare_frames", r.ball_free_glare_frames},
        {"rejected_blobs", r.ball_free_rejected_blobs}}},
      {"occlusion",
       {{"frames", r.occlusion.frames},
        {"no_observation", r.occlusion.no_observation},
        {"wrong", r.occlusion.wrong},
        {"close", r.occlusion.close}}},
      {"timing", timing},
      {"targets",
       {{"median_error_px", kTargetMedianErrorPx},
        {"p99_error_px", kTargetP99ErrorPx},
        {"roi_fps_640x480", kTargetRoiFps640},
        {"full_frame_fps_640x480", kTargetFullFrameFps640},
        {"median_met", r.headline.median_met},
        {"p99_met", r.headline.p99_met},
        {"no_false_detections_met", r.headline.no_false_met},
        {"occlusion_met", r.headline.occlusion_met},
        {"roi_fps_met", r.headline.roi_fps_met},
        {"full_frame_fps_met", r.headline.full_fps_met},
        {"all_met", r.headline.all_met}}},
      {"wall_s", r.wall_s}};
}

std::string to_text(const DetectorReport& r) {
  const AccuracyFigures& a = r.accuracy;
  std::ostringstream s;
  s << std::fixed << std::setprecision(3);
  s << "ball detector on " << r.board << " (simulated camera " << r.options.camera.width_px << "x"
    << r.options.camera.height_px << ", exposure " << r.options.camera.exposure_s * 1e3 << " ms)\n";
  s << "  accuracy, " << a.unoccluded << " unoccluded frames (median blur " << a.median_blur_px << " px, p99 "
    << a.p99_blur_px << " px, radius " << a.median_radius_px << " px):\n"
    << "    detector  median " << a.error_px.median << " px / " << a.error_mm.median << " mm, p99 " << a.error_px.p99
    << " px / " << a.error_mm.p99 << " mm, max " << a.error_px.max << " px; missed " << a.missed << ", wrong "
    << a.wrong << "\n"
    << "    baseline naive centroid  median " << a.naive_error_px.median << " px, p99 " << a.naive_error_px.p99
    << " px\n";
  s << "  ball-free frames " << r.ball_free_frames << " (glare on in " << r.ball_free_glare_frames
    << "): false detections " << r.false_detections << ", blobs rejected " << r.ball_free_rejected_blobs << "\n";
  s << "  occlusion frames " << r.occlusion.frames << ": no observation " << r.occlusion.no_observation << ", wrong "
    << r.occlusion.wrong << ", within " << r.options.wrong_px << " px " << r.occlusion.close << "\n";
  s << std::setprecision(0);
  for (const DetectorTiming& t : r.timing) {
    s << "  " << t.size.width << "x" << t.size.height << " one core: full frame " << t.full_frame_fps
      << " fps, ROI " << t.roi_fps << " fps (x" << std::setprecision(1) << t.roi_speedup << std::setprecision(0)
      << "), render " << t.render_fps << " fps\n";
  }
  s << "  targets " << (r.headline.all_met ? "met" : "NOT all met") << "\n";
  return s.str();
}

}  // namespace pinball::bench
