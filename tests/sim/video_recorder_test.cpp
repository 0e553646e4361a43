#include "pinball/sim/video_recorder.h"

#include <csignal>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/renderer.h"

namespace pinball::sim {
namespace {

namespace fs = std::filesystem;

// A fresh, empty directory under the system temp directory, removed at the end of each test.
class VideoRecorderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = fs::temp_directory_path() / ("pinball_video_test_" + std::to_string(rd()) + std::to_string(rd()));
    ASSERT_TRUE(fs::create_directory(dir_));
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// Frame i: a grey level that changes from frame to frame, with a white square moving right.
cv::Mat test_frame(cv::Size size, int i) {
  cv::Mat f(size, CV_8UC3, cv::Scalar(20 + 10 * i, 40, 60));
  cv::rectangle(f, cv::Rect{4 + 6 * i, 10, 12, 12}, cv::Scalar(255, 255, 255), cv::FILLED);
  return f;
}

TEST_F(VideoRecorderTest, WritesFramesThatVideoCaptureReadsBack) {
  const cv::Size size{160, 120};
  const int n = 10;
  const std::string file = path("frames.avi");
  {
    VideoRecorder rec(file, 25.0, size);
    for (int i = 0; i < n; ++i) {
      rec.write(test_frame(size, i));
      EXPECT_EQ(rec.frames_written(), i + 1);
    }
    rec.close();
    rec.close();  // closing twice is harmless
    EXPECT_EQ(rec.frames_written(), n);
  }
  ASSERT_TRUE(fs::exists(file));
  EXPECT_GT(fs::file_size(file), 0u);

  cv::VideoCapture cap(file);
  ASSERT_TRUE(cap.isOpened());
  EXPECT_EQ(static_cast<int>(cap.get(cv::CAP_PROP_FRAME_WIDTH)), size.width);
  EXPECT_EQ(static_cast<int>(cap.get(cv::CAP_PROP_FRAME_HEIGHT)), size.height);
  int read = 0;
  cv::Mat frame;
  while (cap.read(frame)) {
    ASSERT_EQ(frame.size(), size);
    ASSERT_EQ(frame.type(), CV_8UC3);
    // MJPG is lossy, but each frame should be close to the one written.
    const cv::Mat expected = test_frame(size, read);
    EXPECT_LT(cv::norm(frame, expected, cv::NORM_L1) / (size.area() * 3.0), 8.0) << "frame " << read;
    ++read;
  }
  EXPECT_EQ(read, n);
}

// OpenCV's writer reports no write error: a disk that filled left a cut AVI
// and exit 0. close() reads the index back and says so.
TEST_F(VideoRecorderTest, AVideoTheDiskCutShortIsAnErrorAtClose) {
  const cv::Size size{160, 120};
  const std::string whole = path("whole.avi");
  {
    VideoRecorder rec(whole, 25.0, size);
    for (int i = 0; i < 10; ++i) rec.write(test_frame(size, i));
    rec.close();
  }
  EXPECT_EQ(avi_frame_count(whole), 10);
  const std::string cut = path("cut.avi");
  fs::copy_file(whole, cut);
  fs::resize_file(cut, fs::file_size(whole) / 2);
  EXPECT_NE(avi_frame_count(cut), 10);
  EXPECT_EQ(avi_frame_count(path("none.avi")), -1);

  // A file that may not grow past 64 kB (RLIMIT_FSIZE, as a full disk): in a child process.
  const std::string full = path("full.avi");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG instead
    const rlimit limit{65536, 65536};
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      VideoRecorder rec(full, 25.0, size);
      for (int i = 0; i < 200; ++i) rec.write(test_frame(size, i % 20));
      rec.close();
    } catch (const std::runtime_error& e) {
      _exit(std::string(e.what()).rfind(full + ": the video was not written whole: ", 0) == 0 ? 3 : 4);
    }
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 3) << "0: close() took the cut file for whole; 4: another message";
}

