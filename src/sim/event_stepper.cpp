#include "pinball/sim/event_stepper.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>

#include "game_rules.h"
#include "pinball/sim/collision.h"
#include "pinball/sim/polynomial_roots.h"

namespace pinball::sim {
namespace {

// More events than this inside one step is a ball caught in an endless
// sequence (a pinch the stall rule missed, a carried ball): it rests for the
// rest of the step (docs/physics.md, "The event stepper").
constexpr int kMaxEventsPerStep = 256;
// Cells one box query may cover; the query horizon is chosen so that the
// ball's path box spans at most 2 x 2 cells.
constexpr int kMaxLists = 4;
// Surfaces the ball may touch at once that the contact classification weighs.
constexpr int kMaxTouches = 4;
// Steps of the certified flipper search before it hands back a partial
// horizon (the search then resumes from there).
constexpr int kMaxFlipperIterations = 200;
// A moving flipper stalls when the ball it hits is this close to a surface
// facing the flipper (the ball is pinched: a real coil stalls too).
constexpr double kPinchCosine = -0.1;

// Uniformly accelerated motion: p(τ) = p + v·τ + ½·a·τ².
struct Motion {
  Vec2 p = Vec2::Zero();
  Vec2 v = Vec2::Zero();
  Vec2 a = Vec2::Zero();
  Vec2 pos(double t) const { return p + t * (v + 0.5 * t * a); }
  Vec2 vel(double t) const { return v + t * a; }
};

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

// Cell lists merged in ascending index order without duplicates.
struct CandidateLists {
  std::array<std::span<const std::int32_t>, kMaxLists> lists{};
  int count = 0;

  template <class Fn>
  void for_each(Fn&& fn) const {
    if (count == 1) {
      for (const std::int32_t i : lists[0]) fn(i);
      return;
    }
    std::array<std::size_t, kMaxLists> at{};
    while (true) {
      std::int32_t next = std::numeric_limits<std::int32_t>::max();
      for (int k = 0; k < count; ++k) {
        if (at[k] < lists[k].size()) next = std::min(next, lists[k][at[k]]);
      }
      if (next == std::numeric_limits<std::int32_t>::max()) return;
      fn(next);
      for (int k = 0; k < count; ++k) {
        if (at[k] < lists[k].size() && lists[k][at[k]] == next) ++at[k];
      }
    }
  }
};

void clamp_speed(Vec2& v, double speed_max) {
  const double s2 = v.squaredNorm();
  if (s2 > speed_max * speed_max) v *= speed_max / std::sqrt(s2);
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

}  // namespace

// One step's working state: the ball's current mode and motion, the
// candidates near it, and the search for the next event.
struct EventStepper::Run {
  enum class Mode { kFlight, kSlide, kRest };
  enum class Kind { kHorizon, kObstacle, kFlipper, kFlipperStop, kSensor, kEdge };
  enum class Surface { kNone, kObstacle, kFlipperFace, kFlipperEnd };

  struct Next {
    double t = 0.0;
    Kind kind = Kind::kHorizon;
    std::int32_t index = -1;
    Vec2 normal = Vec2::Zero();
    Vec2 point = Vec2::Zero();
  };

  struct Touch {
    Surface surface = Surface::kNone;
    std::int32_t index = -1;
    double gap = 0.0;
    Vec2 normal = Vec2::Zero();
    Vec2 origin = Vec2::Zero();   // where u = 0 along the tangent
    Vec2 tangent = Vec2::Zero();
    double u_lo = 0.0;
    double u_hi = 0.0;
  };

  const EventStepper& stepper;
  const table::Board& board;
  GameState& state;
  StepEvents& events;
  const double r;
  const Vec2 gravity;

  Mode mode = Mode::kFlight;
  Touch contact;  // the surface the ball slides on (kSlide)
  Motion m;
  CandidateLists obstacles;
  CandidateLists sensors;
  Vec2 box_lo = Vec2::Zero();
  Vec2 box_hi = Vec2::Zero();
  double speed_bound = 0.0;  // |v| + |a|·h: the fastest the ball moves over the horizon
  double t_tol = 0.0;        // time tolerance of the roots over the horizon

