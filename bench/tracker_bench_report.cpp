// The tracker bench's report, JSON and text (the measurement: tracker_bench.cpp).
#include "tracker_bench.h"

#include <iomanip>
#include <sstream>

namespace pinball::bench {
namespace {

std::string bin_label(std::size_t b) {
  std::ostringstream s;
  s << kTrackerDistanceBinStart_m[b] * 100.0;
  if (b + 1 < kTrackerDistanceBins) {
    s << "-" << kTrackerDistanceBinStart_m[b + 1] * 100.0;
  } else {
    s << "+";
  }
  s << " cm";
  return s.str();
}

nlohmann::json stats_json(const ErrorStats& s) { return {{"count", s.count}, {"median", s.median}, {"p90", s.p90}}; }

nlohmann::json bin_json(const BinErrors& b) {
  return {{"observations", b.observations},
          {"valid", b.valid},
          {"valid_fraction", b.valid_fraction},
          {"wrong_flipper", b.wrong_flipper},
          {"abs_dh", stats_json(b.abs_dh)},
          {"abs_dt_impact_ms", stats_json(b.abs_dt_impact_ms)},
          {"abs_ds_mps", stats_json(b.abs_ds_mps)},
          {"abs_dtheta_deg", stats_json(b.abs_dtheta_deg)}};
}

nlohmann::json camera_json(const track::CameraModelConfig& c) {
  return {{"fps", c.fps}, {"m_per_px", c.m_per_px}, {"noise_px", c.noise_px}};
}

}  // namespace

nlohmann::json to_json(const TrackerReport& r) {
  nlohmann::json bins = nlohmann::json::array();
  for (std::size_t b = 0; b < kTrackerDistanceBins; ++b) {
    nlohmann::json hi = b + 1 < kTrackerDistanceBins ? nlohmann::json(kTrackerDistanceBinStart_m[b + 1])
                                                     : nlohmann::json(nullptr);
    bins.push_back({{"from_m", kTrackerDistanceBinStart_m[b]}, {"to_m", hi}});
  }
  nlohmann::json settings = nlohmann::json::array();
  for (const TrackerSetting& s : r.settings) {
    nlohmann::json methods = nlohmann::json::object();
    for (const MethodErrors& m : s.methods) {
      nlohmann::json mb = nlohmann::json::array();
      for (const BinErrors& b : m.bins) mb.push_back(bin_json(b));
      methods[m.method] = {{"bins", mb}, {"beyond_5cm", bin_json(m.beyond_headline)}};
    }
    settings.push_back({{"camera", camera_json(s.camera)},
                        {"g_factor", s.g_factor},
                        {"sigma_m", s.sigma_m},
                        {"observations", s.observations},
                        {"tracker_flushes", s.tracker_flushes},
                        {"methods", methods}});
  }
  nlohmann::json cost = nlohmann::json::array();
  for (const TrackerCostPoint& p : r.cost) {
    cost.push_back({{"name", p.name},
                    {"max_window", p.max_window},
                    {"window_distance_m", p.window_distance_m},
                    {"updates", p.updates},
                    {"median_us", p.median_us},
                    {"p99_us", p.p99_us},
                    {"mean_window", p.mean_window},
                    {"full_window_updates", p.full_window_updates},
                    {"median_us_full_window", p.median_us_full_window},
                    {"median_abs_dh_beyond_5cm", p.median_abs_dh},
                    {"median_abs_dt_impact_ms_beyond_5cm", p.median_abs_dt_impact_ms},
                    {"valid_fraction_beyond_5cm", p.valid_fraction}});
  }
  const ApproachCounts& c = r.approach_counts;
  const TrackerHeadline& h = r.headline;
  const TrackerBenchOptions& o = r.options;
  return {{"benchmark", "tracker"},
          {"board", r.board},
          {"true_g_mps2", r.true_g_mps2},
          {"flipper_length_m", r.flipper_length_m},
          {"options",
           {{"approaches", o.approaches},
            {"seed", o.seed},
            {"sim_dt_s", o.sim_dt_s},
            {"sample_dt_s", o.sample_dt_s},
            {"min_start_distance_m", o.min_start_distance_m},
            {"min_speed_mps", o.min_speed_mps},
            {"headline_camera", camera_json(o.headline_camera)},
            {"g_factors", o.g_factors},
            {"cost_windows", o.cost_windows},
            {"cost_passes", o.cost_passes}}},
          {"approaches",
           {{"count", r.approaches},
            {"segments_evaluated", c.segments},
            {"rejected_no_impact", c.no_impact},
            {"rejected_too_short", c.too_short},
            {"rejected_obstacle", c.obstacle},
            {"simulated_s", c.simulated_s},
            {"median_start_distance_m", r.median_start_distance_m},
            {"median_approach_time_s", r.median_approach_time_s},
            {"median_impact_speed_mps", r.median_impact_speed_mps}}},
          {"distance_bins", bins},
          {"settings", settings},
          {"cost", cost},
          {"timer_overhead_ns", r.timer_overhead_ns},
          {"headline",
           {{"present", h.present},
            {"camera", camera_json(o.headline_camera)},
            {"min_distance_m", kTrackerHeadlineDistance_m},
            {"tracker", {{"median_abs_dh", h.tracker_abs_dh}, {"median_abs_dt_impact_ms", h.tracker_abs_dt_impact_ms}}},
            {"two_point",
             {{"median_abs_dh", h.two_point_abs_dh}, {"median_abs_dt_impact_ms", h.two_point_abs_dt_impact_ms}}},
            {"free_g", {{"median_abs_dh", h.free_g_abs_dh}, {"median_abs_dt_impact_ms", h.free_g_abs_dt_impact_ms}}},
            {"update_median_us", h.update_median_us}}},
          {"targets",
           {{"median_abs_dh", kTargetMedianAbsDh},
            {"median_abs_dt_impact_ms", kTargetMedianAbsDtImpact_ms},
            {"update_median_us", kTargetMedianUpdate_us},
            {"dh_met", h.dh_met},
            {"dt_met", h.dt_met},
            {"cost_met", h.cost_met},
            {"all_met", h.all_met}}},
          {"wall_s", r.wall_s}};
}

std::string to_text(const TrackerReport& r) {
  std::ostringstream out;
  const ApproachCounts& c = r.approach_counts;
  out << std::fixed;
  out << "tracker on " << r.board << ": " << r.approaches << " free-flight approaches (" << c.segments
      << " segments evaluated, " << std::setprecision(0) << c.simulated_s << " s of play at dt "
      << std::setprecision(4) << r.options.sim_dt_s << " s), median start " << std::setprecision(1)
      << r.median_start_distance_m * 100.0 << " cm / " << std::setprecision(0) << r.median_approach_time_s * 1e3
      << " ms before impact\n";
  out << "errors at >= 5 cm before impact, medians (h in flipper lengths of " << std::setprecision(1)
      << r.flipper_length_m * 1e3 << " mm; valid = share of observations with a projection)\n";
  out << "   fps  mm/px  noise    g |  tracker |dh| |dt|ms valid |  2-point |dh| |dt|ms valid |   free-g |dh| |dt|ms "
         "valid\n";
  for (const TrackerSetting& s : r.settings) {
    out << std::setprecision(0) << std::setw(6) << s.camera.fps << std::setprecision(1) << std::setw(7)
        << s.camera.m_per_px * 1e3 << std::setw(7) << s.camera.noise_px << std::setprecision(2) << std::setw(5)
        << s.g_factor << " |";
    for (const MethodErrors& m : s.methods) {
      const BinErrors& b = m.beyond_headline;
      out << std::setprecision(4) << std::setw(14) << b.abs_dh.median << std::setprecision(2) << std::setw(7)
          << b.abs_dt_impact_ms.median << std::setw(6) << b.valid_fraction << " |";
    }
    out << "\n";
  }
  for (const TrackerSetting& s : r.settings) {
    if (s.g_factor != 1.0 || !same_camera(s.camera, r.options.headline_camera)) continue;
    out << "by true distance to impact, " << camera_label(s.camera, s.g_factor) << " (median |dh|, |dt| ms, |ds| m/s, "
        << "|dtheta| deg, valid)\n";
    for (const MethodErrors& m : s.methods) {
      out << "  " << std::setw(9) << m.method;
      for (std::size_t b = 0; b < kTrackerDistanceBins; ++b) {
        const BinErrors& e = m.bins[b];
        out << " | " << bin_label(b) << " " << std::setprecision(3) << e.abs_dh.median << " " << std::setprecision(2)
            << e.abs_dt_impact_ms.median << " " << e.abs_ds_mps.median << " " << std::setprecision(1)
            << e.abs_dtheta_deg.median << " " << std::setprecision(2) << e.valid_fraction;
      }
      out << "\n";
    }
    break;
  }
  out << "cost per Tracker::update on the headline camera (timer overhead " << std::setprecision(0)
      << r.timer_overhead_ns << " ns included)\n";
  for (const TrackerCostPoint& p : r.cost) {
    out << "  " << std::setw(10) << p.name << ": median " << std::setprecision(2) << p.median_us << " us, p99 "
        << p.p99_us << " us, full window " << p.median_us_full_window << " us (" << p.full_window_updates
        << "), mean window " << std::setprecision(1) << p.mean_window << ", |dh| " << std::setprecision(4)
        << p.median_abs_dh << ", |dt| " << std::setprecision(2) << p.median_abs_dt_impact_ms << " ms\n";
  }
  const TrackerHeadline& h = r.headline;
  if (h.present) {
    out << "headline (" << camera_label(r.options.headline_camera, 1.0) << ", >= 5 cm): median |dh| tracker "
        << std::setprecision(4) << h.tracker_abs_dh << " (target <= " << kTargetMedianAbsDh << ", "
        << (h.dh_met ? "met" : "NOT met") << "), two-point " << h.two_point_abs_dh << ", free-g " << h.free_g_abs_dh
        << "; median |dt_impact| tracker " << std::setprecision(2) << h.tracker_abs_dt_impact_ms << " ms (target <= "
        << kTargetMedianAbsDtImpact_ms << ", " << (h.dt_met ? "met" : "NOT met") << "), two-point "
        << h.two_point_abs_dt_impact_ms << " ms, free-g " << h.free_g_abs_dt_impact_ms << " ms\n";
  } else {
    out << "headline camera not among the settings: no accuracy targets checked\n";
  }
  out << "update cost, default tracker: median " << std::setprecision(2) << h.update_median_us << " us (target <= "
      << kTargetMedianUpdate_us << ", " << (h.cost_met ? "met" : "NOT met") << ")\n";
  out << "all targets met: " << (h.all_met ? "yes" : "no") << "; wall time " << std::setprecision(1) << r.wall_s
      << " s\n";
  return out.str();
}

}  // namespace pinball::bench
