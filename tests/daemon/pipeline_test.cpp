// The controller stage's fail-safes against the real DriverBus and the
// reference driver board over a socket pair: commands reach the coils,
// and a stalled camera or a vanished ball releases them.

#include "pinball/daemon/pipeline.h"

#include <gtest/gtest.h>

#include "pinball/firmware/stream_transport.h"
#include "pinball/firmware/virtual_driver_board.h"
#include "pinball/plot/png_file.h"
#include "pinball/table/board_loader.h"
#include "pinball/track/flipper_geometry.h"

namespace pinball::daemon {
namespace {

// Holds the left flipper up whenever the projection is hittable; releases on reset.
class HoldWhenHittable final : public control::FlipperController {
 public:
  void update(const track::TrackerOutput& o, double, std::array<bool, 2>& energized) override {
    if (o.projection.valid && o.projection.hittable) energized[track::kLeftFlipper] = true;
  }
  void reset(std::array<bool, 2>& energized) override { energized = {false, false}; }
};

struct Rig {
  std::unique_ptr<firmware::StreamTransport> host, far;
  std::unique_ptr<firmware::DriverBus> bus;
  firmware::VirtualDriverBoard board{firmware::VirtualDriverBoardOptions{0, 2}};
  HoldWhenHittable controller;
  std::unique_ptr<ControllerStage> stage;
  double t = 0.0;

  Rig() {
    auto pair = firmware::StreamTransport::make_pair();
    host = std::move(pair.first);
    far = std::move(pair.second);
    bus = std::make_unique<firmware::DriverBus>(*host, firmware::DriverBusOptions{});
    ControllerStageOptions o;
    o.stall_timeout_s = 0.02;
    stage = std::make_unique<ControllerStage>(controller, *bus, o);
    for (int i = 0; i < 200 && bus->state() != firmware::BusState::kRunning; ++i) run(0.001);
  }
  // Both ends exchange frames for dt seconds.
  void run(double dt) {
    t += dt;
    bus->poll_once(t);
    board.service(*far, t);
    bus->poll_once(t);
  }
  ProjectionRecord record(bool found, bool hittable) {
    ProjectionRecord r;
    r.seq = seq++;
    r.t_s = t;
    r.found = found;
    r.output.projection.valid = hittable;
    r.output.projection.hittable = hittable;
    return r;
  }
  std::uint64_t seq = 0;
};

TEST(ControllerStage, AFireReachesTheCoil) {
  Rig rig;
  ASSERT_EQ(rig.bus->state(), firmware::BusState::kRunning);
  ControllerStage::Commands cmds;
  const int n = rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds);
  ASSERT_EQ(n, 1);
  EXPECT_TRUE(cmds[0].energize);
  EXPECT_EQ(cmds[0].flipper, track::kLeftFlipper);
  EXPECT_EQ(cmds[0].projection_seq, 0);
  rig.run(0.001);
  EXPECT_NE(rig.board.coil(0).state, firmware::CoilState::kOff);
  // The same wish again gives no second command.
  EXPECT_EQ(rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds), 0);
}

TEST(ControllerStage, CameraStallReleasesWithinOneFramePeriodOfTheTimeout) {
  Rig rig;
  ControllerStage::Commands cmds;
  rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds);
  rig.run(0.001);
  ASSERT_NE(rig.board.coil(0).state, firmware::CoilState::kOff);
  const double last_frame = rig.t;
  const double frame_period = 0.005;
  // The controller thread checks once per frame period while frames are missing.
  double released_at = -1.0;
  for (int i = 0; i < 20 && released_at < 0.0; ++i) {
    rig.run(frame_period);
    if (rig.stage->on_idle(rig.t, 0.0, cmds) > 0) {
      EXPECT_EQ(cmds[0].cause, CommandCause::kCameraStall);
      released_at = rig.t;
    }
  }
  ASSERT_GT(released_at, 0.0);
  EXPECT_GT(released_at - last_frame, 0.02);
  EXPECT_LE(released_at - last_frame, 0.02 + frame_period + 1e-9);
  rig.run(0.001);
  EXPECT_EQ(rig.board.coil(0).state, firmware::CoilState::kOff);
  EXPECT_EQ(rig.stage->counters().camera_stalls, 1u);
  // Nothing held: further silence gives no more commands.
  rig.run(0.1);
  EXPECT_EQ(rig.stage->on_idle(rig.t, 0.0, cmds), 0);
}

