#pragma once
// `pinball bench precision`: position error against run time for the thesis
// stepper (a sweep of dt) and the event stepper (a sweep of its relative
// tolerance), on scenes with closed-form answers and on the full table
// against a tight event-stepper reference. Output: a report (JSON, CSV,
// Markdown) and a log-log plot of error against run time.

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/table/board.h"

namespace pinball::bench {

/// Errors below this (the rounding unit of a coordinate of tens of metres) are
/// counted as this in ratios and on the plot, whose axes are logarithmic (m).
inline constexpr double kPrecisionErrorFloor_m = 1e-15;

/// What to measure.
struct PrecisionBenchOptions {
  std::vector<double> thesis_dt_s;           ///< thesis stepper time steps (s)
  std::vector<double> event_tolerances;      ///< event stepper relative tolerances
  double horizon_s = 10.0;                   ///< simulated time of each closed-form scene (s)
  double event_step_s = 1e-3;                ///< event stepper step horizon (s): where errors are sampled
  double event_rest_height_m = 1e-12;        ///< event stepper rest threshold (below every error of interest)
  double table_horizon_s = 0.5;              ///< simulated time on the full table (s)
  double table_reference_tolerance = 1e-14;  ///< the table's reference: event stepper at this tolerance
  double table_reference_step_s = 1e-4;      ///< ... sampled every this many seconds
  double table_pull = 0.9;                   ///< launcher pull of the table scene's fixed launch
  std::uint64_t table_seed = 7;              ///< launch noise seed of the table scene
  int repeats = 3;                           ///< timed runs after one warm-up; the minimum is reported
  bool with_event = true;                    ///< false: thesis stepper only
};

/// The full measurement: dt 1e-2 .. 1e-6 s in 1-2-5 steps, tolerances 1e-6 .. 1e-14.
PrecisionBenchOptions default_precision_bench_options();

/// A short run for tests (< 5 s): three dt, three tolerances, one repeat.
PrecisionBenchOptions quick_precision_bench_options();

/// One stepper setting on one scene.
struct PrecisionPoint {
  std::string scene;          ///< free_flight, bounce_to_rest, incline_slide, elastic_box, circle_bounce, table
  std::string stepper;        ///< thesis | event
  double setting = 0.0;       ///< dt (s) for the thesis stepper, relative tolerance for the event stepper
  double max_error_m = 0.0;   ///< largest position error over every sampled step end
  double final_error_m = 0.0; ///< position error at the end of the run
  double run_time_s = 0.0;    ///< minimum wall time of the timed runs (stepping only)
  std::uint64_t steps = 0;    ///< step() calls per run
  std::uint64_t events = 0;   ///< GameState::events after the run (event stepper)
};

/// The event stepper against the thesis curve of the same scene at one tolerance.
struct PrecisionComparison {
  std::string scene;              ///< scene name
  double tolerance = 0.0;         ///< event stepper's relative tolerance
  double event_error_m = 0.0;     ///< its max error
  double event_time_s = 0.0;      ///< its run time
  double error_ratio = 0.0;       ///< thesis error at the event's run time / event error
  double speedup = 0.0;           ///< thesis run time at the event's error / event run time
  bool error_ratio_extrapolated = false;  ///< the event run time lies outside the thesis curve's range
  bool speedup_extrapolated = false;      ///< the event error lies outside the thesis curve's range
  double thesis_fit_exponent = 0.0;  ///< p in thesis error ∝ run time^p (least squares, log-log): extrapolation
  double thesis_best_error_m = 0.0;  ///< smallest thesis error measured on the scene
  double thesis_best_time_s = 0.0;   ///< ... and its run time
  double best_speedup = 0.0;         ///< thesis_best_time_s / event run time: measured, no extrapolation
};

/// The targets at the event stepper's default tolerance, over every
/// scene compared (the closed-form ones, and the table for the two ratios).
struct PrecisionTargets {
  bool evaluated = false;                ///< false when the default tolerance was not in the sweep
  double tolerance = 0.0;                ///< the event stepper's default relative tolerance
  double worst_closed_form_error_m = 0.0;  ///< largest event max error over the closed-form scenes (target <= 1e-9)
  std::string worst_scene;               ///< where it was
  double min_error_ratio = 0.0;          ///< smallest error ratio at equal run time (target >= 1000)
  double min_best_speedup = 0.0;         ///< smallest measured speed-up over the thesis's best (target >= 100)
  double min_fit_speedup = 0.0;          ///< smallest speed-up at equal error (power-law extrapolation)
};

/// The whole measurement.
struct PrecisionReport {
  PrecisionBenchOptions options;                 ///< what was run
  std::vector<PrecisionPoint> points;            ///< every (scene, stepper, setting)
  std::vector<PrecisionComparison> comparisons;  ///< every (scene, event tolerance), closed-form scenes and table
  PrecisionTargets targets;                      ///< the targets at the default tolerance
};

/// Names of the scenes with closed-form answers, in report order.
const std::vector<std::string>& closed_form_scenes();

/// The board of a closed-form scene (exposed for tests).
table::Board precision_scene_board(const std::string& scene);

/// The closed-form ball position of a scene at time t_s (exposed for tests).
Vec2 precision_scene_exact(const std::string& scene, double t_s);

/// Runs the measurement on the closed-form scenes and on `table` (skipped when
/// table.source is empty). `progress` (may be empty) receives one line per scene.
PrecisionReport run_precision_bench(const table::Board& table, const PrecisionBenchOptions& options,
                                    const std::function<void(const std::string&)>& progress);

/// log-log interpolation of y(x) through points sorted by x; outside the
/// range, the nearest end segment is extended. Sets `extrapolated` then.
/// (The report extrapolates with loglog_fit instead: end segments are noisy.)
double loglog_interpolate(const std::vector<std::pair<double, double>>& xy, double x, bool& extrapolated);

/// Least-squares line through (log x, log y): y ≈ exp(intercept)·x^slope.
struct LogLogFit {
  double intercept = 0.0;  ///< ln y at x = 1
  double slope = 0.0;      ///< exponent
};
LogLogFit loglog_fit(const std::vector<std::pair<double, double>>& xy);

// The report (precision_bench_report.cpp).

/// The report as one JSON object.
nlohmann::json to_json(const PrecisionReport& report);

/// CSV: scene,stepper,setting,max_error_m,final_error_m,run_time_s.
std::string to_csv(const PrecisionReport& report);

/// Markdown tables for docs/results.md: errors and run times, then the comparisons.
std::string to_markdown(const PrecisionReport& report);

/// Error against run time, log-log, one panel per scene. Throws std::runtime_error if it cannot write.
void plot_precision_png(const PrecisionReport& report, const std::string& path);

}  // namespace pinball::bench
