#pragma once
// A small recorded game for the viewer's tests: 1 s of a ball falling down
// the table, seen at 200 frames/s, with a projection per frame, one fire and
// one release of the left flipper, driver statuses and one PINBALL_STATS, in
// LCM's log format as pinballd writes it.

#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <fstream>
#include <string>
#include <vector>

#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/message_convert.h"
#include "common/temp_path.h"
#include "pinball/core/geometry.h"
#include "pinball/view/log_player.h"
#include "pinball/view/view_render.h"
#include "pinball_lcm/lcmt_pinball_daemon_stats.hpp"
#include "pinball_lcm/lcmt_pinball_driver_status.hpp"
#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"
#include "pinball_lcm/lcmt_pinball_observation.hpp"
#include "pinball_lcm/lcmt_pinball_projection.hpp"

namespace pinball::testing {

inline constexpr double kViewLogFps = 200.0;
inline constexpr int kViewLogFrames = 200;
inline constexpr double kViewLogFire_s = 0.80;     ///< the left coil fires here...
inline constexpr double kViewLogRelease_s = 0.90;  ///< ...and is released here
inline constexpr std::int64_t kViewLogStart_us = 1'700'000'000'000'000;
inline constexpr std::int64_t kViewLogDroppedFrame = 50;  ///< this frame is missing from the log

/// Where the recorded ball is at `t_s` (m): thrown from (0.30, 0.90) down the table.
inline Vec2 view_log_ball(double t_s) { return {0.30 - 0.05 * t_s, 0.90 - 0.30 * t_s - 0.5 * 1.11 * t_s * t_s}; }

/// Writes the log to `path`; returns its bytes' event count.
inline int write_view_log(const std::string& path) {
  std::string bytes;
  std::int64_t n = 0;
  auto add = [&](const char* channel, double t_s, const auto& m) {
    const std::vector<std::uint8_t> data = bus::encode_message(m);
    const std::int64_t utime = kViewLogStart_us + std::llround(t_s * 1e6);
    bus::append_lcm_event(bytes, n++, utime, channel, data.data(), data.size());
  };
  bool fired = false, released = false;
  for (int k = 0; k < kViewLogFrames; ++k) {
    const double t_s = k / kViewLogFps;
    if (!fired && t_s >= kViewLogFire_s) {
      fired = true;
      pinball_lcm::lcmt_pinball_flipper_command c{};
      c.utime = static_cast<std::int64_t>(t_s * 1e6);
      c.flipper = 0;
      c.energize = true;
      c.cause = pinball_lcm::lcmt_pinball_flipper_command::CAUSE_PROJECTION;
      add(bus::kFlipperCommandChannel, t_s, c);
    }
    if (!released && t_s >= kViewLogRelease_s) {
      released = true;
      pinball_lcm::lcmt_pinball_flipper_command c{};
      c.utime = static_cast<std::int64_t>(t_s * 1e6);
      c.seq = 1;
      c.flipper = 0;
      c.energize = false;
      c.cause = pinball_lcm::lcmt_pinball_flipper_command::CAUSE_LAUNCH;
      add(bus::kFlipperCommandChannel, t_s, c);
    }
    if (k % 20 == 0) {
      pinball_lcm::lcmt_pinball_driver_status d{};
      d.utime = static_cast<std::int64_t>(t_s * 1e6);
      d.seq = k / 20;
      d.bus_state = 3;
      d.board_valid = true;
      d.coils_on = (t_s >= kViewLogFire_s && t_s < kViewLogRelease_s) ? 1 : 0;
      add(bus::kDriverStatusChannel, t_s, d);
    }
    if (k == kViewLogDroppedFrame) continue;
    const Vec2 p = view_log_ball(t_s);
    pinball_lcm::lcmt_pinball_observation o{};
    o.utime = static_cast<std::int64_t>(t_s * 1e6);
    o.seq = k;
    o.found = true;
    o.x_m = p.x();
    o.y_m = p.y();
    o.confidence = 1.0;
    add(bus::kObservationChannel, t_s, o);
    // A projection to where the ball will cross y = 0.15 (a stand-in for the 'V').
    const double a = 0.5 * 1.11, b = 0.30 + 1.11 * t_s, c = p.y() - 0.15;
    pinball_lcm::lcmt_pinball_projection j{};
    j.utime = o.utime;
    j.seq = k;
    j.observation_seq = k;
    if (c <= 0.0) {  // past the line: no projection
      add(bus::kProjectionChannel, t_s, j);
      continue;
    }
    const double dt = (-b + std::sqrt(b * b + 4.0 * a * c)) / (2.0 * a);
    const Vec2 impact = view_log_ball(t_s + dt);
    j.valid = true;
    j.flipper = 0;
    j.hittable = true;
    j.speed_mps = 1.0;
    j.angle_rad = -1.2;
    j.h = 0.5;
    j.d_m = (impact - p).norm();
    j.t_impact_s = dt;
    j.impact_x_m = impact.x();
    j.impact_y_m = impact.y();
    add(bus::kProjectionChannel, t_s, j);
  }
  pinball_lcm::lcmt_pinball_daemon_stats s{};
  s.utime = 1'000'000;
  s.num_stages = 1;
  s.stage = {"frame->can_written"};
  s.count = {10};
  s.p50_us = {300.0};
  s.p99_us = {812.0};
  s.max_us = {900.0};
  s.frames = 199;
  s.frames_dropped = 1;
  s.camera_stalls = 0;
  add(bus::kStatsChannel, 1.0, s);  // the last event: the log ends at 1 s
  std::ofstream(path, std::ios::binary) << bytes;
  return static_cast<int>(n);
}

/// The recorded game, written under `name` in the test's temporary folder and read into a player.
inline view::LogPlayer recorded_view_game(const std::string& name) {
  const std::string path = temp_path(name, "game.lcmlog");
  write_view_log(path);
  return view::LogPlayer(bus::read_lcm_log(path));
}

/// Centroid (px) of the pixels of exactly `colour` in a BGR image; (-1, -1) when none.
inline cv::Point2d colour_centroid(const cv::Mat& image, const cv::Scalar& colour, int* count = nullptr) {
  cv::Mat mask;
  cv::inRange(image, colour, colour, mask);
  const cv::Moments m = cv::moments(mask, true);
  if (count != nullptr) *count = static_cast<int>(m.m00);
  return m.m00 == 0 ? cv::Point2d(-1, -1) : cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
}

/// The scene the view's tests draw on: the thesis table at 800 px/m, no calibration or controller.
inline view::ViewScene test_view_scene() {
  return view::load_view_scene(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board", "", "", 800.0);
}

/// Centroid (px) of the ball's colour on the table part of a view picture (the
/// panel's legend shows the colour too).
inline cv::Point2d ball_on_table(const cv::Mat& picture) {
  return colour_centroid(picture(view::view_table_rect(test_view_scene())), view::kViewBallColour);
}

}  // namespace pinball::testing
