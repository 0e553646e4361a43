#include "pinball/learn/identification.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pinball/core/format.h"
#include "pinball/core/least_squares_line.h"
#include "pinball/core/minimize.h"
#include "pinball/core/rng.h"
#include "pinball/core/running_stats.h"
#include "pinball/core/statistics.h"
#include "pinball/sim/collision.h"

namespace pinball::learn {
namespace {

constexpr double kContactStep_s = 0.00025;  // extrapolation step when looking for the contact

// Unit normal of `shape` at the ball centre p, pointing from the surface to
// the ball (the gradient of the distance; central differences).
Vec2 surface_normal(const table::Shape& shape, const Vec2& p) {
  constexpr double h = 1e-6;
  const Vec2 g((table::distance_to_shape(shape, p + Vec2(h, 0)) - table::distance_to_shape(shape, p - Vec2(h, 0))),
               (table::distance_to_shape(shape, p + Vec2(0, h)) - table::distance_to_shape(shape, p - Vec2(0, h))));
  return g.norm() > 0.0 ? Vec2(g / g.norm()) : Vec2::Zero();
}

std::string group_label(const table::ObstacleGroupOverlay& g) {
  return "obstacle group rho=" + format_number(g.board_rho) +
         (g.board_kick_mps > 0.0 ? " kick=" + format_number(g.board_kick_mps) + " m/s" : std::string()) + " (" +
         (g.obstacles.empty() ? std::string() : g.obstacles.front()) +
         (g.obstacles.size() > 1 ? ", ... " + std::to_string(g.obstacles.size()) + " obstacles" : std::string()) + ")";
}

// The rebound joining flight a to flight b, when the ball met one board
// obstacle in between; false otherwise.
bool find_rebound(const table::Board& board, const std::vector<int>& group_of, const FreeFlight& a,
                  const FreeFlight& b, const IdentifyOptions& o, Rebound& out) {
  const double radius = board.ball.radius_m;
  for (double t = a.t_last_s; t <= b.t_first_s; t += kContactStep_s) {
    Vec2 p = a.fit.position_at(t);
    int nearest = -1;
    double nearest_d = INFINITY;
    for (std::size_t k = 0; k < board.shapes.size(); ++k) {
      const double d = table::distance_to_shape(board.shapes[k], p);
      if (d < nearest_d) nearest_d = d, nearest = static_cast<int>(k);
    }
    if (nearest < 0 || nearest_d > radius + o.contact_tolerance_m) continue;
    if (group_of[static_cast<std::size_t>(nearest)] < 0) return false;  // a ball eater
    // Within reach; the contact itself is where the extrapolated ball touches
    // the obstacle (or passes closest to it), up to a few steps on. At a post
    // the normal turns with the contact point: taken a couple of millimetres
    // early it mixes the speed along the post into the speed at it.
    const table::Shape& shape = board.shapes[static_cast<std::size_t>(nearest)];
    double t_before = t - kContactStep_s;  // the step before: out of reach, so apart
    for (double u = t + kContactStep_s; nearest_d > radius && u <= b.t_first_s; u += kContactStep_s) {
      const double d = table::distance_to_shape(shape, a.fit.position_at(u));
      if (d >= nearest_d) break;  // closest approach, short of touching
      t_before = t;
      t = u;
      nearest_d = d;
    }
    if (nearest_d < radius) {  // crossed between t_before and t: the touching moment
      double lo = t_before, hi = t;
      for (int i = 0; i < 20; ++i) {
        const double mid = 0.5 * (lo + hi);
        (table::distance_to_shape(shape, a.fit.position_at(mid)) > radius ? lo : hi) = mid;
      }
      t = hi;
    }
    p = a.fit.position_at(t);
    // Another material this close too: a corner, whose ratio belongs to neither.
    for (std::size_t k = 0; k < board.shapes.size(); ++k)
      if (group_of[k] != group_of[static_cast<std::size_t>(nearest)] &&
          table::distance_to_shape(board.shapes[k], p) < radius + 2.0 * o.contact_tolerance_m)
        return false;
    if (!ball_clear_of_flippers(board, p, o.contact_tolerance_m)) return false;
    // The ball leaves where it arrived, at once; a kicker holds it until its
    // coil fires and throws it from its ring's reach: flight out may join
    // up to kick_dwell_s later and kick_join_tolerance_m away.
    const bool kicker = board.obstacles[static_cast<std::size_t>(nearest)].action.kick_mps > 0.0;
    double t_out = t;
    double join = (b.fit.position_at(t) - p).norm();
    for (double u = t; kicker && u <= std::min(t + o.kick_dwell_s, b.t_first_s); u += kContactStep_s) {
      const double d = (b.fit.position_at(u) - p).norm();
      if (d < join) join = d, t_out = u;
    }
    if (join > (kicker ? o.kick_join_tolerance_m : o.join_tolerance_m)) return false;
    const Vec2 n = surface_normal(board.shapes[static_cast<std::size_t>(nearest)], p);
    out.group = group_of[static_cast<std::size_t>(nearest)];
    out.obstacle = nearest;
    out.t_s = t;
    out.contact_m = p;
    const Vec2 v_in = a.fit.velocity_at(t);
    const Vec2 v_out = b.fit.velocity_at(t_out);
    out.speed_in_mps = -v_in.dot(n);
    out.speed_out_mps = v_out.dot(n);
    const Vec2 along = v_in + out.speed_in_mps * n;
    out.tangent_in_mps = along.norm();
    out.tangent_out_mps = out.tangent_in_mps > 0.0 ? v_out.dot(along) / out.tangent_in_mps : 0.0;
    return out.speed_in_mps >= o.min_normal_speed_mps && out.speed_out_mps > 0.0;
  }
  return false;
}

void identify_groups(const table::Board& board, const std::vector<FreeFlight>& flights, const IdentifyOptions& o,
                     IdentificationResult& result) {
  for (const table::ObstacleGroupOverlay& g : material_groups(board)) {
    GroupResult group;
    group.overlay = g;
    result.groups.push_back(group);
  }
  std::vector<table::ObstacleGroupOverlay> overlays;
  for (const GroupResult& g : result.groups) overlays.push_back(g.overlay);
  const std::vector<int> group_of = material_group_of(board, overlays);
  for (std::size_t k = 1; k < flights.size(); ++k) {
    const FreeFlight& a = flights[k - 1];
    const FreeFlight& b = flights[k];
    if (a.recording != b.recording || b.t_first_s - a.t_last_s > o.max_rebound_gap_s) continue;
    Rebound r;
    if (find_rebound(board, group_of, a, b, o, r)) result.rebounds.push_back(r);
  }
  for (std::size_t g = 0; g < result.groups.size(); ++g) {
    GroupResult& group = result.groups[g];
    std::vector<Rebound> own;
    for (const Rebound& r : result.rebounds)
      if (r.group == static_cast<int>(g)) own.push_back(r);
    fit_material_group(own, o, board.ball.speed_max_mps, group);
    const std::string label = group_label(group.overlay);
    if (!group.identified) {
      result.not_identified.push_back({label + (group.overlay.board_kick_mps > 0.0 ? ": rho and kick" : ": rho"),
                                       group.why_not});
      continue;
    }
    if (!group.overlay.friction) {
      result.not_identified.push_back(
          {label + ": wall friction", "no rebound came in along the obstacle fast enough for friction to show"});
    }
    result.overlay.obstacle_groups.push_back(group.overlay);
  }
}

void identify_launcher(const table::Board& board, std::span<const bus::RecordedPlay> recordings,
                       const std::vector<FreeFlight>& flights, const IdentifyOptions& o, double g_mps2,
                       IdentificationResult& result) {
  const Vec2 rest = board.launcher.position;
  const double clamp = board.ball.speed_max_mps;
  for (const FreeFlight& f : flights) {
    const Vec2 p = recordings[f.recording].frames[f.first].p_board;
    const Vec2 v = f.fit.velocity_at(f.t_first_s);
    const double rise = p.y() - rest.y();
    if (std::abs(p.x() - rest.x()) > o.launch_reach_m || rise < 0.0 || rise > 5.0 * o.launch_reach_m || v.y() <= 0.0)
      continue;
    // Back to the rest position along the chute: energy, no drag.
    const double speed = std::sqrt(v.y() * v.y() + 2.0 * g_mps2 * rise);
    if (speed > 0.25 * clamp) result.launch_speeds_mps.push_back(speed);
  }
  const std::vector<double>& s = result.launch_speeds_mps;
  const int n = static_cast<int>(s.size());
  if (n < o.min_launches) {
    result.not_identified.push_back({"launcher pull and noise", std::to_string(n) + " launches seen leaving the rest "
                                                                "position, needs " + std::to_string(o.min_launches)});
    return;
  }
  // Speeds P·(1 − R)·clamp with R uniform: the unbiased estimates of a uniform's ends.
  const auto [lo_it, hi_it] = std::minmax_element(s.begin(), s.end());
  const double spread = *hi_it - *lo_it;
  const double top = *hi_it + spread / (n - 1), bottom = *lo_it - spread / (n - 1);
  const double end_stderr = spread / (n + 1);
  table::LauncherOverlay launcher;
  launcher.pull = {std::min(1.0, top / clamp), end_stderr / clamp, n};
  // At most the board format's noise (a wider spread is slow launches of another cause: a weak pull,
  // a ball that rolled back): an overlay gives no world a board file could not.
  launcher.noise_max = {std::clamp(1.0 - bottom / top, 0.0, table::kMaxLaunchNoise), std::sqrt(2.0) * end_stderr / top,
                        n};
  result.overlay.launcher = launcher;
}

void identify_flippers(const table::Board& board, std::span<const bus::RecordedPlay> recordings,
                       const std::vector<FreeFlight>& flights, const IdentifyOptions& o, IdentificationResult& result) {
  result.shots = find_flipper_shots(board, recordings, flights, o.shots);
  for (std::size_t k = 0; k < board.flippers.size(); ++k) {
    FlipperStrokeFit fit =
        fit_flipper_stroke(board, static_cast<int>(k), result.shots, o.nominal_actuation_delay_s, o.shots);
    const std::string label = "flipper " + fit.name;
    if (!fit.identified) {
      result.not_identified.push_back({label + " rise delay, stroke speed and mu", fit.why_not});
      result.flipper_strokes.push_back(fit);
      continue;
    }
    table::FlipperOverlay overlay{fit.name, std::nullopt, std::nullopt, fit.rise_delay_s};
    overlay.rise_delay_s->value = std::max(0.0, overlay.rise_delay_s->value);  // noise may put it below zero
    if (fit.stroke_replays_better()) {
      overlay.mu = fit.mu;
      overlay.omega_rad_s = fit.omega_rad_s;
    } else {
      result.not_identified.push_back(
          {label + " stroke speed and mu",
           "the model replays its " + std::to_string(fit.shots) + " shots no closer by a fifth with the fitted values "
           "(median velocity error " + format_number(fit.velocity_error_fitted_mps) + " m/s) than with the board's (" +
               format_number(fit.velocity_error_nominal_mps) + " m/s at the nominal delay, " +
               format_number(fit.velocity_error_delay_only_mps) +
               " m/s at the identified one): the board's are kept; the timing fit's stroke speed only says when "
               "the bat arrives"});
    }
    result.overlay.flippers.push_back(overlay);
    result.flipper_strokes.push_back(fit);
  }
}

// The tangential speed out that the model's response gives one rebound.
double modelled_tangent_out_mps(const Rebound& r, double rho, double kick_mps, double friction) {
  const double change_mps = (1.0 + rho) * r.speed_in_mps + kick_mps;
  return r.tangent_in_mps - sim::wall_friction_loss_mps(r.tangent_in_mps, r.speed_in_mps, change_mps, friction);
}

double tangent_sse(std::span<const Rebound> rebounds, double rho, double kick_mps, double friction) {
  double sse = 0.0;
  for (const Rebound& r : rebounds) sse += std::pow(r.tangent_out_mps - modelled_tangent_out_mps(r, rho, kick_mps, friction), 2);
  return sse;
}

// The friction in [0, table::kMaxWallFriction] with the least squared
// residual (the loss is capped, so the sum is not smooth everywhere).
double best_friction(std::span<const Rebound> rebounds, double rho, double kick_mps) {
  const double found = minimize_on_interval(
      [&](double friction) { return tangent_sse(rebounds, rho, kick_mps, friction); }, 0.0, table::kMaxWallFriction,
      400, 40);
  return found < 1e-9 ? 0.0 : found;  // the sections' rounding at the bound is no friction
}

// The vertex of the parabola through (x[k-1], y[k-1]), (x[k], y[k]),
// (x[k+1], y[k+1]) on an even grid, kept within the neighbours; the grid
// point itself at either end of the grid.
double parabola_vertex(const std::vector<double>& x, const std::vector<double>& y, std::size_t k) {
  if (k == 0 || k + 1 >= x.size()) return x[k];
  const double step = x[k + 1] - x[k];
  const double curvature = y[k - 1] - 2.0 * y[k] + y[k + 1];
  if (!(curvature > 0.0)) return x[k];
  return x[k] + std::clamp(0.5 * step * (y[k - 1] - y[k + 1]) / curvature, -step, step);
}

bool has_two_sided_wall(const table::Board& board) {
  table::Board probe = board;
  table::set_wall_thickness(probe, board.wall_thickness_m + 1e-3);
  for (std::size_t i = 0; i < board.shapes.size(); ++i)
    if ((probe.shapes[i].p0 - board.shapes[i].p0).norm() > 0.0) return true;
  return false;
}

}  // namespace

void fit_material_group(std::span<const Rebound> rebounds, const IdentifyOptions& o, double speed_max_mps,
                        GroupResult& group) {
  // The model clamps the ball's speed after every bounce (thesis 3.3): a
  // rebound that left at the clamp says nothing of ρ or the kick, and fitted
  // as if it did pulls ρ down (the slingshots' 1.4 came out 1.3 from the
  // model's own play).
  const double clamp_mps = o.clamp_share * speed_max_mps;
  std::vector<std::pair<double, double>> in_out;
  std::vector<Rebound> kept;
  group.rebounds = static_cast<int>(rebounds.size());
  for (const Rebound& r : rebounds) {
    if (std::hypot(r.speed_out_mps, r.tangent_out_mps) > clamp_mps) {
      ++group.at_speed_clamp;
      continue;
    }
    in_out.emplace_back(r.speed_in_mps, r.speed_out_mps);
    kept.push_back(r);
  }
  const bool with_kick = group.overlay.board_kick_mps > 0.0;
  const int needed = o.min_rebounds + (with_kick ? 2 : 0);
  group.rms_nominal_mps = rms_residual(in_out, {group.overlay.board_kick_mps, group.overlay.board_rho});
  if (static_cast<int>(in_out.size()) < needed) {
    group.why_not = std::to_string(in_out.size()) + " clean rebounds (both flights seen, one obstacle near" +
                    (group.at_speed_clamp > 0 ? ", below the speed clamp" : "") + "), needs " + std::to_string(needed);
    return;
  }
  // speed out ≈ ρ·speed in (+ kick)
  const TrimmedLineFit fit = fit_line_trimmed(in_out, !with_kick);
  // What an overlay may hold (table/board.h): a fit outside it is no one material's rebounds, and
  // a file holding it would be refused by every command that reads it.
  if (!(fit.line.slope >= 0.0 && fit.line.slope <= table::kMaxRho) ||
      (with_kick && !(fit.line.intercept >= 0.0 && fit.line.intercept <= table::kMaxOverlayKick_mps))) {
    group.why_not = "the clean rebounds fit rho " + format_number(fit.line.slope) +
                    (with_kick ? " and kick " + format_number(fit.line.intercept) + " m/s" : std::string()) +
                    ", outside the overlay's range (rho in [0, " + format_number(table::kMaxRho) + "]" +
                    (with_kick ? ", kick in [0, " + format_number(table::kMaxOverlayKick_mps) + "] m/s" : "") +
                    "): they are not one material's; the board's value is kept";
    return;
  }
  group.identified = true;
  group.outliers = fit.outliers;
  group.overlay.rho = {fit.line.slope, fit.slope_stderr, fit.used};
  if (with_kick) group.overlay.kick_mps = table::IdentifiedValue{fit.line.intercept, fit.intercept_stderr, fit.used};
  group.rms_fitted_mps = rms_residual(in_out, fit.line);
  group.friction =
      fit_wall_friction(kept, group.overlay.rho.value, group.overlay.kick_mps.value_or(table::IdentifiedValue{}).value);
  if (std::isfinite(group.friction.stderr_)) {
    group.overlay.friction =
        table::IdentifiedValue{group.friction.friction, group.friction.stderr_, group.friction.used};
  }
}

WallThicknessFit fit_wall_thickness(const table::Board& belief, std::span<const bus::RecordedPlay> recordings,
                                    const PredictionOptions& options, int bootstrap, std::uint64_t seed,
                                    const std::function<void(int, int)>& progress) {
  constexpr int kSteps = 9;
  constexpr double kStep_m = 0.0005;
  constexpr std::size_t kMinMoments = 100;
  WallThicknessFit fit;
  if (!has_two_sided_wall(belief)) {
    fit.why_not = "the board has no two-sided wall";
    return fit;
  }
  if (bootstrap < 2) {  // no covariance to fall back on: a thickness without an uncertainty is not reported
    fit.why_not = "its uncertainty needs a bootstrap of at least 2 resamples of the moments (--bootstrap)";
    return fit;
  }
  const std::vector<PredictionStart> starts = prediction_starts(recordings, options);
  std::vector<double> thickness;
  std::vector<std::vector<double>> errors;  // per thickness, per start
  if (progress) progress(0, kSteps);
  for (int k = 0; k < kSteps; ++k) {
    table::Board b = belief;
    table::set_wall_thickness(b, k * kStep_m);
    thickness.push_back(k * kStep_m);
    errors.push_back(prediction_error(b, recordings, starts, options).errors_m);
    if (progress) progress(k + 1, kSteps);
  }
  // The moments every thickness predicted (a start the fit refuses is refused at all).
  std::vector<std::size_t> used;
  for (std::size_t s = 0; s < starts.size(); ++s) {
    bool all = true;
    for (const std::vector<double>& e : errors) all = all && !std::isnan(e[s]);
    if (all) used.push_back(s);
  }
  fit.moments = used.size();
  if (used.size() < kMinMoments) {
    fit.why_not = std::to_string(used.size()) + " moments to predict, needs " + std::to_string(kMinMoments);
    return fit;
  }
  const auto means = [&](const std::vector<std::size_t>& moments) {
    std::vector<double> m;
    for (const std::vector<double>& e : errors) {
      double sum = 0.0;
      for (std::size_t s : moments) sum += e[s];
      m.push_back(sum / static_cast<double>(moments.size()));
    }
    return m;
  };
  const auto best_of = [&](const std::vector<double>& m) {
    return parabola_vertex(thickness, m, static_cast<std::size_t>(std::min_element(m.begin(), m.end()) - m.begin()));
  };
  const std::vector<double> m = means(used);
  for (int k = 0; k < kSteps; ++k) fit.scan.emplace_back(thickness[static_cast<std::size_t>(k)], m[static_cast<std::size_t>(k)]);
  fit.thickness_m = best_of(m);
  fit.error_at_zero_m = m.front();
  table::Board best = belief;
  table::set_wall_thickness(best, fit.thickness_m);
  const std::vector<double> at_best = prediction_error(best, recordings, starts, options).errors_m;
  double sum = 0.0;
  for (std::size_t s : used) sum += std::isnan(at_best[s]) ? 0.0 : at_best[s];
  fit.error_fitted_m = sum / static_cast<double>(used.size());
  RunningStats spread;
  Rng rng(seed);
  std::vector<std::size_t> resample(used.size());
  for (int b = 0; b < bootstrap; ++b) {
    for (std::size_t& s : resample) s = used[static_cast<std::size_t>(rng.uniform01() * static_cast<double>(used.size()))];
    spread.add(best_of(means(resample)));
  }
  fit.stderr_m = spread.stddev();
  // At an edge of the scan every resample lands on the edge itself, a spread of 0 that
  // claims a precision the scan does not have: no finer than half a step there.
  const auto least = std::min_element(m.begin(), m.end()) - m.begin();
  fit.at_scan_edge = least == 0 || least == kSteps - 1;
  if (fit.at_scan_edge) fit.stderr_m = std::max(fit.stderr_m, 0.5 * kStep_m);
  fit.identified = true;
  return fit;
}

WallFrictionFit fit_wall_friction(std::span<const Rebound> rebounds, double rho, double kick_mps) {
  if (rebounds.size() < 2) throw std::invalid_argument("fit_wall_friction: need 2 rebounds");
  const double first = best_friction(rebounds, rho, kick_mps);
  std::vector<double> residuals;
  for (const Rebound& r : rebounds) residuals.push_back(r.tangent_out_mps - modelled_tangent_out_mps(r, rho, kick_mps, first));
  const double sigma = robust_sigma(residuals);
  std::vector<Rebound> kept;
  for (std::size_t i = 0; i < rebounds.size(); ++i)
    if (sigma <= 0.0 || std::abs(residuals[i]) <= 3.5 * sigma) kept.push_back(rebounds[i]);
  if (kept.size() < 2) kept.assign(rebounds.begin(), rebounds.end());
  WallFrictionFit fit;
  fit.friction = best_friction(kept, rho, kick_mps);
  fit.used = static_cast<int>(kept.size());
  fit.outliers = static_cast<int>(rebounds.size() - kept.size());
  const double n = static_cast<double>(kept.size());
  const double sse = tangent_sse(kept, rho, kick_mps, fit.friction);
  fit.rms_fitted_mps = std::sqrt(sse / n);
  fit.rms_frictionless_mps = std::sqrt(tangent_sse(kept, rho, kick_mps, 0.0) / n);
  // Standard error from the curvature of the sum (Gauss–Newton: the
  // residuals' derivative in the friction, by central differences).
  constexpr double h = 1e-4;
  double jtj = 0.0;
  for (const Rebound& r : kept) {
    const double d = (modelled_tangent_out_mps(r, rho, kick_mps, fit.friction + h) -
                      modelled_tangent_out_mps(r, rho, kick_mps, std::max(0.0, fit.friction - h))) /
                     (fit.friction + h - std::max(0.0, fit.friction - h));
    jtj += d * d;
  }
  fit.stderr_ = jtj > 0.0 && n > 1.0 ? std::sqrt(sse / (n - 1.0) / jtj) : INFINITY;
  return fit;
}

std::vector<int> material_group_of(const table::Board& board, const std::vector<table::ObstacleGroupOverlay>& groups) {
  std::vector<int> group_of(board.obstacles.size(), -1);
  for (std::size_t k = 0; k < board.obstacles.size(); ++k)
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto& names = groups[g].obstacles;
      if (std::find(names.begin(), names.end(), board.obstacles[k].name) != names.end()) group_of[k] = static_cast<int>(g);
    }
  return group_of;
}

