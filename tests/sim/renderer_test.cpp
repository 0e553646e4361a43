#include "pinball/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/figure_check.h"
#include "pinball/plot/draw.h"
#include "pinball/plot/png_file.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"

namespace pinball::sim {
namespace {

namespace fs = std::filesystem;

constexpr double kScale = 200.0;  // px/m
constexpr int kMargin = 10;       // px

RenderOptions test_options() {
  RenderOptions o;
  o.px_per_m = kScale;
  o.margin_px = kMargin;
  o.draw_hud = false;
  return o;
}

// A 0.5 x 1.0 m table with nothing on it.
table::Board empty_board() {
  table::Board b;
  b.width_m = 0.5;
  b.height_m = 1.0;
  b.ball.radius_m = 0.015;
  b.launcher.position = Vec2{0.47, 0.05};
  return b;
}

void add_line(table::Board& b, const Vec2& p0, const Vec2& p1, const table::Obstacle& o = table::Obstacle{}) {
  table::Shape s;
  s.kind = table::ShapeKind::kLine;
  s.p0 = p0;
  s.p1 = p1;
  s.normal = perp_left((p1 - p0).normalized());
  b.shapes.push_back(s);
  b.obstacles.push_back(o);
}

void add_circle(table::Board& b, const Vec2& c, double r_m, const table::Obstacle& o = table::Obstacle{}) {
  table::Shape s;
  s.kind = table::ShapeKind::kCircle;
  s.p0 = c;
  s.radius_m = r_m;
  b.shapes.push_back(s);
  b.obstacles.push_back(o);
}

// One horizontal wall across the middle of the table, at y = 0.5 m.
table::Board line_board() {
  table::Board b = empty_board();
  add_line(b, Vec2{0.1, 0.5}, Vec2{0.4, 0.5});
  return b;
}

cv::Point pixel_of(const table::Board& b, const Vec2& p_board) {
  const cv::Point2d uv = board_to_pixel(b, test_options(), p_board);
  return {static_cast<int>(std::lround(uv.x)), static_cast<int>(std::lround(uv.y))};
}

int brightness(const cv::Mat& image, cv::Point uv) {
  const cv::Vec3b c = image.at<cv::Vec3b>(uv);
  return std::max({c[0], c[1], c[2]});
}

// Largest channel value in the 3 x 3 neighbourhood of uv (anti-aliased lines spread).
int peak_brightness(const cv::Mat& image, cv::Point uv) {
  int best = 0;
  for (int dv = -1; dv <= 1; ++dv) {
    for (int du = -1; du <= 1; ++du) best = std::max(best, brightness(image, uv + cv::Point{du, dv}));
  }
  return best;
}

bool same_image(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// A fresh, empty directory under the system temp directory, removed at the end of each test.
class RendererFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = fs::temp_directory_path() / ("pinball_renderer_test_" + std::to_string(rd()) + std::to_string(rd()));
    ASSERT_TRUE(fs::create_directory(dir_));
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST(RendererTest, RenderSizeIsScaledTableWithMargins) {
  const table::Board b = empty_board();
  const cv::Size size = render_size(b, test_options());
  EXPECT_EQ(size.width, 100 + 2 * kMargin);
  EXPECT_EQ(size.height, 200 + 2 * kMargin);

  RenderOptions big;  // defaults: 800 px/m, 12 px margin
  table::Board thesis;       // default 0.51 x 1.07 m table
  const cv::Size s2 = render_size(thesis, big);
  EXPECT_EQ(s2.width, static_cast<int>(std::lround(0.51 * 800.0)) + 24);
  EXPECT_EQ(s2.height, static_cast<int>(std::lround(1.07 * 800.0)) + 24);
}

TEST(RendererTest, RenderBoardReturnsBgrImageOfRenderSize) {
  const table::Board b = line_board();
  const cv::Mat image = render_board(b, nullptr, test_options());
  EXPECT_EQ(image.size(), render_size(b, test_options()));
  EXPECT_EQ(image.type(), CV_8UC3);
}

// A 10 m board at 10 000 px/m asked for a 30 GB image: refused, with the scale that fits.
TEST(RendererTest, AnImageOverTheLargestSideIsRefusedWithTheScaleThatFits) {
  table::Board big;
  big.width_m = 10.0;
  big.height_m = 10.0;
  RenderOptions o;  // 12 px margin, no scale bar
  o.px_per_m = 10000.0;
  try {
    render_board(big, nullptr, o);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "render: 10000 px per metre draws this 10 x 10 m board at more than 16384 px a "
                                     "side; use at most 1636 px per metre");
  }
  o.px_per_m = 1636.0;
  EXPECT_LE(render_size(big, o).width, kMaxRenderSide_px);
}

TEST(RendererTest, BoardToPixelFlipsYAndAddsMargin) {
  const table::Board b = empty_board();
  const RenderOptions o = test_options();
  const cv::Point2d origin = board_to_pixel(b, o, Vec2{0.0, 0.0});
  EXPECT_DOUBLE_EQ(origin.x, kMargin);
  EXPECT_DOUBLE_EQ(origin.y, kMargin + 1.0 * kScale);  // bottom-left of the playfield
  const cv::Point2d corner = board_to_pixel(b, o, Vec2{0.5, 1.0});
  EXPECT_DOUBLE_EQ(corner.x, kMargin + 0.5 * kScale);  // top-right
  EXPECT_DOUBLE_EQ(corner.y, kMargin);
  const cv::Point2d mid = board_to_pixel(b, o, Vec2{0.25, 0.75});
  EXPECT_DOUBLE_EQ(mid.x, kMargin + 50.0);
  EXPECT_DOUBLE_EQ(mid.y, kMargin + 50.0);
  // Both corners lie inside the image.
  const cv::Size size = render_size(b, o);
  EXPECT_LT(origin.y, size.height);
  EXPECT_LT(corner.x, size.width);
}

TEST(RendererTest, HorizontalLineIsBrightAlongItsRowAndDarkElsewhere) {
  const table::Board b = line_board();
  const cv::Mat image = render_board(b, nullptr, test_options());
  const int v_line = pixel_of(b, Vec2{0.0, 0.5}).y;
  ASSERT_EQ(v_line, kMargin + 100);
  const int u0 = pixel_of(b, Vec2{0.1, 0.0}).x;
  const int u1 = pixel_of(b, Vec2{0.4, 0.0}).x;
  for (int u = u0 + 2; u <= u1 - 2; ++u) {
    EXPECT_GT(brightness(image, {u, v_line}), 140) << "u = " << u;
  }
  // Inside the playfield but away from the line, the outline and the launcher: dark.
  for (int v = kMargin + 5; v < kMargin + 180; ++v) {
    if (std::abs(v - v_line) <= 3) continue;
    for (int u = kMargin + 5; u < kMargin + 80; ++u) {
      ASSERT_LT(brightness(image, {u, v}), 80) << "u = " << u << ", v = " << v;
    }
  }
  // Beyond the ends of the segment, on its row: dark.
  EXPECT_LT(brightness(image, {u0 - 6, v_line}), 80);
  EXPECT_LT(brightness(image, {u1 + 6, v_line}), 80);
}

TEST(RendererTest, PlayfieldOutlineIsDrawn) {
  const table::Board b = empty_board();
  const cv::Mat image = render_board(b, nullptr, test_options());
  const cv::Point top_mid = pixel_of(b, Vec2{0.25, 1.0});
  const cv::Point left_mid = pixel_of(b, Vec2{0.0, 0.5});
  const cv::Point inside = pixel_of(b, Vec2{0.25, 0.5});
  EXPECT_GT(peak_brightness(image, top_mid), brightness(image, inside) + 40);
  EXPECT_GT(peak_brightness(image, left_mid), brightness(image, inside) + 40);
  // The margin and the playfield have different backgrounds.
  EXPECT_NE(image.at<cv::Vec3b>(cv::Point{2, 2}), image.at<cv::Vec3b>(inside));
}

TEST(RendererTest, BallIsDrawnAtItsPositionOnlyWhenInPlay) {
  const table::Board b = line_board();
  GameState state = make_game_state(b, 7);
  const Vec2 ball{0.25, 0.3};
  state.ball.position_m = ball;
  state.ball_in_play = false;
  const cv::Mat without = render_board(b, &state, test_options());
  state.ball_in_play = true;
  const cv::Mat with = render_board(b, &state, test_options());

  const cv::Point centre = pixel_of(b, ball);
  EXPECT_NE(with.at<cv::Vec3b>(centre), without.at<cv::Vec3b>(centre));
  EXPECT_GT(brightness(with, centre), 150);
  EXPECT_LT(brightness(without, centre), 80);
  // Within the ball radius (3 px) but not beyond it.
  EXPECT_GT(brightness(with, centre + cv::Point{0, 2}), 150);
  const cv::Point far = pixel_of(b, Vec2{0.25, 0.2});
  EXPECT_EQ(with.at<cv::Vec3b>(far), without.at<cv::Vec3b>(far));
  // Only the neighbourhood of the ball changed.
  cv::Mat diff;
  cv::absdiff(with, without, diff);
  cv::Mat diff_gray;
  cv::extractChannel(diff, diff_gray, 0);
  const cv::Rect changed = cv::boundingRect(diff_gray);
  EXPECT_TRUE(changed.contains(centre));
  EXPECT_LE(changed.width, 9);
  EXPECT_LE(changed.height, 9);
}

TEST(RendererTest, HiddenObstacleIsDrawnDifferently) {
  const table::Board b = line_board();
  GameState state = make_game_state(b, 1);
  ASSERT_EQ(state.visible.size(), 1u);
  ASSERT_EQ(state.visible[0], 1);
  const cv::Mat shown = render_board(b, &state, test_options());
  state.visible[0] = 0;
  const cv::Mat hidden = render_board(b, &state, test_options());
  EXPECT_FALSE(same_image(shown, hidden));

  // Greyed: dimmer than the visible line; dashed: some gaps along it.
  const int v = pixel_of(b, Vec2{0.0, 0.5}).y;
  const int u0 = pixel_of(b, Vec2{0.1, 0.0}).x;
  const int u1 = pixel_of(b, Vec2{0.4, 0.0}).x;
  int hidden_max = 0;
  int gaps = 0;
  for (int u = u0 + 2; u <= u1 - 2; ++u) {
    hidden_max = std::max(hidden_max, brightness(hidden, {u, v}));
    if (brightness(hidden, {u, v}) < 60) ++gaps;
  }
  EXPECT_GT(hidden_max, 60);  // still drawn
  EXPECT_LT(hidden_max, brightness(shown, {(u0 + u1) / 2, v}) - 40);
  EXPECT_GT(gaps, 5);

  // The board's own flag stands in when there is no state.
  table::Board b_hidden = b;
  b_hidden.obstacles[0].visible = false;
  EXPECT_TRUE(same_image(render_board(b_hidden, nullptr, test_options()), hidden));
  EXPECT_TRUE(same_image(render_board(b, nullptr, test_options()), shown));
}

TEST(RendererTest, ObstacleColourFollowsWhatItDoes) {
  table::Board b = empty_board();
  table::Obstacle wall;
  table::Obstacle kicker;
  kicker.rho = 1.5;
  table::Obstacle eater;
  eater.action.eats_ball = true;
  table::Obstacle scorer;
  scorer.action.score = 100.0;
  add_line(b, Vec2{0.1, 0.2}, Vec2{0.4, 0.2}, wall);
  add_line(b, Vec2{0.1, 0.4}, Vec2{0.4, 0.4}, kicker);
  add_line(b, Vec2{0.1, 0.6}, Vec2{0.4, 0.6}, eater);
  add_line(b, Vec2{0.1, 0.8}, Vec2{0.4, 0.8}, scorer);
  const cv::Mat image = render_board(b, nullptr, test_options());
  const auto at = [&](double y) { return image.at<cv::Vec3b>(pixel_of(b, Vec2{0.25, y})); };
  const cv::Vec3b w = at(0.2);
  const cv::Vec3b k = at(0.4);
  const cv::Vec3b e = at(0.6);
  const cv::Vec3b s = at(0.8);
  // Wall: light grey.
  EXPECT_GT(w[0], 120);
  EXPECT_NEAR(w[0], w[2], 20);
  // Kicker: warm (red over blue).
  EXPECT_GT(k[2], k[0] + 80);
  // Eater: red.
  EXPECT_GT(e[2], e[0] + 80);
  EXPECT_GT(e[2], e[1] + 80);
  // Scoring wall: brighter than a plain wall.
  EXPECT_GT(s[0] + s[1] + s[2], w[0] + w[1] + w[2] + 30);
  EXPECT_NE(k, e);
}

TEST(RendererTest, CirclesAreFilledAndPointsAreDots) {
  table::Board b = empty_board();
  add_circle(b, Vec2{0.25, 0.6}, 0.04);  // 8 px radius
  add_circle(b, Vec2{0.25, 0.3}, 0.0);   // a point
  const cv::Mat image = render_board(b, nullptr, test_options());
  const cv::Mat plain = render_board(empty_board(), nullptr, test_options());
  const cv::Point c = pixel_of(b, Vec2{0.25, 0.6});
  EXPECT_NE(image.at<cv::Vec3b>(c), plain.at<cv::Vec3b>(c));      // filled
  EXPECT_GT(brightness(image, c + cv::Point{8, 0}), 140);          // outlined
  EXPECT_GT(brightness(image, c + cv::Point{8, 0}), brightness(image, c) + 20);
  EXPECT_EQ(image.at<cv::Vec3b>(c + cv::Point{12, 0}), plain.at<cv::Vec3b>(c + cv::Point{12, 0}));
  const cv::Point p = pixel_of(b, Vec2{0.25, 0.3});
  EXPECT_GT(brightness(image, p), 140);
  EXPECT_EQ(image.at<cv::Vec3b>(p + cv::Point{5, 0}), plain.at<cv::Vec3b>(p + cv::Point{5, 0}));
}

TEST(RendererTest, HiddenCircleIsNotFilled) {
  table::Board b = empty_board();
  add_circle(b, Vec2{0.25, 0.6}, 0.04);
  b.obstacles[0].visible = false;
  const cv::Mat image = render_board(b, nullptr, test_options());
  const cv::Mat plain = render_board(empty_board(), nullptr, test_options());
  const cv::Point c = pixel_of(b, Vec2{0.25, 0.6});
  EXPECT_EQ(image.at<cv::Vec3b>(c), plain.at<cv::Vec3b>(c));
  EXPECT_FALSE(same_image(image, plain));
}

TEST(RendererTest, SensorsAreDrawnAndHolesAreDark) {
  table::Board b = empty_board();
  table::Sensor line;
  line.kind = table::SensorKind::kProximity;
  line.shape.kind = table::ShapeKind::kLine;
  line.shape.p0 = Vec2{0.1, 0.3};
  line.shape.p1 = Vec2{0.4, 0.3};
  table::Sensor hole;
  hole.kind = table::SensorKind::kHole;
  hole.shape.kind = table::ShapeKind::kCircle;
  hole.shape.p0 = Vec2{0.25, 0.7};
  hole.shape.radius_m = 0.03;
  b.sensors = {line, hole};
  const cv::Mat image = render_board(b, nullptr, test_options());
  const cv::Mat plain = render_board(empty_board(), nullptr, test_options());

  const cv::Point on_sensor = pixel_of(b, Vec2{0.25, 0.3});
  EXPECT_GT(peak_brightness(image, on_sensor), 120);
  const cv::Vec3b sc = image.at<cv::Vec3b>(on_sensor);
  EXPECT_NE(sc[0], sc[2]);  // coloured, not a grey wall

  const cv::Point hole_centre = pixel_of(b, Vec2{0.25, 0.7});
  const cv::Vec3b hc = image.at<cv::Vec3b>(hole_centre);
  const cv::Vec3b bg = plain.at<cv::Vec3b>(hole_centre);
  EXPECT_LT(hc[0] + hc[1] + hc[2], bg[0] + bg[1] + bg[2]);
  EXPECT_GT(peak_brightness(image, hole_centre + cv::Point{6, 0}), 120);  // its rim
}

TEST(RendererTest, FlipperIsDrawnAtItsAngle) {
  table::Board b = empty_board();
  table::Flipper f;
  f.side = table::Side::kLeft;
  f.pivot = Vec2{0.1, 0.2};
  f.length_m = 0.1;
  f.theta_min_rad = -0.5;
  f.theta_max_rad = 0.5;
  f.omega_rad_s = 20.0;
  b.flippers.push_back(f);
  const Vec2 mid_down = 0.5 * (f.pivot + table::flipper_tip(f, f.theta_min_rad));
  const Vec2 mid_up = 0.5 * (f.pivot + table::flipper_tip(f, f.theta_max_rad));

  const cv::Mat rest = render_board(b, nullptr, test_options());
  EXPECT_GT(brightness(rest, pixel_of(b, mid_down)), 140);
  EXPECT_LT(brightness(rest, pixel_of(b, mid_up)), 80);

  GameState state = make_game_state(b, 3);
  EXPECT_TRUE(same_image(render_board(b, &state, test_options()), rest));  // a fresh state is at rest
  state.flippers[0].theta_rad = f.theta_max_rad;
  state.flippers[0].energized = true;
  const cv::Mat up = render_board(b, &state, test_options());
  EXPECT_GT(brightness(up, pixel_of(b, mid_up)), 140);
  EXPECT_LT(brightness(up, pixel_of(b, mid_down)), 80);
  // Thick: covers pixels 2 px either side of its axis.
  EXPECT_GT(brightness(up, pixel_of(b, mid_up) + cv::Point{0, 1}), 140);
  EXPECT_GT(brightness(up, pixel_of(b, mid_up) + cv::Point{0, -1}), 140);
}

TEST(RendererTest, LauncherIsMarked) {
  const table::Board b = empty_board();
  table::Board moved = b;
  moved.launcher.position = Vec2{0.25, 0.5};
  EXPECT_FALSE(same_image(render_board(b, nullptr, test_options()), render_board(moved, nullptr, test_options())));
}

TEST(RendererTest, NormalsAreDrawnOnTheNormalSide) {
  const table::Board b = line_board();  // normal points +y (up the table, up the image)
  RenderOptions o = test_options();
  const cv::Mat plain = render_board(b, nullptr, o);
  o.draw_normals = true;
  const cv::Mat ticks = render_board(b, nullptr, o);
  const cv::Point above = pixel_of(b, Vec2{0.25, 0.5 + 0.01});
  const cv::Point below = pixel_of(b, Vec2{0.25, 0.5 - 0.01});
  EXPECT_NE(ticks.at<cv::Vec3b>(above), plain.at<cv::Vec3b>(above));
  EXPECT_EQ(ticks.at<cv::Vec3b>(below), plain.at<cv::Vec3b>(below));
}

TEST(RendererTest, HudNeedsAStateAndTheOption) {
  const table::Board b = line_board();
  GameState state = make_game_state(b, 5);
  state.score = 12345.0;
  state.time_s = 3.25;
  RenderOptions o = test_options();
  const cv::Mat no_hud = render_board(b, &state, o);
  o.draw_hud = true;
  const cv::Mat hud = render_board(b, &state, o);
  EXPECT_FALSE(same_image(hud, no_hud));
  // The text is in the top-left corner.
  cv::Mat diff;
  cv::absdiff(hud, no_hud, diff);
  cv::Mat diff_gray;
  cv::extractChannel(diff, diff_gray, 1);
  const cv::Rect changed = cv::boundingRect(diff_gray);
  EXPECT_LT(changed.x, 20);
  EXPECT_LT(changed.y, 20);
  // A different score draws different text.
  state.score = 99.0;
  EXPECT_FALSE(same_image(render_board(b, &state, o), hud));
  // No state, no HUD.
  EXPECT_TRUE(same_image(render_board(b, nullptr, o), render_board(b, nullptr, test_options())));
}

TEST(RendererTest, SameInputSameImage) {
  table::Board b = line_board();
  add_circle(b, Vec2{0.2, 0.8}, 0.03);
  GameState state = make_game_state(b, 9);
  state.ball_in_play = true;
  state.ball.position_m = Vec2{0.3, 0.4};
  RenderOptions o = test_options();
  o.draw_hud = true;
  EXPECT_TRUE(same_image(render_board(b, &state, o), render_board(b, &state, o)));
}

TEST(RendererTest, RejectsBadOptions) {
  const table::Board b = line_board();
  RenderOptions o = test_options();
  o.px_per_m = 0.0;
  EXPECT_THROW(render_board(b, nullptr, o), std::invalid_argument);
  o = test_options();
  o.margin_px = -1;
  EXPECT_THROW(render_board(b, nullptr, o), std::invalid_argument);
}

TEST(RendererTest, ScaleBarAddsAStripBelowThePlayfield) {
  const table::Board b = line_board();
  RenderOptions o = test_options();
  const cv::Mat plain = render_board(b, nullptr, o);
  o.draw_scale_bar = true;
  const cv::Mat with_bar = render_board(b, nullptr, o);
  EXPECT_EQ(with_bar.size(), render_size(b, o));
  EXPECT_EQ(with_bar.cols, plain.cols);
  EXPECT_GT(with_bar.rows, plain.rows);
  // The playfield is drawn the same; the strip holds a white box with a black bar.
  EXPECT_TRUE(same_image(with_bar(cv::Rect(0, 0, plain.cols, plain.rows)), plain));
  const cv::Mat strip = with_bar(cv::Rect(0, plain.rows, plain.cols, with_bar.rows - plain.rows));
  EXPECT_GT(pinball::testing::count_colour(strip, cv::Scalar(255, 255, 255), 5), 200);
  EXPECT_GT(pinball::testing::count_colour(strip, cv::Scalar(0, 0, 0), 10), 60);
}

// At 50 px/m the thesis board is 26 px wide: the image widens so the bar's label ("20 cm") is not cut.
TEST(RendererTest, ANarrowBoardWidensItsImageForTheScaleBarsLabel) {
  table::Board thesis;  // 0.51 x 1.07 m
  RenderOptions o;
  o.px_per_m = 50.0;
  o.margin_px = 0;
  o.draw_scale_bar = true;
  const cv::Mat image = render_board(thesis, nullptr, o);
  EXPECT_GT(image.cols, static_cast<int>(std::lround(0.51 * 50.0)));
  EXPECT_EQ(image.size(), render_size(thesis, o));
  // The label's white box lies wholly inside: none of it in the image's last column.
  const cv::Mat strip = image(cv::Rect(0, image.rows - 44, image.cols, 44));
  EXPECT_GT(pinball::testing::count_colour(strip, cv::Scalar(255, 255, 255), 5), 200);
  EXPECT_EQ(pinball::testing::count_colour(strip.col(strip.cols - 1), cv::Scalar(255, 255, 255), 5), 0);
  o.draw_scale_bar = false;
  EXPECT_EQ(render_size(thesis, o).width, static_cast<int>(std::lround(0.51 * 50.0)));
}

TEST_F(RendererFileTest, BoardFigureIsWrittenWithLegendAndNotTrivial) {
  // What `pinball render` writes: the board with its scale bar, the legend beside it, a title above.
  const table::Board b = line_board();
  RenderOptions o = test_options();
  o.draw_scale_bar = true;
  const std::vector<plot::LegendEntry> legend = board_legend();
  EXPECT_GE(legend.size(), 6u);
  const cv::Mat board_image = render_board(b, nullptr, o);
  const std::string path = (dir_ / "board.png").string();
  plot::write_png(plot::annotated_picture(board_image, legend, "Board test - pinball render"), path);
  const cv::Mat back = pinball::testing::read_figure(path);
  ASSERT_FALSE(back.empty());
  EXPECT_GT(back.cols, board_image.cols + 100);  // the legend beside the board
  EXPECT_GT(back.rows, board_image.rows);          // the title above
  for (const plot::LegendEntry& e : legend) {
    EXPECT_GT(pinball::testing::count_colour(back, e.colour, 20), 8) << e.label;
  }
}

}  // namespace
}  // namespace pinball::sim
