#pragma once
// The daemon's two hot stages as plain classes, free of threads and clocks so
// that the lab, the embedded simulation, `pinball replay` and the tests drive
// the same code:
//   CameraStage:     frame -> BallDetector -> Tracker -> ProjectionRecord
//   ControllerStage: ProjectionRecord -> FlipperController -> DriverBus
// Neither allocates after construction.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>

#include "pinball/calibration/calibration_file.h"
#include "pinball/control/controller_file.h"
#include "pinball/control/flipper_controller.h"
#include "pinball/core/single_writer_counter.h"
#include "pinball/daemon/daemon_config.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/table/board.h"
#include "pinball/track/observation.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/track/tracker.h"
#include "pinball/vision/camera_homography.h"
#include "pinball/vision/ball_detector.h"
#include "pinball/vision/capture_source.h"
#include "pinball/vision/frame.h"

namespace pinball::daemon {

/// What the camera thread hands the controller thread for every frame, with
/// the wall-clock stamps of each stage (steady clock, s) for the latency table.
struct ProjectionRecord {
  std::uint64_t seq = 0;           ///< projection number (one per frame)
  std::uint64_t frame_seq = 0;     ///< the frame's sequence number
  double t_s = 0.0;                ///< the frame's stamp on the pipeline's clock (s): when it was had
                                   ///< (lockstep's now); the ball's exposure date is observation.t_s
  bool found = false;              ///< the detector saw the ball
  track::Observation observation;  ///< where (valid when found)
  double u_px = 0.0;               ///< image position (valid when found)
  double v_px = 0.0;               ///< image position (valid when found)
  track::ContactSensors contacts;  ///< flipper contact sensors read with the frame
  track::TrackerOutput output;     ///< the tracker's answer (projection invalid when not found)
  double capture_wall_s = 0.0;     ///< steady clock when the frame was handed over
  double detected_wall_s = 0.0;    ///< ... when detection finished
  double projected_wall_s = 0.0;   ///< ... when the tracker finished
};

/// Why a command was given (the lcmt_pinball_flipper_command cause codes).
enum class CommandCause : std::int8_t {
  kProjection = 0,  ///< the controller acted on a projection
  kLaunch = 1,      ///< a launch was seen: release (thesis 5.2.3)
  kBallLost = 2,    ///< the ball was lost or left the camera's view
  kCameraStall = 3, ///< no frame within the stall timeout
  kShutdown = 4,    ///< the daemon is stopping
  kBusFault = 5,    ///< the CAN link failed
};

/// One solenoid command as given (for LCM and the latency table).
struct CommandRecord {
  std::uint64_t seq = 0;             ///< command number
  std::int64_t projection_seq = -1;  ///< the projection behind it, -1 for timeouts and shutdown
  int flipper = -1;                  ///< track::kLeftFlipper / kRightFlipper, -1: all
  bool energize = false;             ///< fire (true) or release (false)
  CommandCause cause = CommandCause::kProjection;  ///< why
  double t_s = 0.0;                  ///< pipeline clock (s)
  double capture_wall_s = 0.0;       ///< steady clock of the frame behind it (0: none)
  double command_wall_s = 0.0;       ///< steady clock when DriverBus accepted it
  double written_wall_s = 0.0;       ///< steady clock when its CAN frame was written (0: not yet)
};

/// Counters of the camera stage.
struct CameraStageCounters {
  std::uint64_t frames = 0;       ///< frames processed
  std::uint64_t detections = 0;   ///< frames with a ball
  std::uint64_t projections = 0;  ///< valid projections
  std::uint64_t track_resets = 0; ///< tracker reset because the ball was out of sight
};

/// Detector and tracker for one camera.
class CameraStage {
 public:
  /// Borrows both; `detector` may be null when only track() is used. `lost_after_s`: a ball unseen this long is forgotten (the
  /// tracker starts afresh with the next sighting).
  CameraStage(vision::BallDetector* detector, track::Tracker& tracker, double lost_after_s);

