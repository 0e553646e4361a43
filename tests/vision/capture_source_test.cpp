#include "pinball/vision/capture_source.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "pinball/core/clock.h"
#include "pinball/table/board_loader.h"
#include "pinball/vision/ball_detector.h"
#include "pinball/simlab/sim_camera_source.h"

namespace pinball::vision {
namespace {

namespace fs = std::filesystem;

fs::path temp_path(const std::string& name) {
  return fs::temp_directory_path() / ("pinball_vision_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                      "_" + name);
}

CaptureConfig source(const std::string& name) {
  CaptureConfig c;
  c.source = name;
  return c;
}

// Expects `f` to throw std::runtime_error whose message contains `needle`.
template <class F>
void expect_error_naming(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(CaptureSource, TellsDevicesFromFiles) {
  EXPECT_TRUE(is_device_source("0"));
  EXPECT_TRUE(is_device_source("/dev/video2"));
  EXPECT_FALSE(is_device_source("play.avi"));
  EXPECT_FALSE(is_device_source("/tmp/0.avi"));
}

TEST(CaptureSource, AMissingDeviceIsNamedBeforeAnythingIsOpened) {
  EXPECT_EQ(missing_camera_device("/dev/pinball-no-such-video"), "/dev/pinball-no-such-video: no such camera device");
  EXPECT_EQ(missing_camera_device("/dev/null"), "");  // there: whether it is a camera is V4L2's to say
  EXPECT_EQ(missing_camera_device("0"), "");          // an index: V4L2 resolves it
  EXPECT_EQ(missing_camera_device("play.avi"), "");   // a file is not a device
}

TEST(CaptureSource, AnExposureIsSetInV4l2sStepsOf100Microseconds) {
  EXPECT_DOUBLE_EQ(v4l2_exposure_units(0.002), 20.0);
  EXPECT_DOUBLE_EQ(v4l2_exposure_units(0.00249), 25.0);  // rounded to the nearest step
  EXPECT_DOUBLE_EQ(v4l2_exposure_units(1e-6), 1.0);      // shorter than a step: the shortest the driver has
  EXPECT_DOUBLE_EQ(v4l2_exposure_units(1.0), 10000.0);
}

TEST(CaptureSource, MissingOrUnreadableSourcesGiveAClearError) {
  expect_error_naming([] { CaptureSource(source("/nonexistent/dir/play.avi")); }, "/nonexistent/dir/play.avi");
  expect_error_naming([] { CaptureSource(source("/dev/video97")); }, "/dev/video97");
  expect_error_naming([] { CaptureSource(source("")); }, "no camera device or video file");
  const fs::path junk = temp_path("junk.avi");
  {
    std::ofstream out(junk);
    out << "this is not a video\n";
  }
  expect_error_naming([&] { CaptureSource(source(junk.string())); }, junk.string());
  fs::remove(junk);
}

TEST(CaptureSource, ReadsARealCameraWhenThereIsOne) {
  if (!fs::exists("/dev/video0")) {
    GTEST_SKIP() << "no V4L2 camera on this machine (/dev/video0 absent); the file path below covers the code";
  }
  CaptureConfig c = source("/dev/video0");
  c.fps = 30.0;
  CaptureSource camera(c);
  Frame frame;
  ASSERT_TRUE(camera.read(frame));
  EXPECT_EQ(frame.gray.type(), CV_8UC1);
  EXPECT_TRUE(camera.is_device());
}

TEST(CaptureSource, VideoFileGivesTheSameDetectionsAsTheFramesItCameFrom) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  simlab::SimCameraConfig c;
  c.lamp_toggle_probability = 0.0;
  simlab::SimCameraSource camera(board, c);
  const fs::path path = temp_path("ball.avi");
  // 40 frames: 8 without the ball (the background), then the ball crossing the table.
  std::vector<cv::Mat> originals;
  Frame frame;
  {
    cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), c.fps, camera.frame_size(),
                           true);
    ASSERT_TRUE(writer.isOpened());
    writer.set(cv::VIDEOWRITER_PROP_QUALITY, 100);
    cv::Mat bgr;
    for (int i = 0; i < 40; ++i) {
      const Vec2 p{0.1 + 0.008 * i, 0.2 + 0.02 * i};
      if (i < 8) {
        camera.render({}, i / c.fps, frame);
      } else {
        camera.render({&p, 1}, i / c.fps, frame);
      }
      originals.push_back(frame.gray.clone());
      cv::cvtColor(frame.gray, bgr, cv::COLOR_GRAY2BGR);
      writer.write(bgr);
    }
  }
  CaptureSource file(source(path.string()));
  EXPECT_FALSE(file.is_device());
  EXPECT_EQ(file.frame_size(), camera.frame_size());
  EXPECT_NEAR(file.fps(), c.fps, 1e-6);
  std::vector<Frame> read_back;
  Frame f;
  while (file.read(f)) {
    Frame copy;
    copy.gray = f.gray.clone();
    copy.t_s = f.t_s;
    copy.driver_t_s = f.driver_t_s;
    copy.sequence = f.sequence;
    read_back.push_back(copy);
  }
  EXPECT_TRUE(file.at_end());
  ASSERT_EQ(read_back.size(), originals.size());
  EXPECT_EQ(file.counters().frames, originals.size());
  EXPECT_EQ(file.counters().dropped, 0u);
  for (std::size_t i = 0; i < read_back.size(); ++i) {
    EXPECT_EQ(read_back[i].sequence, i);
    EXPECT_NEAR(read_back[i].driver_t_s, i / c.fps, 1e-3);
    if (i > 0) {  // on the file's clock, not the decoder's (60 frames of 200 fps had spanned 25 ms)
      EXPECT_NEAR(read_back[i].t_s - read_back[i - 1].t_s, 1.0 / c.fps, 1e-3) << i;
    }
  }
  // Paced (pinballd), the file plays as the camera delivered it: no frame before its time.
  CaptureConfig paced = source(path.string());
  paced.pace_file = true;
  CaptureSource played(paced);
  ASSERT_TRUE(played.read(f));
  const double first_s = f.t_s;
  int frames = 1;
  while (played.read(f)) {
    ++frames;
    EXPECT_GE(steady_now_s(), f.t_s) << "frame " << frames - 1 << " came before its time";
  }
  EXPECT_EQ(frames, 40);
  EXPECT_NEAR(f.t_s - first_s, 39 / c.fps, 1e-3);
  EXPECT_GE(steady_now_s() - first_s, 39 / c.fps);
  // Same detector, background learned from the first 8 frames of each stream.
  auto detections = [&](const std::vector<cv::Mat>& frames) {
    BallDetector detector(camera.homography(), camera.frame_size());
    detector.set_occluder_mask(camera.occluder_mask());
    for (int i = 0; i < 8; ++i) detector.background().add_training_frame(frames[static_cast<std::size_t>(i)]);
    detector.background().finish_training();
    std::vector<Detection> out;
    Frame g;
    for (std::size_t i = 8; i < frames.size(); ++i) {
      g.gray = frames[i];
      g.t_s = i / c.fps;
      out.push_back(detector.detect(g));
    }
    return out;
  };
  std::vector<cv::Mat> decoded;
  for (const Frame& r : read_back) decoded.push_back(r.gray);
  const std::vector<Detection> a = detections(originals);
  const std::vector<Detection> b = detections(decoded);
  ASSERT_EQ(a.size(), b.size());
  int found = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].found, b[i].found) << "frame " << i + 8;
    if (!a[i].found || !b[i].found) continue;
    ++found;
    EXPECT_LT(cv::norm(a[i].uv_px - b[i].uv_px), 0.25) << "frame " << i + 8;  // MJPG is lossy
  }
  EXPECT_GE(found, 25);
  fs::remove(path);
}

TEST(CaptureSource, CountsFramesMissingFromTimestampGaps) {
  constexpr double kPeriod = 0.005;  // 200 fps
  EXPECT_EQ(frames_dropped_between(1.000, 1.005, kPeriod), 0u);
  EXPECT_EQ(frames_dropped_between(1.000, 1.007, kPeriod), 0u);  // jitter under 1.5 periods
  EXPECT_EQ(frames_dropped_between(1.000, 1.010, kPeriod), 1u);
  EXPECT_EQ(frames_dropped_between(1.000, 1.021, kPeriod), 3u);
  EXPECT_EQ(frames_dropped_between(1.000, 0.990, kPeriod), 0u);  // clock went back: nothing counted
  EXPECT_EQ(frames_dropped_between(1.000, 2.000, 0.0), 0u);
}

}  // namespace
}  // namespace pinball::vision
