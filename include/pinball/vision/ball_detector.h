#pragma once
// Finds the ball in a grayscale frame and reports where it is on the table.
// Background subtraction (|frame − background|), a threshold, connected
// blobs; a blob is the ball only when its area, elongation and fill match a
// ball of the board's radius at that place in the image (so lamps, glare and
// flippers are rejected) and it touches neither a known occluder nor the edge
// of the image. The centre is the sub-pixel centroid of the difference image
// with saturating weights (shading and the specular highlight do not pull it),
// undistorted as one point when the lens is known (cv::undistortPoints, never
// the whole frame) and mapped to the board through the camera homography; the
// observation is dated at the exposure of the ball's row: the frame's stamp
// less the camera's latency, plus the row times the row time under a rolling
// shutter. A ball touching a thin
// bright object (a flipper, a rail) merges with it into one blob of the wrong
// shape; when no blob passes, such blobs are opened (eroded then dilated) with
// a disc smaller than the ball, which removes the thin parts and keeps the
// ball, and the pieces are tested again. The search looks first
// in a region around the predicted position and falls back to the whole frame.
// No allocation per frame after construction.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/track/observation.h"
#include "pinball/vision/background_model.h"
#include "pinball/vision/camera_homography.h"
#include "pinball/vision/frame.h"
#include "pinball/vision/frame_dejitter.h"
#include "pinball/vision/lens_model.h"

namespace pinball::vision {

/// Detector settings.
struct BallDetectorConfig {
  double ball_radius_m = 0.0135;     ///< ball radius (m): sets the expected blob size through the homography
  int threshold = 30;                ///< |frame − background| above this (gray levels) is foreground
  double min_area_ratio = 0.55;      ///< smallest blob area accepted, as a fraction of π·r_px²
  double max_area_ratio = 2.6;       ///< largest blob area accepted (motion blur makes the ball longer)
  double max_elongation = 2.0;       ///< largest major/minor axis ratio of the blob's second moments
  double min_fill = 0.78;            ///< smallest area / area of the ellipse with the same moments
  double max_model_error = 0.05;     ///< largest relative gap between the blob's area and a blurred ball's
                                     ///< (a stadium) with the same second moments: rejects a ball merged with a lamp
  double radius_tolerance = 0.12;    ///< the radius from the blob's minor axis may differ this much (fraction)
                                     ///< from the expected radius
  double weight_floor_fraction = 0.5;///< centroid weights start at this fraction of the threshold
  double weight_saturation = 0.5;    ///< ... and saturate at this fraction of the blob's peak difference
  bool use_roi = true;               ///< search around the prediction before the whole frame
  double roi_radius_factor = 3.5;    ///< ROI half-size: this many ball radii plus the last motion per frame
  int occluder_margin_px = 2;        ///< a blob this close to an occluder counts as hidden by it
  int edge_margin_px = 2;            ///< a blob this close to the image (or ROI) edge counts as cut by it (>= 2)
  double background_rate = 0.0;      ///< running background update rate per update (0: frozen)
  int background_every = 4;          ///< frames between running updates
  double separation_radius_fraction = 0.9;  ///< disc radius of the opening that separates the ball from thin
                                            ///< attached objects, as a fraction of the expected ball radius:
                                            ///< removes parts narrower than 2× this radius (0: no separation)
  double max_separated_elongation = 1.5;    ///< largest elongation of a ball cut loose by the opening (a ball
                                            ///< blurred by about one radius): a longer piece is more likely
                                            ///< a ball with a lump of the object it touches
  // The camera's corrections (calibration file: intrinsics, camera_timing). Off, the
  // detector treats the camera as an ideal pinhole with a global shutter stamped at exposure.
  std::optional<CameraIntrinsics> lens;     ///< undistort the centroid before the homography (its size must be the frame's)
  double latency_s = 0.0;                   ///< the frame's stamp minus row 0's mid-exposure (s): subtracted
  double row_time_s = 0.0;                  ///< rolling shutter: the ball's row v was exposed v · this after row 0 (s)
  int dejitter_frames = 0;                  ///< > 0: date frames by the camera's steady clock, the lower envelope of
                                            ///< the stamps over this many frames (FrameDejitter); latency_s is then
                                            ///< the minimum latency. 0: the stamps as they come
  double frame_period_s = 0.005;            ///< the camera's frame period, for dejittering (s)
};

/// Why a frame gave no ball.
enum class DetectionMiss : std::uint8_t {
  kNone,          ///< the ball was found
  kBadFrame,      ///< the frame is not 8-bit gray of the detector's size
  kNoBackground,  ///< the background is not learned yet
  kNoBlob,        ///< nothing above the threshold
  kWrongSize,     ///< blobs, but none of a ball's area
  kWrongShape,    ///< ball-sized blobs, but too long or too ragged
  kOccluded,      ///< a candidate touched an occluder
  kCut,           ///< a candidate touched the image edge
};

/// One frame's answer.
struct Detection {
  bool found = false;               ///< true: `observation` holds the ball
  track::Observation observation;   ///< t_s (the frame's), p_board (m), confidence in (0, 1]
  cv::Point2d uv_px{0.0, 0.0};      ///< sub-pixel centre in the image as the sensor saw it (px)
  cv::Point2d uv_ideal_px{0.0, 0.0};///< the same undistorted: where an ideal pinhole camera saw it (px)
  double area_px = 0.0;             ///< the accepted blob's area (px)
  double expected_area_px = 0.0;    ///< π·r_px² at that place (px)
  double elongation = 0.0;          ///< major/minor axis ratio
  double model_error = 0.0;         ///< relative gap between its area and a blurred ball's with its moments
  double radius_px = 0.0;           ///< radius from its minor axis (px)
  bool from_roi = false;            ///< found in the region of interest
  bool separated = false;           ///< found only after opening away thin objects attached to it (a flipper)
  int blobs = 0;                    ///< blobs examined (all searches of this frame)
  DetectionMiss miss = DetectionMiss::kNone;  ///< reason when not found
};

/// Name of a miss reason ("none", "bad_frame", "no_background", "no_blob", ...).
const char* to_string(DetectionMiss miss);

/// Running totals.
struct DetectorCounters {
  std::uint64_t frames = 0;             ///< frames given to detect()
  std::uint64_t found = 0;              ///< frames with a ball
  std::uint64_t found_in_roi = 0;       ///< of those, found by the ROI search
  std::uint64_t full_searches = 0;      ///< whole-frame searches
  std::uint64_t rejected_size = 0;      ///< blobs of the wrong area
  std::uint64_t rejected_shape = 0;     ///< blobs of the wrong elongation or fill
  std::uint64_t rejected_occluded = 0;  ///< blobs touching an occluder
  std::uint64_t rejected_edge = 0;      ///< blobs touching the image edge
  std::uint64_t separations = 0;        ///< rejected blobs opened to separate a ball from thin attached objects
  std::uint64_t found_separated = 0;    ///< frames whose ball was found only after such an opening
  std::uint64_t bad_frames = 0;         ///< frames of the wrong size or type (ignored)
};

/// The ball detector for one camera.
class BallDetector {
 public:
  /// A detector for frames of `frame_size` seen through `homography`.
  /// Throws std::invalid_argument naming a bad setting.
  BallDetector(const CameraHomography& homography, cv::Size frame_size, const BallDetectorConfig& config = {});