  /// Detects and tracks one frame; fills `out` (seq, times, detection, output).
  void process(const vision::Frame& frame, const track::ContactSensors& contacts, double capture_wall_s,
               ProjectionRecord& out);
  /// Tracks one observation made elsewhere (LCM, a replayed log). `t_s` is
  /// the frame's stamp, when the pipeline had it; the observation's own t_s
  /// is the ball's exposure date, which the tracker fits, and the stamp less
  /// it becomes its latency_s. `found` false is a frame without the ball.
  void track(bool found, const track::Observation& observation, double t_s, const track::ContactSensors& contacts,
             double capture_wall_s, ProjectionRecord& out);
  /// Counters so far (from any thread).
  CameraStageCounters counters() const {
    return {frames_.load(), detections_.load(), projections_.load(), track_resets_.load()};
  }

 private:
  vision::BallDetector* detector_;
  track::Tracker& tracker_;
  double lost_after_s_;
  double last_seen_t_s_ = -1e300;
  bool tracking_ = false;
  std::uint64_t seq_ = 0;
  SingleWriterCounter frames_, detections_, projections_, track_resets_;  // CameraStageCounters, live
};

/// Settings of the controller stage.
struct ControllerStageOptions {
  /// Release every flipper when no frame has arrived for this long, or the
  /// ball has not been seen for this long while a flipper is up (s).
  double stall_timeout_s = 0.02;
  /// Board driver of tracker flipper f (flipper i of the board is driver i).
  std::array<int, 2> driver_of_flipper{0, 1};
  /// The coils' recycle time (s): a fire this soon after a release would be
  /// refused by the board, so it waits (PROTOCOL.md, Configure.recycle_ms).
  double recycle_s = 0.010;
};

/// Counters of the controller stage.
struct ControllerStageCounters {
  std::uint64_t projections = 0;     ///< records handled
  std::uint64_t commands = 0;        ///< commands given
  std::uint64_t refused = 0;         ///< commands DriverBus refused (queue full, not running)
  std::uint64_t camera_stalls = 0;   ///< releases because frames stopped
  std::uint64_t ball_lost = 0;       ///< releases because the ball was out of sight
  std::uint64_t bus_faults = 0;      ///< releases because the CAN session dropped or the coils were dropped under it
  std::uint64_t deferred = 0;        ///< fires held back until the coil's recycle time had passed
};

/// The action side: flipper commands from projections, with the fail-safes.
class ControllerStage {
 public:
  /// At most this many commands per call.
  static constexpr int kMaxCommands = 4;
  using Commands = std::array<CommandRecord, kMaxCommands>;

  /// Borrows the controller and the bus.
  ControllerStage(control::FlipperController& controller, firmware::DriverBus& bus,
                  const ControllerStageOptions& options = {});

  /// Acts on one record at pipeline time `now_s`; returns the number of
  /// commands written to `out`. When the CAN session has dropped since the
  /// last call (bus-off, no Status), the bus has already made the coils safe:
  /// the stage forgets its commands (a kBusFault release) so that the next
  /// approach fires afresh once the session is back.
  int on_record(const ProjectionRecord& record, double now_s, double now_wall_s, Commands& out);
  /// Call when no record has arrived: releases every flipper once frames have
  /// been missing for the stall timeout. Returns the commands written.
  int on_idle(double now_s, double now_wall_s, Commands& out);
  /// Releases every flipper at once (shutdown, bus fault); returns the commands written.
  int release_all(CommandCause cause, double now_s, double now_wall_s, Commands& out);
  /// Commands in force (true: energised), per tracker flipper.
  const std::array<bool, 2>& energized() const { return energized_; }
  /// Counters so far (from any thread: the LCM thread reports them while the stage runs).
  ControllerStageCounters counters() const {
    return {projections_.load(), commands_.load(), refused_.load(), camera_stalls_.load(),
            ball_lost_.load(),   bus_faults_.load(), deferred_.load()};
  }
  /// The settings.
  const ControllerStageOptions& options() const { return options_; }

