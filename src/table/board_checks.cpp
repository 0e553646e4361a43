#include "board_loader_internal.h"

// The checks that need the whole file, run after its last statement: a Board is
// returned only when all of them pass.

#include <stdexcept>

#include "pinball/table/board_loader.h"

namespace pinball::table::loader {

namespace {

constexpr std::string_view kRequired[] = {"pinball-board", "size", "ball", "gravity", "dt", "balls", "launcher"};

// Why a ball put at `p` (the launch position, the start, a hole's kick-out) would begin inside
// something: off the table, overlapping an obstacle or a flipper down, or inside a polygon's
// solid; "" when it is clear.
std::string ball_placement_problem(const LoadState& state, const Vec2& p) {
  const Board& board = state.board;
  if (!(p.x() >= 0.0 && p.x() <= board.width_m && p.y() >= 0.0 && p.y() <= board.height_m)) {
    return "lies outside the table (0..W, 0..H = " + fmt(board.width_m / state.length_scale) + ", " +
           in_file_unit(state, board.height_m) + ")";
  }
  if (const std::optional<BallOverlap> o = ball_overlap(board, p)) {
    return "overlaps " + o->what + " (distance " + in_file_unit(state, o->distance_m) + ", ball radius " +
           in_file_unit(state, board.ball.radius_m) + ")";
  }
  for (const LoadState::Polygon& solid : state.polygons) {
    if (point_in_polygon(p, solid.vertices_m)) return "lies inside polygon '" + solid.name + "'";
  }
  return "";
}

// What takes a ball placed at `p` at once: a hole its centre lies in ("hole 'name'"), or an eating
// sensor it touches ("eating sensor 'name'"); "" for none.
std::string sensor_taking_ball_at(const Board& board, const Vec2& p) {
  for (const Sensor& sensor : board.sensors) {
    if (sensor.kind == SensorKind::kHole && (p - sensor.shape.p0).norm() <= sensor.shape.radius_m) {
      return "hole '" + sensor.name + "'";
    }
    if (sensor.kind == SensorKind::kProximity && sensor.action.eats_ball &&
        distance_to_shape(sensor.shape, p) <= board.ball.radius_m) {
      return "eating sensor '" + sensor.name + "'";
    }
  }
  return "";
}

void check_launcher_clear(const LoadState& state) {
  const std::string problem = ball_placement_problem(state, state.board.launcher.position);
  if (!problem.empty()) {
    throw BoardError(state.file, state.seen.at("launcher"), "launcher: ball at the launch position " + problem);
  }
  // Every ball would be taken at its first step (by an eater: each lost at once, scoring 0).
  if (const std::string taker = sensor_taking_ball_at(state.board, state.board.launcher.position); !taker.empty()) {
    throw BoardError(state.file, state.seen.at("launcher"),
                     "launcher: ball at the launch position starts inside " + taker);
  }
}

// A hole that kicks the ball out puts it at the hole's centre: clear of everything, or the ball
// starts inside a post or a wall (found: through a closed box, in the twin).
void check_kickouts_clear(const LoadState& state) {
  for (const Sensor& hole : state.board.sensors) {
    if (hole.kind != SensorKind::kHole || !hole.has_kickout) continue;
    const std::string problem = ball_placement_problem(state, hole.shape.p0);
    if (!problem.empty()) {
      throw BoardError(state.file, hole.source_line, "hole: the ball kicked out at its centre " + problem);
    }
  }
}

/// The board's own pull must launch the ball out of the launcher: a launch
/// slower than min_launch_speed_mps stops within one radius of the launch
/// point and is relaunched at its apex for ever. A board with `start`
/// never launches.
void check_launch_speed(const LoadState& state) {
  const Board& board = state.board;
  if (board.start) return;
  const double slowest = slowest_launch_mps(board, board.launcher.pull);
  const double needed = min_launch_speed_mps(board);
  if (slowest >= needed) return;
  throw BoardError(state.file, state.seen.at("launcher"),
                   "launcher: attribute pull=" + fmt(board.launcher.pull) + " launches as slowly as " +
                       in_file_unit(state, slowest, "/s") + " (pull x (1 - noise) x SPEED_MAX), below the " +
                       in_file_unit(state, needed, "/s") +
                       " the ball needs to rise above its own radius against G (sqrt(2 G R + (" +
                       in_file_unit(state, kLauncherStillSpeed_mps, "/s") +
                       ")^2) + G dt): it would be relaunched at its apex for ever");
}

/// The start must put the ball on the table, clear of every obstacle, flipper
/// and hole, and not where it would count as resting in the launcher.
void check_start(const LoadState& state) {
  const Board& board = state.board;
  if (!board.start) return;
  const Vec2 p = board.start->position;
  const Vec2 v = board.start->velocity_mps;
  const double r = board.ball.radius_m;
  const int line = state.seen.at("start");
  const auto fail = [&](const std::string& what) { throw BoardError(state.file, line, "start: " + what); };
  if (!(v.norm() <= board.ball.speed_max_mps)) {
    fail("speed of fields VX VY (" + in_file_unit(state, v.norm(), "/s") + ") exceeds the ball's SPEED_MAX (" +
         in_file_unit(state, board.ball.speed_max_mps, "/s") + ")");
  }
  if (const std::string problem = ball_placement_problem(state, p); !problem.empty()) {
    fail("ball at fields X Y (" + fmt(p.x() / state.length_scale) + ", " + fmt(p.y() / state.length_scale) + ") " +
         unit_name(state) + " " + problem);
  }
  if (const std::string taker = sensor_taking_ball_at(board, p); !taker.empty()) {
    fail("ball at fields X Y starts inside " + taker);
  }
  if ((p - board.launcher.position).norm() < r && v.norm() < min_launch_speed_mps(board)) {
    fail("a ball at fields X Y this slow (" + in_file_unit(state, v.norm(), "/s") +
         ") counts as resting in the launcher and "
         "would be served again for ever");
  }
}

}  // namespace

// Every piece within a few cm of the playfield: a coordinate typed in the wrong unit or with a
// digit too many (x = 5000 mm on a 510 mm table) had been accepted up to 100 m from the origin.
void check_pieces_on_playfield(const LoadState& state) {
  const Board& board = state.board;
  const auto require_near = [&](const Vec2& p, int line, const std::string& what) {
    if (near_playfield(board, p)) return;
    throw BoardError(state.file, line,
                     what + " at (" + fmt(p.x() / state.length_scale) + ", " + fmt(p.y() / state.length_scale) +
                         ") " + unit_name(state) + " lies " + off_playfield_text(board));
  };
  for (std::size_t i = 0; i < board.shapes.size(); ++i) {
    const Shape& shape = board.shapes[i];
    const std::string what = "obstacle '" + board.obstacles[i].name + "'";
    require_near(shape.p0, board.obstacles[i].source_line, what);
    if (shape.kind == ShapeKind::kLine) require_near(shape.p1, board.obstacles[i].source_line, what);
  }
  for (const Sensor& sensor : board.sensors) {
    const std::string what = "sensor '" + sensor.name + "'";
    require_near(sensor.shape.p0, sensor.source_line, what);
    if (sensor.shape.kind == ShapeKind::kLine) require_near(sensor.shape.p1, sensor.source_line, what);
  }
  for (const Flipper& f : board.flippers) require_near(f.pivot, f.source_line, "the pivot of flipper '" + f.name + "'");
}

void check_whole_file(const LoadState& state) {
  const Board& board = state.board;
  for (const std::string_view required : kRequired) {
    if (!state.seen.contains(std::string(required))) {
      throw BoardError(state.file, 0, "missing required '" + std::string(required) + "' statement");
    }
  }
  for (std::size_t k = 0; k < board.banks.size(); ++k) {
    if (board.banks[k].members.empty()) {
      throw BoardError(state.file, state.bank_lines[k],
                       "bank: bank '" + board.banks[k].name + "' has no members (no obstacle says bank=" +
                           board.banks[k].name + ")");
    }
  }
  for (const Flipper& f : board.flippers) {
    if (const std::string problem = flipper_tip_speed_problem(board, f); !problem.empty()) {
      throw BoardError(state.file, f.source_line, "flipper: " + problem);
    }
    // check_flipper_time_step's rule, said in the file's unit.
    const double chord = flipper_step_chord_m(f, board.dt_s);
    if (!(chord < board.ball.radius_m)) {
      Board one;
      one.ball = board.ball;
      one.flippers.push_back(f);
      throw BoardError(state.file, f.source_line,
                       "flipper: flipper '" + f.name + "': l*sin(omega*dt/2) = " + in_file_unit(state, chord) +
                           " is not below the ball radius " + in_file_unit(state, board.ball.radius_m) +
                           " at dt = " + fmt(board.dt_s) + " s (largest stable dt is " +
                           fmt(max_stable_dt_s(one)) + " s)");
    }
  }
  check_pieces_on_playfield(state);
  check_launcher_clear(state);
  check_launch_speed(state);
  check_start(state);
  check_kickouts_clear(state);
}

}  // namespace pinball::table::loader