TEST(ControllerStage, ABallOutOfSightReleasesAfterTheTimeout) {
  Rig rig;
  ControllerStage::Commands cmds;
  rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds);
  int released = 0;
  double t_release = 0.0;
  const double t_seen = rig.t;
  for (int i = 0; i < 10 && released == 0; ++i) {
    rig.run(0.005);  // frames keep coming, without the ball
    released = rig.stage->on_record(rig.record(false, false), rig.t, 0.0, cmds);
    t_release = rig.t;
  }
  ASSERT_EQ(released, 1);
  EXPECT_EQ(cmds[0].cause, CommandCause::kBallLost);
  EXPECT_FALSE(cmds[0].energize);
  EXPECT_LE(t_release - t_seen, 0.02 + 0.005 + 1e-9);
  rig.run(0.001);
  EXPECT_EQ(rig.board.coil(0).state, firmware::CoilState::kOff);
}

TEST(ControllerStage, AFireWaitsForTheCoilsRecycleTime) {
  Rig rig;
  ControllerStage::Commands cmds;
  rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds);
  rig.run(0.001);
  rig.stage->release_all(CommandCause::kBallLost, rig.t, 0.0, cmds);
  rig.run(0.001);
  // Wanted again 2 ms after the release: held back, then fired once the 10 ms have passed.
  EXPECT_EQ(rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds), 0);
  EXPECT_EQ(rig.stage->counters().deferred, 1u);
  rig.run(0.005);
  EXPECT_EQ(rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds), 0);
  rig.run(0.006);
  ASSERT_EQ(rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds), 1);
  EXPECT_TRUE(cmds[0].energize);
  rig.run(0.001);
  EXPECT_NE(rig.board.coil(0).state, firmware::CoilState::kOff);
  EXPECT_EQ(rig.board.counters().refused_recycle, 0u);
}

TEST(ControllerStage, ReleaseAllSwitchesEverythingOff) {
  Rig rig;
  ControllerStage::Commands cmds;
  rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds);
  rig.run(0.001);
  ASSERT_EQ(rig.stage->release_all(CommandCause::kShutdown, rig.t, 0.0, cmds), 1);
  EXPECT_EQ(cmds[0].flipper, -1);
  rig.run(0.001);
  EXPECT_EQ(rig.board.coil(0).state, firmware::CoilState::kOff);
  EXPECT_FALSE(rig.stage->energized()[0]);
}

