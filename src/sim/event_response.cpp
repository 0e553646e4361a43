// Collision response of the event stepper: the thesis response (collision.h,
// game_rules.h) at the event, then the rest threshold that ends a series of
// ever smaller bounces, and the flipper's stall and separation rules
// (docs/physics.md, "Contact mode", "Turning flippers").

#include <cmath>
#include <cstdint>

#include "event_context.h"
#include "pinball/sim/game_rules.h"
#include "pinball/sim/collision.h"

namespace pinball::sim::event {
namespace {

// A moving flipper stalls when the ball it hits is this close to a surface
// facing the flipper (the ball is pinched: a real coil stalls too).
constexpr double kPinchCosine = -0.1;

void clamp_speed(Vec2& v, double speed_max) {
  const double s2 = v.squaredNorm();
  if (s2 > speed_max * speed_max) v *= speed_max / std::sqrt(s2);
}

// A bounce whose normal speed would not lift the ball above rest_height
// against the acceleration pressing it to the surface leaves it touching.
void settle(StepContext& ctx, const Vec2& n, double surface_speed, const Vec2& accel) {
  Vec2& v = ctx.state.ball.velocity_mps;
  const double w = v.dot(n) - surface_speed;
  const double press = -accel.dot(n);
  if (press > 0.0 && w < std::sqrt(2.0 * press * ctx.options.rest_height_m)) v -= w * n;
}

void finish_response(StepContext& ctx) {
  if (ctx.options.speed_clamp) clamp_speed(ctx.state.ball.velocity_mps, ctx.board.ball.speed_max_mps);
}

// A ball jammed between moving flipper `pusher` and a surface facing it: an obstacle, or another
// flipper's blade (two flippers whose sweeps overlap had held the ball by the event guard alone).
bool pinched(const StepContext& ctx, std::int32_t pusher, const Vec2& n) {
  const table::Board& board = ctx.board;
  const Vec2& p = ctx.state.ball.position_m;
  const double r = ctx.r;
  const double near = ctx.options.contact_tolerance_m;
  bool found = false;
  for (std::size_t j = 0; j < board.flippers.size() && !found; ++j) {
    if (static_cast<std::int32_t>(j) == pusher) continue;
    const table::Flipper& f = board.flippers[j];
    const Vec2 tip = table::flipper_tip(f, ctx.state.flippers[j].theta_rad);
    const Vec2 d = p - (f.pivot + closest_param_on_segment(p, f.pivot, tip) * (tip - f.pivot));
    const double dist = d.norm();
    if (dist > 0.0 && dist - r <= near) found = (d / dist).dot(n) < kPinchCosine;
  }
  ctx.obstacles.for_each([&](std::int32_t i) {
    if (found || ctx.state.visible[i] != kVisible) return;
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

void hit_flipper(StepContext& ctx, const Next& next) {
  const table::Flipper& f = ctx.board.flippers[next.index];
  FlipperState& fs = ctx.state.flippers[next.index];
  Vec2& v = ctx.state.ball.velocity_mps;
  StepEvents& events = ctx.events;
  events.flipper = next.index;
  // Only a face that moves into the ball can pinch it: at the pivot it stands still (a ball resting in
  // the corner of a floor and the pivot had stalled the flipper for as long as it was held).
  const bool closing =
      fs.omega_rad_s != 0.0 &&
      flipper_point_velocity(f, fs.theta_rad, fs.omega_rad_s, next.point).dot(next.normal) > 0.0;
  if (closing && pinched(ctx, next.index, next.normal)) {
    fs.omega_rad_s = 0.0;  // stalled until the next step's command
    events.flags |= StepEvents::kFlipperStall;
  }
  const Vec2 accel = ctx.m.a;
  v = flipper_response(f, fs.theta_rad, fs.omega_rad_s, next.point, next.normal, v);
  if (fs.omega_rad_s != 0.0) {
    // The face carries the ball: it leaves at least a little faster than
    // the face at the contact, or the face would strike it again at once.
    const double face = flipper_point_velocity(f, fs.theta_rad, fs.omega_rad_s, next.point).dot(next.normal);
    const double rel = v.dot(next.normal) - face;
    if (rel < ctx.separation_speed_mps) v += (ctx.separation_speed_mps - rel) * next.normal;
    events.flags |= face > 0.0 ? StepEvents::kFlipperPush : StepEvents::kHitFlipper;
  } else {
    settle(ctx, next.normal, 0.0, accel);
    events.flags |= StepEvents::kHitFlipper;
  }
  finish_response(ctx);
}

}  // namespace

void handle(StepContext& ctx, const Next& next) {
  const table::Board& board = ctx.board;
  GameState& state = ctx.state;
  switch (next.kind) {
    case Kind::kHorizon:
    case Kind::kEdge:  // the next classification lets it fly
      return;
    case Kind::kFlipperStop: {
      const table::Flipper& f = board.flippers[next.index];
      FlipperState& fs = state.flippers[next.index];
      fs.theta_rad = fs.omega_rad_s > 0.0 ? f.theta_max_rad : f.theta_min_rad;
      fs.omega_rad_s = 0.0;
      return;
    }
    case Kind::kSensor:
      state.sensor_inside[next.index] = 1;
      rules::fire_sensor(board, state, next.index, ctx.events);
      // A kickout faster than the clamp is clamped, as the thesis stepper's next step does: it had flown
      // at 100 m/s under a 5 m/s clamp until its first collision.
      if (state.ball_in_play) finish_response(ctx);
      return;
    case Kind::kObstacle: {
      const Vec2 accel = ctx.m.a;
      rules::hit_obstacle(board, state, next.index, next.normal, ctx.events, ctx.r + ctx.touch_m);
      if (!state.ball_in_play) return;
      if (board.obstacles[next.index].action.kick_mps == 0.0 && state.visible[next.index] == kVisible) {
        settle(ctx, next.normal, 0.0, accel);
      }
      finish_response(ctx);
      return;
    }
    case Kind::kFlipper:
      hit_flipper(ctx, next);
      return;
  }
}

}  // namespace pinball::sim::event
