#include "pinball/learn/prediction_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pinball/core/running_stats.h"
#include "pinball/core/statistics.h"
#include "pinball/learn/identification.h"
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

// True when the ball never moved faster than max_speed_mps between two frames
// that saw it, from `from` to the first frame at or past t_end: one ball all
// along (a drained ball and the next one in the shooter lane are two).
bool one_ball(const bus::RecordedPlay& play, std::size_t from, double t_end, double max_speed_mps) {
  std::size_t last_seen = from;
  for (std::size_t i = from + 1; i < play.frames.size(); ++i) {
    const bus::RecordedFrame& b = play.frames[i];
    if (b.found) {
      const bus::RecordedFrame& a = play.frames[last_seen];
      if (!(b.t_s > a.t_s) || (b.p_board - a.p_board).norm() > max_speed_mps * (b.t_s - a.t_s)) return false;
      last_seen = i;
    }
    if (b.t_s >= t_end) return true;
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
  std::vector<track::AccelerationFit> own;  // each start's history with an acceleration of its own
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
      if (!seen_at(play, i, t + o.horizon_s, seen) || !one_ball(play, i, t + o.horizon_s, o.max_speed_mps)) continue;
      const std::vector<track::Observation> obs = history_of(play, i, o.history_frames);
      const track::TrajectoryFit fit = track::fit_free_gravity(obs, o.sigma_m);
      if (!fit.valid || fit.chi2 > track::chi2_threshold(fit.dof)) continue;
      starts.push_back({r, i});
      own.push_back(track::fit_free_acceleration(obs, o.sigma_m));
    }
  }
  // Under g or pushed: against the usual acceleration of these histories
  // (most balls fly free), by how much χ² an acceleration of its own saves.
  std::vector<double> down_mps2;
  for (const track::AccelerationFit& f : own)
    if (f.valid) down_mps2.push_back(-f.a_mps2.y());
  if (down_mps2.empty()) return starts;
  const double usual_g_mps2 = median(down_mps2);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const track::TrajectoryFit usual = track::fit_fixed_gravity(
        history_of(recordings[starts[k].recording], starts[k].frame, o.history_frames), usual_g_mps2, o.sigma_m);
    starts[k].pushed = own[k].valid && usual.chi2 - own[k].chi2 > track::chi2_threshold(2);
  }
  return starts;
}

ErrorRatio paired_error_ratio(const PredictionError& model, const PredictionError& baseline) {
  if (model.errors_m.size() != baseline.errors_m.size())
    throw std::invalid_argument("paired_error_ratio: " + std::to_string(model.errors_m.size()) + " against " +
                                std::to_string(baseline.errors_m.size()) + " starts");
  double sum_model = 0.0, sum_baseline = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < model.errors_m.size(); ++i) {
    if (std::isnan(model.errors_m[i]) || std::isnan(baseline.errors_m[i])) continue;
    sum_model += model.errors_m[i];
    sum_baseline += baseline.errors_m[i];
    ++n;
  }
  ErrorRatio out;
  out.moments = n;
  if (n < 2 || !(sum_baseline > 0.0)) return out;
  out.ratio = sum_model / sum_baseline;
  // Delta method: R = mean(a)/mean(b), var R ≈ var(a − R·b) / (n·mean(b)²).
  RunningStats d;
  for (std::size_t i = 0; i < model.errors_m.size(); ++i)
    if (!std::isnan(model.errors_m[i]) && !std::isnan(baseline.errors_m[i]))
      d.add(model.errors_m[i] - out.ratio * baseline.errors_m[i]);
  const double mean_baseline = sum_baseline / static_cast<double>(n);
  out.ci95 = d.ci95_half_width() / mean_baseline;
  return out;
}

