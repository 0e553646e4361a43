#pragma once
// `pinball bench calibration`: how well the calibration routines recover a
// simulated lab machine whose truth is known (calibration/sim_lab.h): the
// camera homography from markers in a rendered frame (default camera:
// perspective, noise, anti-aliasing), each flipper's pivot, tip and stops by
// both methods, gravity from 3, 5 and 10 rolls (many independent sets), and
// what the calibrated geometry does to the tracker's projections against the
// true geometry on the same observations.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/table/board.h"

namespace pinball::bench {

/// Targets from the issue.
inline constexpr double kTargetPivotTipError_m = 0.001;   ///< pivot and tip within 1 mm
inline constexpr double kTargetThetaError_deg = 0.5;      ///< θ limits within 0.5°
inline constexpr double kTargetGravityError = 0.01;       ///< gravity within 1 % from 5 rolls

/// What to measure.
struct CalibrationBenchOptions {
  std::uint64_t seed = 1;            ///< lab seed (camera art and noise, rolls)
  int gravity_sets = 40;             ///< independent roll sets per roll count
  std::vector<int> roll_counts{3, 5, 10};  ///< rolls per set
  int approaches = 300;              ///< tracker approaches for the effect on projections
};

/// One flipper by one method, against the truth.
struct FlipperErrors {
  std::string flipper;          ///< name
  std::string method;           ///< markers | markerless
  double pivot_mm = 0.0;        ///< |pivot − true pivot|
  double tip_mm = 0.0;          ///< |tip − true tip| (down)
  double length_mm = 0.0;       ///< length − true length
  double theta_min_deg = 0.0;   ///< θ_min − true θ_min
  double theta_max_deg = 0.0;   ///< θ_max − true θ_max
  int points = 0;               ///< markers or tip points behind it
  bool met = false;             ///< pivot, tip within 1 mm and both θ within 0.5°
};

/// Gravity from sets of n rolls.
struct GravityErrors {
  int rolls = 0;                     ///< n
  int sets = 0;                      ///< independent sets
  double median_abs_error_pct = 0.0; ///< median |ĝ − g_true| / g_true (%)
  double max_abs_error_pct = 0.0;    ///< largest over the sets (%)
  double coverage = 0.0;             ///< fraction of sets whose interval holds the truth
  double median_half_width_pct = 0.0;///< median interval half-width (% of g)
  int outliers_rejected = 0;         ///< rolls rejected over all sets
  bool met = false;                  ///< max error within 1 % (checked for n = 5)
};

/// The tracker with some geometry and g, against the truth.
struct TrackerEffect {
  std::string geometry;              ///< "true", "markers", "markerless"
  std::size_t observations = 0;      ///< observations at >= 5 cm from impact
  double valid_fraction = 0.0;       ///< with a valid projection
  double median_impact_mm = 0.0;     ///< median |predicted − true impact point| (mm)
  double p90_impact_mm = 0.0;        ///< 90th percentile (mm)
  double median_dt_ms = 0.0;         ///< median |Δt_impact| (ms)
  double median_abs_dh = 0.0;        ///< median |Δh| in the true geometry's flipper lengths
};

/// The whole measurement.
struct CalibrationReport {
  std::string board;                      ///< board file
  CalibrationBenchOptions options;        ///< what was asked
  double true_g_mps2 = 0.0;               ///< the machine's g
  int markers_detected = 0;               ///< camera calibration: marker candidates
  int markers_used = 0;                   ///< ... matched and kept
  double reprojection_rms_px = 0.0;       ///< detected vs reprojected markers
  double homography_max_error_mm = 0.0;   ///< largest board error of the fitted homography over the table (mm)
  double homography_rms_error_mm = 0.0;   ///< RMS over a grid on the table (mm)
  std::vector<FlipperErrors> flippers;    ///< every flipper by both methods
  std::vector<double> disagreement_pivot_mm;  ///< per flipper: |markers − markerless| pivot (mm)
  std::vector<GravityErrors> gravity;     ///< per roll count
  std::vector<TrackerEffect> tracker;     ///< true, markers, markerless
  bool flippers_met = false;              ///< every flipper, both methods
  bool gravity_met = false;               ///< the 5-roll sets
  double wall_s = 0.0;                    ///< wall time (s)
};

/// Runs the measurement; `progress` (may be empty) gets a line per stage.
CalibrationReport run_calibration_bench(const table::Board& board, const CalibrationBenchOptions& options,
                                        const std::function<void(const std::string&)>& progress);

// The report (calibration_bench_report.cpp).

/// The report as one JSON object.
nlohmann::json to_json(const CalibrationReport& report);

/// The report as text.
std::string to_text(const CalibrationReport& report);

}  // namespace pinball::bench
