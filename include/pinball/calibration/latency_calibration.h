#pragma once
// The camera's latency measured against a known event, not assumed (issue
// 18): the host commands a flipper's coil on at a time it knows, and the
// frames show when the flipper began to move. The frames are dated by the
// camera's steady clock (vision::FrameDejitter), so what is measured is the
// latency those dates carry: a frame's dejittered stamp minus the middle of
// its row 0's exposure, the camera_timing section's latency_s.
//
// Per event: a rest image (the mean of the frames just before the command);
// per frame the motion metric, the change of the region's angular moment
// about the pivot, Σ (frame − rest)·a·(φ − φ̄) over the flipper's region (a: a
// pixel's board area, φ: its polar angle about the pivot, φ̄ the rest image's
// mean angle, so that a change of brightness over the whole region adds
// nothing). For a rigid bat turning about its pivot the metric is exactly
// proportional to the angle it has turned through, all the way to the up
// stop (a plain mean |frame − rest| stops growing once the bat has moved its
// own width, a sixth of the stroke). Lamps flicker at twice the mains
// frequency and a rolling shutter turns that into bands across the image, so
// each frame's rows are first scaled to the rest image's brightness, measured
// on the static table beside the flipper (a quadratic in the row). A solenoid starts the flipper from rest
// with a roughly constant angular acceleration, so the angle, and the metric,
// grows as (t − t_move)²: √(metric / full stroke) against the frame's time
// is a straight line over the frames between fit_low and fit_high of the full
// stroke, and where it crosses zero is when the motion started. A frame's
// time is its stamp plus row · row time for the rows whose change makes its
// metric (a rolling shutter exposes row v v · row time after row 0; the
// rows are where the bat's edges were, from the frames either side), so
//   latency = zero crossing − (command + actuation delay)
// is a frame's stamp minus its row 0's mid-exposure. A frame averages the
// angle over its exposure, which lifts the early points by e²/12 in the
// line's units: taken off before the final fit.
//
// Pure: it knows nothing of cameras or CAN; `pinball calibrate latency`
// records, this measures (docs/calibration.md, "Camera latency").

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/calibration/calibration_file.h"
#include "pinball/core/geometry.h"
#include "pinball/table/board.h"

namespace pinball::calibration {

/// Board point (m) -> where the camera shows it (px): the homography, then the lens when there is one.
using ImageFromBoard = std::function<cv::Point2d(const Vec2&)>;

/// How wide a region to watch around the flipper's sweep.
struct FlipperRegionOptions {
  double half_width_m = 0.018;   ///< the bat's half width at its widest, with its rubber, plus a margin (m)
  double sample_step_m = 0.0006; ///< board sampling step when the region is rasterised (m): a fraction of a pixel
  int reference_margin_px = 24;  ///< the static table this far left and right of the region dates each row's brightness
  int reference_guard_px = 3;    ///< ... leaving this much space next to the region (a blurred bat's edge)
};

/// The pixels a flipper can cover between its stops (each within half_width_m
/// of the bat at some angle; a disc of that radius about the pivot left out,
/// where the angle means little), with what each tells of the angle, and
/// static table beside them in the same rows.
struct FlipperRegion {
  cv::Rect roi;              ///< bounding box in the image (px); a recording keeps only these pixels
  cv::Mat mask;              ///< CV_8U over roi: 255 on the region
  cv::Mat angle_rad;         ///< CV_64F over roi: polar angle about the pivot from the down stop, positive towards
                             ///< the up stop (rad)
  cv::Mat area_m2;           ///< CV_64F over roi: board area one pixel covers (m²)
  cv::Mat reference;         ///< CV_8U over roi: 255 on the static table beside the region, in its rows
  double mean_row_px = 0.0;  ///< mean image row of the region (px)
  int pixels = 0;            ///< pixels in the region
  int reference_pixels = 0;  ///< pixels in the reference
  double sweep_rad = 0.0;    ///< the stroke, down stop to up stop (rad)
};

/// Rasterises `flipper`'s region through `image_from_board` for images of
/// `image_size`. Throws std::invalid_argument for a flipper without length or
/// stroke, a bad option, or a region that falls outside the image.
FlipperRegion flipper_region(const table::Flipper& flipper, const ImageFromBoard& image_from_board, cv::Size image_size,
                             const FlipperRegionOptions& options = {});

/// One frame as a latency recording keeps it.
struct LatencyFrame {
  cv::Mat gray;                 ///< CV_8U: the frame's pixels in the region's roi (or the whole frame)
  double t_s = 0.0;             ///< the host's stamp on the frame (s, the commands' clock)
  std::uint64_t sequence = 0;   ///< the camera's frame number; a gap means frames were lost
};

/// What a latency run recorded: frames in sequence order and the commands.
struct LatencyRecording {
  std::vector<LatencyFrame> frames;  ///< every frame, in order
  std::vector<double> command_t_s;   ///< host times the flipper's coil was commanded on (s), one per event, increasing

