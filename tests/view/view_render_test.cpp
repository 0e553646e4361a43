#include "pinball/view/view_render.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <stdexcept>

#include "pinball/view/log_player.h"
#include "view/view_log.h"

namespace pinball::view {
namespace {

const std::string kBoard = std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board";
const std::string kController = std::string(PINBALL_SOURCE_DIR) + "/controllers/best.json";



TEST(ViewRender, DrawsTheBallWhereTheLogSaysItWas) {
  const ViewScene scene = load_view_scene(kBoard, "", "", 800.0);
  LogPlayer player = pinball::testing::recorded_view_game("view_render");
  player.seek(0.6001);
  const cv::Mat picture = render_view(scene, player.state(), {"game.lcmlog", "log 0.6 s"});
  int n = 0;
  const cv::Mat table = picture(view_table_rect(scene));  // the panel's legend shows the colours too
  const cv::Point2d c = pinball::testing::colour_centroid(table, kViewBallColour, &n);
  const cv::Point2d truth = view_pixel(scene, pinball::testing::view_log_ball(0.6));
  EXPECT_GT(n, 50);  // a disc of about 11 px radius
  EXPECT_NEAR(c.x, truth.x, 1.0);
  EXPECT_NEAR(c.y, truth.y, 1.0);
  // The trail and the projected path are drawn too.
  int trail = 0, path = 0;
  pinball::testing::colour_centroid(table, kViewTrailColour, &trail);
  pinball::testing::colour_centroid(table, kViewTrajectoryColour, &path);
  EXPECT_GT(trail, 20);
  EXPECT_GT(path, 20);
}

TEST(ViewRender, AFlipperWhoseCoilIsOnIsDrawnUp) {
  const ViewScene scene = load_view_scene(kBoard, "", "", 800.0);
  LogPlayer player = pinball::testing::recorded_view_game("view_render");
  player.seek(pinball::testing::kViewLogFire_s + 0.05);
  ASSERT_TRUE(player.state().coil_on(0));
  const cv::Mat on = render_view(scene, player.state(), {"", ""});
  player.seek(player.duration_s());
  const cv::Mat off = render_view(scene, player.state(), {"", ""});
  // Around the left flipper's tip the two pictures differ.
  const table::Flipper& f = scene.board.flippers[0];
  const cv::Point2d tip = view_pixel(scene, table::flipper_tip(f, f.theta_max_rad));
  const cv::Rect around(static_cast<int>(tip.x) - 6, static_cast<int>(tip.y) - 6, 12, 12);
  EXPECT_GT(cv::norm(on(around), off(around), cv::NORM_L1), 1000.0);
}

TEST(ViewRender, TheProjectedPathRunsFromTheObservationToTheImpactUnderG) {
  const ViewScene scene = load_view_scene(kBoard, "", "", 800.0);
  pinball_lcm::lcmt_pinball_projection p{};
  p.valid = true;
  p.t_impact_s = 0.4;
  p.impact_x_m = 0.25;
  p.impact_y_m = 0.12;
  const Vec2 origin(0.10, 0.60);
  EXPECT_NEAR((projected_path_point(scene, origin, p, 0.0) - origin).norm(), 0.0, 1e-12);
  EXPECT_NEAR((projected_path_point(scene, origin, p, 0.4) - Vec2(0.25, 0.12)).norm(), 0.0, 1e-12);
  // Second difference of a parabola: g dt^2, pointing down the table.
  const double dt = 0.1;
  const Vec2 a = projected_path_point(scene, origin, p, 0.1), b = projected_path_point(scene, origin, p, 0.2),
             c = projected_path_point(scene, origin, p, 0.3);
  EXPECT_NEAR((a - 2.0 * b + c).y(), -scene.gravity_mps2 * dt * dt, 1e-12);
  EXPECT_NEAR((a - 2.0 * b + c).x(), 0.0, 1e-12);
}

TEST(ViewRender, DCriticalComesFromTheControllerWhenOneIsGiven) {
  const ViewScene without = load_view_scene(kBoard, "", "", 800.0);
  const ViewScene with = load_view_scene(kBoard, "", kController, 800.0);
  pinball_lcm::lcmt_pinball_projection p{};
  p.valid = true;
  p.flipper = 0;
  p.hittable = true;
  p.speed_mps = 1.5;
  p.angle_rad = -1.0;
  p.h = 0.6;
  p.d_m = 0.1;
  EXPECT_FALSE(d_critical_m(without, p).has_value());
  ASSERT_TRUE(d_critical_m(with, p).has_value());
  EXPECT_TRUE(std::isfinite(*d_critical_m(with, p)));
}

TEST(ViewRender, ABadBoardFileIsNamed) {
  try {
    load_view_scene("/nonexistent/table.board", "", "", 800.0);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/table.board"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pinball::view