std::vector<table::ObstacleGroupOverlay> material_groups(const table::Board& board) {
  std::vector<table::ObstacleGroupOverlay> groups;
  for (const table::Obstacle& o : board.obstacles) {
    if (o.action.eats_ball) continue;
    auto it = std::find_if(groups.begin(), groups.end(), [&](const table::ObstacleGroupOverlay& g) {
      return g.board_rho == o.rho && g.board_kick_mps == o.action.kick_mps;
    });
    if (it == groups.end()) {
      groups.push_back({});
      it = groups.end() - 1;
      it->board_rho = o.rho;
      it->board_kick_mps = o.action.kick_mps;
    }
    if (std::find(it->obstacles.begin(), it->obstacles.end(), o.name) == it->obstacles.end())
      it->obstacles.push_back(o.name);
  }
  return groups;
}

void check_recording_fits_board(const bus::RecordedPlay& play, const table::Board& board) {
  std::size_t found = 0;
  std::size_t off = 0;
  for (const bus::RecordedFrame& f : play.frames) {
    if (!f.found) continue;
    ++found;
    off += table::near_playfield(board, f.p_board) ? 0 : 1;
  }
  if (found > 0 && static_cast<double>(off) > table::kMostOffPlayfield * static_cast<double>(found)) {
    throw std::runtime_error(play.source + ": " + std::to_string(off) + " of its " + std::to_string(found) +
                             " sightings lie " + table::off_playfield_text(board) +
                             ": a log of another table, or a camera calibration in other units?");
  }
  const int flippers = static_cast<int>(board.flippers.size());
  for (const bus::RecordedCommand& c : play.commands) {
    if (c.flipper >= flippers) {
      throw std::runtime_error(play.source + ": its commands fire flipper " + std::to_string(c.flipper) + ", and " +
                               board.source + " has " + std::to_string(flippers) +
                               " flippers: a log of another table?");
    }
  }
  // A game's log (10 s and more) with not one command among its frames: another clock. A log
  // of a few frames may just hold no command.
  constexpr double kGameLog_s = 10.0;
  if (play.commands.empty() || play.duration_s() < kGameLog_s) return;
  const double first_s = play.frames.front().t_s;
  const double last_s = play.frames.back().t_s;
  const bool any_within = std::any_of(play.commands.begin(), play.commands.end(), [&](const bus::RecordedCommand& c) {
    return c.t_s >= first_s && c.t_s <= last_s;
  });
  if (!any_within) {
    throw std::runtime_error(play.source + ": none of its " + std::to_string(play.commands.size()) +
                             " commands lies within its frames' time (" + format_number(first_s) + " to " +
                             format_number(last_s) + " s; the commands " + format_number(play.commands.front().t_s) +
                             " to " + format_number(play.commands.back().t_s) +
                             " s): the two were recorded on different clocks, and no shot can be matched");
  }
}

