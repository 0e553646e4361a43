#pragma once
// `pinball bench detector`: the camera path measured against the simulator's
// truth. The simulated camera (simlab::SimCameraSource) renders the thesis
// table while the oracle spastic player plays it; the BallDetector finds the
// ball in every frame and its centre is compared with the true ball centre at
// mid-exposure. Measured in the same run:
//  - accuracy on unoccluded frames with motion blur (px and mm), against a
//    naive centroid (plain threshold + moments of the whole frame, no
//    background model) as the baseline;
//  - false detections on ball-free frames (lamps blinking, glare flickering);
//  - behaviour under occlusion: frames with the ball partly or wholly under a
//    plastic must give no observation, never a wrong one;
//  - frames per second on one core for full-frame and ROI detection at
//    640x480 and 1280x1024 (full-frame is the baseline for ROI).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/table/board.h"
#include "pinball/vision/ball_detector.h"
#include "pinball/simlab/sim_camera_source.h"

namespace pinball::bench {

/// Targets from the issue.
inline constexpr double kTargetMedianErrorPx = 0.3;      ///< median centre error, unoccluded blurred frames (px)
inline constexpr double kTargetP99ErrorPx = 1.0;         ///< 99th percentile (px)
inline constexpr double kTargetRoiFps640 = 1000.0;       ///< ROI detection at 640x480, one core
inline constexpr double kTargetFullFrameFps640 = 300.0;  ///< full-frame detection at 640x480, one core

/// What to measure.
struct DetectorBenchOptions {
  std::uint64_t seed = 1;                   ///< game, camera and placement seed
  int play_frames = 4000;                   ///< frames with the ball in play to score (640x480)
  int ball_free_frames = 10000;             ///< frames without a ball to count false detections on
  int occlusion_frames = 600;               ///< frames with the ball placed partly or wholly under plastic
  int timing_frames = 300;                  ///< distinct frames per timing sequence
  int timing_repeats = 5;                   ///< passes over them per timed mode
  std::vector<cv::Size> timing_sizes{{640, 480}, {1280, 1024}};  ///< image sizes timed
  int background_frames = 32;               ///< ball-free frames averaged into the background
  double wrong_px = 1.0;                    ///< a detection further than this from the truth is wrong (px)
  double naive_threshold = 170.0;           ///< baseline: gray level the naive centroid thresholds at
  simlab::SimCameraConfig camera = default_camera();  ///< the simulated camera (size is per measurement)
  vision::BallDetectorConfig detector;      ///< the detector under test