  /// Where plastics and other fixed things hide the playfield: CV_8UC1 of the
  /// frame size, non-zero where occluded. Empty clears it.
  void set_occluder_mask(const cv::Mat& mask);

  /// The background model (train it with ball-free frames before detecting).
  BackgroundModel& background() { return background_; }
  const BackgroundModel& background() const { return background_; }

  /// Finds the ball in `frame`. `predicted_uv_px` (may be null) overrides the
  /// detector's own constant-velocity prediction for the ROI. Never throws.
  Detection detect(const Frame& frame, const cv::Point2d* predicted_uv_px = nullptr);

  /// Forgets the last position: the next frame is searched whole.
  void forget_track() { track_frames_ = 0; }

  /// Expected ball radius (px) around image point uv_px.
  double expected_radius_px(const cv::Point2d& uv_px) const;

  /// Running totals.
  const DetectorCounters& counters() const { return counters_; }
  /// The settings.
  const BallDetectorConfig& config() const { return config_; }
  /// The homography in use.
  const CameraHomography& homography() const { return homography_; }

 private:
  struct Blob {
    double area = 0.0;
    double su = 0.0, sv = 0.0, suu = 0.0, svv = 0.0, suv = 0.0;
    int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
    bool occluded = false;
    bool at_region_edge = false;
  };
  struct Best;  // the best blob of a search so far
  static constexpr int kMaxSplits = 4;        // rejected blobs opened per search, at most
  static constexpr int kMaxSplitRadius = 64;  // largest opening disc radius (px)

  // Searches `region`; `region_is_roi` marks a blob on the region's border as cut by the ROI.
  bool search(const cv::Rect& region, bool region_is_roi, double t_s, Detection& out);
  // Tests the blobs of binary_ inside `box` (within `region`); `opened`: the second pass on opened blobs.
  void scan(const cv::Rect& region, const cv::Rect& box, bool region_is_roi, bool opened, Detection& out, Best& best);
  // Keeps a rejected blob (its pixels in stack_) for opening.
  void add_split(const Blob& blob);
  // Writes into binary_ the opening of split candidate `label` (its pixels in split_label_ inside `box`).
  void open_split(std::uint8_t label, const cv::Rect& box);
  void fill_blob(int u, int v, const cv::Rect& region, Blob& blob);
  // `opened`: foreground pixels outside the blob (the thin parts the opening removed) get no weight.
  cv::Point2d weighted_centroid(const Blob& blob, bool opened);

  CameraHomography homography_;
  std::optional<PointUndistorter> undistorter_;  // with a lens
  double speck_area_px2_ = 0.0;  // a blob smaller is noise wherever it lies (set at construction)
  std::optional<FrameDejitter> dejitter_;        // with dejitter_frames > 0
  cv::Size size_;
  BallDetectorConfig config_;
  BackgroundModel background_;
  cv::Mat diff_;       // CV_8U |frame − background|
  cv::Mat binary_;     // CV_8U foreground, consumed by the blob fill
  cv::Mat occluder_;   // CV_8U dilated occluder mask (empty: none)
  cv::Mat halo_;       // CV_8U scratch: the accepted blob and its rim, cleared after use
  cv::Mat split_label_;  // CV_8U scratch: pixels of rejected blobs to open (1..kMaxSplits), cleared after use
  cv::Mat split_core_;   // CV_8U scratch: a candidate's erosion, cleared after use
  cv::Mat split_run_;    // CV_16S scratch: horizontal run half-lengths, then distances to the erosion
  std::array<cv::Rect, kMaxSplits> split_box_{};  // bounding boxes of the split candidates
  int split_count_ = 0;
  const cv::Mat* frame_ = nullptr;
  std::vector<std::int32_t> stack_;  // flood-fill queue, sized for a whole frame; holds the last blob's pixels
  // Track for the ROI.
  int track_frames_ = 0;               // consecutive frames found (0: lost)
  cv::Point2d last_uv_px_{0.0, 0.0};
  cv::Point2d velocity_px_{0.0, 0.0};  // per frame
  double last_t_s_ = 0.0;
  DetectorCounters counters_;
};

}  // namespace pinball::vision