  Run(const EventStepper& s, GameState& st, StepEvents& ev)
      : stepper(s),
        board(s.board_),
        state(st),
        events(ev),
        r(s.board_.ball.radius_m),
        gravity(0.0, -s.board_.gravity_mps2) {}

  const EventStepperOptions& options() const { return stepper.options_; }

  // ---- The step ----------------------------------------------------------

  void run(double horizon_s) {
    double t = 0.0;
    int count = 0;
    while (t < horizon_s) {
      if (!state.ball_in_play) {
        advance_flippers(horizon_s - t);
        return;
      }
      classify();
      const double h = choose_horizon(horizon_s - t);
      Next next;
      next.t = h;
      find_flipper_stops(next);
      if (mode != Mode::kRest) {
        find_obstacle_impact(next);
        find_edge(next);
        if (!board.sensors.empty()) find_sensor_entry(next);
      }
      if (!board.flippers.empty()) find_flipper_impact(next);
      advance(next.t);
      t = (next.kind == Kind::kHorizon && h == horizon_s - t) ? horizon_s : t + next.t;
      if (next.kind == Kind::kHorizon) continue;
      ++state.events;
      handle(next);
      if (++count > kMaxEventsPerStep) {
        give_up(horizon_s - t);
        return;
      }
    }
  }

  // The guard: the ball rests where it is for the rest of the step, and a
  // flipper that could reach it stalls.
  void give_up(double remaining_s) {
    state.ball.velocity_mps = Vec2::Zero();
    const Vec2& p = state.ball.position_m;
    for (std::size_t i = 0; i < board.flippers.size(); ++i) {
      const table::Flipper& f = board.flippers[i];
      FlipperState& fs = state.flippers[i];
      if (fs.omega_rad_s == 0.0) continue;
      if ((p - f.pivot).norm() <= f.length_m + r + stepper.touch_m_) {
        fs.omega_rad_s = 0.0;
        events.flags |= StepEvents::kFlipperStall;
        events.flipper = static_cast<std::int32_t>(i);
      }
    }
    advance_flippers(remaining_s);
  }

  void advance_flippers(double dt) {
    for (std::size_t i = 0; i < board.flippers.size(); ++i) {
      FlipperState& fs = state.flippers[i];
      if (fs.omega_rad_s == 0.0) continue;
      const table::Flipper& f = board.flippers[i];
      fs.theta_rad = std::clamp(fs.theta_rad + fs.omega_rad_s * dt, f.theta_min_rad, f.theta_max_rad);
      if (fs.theta_rad == f.theta_min_rad || fs.theta_rad == f.theta_max_rad) fs.omega_rad_s = 0.0;
    }
  }

  void advance(double dt) {
    if (dt > 0.0) {
      state.ball.position_m = m.pos(dt);
      state.ball.velocity_mps = m.vel(dt);
      for (std::size_t i = 0; i < board.flippers.size(); ++i) {
        FlipperState& fs = state.flippers[i];
        if (fs.omega_rad_s == 0.0) continue;
        const table::Flipper& f = board.flippers[i];
        fs.theta_rad = std::clamp(fs.theta_rad + fs.omega_rad_s * dt, f.theta_min_rad, f.theta_max_rad);
      }
    }
  }

  // The longest stretch over which the ball's path box covers at most 2 x 2
  // grid cells, then the candidates of those cells.
  double choose_horizon(double remaining) {
    m.p = state.ball.position_m;
    m.v = state.ball.velocity_mps;
    double h = remaining;
    const double cell = stepper.obstacle_grid_.cell_m();
    if (options().use_grid && cell > 0.0) {
      const double span = 0.9 * cell;
      const double sv = m.v.norm();
      const double sa = m.a.norm();
      const double h_cell = sa > 0.0 ? 2.0 * span / (sv + std::sqrt(sv * sv + 2.0 * sa * span)) : span / sv;
      h = std::min(h, h_cell);
    }
    while (true) {
      motion_box(m, h, box_lo, box_hi);
      if (!options().use_grid) {
        obstacles.lists[0] = stepper.all_obstacles_;
        obstacles.count = 1;
        sensors.lists[0] = stepper.all_sensors_;
        sensors.count = 1;
        break;
      }
      const int no = stepper.obstacle_grid_.candidates_in_box(box_lo, box_hi, obstacles.lists.data(), kMaxLists);
      const int ns = stepper.sensor_grid_.candidates_in_box(box_lo, box_hi, sensors.lists.data(), kMaxLists);
      if (no <= kMaxLists && ns <= kMaxLists) {
        obstacles.count = no;
        sensors.count = ns;
        break;
      }
      h *= 0.5;  // round-off put the box on a third cell: shorten
    }
    speed_bound = m.v.norm() + m.a.norm() * h;
    t_tol = stepper.length_tol_m_ / std::max(speed_bound, 1e-300);
    return h;
  }