  /// The bench's camera: the default simulated camera with a flickering glare patch.
  static simlab::SimCameraConfig default_camera();
};

/// A short run for tests: few frames of each kind, 640x480 timing only.
DetectorBenchOptions quick_detector_bench_options();

/// Median, 99th percentile and maximum of a set of errors.
struct ErrorSummary {
  std::size_t count = 0;  ///< samples
  double median = 0.0;    ///< 0 when count == 0
  double p99 = 0.0;       ///< 0 when count == 0
  double max = 0.0;       ///< 0 when count == 0
};

/// The summary of a set of errors (bench camera shares it).
ErrorSummary summarise_errors(std::vector<double> errors);

/// The summary as JSON: count, median, p99, max.
nlohmann::json to_json(const ErrorSummary& summary);

/// Learns the detector's background from `frames` ball-free frames rendered
/// from t_s on (advanced), with the lamps still and the glare off.
void learn_background(simlab::SimCameraSource& camera, vision::BallDetector& detector, int frames, double& t_s);

/// Accuracy on frames from play.
struct AccuracyFigures {
  std::size_t frames = 0;              ///< frames delivered during play
  std::size_t ball_frames = 0;         ///< of them, ball in view for the whole exposure
  std::size_t unoccluded = 0;          ///< ... and not under plastic nor glare: the accuracy set
  std::size_t detected = 0;            ///< accuracy-set frames with an observation
  std::size_t missed = 0;              ///< accuracy-set frames without one
  std::size_t wrong = 0;               ///< observations further than wrong_px from the truth
  ErrorSummary error_px;               ///< detector, image (px)
  ErrorSummary error_mm;               ///< detector, board (mm)
  ErrorSummary naive_error_px;         ///< baseline naive centroid on the same frames (px)
  std::size_t naive_found = 0;         ///< frames where the naive threshold found anything
  double median_blur_px = 0.0;         ///< median motion blur over the exposure (px)
  double p99_blur_px = 0.0;            ///< 99th percentile of the blur (px)
  double median_radius_px = 0.0;       ///< median ball radius in the image (px)
  std::size_t in_glare = 0;            ///< ball frames with the ball in the glare (excluded)
  std::size_t in_glare_detected = 0;   ///< ... with an observation
  std::size_t in_glare_wrong = 0;      ///< ... with a wrong one
  std::size_t no_ball_frames = 0;      ///< play frames without a ball (between balls)
  std::size_t no_ball_detections = 0; ///< ... with an observation (false)
};

/// Occlusion: the ball placed near and under the plastics.
struct OcclusionFigures {
  std::size_t frames = 0;           ///< frames with part of the ball under plastic
  std::size_t no_observation = 0;   ///< of them, correctly no observation
  std::size_t wrong = 0;            ///< observations further than wrong_px from the truth
  std::size_t close = 0;            ///< observations within wrong_px (a sliver under plastic)
};

/// One timed configuration.
struct DetectorTiming {
  cv::Size size;                 ///< image size
  double full_frame_fps = 0.0;   ///< whole-frame search every frame (the baseline)
  double roi_fps = 0.0;          ///< ROI around the prediction, whole frame when lost
  double roi_speedup = 0.0;      ///< roi_fps / full_frame_fps
  double roi_found_fraction = 0.0;  ///< ROI-mode frames answered from the ROI
  double render_fps = 0.0;       ///< SimCameraSource frames rendered per second (for the daemon's 200 fps)
  std::size_t frames = 0;        ///< frames per pass
  double ball_fraction = 0.0;    ///< frames of the sequence with the ball in view
};

/// The targets.
struct DetectorHeadline {
  bool median_met = false;       ///< error_px.median <= kTargetMedianErrorPx
  bool p99_met = false;          ///< error_px.p99 <= kTargetP99ErrorPx
  bool no_false_met = false;     ///< no false detection on ball-free frames
  bool roi_fps_met = false;      ///< 640x480 ROI fps >= kTargetRoiFps640
  bool full_fps_met = false;     ///< 640x480 full-frame fps >= kTargetFullFrameFps640
  bool occlusion_met = false;    ///< no wrong observation under occlusion
  bool all_met = false;          ///< all of them
};

/// The whole measurement.
struct DetectorReport {
  std::string board;                  ///< board file
  DetectorBenchOptions options;       ///< what was asked
  AccuracyFigures accuracy;           ///< play frames, 640x480 (or options.camera's size)
  std::size_t ball_free_frames = 0;   ///< ball-free frames examined
  std::size_t false_detections = 0;   ///< observations on them
  std::size_t ball_free_glare_frames = 0;  ///< of them, with the glare on
  std::size_t ball_free_rejected_blobs = 0;  ///< blobs rejected on them (lamps, glare)
  OcclusionFigures occlusion;         ///< ball under plastic
  std::vector<DetectorTiming> timing; ///< per size
  DetectorHeadline headline;          ///< targets
  double wall_s = 0.0;                ///< wall time of the run (s)
};

/// Runs the measurement; `progress` (may be empty) receives a line per stage.
DetectorReport run_detector_bench(const table::Board& board, const DetectorBenchOptions& options,
                                  const std::function<void(const std::string&)>& progress);

// The report (detector_bench_report.cpp).

/// The report as one JSON object.
nlohmann::json to_json(const DetectorReport& report);

/// The report as a compact text summary.
std::string to_text(const DetectorReport& report);

}  // namespace pinball::bench
