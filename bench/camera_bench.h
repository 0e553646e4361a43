#pragma once
// `pinball bench camera`: what a real camera's faults cost the detector and
// the tracker, and what the corrections win back. One run renders the same
// ball motions through the simulated camera (simlab::SimCameraSource) with
// one fault at a time (lens distortion, rolling shutter, latency and jitter,
// flicker and gain drift) and then all together, each seen by a detector
// without and with the correction (undistorted centroid, the ball row's
// exposure time, the latency subtracted), beside the ideal camera.
//
// The truth is the ball's true position at its true exposure time. An
// observation (t, p) is judged by the distance from p to where the ball was
// at the time t it claims, so a wrong time stamp counts as much as a wrong
// place; the time error itself is reported apart.
//  - Detector: a ball crossing the table in straight lines at 1, 3 and 5 m/s.
//  - Tracker: the free-flight approaches of `pinball bench tracker`, rendered
//    frame by frame and detected; |Δh| and |Δt_impact| pooled beyond 5 cm.
//  - Cost: detector frames per second on one core, ROI search, with and
//    without every correction.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "detector_bench.h"
#include "pinball/calibration/intrinsics_calibration.h"
#include "pinball/simlab/sim_camera_source.h"
#include "pinball/table/board.h"
#include "pinball/vision/lens_model.h"

namespace pinball::bench {

/// Corrected errors must stay within this fraction above the ideal camera's.
inline constexpr double kTargetCorrectedWithinFraction = 0.10;

/// What to measure.
struct CameraBenchOptions {
  std::uint64_t seed = 1;                           ///< motion, camera and approach seed
  std::vector<double> speeds_mps{1.0, 3.0, 5.0};    ///< detector: ball speeds
  int frames_per_speed = 400;                       ///< detector: frames scored per speed and scenario
  int approaches = 150;                             ///< tracker: free-flight approaches per scenario
  int background_frames = 32;                       ///< ball-free frames the background is learned from
  int timing_frames = 300;                          ///< cost: frames timed per pass
  simlab::SimCameraRealism camera = simlab::SimCameraRealism::typical();  ///< the faults, as a typical camera has them
  std::optional<vision::CameraIntrinsics> calibrated_lens;  ///< from `calibrate intrinsics`: adds scenarios
  std::string calibrated_lens_source;               ///< how it was obtained (for the report)
  std::optional<double> measured_latency_s;         ///< from `calibrate latency`: adds scenarios
  std::string measured_latency_source;              ///< how it was obtained (for the report)
};

/// A short run for tests.
CameraBenchOptions quick_camera_bench_options();

/// One camera fault and the detector's answer to it.
struct CameraScenario {
  std::string name;                    ///< "ideal", "distortion_uncorrected", ...
  simlab::SimCameraRealism camera;     ///< the faults rendered
  vision::BallDetectorConfig corrections;  ///< lens, latency_s, row_time_s given to the detector (rest default)
  bool corrected = false;              ///< the detector corrects the faults it is given
};

/// The scenarios of one run, in report order.
std::vector<CameraScenario> camera_scenarios(const CameraBenchOptions& options);

/// Detector errors at one speed.
struct CameraDetectorFigures {
  double speed_mps = 0.0;        ///< ball speed
  std::size_t frames = 0;        ///< frames with the ball whole, unhidden, in view
  std::size_t detected = 0;      ///< of them, with an observation
  ErrorSummary error_mm;         ///< |p − p_true(t claimed)| (mm)
  ErrorSummary error_px;         ///< the same in the ideal image (px)
  ErrorSummary position_mm;      ///< |p − p_true(t true)|: the place alone (mm)
  double median_abs_dt_ms = 0.0; ///< median |t claimed − t true| (ms)
  double mean_dt_ms = 0.0;       ///< mean signed t claimed − t true (ms)
};

/// Tracker errors on the approaches.
struct CameraTrackerFigures {
  std::size_t approaches = 0;         ///< approaches played
  std::size_t observations = 0;       ///< observations at >= 5 cm from impact
  double valid_fraction = 0.0;        ///< of them, with a projection
  double median_abs_dh = 0.0;         ///< median |Δh| (flipper lengths)
  double median_abs_dt_impact_ms = 0.0;  ///< median |Δt_impact| (ms)
};

/// One scenario's figures.
struct CameraScenarioResult {
  CameraScenario scenario;                      ///< what was rendered and corrected
  std::vector<CameraDetectorFigures> detector;  ///< per speed
  CameraTrackerFigures tracker;                 ///< approaches
  double pooled_median_error_mm = 0.0;          ///< detector, all speeds pooled
  double ratio_to_ideal = 0.0;                  ///< pooled_median_error_mm / the ideal's (detector)
  double tracker_dh_ratio_to_ideal = 0.0;       ///< median |Δh| / the ideal's
  double tracker_dt_ratio_to_ideal = 0.0;       ///< median |Δt_impact| / the ideal's
  bool within_target = false;                   ///< corrected: all three ratios <= 1 + kTargetCorrectedWithinFraction
};

/// The lens a calibration recovered, against the true one.
struct CalibratedLensFigures {
  bool present = false;                   ///< a calibrated lens was given
  std::string source;                     ///< how it was obtained
  vision::CameraIntrinsics truth;         ///< the simulated camera's lens
  vision::CameraIntrinsics calibrated;    ///< the calibration's
  calibration::LensComparison comparison; ///< focal lengths, principal point, distortion against the truth
};

/// Detector cost per frame with and without the corrections.
struct CameraCostFigures {
  double plain_roi_fps = 0.0;      ///< no correction
  double corrected_roi_fps = 0.0;  ///< lens, latency and rolling shutter corrected
  std::size_t frames = 0;          ///< frames per pass
};

/// The whole measurement.
struct CameraReport {
  std::string board;                        ///< board file
  CameraBenchOptions options;               ///< what was asked
  std::vector<CameraScenarioResult> scenarios;  ///< in camera_scenarios() order
  CalibratedLensFigures calibrated_lens;    ///< when given
  double true_latency_s = 0.0;              ///< the camera's minimum latency (what a measurement should find, s)
  CameraCostFigures cost;                   ///< detector frames per second
  bool corrected_within_target = false;     ///< every corrected scenario within the target
  double wall_s = 0.0;                      ///< wall time (s)
};

/// The latency `pinball calibrate latency --sim` measures on this camera
/// (`events` fires of the first flipper, seed `seed`), as the lab would.
double measure_simulated_latency_s(const table::Board& board, const simlab::SimCameraRealism& camera, int events,
                                   std::uint64_t seed);

/// The lens `pinball calibrate intrinsics --sim` recovers from `views`
/// simulated views of the default chessboard through `lens`, as the lab would.
vision::CameraIntrinsics calibrate_simulated_lens(const vision::CameraIntrinsics& lens, int views, std::uint64_t seed);

/// Runs the measurement; `progress` (may be empty) receives one line per scenario.
CameraReport run_camera_bench(const table::Board& board, const CameraBenchOptions& options,
                              const std::function<void(const std::string&)>& progress);

/// The report as one JSON object (camera_bench_report.cpp).
nlohmann::json to_json(const CameraReport& report);

/// The report as a text table.
std::string to_text(const CameraReport& report);

}  // namespace pinball::bench