TEST(ControllerStage, BusOffIsSurvivedAndCounted) {
  Rig rig;
  ControllerStage::Commands cmds;
  rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds);
  rig.run(0.001);
  // The CAN controller reports bus-off: the host stops, waits, reopens, re-handshakes.
  ASSERT_EQ(rig.far->send(firmware::make_error_frame(0x40 /* CAN_ERR_BUSOFF */)), firmware::TxStatus::kOk);
  rig.run(0.001);
  EXPECT_EQ(rig.bus->state(), firmware::BusState::kBusOff);
  for (int i = 0; i < 500 && rig.bus->state() != firmware::BusState::kRunning; ++i) rig.run(0.001);
  EXPECT_EQ(rig.bus->state(), firmware::BusState::kRunning);
  const firmware::DriverBusCounters k = rig.bus->counters();
  EXPECT_EQ(k.bus_off, 1u);
  EXPECT_EQ(k.reconnects, 1u);
  EXPECT_EQ(rig.board.coil(0).state, firmware::CoilState::kOff);
  // The stage learns of it with the next record, forgets its command, and
  // fires afresh on the next approach.
  EXPECT_TRUE(rig.stage->energized()[0]);
  ASSERT_EQ(rig.stage->on_record(rig.record(true, false), rig.t, 0.0, cmds), 1);
  EXPECT_EQ(cmds[0].cause, CommandCause::kBusFault);
  EXPECT_FALSE(rig.stage->energized()[0]);
  EXPECT_EQ(rig.stage->counters().bus_faults, 1u);
  rig.run(0.02);  // the driver thread runs between records; the coil's recycle time passes
  ASSERT_EQ(rig.stage->on_record(rig.record(true, true), rig.t, 0.0, cmds), 1);
  EXPECT_TRUE(cmds[0].energize);
  rig.run(0.001);
  EXPECT_NE(rig.board.coil(0).state, firmware::CoilState::kOff)
      << "refused: busy " << rig.board.counters().refused_busy << " locked " << rig.board.counters().refused_locked
      << " recycle " << rig.board.counters().refused_recycle << " not armed " << rig.board.counters().refused_not_armed
      << " stale " << rig.board.counters().stale << " dropped " << rig.bus->counters().dropped_not_running;
}

TEST(CameraStage, ForgetsABallOutOfSightAndSaysSo) {
  const table::Board board = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  track::Tracker tracker(track::flipper_geometry_from_board(board), track::TrackerConfig{});
  CameraStage stage(nullptr, tracker, 0.02);
  ProjectionRecord r;
  for (int i = 0; i < 10; ++i) {
    track::Observation o;
    o.t_s = i * 0.005;
    o.p_board = Vec2(0.25, 0.6 - 0.001 * i);
    stage.track(true, o, o.t_s, {}, 0.0, r);
  }
  EXPECT_GT(tracker.history_size(), 0u);
  int lost = 0;
  for (int i = 10; i < 20; ++i) {
    stage.track(false, {}, i * 0.005, {}, 0.0, r);
    lost += r.output.launch.lost ? 1 : 0;
  }
  EXPECT_EQ(lost, 1);
  EXPECT_EQ(tracker.history_size(), 0u);
  EXPECT_EQ(stage.counters().frames, 20u);
  EXPECT_EQ(stage.counters().detections, 10u);
  EXPECT_EQ(stage.counters().track_resets, 1u);
}

TEST(CameraStage, TheTrackerFitsTheExposureDatesAndTheStampGivesTheLatency) {
  // The detector dates each sighting 7 ms before its frame's stamp (the
  // calibrated latency): the tracker must fit those dates, and the record
  // keeps the stamp (lockstep's now) and the 7 ms as the observation's latency.
  const table::Board board = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  track::Tracker tracker(track::flipper_geometry_from_board(board), track::TrackerConfig{});
  CameraStage stage(nullptr, tracker, 0.5);
  ProjectionRecord r;
  const double g = track::TrackerConfig{}.g_mps2;
  for (int i = 0; i < 10; ++i) {
    track::Observation o;
    o.t_s = 1.0 + i * 0.005;
    const double tau = i * 0.005;
    o.p_board = Vec2(0.25 + 0.5 * tau, 0.3 - 2.0 * tau - 0.5 * g * tau * tau);  // free flight
    stage.track(true, o, o.t_s + 0.007, {}, 0.0, r);
    EXPECT_DOUBLE_EQ(r.observation.t_s, o.t_s);
    EXPECT_NEAR(r.observation.latency_s, 0.007, 1e-9);
    EXPECT_DOUBLE_EQ(r.t_s, o.t_s + 0.007);
  }
  ASSERT_TRUE(r.output.fit.valid);
  EXPECT_NEAR(r.output.fit.t_ref_s, 1.045, 1e-9) << "the fit is dated at the exposures, not the stamps";
  EXPECT_NEAR(r.output.projection.latency_s, 0.007, 1e-9);
}

