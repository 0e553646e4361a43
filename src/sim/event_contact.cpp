// Contact mode of the event stepper: which surfaces hold the ball, so that a
// ball at rest rests and a ball on a slope slides instead of bouncing forever
// (docs/physics.md, "Contact mode").

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "event_context.h"

namespace pinball::sim::event {
namespace {

// Surfaces the ball may touch at once that the contact classification weighs.
constexpr int kMaxTouches = 4;

// A ball whose centre's foot is at an end of a line and moving past it is
// leaving the line, not sliding on it.
bool on_range(const StepContext& ctx, const Touch& t, const Vec2& p, const Vec2& v) {
  const double u = (p - t.origin).dot(t.tangent);
  const double touch = ctx.touch_m;
  if (u < t.u_lo - touch || u > t.u_hi + touch) return false;
  const Vec2 a = ctx.gravity - ctx.gravity.dot(t.normal) * t.normal;
  const double ut = v.dot(t.tangent);
  const double at = a.dot(t.tangent);
  if (u >= t.u_hi - touch && (ut > 0.0 || (ut == 0.0 && at > 0.0))) return false;
  if (u <= t.u_lo + touch && (ut < 0.0 || (ut == 0.0 && at < 0.0))) return false;
  return true;
}

// Contact with a circle (or a flipper's end) slides along the tangent at
// the contact point for a short stretch, after which the ball flies again
// (and falls back if gravity holds it to the circle).
void set_circle_range(const StepContext& ctx, Touch& t, const Vec2& p) {
  t.origin = p;
  t.tangent = perp_left(t.normal);
  t.u_lo = -ctx.circle_slide_m;
  t.u_hi = ctx.circle_slide_m;
}

}  // namespace

// Surfaces the ball touches now with (nearly) no normal speed decide its
// mode: flight, sliding along one of them, or resting against two.
void classify(StepContext& ctx) {
  const table::Board& board = ctx.board;
  const GameState& state = ctx.state;
  const Vec2& gravity = ctx.gravity;
  const double r = ctx.r;
  ctx.mode = Mode::kFlight;
  ctx.contact = Touch{};
  ctx.m.a = gravity;
  Vec2& p = ctx.state.ball.position_m;
  Vec2& v = ctx.state.ball.velocity_mps;
  std::array<Touch, kMaxTouches> touches;
  int n = 0;
  // Only a touch without normal speed (round-off, or one that settle()
  // dropped after a bounce too weak to lift the ball by rest_height) is a
  // contact. A real normal speed, however small, is a bounce or a lift-off
  // for the impact search: two touches that each had a little would
  // otherwise stop a ball sliding fast through a flat V.
  auto keep = [&](const Touch& t) {
    if (std::abs(v.dot(t.normal)) > ctx.touch_speed_mps) return;
    if (n < kMaxTouches) touches[n++] = t;
  };
  const double touch = ctx.touch_m;
  CandidateLists here;
  here.lists[0] = ctx.options.use_grid ? ctx.obstacle_grid.candidates(p) : ctx.all_obstacles;
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
      if (!on_range(ctx, t, p, v)) return;
    } else {
      const Vec2 d = p - s.p0;
      const double dist = d.norm();
      t.gap = dist - s.radius_m - r;
      if (dist == 0.0 || std::abs(t.gap) > touch) return;
      t.normal = d / dist;
      set_circle_range(ctx, t, p);
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
      if (!on_range(ctx, t, p, v)) continue;
    } else {
      t.surface = Surface::kFlipperEnd;
      t.normal = d / dist;
      set_circle_range(ctx, t, p);
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
    ctx.mode = Mode::kRest;
    v = Vec2::Zero();
    ctx.m.a = Vec2::Zero();
    return;
  }
  Touch& contact = ctx.contact;
  contact = touches[slide];
  ctx.mode = Mode::kSlide;
  // Snap onto the surface and drop the normal speed (both below the
  // tolerances): the slide then keeps its distance exactly.
  p -= contact.gap * contact.normal;
  v -= v.dot(contact.normal) * contact.normal;
  ctx.m.a = gravity - gravity.dot(contact.normal) * contact.normal;
  const bool on_circle =
      contact.surface == Surface::kFlipperEnd ||
      (contact.surface == Surface::kObstacle && board.shapes[contact.index].kind == table::ShapeKind::kCircle);
  if (on_circle) set_circle_range(ctx, contact, p);
}

}  // namespace pinball::sim::event
