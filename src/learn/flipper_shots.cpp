#include "pinball/learn/flipper_shots.h"

#include <algorithm>
#include <cmath>

#include "pinball/core/least_squares_line.h"
#include "pinball/core/minimize.h"
#include "pinball/core/statistics.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {
namespace {

constexpr double kJoinStep_s = 0.00025;  // search step for where the flights in and out meet
constexpr int kAngleBisections = 40;
constexpr double kMuLimit = 4.0;       // μ searched in [0, kMuLimit]
constexpr int kMuGridSteps = 16;       // coarse grid over it, then golden-section refinement
constexpr int kMuGoldenSteps = 14;

// Signed distance of the ball centre p above the bat's line at angle θ (m).
double height_above_bat(const table::Flipper& f, double theta_rad, const Vec2& p) {
  return (p - f.pivot).dot(table::flipper_up_normal(f, theta_rad));
}

// The bat's angle that puts p one radius above its line, when the stroke
// reaches it from a ball above the down bat; nullopt otherwise.
std::optional<double> contact_angle(const table::Flipper& f, const Vec2& p, double radius_m, double tolerance_m) {
  if (height_above_bat(f, f.theta_min_rad, p) < radius_m - tolerance_m) return std::nullopt;  // below the down bat
  if (height_above_bat(f, f.theta_max_rad, p) > radius_m) return std::nullopt;               // the bat never reaches it
  double lo = f.theta_min_rad, hi = f.theta_max_rad;  // height falls as θ grows
  if (height_above_bat(f, lo, p) <= radius_m) return lo;
  for (int i = 0; i < kAngleBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    (height_above_bat(f, mid, p) > radius_m ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The command of flipper k in force at time t, and whether the bat was down
// when it was given: the last command before it was a release long enough
// before (or there was none).
const bus::RecordedCommand* stroke_command(const bus::RecordedPlay& play, int k, double t, double min_down_s) {
  const auto end = std::upper_bound(play.commands.begin(), play.commands.end(), t,
                                    [](double time, const bus::RecordedCommand& c) { return time < c.t_s; });
  const bus::RecordedCommand* last = nullptr;
  const bus::RecordedCommand* before = nullptr;
  for (auto it = end; it != play.commands.begin() && before == nullptr;) {
    --it;
    if (it->flipper != k && it->flipper != -1) continue;
    (last == nullptr ? last : before) = &*it;
  }
  if (last == nullptr || !last->energize) return nullptr;
  if (before != nullptr && (before->energize || last->t_s - before->t_s < min_down_s)) return nullptr;
  return last;
}

bool near_other_obstacle(const table::Board& board, const Vec2& p, double reach_m) {
  for (const table::Shape& shape : board.shapes)
    if (table::distance_to_shape(shape, p) < reach_m) return true;
  return false;
}

// Plays `shot` again in the model: the ball from the flight in's last frame,
// the bat rising `delay_s` after the command at the board's ω, until the
// flight out's first frame. The velocity error there (m/s); infinite when
// the ball is lost on the way.
double replay_error(sim::World& world, table::Board& board, sim::GameState& state, const FlipperShot& shot,
                    double delay_s) {
  const table::Flipper& f = board.flippers[static_cast<std::size_t>(shot.flipper)];
  for (sim::FlipperState& fs : state.flippers) fs = {};
  for (std::size_t k = 0; k < board.flippers.size(); ++k) state.flippers[k].theta_rad = board.flippers[k].theta_min_rad;
  sim::FlipperState& bat = state.flippers[static_cast<std::size_t>(shot.flipper)];
  const double motion_s = shot.command_t_s + delay_s;
  if (motion_s < shot.before_t_s) {  // already rising
    bat.theta_rad = std::min(f.theta_max_rad, f.theta_min_rad + f.omega_rad_s * (shot.before_t_s - motion_s));
    bat.energized = bat.was_energized = true;
  }
  state.ball.position_m = shot.before_p_m;
  state.ball.velocity_mps = shot.before_v_mps;
  state.ball.height_m = 0.0;
  state.ball_in_play = true;
  const double dt = world.dt_s();
  for (double t = shot.before_t_s; t < shot.after_t_s - 0.5 * dt; t += dt) {
    if (t >= motion_s) bat.energized = true;
    world.step(state);
    if (!state.ball_in_play) return INFINITY;
  }
  return (state.ball.velocity_mps - shot.after_v_mps).norm();
}

// The μ of flipper `k` whose replay of `shot` leaves as the flight out does.
double shot_mu(sim::World& world, table::Board& board, sim::GameState& state, const FlipperShot& shot,
               double delay_s) {
  double& mu = board.flippers[static_cast<std::size_t>(shot.flipper)].mu;  // the world reads it at every push
  const auto error_at = [&](double m) {
    mu = m;
    return replay_error(world, board, state, shot, delay_s);
  };
  return minimize_on_interval(error_at, 0.0, kMuLimit, kMuGridSteps, kMuGoldenSteps);
}

}  // namespace

std::vector<FlipperShot> find_flipper_shots(const table::Board& board, std::span<const bus::RecordedPlay> recordings,
                                            std::span<const FreeFlight> flights, const ShotOptions& o) {
  const double radius = board.ball.radius_m;
  std::vector<FlipperShot> shots;
  for (std::size_t i = 1; i < flights.size(); ++i) {
    const FreeFlight& a = flights[i - 1];
    const FreeFlight& b = flights[i];
    if (a.recording != b.recording || b.t_first_s - a.t_last_s > o.max_gap_s) continue;
    double t_join = a.t_last_s, gap = INFINITY;
    for (double t = a.t_last_s; t <= b.t_first_s; t += kJoinStep_s) {
      const double d = (a.fit.position_at(t) - b.fit.position_at(t)).norm();
      if (d < gap) gap = d, t_join = t;
    }
    if (gap > o.join_tolerance_m) continue;
    const Vec2 contact = 0.5 * (a.fit.position_at(t_join) + b.fit.position_at(t_join));
    if (near_other_obstacle(board, contact, radius + o.contact_tolerance_m)) continue;
    for (std::size_t k = 0; k < board.flippers.size(); ++k) {
      const table::Flipper& f = board.flippers[k];
      const std::optional<double> theta = contact_angle(f, contact, radius, o.contact_tolerance_m);
      if (!theta) continue;
      const double arm = (contact - f.pivot).dot(table::flipper_direction(f, *theta));
      if (arm <= 0.0 || arm > f.length_m) continue;
      const bus::RecordedCommand* command =
          stroke_command(recordings[a.recording], static_cast<int>(k), t_join, o.min_down_s);
      if (command == nullptr || t_join - command->t_s > o.max_stroke_s) continue;
      const Vec2 n = table::flipper_up_normal(f, *theta);
      FlipperShot shot;
      shot.flipper = static_cast<int>(k);
      shot.recording = a.recording;
      shot.command_t_s = command->t_s;
      shot.contact_t_s = t_join;
      shot.contact_m = contact;
      shot.stroke_rad = *theta - f.theta_min_rad;
      shot.arm_m = arm;
      shot.speed_in_mps = -a.fit.velocity_at(t_join).dot(n);
      shot.speed_out_mps = b.fit.velocity_at(t_join).dot(n);
      shot.before_t_s = a.t_last_s;
      shot.before_p_m = a.fit.position_at(a.t_last_s);
      shot.before_v_mps = a.fit.velocity_at(a.t_last_s);
      shot.after_t_s = b.t_first_s;
      shot.after_p_m = b.fit.position_at(b.t_first_s);
      shot.after_v_mps = b.fit.velocity_at(b.t_first_s);
      if (shot.speed_out_mps >= o.min_speed_out_mps) shots.push_back(shot);
      break;
    }
  }
  return shots;
}

FlipperStrokeFit fit_flipper_stroke(const table::Board& board, int flipper, std::span<const FlipperShot> shots,
                                    double nominal_delay_s, const ShotOptions& o) {
  const table::Flipper& f = board.flippers.at(static_cast<std::size_t>(flipper));
  FlipperStrokeFit fit;
  fit.name = f.name;
  std::vector<std::pair<double, double>> timing;  // (Δθ, contact − command)
  std::vector<const FlipperShot*> mine;
  for (const FlipperShot& s : shots)
    if (s.flipper == flipper) timing.emplace_back(s.stroke_rad, s.contact_t_s - s.command_t_s), mine.push_back(&s);
  fit.shots = static_cast<int>(timing.size());
  fit.timing_rms_nominal_s = rms_residual(timing, {nominal_delay_s, 1.0 / f.omega_rad_s});
  if (fit.shots < o.min_shots) {
    fit.why_not = std::to_string(fit.shots) + " shots (a free flight into the rising bat and one out), needs " +
                  std::to_string(o.min_shots);
    return fit;
  }
  TrimmedLineFit line;
  try {
    line = fit_line_trimmed(timing, false);
  } catch (const std::invalid_argument&) {
    line.line.slope = 0.0;
  }
  if (!(line.line.slope > 0.0) || line.slope_stderr >= 0.5 * line.line.slope) {
    fit.why_not = std::to_string(fit.shots) +
                  " shots, struck at too few points of the stroke to tell its speed from its delay";
    return fit;
  }
  fit.identified = true;
  fit.outliers = line.outliers;
  const double omega = 1.0 / line.line.slope;
  fit.rise_delay_s = {line.line.intercept, line.intercept_stderr, line.used};
  fit.omega_rad_s = {omega, line.slope_stderr * omega * omega, line.used};
  fit.timing_rms_fitted_s = rms_residual(timing, line.line);

  // μ: each shot replayed in the model with the identified stroke.
  table::Board model = board;
  const auto world = sim::make_model_world(model);
  sim::GameState state = sim::make_game_state(model, 1);
  // The median: a replay that misses a second push is off by metres per second.
  const auto median_replay_error = [&](double delay_s) {
    std::vector<double> errors;
    for (const FlipperShot* s : mine) errors.push_back(replay_error(*world, model, state, *s, delay_s));
    return median(errors);
  };
  fit.velocity_error_nominal_mps = median_replay_error(nominal_delay_s);
  fit.velocity_error_delay_only_mps = median_replay_error(fit.rise_delay_s.value);
  model.flippers[static_cast<std::size_t>(flipper)].omega_rad_s = omega;
  std::vector<std::pair<double, double>> mus;  // (1, μ of one shot): the trimmed mean is the line's slope
  for (const FlipperShot* s : mine) mus.emplace_back(1.0, shot_mu(*world, model, state, *s, fit.rise_delay_s.value));
  const TrimmedLineFit m = fit_line_trimmed(mus, true);
  fit.mu = table::IdentifiedValue{m.line.slope, m.slope_stderr, m.used};
  model.flippers[static_cast<std::size_t>(flipper)].mu = m.line.slope;
  fit.velocity_error_fitted_mps = median_replay_error(fit.rise_delay_s.value);
  return fit;
}

}  // namespace pinball::learn