 private:
  int apply(const std::array<bool, 2>& want, CommandCause cause, std::int64_t projection_seq, double now_s,
            double capture_wall_s, double now_wall_s, Commands& out);
  control::FlipperController& controller_;
  firmware::DriverBus& bus_;
  ControllerStageOptions options_;
  std::array<bool, 2> energized_{};  // commands given to the bus
  std::array<bool, 2> wanted_{};     // the controller's commands
  std::array<double, 2> released_at_s_{-1e300, -1e300};  // last release per flipper (pipeline clock)
  double last_record_t_s_ = -1e300;
  double last_seen_t_s_ = -1e300;
  bool started_ = false;
  bool bus_was_running_ = false;
  std::uint64_t sessions_seen_ = 0;
  std::uint64_t coils_dropped_seen_ = 0;
  std::uint64_t seq_ = 0;
  SingleWriterCounter projections_, commands_, refused_, camera_stalls_, ball_lost_, bus_faults_,
      deferred_;  // ControllerStageCounters, live
};

/// What the tracker and the detector believe about the table: the board's
/// geometry, corrected by the calibration file when the configuration names
/// one (flippers, g, camera homography). Shared by pinballd and `pinball
/// replay`, so that a replay decides as the daemon did.
struct TrackingSetup {
  track::TrackerConfig tracker;                      ///< g, windows, critical area
  track::FlipperGeometry geometry;                   ///< flipper lines the projections use
  std::optional<vision::CameraHomography> homography;  ///< from the calibration's camera section, if any
  std::optional<vision::CameraIntrinsics> lens;        ///< from its intrinsics section, if any
  std::optional<calibration::CameraTiming> timing;     ///< from its camera_timing section, if any
};

/// The detector's corrections for a camera with this lens and timing (either may be
/// absent): the lens undistorts the centroid; with a timing the frames are dated by the
/// camera's steady clock (vision::kDefaultDejitterFrames) less the latency, plus the ball's row's time.
void apply_camera_corrections(const std::optional<vision::CameraIntrinsics>& lens,
                              const std::optional<calibration::CameraTiming>& timing, double fps,
                              vision::BallDetectorConfig& config);
/// What pinballd asks of a lab camera (camera.source v4l2 or file): the
/// device, the requested size and rate, the pixel format and a fixed
/// exposure (camera.exposure_s < 0: the driver's automatic exposure, left
/// as it is).
vision::CaptureConfig capture_config_for(const CameraSettings& camera);
/// The lab camera, opened as capture_config_for asks. Throws runtime_error
/// when its frames are not camera.width_px x camera.height_px (a recording
/// of another size, or a device that would not take the size): the detector,
/// the mask and the homography all take frames of the configured size.
std::unique_ptr<vision::CaptureSource> open_lab_camera(const CameraSettings& camera);
/// The occluder mask camera.occluder_mask names, white where plastics hide
/// the playfield. Throws ConfigError naming the configuration (`origin`), the
/// key and the file when it is not an image or not `frame_size`.
cv::Mat load_occluder_mask(const std::string& path, cv::Size frame_size, const std::string& origin);

/// What a configuration names, loaded and checked as pinballd starts, before
/// it opens anything: the belief board with its overlay, the controller file,
/// the tracking setup from the calibration and the occluder mask. A lab
/// camera needs the calibration's homography (ConfigError without one).
/// `config`'s paths must be found already (find_data_files).
struct DaemonInputs {
  table::Board board;
  control::ControllerSpec spec;
  TrackingSetup setup;
  cv::Mat occluder_mask;  ///< CV_8U; empty: none
};
DaemonInputs load_daemon_inputs(const DaemonConfig& config);

/// The setup for `config` on `board` (the table's board file). Throws
/// std::runtime_error naming the calibration file and key when it is bad or
/// calibrates a flipper the board lacks.
TrackingSetup tracking_setup_for(const DaemonConfig& config, const table::Board& board);
/// The controller stage's settings for `config` on `board`.
ControllerStageOptions controller_stage_options_for(const DaemonConfig& config, const table::Board& board);
/// How long the camera stage keeps an unseen ball before forgetting it (s).
double lost_after_s_for(const DaemonConfig& config);
/// The driver bus's settings for `config` with `drivers` coils: its board id,
/// the coils' timings, the heartbeat and the board's watchdog (pinballd's,
/// and `calibrate latency --config`'s, so that both fire the same board alike).
firmware::DriverBusOptions driver_bus_options_for(const DaemonConfig& config, int drivers);

}  // namespace pinball::daemon