IdentificationResult identify_table(const table::Board& board, std::span<const bus::RecordedPlay> recordings,
                                    const IdentifyOptions& options,
                                    const std::function<void(const std::string&, int, int)>& progress) {
  IdentificationResult result;
  std::vector<FreeFlight> flights;
  // Each stage reports 0 done as it starts, so that its meter times the whole stage.
  if (progress) progress("free flights", 0, static_cast<int>(recordings.size()));
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    const bus::RecordedPlay& play = recordings[r];
    result.overlay.recordings.push_back(play.source);
    result.frames += play.frames.size();
    if (result.malformed == 0 && play.malformed > 0) result.first_malformed = play.source + ": " + play.first_malformed;
    result.malformed += play.malformed;
    result.commands += play.commands.size();
    result.recorded_s += play.duration_s();
    for (const bus::RecordedFrame& f : play.frames) result.sightings += f.found ? 1 : 0;
    const std::vector<FreeFlight> found = find_free_flights(play, r, board, options.flights);
    flights.insert(flights.end(), found.begin(), found.end());
    if (progress) progress("free flights", static_cast<int>(r + 1), static_cast<int>(recordings.size()));
  }
  result.flights = flights.size();
  const auto recording_names = [&recordings] {
    std::string names;
    for (const bus::RecordedPlay& play : recordings) names += (names.empty() ? "" : ", ") + play.source;
    return names;
  };
  if (flights.size() < 2) {
    throw std::runtime_error(recording_names() + ": " + std::to_string(flights.size()) + " free flights in " +
                             format_number(result.recorded_s) + " s of play (a free flight: at least " +
                             std::to_string(options.flights.min_points) +
                             " sightings in a row clear of everything), 2 needed for g, the first parameter; "
                             "nothing can be identified: record more play");
  }
  const auto bootstrap_progress = [&](int done, int total) {
    if (progress) progress("gravity bootstrap", done, total);
  };
  result.gravity_no_drag = fit_flight_gravity(recordings, flights, board.gravity_mps2, options.flights.sigma_m, false,
                                              options.bootstrap, options.seed, bootstrap_progress);
  if (options.fit_drag)
    result.gravity = fit_flight_gravity(recordings, flights, board.gravity_mps2, options.flights.sigma_m, true, 0,
                                        options.seed);
  else
    result.gravity = result.gravity_no_drag;
  const FlightGravity& g = result.gravity_no_drag;
  if (!(g.g_mps2 > 0.0 && g.g_mps2 <= table::kMaxGravity_mps2)) {
    throw std::runtime_error(recording_names() + ": the " + std::to_string(g.flights) + " free flights give g " +
                             format_number(g.g_mps2) + " m/s^2 along the table, outside (0, " +
                             format_number(table::kMaxGravity_mps2) +
                             "]: they are not free flights on this board (its calibration or geometry?); "
                             "nothing can be identified");
  }
  result.sliding = fit_sliding_friction(recordings, flights, g, options.flights.sigma_m);
  result.overlay.gravity_mps2 = table::IdentifiedValue{g.g_mps2, g.g_stderr_mps2, g.flights};
  identify_groups(board, flights, options, result);
  identify_launcher(board, recordings, flights, options, g.g_mps2, result);
  identify_flippers(board, recordings, flights, options, result);
  {
    // Last: the thickness is judged on the model with everything else identified.
    table::Board belief = board;
    table::apply_board_overlay(result.overlay, "(identified)", belief);
    PredictionOptions prediction;
    prediction.sigma_m = options.flights.sigma_m;
    result.wall_thickness = fit_wall_thickness(belief, recordings, prediction, options.bootstrap, options.seed,
                                               [&](int done, int total) {
                                                 if (progress) progress("wall thickness", done, total);
                                               });
    const WallThicknessFit& t = result.wall_thickness;
    if (t.identified)
      result.overlay.wall_thickness_m =
          table::IdentifiedValue{t.thickness_m, t.stderr_m, static_cast<int>(t.moments)};
    else
      result.not_identified.push_back({"two-sided wall thickness", t.why_not});
  }
  result.not_identified.push_back(
      {"camera latency", "a constant error in it shifts the ball's frames against the commands by the same amount "
                         "as the coil's rise delay, so ball tracks cannot tell them apart (the identified rise delay "
                         "holds both, which is what a controller leads by); `pinball calibrate latency` measures it "
                         "(docs/calibration.md)"});
  result.not_identified.push_back(
      {"speed clamp", "the model's clamp stands in for friction; the drag the free flights show is reported "
                      "instead (the model cannot play it)"});
  result.not_identified.push_back(
      {"playfield sliding friction", "the model's ball has no spin, so it never skids after a bounce; the sliding "
                                     "friction the skidding flights show is reported instead (the model cannot play "
                                     "it)"});
  result.overlay.board = board.source;
  return result;
}

}  // namespace pinball::learn
