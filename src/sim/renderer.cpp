#include "pinball/sim/renderer.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "pinball/core/format.h"
#include "pinball/plot/draw.h"

namespace pinball::sim {
namespace {

// Sub-pixel drawing: OpenCV takes fixed-point coordinates with this many
// fractional bits, so thin lines land where the board says, not on a rounded pixel.
constexpr int kShift = 4;
constexpr double kFixedScale = 1 << kShift;

// Colours, BGR.
const cv::Scalar kBackground{18, 18, 18};
const cv::Scalar kPlayfield{46, 34, 26};
const cv::Scalar kOutline{130, 130, 130};
const cv::Scalar kWall{205, 205, 205};
const cv::Scalar kKicker{40, 150, 255};
const cv::Scalar kEater{50, 50, 230};
const cv::Scalar kHidden{85, 85, 85};
const cv::Scalar kSensor{210, 190, 40};
const cv::Scalar kHole{6, 6, 6};
const cv::Scalar kFlipper{60, 210, 245};
const cv::Scalar kFlipperUp{150, 240, 255};
const cv::Scalar kLauncher{200, 120, 200};
const cv::Scalar kBall{195, 200, 205};
const cv::Scalar kBallHighlight{255, 255, 255};
const cv::Scalar kNormal{230, 80, 230};
const cv::Scalar kHudText{235, 235, 235};

constexpr int kLineThickness_px = 2;
constexpr int kSensorThickness_px = 1;
constexpr int kPointRadius_px = 2;
constexpr double kDashOn_px = 7.0;   // hidden obstacles: drawn length of a dash
constexpr double kDashOff_px = 6.0;  // gap between dashes (round caps eat about 2 px of it)
constexpr double kFlipperWidth_m = 0.010;  // drawn width; the model's flipper is a segment
constexpr double kNormalTick_m = 0.015;    // length of a normal tick
constexpr int kScaleBarStrip_px = 44;      // the strip below the playfield that holds the scale bar
constexpr int kScaleBarMinWidth_px = 96;  // narrow boards (a low --px-per-m) still show the bar's label

// Pixel (u, v) as an OpenCV fixed-point point for `shift = kShift`.
cv::Point to_fixed(const cv::Point2d& uv_px) {
  return {static_cast<int>(std::lround(uv_px.x * kFixedScale)), static_cast<int>(std::lround(uv_px.y * kFixedScale))};
}

// A length in pixels as a fixed-point radius.
int to_fixed(double length_px) { return static_cast<int>(std::lround(length_px * kFixedScale)); }

// `c` moved a fraction `t` toward white (t in [0, 1]).
cv::Scalar brighten(const cv::Scalar& c, double t) {
  return {c[0] + (255.0 - c[0]) * t, c[1] + (255.0 - c[1]) * t, c[2] + (255.0 - c[2]) * t};
}

// `c` scaled toward black by `f` in [0, 1].
cv::Scalar darken(const cv::Scalar& c, double f) { return {c[0] * f, c[1] * f, c[2] * f}; }

// Colour of a reflecting obstacle by what it does (ignores visibility).
cv::Scalar obstacle_colour(const table::Obstacle& o) {
  cv::Scalar c = kWall;
  if (o.action.eats_ball) {
    c = kEater;
  } else if (o.rho > 1.0 || o.action.kick_mps > 0.0) {
    c = kKicker;
  }
  const bool scores = o.action.score != 0.0 || o.action.contact_score_per_s != 0.0;
  return scores ? brighten(c, 0.45) : darken(c, 0.85);
}

void draw_line(cv::Mat& image, const cv::Point2d& a_px, const cv::Point2d& b_px, const cv::Scalar& colour,
               int thickness_px) {
  cv::line(image, to_fixed(a_px), to_fixed(b_px), colour, thickness_px, cv::LINE_AA, kShift);
}

// Dashed segment a -> b: kDashOn_px drawn, kDashOff_px skipped.
void draw_dashed_line(cv::Mat& image, const cv::Point2d& a_px, const cv::Point2d& b_px, const cv::Scalar& colour,
                      int thickness_px) {
  const cv::Point2d d = b_px - a_px;
  const double length_px = std::hypot(d.x, d.y);
  if (length_px <= kDashOn_px) {
    draw_line(image, a_px, b_px, colour, thickness_px);
    return;
  }
  const cv::Point2d unit = d * (1.0 / length_px);
  for (double s = 0.0; s < length_px; s += kDashOn_px + kDashOff_px) {
    const double e = std::min(s + kDashOn_px, length_px);
    draw_line(image, a_px + unit * s, a_px + unit * e, colour, thickness_px);
  }
}

// Dashed circle outline: arcs of about kDashOn_px with gaps of kDashOff_px.
void draw_dashed_circle(cv::Mat& image, const cv::Point2d& c_px, double r_px, const cv::Scalar& colour,
                        int thickness_px) {
  const double circumference_px = 2.0 * M_PI * r_px;
  const int dashes = static_cast<int>(circumference_px / (kDashOn_px + kDashOff_px));
  if (dashes < 3) {
    cv::circle(image, to_fixed(c_px), to_fixed(r_px), colour, thickness_px, cv::LINE_AA, kShift);
    return;
  }
  const double step_rad = 2.0 * M_PI / dashes;
  const double on_rad = step_rad * kDashOn_px / (kDashOn_px + kDashOff_px);
  for (int i = 0; i < dashes; ++i) {
    const double a0 = i * step_rad;
    const double a1 = a0 + on_rad;
    const cv::Point2d p0 = c_px + cv::Point2d{std::cos(a0), std::sin(a0)} * r_px;
    const cv::Point2d p1 = c_px + cv::Point2d{std::cos(a1), std::sin(a1)} * r_px;
    draw_line(image, p0, p1, colour, thickness_px);
  }
}

void draw_playfield(cv::Mat& image, const table::Board& board, const RenderOptions& options) {
  const cv::Point2d top_left = board_to_pixel(board, options, Vec2{0.0, board.height_m});
  const cv::Point2d bottom_right = board_to_pixel(board, options, Vec2{board.width_m, 0.0});
  cv::rectangle(image, to_fixed(top_left), to_fixed(bottom_right), kPlayfield, cv::FILLED, cv::LINE_8, kShift);
  cv::rectangle(image, to_fixed(top_left), to_fixed(bottom_right), kOutline, 1, cv::LINE_AA, kShift);
}

void draw_sensors(cv::Mat& image, const table::Board& board, const RenderOptions& options) {
  for (const table::Sensor& s : board.sensors) {
    const cv::Point2d p0 = board_to_pixel(board, options, s.shape.p0);
    if (s.shape.kind == table::ShapeKind::kLine) {
      draw_line(image, p0, board_to_pixel(board, options, s.shape.p1), kSensor, kSensorThickness_px);
      continue;
    }
    const double r_px = s.shape.radius_m * options.px_per_m;
    if (s.kind == table::SensorKind::kHole) {
      cv::circle(image, to_fixed(p0), to_fixed(std::max(r_px, 1.0)), kHole, cv::FILLED, cv::LINE_AA, kShift);
    }
    if (r_px > 0.0) {
      cv::circle(image, to_fixed(p0), to_fixed(r_px), kSensor, kSensorThickness_px, cv::LINE_AA, kShift);
    } else {
      cv::circle(image, to_fixed(p0), to_fixed(static_cast<double>(kPointRadius_px)), kSensor, cv::FILLED,
                 cv::LINE_AA, kShift);
    }
  }
}

void draw_obstacles(cv::Mat& image, const table::Board& board, const GameState* state, const RenderOptions& options) {
  assert(board.shapes.size() == board.obstacles.size());
  const std::size_t n = std::min(board.shapes.size(), board.obstacles.size());
  for (std::size_t i = 0; i < n; ++i) {
    const table::Shape& shape = board.shapes[i];
    const table::Obstacle& obstacle = board.obstacles[i];
    const bool visible =
        state != nullptr && i < state->visible.size() ? state->visible[i] == kVisible : obstacle.visible;
    const cv::Scalar colour = visible ? obstacle_colour(obstacle) : kHidden;
    const cv::Point2d p0 = board_to_pixel(board, options, shape.p0);

    if (shape.kind == table::ShapeKind::kLine) {
      const cv::Point2d p1 = board_to_pixel(board, options, shape.p1);
      if (visible) {
        draw_line(image, p0, p1, colour, kLineThickness_px);
      } else {
        draw_dashed_line(image, p0, p1, colour, kLineThickness_px);
      }
      continue;
    }

    const double r_px = shape.radius_m * options.px_per_m;
    if (r_px <= 0.0) {  // a point
      cv::circle(image, to_fixed(p0), to_fixed(static_cast<double>(kPointRadius_px)), colour, cv::FILLED,
                 cv::LINE_AA, kShift);
    } else if (visible) {
      cv::circle(image, to_fixed(p0), to_fixed(r_px), darken(colour, 0.45), cv::FILLED, cv::LINE_AA, kShift);
      cv::circle(image, to_fixed(p0), to_fixed(r_px), colour, kLineThickness_px, cv::LINE_AA, kShift);
    } else {
      draw_dashed_circle(image, p0, r_px, colour, kLineThickness_px);
    }
  }
}

void draw_normals(cv::Mat& image, const table::Board& board, const RenderOptions& options) {
  for (const table::Shape& shape : board.shapes) {
    if (shape.kind != table::ShapeKind::kLine) continue;
    const Vec2 mid = 0.5 * (shape.p0 + shape.p1);
    draw_line(image, board_to_pixel(board, options, mid),
              board_to_pixel(board, options, mid + kNormalTick_m * shape.normal), kNormal, 1);
  }
}

void draw_flippers(cv::Mat& image, const table::Board& board, const GameState* state, const RenderOptions& options) {
  const int width_px = std::max(3, static_cast<int>(std::lround(kFlipperWidth_m * options.px_per_m)));
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const table::Flipper& f = board.flippers[i];
    const bool has_state = state != nullptr && i < state->flippers.size();
    const double theta_rad = has_state ? state->flippers[i].theta_rad : f.theta_min_rad;
    const bool up = has_state && state->flippers[i].energized;
    const cv::Point2d pivot_px = board_to_pixel(board, options, f.pivot);
    const cv::Point2d tip_px = board_to_pixel(board, options, table::flipper_tip(f, theta_rad));
    // OpenCV draws thick lines with round caps.
    draw_line(image, pivot_px, tip_px, up ? kFlipperUp : kFlipper, width_px);
    cv::circle(image, to_fixed(pivot_px), to_fixed(static_cast<double>(kPointRadius_px)), kBackground, cv::FILLED,
               cv::LINE_AA, kShift);
  }
}

void draw_launcher(cv::Mat& image, const table::Board& board, const RenderOptions& options) {
  const cv::Point2d c_px = board_to_pixel(board, options, board.launcher.position);
  const double h_px = std::max(3.0, board.ball.radius_m * options.px_per_m);
  cv::rectangle(image, to_fixed(c_px - cv::Point2d{h_px, h_px}), to_fixed(c_px + cv::Point2d{h_px, h_px}),
                kLauncher, 1, cv::LINE_AA, kShift);
  draw_line(image, c_px + cv::Point2d{0.0, h_px}, c_px + cv::Point2d{0.0, 2.5 * h_px}, kLauncher, 1);
}

void draw_ball(cv::Mat& image, const table::Board& board, const GameState& state, const RenderOptions& options) {
  const cv::Point2d c_px = board_to_pixel(board, options, state.ball.position_m);
  const double r_px = std::max(2.0, board.ball.radius_m * options.px_per_m);
  cv::circle(image, to_fixed(c_px), to_fixed(r_px), kBall, cv::FILLED, cv::LINE_AA, kShift);
  // A specular highlight up and left of the centre, as under overhead light.
  const cv::Point2d h_px = c_px + cv::Point2d{-0.35 * r_px, -0.35 * r_px};
  cv::circle(image, to_fixed(h_px), to_fixed(std::max(1.0, 0.3 * r_px)), kBallHighlight, cv::FILLED, cv::LINE_AA,
             kShift);
}

void draw_hud(cv::Mat& image, const GameState& state) {
  // Three short lines rather than one long one: each fits std::string's inline buffer.
  char line[32];
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const double font_scale = 0.45;
  const int line_height_px = 16;
  const int x_px = 6;
  int y_px = 14;
  std::snprintf(line, sizeof line, "score %.0f", state.score);
  cv::putText(image, line, {x_px, y_px}, font, font_scale, kHudText, 1, cv::LINE_AA);
  y_px += line_height_px;
  std::snprintf(line, sizeof line, "balls %d", state.balls_left);
  cv::putText(image, line, {x_px, y_px}, font, font_scale, kHudText, 1, cv::LINE_AA);
  y_px += line_height_px;
  std::snprintf(line, sizeof line, "t %.1f s", state.time_s);
  cv::putText(image, line, {x_px, y_px}, font, font_scale, kHudText, 1, cv::LINE_AA);
}

// The colours above and what they mean (board_legend).
std::vector<plot::LegendEntry> legend_entries() {
  using plot::line_entry, plot::LineStyle;
  return {line_entry("wall", darken(kWall, 0.85)),
          line_entry("kicker (rho > 1 or a kick)", darken(kKicker, 0.85)),
          line_entry("ball eater", darken(kEater, 0.85)),
          line_entry("hidden until a flag shows it", kHidden, LineStyle::kDashed),
          line_entry("sensor", kSensor),
          line_entry("flipper (at rest)", kFlipper),
          plot::marker_entry("launcher", kLauncher, plot::Marker::kSquare)};
}

}  // namespace

