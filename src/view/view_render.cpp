#include "pinball/view/view_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "pinball/bus/message_convert.h"
#include "pinball/calibration/calibration_file.h"
#include "pinball/plot/draw.h"
#include "pinball/sim/game_state.h"
#include "pinball/table/board_loader.h"
#include "pinball/track/projection.h"
#include "pinball/track/tracker.h"

namespace pinball::view {
namespace {

constexpr int kPanelWidth_px = 330;
constexpr int kStripHeight_px = 44;
constexpr int kMinTableHeight_px = 560;  // room for the panel's text and legend beside a small table
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;
constexpr int kLine_px = 17;
const cv::Scalar kPanelBackground{40, 40, 40};
const cv::Scalar kText{235, 235, 235};
const cv::Scalar kDimText{150, 150, 150};
const cv::Scalar kVColour{120, 120, 120};
const cv::Scalar kReleaseColour{200, 160, 60};
const cv::Scalar kCoilOffColour{90, 90, 90};

const char* cause_name(int cause) {
  switch (cause) {
    case pinball_lcm::lcmt_pinball_flipper_command::CAUSE_PROJECTION: return "projection";
    case pinball_lcm::lcmt_pinball_flipper_command::CAUSE_LAUNCH: return "launch";
    case pinball_lcm::lcmt_pinball_flipper_command::CAUSE_BALL_LOST: return "ball lost";
    case pinball_lcm::lcmt_pinball_flipper_command::CAUSE_CAMERA_STALL: return "camera stall";
    case pinball_lcm::lcmt_pinball_flipper_command::CAUSE_SHUTDOWN: return "shutdown";
    case pinball_lcm::lcmt_pinball_flipper_command::CAUSE_BUS_FAULT: return "bus fault";
    default: return "?";
  }
}

const char* flipper_name(int flipper) { return flipper == 0 ? "left" : flipper == 1 ? "right" : "all"; }

cv::Point to_point(const cv::Point2d& p) { return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))}; }

void text(cv::Mat& image, const std::string& s, cv::Point at, const cv::Scalar& colour = kText) {
  cv::putText(image, s, at, kFont, kFontScale, colour, 1, cv::LINE_AA);
}

std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// The table: the board with each flipper up while its coil is on (the daemon
// sees no flipper angles; the coil says where the flipper is going).
cv::Mat draw_table(const ViewScene& scene, const ViewState& state) {
  sim::GameState flippers = sim::make_game_state(scene.board, 0);
  for (std::size_t i = 0; i < flippers.flippers.size(); ++i) {
    const bool on = state.coil_on(static_cast<int>(i));
    flippers.flippers[i].energized = on;
    flippers.flippers[i].theta_rad = on ? scene.board.flippers[i].theta_max_rad : scene.board.flippers[i].theta_min_rad;
  }
  flippers.ball_in_play = false;
  sim::RenderOptions options = scene.render;
  options.draw_hud = false;
  return sim::render_board(scene.board, &flippers, options);
}

void draw_v(cv::Mat& image, const ViewScene& scene) {
  for (const track::FlipperLine& line : scene.geometry.lines) {
    cv::line(image, to_point(view_pixel(scene, line.pivot)), to_point(view_pixel(scene, scene.geometry.apex)), kVColour, 1,
             cv::LINE_AA);
  }
}

void draw_trail_and_ball(cv::Mat& image, const ViewScene& scene, const ViewState& state) {
  const double r_px = std::max(2.0, scene.board.ball.radius_m * scene.render.px_per_m);
  const std::deque<Sighting>& trail = state.trail();
  for (std::size_t i = 1; i < trail.size(); ++i) {
    cv::line(image, to_point(view_pixel(scene, trail[i - 1].p_board)), to_point(view_pixel(scene, trail[i].p_board)),
             kViewTrailColour, 2, cv::LINE_AA);
  }
  for (const Sighting& s : trail) cv::circle(image, to_point(view_pixel(scene, s.p_board)), 2, kViewTrailColour, cv::FILLED);
  if (const std::optional<Sighting> ball = state.ball()) {
    cv::circle(image, to_point(view_pixel(scene, ball->p_board)), static_cast<int>(std::lround(r_px)), kViewBallColour,
               cv::FILLED, cv::LINE_8);
  }
}

