#include "pinball/sim/thesis_stepper.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "pinball/sim/game_rules.h"
#include "pinball/sim/collision.h"
#include "pinball/sim/penetration.h"

namespace pinball::sim {
namespace {

// A flipper push that would leave the ball deeper than this in a wall stalls
// the flipper instead (the ball is jammed; a real coil stalls too).
constexpr double kStallDepth_m = 1e-9;

// Contacts resolved within one step before the rest of the step is dropped
// (a ball wedged between two surfaces would otherwise bounce without end).
constexpr int kMaxContactsPerStep = 4;

void clamp_speed(Vec2& v, double speed_max) {
  const double s2 = v.squaredNorm();
  if (s2 > speed_max * speed_max) v *= speed_max / std::sqrt(s2);
}

/// The contacts of one step, kept for a wedged ball (no allocation).
/// The first angle between `from` and `to` at which the tip of `f` comes
/// within `r` of `p`: NaN when it never does. The tip's distance to p falls
/// while the blade turns toward p's direction and rises after, so the first
/// touch lies before the closest angle, which is found first (bisection on
/// the side of p the blade is on), then the touch within it: the first angle
/// at which the tip is inside the ball, by round-off.
double tip_touch_angle(const table::Flipper& f, const Vec2& p, double r, double from, double to) {
  const Vec2 rel = p - f.pivot;
  const double front = to > from ? 1.0 : -1.0;
  double lo = from;
  double hi = to;
  for (int i = 0; i < 60; ++i) {  // the angle pointing at p: the blade's line there
    const double mid = 0.5 * (lo + hi);
    (front * rel.dot(table::flipper_up_normal(f, mid)) >= 0.0 ? lo : hi) = mid;
  }
  const double closest = hi;
  auto gap = [&](double theta) { return (p - table::flipper_tip(f, theta)).norm() - r; };
  if (gap(closest) >= 0.0) return std::nan("");
  if (gap(from) < 0.0) return from;
  lo = from;
  hi = closest;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (gap(mid) >= 0.0 ? lo : hi) = mid;
  }
  return hi;  // the first angle touching, within round-off of the ball's surface
}

struct StepContacts {
  Vec2 normal[kMaxContactsPerStep];
  Vec2 point[kMaxContactsPerStep];
  std::int32_t obstacle[kMaxContactsPerStep];  // the obstacle hit, or -1 for a flipper
  std::int32_t flipper[kMaxContactsPerStep];   // the flipper hit, or -1 for an obstacle
  int count = 0;
};

/// Projects v onto the cone of velocities that move into none of `normals`
/// ({u : u·nᵢ ≥ 0}): the closest such velocity, found among v itself, v with
/// one normal component removed, and 0 (the cone's apex; in 2-D no other
/// point can be nearest). A projection onto a convex cone through 0 never
/// lengthens v, so this takes energy away and never adds it.
Vec2 project_onto_free_cone(const Vec2& v, const Vec2* normals, int n) {
  const double tol = 1e-12 * v.norm();
  const auto free = [&](const Vec2& u) {
    for (int i = 0; i < n; ++i) {
      if (u.dot(normals[i]) < -tol) return false;
    }
    return true;
  };
  if (free(v)) return v;
  Vec2 best = Vec2::Zero();
  for (int i = 0; i < n; ++i) {
    const double vn = v.dot(normals[i]);
    if (vn >= 0.0) continue;
    const Vec2 u = v - vn * normals[i];
    if (free(u) && u.squaredNorm() > best.squaredNorm()) best = u;
  }
  return best;
}

}  // namespace

ThesisStepper::ThesisStepper(const table::Board& board, ThesisStepperOptions options) : board_(board), options_(options) {
  if (options_.dt_s == 0.0) options_.dt_s = board.dt_s;
  if (!(options_.dt_s > 0.0) || !std::isfinite(options_.dt_s)) {
    throw std::invalid_argument("time step must be a positive number of seconds");
  }
  table::check_flipper_time_step(board, options_.dt_s);
  // Within one step the centre moves at most speed_max·dt, and a contact
  // counts within contact_tolerance of the surface.
  reach_m_ = board.ball.radius_m + board.ball.speed_max_mps * options_.dt_s + options_.contact_tolerance_m +
             options_.separation_m;
  const double cell_m = std::max(reach_m_, 1e-3);
  obstacle_grid_ = UniformGrid(board.shapes, reach_m_, cell_m);
  sensor_shapes_ = rules::sensor_shapes(board);
  sensor_grid_ = UniformGrid(sensor_shapes_, reach_m_, cell_m);
  all_obstacles_ = rules::all_indices(board.shapes.size());
  all_sensors_ = rules::all_indices(board.sensors.size());
  has_contact_score_ = rules::has_contact_score(board);
}