cv::Size render_size(const table::Board& board, const RenderOptions& options) {
  const int playfield_w_px = static_cast<int>(std::lround(board.width_m * options.px_per_m)) + 2 * options.margin_px;
  const int w_px = options.draw_scale_bar ? std::max(playfield_w_px, kScaleBarMinWidth_px) : playfield_w_px;
  const int h_px = static_cast<int>(std::lround(board.height_m * options.px_per_m)) + 2 * options.margin_px +
                   (options.draw_scale_bar ? kScaleBarStrip_px : 0);
  return {w_px, h_px};
}

cv::Point2d board_to_pixel(const table::Board& board, const RenderOptions& options, const Vec2& p_board) {
  return {options.margin_px + p_board.x() * options.px_per_m,
          options.margin_px + (board.height_m - p_board.y()) * options.px_per_m};
}

cv::Mat render_board(const table::Board& board, const GameState* state, const RenderOptions& options) {
  if (!(options.px_per_m > 0.0) || options.margin_px < 0 || !(board.width_m > 0.0) || !(board.height_m > 0.0)) {
    throw std::invalid_argument("render_board: needs px_per_m > 0, margin_px >= 0 and a board of positive size");
  }
  // In doubles, before render_size's int conversion could overflow.
  const double extra_px = 2.0 * options.margin_px + (options.draw_scale_bar ? kScaleBarStrip_px : 0);
  const double longest_m = std::max(board.width_m, board.height_m);
  if (longest_m * options.px_per_m + extra_px > kMaxRenderSide_px) {
    throw std::invalid_argument(
        "render: " + format_number(options.px_per_m) + " px per metre draws this " + format_number(board.width_m) +
        " x " + format_number(board.height_m) + " m board at more than " + std::to_string(kMaxRenderSide_px) +
        " px a side; use at most " +
        format_number(std::floor((kMaxRenderSide_px - extra_px) / longest_m)) +
        " px per metre");
  }
  const cv::Size size = render_size(board, options);
  cv::Mat image(size, CV_8UC3, kBackground);
  draw_playfield(image, board, options);
  draw_sensors(image, board, options);
  draw_obstacles(image, board, state, options);
  if (options.draw_normals) draw_normals(image, board, options);
  draw_flippers(image, board, state, options);
  draw_launcher(image, board, options);
  if (state != nullptr) {
    if (state->ball_in_play) draw_ball(image, board, *state, options);
    if (options.draw_hud) draw_hud(image, *state);
  }
  if (options.draw_scale_bar) plot::draw_scale_bar(image, options.px_per_m, plot::Corner::kBottomLeft);
  return image;
}

std::vector<plot::LegendEntry> board_legend() { return legend_entries(); }

}  // namespace pinball::sim
