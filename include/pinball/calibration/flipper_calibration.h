#pragma once
// Flipper calibration, two ways.
// Markers (thesis 4.1.3): a marker on the pivot and one on the tip of every
// flipper, photographed once with the flippers down and once held up; the
// markers' board positions (through the camera homography) give the pivot,
// the tip, the length and both stops.
// Markerless: a short video of one flipper swept by hand from stop to stop.
// The background is the per-pixel minimum over the video (the bright flipper
// is elsewhere in some frame everywhere it moves), the flipper is the largest
// bright blob above it. In every frame the blade's centre line is fitted to
// the midpoints of its two long edges (half-contrast, subpixel) and its tip is
// the centre of its rounded end: a circle, centred on that line, fitted to the
// half-contrast outline of the end (so neither the end's radius nor the
// blade's width needs to be known). The centre lines, mapped to the board,
// all pass through the pivot: their least-squares meeting point is the pivot,
// whatever the tip model. The length is the median distance of the tips from
// it, and the angles where the tip rests give θ_min and θ_max.

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/calibration/calibration_file.h"
#include "pinball/calibration/circle_fit.h"
#include "pinball/core/geometry.h"
#include "pinball/table/board.h"
#include "pinball/vision/camera_homography.h"
#include "pinball/vision/frame_source.h"

namespace pinball::calibration {

/// Elevation θ (rad) of a flipper of `side` whose tip is at `tip` (the board's convention).
double flipper_angle(table::Side side, const Vec2& pivot, const Vec2& tip);

/// How far the two sightings of one pivot marker (down, up), or the blade's
/// two lengths, may differ: a few times a marker's placement error.
inline constexpr double kMarkerAgreement_m = 0.003;

/// Marker method: `down` and `up` are the markers seen (board frame, m) with
/// the flippers down and held up. The markers of `nominal` are those nearest
/// to its nominal pivot and tips, within tolerance_m. Throws
/// std::runtime_error naming the flipper and the marker that is missing, or
/// the pivot or length that moved by more than kMarkerAgreement_m between
/// the pictures.
FlipperCalibration calibrate_flipper_markers(const table::Flipper& nominal, std::span<const Vec2> down,
                                             std::span<const Vec2> up, double tolerance_m = 0.03);

/// Markerless method settings.
struct SweepOptions {
  int threshold = 40;              ///< frame − background above this (gray levels) is the flipper
  int min_area_px = 20;            ///< smallest flipper blob (px)
  double stop_band_rad = 0.026;    ///< tips within this of the extreme angles (5th/95th percentile) rest on a stop
  CircleFitOptions circle;         ///< the pivot fit (lines meeting) and the tip circle fit's trimming
};

/// The blade seen in a sweep video.
struct SweepTrack {
  int frames = 0;                      ///< frames read (second pass)
  std::vector<double> t_s;             ///< time of each sighting (s)
  std::vector<Vec2> tips_board;        ///< tip positions (m, board frame): the centres of the blade's rounded end
  std::vector<Line2> blades_board;     ///< the blade's centre line in each sighting (m, board frame); may be empty
  LinesMeet meet;                      ///< where the centre lines meet (m): the pivot
  CircleFit circle;                    ///< pivot and length as a circle through the tips (m)
};

/// Finds the flipper's blade in the frames of a sweep: learn() every frame
/// once (the background), then measure() every frame again, then finish().
class TipTracker {
 public:
  /// For frames of `size` seen through `homography`.
  TipTracker(cv::Size size, const vision::CameraHomography& homography, const SweepOptions& options = {});

  /// First pass: one frame into the background (per-pixel minimum).
  void learn(const cv::Mat& gray);
  /// Second pass: finds the blade in one frame; false when none is visible.
  bool measure(const cv::Mat& gray, double t_s);
  /// The tips and centre lines in board coordinates. Throws
  /// std::runtime_error when the blade was seen in fewer than 10 frames or
  /// never turned.
  SweepTrack finish() const;

 private:
  struct Sighting {
    double t_s = 0.0;
    cv::Point2d centre_px;          // on the centre line
    cv::Point2d axis;               // unit, image
    cv::Point2d end_plus_px, end_minus_px;  // half-contrast ends along the axis, either way
    cv::Point2d tip_plus_px, tip_minus_px;  // centres of the rounded ends
    bool tip_plus_ok = false, tip_minus_ok = false;  // whether that end fitted a circle
  };
  double edge_along(const cv::Point2d& from, const cv::Point2d& dir, double level, double max_px) const;
  bool fit_centre_line(cv::Point2d& c, cv::Point2d& d, double half_length_px, double& width_px) const;
  bool fit_end(const cv::Point2d& c, const cv::Point2d& d, double width_px, double reach_px, double& s_px) const;

  cv::Size size_;
  vision::CameraHomography homography_;
  SweepOptions options_;
  cv::Mat background_;
  cv::Mat diff_, binary_, labels_, stats_, centroids_;
  int learned_ = 0;
  int measured_ = 0;
  std::vector<Sighting> sightings_;
};

/// Opens a frame source afresh (the video is read twice).
using FrameSourceFactory = std::function<std::unique_ptr<vision::FrameSource>()>;

/// Markerless method on a sweep video of flipper `nominal` (its name and side
/// only). `track` (may be null) receives the tips, the centre lines and the fits.
FlipperCalibration calibrate_flipper_sweep(const FrameSourceFactory& open, const vision::CameraHomography& homography,
                                           const table::Flipper& nominal, const SweepOptions& options = {},
                                           SweepTrack* track = nullptr);

/// The fit of a sweep track alone (for tests and for tracks from elsewhere):
/// the pivot where track.blades_board meet, or, when the track has no lines
/// (tips tracked some other way), the centre of the circle fitted to the tips.
FlipperCalibration flipper_from_sweep_track(SweepTrack& track, const table::Flipper& nominal, const SweepOptions& options);

/// How `a` differs from `b` (a minus b; distances for the points).
FlipperDisagreement compare_flippers(const FlipperCalibration& a, const FlipperCalibration& b);

}  // namespace pinball::calibration