  // ---- Contact classification --------------------------------------------

  // Surfaces the ball touches now with (nearly) no normal speed decide its
  // mode: flight, sliding along one of them, or resting against two.
  void classify() {
    mode = Mode::kFlight;
    contact = Touch{};
    m.a = gravity;
    Vec2& p = state.ball.position_m;
    Vec2& v = state.ball.velocity_mps;
    std::array<Touch, kMaxTouches> touches;
    int n = 0;
    // Only a touch without normal speed (round-off, or one that settle()
    // dropped after a bounce too weak to lift the ball by rest_height) is a
    // contact. A real normal speed, however small, is a bounce or a lift-off
    // for the impact search: two touches that each had a little would
    // otherwise stop a ball sliding fast through a flat V.
    auto keep = [&](const Touch& t) {
      if (std::abs(v.dot(t.normal)) > stepper.touch_speed_mps_) return;
      if (n < kMaxTouches) touches[n++] = t;
    };
    const double touch = stepper.touch_m_;
    CandidateLists here;
    here.lists[0] = options().use_grid ? stepper.obstacle_grid_.candidates(p)
                                       : std::span<const std::int32_t>(stepper.all_obstacles_);
    here.count = 1;
    here.for_each([&](std::int32_t i) {
      if (state.visible[i] != kVisible) return;
      const table::Shape& s = board.shapes[i];
      Touch t;
      t.surface = Surface::kObstacle;
      t.index = i;
      if (s.kind == table::ShapeKind::kLine) {
        const double sc = (p - s.p0).dot(s.normal);
        t.gap = sc - r;
        if (sc < 0.0 || std::abs(t.gap) > touch) return;
        const Vec2 ab = s.p1 - s.p0;
        const double len = ab.norm();
        t.normal = s.normal;
        t.origin = s.p0;
        t.tangent = ab / len;
        t.u_lo = 0.0;
        t.u_hi = len;
        if (!on_range(t, p, v)) return;
      } else {
        const Vec2 d = p - s.p0;
        const double dist = d.norm();
        t.gap = dist - s.radius_m - r;
        if (dist == 0.0 || std::abs(t.gap) > touch) return;
        t.normal = d / dist;
        set_circle_range(t, p);
      }
      keep(t);
    });
    for (std::size_t k = 0; k < board.flippers.size(); ++k) {
      const FlipperState& fs = state.flippers[k];
      if (fs.omega_rad_s != 0.0) continue;  // a moving flipper is never a resting contact
      const table::Flipper& f = board.flippers[k];
      const Vec2 rel = p - f.pivot;
      if (rel.squaredNorm() > std::pow(f.length_m + r + touch, 2)) continue;
      const Vec2 dir = table::flipper_direction(f, fs.theta_rad);
      const double along = rel.dot(dir);
      const double clamped = std::clamp(along, 0.0, f.length_m);
      const Vec2 closest = f.pivot + clamped * dir;
      const Vec2 d = p - closest;
      const double dist = d.norm();
      Touch t;
      t.index = static_cast<std::int32_t>(k);
      t.gap = dist - r;
      if (dist == 0.0 || std::abs(t.gap) > touch) continue;
      if (along > 0.0 && along < f.length_m) {
        t.surface = Surface::kFlipperFace;
        const Vec2 up = table::flipper_up_normal(f, fs.theta_rad);
        t.normal = rel.dot(up) >= 0.0 ? up : Vec2(-up);
        t.origin = f.pivot;
        t.tangent = dir;
        t.u_lo = 0.0;
        t.u_hi = f.length_m;
        if (!on_range(t, p, v)) continue;
      } else {
        t.surface = Surface::kFlipperEnd;
        t.normal = d / dist;
        set_circle_range(t, p);
      }
      keep(t);
    }
    if (n == 0) return;

    // The contact force is a non-negative multiple of each normal: a single
    // surface holds the ball when gravity presses into it and the slide it
    // leaves does not press into another touching surface; else two hold it.
    int slide = -1;
    bool pressed = false;
    for (int i = 0; i < n; ++i) pressed = pressed || gravity.dot(touches[i].normal) < 0.0;
    if (!pressed) {
      // Nothing supports it: flight. An approach too slow to count as an
      // impact (round-off) stops, or the ball would creep into the surface.
      for (int i = 0; i < n; ++i) v -= std::min(v.dot(touches[i].normal), 0.0) * touches[i].normal;
      return;
    }
    const double eps_a = 1e-12 * std::max(board.gravity_mps2, 1e-300);
    for (int i = 0; i < n && slide < 0; ++i) {
      const Vec2& ni = touches[i].normal;
      const double gn = gravity.dot(ni);
      if (gn >= 0.0) continue;
      const Vec2 ai = gravity - gn * ni;
      bool ok = true;
      for (int j = 0; j < n; ++j) {
        if (j != i && ai.dot(touches[j].normal) < -eps_a) ok = false;
      }
      if (ok) slide = i;
    }
    if (slide < 0) {
      mode = Mode::kRest;
      v = Vec2::Zero();
      m.a = Vec2::Zero();
      return;
    }
    contact = touches[slide];
    mode = Mode::kSlide;
    // Snap onto the surface and drop the normal speed (both below the
    // tolerances): the slide then keeps its distance exactly.
    p -= contact.gap * contact.normal;
    v -= v.dot(contact.normal) * contact.normal;
    m.a = gravity - gravity.dot(contact.normal) * contact.normal;
    if (contact.surface == Surface::kObstacle && board.shapes[contact.index].kind == table::ShapeKind::kCircle) {
      set_circle_range(contact, p);
    } else if (contact.surface == Surface::kFlipperEnd) {
      set_circle_range(contact, p);
    }
  }