void draw_projection(cv::Mat& image, const ViewScene& scene, const ViewState& state,
                     const pinball_lcm::lcmt_pinball_projection& p) {
  std::vector<cv::Point> path;
  constexpr int kSegments = 40;
  for (int i = 0; i <= kSegments; ++i) {
    const double t_s = p.t_impact_s * i / kSegments;
    path.push_back(to_point(view_pixel(scene, projected_path_point(scene, state.projection_origin(), p, t_s))));
  }
  cv::polylines(image, path, false, kViewTrajectoryColour, 2, cv::LINE_AA);
  const cv::Point impact = to_point(view_pixel(scene, Vec2(p.impact_x_m, p.impact_y_m)));
  cv::drawMarker(image, impact, kViewTrajectoryColour, cv::MARKER_TILTED_CROSS, 14, 2, cv::LINE_AA);
  std::string label = format("d %.0f mm", 1e3 * p.d_m);
  if (const std::optional<double> dc = d_critical_m(scene, p)) label += format(" / crit %.0f mm", 1e3 * *dc);
  // Beside the impact, on whichever side keeps the label on the table.
  int baseline = 0;
  const int width_px = cv::getTextSize(label, kFont, kFontScale, 1, &baseline).width;
  const cv::Point at = impact.x + 10 + width_px < image.cols ? impact + cv::Point(10, -10)
                                                             : impact + cv::Point(-10 - width_px, -10);
  text(image, label, at, kViewTrajectoryColour);
}

void draw_commands_on_flippers(cv::Mat& image, const ViewScene& scene, const ViewState& state) {
  for (std::size_t i = 0; i < scene.board.flippers.size() && i < 2; ++i) {
    const std::optional<SentCommand> c = state.flashing_command(static_cast<int>(i));
    if (!c) continue;
    const cv::Point pivot = to_point(view_pixel(scene, scene.board.flippers[i].pivot));
    text(image, c->energize ? "FIRE" : "release", pivot + cv::Point(i == 0 ? -10 : -50, 28),
         c->energize ? kViewCoilOnColour : kReleaseColour);
  }
}

void draw_panel(cv::Mat& panel, const ViewScene& scene, const ViewState& state) {
  int y = 22;
  auto line = [&](const std::string& s, const cv::Scalar& colour = kText) {
    text(panel, s, {10, y}, colour);
    y += kLine_px;
  };
  line(state.ball_number() >= 0 ? format("ball %.0f   points %.0f", state.ball_number() + 1.0, state.ball_points())
                                : std::string("no ball launched yet"));
  if (const std::optional<Sighting> b = state.ball()) {
    line(format("ball at x %.3f  y %.3f m", b->p_board.x(), b->p_board.y()));
  } else {
    line("ball not seen in the last frame", kDimText);
  }
  y += 6;
  line("projection", kDimText);
  if (const auto& p = state.projection()) {
    line(std::string(flipper_name(p->flipper)) + " flipper" + format(", h %.2f", p->h) +
         (p->hittable ? "" : " (not hittable)") + (p->rolling ? " rolling" : ""));
    line(format("d %.1f mm, t_impact %.1f ms", 1e3 * p->d_m, 1e3 * p->t_impact_s));
    if (const std::optional<double> dc = d_critical_m(scene, *p)) {
      line(format("d_critical %.1f mm", 1e3 * *dc), p->d_m <= *dc ? kViewCoilOnColour : kText);
    } else {
      line("d_critical: no controller given", kDimText);
    }
    line(format("speed %.2f m/s, angle %.1f deg", p->speed_mps, p->angle_rad * 180.0 / M_PI));
  } else {
    line(std::string("none: ") + track::to_string(static_cast<track::NoProjection>(state.no_projection_reason())), kDimText);
  }
  y += 6;
  line("coils (PINBALL_DRIVER_STATUS)", kDimText);
  for (int i = 0; i < 2; ++i) {
    const bool known = state.driver_status().has_value();
    const bool on = state.coil_on(i);
    cv::rectangle(panel, cv::Rect(10, y - 11, 14, 14), known ? (on ? kViewCoilOnColour : kCoilOffColour) : kPanelBackground,
                  cv::FILLED);
    cv::rectangle(panel, cv::Rect(10, y - 11, 14, 14), kText, 1);
    text(panel, std::string(flipper_name(i)) + (known ? (on ? ": on" : ": off") : ": no status yet"), {32, y});
    y += kLine_px + 2;
  }
  y += 4;
  line("commands sent (PINBALL_FLIPPER_CMD)", kDimText);
  const std::deque<SentCommand>& commands = state.commands();
  if (commands.empty()) line("none", kDimText);
  for (auto it = commands.rbegin(); it != commands.rend(); ++it) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%8.3f s %-5s %-7s %s", it->t_s, flipper_name(it->flipper),
                  it->energize ? "fire" : "release", cause_name(it->cause));
    line(buf, it->energize ? kViewCoilOnColour : kReleaseColour);
  }
}

// What the colours mean, at the foot of the panel.
void draw_legend(cv::Mat& panel) {
  const std::vector<plot::LegendEntry> entries{
      plot::marker_entry("ball (last frame)", kViewBallColour, plot::Marker::kDot),
      plot::line_entry("its sightings, last 0.5 s", kViewTrailColour),
      plot::line_entry("projected path, impact", kViewTrajectoryColour, plot::LineStyle::kSolid,
                       plot::Marker::kTiltedCross),
      plot::line_entry("flippers' V", kVColour),
      plot::marker_entry("coil on / fire command", kViewCoilOnColour, plot::Marker::kSquare),
      plot::marker_entry("release command", kReleaseColour, plot::Marker::kSquare)};
  plot::draw_legend(panel, entries, plot::Corner::kBottomLeft);
}

