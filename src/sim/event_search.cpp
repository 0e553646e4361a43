// Event search of the event stepper: the earliest event within the horizon,
// from polynomial roots (lines: quadratic, circles and points: quartic), a
// certified root search for turning flippers, flipper stops and sensor
// entries (docs/physics.md, "The event stepper").

#include <algorithm>
#include <cmath>
#include <span>

#include "event_context.h"
#include "pinball/sim/collision.h"
#include "pinball/sim/polynomial_roots.h"

namespace pinball::sim::event {
namespace {

// Steps of the certified flipper search before it hands back a partial
// horizon (the search then resumes from there).
constexpr int kMaxFlipperIterations = 200;

// The bounding box of the motion's centre over [0, h].
void motion_box(const Motion& m, double h, Vec2& lo, Vec2& hi) {
  const Vec2 end = m.pos(h);
  lo = m.p.cwiseMin(end);
  hi = m.p.cwiseMax(end);
  for (int k = 0; k < 2; ++k) {
    if (m.a[k] == 0.0) continue;
    const double t = -m.v[k] / m.a[k];  // turning point of this coordinate
    if (t > 0.0 && t < h) {
      const double x = m.p[k] + t * (m.v[k] + 0.5 * t * m.a[k]);
      lo[k] = std::min(lo[k], x);
      hi[k] = std::max(hi[k], x);
    }
  }
}

// |p(τ) − c|² − R² as a quartic in τ; the constant term factored so that it
// keeps its digits when the ball touches (|p − c| ≈ R).
void circle_poly(const Motion& m, const Vec2& c, double reach_m, double out[5]) {
  const Vec2 d = m.p - c;
  const double dist = d.norm();
  out[0] = (dist - reach_m) * (dist + reach_m);
  out[1] = 2.0 * d.dot(m.v);
  out[2] = m.v.squaredNorm() + d.dot(m.a);
  out[3] = m.v.dot(m.a);
  out[4] = 0.25 * m.a.squaredNorm();
}

// Touching (within tolerance) and approaching. A touching ball whose
// normal speed is below touch_speed was classified as a contact (or as
// leaving over an end) before the search, so only a real approach counts.
bool approaching_now(const StepContext& ctx, double gap, double vn) {
  return gap <= ctx.touch_m && vn < -ctx.touch_speed_mps;
}

// One-sided line: the ball's surface reaches the front face within the segment.
bool line_impact(const StepContext& ctx, const table::Shape& s, double horizon, double& t_hit) {
  const Motion& m = ctx.m;
  const Vec2& n = s.normal;
  const double sc = (m.p - s.p0).dot(n);
  const double gap = sc - ctx.r;
  const double vn = m.v.dot(n);
  const double an = m.a.dot(n);
  const Vec2 ab = s.p1 - s.p0;
  auto foot_inside = [&](double t) {
    const double u = (m.pos(t) - s.p0).dot(ab);
    return u >= 0.0 && u <= ab.squaredNorm();
  };
  if (sc >= 0.0 && approaching_now(ctx, gap, vn)) {
    if (!foot_inside(0.0)) return false;
    t_hit = 0.0;
    return true;
  }
  const double c[3] = {gap, vn, 0.5 * an};
  double t;
  if (!first_crossing_down(c, 2, 0.0, horizon, ctx.t_tol, t) || !foot_inside(t)) return false;
  t_hit = t;
  return true;
}

// Circle of radius reach_m (its own plus the ball's) around c.
bool circle_impact(const StepContext& ctx, const Vec2& c, double reach_m, double horizon, double& t_hit,
                   Vec2& normal) {
  const Motion& m = ctx.m;
  if (distance_point_box(c, ctx.box_lo, ctx.box_hi) > reach_m + ctx.touch_m) return false;
  double poly[5];
  circle_poly(m, c, reach_m, poly);
  const Vec2 d = m.p - c;
  const double dist = d.norm();
  double t = 0.0;
  // d/dτ |p − c|² at τ = 0 is 2·|d|·(normal speed).
  const bool now = dist > 0.0 && approaching_now(ctx, dist - reach_m, poly[1] / (2.0 * dist));
  if (!now && !first_crossing_down(poly, 4, 0.0, horizon, ctx.t_tol, t)) return false;
  const Vec2 at = m.pos(t) - c;
  const double len = at.norm();
  if (len == 0.0) return false;
  t_hit = t;
  normal = at / len;
  return true;
}

// Certified search against a turning flipper: the gap D(τ) between ball and
// segment obeys D(τ + δ) >= D + D'·δ − ½·C·δ² (C bounds |D''|) and
// D(τ + δ) >= D − B·δ (B bounds |D'|), so a step to the first zero of
// either bound, allowing at most length_tol of overlap, can never pass a
// contact. It ends at D <= length_tol with the ball approaching.
void moving_flipper_impact(const StepContext& ctx, const table::Flipper& f, const FlipperState& fs,
                           std::int32_t index, Next& next) {
  const Motion& m = ctx.m;
  const double r = ctx.r;
  const double w = std::abs(fs.omega_rad_s);
  const double h = next.t;
  const double tol = ctx.length_tol_m;
  const double vmax = m.v.norm() + m.a.norm() * h;
  const double reach = (m.p - f.pivot).norm() + m.v.norm() * h + 0.5 * m.a.norm() * h * h;
  const double arm = std::min(reach, f.length_m + r + ctx.touch_m + vmax * h);
  const double b = vmax + w * f.length_m;
  const double vrot = vmax + w * arm;
  const double c = m.a.norm() + 2.0 * w * vrot + w * w * arm + vrot * vrot / (0.5 * r);
  double t = 0.0;
  for (int it = 0; it < kMaxFlipperIterations; ++it) {
    const double theta = fs.theta_rad + fs.omega_rad_s * t;
    const Vec2 dir = table::flipper_direction(f, theta);
    const Vec2 q = m.pos(t);
    const double along = std::clamp((q - f.pivot).dot(dir), 0.0, f.length_m);
    const Vec2 closest = f.pivot + along * dir;
    const Vec2 d = q - closest;
    const double dist = d.norm();
    const double gap = dist - r;
    const Vec2 n = dist > 0.0 ? Vec2(d / dist) : table::flipper_up_normal(f, theta);
    const double rate = n.dot(m.vel(t) - flipper_point_velocity(f, theta, fs.omega_rad_s, closest));
    if (gap <= tol && rate < 0.0) {
      if (t < next.t) next = {t, Kind::kFlipper, index, n, closest};
      return;
    }
    const double first = std::max(gap, 0.0) / b;
    const double slack = gap + tol;
    const double second = slack > 0.0 ? (rate + std::sqrt(rate * rate + 2.0 * c * slack)) / c : 0.0;
    // Separating, D' >= rate − C·δ stays >= 0 for rate / C: no approach can begin before. A ball
    // leaving an overlap had crept forward by the least step and frozen there.
    const double separating = rate > 0.0 ? rate / c : 0.0;
    // The least step is length_tol at the flipper's closing speed b, never the ball's alone: a ball at
    // rest (g = 0, a corner) has no speed of its own and the step had jumped the whole horizon, the
    // blade passing through it.
    t += std::max({first, second, separating, 1e-3 * tol / b});
    if (t >= next.t) return;
  }
  // Not settled within the iteration budget: come back from here.
  next = {t, Kind::kHorizon, -1, Vec2::Zero(), Vec2::Zero()};
}

}  // namespace

// The longest stretch over which the ball's path box covers at most 2 x 2
// grid cells, then the candidates of those cells.
double choose_horizon(StepContext& ctx, double remaining_s) {
  Motion& m = ctx.m;
  m.p = ctx.state.ball.position_m;
  m.v = ctx.state.ball.velocity_mps;
  double h = remaining_s;
  const double cell = ctx.obstacle_grid.cell_m();
  if (ctx.options.use_grid && cell > 0.0) {
    const double span = 0.9 * cell;
    const double sv = m.v.norm();
    const double sa = m.a.norm();
    const double h_cell = sa > 0.0 ? 2.0 * span / (sv + std::sqrt(sv * sv + 2.0 * sa * span)) : span / sv;
    h = std::min(h, h_cell);
  }
  while (true) {
    motion_box(m, h, ctx.box_lo, ctx.box_hi);
    if (!ctx.options.use_grid) {
      ctx.obstacles.lists[0] = ctx.all_obstacles;
      ctx.obstacles.count = 1;
      ctx.sensors.lists[0] = ctx.all_sensors;
      ctx.sensors.count = 1;
      break;
    }
    const int no = ctx.obstacle_grid.candidates_in_box(ctx.box_lo, ctx.box_hi, ctx.obstacles.lists.data(), kMaxLists);
    const int ns = ctx.sensor_grid.candidates_in_box(ctx.box_lo, ctx.box_hi, ctx.sensors.lists.data(), kMaxLists);
    if (no <= kMaxLists && ns <= kMaxLists) {
      ctx.obstacles.count = no;
      ctx.sensors.count = ns;
      break;
    }
    h *= 0.5;  // round-off put the box on a third cell: shorten
  }
  ctx.speed_bound = m.v.norm() + m.a.norm() * h;
  ctx.t_tol = ctx.length_tol_m / std::max(ctx.speed_bound, 1e-300);
  return h;
}

void find_flipper_stops(const StepContext& ctx, Next& next) {
  const table::Board& board = ctx.board;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const FlipperState& fs = ctx.state.flippers[i];
    if (fs.omega_rad_s == 0.0) continue;
    const table::Flipper& f = board.flippers[i];
    const double stop = fs.omega_rad_s > 0.0 ? f.theta_max_rad : f.theta_min_rad;
    const double t = std::max(0.0, (stop - fs.theta_rad) / fs.omega_rad_s);
    if (t < next.t) next = {t, Kind::kFlipperStop, static_cast<std::int32_t>(i), Vec2::Zero(), Vec2::Zero()};
  }
}