TEST_F(VideoRecorderTest, RecordsRenderedBoardFrames) {
  table::Board b;
  table::Shape s;
  s.p0 = Vec2{0.1, 0.5};
  s.p1 = Vec2{0.4, 0.5};
  s.normal = Vec2{0.0, 1.0};
  b.shapes.push_back(s);
  b.obstacles.emplace_back();
  RenderOptions o;
  o.px_per_m = 300.0;
  GameState state = make_game_state(b, 1);
  state.ball_in_play = true;
  const cv::Size size = render_size(b, o);
  const std::string file = path("board.avi");
  {
    VideoRecorder rec(file, 30.0, size);
    for (int i = 0; i < 5; ++i) {
      state.ball.position_m = Vec2{0.1 + 0.05 * i, 0.3};
      state.time_s = i / 30.0;
      rec.write(render_board(b, &state, o));
    }
    rec.close();
  }
  cv::VideoCapture cap(file);
  ASSERT_TRUE(cap.isOpened());
  cv::Mat frame;
  int read = 0;
  while (cap.read(frame)) {
    EXPECT_EQ(frame.size(), size);
    ++read;
  }
  EXPECT_EQ(read, 5);
}

// A run that failed or was stopped had left a cut AVI in place of a good one: a recorder not closed
// takes what it wrote with it.
TEST_F(VideoRecorderTest, ARecorderNotClosedLeavesTheOldFileAsItWas) {
  const cv::Size size{64, 48};
  const std::string file = path("kept.avi");
  {
    VideoRecorder rec(file, 10.0, size);
    for (int i = 0; i < 3; ++i) rec.write(test_frame(size, i));
    rec.close();
  }
  const auto bytes = std::filesystem::file_size(file);
  {
    VideoRecorder rec(file, 10.0, size);
    for (int i = 0; i < 7; ++i) rec.write(test_frame(size, i));
    rec.finish();  // checked, never committed: the run failed elsewhere
  }
  EXPECT_EQ(std::filesystem::file_size(file), bytes);
  EXPECT_EQ(avi_frame_count(file), 3);
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(file).parent_path())) {
    EXPECT_EQ(e.path().string().find(".partial"), std::string::npos) << e.path();
  }
}

TEST_F(VideoRecorderTest, WrongFrameSizeOrTypeThrows) {
  const cv::Size size{64, 48};
  VideoRecorder rec(path("bad.avi"), 10.0, size);
  EXPECT_THROW(rec.write(cv::Mat(cv::Size{48, 64}, CV_8UC3, cv::Scalar::all(0))), std::invalid_argument);
  EXPECT_THROW(rec.write(cv::Mat(size, CV_8UC1, cv::Scalar::all(0))), std::invalid_argument);
  EXPECT_THROW(rec.write(cv::Mat(size, CV_32FC3, cv::Scalar::all(0))), std::invalid_argument);
  EXPECT_THROW(rec.write(cv::Mat()), std::invalid_argument);
  EXPECT_EQ(rec.frames_written(), 0);
  rec.write(cv::Mat(size, CV_8UC3, cv::Scalar::all(0)));
  EXPECT_EQ(rec.frames_written(), 1);
}

TEST_F(VideoRecorderTest, WriteAfterCloseThrows) {
  const cv::Size size{64, 48};
  VideoRecorder rec(path("closed.avi"), 10.0, size);
  rec.close();
  EXPECT_THROW(rec.write(cv::Mat(size, CV_8UC3, cv::Scalar::all(0))), std::logic_error);
  EXPECT_EQ(rec.frames_written(), 0);
}

TEST_F(VideoRecorderTest, UnopenablePathThrowsNamingIt) {
  const std::string file = path("no_such_dir/out.avi");
  try {
    VideoRecorder rec(file, 25.0, cv::Size{64, 48});
    FAIL() << "VideoRecorder opened " << file;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
}

TEST_F(VideoRecorderTest, ANameThatIsNoAviIsRefusedByName) {
  const std::string file = path("out.txt");
  try {
    VideoRecorder rec(file, 25.0, cv::Size{64, 48});
    FAIL() << "VideoRecorder opened " << file;
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), file + ": an MJPG AVI is written; give the file name an .avi extension");
  }
  EXPECT_NO_THROW(check_avi_name("x/Play.AVI"));
}

TEST_F(VideoRecorderTest, RejectsBadFpsAndSize) {
  EXPECT_THROW(VideoRecorder(path("a.avi"), 0.0, cv::Size{64, 48}), std::invalid_argument);
  EXPECT_THROW(VideoRecorder(path("b.avi"), 25.0, cv::Size{0, 48}), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::sim
