#include "pinball/sim/event_stepper.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>

#include "event_context.h"
#include "pinball/sim/game_rules.h"

namespace pinball::sim {
namespace {

// More events than this inside one step is a ball caught in an endless
// sequence (a pinch the stall rule missed, a carried ball): it rests for the
// rest of the step (docs/physics.md, "The event stepper").
constexpr int kMaxEventsPerStep = 256;
// The same for searches that stop short of their horizon (a turning flipper's certified search out of
// iterations): so many in one step is a search that no longer gets anywhere.
constexpr int kMaxPartialHorizonsPerStep = 1024;

// Turns the flippers with nothing else moving (no ball in play, or the guard):
// one that reaches its stop stays there.
void advance_flippers(event::StepContext& ctx, double dt) {
  for (std::size_t i = 0; i < ctx.board.flippers.size(); ++i) {
    FlipperState& fs = ctx.state.flippers[i];
    if (fs.omega_rad_s == 0.0) continue;
    const table::Flipper& f = ctx.board.flippers[i];
    fs.theta_rad = std::clamp(fs.theta_rad + fs.omega_rad_s * dt, f.theta_min_rad, f.theta_max_rad);
    if (fs.theta_rad == f.theta_min_rad || fs.theta_rad == f.theta_max_rad) fs.omega_rad_s = 0.0;
  }
}

// Moves ball and flippers to the event. A flipper's stop is an event of its
// own, so the clamp only catches round-off.
void advance(event::StepContext& ctx, double dt) {
  if (dt > 0.0) {
    ctx.state.ball.position_m = ctx.m.pos(dt);
    ctx.state.ball.velocity_mps = ctx.m.vel(dt);
    for (std::size_t i = 0; i < ctx.board.flippers.size(); ++i) {
      FlipperState& fs = ctx.state.flippers[i];
      if (fs.omega_rad_s == 0.0) continue;
      const table::Flipper& f = ctx.board.flippers[i];
      fs.theta_rad = std::clamp(fs.theta_rad + fs.omega_rad_s * dt, f.theta_min_rad, f.theta_max_rad);
    }
  }
}

// The guard: the ball rests where it is for the rest of the step, and a
// flipper that could reach it stalls.
void give_up(event::StepContext& ctx, double remaining_s) {
  ctx.state.ball.velocity_mps = Vec2::Zero();
  const Vec2& p = ctx.state.ball.position_m;
  for (std::size_t i = 0; i < ctx.board.flippers.size(); ++i) {
    const table::Flipper& f = ctx.board.flippers[i];
    FlipperState& fs = ctx.state.flippers[i];
    if (fs.omega_rad_s == 0.0) continue;
    if ((p - f.pivot).norm() <= f.length_m + ctx.r + ctx.touch_m) {
      fs.omega_rad_s = 0.0;
      ctx.events.flags |= StepEvents::kFlipperStall;
      ctx.events.flipper = static_cast<std::int32_t>(i);
    }
  }
  advance_flippers(ctx, remaining_s);
}

// The step as a chain of stages: classify the contacts, choose a horizon,
// search it for the earliest event, advance to it, respond; until the
// horizon is used up.
void run_events(event::StepContext& ctx, double horizon_s) {
  using event::Kind;
  using event::Mode;
  const table::Board& board = ctx.board;
  double t = 0.0;
  int count = 0;
  int partial = 0;
  while (t < horizon_s) {
    if (!ctx.state.ball_in_play) {
      advance_flippers(ctx, horizon_s - t);
      return;
    }
    event::classify(ctx);
    const double h = event::choose_horizon(ctx, horizon_s - t);
    event::Next next;
    next.t = h;
    event::find_flipper_stops(ctx, next);
    if (ctx.mode != Mode::kRest) {
      event::find_obstacle_impact(ctx, next);
      event::find_edge(ctx, next);
      if (!board.sensors.empty()) event::find_sensor_entry(ctx, next);
    }
    if (!board.flippers.empty()) event::find_flipper_impact(ctx, next);
    advance(ctx, next.t);
    // The whole rest of the step only when the search covered it: one that stopped short (the flipper's
    // search) had been taken for the step's end, and the ball moved 1e-13 s per step.
    const bool to_the_end = next.kind == Kind::kHorizon && next.t == h && h == horizon_s - t;
    t = to_the_end ? horizon_s : t + next.t;
    if (next.kind == Kind::kHorizon) {
      if (next.t < h && ++partial > kMaxPartialHorizonsPerStep) {
        give_up(ctx, horizon_s - t);
        return;
      }
      continue;
    }
    ++ctx.state.events;
    event::handle(ctx, next);
    if (++count > kMaxEventsPerStep) {
      give_up(ctx, horizon_s - t);
      return;
    }
  }
}

}  // namespace

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
  // At a circle of radius ρ the ball's centre moves on one of R = ρ + r, whose
  // tangent leaves it by circle_slide²/2R: R = r (a point, the tightest) bounds
  // the lift for every circle, and a hundredth of the rest height keeps the
  // slide's error far below it.
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
  event::StepContext ctx{.board = board_,
                         .options = options_,
                         .obstacle_grid = obstacle_grid_,
                         .sensor_grid = sensor_grid_,
                         .all_obstacles = all_obstacles_,
                         .all_sensors = all_sensors_,
                         .length_tol_m = length_tol_m_,
                         .touch_m = touch_m_,
                         .touch_speed_mps = touch_speed_mps_,
                         .separation_speed_mps = separation_speed_mps_,
                         .circle_slide_m = circle_slide_m_,
                         .r = board_.ball.radius_m,
                         .gravity = Vec2(0.0, -board_.gravity_mps2),
                         .state = state,
                         .events = events};
  run_events(ctx, options_.dt_s);

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