void find_obstacle_impact(const StepContext& ctx, Next& next) {
  ctx.obstacles.for_each([&](std::int32_t i) {
    if (ctx.state.visible[i] != kVisible || is_contact(ctx, Surface::kObstacle, i)) return;
    const table::Shape& s = ctx.board.shapes[i];
    double t;
    if (s.kind == table::ShapeKind::kLine) {
      if (line_impact(ctx, s, next.t, t) && t < next.t) next = {t, Kind::kObstacle, i, s.normal, Vec2::Zero()};
    } else {
      Vec2 n;
      if (circle_impact(ctx, s.p0, s.radius_m + ctx.r, next.t, t, n) && t < next.t) {
        next = {t, Kind::kObstacle, i, n, Vec2::Zero()};
      }
    }
  });
}

// Leaving the end of the surface the ball slides on.
void find_edge(const StepContext& ctx, Next& next) {
  if (ctx.mode != Mode::kSlide) return;
  const Motion& m = ctx.m;
  const Touch& contact = ctx.contact;
  const double u0 = (m.p - contact.origin).dot(contact.tangent);
  const double u1 = m.v.dot(contact.tangent);
  const double u2 = 0.5 * m.a.dot(contact.tangent);
  const double above[3] = {contact.u_hi - u0, -u1, -u2};
  const double below[3] = {u0 - contact.u_lo, u1, u2};
  double t;
  for (const double* c : {above, below}) {
    if (first_crossing_down(c, 2, 0.0, next.t, ctx.t_tol, t) && t < next.t) {
      next = {t, Kind::kEdge, -1, Vec2::Zero(), Vec2::Zero()};
    }
  }
}