std::span<const std::int32_t> ThesisStepper::obstacle_candidates(const Vec2& p) const {
  return options_.use_grid ? obstacle_grid_.candidates(p) : std::span<const std::int32_t>(all_obstacles_);
}

StepEvents ThesisStepper::step(GameState& state) const {
  StepEvents events;
  update_flippers(state, events);
  if (state.ball_in_play) move_ball(state, events);
  if (state.rising_flags > 0) raise_flags(state);
  state.time_s += options_.dt_s;
  ++state.steps;
  return events;
}

void ThesisStepper::update_flippers(GameState& state, StepEvents& events) const {
  const double dt = options_.dt_s;
  const double r = board_.ball.radius_m;
  for (std::size_t i = 0; i < board_.flippers.size(); ++i) {
    const table::Flipper& f = board_.flippers[i];
    FlipperState& fs = state.flippers[i];
    const double omega = rules::take_command(f, fs, state.flips);
    const double theta_old = fs.theta_rad;
    const double theta_new = std::clamp(theta_old + dt * omega, f.theta_min_rad, f.theta_max_rad);
    if (theta_new == theta_old) {  // resting on a stop
      fs.omega_rad_s = 0.0;
      continue;
    }
    fs.theta_rad = theta_new;
    fs.omega_rad_s = omega;
    if (!state.ball_in_play) continue;

    // Sweep test (thesis 3.3.3): did the moving face pass into the ball?
    Vec2& p = state.ball.position_m;
    const Vec2 rel = p - f.pivot;
    if (rel.squaredNorm() > (f.length_m + r) * (f.length_m + r)) continue;
    const double front = omega > 0.0 ? 1.0 : -1.0;  // the face that moves toward the ball
    if (front * rel.dot(table::flipper_up_normal(f, theta_old)) < 0.0) continue;  // ball behind: face moves away
    const Vec2 dir = table::flipper_direction(f, theta_new);
    const Vec2 n_face = front * table::flipper_up_normal(f, theta_new);
    const double along = rel.dot(dir);
    if (along <= 0.0) continue;  // the pivot does not move
    Vec2 pushed, normal, contact;
    if (along < f.length_m) {
      const double s = rel.dot(n_face);
      if (s >= r) continue;
      normal = n_face;
      pushed = p + (r + options_.separation_m - s) * n_face;  // out the front even if the centre was crossed
      contact = f.pivot + along * dir;
    } else {
      contact = f.pivot + f.length_m * dir;
      double dist = (p - contact).norm();
      if (dist >= r && front * rel.dot(table::flipper_up_normal(f, theta_new)) < 0.0) {
        // The blade swept past the ball's direction, the tip's arc through the ball between the two
        // angles (the thesis's chord rule keeps the tip's chord, not its arc's depth, below 2r: a tip
        // passing 3.5 mm deep into a resting ball had left it where it was). The blade stops where
        // its tip first touches the ball, and strikes it there.
        const double theta_touch = tip_touch_angle(f, p, r, theta_old, theta_new);
        if (std::isnan(theta_touch)) continue;  // the arc stays a ball's radius away
        fs.theta_rad = theta_touch;
        contact = table::flipper_tip(f, theta_touch);
        dist = (p - contact).norm();
      }
      if (dist >= r) continue;
      const Vec2 away = p - contact;
      normal = dist > 0.0 ? Vec2(away / dist) : n_face;
      pushed = contact + (r + options_.separation_m) * normal;
    }
    if (push_is_blocked(state, i, p, pushed)) {
      fs.theta_rad = theta_old;  // jammed against a wall: the flipper stalls
      fs.omega_rad_s = 0.0;
      events.flags |= StepEvents::kFlipperStall;
      events.flipper = static_cast<std::int32_t>(i);
      continue;
    }
    p = pushed;
    state.ball.velocity_mps = flipper_response(f, fs.theta_rad, omega, contact, normal, state.ball.velocity_mps);
    events.flags |= StepEvents::kFlipperPush;
    events.flipper = static_cast<std::int32_t>(i);
  }
}

