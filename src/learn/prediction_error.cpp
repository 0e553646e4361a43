#include "pinball/learn/prediction_error.h"

#include <algorithm>
#include <cmath>

#include "pinball/core/running_stats.h"
#include "pinball/core/statistics.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/model_world.h"
#include "pinball/track/trajectory_fit.h"

namespace pinball::learn {
namespace {

std::vector<track::Observation> history_of(const bus::RecordedPlay& play, std::size_t last, int frames) {
  std::vector<track::Observation> obs;
  for (std::size_t i = last + 1 - static_cast<std::size_t>(frames); i <= last; ++i)
    obs.push_back({play.frames[i].t_s, play.frames[i].p_board, 1.0, 0.0});
  return obs;
}

// Where the camera saw the ball at time t: between the two frames around it.
bool seen_at(const bus::RecordedPlay& play, std::size_t from, double t, Vec2& p) {
  for (std::size_t i = from; i + 1 < play.frames.size(); ++i) {
    const bus::RecordedFrame& a = play.frames[i];
    const bus::RecordedFrame& b = play.frames[i + 1];
    if (b.t_s < t) continue;
    if (a.t_s > t || !a.found || !b.found || b.t_s <= a.t_s) return false;
    const double s = (t - a.t_s) / (b.t_s - a.t_s);
    p = a.p_board + s * (b.p_board - a.p_board);
    return true;
  }
  return false;
}

// True when the frames seen from the moment to the horizon fit one parabola.
bool flew_free(const bus::RecordedPlay& play, std::size_t from, double t_end, double sigma_m) {
  std::vector<track::Observation> obs;
  for (std::size_t i = from; i < play.frames.size() && play.frames[i].t_s <= t_end; ++i)
    if (play.frames[i].found) obs.push_back({play.frames[i].t_s, play.frames[i].p_board, 1.0, 0.0});
  const track::TrajectoryFit fit = track::fit_free_gravity(obs, sigma_m);
  return fit.valid && fit.chi2 <= track::chi2_threshold(fit.dof);
}

}  // namespace

std::vector<PredictionStart> prediction_starts(std::span<const bus::RecordedPlay> recordings,
                                               const PredictionOptions& o) {
  std::vector<PredictionStart> starts;
  const auto history = static_cast<std::size_t>(o.history_frames);
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    const bus::RecordedPlay& play = recordings[r];
    std::size_t next_command = 0;
    for (std::size_t i = history - 1; i < play.frames.size(); i += static_cast<std::size_t>(o.stride_frames)) {
      const double t = play.frames[i].t_s;
      bool all_seen = true;
      for (std::size_t k = i + 1 - history; k <= i; ++k) all_seen = all_seen && play.frames[k].found;
      if (!all_seen) continue;
      while (next_command < play.commands.size() && play.commands[next_command].t_s < t - o.command_margin_s)
        ++next_command;
      // Flippers down: no command near the window, and the last one before it released (or none).
      if (next_command < play.commands.size() && play.commands[next_command].t_s <= t + o.horizon_s) continue;
      if (next_command > 0 && play.commands[next_command - 1].energize) continue;
      Vec2 seen;
      if (!seen_at(play, i, t + o.horizon_s, seen)) continue;
      const std::vector<track::Observation> obs = history_of(play, i, o.history_frames);
      const track::TrajectoryFit fit = track::fit_free_gravity(obs, o.sigma_m);
      if (!fit.valid || fit.chi2 > track::chi2_threshold(fit.dof)) continue;
      starts.push_back({r, i});
    }
  }
  return starts;
}

PredictionError prediction_error(const table::Board& belief, std::span<const bus::RecordedPlay> recordings,
                                 std::span<const PredictionStart> starts, const PredictionOptions& o) {
  const std::unique_ptr<sim::World> world = sim::make_model_world(belief);
  sim::GameState state = sim::make_game_state(belief, 1);
  const auto steps = static_cast<std::uint64_t>(std::llround(o.horizon_s / world->dt_s()));
  std::vector<double> errors;
  errors.reserve(starts.size());
  RunningStats free, collided;
  for (const PredictionStart& s : starts) {
    const bus::RecordedPlay& play = recordings[s.recording];
    const track::TrajectoryFit fit =
        track::fit_fixed_gravity(history_of(play, s.frame, o.history_frames), belief.gravity_mps2, o.sigma_m);
    Vec2 seen;
    if (!fit.valid || !seen_at(play, s.frame, fit.t_ref_s + o.horizon_s, seen)) continue;
    sim::reset_game(belief, state);
    state.ball.position_m = fit.p_ref;
    state.ball.velocity_mps = fit.v_ref;
    state.ball_in_play = true;
    for (std::uint64_t k = 0; k < steps && state.ball_in_play; ++k) world->step(state);
    errors.push_back((state.ball.position_m - seen).norm());  // a lost ball: where the model lost it
    (flew_free(play, s.frame, fit.t_ref_s + o.horizon_s, o.sigma_m) ? free : collided).add(errors.back());
  }
  PredictionError out;
  out.moments = errors.size();
  if (errors.empty()) return out;
  RunningStats stats;
  for (double e : errors) stats.add(e);
  out.mean_m = stats.mean();
  out.mean_ci95_m = stats.ci95_half_width();
  out.median_m = median(errors);
  out.p90_m = quantile(errors, 0.9);
  out.free_moments = static_cast<std::size_t>(free.count());
  out.free_mean_m = free.mean();
  out.collision_mean_m = collided.mean();
  return out;
}

}  // namespace pinball::learn
