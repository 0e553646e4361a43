// The calibration bench's report, JSON and text (the measurement: calibration_bench.cpp).
#include "calibration_bench.h"

#include <sstream>

namespace pinball::bench {

nlohmann::json to_json(const CalibrationReport& r) {
  nlohmann::json flippers = nlohmann::json::array();
  for (const FlipperErrors& e : r.flippers) {
    flippers.push_back({{"flipper", e.flipper}, {"method", e.method}, {"pivot_error_mm", e.pivot_mm},
                        {"tip_error_mm", e.tip_mm}, {"length_error_mm", e.length_mm},
                        {"theta_min_error_deg", e.theta_min_deg}, {"theta_max_error_deg", e.theta_max_deg},
                        {"points", e.points}, {"targets_met", e.met}});
  }
  nlohmann::json gravity = nlohmann::json::array();
  for (const GravityErrors& g : r.gravity) {
    gravity.push_back({{"rolls", g.rolls}, {"sets", g.sets}, {"median_abs_error_pct", g.median_abs_error_pct},
                       {"max_abs_error_pct", g.max_abs_error_pct}, {"interval_coverage", g.coverage},
                       {"median_half_width_pct", g.median_half_width_pct},
                       {"rolls_rejected", g.outliers_rejected}, {"within_1pct", g.met}});
  }
  nlohmann::json tracker = nlohmann::json::array();
  for (const TrackerEffect& t : r.tracker) {
    tracker.push_back({{"geometry", t.geometry}, {"observations", t.observations}, {"valid_fraction", t.valid_fraction},
                       {"median_impact_error_mm", t.median_impact_mm}, {"p90_impact_error_mm", t.p90_impact_mm},
                       {"median_dt_impact_ms", t.median_dt_ms}, {"median_abs_dh", t.median_abs_dh}});
  }
  return {{"benchmark", "calibration"},
          {"board", r.board},
          {"seed", r.options.seed},
          {"true_g_mps2", r.true_g_mps2},
          {"camera",
           {{"markers_detected", r.markers_detected}, {"markers_used", r.markers_used},
            {"reprojection_rms_px", r.reprojection_rms_px}, {"homography_max_error_mm", r.homography_max_error_mm},
            {"homography_rms_error_mm", r.homography_rms_error_mm}}},
          {"flippers", flippers},
          {"disagreement_pivot_mm", r.disagreement_pivot_mm},
          {"gravity", gravity},
          {"tracker", tracker},
          {"flipper_targets_met", r.flippers_met},
          {"gravity_target_met", r.gravity_met},
          {"wall_s", r.wall_s}};
}

std::string to_text(const CalibrationReport& r) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(3);
  s << "calibration on " << r.board << " (simulated lab, seed " << r.options.seed << ")\n"
    << "  camera: " << r.markers_used << " of " << r.markers_detected << " markers, reprojection rms "
    << r.reprojection_rms_px << " px; homography error over the table rms " << r.homography_rms_error_mm
    << " mm, max " << r.homography_max_error_mm << " mm\n";
  for (const FlipperErrors& e : r.flippers) {
    s << "  " << e.flipper << " " << e.method << ": pivot " << e.pivot_mm << " mm, tip " << e.tip_mm << " mm, length "
      << e.length_mm << " mm, theta_min " << e.theta_min_deg << " deg, theta_max " << e.theta_max_deg << " deg ("
      << e.points << " points)" << (e.met ? "" : "  TARGET MISSED") << "\n";
  }
  for (std::size_t i = 0; i < r.disagreement_pivot_mm.size(); ++i) {
    s << "  methods disagree on pivot " << i << " by " << r.disagreement_pivot_mm[i] << " mm\n";
  }
  for (const GravityErrors& g : r.gravity) {
    s << "  gravity from " << g.rolls << " rolls (" << g.sets << " sets): median error " << g.median_abs_error_pct
      << " %, max " << g.max_abs_error_pct << " %, 95% interval half-width " << g.median_half_width_pct
      << " %, coverage " << g.coverage << ", rolls rejected " << g.outliers_rejected << "\n";
  }
  for (const TrackerEffect& t : r.tracker) {
    s << "  tracker, " << t.geometry << " geometry: impact point median " << t.median_impact_mm << " mm, p90 "
      << t.p90_impact_mm << " mm, |dt| " << t.median_dt_ms << " ms, |dh| " << t.median_abs_dh << ", valid "
      << t.valid_fraction << " (" << t.observations << " observations >= 5 cm)\n";
  }
  s << "  " << (r.flippers_met && r.gravity_met ? "targets met" : "TARGETS MISSED") << " (" << r.wall_s << " s)\n";
  return s.str();
}

}  // namespace pinball::bench