void ThesisStepper::move_ball(GameState& state, StepEvents& events) const {
  const double dt = options_.dt_s;
  const double r = board_.ball.radius_m;
  Vec2& p = state.ball.position_m;
  Vec2& v = state.ball.velocity_mps;
  const Vec2 start = p;

  // Semi-implicit Euler: the new velocity first, clamped, then used for the
  // collision search and the move (thesis eq. 3.1–3.2).
  v.y() -= dt * board_.gravity_mps2;
  clamp_speed(v, board_.ball.speed_max_mps);

  // Earliest time of impact over every candidate on the new velocity. After
  // a contact the rest of the step continues from the contact with the new
  // velocity (docs/physics.md: the thesis drops it, which stops a ball
  // sliding along a wall dead); after kMaxContactsPerStep the rest is dropped.
  const auto candidates = obstacle_candidates(start);
  const double flipper_reach = r + board_.ball.speed_max_mps * dt + options_.separation_m;
  double remaining = dt;
  StepContacts contacts;
  bool wedged = true;  // until the step ends with its time used up
  for (int contact = 0; contact < kMaxContactsPerStep; ++contact) {
    Contact best;
    best.t_s = INFINITY;
    std::int32_t hit_obstacle = -1;
    std::int32_t hit_flipper = -1;
    Contact c;
    for (const std::int32_t i : candidates) {
      if (state.visible[i] != kVisible) continue;
      if (shape_time_of_impact(board_.shapes[i], p, v, r, remaining, c) && c.t_s < best.t_s) {
        best = c;
        hit_obstacle = i;
      }
    }
    for (std::size_t i = 0; i < board_.flippers.size(); ++i) {
      const table::Flipper& f = board_.flippers[i];
      const double theta = state.flippers[i].theta_rad;
      if ((start - f.pivot).squaredNorm() > std::pow(f.length_m + flipper_reach, 2)) continue;
      // The flipper is a two-sided segment with a point at each end (thesis 3.2.4).
      const bool face = line_time_of_impact(flipper_face(f, theta, p), p, v, r, remaining, c);
      if (face && c.t_s < best.t_s) {
        best = c;
        hit_obstacle = -1;
        hit_flipper = static_cast<std::int32_t>(i);
      }
      for (const Vec2& end : {table::flipper_tip(f, theta), f.pivot}) {
        if (circle_time_of_impact(end, 0.0, p, v, r, remaining, c) && c.t_s < best.t_s) {
          best = c;
          hit_obstacle = -1;
          hit_flipper = static_cast<std::int32_t>(i);
        }
      }
    }
    if (hit_obstacle < 0 && hit_flipper < 0) {
      p += remaining * v;
      wedged = false;
      break;
    }
    // Stop short of contact by the separation, measured along the normal, so
    // the move never enters any other surface (thesis 3.3.2, fn. 3).
    const double approach = -v.dot(best.normal);
    const double t_move = std::max(0.0, best.t_s - options_.separation_m / approach);
    p += t_move * v;
    remaining -= t_move;
    contacts.normal[contacts.count] = best.normal;
    contacts.point[contacts.count] = best.point;
    contacts.obstacle[contacts.count] = hit_obstacle;
    contacts.flipper[contacts.count] = hit_flipper;
    ++contacts.count;
    if (hit_obstacle >= 0) {
      apply_obstacle_hit(state, hit_obstacle, best.normal, events);
    } else {
      const table::Flipper& f = board_.flippers[hit_flipper];
      const FlipperState& fs = state.flippers[hit_flipper];
      v = flipper_response(f, fs.theta_rad, fs.omega_rad_s, best.point, best.normal, v);
      events.flags |= StepEvents::kHitFlipper;
      events.flipper = hit_flipper;
    }
    // Kicks may exceed the clamp; the rest of this step must stay within the
    // broadphase's reach, so the clamp applies at once.
    clamp_speed(v, board_.ball.speed_max_mps);
    if (!state.ball_in_play) return;  // eaten by the obstacle's action
  }
  if (wedged && remaining > 0.0) {
    // The contacts ran out with time left: the ball is wedged between
    // surfaces (a narrow V) and the rest of the step is dropped, which holds
    // its position. Its velocity must not keep what gravity feeds it while it
    // is held, or it gathers speed step after step (|v| ≈ 3720·dt and energy
    // from nowhere in a 1.2° V, issue 17): the components into the surfaces it
    // still touches go, an inelastic rest on all of them at once.
    Vec2 touching[kMaxContactsPerStep];
    int n = 0;
    for (int k = 0; k < contacts.count; ++k) {
      // Near the contact's plane and near the surface itself: the plane alone had taken a ball that
      // had rattled on 0.1 m past a needle's end for one still on it, and taken 99.6 % of its energy.
      const double plane_gap_m = (p - contacts.point[k]).dot(contacts.normal[k]) - r;
      double surface_m = 0.0;
      if (contacts.obstacle[k] >= 0) {
        surface_m = table::distance_to_shape(board_.shapes[contacts.obstacle[k]], p);
      } else {
        const table::Flipper& f = board_.flippers[contacts.flipper[k]];
        const double theta = state.flippers[contacts.flipper[k]].theta_rad;
        surface_m = distance_point_segment(p, f.pivot, table::flipper_tip(f, theta));
      }
      if (std::max(plane_gap_m, surface_m - r) <= options_.contact_tolerance_m) touching[n++] = contacts.normal[k];
    }
    v = project_onto_free_cone(v, touching, n);
  }

  update_sensors(state, start, events);
  if (!state.ball_in_play) return;
  update_contacts(state, candidates, events);

  const double margin = 2.0 * r;
  if (p.x() < -margin || p.y() < -margin || p.x() > board_.width_m + margin || p.y() > board_.height_m + margin) {
    events.flags |= StepEvents::kLeftTable;
    lose_ball(state, events);
  }
}

