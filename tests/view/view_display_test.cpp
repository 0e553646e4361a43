// `pinball view` with its window, under a virtual display (ctest runs this
// suite through xvfb-run): a recorded log played in the window and the live
// window fed by liblcm, each ending in a snapshot of what it showed.

#include <gtest/gtest.h>

#include <cstdlib>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/command_test.h"
#include "pinball/view/view_render.h"
#include "view/view_log.h"

namespace pinball::testing {
namespace {

class ViewWindow : public CommandTest {
 protected:
  void SetUp() override {
    if (std::getenv("DISPLAY") == nullptr) GTEST_SKIP() << "no display: ctest runs this suite under xvfb-run";
    CommandTest::SetUp();
    log_ = (dir_ / "game.lcmlog").string();
    write_view_log(log_);
  }
  std::string log_;
};

cv::Point2d ball_in(const std::string& png) {
  return ball_on_table(cv::imread(png, cv::IMREAD_COLOR));
}

TEST_F(ViewWindow, PlaysALogInTheWindowAndTheLastFrameShowsTheBallWhereTheLogSaysItWas) {
  const std::string png = (dir_ / "window.png").string();
  const CommandResult r = run("view " + log_ + " --speed 2 --quit-at 0.6001 --snapshot " + png + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["frames_drawn"].get<int>(), 5);
  const Vec2 truth = view_log_ball(0.6);
  EXPECT_NEAR(j["ball"]["x_m"].get<double>(), truth.x(), 1e-9);
  const cv::Point2d c = ball_in(png);
  EXPECT_NEAR(c.x, j["ball"]["u_px"].get<double>(), 1.0);
  EXPECT_NEAR(c.y, j["ball"]["v_px"].get<double>(), 1.0);
}

TEST_F(ViewWindow, TheLiveWindowDrawsWhatLiblcmDelivers) {
  const std::string png = (dir_ / "live.png").string();
  const CommandResult r =
      run("view --lcm-url 'file://" + log_ + "?speed=1' --quit-at 0.5 --snapshot " + png + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GE(j["t_s"].get<double>(), 0.5);
  EXPECT_GT(j["observations"].get<int>(), 90);
  EXPECT_GT(ball_in(png).x, 0.0);
}

}  // namespace
}  // namespace pinball::testing
