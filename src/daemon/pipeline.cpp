#include "pinball/daemon/pipeline.h"

#include <algorithm>
#include <cmath>

#include "pinball/calibration/calibration_file.h"
#include "pinball/core/utime.h"
#include "pinball/core/clock.h"
#include "pinball/core/format.h"
#include "pinball/plot/png_file.h"
#include "pinball/table/board_overlay.h"

namespace pinball::daemon {

CameraStage::CameraStage(vision::BallDetector* detector, track::Tracker& tracker, double lost_after_s)
    : detector_(detector), tracker_(tracker), lost_after_s_(lost_after_s) {}

void CameraStage::process(const vision::Frame& frame, const track::ContactSensors& contacts, double capture_wall_s,
                          ProjectionRecord& out) {
  const vision::Detection d = detector_->detect(frame);
  const double detected_wall_s = steady_now_s();
  out.u_px = d.found ? d.uv_px.x : 0.0;
  out.v_px = d.found ? d.uv_px.y : 0.0;
  track(d.found, d.observation, frame.t_s, contacts, capture_wall_s, out);
  out.frame_seq = frame.sequence;
  out.detected_wall_s = detected_wall_s;
}

void CameraStage::track(bool found, const track::Observation& observation, double t_s,
                        const track::ContactSensors& contacts, double capture_wall_s, ProjectionRecord& out) {
  // Whole microseconds, as the observation travels on LCM: a replayed log
  // then gives the tracker exactly the times it had live.
  t_s = utime_rounded(t_s);
  out.seq = seq_++;
  out.frame_seq = out.seq;
  out.t_s = t_s;
  out.contacts = contacts;
  out.capture_wall_s = capture_wall_s;
  out.found = found;
  frames_.add();
  if (found) {
    detections_.add();
    out.observation = observation;
    // The tracker fits the detector's exposure dates (calibrated latency,
    // rolling shutter, the camera's steady clock); the stamp less that date
    // is the latency a leading controller adds to its lead.
    out.observation.t_s = utime_rounded(observation.t_s);
    out.observation.latency_s = std::max(0.0, t_s - out.observation.t_s);
    last_seen_t_s_ = t_s;
    tracking_ = true;
    out.output = tracker_.update(out.observation, contacts);
    if (out.output.projection.valid) projections_.add();
    return;
  }
  out.output = track::TrackerOutput{};
  if (tracking_ && t_s - last_seen_t_s_ > lost_after_s_) {
    // Out of sight for too long (drained, or hidden): the next sighting is a new trajectory.
    tracker_.reset();
    tracking_ = false;
    track_resets_.add();
    out.output.launch.lost = true;
  }
}

ControllerStage::ControllerStage(control::FlipperController& controller, firmware::DriverBus& bus,
                                 const ControllerStageOptions& options)
    : controller_(controller), bus_(bus), options_(options) {}

int ControllerStage::on_record(const ProjectionRecord& record, double now_s, double now_wall_s, Commands& out) {
  projections_.add();
  started_ = true;
  // A session that dropped or restarted since the last record has lost our
  // commands, and so has a coil the board or the bus switched off on its own
  // (watchdog, hold cap, a stalled chain, a Release that had to be escalated).
  const bool running = bus_.state() == firmware::BusState::kRunning;
  const firmware::DriverBusCounters bc = bus_.counters();
  const bool dropped = (bus_was_running_ && !running) || (sessions_seen_ != 0 && bc.sessions != sessions_seen_) ||
                       bc.coils_dropped != coils_dropped_seen_;
  bus_was_running_ = running;
  sessions_seen_ = bc.sessions;
  coils_dropped_seen_ = bc.coils_dropped;
  if (dropped) {
    bus_faults_.add();
    if (energized_[0] || energized_[1]) {
      controller_.reset(wanted_);
      return release_all(CommandCause::kBusFault, now_s, now_wall_s, out);
    }
  }
  last_record_t_s_ = now_s;
  CommandCause cause = CommandCause::kProjection;
  if (record.found) {
    last_seen_t_s_ = record.t_s;
    controller_.update(record.output, record.t_s, wanted_);
    if (record.output.launch.launched) cause = CommandCause::kLaunch;
    if (record.output.launch.lost) cause = CommandCause::kBallLost;
  } else if (record.output.launch.lost) {
    controller_.reset(wanted_);  // the camera stage gave the ball up
    cause = CommandCause::kBallLost;
  } else if ((wanted_[0] || wanted_[1]) && record.t_s - last_seen_t_s_ > options_.stall_timeout_s) {
    // A flipper is up and the ball has not been seen for the timeout: let go.
    controller_.reset(wanted_);
    ball_lost_.add();
    cause = CommandCause::kBallLost;
  }
  return apply(wanted_, cause, static_cast<std::int64_t>(record.seq), now_s, record.capture_wall_s, now_wall_s, out);
}

int ControllerStage::on_idle(double now_s, double now_wall_s, Commands& out) {
  if (!started_ || now_s - last_record_t_s_ <= options_.stall_timeout_s) return 0;
  if (!energized_[0] && !energized_[1]) return 0;
  camera_stalls_.add();
  controller_.reset(wanted_);
  return release_all(CommandCause::kCameraStall, now_s, now_wall_s, out);
}

int ControllerStage::release_all(CommandCause cause, double now_s, double now_wall_s, Commands& out) {
  bus_.release_all();  // takes priority over anything queued
  wanted_ = {false, false};
  for (std::size_t f = 0; f < 2; ++f) {
    if (energized_[f]) released_at_s_[f] = now_s;
  }
  int n = 0;
  CommandRecord& c = out[static_cast<std::size_t>(n++)];
  c = CommandRecord{seq_++, -1, -1, false, cause, now_s, 0.0, now_wall_s};
  energized_ = {false, false};
  commands_.add();
  return n;
}

int ControllerStage::apply(const std::array<bool, 2>& want, CommandCause cause, std::int64_t projection_seq,
                           double now_s, double capture_wall_s, double now_wall_s, Commands& out) {
  int n = 0;
  for (int f = 0; f < 2; ++f) {
    if (want[static_cast<std::size_t>(f)] == energized_[static_cast<std::size_t>(f)]) continue;
    const bool on = want[static_cast<std::size_t>(f)];
    // The board measures the recycle time on its own clock; a millisecond of
    // margin covers the hand-off to the driver thread.
    if (on && now_s - released_at_s_[static_cast<std::size_t>(f)] < options_.recycle_s + 1e-3) {
      deferred_.add();  // the next record fires it, once the coil may be fired again
      continue;
    }
    const int driver = options_.driver_of_flipper[static_cast<std::size_t>(f)];
    const bool accepted = on ? bus_.fire(driver) : bus_.release(driver);
    if (!accepted) {
      refused_.add();
      if (on) continue;     // a refused fire is tried again on the next record
      bus_.release_all();   // a release must not be lost: this one cannot be refused
    }
    energized_[static_cast<std::size_t>(f)] = on;
    if (!on) released_at_s_[static_cast<std::size_t>(f)] = now_s;
    commands_.add();
    out[static_cast<std::size_t>(n++)] =
        CommandRecord{seq_++, projection_seq, f, on, on ? CommandCause::kProjection : cause, now_s, capture_wall_s,
                      now_wall_s};
  }
  return n;
}

DaemonInputs load_daemon_inputs(const DaemonConfig& config) {
  const bool sim = config.mode == "sim";
  DaemonInputs in;
  in.board = table::load_belief_board(sim ? config.sim.board : config.board, config.identified);
  in.spec = control::load_controller(config.controller);
  if (sim) control::check_controller_launch(in.spec, in.board, config.controller);  // a lab launches by hand
  in.setup = tracking_setup_for(config, in.board);
  if (!sim && config.camera.source != "lcm" && !in.setup.homography) {
    throw ConfigError(config.origin + ": calibration: the lab camera needs a calibration file with a camera section "
                      "(docs/calibration.md)");
  }
  if (!config.camera.occluder_mask.empty()) {
    in.occluder_mask = load_occluder_mask(config.camera.occluder_mask,
                                          cv::Size(config.camera.width_px, config.camera.height_px), config.origin);
  }
  return in;
}

TrackingSetup tracking_setup_for(const DaemonConfig& config, const table::Board& board) {
  track::CameraModelConfig camera_model;
  camera_model.fps = config.camera.fps;
  TrackingSetup s{track::default_tracker_config(board, camera_model), track::flipper_geometry_from_board(board), {}, {}, {}};
  if (!config.calibration.empty()) {
    const calibration::Calibration c = calibration::read_calibration(config.calibration);
    calibration::check_calibration_matches_board(c, config.calibration, board);  // a misnamed flipper is refused
    calibration::apply_calibration(c, config.calibration, s.tracker, s.geometry);
    // A section measured on images of another size maps nothing onto these frames: the game
    // would play blind (found: a 640x480 homography with 320x240 frames, exit 0, no ball seen).
    const auto require_frame_size = [&](const std::string& key, const std::string& what, int width_px,
                                        int height_px) {
      if (width_px == config.camera.width_px && height_px == config.camera.height_px) return;
      throw std::runtime_error(config.calibration + ":" + key + ": " + what + " was calibrated on " +
                               std::to_string(width_px) + "x" + std::to_string(height_px) +
                               " images but camera.width_px x camera.height_px is " +
                               std::to_string(config.camera.width_px) + "x" + std::to_string(config.camera.height_px));
    };
    if (c.camera) {
      require_frame_size("camera.image_width_px", "the camera's homography", c.camera->image_width_px,
                         c.camera->image_height_px);
      s.homography = calibration::camera_homography(c, config.calibration);
    }
    if (c.intrinsics) {
      const vision::CameraIntrinsics& lens = c.intrinsics->lens;
      require_frame_size("intrinsics.lens.width_px", "the lens", lens.width_px, lens.height_px);
      s.lens = lens;
    }
    s.timing = c.camera_timing;
  }
  return s;
}

void apply_camera_corrections(const std::optional<vision::CameraIntrinsics>& lens,
                              const std::optional<calibration::CameraTiming>& timing, double fps,
                              vision::BallDetectorConfig& config) {
  config.lens = lens;
  if (!timing) return;
  config.latency_s = timing->latency_s;
  config.row_time_s = timing->row_time_s;
  // The latency is measured on the steady clock's dates (pinball calibrate latency), so date frames by it.
  config.dejitter_frames = vision::kDefaultDejitterFrames;
  config.frame_period_s = 1.0 / fps;
}

vision::CaptureConfig capture_config_for(const CameraSettings& camera) {
  vision::CaptureConfig cc;
  cc.source = camera.device;
  cc.width_px = camera.width_px;
  cc.height_px = camera.height_px;
  cc.fps = camera.fps;
  cc.fourcc = camera.fourcc;
  cc.exposure_s = camera.exposure_s;
  cc.pace_file = true;  // a recorded video plays as the camera delivered it
  return cc;
}

std::unique_ptr<vision::CaptureSource> open_lab_camera(const CameraSettings& camera) {
  auto capture = std::make_unique<vision::CaptureSource>(capture_config_for(camera));
  const cv::Size wanted(camera.width_px, camera.height_px);
  if (capture->frame_size() != wanted) {
    throw std::runtime_error(capture->describe() + ": not the " + std::to_string(wanted.width) + "x" +
                             std::to_string(wanted.height) +
                             " px of camera.width_px x camera.height_px; the detector, the mask and the "
                             "calibration take frames of that size");
  }
  // The frame clock's correction runs on 1/camera.fps: a camera that grants another rate than asked
  // (120 for 200) dated every frame 0.2 s early, and the controller led by as much.
  if (std::abs(capture->fps() - camera.fps) > 0.01 * camera.fps) {
    throw std::runtime_error(capture->describe() + ": not the " + format_number(camera.fps) +
                             " frames/s of camera.fps; set camera.fps to the rate it gives (a camera: "
                             "v4l2-ctl --list-formats-ext lists its rates at each size)");
  }
  return capture;
}

cv::Mat load_occluder_mask(const std::string& path, cv::Size frame_size, const std::string& origin) {
  cv::Mat mask;
  try {
    mask = plot::read_gray_image(path);
  } catch (const std::runtime_error& e) {
    throw ConfigError(origin + ": camera.occluder_mask: " + e.what());
  }
  if (mask.size() != frame_size) {
    throw ConfigError(origin + ": camera.occluder_mask: " + path + " is " + std::to_string(mask.cols) + "x" +
                      std::to_string(mask.rows) + " px, the frames are " + std::to_string(frame_size.width) + "x" +
                      std::to_string(frame_size.height));
  }
  return mask;
}

ControllerStageOptions controller_stage_options_for(const DaemonConfig& config, const table::Board& board) {
  ControllerStageOptions o;
  o.stall_timeout_s = config.camera.stall_timeout_s;
  o.recycle_s = config.coils.recycle_ms * 1e-3;
  o.driver_of_flipper = table::flippers_by_side(board);
  return o;
}

firmware::DriverBusOptions driver_bus_options_for(const DaemonConfig& c, int drivers) {
  firmware::DriverBusOptions o;
  o.board_id = static_cast<std::uint8_t>(c.can.board_id);
  o.driver_count = drivers;
  for (auto& d : o.drivers) d = c.coils;
  o.heartbeat_period_s = c.can.heartbeat_period_s;
  o.watchdog_timeout_s = c.can.watchdog_timeout_s;
  return o;
}

double lost_after_s_for(const DaemonConfig& config) {
  // A ball unseen for the stall timeout plus 4 frame periods is gone.
  return config.camera.stall_timeout_s + 4.0 / config.camera.fps;
}

}  // namespace pinball::daemon
