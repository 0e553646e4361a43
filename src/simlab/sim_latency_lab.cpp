#include "pinball/simlab/sim_latency_lab.h"

#include <algorithm>
#include <cmath>

#include "pinball/core/check.h"
#include "pinball/core/rng.h"

namespace pinball::simlab {
namespace {

// The flipper's angle at t_s: constant angular acceleration from the down stop
// to the up stop after each command's delay, held, then back once released.
class FlipperMotion {
 public:
  FlipperMotion(const table::Flipper& f, const SimLatencyOptions& o, const std::vector<double>& move_s,
                const std::vector<char>& dead)
      : f_(f), o_(o), move_s_(move_s), dead_(dead) {}

  double angle(double t_s) const {
    const double stroke = f_.theta_max_rad - f_.theta_min_rad;
    // The last event that started moving by t_s decides the angle.
    const auto it = std::upper_bound(move_s_.begin(), move_s_.end(), t_s);
    if (it == move_s_.begin()) return f_.theta_min_rad;
    const std::size_t k = static_cast<std::size_t>(it - move_s_.begin()) - 1;
    if (dead_[k]) return f_.theta_min_rad;
    const double since = t_s - move_s_[k];
    if (since < o_.stroke_s) return f_.theta_min_rad + stroke * (since / o_.stroke_s) * (since / o_.stroke_s);
    const double falling = since - o_.hold_s;  // released hold_s after the command, moving a delay later
    if (falling < 0.0) return f_.theta_max_rad;
    if (falling < o_.return_s) return f_.theta_max_rad - stroke * (falling / o_.return_s) * (falling / o_.return_s);
    return f_.theta_min_rad;
  }

 private:
  const table::Flipper& f_;
  const SimLatencyOptions& o_;
  const std::vector<double>& move_s_;
  const std::vector<char>& dead_;
};

}  // namespace

SimCameraConfig SimLatencyOptions::typical_camera() {
  SimCameraConfig c;
  c.realism = SimCameraRealism::typical(c.width_px, c.height_px);
  return c;
}

double min_latency_step_s(const SimCameraConfig& camera) {
  const SimCameraRealism& r = camera.realism;
  // The camera keeps 2048 samples: 1800 steps must span a frame's exposure, readout and delivery.
  const double needed_s = 1.0 / camera.fps + r.latency_min_s + 20.0 * r.latency_jitter_mean_s + 0.01;
  return needed_s / 1800.0;
}

SimLatencyRun simulate_latency_run(const table::Board& board, const SimLatencyOptions& o) {
  const char* ctx = "simulated latency run";
  check_input(o.flipper < board.flippers.size(), ctx, "the board has no flipper " + std::to_string(o.flipper));
  check_input(o.events >= 1 && o.events <= 10000, ctx, "events must be in [1, 10000]");
  check_input(std::isfinite(o.stroke_s) && o.stroke_s > 0.0 && std::isfinite(o.hold_s) && o.hold_s >= o.stroke_s &&
                  std::isfinite(o.return_s) && o.return_s > 0.0,
              ctx, "stroke_s and return_s must be > 0 and hold_s >= stroke_s");
  check_input(std::isfinite(o.actuation_delay_s) && o.actuation_delay_s >= 0.0 && o.actuation_delay_s <= 0.1, ctx,
              "actuation_delay_s must be in [0, 0.1] s");
  check_input(std::isfinite(o.spacing_s) && o.spacing_s >= o.actuation_delay_s + o.hold_s + o.return_s + 0.2, ctx,
              "spacing_s must leave 0.2 s of rest between the flipper's return and the next command");
  check_input(std::isfinite(o.lead_in_s) && o.lead_in_s >= 0.0, ctx, "lead_in_s must be >= 0");
  for (const int e : o.dead_events) check_input(e >= 0 && e < o.events, ctx, "dead_events must name events");
  SimCameraConfig cc = o.camera;
  cc.seed = o.seed;
  const SimCameraRealism& r = cc.realism;
  check_input(std::isfinite(o.step_s) && o.step_s >= min_latency_step_s(cc) && o.step_s <= 0.001, ctx,
              "step_s must be <= 1 ms and cover the camera's latency in 1800 steps");

  const table::Flipper& flipper = board.flippers[o.flipper];
  SimCameraSource camera(board, cc);
  camera.set_lamps_blinking(false);  // the lab's machine in test mode: lamps steady
  SimLatencyRun run;
  run.region = calibration::flipper_region(flipper, [&](const Vec2& p) { return camera.image_from_board(p); },
                                           camera.frame_size());
  run.true_latency_s = r.latency_min_s;
  run.timing.frame_period_s = 1.0 / cc.fps;
  run.timing.row_time_s = r.row_time_s;
  run.timing.actuation_delay_s = o.actuation_delay_s;
  run.timing.exposure_s = cc.exposure_s;

  Rng rng(o.seed ^ 0x1A7E9C5ULL);
  std::vector<double> move_s;
  std::vector<char> dead(static_cast<std::size_t>(o.events), 0);
  for (const int e : o.dead_events) dead[static_cast<std::size_t>(e)] = 1;
  for (int k = 0; k < o.events; ++k) {
    const double command = o.lead_in_s + k * o.spacing_s + rng.uniform(0.0, 1.0 / cc.fps);
    run.recording.command_t_s.push_back(command);
    move_s.push_back(command + o.actuation_delay_s);
  }
  const FlipperMotion motion(flipper, o, move_s, dead);
  const double end_s = run.recording.command_t_s.back() + o.spacing_s;
  const auto steps = static_cast<std::int64_t>(std::ceil(end_s / o.step_s));
  std::vector<double> theta;
  for (const table::Flipper& f : board.flippers) theta.push_back(f.theta_min_rad);
  vision::Frame frame;
  double latency_sum = 0.0;
  const Vec2 nowhere{-1.0, -1.0};
  for (std::int64_t i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) * o.step_s;
    theta[o.flipper] = motion.angle(t);
    camera.set_flipper_angles(theta);
    camera.observe_ball(t, nowhere, false);
    while (camera.read(frame)) {
      run.recording.add_frame(run.region, frame.gray, frame.t_s, frame.sequence);
      latency_sum += camera.truth().latency_s;
    }
  }
  run.frames_dropped = camera.counters().dropped;
  if (!run.recording.frames.empty()) {
    run.true_mean_latency_s = latency_sum / static_cast<double>(run.recording.frames.size());
  }
  return run;
}

}  // namespace pinball::simlab