void find_sensor_entry(const StepContext& ctx, Next& next) {
  const Motion& m = ctx.m;
  const double r = ctx.r;
  const double t_tol = ctx.t_tol;
  ctx.sensors.for_each([&](std::int32_t i) {
    if (ctx.state.sensor_inside[i]) return;
    const table::Sensor& sensor = ctx.board.sensors[i];
    const table::Shape& s = sensor.shape;
    double t = INFINITY;
    if (sensor.kind == table::SensorKind::kHole || s.kind == table::ShapeKind::kCircle) {
      const double reach = sensor.kind == table::SensorKind::kHole ? s.radius_m : s.radius_m + r;
      if (distance_point_box(s.p0, ctx.box_lo, ctx.box_hi) > reach) return;
      if ((m.p - s.p0).norm() <= reach) {
        t = 0.0;
      } else {
        double poly[5];
        circle_poly(m, s.p0, reach, poly);
        if (!first_crossing_down(poly, 4, 0.0, next.t, t_tol, t)) return;
      }
    } else {
      // A line sensor is touched when the ball is within r of the segment:
      // either face within the segment, or either end.
      if (distance_point_segment(m.p, s.p0, s.p1) <= r) {
        t = 0.0;
      } else {
        const Vec2 ab = s.p1 - s.p0;
        for (const double side : {1.0, -1.0}) {
          const Vec2 n = side * s.normal;
          const double c[3] = {(m.p - s.p0).dot(n) - r, m.v.dot(n), 0.5 * m.a.dot(n)};
          double tf;
          if (first_crossing_down(c, 2, 0.0, next.t, t_tol, tf)) {
            const double u = (m.pos(tf) - s.p0).dot(ab);
            if (u >= 0.0 && u <= ab.squaredNorm()) t = std::min(t, tf);
          }
        }
        for (const Vec2& end : {s.p0, s.p1}) {
          double poly[5];
          circle_poly(m, end, r, poly);
          double te;
          if (first_crossing_down(poly, 4, 0.0, next.t, t_tol, te)) t = std::min(t, te);
        }
      }
    }
    if (t < next.t) next = {t, Kind::kSensor, i, Vec2::Zero(), Vec2::Zero()};
  });
}