void draw_strip(cv::Mat& strip, const ViewState& state, const ViewCaption& caption) {
  const DaemonFigures f = state.figures();
  std::string figures = format("camera %.0f fps", f.frame_rate_hz) +
                        format("   dropped %.0f   stalls %.0f", static_cast<double>(f.frames_dropped),
                               static_cast<double>(f.camera_stalls));
  figures += f.frame_to_can_p99_us >= 0.0 ? format("   frame->CAN p99 %.0f us", f.frame_to_can_p99_us)
                                          : std::string("   frame->CAN p99: no PINBALL_STATS yet");
  if (state.malformed() > 0) figures += format("   malformed %.0f", static_cast<double>(state.malformed()));
  text(strip, figures, {10, 17});
  text(strip, "pinball view: " + caption.source + "   " + caption.status, {10, 36}, kDimText);
}

}  // namespace

ViewScene load_view_scene(const std::string& board_path, const std::string& calibration_path,
                          const std::string& controller_path, double px_per_m) {
  ViewScene scene;
  scene.board = table::load_board(board_path);
  track::TrackerConfig tracker = track::default_tracker_config(scene.board, {});
  if (!calibration_path.empty()) {
    const calibration::Calibration c = calibration::read_calibration(calibration_path);
    calibration::apply_calibration(c, calibration_path, scene.board);
    scene.geometry = track::flipper_geometry_from_board(scene.board);
    calibration::apply_calibration(c, calibration_path, tracker, scene.geometry);
  } else {
    scene.geometry = track::flipper_geometry_from_board(scene.board);
  }
  scene.gravity_mps2 = tracker.g_mps2;
  if (!controller_path.empty()) {
    scene.controller = std::make_shared<const control::ControllerSpec>(control::load_controller(controller_path));
  }
  scene.render.px_per_m = px_per_m;
  scene.render.draw_hud = false;
  return scene;
}

std::optional<double> d_critical_m(const ViewScene& scene, const pinball_lcm::lcmt_pinball_projection& m) {
  if (!scene.controller || !m.valid) return std::nullopt;
  const track::TrajectoryProjection p = bus::from_lcm_projection(m);
  if (scene.controller->spastic) {
    if (!p.hittable) return std::nullopt;
    return scene.controller->spastic->reach_m;
  }
  if (scene.controller->shot_table) {
    const control::ImitationDecision d = scene.controller->shot_table->decide(p);
    if (!d.fire) return std::nullopt;
    return d.d_critical_m;
  }
  return scene.controller->action_function.action(p).d_critical_m;
}

Vec2 projected_path_point(const ViewScene& scene, const Vec2& origin, const pinball_lcm::lcmt_pinball_projection& p,
                          double t_s) {
  const Vec2 impact(p.impact_x_m, p.impact_y_m);
  const Vec2 g(0.0, -scene.gravity_mps2);
  const double T = p.t_impact_s;
  if (!(T > 1e-6)) return impact;
  // p(t) = origin + v0 t + g t^2 / 2 with p(T) = impact.
  const Vec2 v0 = (impact - origin - 0.5 * g * T * T) / T;
  return origin + v0 * t_s + 0.5 * g * t_s * t_s;
}

cv::Rect view_table_rect(const ViewScene& scene) {
  sim::RenderOptions options = scene.render;
  options.draw_hud = false;
  return {cv::Point(0, 0), sim::render_size(scene.board, options)};
}

cv::Point2d view_pixel(const ViewScene& scene, const Vec2& p_board) {
  return sim::board_to_pixel(scene.board, scene.render, p_board);
}

cv::Mat render_view(const ViewScene& scene, const ViewState& state, const ViewCaption& caption) {
  cv::Mat table = draw_table(scene, state);
  plot::draw_scale_bar(table, scene.render.px_per_m, plot::Corner::kTopLeft);
  draw_v(table, scene);
  if (const auto& p = state.projection()) draw_projection(table, scene, state, *p);
  draw_trail_and_ball(table, scene, state);
  draw_commands_on_flippers(table, scene, state);

  const int width_px = table.cols + kPanelWidth_px;
  const int height_px = std::max(table.rows, kMinTableHeight_px) + kStripHeight_px;
  cv::Mat picture(height_px, width_px, CV_8UC3, kPanelBackground);
  table.copyTo(picture(cv::Rect(0, 0, table.cols, table.rows)));
  cv::Mat panel = picture(cv::Rect(table.cols, 0, kPanelWidth_px, height_px - kStripHeight_px));
  draw_panel(panel, scene, state);
  draw_legend(panel);
  cv::Mat strip = picture(cv::Rect(0, height_px - kStripHeight_px, width_px, kStripHeight_px));
  strip.setTo(cv::Scalar(25, 25, 25));
  draw_strip(strip, state, caption);
  return picture;
}

}  // namespace pinball::view