  /// Keeps a copy of `region`'s pixels of `gray` (a whole CV_8U frame) with its stamp and sequence.
  /// Throws std::invalid_argument for a frame that is not 8-bit gray or does not hold the roi.
  void add_frame(const FlipperRegion& region, const cv::Mat& gray, double t_s, std::uint64_t sequence);
};

/// The measurement's settings: what it must know of the camera and the drive, and its thresholds.
struct LatencyOptions {
  double frame_period_s = 0.005;    ///< the camera's frame period (s), for dating frames by its clock
  double row_time_s = 0.0;          ///< rolling shutter: row v is exposed v · this after row 0 (s); 0: global shutter
  double exposure_s = 0.0;          ///< exposure time (s): a frame averages the angle over it; 0: not corrected
  double actuation_delay_s = 0.004; ///< the host's command to the flipper's first motion (s): CAN, coil current rise,
                                    ///< plunger slack (docs/calibration.md says how to measure it)
  int dejitter_frames = 100;        ///< frames in the steady clock's lower envelope; earlier events are not used
  int rest_frames = 6;              ///< frames just before the command averaged into the rest image
  double window_s = 0.2;            ///< frames stamped up to this long after the command belong to the event (s)
  double fit_low = 0.05;            ///< the fit takes the frames from this fraction of the full stroke ...
  double fit_high = 0.6;            ///< ... to this one, before the flipper first passes it
  int min_fit_frames = 2;           ///< fewer frames in that window: the event is not used
  double max_fit_rms = 0.05;        ///< largest RMS residual of √(fraction of the stroke) about its line
  double min_motion_sigmas = 50.0;  ///< the full stroke's metric must be this many times the rest frames' noise
};

/// Why an event was left out.
enum class LatencyRejection : std::uint8_t {
  kNone,             ///< used
  kClockNotSettled,  ///< too early in the recording: the frame clock's envelope had too few frames
  kFramesDropped,    ///< frames dropped around it (or the recording ends within its window)
  kNoMotion,         ///< no motion seen: the flipper did not move, or not enough above the noise
  kTooFewFitFrames,  ///< too few frames in the fit window
  kFitResidual,      ///< fit residual too large: the motion did not start as a steady acceleration
};

/// "used", "frame clock not settled", "frames dropped around it", "no motion
/// seen", "too few frames in the fit window", "fit residual too large".
const char* to_string(LatencyRejection rejection);

/// One event as measured.
struct LatencyEvent {
  double command_t_s = 0.0;       ///< when the coil was commanded on (s)
  LatencyRejection rejection = LatencyRejection::kNone;  ///< why it was left out (kNone: used)
  double latency_s = 0.0;         ///< its latency (s; used events)
  double motion_stamp_s = 0.0;    ///< the stamp of a frame whose row 0 was exposed as the motion started (s)
  double motion_row_px = 0.0;     ///< mean image row of the change in the fit frames (px): whose exposure time counts
  int fit_frames = 0;             ///< frames in the fit
  double fit_rms = 0.0;           ///< RMS residual of √(fraction of the stroke) about the line
  double stroke_sigmas = 0.0;     ///< the full stroke's metric over the rest frames' noise

  /// Whether it is in the estimate.
  bool used() const { return rejection == LatencyRejection::kNone; }
};

/// The measurement.
struct LatencyEstimate {
  double latency_s = 0.0;         ///< median of the used events' latencies (s)
  double spread_s = 0.0;          ///< their standard deviation (s)
  int events_used = 0;            ///< events in the estimate
  int events_rejected = 0;        ///< events left out (each says why)
  double row_time_s = 0.0;        ///< the row time it was measured with (s)
  double motion_row_px = 0.0;     ///< mean over the used events of the rows whose exposure times count (px)
  std::vector<LatencyEvent> events;  ///< every event, in command order

  /// The calibration file's camera_timing section.
  CameraTiming camera_timing() const;
};

/// The camera's true frame period (s) from a recording's stamps: the slope of
/// their lower envelope between its first and last `window` frames, starting
/// from `nominal_period_s`. A camera's crystal runs off its nominal rate by up
/// to ~100 ppm, which over the envelope's window would shift the dates by
/// tens of µs. The nominal period for fewer than 2·window frames. Throws
/// std::invalid_argument for a period <= 0 or a window < 2.
double estimate_frame_period_s(const LatencyRecording& recording, double nominal_period_s, int window = 100);

/// How long a run records before its first command (s): the frames that date
/// the clock (dejitter_frames) and the rest frames, with a margin, at the
/// camera's period. The lab's run and the simulated one both wait this long.
inline double latency_lead_in_s(const LatencyOptions& options, double frame_period_s) {
  return (options.dejitter_frames + options.rest_frames + 34) * frame_period_s;
}

/// Measures the latency from a recording. Throws std::invalid_argument for bad
/// options or frames, and std::runtime_error "latency: only 2 of 10 events
/// usable (event 3: no motion seen, ...)" when fewer than 3 events survive.
LatencyEstimate measure_latency(const LatencyRecording& recording, const FlipperRegion& region,
                                const LatencyOptions& options);

}  // namespace pinball::calibration