PredictionError prediction_error(const table::Board& belief, std::span<const bus::RecordedPlay> recordings,
                                 std::span<const PredictionStart> starts, const PredictionOptions& o) {
  const std::unique_ptr<sim::World> world = sim::make_model_world(belief);
  sim::GameState state = sim::make_game_state(belief, 1);
  const auto steps = static_cast<std::uint64_t>(std::llround(o.horizon_s / world->dt_s()));
  std::vector<double> errors;
  errors.reserve(starts.size());
  std::vector<double> each(starts.size(), std::numeric_limits<double>::quiet_NaN());
  RunningStats free, collided, under_g, pushed;
  // What the model's ball hit first: a material group, then the flippers, then nothing, then lost.
  const std::vector<table::ObstacleGroupOverlay> groups = material_groups(belief);
  const std::vector<int> group_of = material_group_of(belief, groups);
  const std::size_t flipper_hit = groups.size();
  const std::size_t nothing_hit = flipper_hit + belief.flippers.size();
  const std::size_t lost = nothing_hit + 1;
  std::vector<RunningStats> by_hit(lost + 1);
  for (std::size_t index = 0; index < starts.size(); ++index) {
    const PredictionStart& s = starts[index];
    const bus::RecordedPlay& play = recordings[s.recording];
    const std::vector<track::Observation> history = history_of(play, s.frame, o.history_frames);
    const track::TrajectoryFit fit = track::fit_fixed_gravity(history, belief.gravity_mps2, o.sigma_m);
    Vec2 seen;
    if (!fit.valid || !seen_at(play, s.frame, fit.t_ref_s + o.horizon_s, seen)) continue;
    sim::reset_game(belief, state);
    state.ball.position_m = fit.p_ref;
    state.ball.velocity_mps = fit.v_ref;
    if (s.pushed) {
      // g forced on a pushed history gets the velocity wrong by the push
      // times half the history (0.11 m/s for a 1.95 m/s² skid over 115 ms):
      // the start is the history's own acceleration fit's.
      const track::AccelerationFit own = track::fit_free_acceleration(history, o.sigma_m);
      state.ball.position_m = own.p_ref;
      state.ball.velocity_mps = own.v_ref;
    }
    state.ball_in_play = true;
    std::size_t first_hit = nothing_hit;
    Vec2 predicted = state.ball.position_m;
    const double t_end = state.time_s + static_cast<double>(steps) * world->dt_s();
    for (std::uint64_t k = 0; k < steps; ++k) {
      const Vec2 p = state.ball.position_m;
      const Vec2 v = state.ball.velocity_mps;
      const double t = state.time_s;
      const sim::StepEvents e = world->step(state);
      predicted = state.ball.position_m;
      if (e.has(sim::StepEvents::kBallLost)) {
        // The model takes a lost ball off the table (to the launcher); the
        // camera still sees it go on. Past the eat line the model has nothing
        // left to hit, so the ball flies on under g from where it was lost.
        predicted = track::exact_trajectory(p, v, belief.gravity_mps2, t).position_at(t_end);
        if (first_hit == nothing_hit) first_hit = lost;
        break;
      }
      if (first_hit != nothing_hit) continue;
      if (e.has(sim::StepEvents::kHitObstacle) && e.obstacle >= 0 &&
                 group_of[static_cast<std::size_t>(e.obstacle)] >= 0) {
        first_hit = static_cast<std::size_t>(group_of[static_cast<std::size_t>(e.obstacle)]);
      } else if ((e.has(sim::StepEvents::kHitFlipper) || e.has(sim::StepEvents::kFlipperPush)) && e.flipper >= 0) {
        first_hit = flipper_hit + static_cast<std::size_t>(e.flipper);
      }
    }
    errors.push_back((predicted - seen).norm());
    each[index] = errors.back();
    (s.pushed ? pushed : under_g).add(errors.back());
    if (flew_free(play, s.frame, fit.t_ref_s + o.horizon_s, o.sigma_m)) {
      free.add(errors.back());
    } else {
      collided.add(errors.back());
      by_hit[first_hit].add(errors.back());
    }
  }
  PredictionError out;
  out.errors_m = std::move(each);
  out.moments = errors.size();
  if (errors.empty()) return out;
  RunningStats stats;
  for (double e : errors) stats.add(e);
  out.mean_m = stats.mean();
  out.mean_ci95_m = stats.ci95_half_width();
  out.median_m = median(errors);
  out.p90_m = quantile(errors, 0.9);
  // A class with no moment has no mean: NaN (null in JSON, "none" in text), not 0 mm.
  const auto mean_of = [](const RunningStats& r) {
    return r.count() > 0 ? r.mean() : std::numeric_limits<double>::quiet_NaN();
  };
  out.free_moments = static_cast<std::size_t>(free.count());
  out.free_mean_m = mean_of(free);
  out.collision_mean_m = mean_of(collided);
  out.under_g_moments = static_cast<std::size_t>(under_g.count());
  out.under_g_mean_m = mean_of(under_g);
  out.pushed_moments = static_cast<std::size_t>(pushed.count());
  out.pushed_mean_m = mean_of(pushed);
  for (std::size_t h = 0; h < by_hit.size(); ++h) {
    if (by_hit[h].count() == 0) continue;
    const std::vector<std::string>& names = h < flipper_hit ? groups[h].obstacles : std::vector<std::string>{};
    const std::string what = h < flipper_hit
                                 ? "obstacles " + names.front() +
                                       (names.size() > 1 ? " and " + std::to_string(names.size() - 1) + " more" : "")
                             : h < nothing_hit ? "flipper " + belief.flippers[h - flipper_hit].name
                             : h == nothing_hit ? std::string("nothing")
                                                : std::string("lost");
    out.collisions_by_model_hit.push_back({what, static_cast<std::size_t>(by_hit[h].count()), by_hit[h].mean()});
  }
  std::stable_sort(out.collisions_by_model_hit.begin(), out.collisions_by_model_hit.end(),
                   [](const CollisionError& a, const CollisionError& b) { return a.moments > b.moments; });
  return out;
}

}  // namespace pinball::learn