void find_flipper_impact(const StepContext& ctx, Next& next) {
  const table::Board& board = ctx.board;
  const double r = ctx.r;
  for (std::size_t k = 0; k < board.flippers.size(); ++k) {
    const table::Flipper& f = board.flippers[k];
    const FlipperState& fs = ctx.state.flippers[k];
    const auto index = static_cast<std::int32_t>(k);
    if (distance_point_box(f.pivot, ctx.box_lo, ctx.box_hi) > f.length_m + r + ctx.touch_m) continue;
    if (fs.omega_rad_s != 0.0) {
      moving_flipper_impact(ctx, f, fs, index, next);
      continue;
    }
    if (ctx.mode == Mode::kRest) continue;  // a resting ball meets only moving flippers
    // A flipper at rest is a two-sided segment with a point at each end.
    const bool on_face = is_contact(ctx, Surface::kFlipperFace, index);
    const bool on_end = is_contact(ctx, Surface::kFlipperEnd, index);
    double t;
    if (!on_face) {
      const table::Shape face = flipper_face(f, fs.theta_rad, ctx.m.p);
      if (line_impact(ctx, face, next.t, t) && t < next.t) {
        const Vec2 q = ctx.m.pos(t) - r * face.normal;
        next = {t, Kind::kFlipper, index, face.normal, q};
      }
    }
    if (on_face || on_end) continue;
    Vec2 n;
    for (const Vec2& end : {table::flipper_tip(f, fs.theta_rad), f.pivot}) {
      if (circle_impact(ctx, end, r, next.t, t, n) && t < next.t) next = {t, Kind::kFlipper, index, n, end};
    }
  }
}

}  // namespace pinball::sim::event
