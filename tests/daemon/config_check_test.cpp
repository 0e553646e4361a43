// pinballd --check: a configuration and its files, loaded as at start,
// without a game, and in the lab the hardware looked for, not opened.

#include "pinball/daemon/config_check.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "pinball/calibration/calibration_file.h"
#include "pinball/daemon/daemon.h"
#include "pinball/plot/png_file.h"

namespace pinball::daemon {
namespace {

namespace fs = std::filesystem;

const std::string kSourceTree = PINBALL_SOURCE_DIR;

std::string check_error(const DaemonConfig& config) {
  try {
    check_daemon_config(config);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// The lab example, with a camera device and a CAN interface no machine has:
// the check finds neither, the same on the lab machine as here.
DaemonConfig lab_without_hardware() {
  DaemonConfig c = load_daemon_config(kSourceTree + "/config/lab.example.yaml");
  c.camera.device = "/dev/pinball-check-no-such-video";
  c.can.interface = "pbnosuch0";
  return c;
}

TEST(ConfigCheck, TheEmbeddedSimulationIsWhatPinballdRunsWithNoArguments) {
  const ConfigCheck c = check_daemon_config(DaemonConfig{});
  EXPECT_EQ(c.mode, "sim");
  EXPECT_EQ(fs::path(c.board).filename(), "mit1993.board");
  EXPECT_EQ(fs::path(c.controller).filename(), "imitation.json");
  EXPECT_EQ(c.controller_kind, "imitation");
  EXPECT_EQ(c.world, "model on the thesis stepper");
  EXPECT_EQ(c.camera, "sim 640x480 at 200 fps");
  EXPECT_EQ(c.can, "sim (the virtual driver board)");
  EXPECT_TRUE(c.warnings.empty());
  const nlohmann::json j = config_check_to_json(c);
  EXPECT_TRUE(j.at("ok").get<bool>());
  EXPECT_TRUE(j.at("calibration").is_null());
  EXPECT_EQ(j.at("controller_kind"), "imitation");
  const std::string text = config_check_to_text(c);
  EXPECT_NE(text.find("controller       " + c.controller + " (imitation)\n"), std::string::npos) << text;
  EXPECT_NE(text.find("ok: the configuration and every file it names load\n"), std::string::npos) << text;
}

// What the start would warn of, the check says first.
TEST(ConfigCheck, SaysTheWarningsTheStartWouldPrint) {
  DaemonConfig slow;
  slow.camera.fps = 5.0;
  slow.camera.stall_timeout_s = 0.5;
  const ConfigCheck c = check_daemon_config(slow);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_EQ(c.warnings[0], sim_watchdog_warning(slow));
  EXPECT_NE(config_check_to_text(c).find("warning          camera.fps 5: "), std::string::npos);
}

TEST(ConfigCheck, TheTwinAndTheSpasticFileAreLoadedToo) {
  DaemonConfig c;
  c.sim.world = simlab::WorldKind::kTwin;
  c.controller = "controllers/spastic.json";
  const ConfigCheck check = check_daemon_config(c);
  EXPECT_EQ(check.world, "twin");
  EXPECT_EQ(check.controller_kind, "spastic");
  c.sim.twin_params = kSourceTree + "/tests/bad_input/twin/empty.yaml";
  EXPECT_NE(check_error(c), "") << "a bad twin parameter file is refused";
}

TEST(ConfigCheck, InTheLabEveryMissingPieceOfHardwareIsNamedAtOnce) {
  const std::string what = check_error(lab_without_hardware());
  EXPECT_EQ(what.rfind(kSourceTree + "/config/lab.example.yaml: camera.device", 0), 0u) << what;
  EXPECT_NE(what.find("camera.device: /dev/pinball-check-no-such-video: no such camera device"), std::string::npos)
      << what;
  EXPECT_NE(what.find("can.interface: no interface pbnosuch0"), std::string::npos) << what;
}

// A recording as the lab camera: a file that is no video is found out by
// the check, as the start would find it.
TEST(ConfigCheck, ARecordedCameraThatIsNoVideoFailsTheCheck) {
  DaemonConfig c = lab_without_hardware();
  c.camera.source = "file";
  c.camera.device = kSourceTree + "/README.md";
  const std::string what = check_error(c);
  EXPECT_NE(what.find("camera.device: capture: cannot open video file '" + c.camera.device + "'"), std::string::npos)
      << what;
}

// An LCM provider with no connection (a tcpq:// server that is not listening)
// failed only the start; the check opens it too (a file:// log it leaves alone).
TEST(ConfigCheck, AnLcmServerThatIsNotListeningFailsTheCheck) {
  DaemonConfig c;
  c.lcm_url = "tcpq://127.0.0.1:1";  // port 1: nobody listens there
  EXPECT_EQ(check_error(c), "the command line: lcm_url: lcm: cannot open 'tcpq://127.0.0.1:1': the provider has no "
                            "connection (tcpq://: is the server listening? udpm://: is the port a real one, and "
                            "multicast routed?)");
  const std::string log = ::testing::TempDir() + "/config_check_lcm_" + std::to_string(::getpid()) + ".lcmlog";
  c.lcm_url = "file://" + log + "?mode=w";
  EXPECT_EQ(check_error(c), "");
  EXPECT_FALSE(fs::exists(log)) << "the check wrote the log";
}

// Three grey frames as an MJPG video of this rate and size: a recording to stand in for the lab's camera.
std::string grey_video(const std::string& name, double fps, cv::Size size) {
  const std::string path = ::testing::TempDir() + "/config_check_" + name + "_" + std::to_string(::getpid()) + ".avi";
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, size);
  EXPECT_TRUE(writer.isOpened()) << path;
  const cv::Mat grey(size, CV_8UC3, cv::Scalar(40, 40, 40));
  for (int i = 0; i < 3; ++i) writer.write(grey);
  return path;
}

// A recording of another frame size than the configuration's: the check says
// so, as the start does (it was found only at the start).
TEST(ConfigCheck, ARecordedCameraOfAnotherFrameSizeFailsTheCheck) {
  DaemonConfig c = lab_without_hardware();
  c.camera.source = "file";
  c.camera.device = grey_video("320x240", 30.0, cv::Size(320, 240));
  const std::string what = check_error(c);
  EXPECT_NE(what.find("camera.device: video file " + c.camera.device + " 320x240 at 30 fps"), std::string::npos)
      << what;
  EXPECT_NE(what.find(": not the 640x480 px of camera.width_px x camera.height_px"), std::string::npos) << what;
  fs::remove(c.camera.device);
}

// A recording (or a camera) at another rate than camera.fps: the frame clock's correction runs on
// 1/camera.fps, and 120 frames/s taken for 200 had dated every frame 0.2 s early.
TEST(ConfigCheck, ARecordedCameraOfAnotherFrameRateFailsTheCheck) {
  DaemonConfig c = lab_without_hardware();
  c.camera.source = "file";
  c.camera.device = grey_video("30fps", 30.0, cv::Size(640, 480));
  ASSERT_EQ(c.camera.fps, 200.0);
  const std::string what = check_error(c);
  EXPECT_NE(what.find("camera.device: video file " + c.camera.device + " 640x480 at 30 fps: not the 200 frames/s of "
                      "camera.fps"),
            std::string::npos)
      << what;
  c.camera.fps = 30.0;
  EXPECT_EQ(check_error(c).find("frames/s"), std::string::npos) << check_error(c);
  fs::remove(c.camera.device);
}

// The command line's CAN log is checked as the file's would be, and a failed
// check is still one JSON object.
TEST(ConfigCheck, ACanLogThatCannotBeWrittenFailsTheCheck) {
  DaemonConfig c;
  c.can.log = "/nonexistent-pinball-folder/can.log";
  const std::string what = check_error(c);
  EXPECT_EQ(what, "the command line: can.log: '/nonexistent-pinball-folder/can.log': its folder "
                  "/nonexistent-pinball-folder does not exist");
  const nlohmann::json j = config_check_failure_to_json(what);
  EXPECT_FALSE(j.at("ok").get<bool>());
  EXPECT_EQ(j.at("error"), what);
}

// A homography or a lens measured on images of another size would map nothing onto these
// frames: the game played blind, exit 0 (found in sim with 320x240 frames).
TEST(ConfigCheck, TheCalibrationMustBeOfTheFramesSize) {
  DaemonConfig c;
  c.calibration = kSourceTree + "/calibration/lab.example.yaml";  // measured on 640x480
  c.camera.width_px = 320;
  c.camera.height_px = 240;
  EXPECT_EQ(check_error(c), c.calibration +
                                ":camera.image_width_px: the camera's homography was calibrated on 640x480 images but "
                                "camera.width_px x camera.height_px is 320x240");
  c.camera.width_px = 640;
  c.camera.height_px = 480;
  EXPECT_EQ(check_error(c), "");
}

TEST(ConfigCheck, ALabCameraNeedsTheCalibrationsHomographyAndAMaskOfItsSize) {
  DaemonConfig c = lab_without_hardware();
  calibration::Calibration no_camera = calibration::read_calibration(c.calibration);
  no_camera.camera.reset();
  const std::string cal = ::testing::TempDir() + "/config_check_cal.yaml";
  calibration::write_calibration(no_camera, cal);
  DaemonConfig without = c;
  without.calibration = cal;
  // Checked after loading, and still named by the file they came from.
  const std::string file = kSourceTree + "/config/lab.example.yaml";
  EXPECT_EQ(check_error(without), file + ": calibration: the lab camera needs a calibration file with a camera "
                                         "section (docs/calibration.md)");
  fs::remove(cal);

  const std::string mask = ::testing::TempDir() + "/config_check_mask.png";
  plot::write_png(cv::Mat(240, 320, CV_8UC1, cv::Scalar(0)), mask);
  c.camera.occluder_mask = mask;
  EXPECT_EQ(check_error(c), file + ": camera.occluder_mask: " + mask + " is 320x240 px, the frames are 640x480");
  fs::remove(mask);
}

}  // namespace
}  // namespace pinball::daemon
