#pragma once
// The lab in the simulator: everything `pinball calibrate` reads, generated
// from a board for practice and for measuring the routines against a known
// truth. By default the simulated machine is the one its board file
// describes, as pinballd's simulated table is, so that a practice calibration
// fed to pinballd plays the same machine. A mounting error (the flippers a
// few millimetres and a fraction of a degree off, as a real machine differs
// from its drawing) is given on request: the calibration bench and tests use
// one, so that the routines measure something. The routines see only images,
// videos and observations, the nominal board only to name and roughly place
// things.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/calibration/gravity_calibration.h"
#include "pinball/core/geometry.h"
#include "pinball/table/board.h"
#include "pinball/track/camera_model.h"
#include "pinball/vision/frame_source.h"
#include "pinball/simlab/sim_camera_source.h"

namespace pinball::simlab {

/// How the simulated lab differs from the board and how it is recorded.
struct SimLabOptions {
  std::uint64_t seed = 1;                     ///< camera art and noise, roll places and observation noise
  simlab::SimCameraConfig camera;             ///< the camera (its seed is replaced by `seed`)
  Vec2 pivot_offset_m{0.0, 0.0};              ///< the machine's pivots sit this far from the board file's (m)
  double length_offset_m = 0.0;               ///< its flippers are this much longer (m)
  double theta_offset_rad = 0.0;              ///< both stops this much higher (rad)
  double sweep_rest_s = 0.25;                 ///< a swept flipper rests this long on each stop (s)
  double sweep_move_s = 0.5;                  ///< ... and takes this long from stop to stop (s), by hand
  int sweeps = 2;                             ///< up-and-down sweeps per video
  track::CameraModelConfig roll_camera;       ///< the camera model the rolls are observed through
  double roll_hold_s = 0.1;                   ///< the ball rests this long before it is let go (s)
  double roll_after_contact_s = 0.1;          ///< recording goes on this long after it first hits something (s)
  double roll_min_travel_m = 0.25;            ///< a roll travels at least this far before hitting anything (m)
};

/// `options` with the flippers mounted as a real machine differs from its
/// drawing: pivots 3 mm across and 2 mm down (3.6 mm), 2 mm longer, both
/// stops 0.012 rad (0.7 degrees) higher. What the calibration bench and tests
/// measure the routines against.
SimLabOptions with_mounting_error(SimLabOptions options);

/// The simulated lab machine.
class SimLab {
 public:
  /// Builds the machine from the nominal board. Throws std::invalid_argument
  /// for a bad camera setting.
  explicit SimLab(const table::Board& nominal, const SimLabOptions& options = {});
  SimLab(const SimLab&) = delete;             ///< the camera refers to the machine's board
  SimLab& operator=(const SimLab&) = delete;

  /// The board file's description.
  const table::Board& nominal() const { return nominal_; }
  /// The machine as it really is (the truth the bench measures against).
  const table::Board& truth() const { return truth_; }
  /// The camera's true homography.
  const vision::CameraHomography& true_homography() const { return camera_->homography(); }
  /// Image size (px).
  cv::Size image_size() const { return camera_->frame_size(); }
  /// The settings.
  const SimLabOptions& options() const { return options_; }

  /// One camera frame with markers at `markers` (board, m) and every flipper
  /// down (or held up).
  cv::Mat marker_image(std::span<const Vec2> markers, bool flippers_up);
  /// The camera calibration image: markers at default_marker_layout(nominal).
  cv::Mat camera_image();
  /// The flipper marker image: a marker on every flipper's true pivot and tip.
  cv::Mat flipper_markers_image(bool flippers_up);
  /// A video of flipper `index` swept by hand from stop to stop (others
  /// down); every call gives the same frames. The source refers to this lab.
  std::unique_ptr<vision::FrameSource> sweep_video(std::size_t index) const;
  /// The true flipper angle of the sweep at time t_s (rad).
  double sweep_angle(std::size_t index, double t_s) const;
  /// Duration of a sweep video (s).
  double sweep_duration_s() const;

  /// `count` rolls from rest at random free places on the table, observed
  /// through the camera model; `stream` picks an independent set.
  std::vector<calibration::GravityRoll> rolls(int count, std::uint64_t stream = 0) const;

 private:
  table::Board nominal_;
  table::Board truth_;
  SimLabOptions options_;
  std::unique_ptr<simlab::SimCameraSource> camera_;
  vision::Frame frame_;
};

}  // namespace pinball::simlab