TEST(TrackingSetup, TheCalibrationsLensAndTimingReachTheDetector) {
  const table::Board board = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  calibration::Calibration c;
  c.board = "boards/mit1993.board";
  c.intrinsics = calibration::IntrinsicsCalibration{vision::typical_wide_lens(), "chessboard", 20, 1, 0.12};
  c.camera_timing = calibration::CameraTiming{0.0071, 0.0002, 1e-5, 12};
  const std::string path = ::testing::TempDir() + "/pipeline_lens.yaml";
  calibration::write_calibration(c, path);
  DaemonConfig config;
  config.calibration = path;
  const TrackingSetup setup = tracking_setup_for(config, board);
  ASSERT_TRUE(setup.lens.has_value());
  ASSERT_TRUE(setup.timing.has_value());
  vision::BallDetectorConfig d;
  apply_camera_corrections(setup.lens, setup.timing, config.camera.fps, d);
  ASSERT_TRUE(d.lens.has_value());
  EXPECT_DOUBLE_EQ(d.lens->k1, vision::typical_wide_lens().k1);
  EXPECT_DOUBLE_EQ(d.latency_s, 0.0071);
  EXPECT_DOUBLE_EQ(d.row_time_s, 1e-5);
  EXPECT_EQ(d.dejitter_frames, vision::kDefaultDejitterFrames);  // the latency was measured on the steady clock's dates
  EXPECT_DOUBLE_EQ(d.frame_period_s, 1.0 / config.camera.fps);

  // A lens calibrated on other images than the camera delivers is refused, naming the file.
  config.camera.width_px = 1280;
  config.camera.height_px = 960;
  try {
    tracking_setup_for(config, board);
    FAIL() << "a 640x480 lens on a 1280x960 camera was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":intrinsics.lens.width_px"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1280x960"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

TEST(LabCamera, TheConfigurationReachesTheCapture) {
  CameraSettings camera;
  camera.device = "/dev/video2";
  camera.width_px = 1280;
  camera.height_px = 1024;
  camera.fps = 150.0;
  vision::CaptureConfig cc = capture_config_for(camera);
  EXPECT_EQ(cc.source, "/dev/video2");
  EXPECT_EQ(cc.width_px, 1280);
  EXPECT_EQ(cc.height_px, 1024);
  EXPECT_DOUBLE_EQ(cc.fps, 150.0);
  EXPECT_EQ(cc.fourcc, "");
  EXPECT_LT(cc.exposure_s, 0.0) << "no exposure_s: the driver's automatic exposure is left alone";
  camera.fourcc = "GREY";
  camera.exposure_s = 0.0025;
  cc = capture_config_for(camera);
  EXPECT_EQ(cc.fourcc, "GREY");
  EXPECT_DOUBLE_EQ(cc.exposure_s, 0.0025);
}

TEST(LabCamera, TheOccluderMaskMustBeAnImageOfTheFramesSize) {
  const std::string path = ::testing::TempDir() + "/pipeline_mask.png";
  cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(100, 50, 40, 30)).setTo(255);
  plot::write_png(mask, path);
  const cv::Mat back = load_occluder_mask(path, cv::Size(640, 480), "lab.yaml");
  EXPECT_EQ(cv::norm(back, mask, cv::NORM_INF), 0.0);
  try {
    load_occluder_mask(path, cv::Size(1280, 1024), "lab.yaml");
    FAIL() << "a 640x480 mask for 1280x1024 frames was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "lab.yaml: camera.occluder_mask: " + path + " is 640x480 px, the frames are 1280x1024");
  }
  std::remove(path.c_str());
  try {
    load_occluder_mask(path, cv::Size(640, 480), "lab.yaml");
    FAIL() << "a missing mask was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("lab.yaml: camera.occluder_mask: " + path + ": cannot be read", 0), 0u)
        << e.what();
  }
}

}  // namespace
}  // namespace pinball::daemon