bool ThesisStepper::push_is_blocked(const GameState& state, std::size_t pusher, const Vec2& from,
                                    const Vec2& to) const {
  if (obstacle_penetration_m(board_, state, obstacle_candidates(to), to) > kStallDepth_m) return true;
  // The way there too: a push longer than the ball's radius (a long blade, a fast stroke, a long step)
  // had carried its centre past a one-sided line or through a polygon, where no overlap is counted.
  const double r = board_.ball.radius_m;
  Contact c;
  for (const Vec2& at : {from, to}) {
    for (const std::int32_t k : obstacle_candidates(at)) {
      if (state.visible[k] != kVisible) continue;
      if (shape_time_of_impact(board_.shapes[k], from, to - from, r, 1.0, c)) return true;
    }
  }
  // And the other flippers: one whose blade lay in the way had been pushed through.
  for (std::size_t j = 0; j < board_.flippers.size(); ++j) {
    if (j == pusher) continue;
    const table::Flipper& f = board_.flippers[j];
    const double d = distance_point_segment(to, f.pivot, table::flipper_tip(f, state.flippers[j].theta_rad));
    if (r - d > kStallDepth_m) return true;
  }
  return false;
}

void ThesisStepper::apply_obstacle_hit(GameState& state, std::int32_t index, const Vec2& normal,
                                       StepEvents& events) const {
  rules::hit_obstacle(board_, state, index, normal, events, board_.ball.radius_m + options_.separation_m);
}

void ThesisStepper::update_sensors(GameState& state, const Vec2& from, StepEvents& events) const {
  const double r = board_.ball.radius_m;
  const auto candidates = options_.use_grid ? sensor_grid_.candidates(from) : std::span<const std::int32_t>(all_sensors_);
  for (const std::int32_t i : candidates) {
    const table::Sensor& sensor = board_.sensors[i];
    const Vec2& to = state.ball.position_m;
    const bool inside = rules::on_sensor(sensor, to, r);
    const bool entered = rules::swept_onto_sensor(sensor, from, to, r) && !state.sensor_inside[i];
    state.sensor_inside[i] = inside ? 1 : 0;
    if (!entered) continue;
    rules::fire_sensor(board_, state, i, events);
    if (!state.ball_in_play) return;
  }
}

void ThesisStepper::update_contacts(GameState& state, std::span<const std::int32_t> candidates,
                                    StepEvents& events) const {
  rules::update_contacts(board_, state, candidates, board_.ball.radius_m + options_.contact_tolerance_m,
                         options_.dt_s, has_contact_score_, events);
}

void ThesisStepper::raise_flags(GameState& state) const {
  rules::raise_flags(board_, state, board_.ball.radius_m + options_.separation_m);
}

void ThesisStepper::lose_ball(GameState& state, StepEvents& events) const { rules::lose_ball(board_, state, events); }

}  // namespace pinball::sim
