#include "draw_bench.h"

#include <algorithm>
#include <chrono>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/bus/channels.h"
#include "pinball/bus/message_convert.h"
#include "pinball_lcm/lcmt_pinball_observation.hpp"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/model_world.h"
#include "pinball/sim/renderer.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/view/view_render.h"

namespace pinball::bench {
namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

template <class T>
void feed(view::ViewState& state, const char* channel, const T& m, double t_s) {
  const std::vector<std::uint8_t> data = bus::encode_message(m);
  state.apply(channel, data.data(), data.size(), t_s);
}

// A view with everything on it: half a second of trail down the middle of
// the table, a projection onto the left flipper, a full command list, a coil
// on, and the daemon's stats.
view::ViewState busy_view(const table::Board& board) {
  view::ViewState state;
  const Vec2 start(0.5 * board.width_m, 0.6 * board.height_m);
  for (int k = 0; k <= 100; ++k) {
    const double t_s = k / 200.0;
    pinball_lcm::lcmt_pinball_observation o{};
    o.utime = static_cast<std::int64_t>(t_s * 1e6);
    o.seq = k;
    o.found = true;
    o.x_m = start.x() - 0.05 * t_s;
    o.y_m = start.y() - 0.4 * t_s - 0.5 * board.gravity_mps2 * t_s * t_s;
    o.confidence = 1.0;
    feed(state, bus::kObservationChannel, o, t_s);
    if (k % 12 == 0) {
      pinball_lcm::lcmt_pinball_flipper_command c{};
      c.utime = o.utime;
      c.seq = k;
      c.flipper = (k / 12) % 2;
      c.energize = (k / 24) % 2 == 0;
      feed(state, bus::kFlipperCommandChannel, c, t_s);
    }
  }
  const track::FlipperGeometry v = track::flipper_geometry_from_board(board);
  pinball_lcm::lcmt_pinball_projection p{};
  p.utime = 500'000;
  p.observation_seq = 100;
  p.valid = true;
  p.flipper = 0;
  p.hittable = true;
  p.speed_mps = 1.5;
  p.angle_rad = -1.2;
  p.h = 0.6;
  p.d_m = 0.3;
  p.t_impact_s = 0.25;
  const Vec2 impact = v.lines[0].pivot + 0.6 * (v.apex - v.lines[0].pivot) / v.h_apex[0];
  p.impact_x_m = impact.x();
  p.impact_y_m = impact.y();
  feed(state, bus::kProjectionChannel, p, 0.5);
  pinball_lcm::lcmt_pinball_driver_status d{};
  d.utime = 500'000;
  d.coils_on = 1;
  feed(state, bus::kDriverStatusChannel, d, 0.5);
  pinball_lcm::lcmt_pinball_daemon_stats s{};
  s.utime = 500'000;
  s.num_stages = 1;
  s.stage = {"frame->can_written"};
  s.count = {100};
  s.p50_us = {100.0};
  s.p99_us = {250.0};
  s.max_us = {400.0};
  feed(state, bus::kStatsChannel, s, 0.5);
  return state;
}

// Best frames/s of `draw` over the repeats.
template <class Draw>
DrawCost measure(const DrawBenchOptions& o, const char* what, Draw draw,
                 const std::function<void(const std::string&)>& progress) {
  DrawCost cost;
  for (int r = 0; r < o.repeats; ++r) {
    cv::Mat last;
    const double t0 = now_s();
    for (int i = 0; i < o.frames; ++i) last = draw();
    const double fps = o.frames / std::max(1e-9, now_s() - t0);
    cost.frames_per_s = std::max(cost.frames_per_s, fps);
    cost.width_px = last.cols;
    cost.height_px = last.rows;
    if (progress) progress(std::string(what) + " " + std::to_string(r + 1) + "/" + std::to_string(o.repeats));
  }
  cost.ms_per_frame = 1e3 / cost.frames_per_s;
  return cost;
}

nlohmann::json to_json(const DrawCost& c) {
  return {{"width_px", c.width_px}, {"height_px", c.height_px}, {"frames_per_s", c.frames_per_s},
          {"ms_per_frame", c.ms_per_frame}};
}

}  // namespace

DrawBenchReport run_draw_bench(const table::Board& board, const DrawBenchOptions& o,
                               const std::function<void(const std::string&)>& progress) {
  DrawBenchReport r;
  r.frames = o.frames;
  r.repeats = o.repeats;
  // pinball play's picture, a second into a ball.
  const std::unique_ptr<sim::World> world = sim::make_model_world(board);
  sim::GameState game = sim::make_game_state(board, 1);
  sim::begin_ball(*world, game, board.launcher.pull);
  while (game.time_s < 1.0) world->step(game);
  const sim::RenderOptions render;
  r.play = measure(o, "play", [&] { return sim::render_board(board, &game, render); }, progress);

  view::ViewScene scene;
  scene.board = board;
  scene.geometry = track::flipper_geometry_from_board(board);
  scene.gravity_mps2 = board.gravity_mps2;
  const view::ViewState state = busy_view(board);
  r.view = measure(o, "view", [&] { return view::render_view(scene, state, {"bench", "draw"}); }, progress);

  const cv::Mat picture = view::render_view(scene, state, {"bench", "draw"});
  r.copy = measure(o, "copy", [&] { return picture.clone(); }, progress);
  return r;
}

nlohmann::json to_json(const DrawBenchReport& r) {
  return {{"benchmark", "draw"},
          {"play", to_json(r.play)},
          {"view", to_json(r.view)},
          {"baseline_copy", to_json(r.copy)},
          {"frames", r.frames},      {"repeats", r.repeats},    {"target_frames_per_s", 60}};
}

}  // namespace pinball::bench