  // A ball whose centre's foot is at an end of a line and moving past it is
  // leaving the line, not sliding on it.
  bool on_range(const Touch& t, const Vec2& p, const Vec2& v) const {
    const double u = (p - t.origin).dot(t.tangent);
    const double touch = stepper.touch_m_;
    if (u < t.u_lo - touch || u > t.u_hi + touch) return false;
    const Vec2 a = gravity - gravity.dot(t.normal) * t.normal;
    const double ut = v.dot(t.tangent);
    const double at = a.dot(t.tangent);
    if (u >= t.u_hi - touch && (ut > 0.0 || (ut == 0.0 && at > 0.0))) return false;
    if (u <= t.u_lo + touch && (ut < 0.0 || (ut == 0.0 && at < 0.0))) return false;
    return true;
  }

  // Contact with a circle (or a flipper's end) slides along the tangent at
  // the contact point for a short stretch, after which the ball flies again
  // (and falls back if gravity holds it to the circle).
  void set_circle_range(Touch& t, const Vec2& p) const {
    t.origin = p;
    t.tangent = perp_left(t.normal);
    t.u_lo = -stepper.circle_slide_m_;
    t.u_hi = stepper.circle_slide_m_;
  }

  bool is_contact(Surface s, std::int32_t index) const {
    return mode == Mode::kSlide && contact.surface == s && contact.index == index;
  }

  // ---- Event search --------------------------------------------------------

  void find_flipper_stops(Next& next) const {
    for (std::size_t i = 0; i < board.flippers.size(); ++i) {
      const FlipperState& fs = state.flippers[i];
      if (fs.omega_rad_s == 0.0) continue;
      const table::Flipper& f = board.flippers[i];
      const double stop = fs.omega_rad_s > 0.0 ? f.theta_max_rad : f.theta_min_rad;
      const double t = std::max(0.0, (stop - fs.theta_rad) / fs.omega_rad_s);
      if (t < next.t) next = {t, Kind::kFlipperStop, static_cast<std::int32_t>(i), Vec2::Zero(), Vec2::Zero()};
    }
  }

