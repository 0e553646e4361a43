#pragma once
// `pinball bench tracker`: how well the ball tracker (thesis Ch. 4) predicts
// the impact on the flippers' 'V', against the simulator's truth, for a grid
// of camera settings and a miscalibrated g, with two baselines measured on the
// same observations (a two-point parabola and a fit with g free), and what one
// observation update costs as a function of the fit window.
//
// Ground truth: the oracle spastic player plays the board on the thesis
// stepper at a small dt; each free-flight segment that enters the critical
// area gives at most one approach, its true state (p, v) at that instant. From
// there the truth is the exact parabola p + v·t − (0, g·t²/2) with the board's
// g, projected analytically; only parabolas that reach a hittable point of the
// 'V' without touching any obstacle and start far enough from it are kept.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"
#include "pinball/track/camera_model.h"
#include "pinball/track/projection.h"

namespace pinball::bench {

/// Edges of the bins of true remaining distance to impact (m): 0–2, 2–5,
/// 5–10, 10–20 and 20+ cm.
inline constexpr std::array<double, 5> kTrackerDistanceBinStart_m{0.0, 0.02, 0.05, 0.10, 0.20};
/// Number of distance bins.
inline constexpr std::size_t kTrackerDistanceBins = kTrackerDistanceBinStart_m.size();
/// The headline figures pool the bins at or beyond this true distance (m).
inline constexpr double kTrackerHeadlineDistance_m = 0.05;

/// Targets from the issue, for the headline camera (200 fps, 2 mm/px, 0.3 px, true g, >= 5 cm).
inline constexpr double kTargetMedianAbsDh = 0.03;         ///< flipper lengths
inline constexpr double kTargetMedianAbsDtImpact_ms = 2.0;  ///< ms
inline constexpr double kTargetMedianUpdate_us = 5.0;       ///< µs per Tracker::update, one core

/// What to measure.
struct TrackerBenchOptions {
  int approaches = 2000;              ///< free-flight approaches to collect
  std::uint64_t seed = 1;             ///< game seed (launch noise) and camera noise seeds
  double sim_dt_s = 1e-4;             ///< thesis stepper step used to find approaches (s)
  double sample_dt_s = 5e-4;          ///< the camera is fed the exact parabola at this step (s)
  double min_start_distance_m = 0.15; ///< an approach starts at least this far from its impact (m)
  double min_speed_mps = 0.1;         ///< a ball slower than this is not an approach
  double max_simulated_s = 40000.0;   ///< give up collecting after this much simulated play (s)
  std::vector<double> fps{100.0, 200.0, 500.0};       ///< camera grid: frame rates
  std::vector<double> m_per_px{0.001, 0.002, 0.004};  ///< camera grid: resolutions (m/px)
  std::vector<double> noise_px{0.0, 0.3, 1.0};        ///< camera grid: centroid noise (px)
  track::CameraModelConfig headline_camera{200.0, 0.002, 0.3, 0.0, 0.0};  ///< the target camera
  std::vector<double> g_factors{0.5, 0.9, 1.1, 1.5};  ///< calibrated g / true g, on the headline camera
  std::vector<int> cost_windows{4, 8, 16, 32, 64};    ///< window caps for the cost sweep
  int cost_passes = 3;                                ///< timed passes over all approaches per cost point (pooled)
};

/// A short run: 100 approaches, the headline camera only, g true, two window caps, one timed pass.
TrackerBenchOptions quick_tracker_bench_options();

/// One ground-truth approach: the exact parabola from (p0, v0) at t = 0.
struct TrackerApproach {
  Vec2 p0 = Vec2::Zero();             ///< true ball centre at the start (m)
  Vec2 v0 = Vec2::Zero();             ///< true velocity at the start (m/s)
  double g_mps2 = 0.0;                ///< true gravity along −y (m/s²)
  double start_time_s = 0.0;          ///< simulated game time at which the stepper's ball was here (s)
  track::TrajectoryProjection truth;  ///< exact projection from t = 0 (t_impact_s: time of impact, s)
};

/// Why evaluated free-flight segments were not kept.
struct ApproachCounts {
  std::size_t segments = 0;       ///< free-flight segments evaluated in the critical area
  std::size_t kept = 0;           ///< approaches kept
  std::size_t no_impact = 0;      ///< exact parabola never meets the 'V' (or not hittably)
  std::size_t too_short = 0;      ///< starts closer than min_start_distance_m to its impact
  std::size_t obstacle = 0;       ///< touches an obstacle, a hole or leaves the 'V' side before impact
  double simulated_s = 0.0;       ///< simulated play it took (s)
};

/// Plays the board and collects up to options.approaches approaches, in
/// game order (deterministic by options.seed).
std::vector<TrackerApproach> collect_tracker_approaches(const table::Board& board, const TrackerBenchOptions& options,
                                                        ApproachCounts* counts = nullptr);

/// One projection judged against an approach's truth (t = 0 at the approach's start).
struct ProjectionError {
  bool valid = false;            ///< the predictor gave a projection
  bool wrong_flipper = false;    ///< onto the other flipper than the truth
  double abs_dh = 0.0;           ///< |Δh| in flipper lengths, along the 'V' (through the apex when the flipper is wrong)
  double abs_dt_impact_s = 0.0;  ///< |predicted − true time of impact| (s)
  double abs_ds_mps = 0.0;       ///< |Δs_impact| (m/s)
  double abs_dtheta_deg = 0.0;   ///< |Δθ_impact| (degrees, modulo 180)
};

/// The error of projection `p` (made at p.t_observation_s) against approach `a`'s truth.
ProjectionError projection_error(const track::TrajectoryProjection& p, const TrackerApproach& a,
                                 const track::FlipperGeometry& geometry);

/// Distance (m) from the ball at time t_s of approach `a` to its true impact point.
double remaining_distance(const TrackerApproach& a, double t_s);

/// Median and 90th percentile of one error over the observations that had a projection.
struct ErrorStats {
  std::size_t count = 0;  ///< samples
  double median = 0.0;    ///< 0 when count == 0
  double p90 = 0.0;       ///< 0 when count == 0
};

/// Errors of one predictor in one distance bin (or pooled).
struct BinErrors {
  std::size_t observations = 0;   ///< observations whose true distance falls here
  std::size_t valid = 0;          ///< of them, with a valid projection
  double valid_fraction = 0.0;    ///< valid / observations
  std::size_t wrong_flipper = 0;  ///< valid projections onto the other flipper than the truth
  ErrorStats abs_dh;              ///< |Δh| in flipper lengths, measured along the 'V' (through the apex when the flipper is wrong)
  ErrorStats abs_dt_impact_ms;    ///< |predicted − true time of impact| (ms)
  ErrorStats abs_ds_mps;          ///< |Δs_impact| (m/s)
  ErrorStats abs_dtheta_deg;      ///< |Δθ_impact| (degrees, modulo 180)
};

/// One predictor on one camera setting.
struct MethodErrors {
  std::string method;                                ///< "tracker", "two_point" or "free_g"
  std::array<BinErrors, kTrackerDistanceBins> bins;  ///< by true distance to impact
  BinErrors beyond_headline;                         ///< the bins at >= kTrackerHeadlineDistance_m pooled
};

/// One camera setting (and calibrated g).
struct TrackerSetting {
  track::CameraModelConfig camera;    ///< the camera
  double g_factor = 1.0;              ///< calibrated g / true g given to the predictors
  double sigma_m = 0.0;               ///< σ the tracker assumes (quantisation and noise)
  std::size_t observations = 0;       ///< observations over all approaches
  std::size_t tracker_flushes = 0;    ///< χ² flushes of the tracker (all false alarms: the truth is free flight)
  std::vector<MethodErrors> methods;  ///< tracker, two_point, free_g
};

/// One point of the cost sweep: Tracker::update timed call by call.
struct TrackerCostPoint {
  std::string name;                     ///< "window_<N>" or "default"
  int max_window = 0;                   ///< window cap
  double window_distance_m = 0.0;       ///< window rule distance d (huge: the cap decides)
  std::size_t updates = 0;              ///< timed updates (all passes)
  double median_us = 0.0;               ///< median time per update (µs)
  double p99_us = 0.0;                  ///< 99th percentile (µs)
  double mean_window = 0.0;             ///< mean points in the fit over the timed updates that fitted
  std::size_t full_window_updates = 0;  ///< updates whose fit used exactly max_window points
  double median_us_full_window = 0.0;   ///< median time of those (µs)
  double median_abs_dh = 0.0;           ///< median |Δh| at >= 5 cm on the headline camera (flipper lengths)
  double median_abs_dt_impact_ms = 0.0; ///< median |Δt_impact| at >= 5 cm (ms)
  double valid_fraction = 0.0;          ///< observations at >= 5 cm with a valid projection
};

/// The figures the issue sets targets for.
struct TrackerHeadline {
  bool present = false;                    ///< the headline camera with true g was measured (with valid projections)
  double tracker_abs_dh = 0.0;             ///< median |Δh| (flipper lengths), >= 5 cm
  double tracker_abs_dt_impact_ms = 0.0;   ///< median |Δt_impact| (ms), >= 5 cm
  double two_point_abs_dh = 0.0;           ///< the same for the two-point baseline
  double two_point_abs_dt_impact_ms = 0.0;
  double free_g_abs_dh = 0.0;              ///< the same for the g-free fit baseline
  double free_g_abs_dt_impact_ms = 0.0;
  bool has_cost = false;                   ///< the default configuration's cost was measured
  double update_median_us = 0.0;           ///< default tracker, median µs per update
  bool dh_met = false;                     ///< tracker_abs_dh <= kTargetMedianAbsDh
  bool dt_met = false;                     ///< tracker_abs_dt_impact_ms <= kTargetMedianAbsDtImpact_ms
  bool cost_met = false;                   ///< update_median_us <= kTargetMedianUpdate_us
  bool all_met = false;                    ///< all three
};

/// The whole measurement.
struct TrackerReport {
  std::string board;                      ///< board file
  double true_g_mps2 = 0.0;               ///< the board's g (m/s²)
  double flipper_length_m = 0.0;          ///< mean flipper length: the unit of h (m)
  TrackerBenchOptions options;            ///< what was asked
  ApproachCounts approach_counts;         ///< how the approaches were found
  std::size_t approaches = 0;             ///< approaches used
  double median_start_distance_m = 0.0;   ///< median distance from start to impact (m)
  double median_approach_time_s = 0.0;    ///< median time from start to impact (s)
  double median_impact_speed_mps = 0.0;   ///< median true s_impact (m/s)
  std::vector<TrackerSetting> settings;   ///< camera grid (g true), then g miscalibrated on the headline camera
  std::vector<TrackerCostPoint> cost;     ///< window caps, then "default"
  double timer_overhead_ns = 0.0;         ///< median of two back-to-back steady_clock reads (ns; included in costs)
  TrackerHeadline headline;               ///< the targets
  double wall_s = 0.0;                    ///< wall time of the whole run (s)
};

/// Runs the measurement; `progress` (may be empty) receives one line after
/// the approaches are collected, one per camera setting and one per cost point.
TrackerReport run_tracker_bench(const table::Board& board, const TrackerBenchOptions& options,
                                const std::function<void(const std::string&)>& progress);

/// Whether two cameras have the same frame rate, resolution and noise (finds the headline setting).
bool same_camera(const track::CameraModelConfig& a, const track::CameraModelConfig& b);

/// A setting as the progress lines and the text name it: "200 fps, 2 mm/px, 0.3 px, g x1".
std::string camera_label(const track::CameraModelConfig& c, double g_factor);

// The report (tracker_bench_report.cpp).

/// The report as one JSON object.
nlohmann::json to_json(const TrackerReport& report);

/// The report as a compact text table.
std::string to_text(const TrackerReport& report);

}  // namespace pinball::bench