  // Touching (within tolerance) and approaching. A touching ball whose
  // normal speed is below touch_speed was classified as a contact (or as
  // leaving over an end) before the search, so only a real approach counts.
  bool approaching_now(double gap, double vn) const {
    return gap <= stepper.touch_m_ && vn < -stepper.touch_speed_mps_;
  }

  // One-sided line: the ball's surface reaches the front face within the segment.
  bool line_impact(const table::Shape& s, double horizon, double& t_hit) const {
    const Vec2& n = s.normal;
    const double sc = (m.p - s.p0).dot(n);
    const double gap = sc - r;
    const double vn = m.v.dot(n);
    const double an = m.a.dot(n);
    const Vec2 ab = s.p1 - s.p0;
    auto foot_inside = [&](double t) {
      const double u = (m.pos(t) - s.p0).dot(ab);
      return u >= 0.0 && u <= ab.squaredNorm();
    };
    if (sc >= 0.0 && approaching_now(gap, vn)) {
      if (!foot_inside(0.0)) return false;
      t_hit = 0.0;
      return true;
    }
    const double c[3] = {gap, vn, 0.5 * an};
    double t;
    if (!first_crossing_down(c, 2, 0.0, horizon, t_tol, t) || !foot_inside(t)) return false;
    t_hit = t;
    return true;
  }

  // Circle of radius reach_m (its own plus the ball's) around c.
  bool circle_impact(const Vec2& c, double reach_m, double horizon, double& t_hit, Vec2& normal) const {
    if (distance_point_box(c, box_lo, box_hi) > reach_m + stepper.touch_m_) return false;
    double poly[5];
    circle_poly(m, c, reach_m, poly);
    const Vec2 d = m.p - c;
    const double dist = d.norm();
    double t = 0.0;
    // d/dτ |p − c|² at τ = 0 is 2·|d|·(normal speed).
    const bool now = dist > 0.0 && approaching_now(dist - reach_m, poly[1] / (2.0 * dist));
    if (!now && !first_crossing_down(poly, 4, 0.0, horizon, t_tol, t)) return false;
    const Vec2 at = m.pos(t) - c;
    const double len = at.norm();
    if (len == 0.0) return false;
    t_hit = t;
    normal = at / len;
    return true;
  }

  void find_obstacle_impact(Next& next) const {
    obstacles.for_each([&](std::int32_t i) {
      if (state.visible[i] != kVisible || is_contact(Surface::kObstacle, i)) return;
      const table::Shape& s = board.shapes[i];
      double t;
      if (s.kind == table::ShapeKind::kLine) {
        if (line_impact(s, next.t, t) && t < next.t) next = {t, Kind::kObstacle, i, s.normal, Vec2::Zero()};
      } else {
        Vec2 n;
        if (circle_impact(s.p0, s.radius_m + r, next.t, t, n) && t < next.t) {
          next = {t, Kind::kObstacle, i, n, Vec2::Zero()};
        }
      }
    });
  }

  // Leaving the end of the surface the ball slides on.
  void find_edge(Next& next) const {
    if (mode != Mode::kSlide) return;
    const double u0 = (m.p - contact.origin).dot(contact.tangent);
    const double u1 = m.v.dot(contact.tangent);
    const double u2 = 0.5 * m.a.dot(contact.tangent);
    const double above[3] = {contact.u_hi - u0, -u1, -u2};
    const double below[3] = {u0 - contact.u_lo, u1, u2};
    double t;
    for (const double* c : {above, below}) {
      if (first_crossing_down(c, 2, 0.0, next.t, t_tol, t) && t < next.t) {
        next = {t, Kind::kEdge, -1, Vec2::Zero(), Vec2::Zero()};
      }
    }
  }

  void find_sensor_entry(Next& next) const {
    sensors.for_each([&](std::int32_t i) {
      if (state.sensor_inside[i]) return;
      const table::Sensor& sensor = board.sensors[i];
      const table::Shape& s = sensor.shape;
      double t = INFINITY;
      if (sensor.kind == table::SensorKind::kHole || s.kind == table::ShapeKind::kCircle) {
        const double reach = sensor.kind == table::SensorKind::kHole ? s.radius_m : s.radius_m + r;
        if (distance_point_box(s.p0, box_lo, box_hi) > reach) return;
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

  void find_flipper_impact(Next& next) const {
    for (std::size_t k = 0; k < board.flippers.size(); ++k) {
      const table::Flipper& f = board.flippers[k];
      const FlipperState& fs = state.flippers[k];
      const auto index = static_cast<std::int32_t>(k);
      if (distance_point_box(f.pivot, box_lo, box_hi) > f.length_m + r + stepper.touch_m_) continue;
      if (fs.omega_rad_s != 0.0) {
        moving_flipper_impact(f, fs, index, next);
        continue;
      }
      if (mode == Mode::kRest) continue;  // a resting ball meets only moving flippers
      // A flipper at rest is a two-sided segment with a point at each end.
      const bool on_face = is_contact(Surface::kFlipperFace, index);
      const bool on_end = is_contact(Surface::kFlipperEnd, index);
      double t;
      if (!on_face) {
        const table::Shape face = flipper_face(f, fs.theta_rad, m.p);
        if (line_impact(face, next.t, t) && t < next.t) {
          const Vec2 q = m.pos(t) - r * face.normal;
          next = {t, Kind::kFlipper, index, face.normal, q};
        }
      }
      if (on_face || on_end) continue;
      Vec2 n;
      for (const Vec2& end : {table::flipper_tip(f, fs.theta_rad), f.pivot}) {
        if (circle_impact(end, r, next.t, t, n) && t < next.t) next = {t, Kind::kFlipper, index, n, end};
      }
    }
  }

  // Certified search against a turning flipper: the gap D(τ) between ball and
  // segment obeys D(τ + δ) >= D + D'·δ − ½·C·δ² (C bounds |D''|) and
  // D(τ + δ) >= D − B·δ (B bounds |D'|), so a step to the first zero of
  // either bound, allowing at most length_tol of overlap, can never pass a
  // contact. It ends at D <= length_tol with the ball approaching.
  void moving_flipper_impact(const table::Flipper& f, const FlipperState& fs, std::int32_t index, Next& next) const {
    const double w = std::abs(fs.omega_rad_s);
    const double h = next.t;
    const double tol = stepper.length_tol_m_;
    const double vmax = m.v.norm() + m.a.norm() * h;
    const double reach = (m.p - f.pivot).norm() + m.v.norm() * h + 0.5 * m.a.norm() * h * h;
    const double arm = std::min(reach, f.length_m + r + stepper.touch_m_ + vmax * h);
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
      t += std::max({first, second, 1e-3 * t_tol});
      if (t >= next.t) return;
    }
    // Not settled within the iteration budget: come back from here.
    next = {t, Kind::kHorizon, -1, Vec2::Zero(), Vec2::Zero()};
  }

  // ---- Responses -------------------------------------------------------------

  // A bounce whose normal speed would not lift the ball above rest_height
  // against the acceleration pressing it to the surface leaves it touching.
  void settle(const Vec2& n, double surface_speed, const Vec2& accel) {
    Vec2& v = state.ball.velocity_mps;
    const double w = v.dot(n) - surface_speed;
    const double press = -accel.dot(n);
    if (press > 0.0 && w < std::sqrt(2.0 * press * options().rest_height_m)) v -= w * n;
  }

  void finish_response() {
    if (options().speed_clamp) clamp_speed(state.ball.velocity_mps, board.ball.speed_max_mps);
  }

  void handle(const Next& next) {
    switch (next.kind) {
      case Kind::kHorizon:
        return;
      case Kind::kEdge:
        return;  // the next classification lets it fly
      case Kind::kFlipperStop: {
        const table::Flipper& f = board.flippers[next.index];
        FlipperState& fs = state.flippers[next.index];
        fs.theta_rad = fs.omega_rad_s > 0.0 ? f.theta_max_rad : f.theta_min_rad;
        fs.omega_rad_s = 0.0;
        return;
      }
      case Kind::kSensor:
        state.sensor_inside[next.index] = 1;
        rules::fire_sensor(board, state, next.index, events);
        return;
      case Kind::kObstacle: {
        const Vec2 accel = m.a;
        rules::hit_obstacle(board, state, next.index, next.normal, events, r + stepper.touch_m_);
        if (!state.ball_in_play) return;
        if (board.obstacles[next.index].action.kick_mps == 0.0 && state.visible[next.index] == kVisible) {
          settle(next.normal, 0.0, accel);
        }
        finish_response();
        return;
      }
      case Kind::kFlipper:
        hit_flipper(next);
        return;
    }
  }

  // A ball jammed between a moving flipper and a surface facing it.
  bool pinched(const Vec2& n) const {
    const Vec2& p = state.ball.position_m;
    const double near = options().contact_tolerance_m;
    bool found = false;
    obstacles.for_each([&](std::int32_t i) {
      if (found || state.visible[i] != kVisible) return;
      const table::Shape& s = board.shapes[i];
      Vec2 ns;
      if (s.kind == table::ShapeKind::kLine) {
        const double sc = (p - s.p0).dot(s.normal);
        const Vec2 ab = s.p1 - s.p0;
        const double u = (p - s.p0).dot(ab);
        if (sc < 0.0 || sc - r > near || u < 0.0 || u > ab.squaredNorm()) return;
        ns = s.normal;
      } else {
        const Vec2 d = p - s.p0;
        const double dist = d.norm();
        if (dist == 0.0 || dist - s.radius_m - r > near) return;
        ns = d / dist;
      }
      found = ns.dot(n) < kPinchCosine;
    });
    return found;
  }

  void hit_flipper(const Next& next) {
    const table::Flipper& f = board.flippers[next.index];
    FlipperState& fs = state.flippers[next.index];
    Vec2& v = state.ball.velocity_mps;
    events.flipper = next.index;
    if (fs.omega_rad_s != 0.0 && pinched(next.normal)) {
      fs.omega_rad_s = 0.0;  // stalled until the next step's command
      events.flags |= StepEvents::kFlipperStall;
    }
    const Vec2 accel = m.a;
    v = flipper_response(f, fs.theta_rad, fs.omega_rad_s, next.point, next.normal, v);
    if (fs.omega_rad_s != 0.0) {
      // The face carries the ball: it leaves at least a little faster than
      // the face at the contact, or the face would strike it again at once.
      const double face = flipper_point_velocity(f, fs.theta_rad, fs.omega_rad_s, next.point).dot(next.normal);
      const double rel = v.dot(next.normal) - face;
      if (rel < stepper.separation_speed_mps_) v += (stepper.separation_speed_mps_ - rel) * next.normal;
      events.flags |= face > 0.0 ? StepEvents::kFlipperPush : StepEvents::kHitFlipper;
    } else {
      settle(next.normal, 0.0, accel);
      events.flags |= StepEvents::kHitFlipper;
    }
    finish_response();
  }
};

EventStepper::EventStepper(const table::Board& board, EventStepperOptions options) : board_(board), options_(options) {
  if (options_.dt_s == 0.0) options_.dt_s = board.dt_s;
  auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  if (!positive(options_.dt_s)) throw std::invalid_argument("event stepper: dt must be a positive number of seconds");
  if (!positive(options_.relative_tolerance) || options_.relative_tolerance >= 1.0) {
    throw std::invalid_argument("event stepper: relative_tolerance must be in (0, 1)");
  }
  if (!positive(options_.rest_height_m)) throw std::invalid_argument("event stepper: rest_height_m must be positive");
  if (!(options_.contact_tolerance_m >= 0.0) || !std::isfinite(options_.contact_tolerance_m)) {
    throw std::invalid_argument("event stepper: contact_tolerance_m must be >= 0");
  }
  const double r = board.ball.radius_m;
  // Root tolerances scale with the board's size: the diagonal of what is on
  // it (the table's when it is empty), not the coordinates, so a board far
  // from the origin is solved as finely as at the origin. Round-off scales
  // with the coordinates' magnitude (far from the origin fewer digits are
  // left) and goes into the touch distance instead.
  const double table = std::hypot(board.width_m, board.height_m);
  double coord = table;
  Vec2 lo = Vec2::Constant(INFINITY);
  Vec2 hi = Vec2::Constant(-INFINITY);
  // What the ball can meet: a ball leaves the table 2r beyond its bounds, so
  // a shape wholly more than 3r outside them is out of reach (the bench's
  // far copies) and does not count.
  const Vec2 reach_lo = Vec2::Constant(-3.0 * r);
  const Vec2 reach_hi = Vec2(board.width_m, board.height_m) + Vec2::Constant(3.0 * r);
  auto cover = [&](Vec2 a, Vec2 b) {
    if ((a.array() > reach_hi.array()).any() || (b.array() < reach_lo.array()).any()) return;
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
    coord = std::max({coord, a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()});
  };
  for (const table::Shape& s : board.shapes) {
    if (s.kind == table::ShapeKind::kCircle) {
      cover(s.p0 - Vec2::Constant(s.radius_m), s.p0 + Vec2::Constant(s.radius_m));
    } else {
      cover(s.p0.cwiseMin(s.p1), s.p0.cwiseMax(s.p1));
    }
  }
  for (const table::Flipper& f : board.flippers) {
    cover(f.pivot - Vec2::Constant(f.length_m), f.pivot + Vec2::Constant(f.length_m));
  }
  const double extent = lo.x() <= hi.x() ? std::max((hi - lo).norm(), 2.0 * r) : table;
  length_tol_m_ = options_.relative_tolerance * extent;
  touch_m_ = 4.0 * length_tol_m_ + 64.0 * std::numeric_limits<double>::epsilon() * coord;
  const double rest_speed = std::sqrt(2.0 * board.gravity_mps2 * options_.rest_height_m);
  touch_speed_mps_ = 1e-3 * rest_speed;
  separation_speed_mps_ = std::max(rest_speed, 1e-3);
  // The tangent of a circle leaves it by circle_slide²/2R; a hundredth of the
  // rest height keeps the slide's error far below it.
  const double lift_m = std::max(1e-2 * options_.rest_height_m, 100.0 * touch_m_);
  circle_slide_m_ = std::sqrt(2.0 * r * lift_m);

  const double reach = r + options_.contact_tolerance_m + touch_m_;
  const double cell = 2.0 * reach;
  obstacle_grid_ = UniformGrid(board.shapes, reach, cell);
  sensor_shapes_ = rules::sensor_shapes(board);
  sensor_grid_ = UniformGrid(sensor_shapes_, reach, obstacle_grid_.cell_m() > 0.0 ? obstacle_grid_.cell_m() : cell);
  all_obstacles_ = rules::all_indices(board.shapes.size());
  all_sensors_ = rules::all_indices(board.sensors.size());
  has_contact_score_ = rules::has_contact_score(board);
}

StepEvents EventStepper::step(GameState& state) const {
  StepEvents events;
  for (std::size_t i = 0; i < board_.flippers.size(); ++i) {
    const table::Flipper& f = board_.flippers[i];
    FlipperState& fs = state.flippers[i];
    const double omega = rules::take_command(f, fs, state.flips);
    const bool at_stop = omega > 0.0 ? fs.theta_rad >= f.theta_max_rad : fs.theta_rad <= f.theta_min_rad;
    fs.omega_rad_s = at_stop ? 0.0 : omega;
  }
  Run run(*this, state, events);
  run.run(options_.dt_s);

  const double r = board_.ball.radius_m;
  if (state.ball_in_play) {
    const Vec2& p = state.ball.position_m;
    rules::update_contacts(board_, state,
                           options_.use_grid ? obstacle_grid_.candidates(p) : std::span<const std::int32_t>(all_obstacles_),
                           r + options_.contact_tolerance_m, options_.dt_s, has_contact_score_, events);
    // A sensor is entered again only after the ball has left it.
    for (std::size_t i = 0; i < board_.sensors.size(); ++i) {
      if (state.sensor_inside[i]) state.sensor_inside[i] = rules::on_sensor(board_.sensors[i], p, r) ? 1 : 0;
    }
    const double margin = 2.0 * r;
    if (p.x() < -margin || p.y() < -margin || p.x() > board_.width_m + margin || p.y() > board_.height_m + margin) {
      events.flags |= StepEvents::kLeftTable;
      rules::lose_ball(board_, state, events);
    }
  }
  if (state.rising_flags > 0) rules::raise_flags(board_, state, r + touch_m_);
  state.time_s += options_.dt_s;
  ++state.steps;
  return events;
}

}  // namespace pinball::sim
