#include "board_loader_internal.h"

// One function per statement kind of docs/board-format.md, and the table that
// tells the driver which one reads a keyword.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>

namespace pinball::table::loader {

namespace {

constexpr std::string_view kObstacleAttributes = "rho friction score kick contact eat hidden bank name";

// Physical bounds, SI. A table is about 0.5 m x 1 m, its ball 27 mm across and
// at most a few m/s fast; the bounds are loose around that. They are here so
// that a typo (a missing `units mm`, an exponent too many) is refused at its
// line instead of making the simulator spin (dt 1e-12), allocate (a 1e9 m
// table) or overflow (a coordinate of 1e300).
constexpr double kMaxLength_m = 10.0;        // size W and H, every radius and flipper length
constexpr double kMaxCoordinate_m = 100.0;   // every position, either axis
constexpr double kMaxBallRadius_m = 0.1;     // a pinball is 13.5 mm
constexpr double kMinBallRadius_m = 0.001;   // below a millimetre the contact tolerances are the ball's size
constexpr double kMaxSpeed_mps = 100.0;      // SPEED_MAX, kick, kickout: twenty times a hard shot

/// Requires `v`, read in the file's length unit (per second with per = "/s",
/// ...), to be at most `max_si`; the message states the bound in the file's unit.
void require_at_most(const LoadState& state, const Reader& r, double v, const std::string& label, double max_si,
                     const std::string& per = "") {
  r.require(v * state.length_scale <= max_si, label, "at most " + fmt(max_si / state.length_scale) + " " +
                                                          unit_name(state) + per, v);
}

/// A position read in the file's unit, in metres; refused beyond kMaxCoordinate_m on either axis.
Vec2 position(const LoadState& state, const Reader& r, double x, double y, const std::string& label) {
  const Vec2 p = Vec2{x, y} * state.length_scale;
  if (!(std::abs(p.x()) <= kMaxCoordinate_m && std::abs(p.y()) <= kMaxCoordinate_m)) {
    r.fail(label + " must lie within " + fmt(kMaxCoordinate_m / state.length_scale) + " " + unit_name(state) +
           " of the origin on each axis, got (" + fmt(x) + ", " + fmt(y) + ")");
  }
  return p;
}

/// A reflectivity attribute: [0, kMaxRho].
double rho_attribute(const Reader& r, double fallback) {
  const double rho = r.attribute("rho", fallback);
  r.require(rho >= 0, "attribute rho", ">= 0", rho);
  r.require(rho <= kMaxRho, "attribute rho", "at most " + fmt(kMaxRho), rho);
  return rho;
}

// ---- header and constants ----

void header(LoadState&, const Reader& r) {
  const double version = r.numbers(0, {"VERSION"})[0];
  if (version != 1.0) r.fail("unsupported format version " + fmt(version) + " (this loader reads version 1)");
}

/// units/angles: a single word, before any length or angle.
std::string_view unit_word(const LoadState& state, const Reader& r, std::string_view a, std::string_view b) {
  std::string choices = "'";  // built piecewise: GCC 12 warns falsely on "literal" + std::string
  choices.append(a).append("' or '").append(b).append("'");
  if (r.arg_count() != 1) r.fail("expected one word, " + choices + ", got " + std::to_string(r.arg_count()));
  if (r.arg(0) != a && r.arg(0) != b) r.fail("expected " + choices + ", got '" + std::string(r.arg(0)) + "'");
  if (state.first_dimensioned_line != 0) {
    r.fail("must come before the first statement that uses a length or angle (line " +
           std::to_string(state.first_dimensioned_line) + ")");
  }
  return r.arg(0);
}
void units(LoadState& state, const Reader& r) {
  state.length_scale = unit_word(state, r, "m", "mm") == "mm" ? 1e-3 : 1.0;
}
void angles(LoadState& state, const Reader& r) {
  state.angle_scale = unit_word(state, r, "rad", "deg") == "deg" ? std::numbers::pi / 180.0 : 1.0;
}

void size(LoadState& state, const Reader& r) {
  const auto v = r.numbers(0, {"W", "H"});
  r.require(v[0] > 0, "field W (width)", "> 0", v[0]);
  r.require(v[1] > 0, "field H (height)", "> 0", v[1]);
  require_at_most(state, r, v[0], "field W (width)", kMaxLength_m);
  require_at_most(state, r, v[1], "field H (height)", kMaxLength_m);
  state.board.width_m = v[0] * state.length_scale;
  state.board.height_m = v[1] * state.length_scale;
}

void ball(LoadState& state, const Reader& r) {
  const auto v = r.numbers(0, {"R", "SPEED_MAX"});
  r.require(v[0] > 0, "field R (radius)", "> 0", v[0]);
  r.require(v[1] > 0, "field SPEED_MAX", "> 0", v[1]);
  require_at_most(state, r, v[0], "field R (radius)", kMaxBallRadius_m);
  r.require(v[0] * state.length_scale >= kMinBallRadius_m, "field R (radius)",
            "at least " + fmt(kMinBallRadius_m / state.length_scale) + " " + unit_name(state), v[0]);
  require_at_most(state, r, v[1], "field SPEED_MAX", kMaxSpeed_mps, "/s");
  state.board.ball.radius_m = v[0] * state.length_scale;
  state.board.ball.speed_max_mps = v[1] * state.length_scale;
}

void gravity(LoadState& state, const Reader& r) {
  const double g = r.numbers(0, {"G"})[0];
  r.require(g >= 0, "field G", ">= 0", g);
  require_at_most(state, r, g, "field G", kMaxGravity_mps2, "/s^2");
  state.board.gravity_mps2 = g * state.length_scale;
}

void dt(LoadState& state, const Reader& r) {
  const double dt = r.numbers(0, {"DT"})[0];
  r.require(dt > 0, "field DT (seconds)", "> 0", dt);
  r.require(dt >= kMinDt_s && dt <= kMaxDt_s, "field DT (seconds)", "in [" + fmt(kMinDt_s) + ", " + fmt(kMaxDt_s) + "]",
            dt);
  state.board.dt_s = dt;
}

void balls(LoadState& state, const Reader& r) {
  const double n = r.numbers(0, {"N"})[0];
  r.require(n >= 1 && n == std::floor(n), "field N (balls per game)", "an integer >= 1", n);
  r.require(n <= 1e6, "field N (balls per game)", "at most 1000000", n);
  state.board.balls_per_game = static_cast<int>(n);
}

void launcher(LoadState& state, const Reader& r) {
  const auto v = r.numbers(0, {"X", "Y"});
  Launcher& l = state.board.launcher;
  l.position = position(state, r, v[0], v[1], "fields X Y");
  l.pull = r.attribute("pull", 1.0);
  r.require(l.pull > 0 && l.pull <= 1, "attribute pull", "in (0, 1]", l.pull);
  l.noise_max = r.attribute("noise", 0.03);
  r.require(l.noise_max >= 0 && l.noise_max <= kMaxLaunchNoise, "attribute noise", "in [0, 0.5]", l.noise_max);
}

void start(LoadState& state, const Reader& r) {
  const auto v = r.numbers(0, {"X", "Y", "VX", "VY"});
  BallStart b;
  b.position = position(state, r, v[0], v[1], "fields X Y");
  require_at_most(state, r, std::hypot(v[2], v[3]), "speed of fields VX VY", kMaxSpeed_mps, "/s");
  b.velocity_mps = Vec2{v[2], v[3]} * state.length_scale;
  state.board.start = b;
}

void defaults(LoadState& state, const Reader& r) {
  if (r.arg_count() != 0) r.fail("takes only attributes (rho=R), got '" + std::string(r.arg(0)) + "'");
  state.default_rho = rho_attribute(r, state.default_rho);
}

int bank_index(const Board& board, std::string_view name) {
  for (std::size_t k = 0; k < board.banks.size(); ++k) {
    if (board.banks[k].name == name) return static_cast<int>(k);
  }
  return -1;
}

/// Points (score=, contact=, bonus=): 0 to kMaxPoints.
double points_attribute(const Reader& r, std::string_view key) {
  const double points = r.attribute(key, 0.0);
  const std::string label = "attribute " + std::string(key);
  r.require(points >= 0, label, ">= 0", points);
  r.require(points <= kMaxPoints, label, "at most " + fmt(kMaxPoints), points);
  return points;
}

void bank(LoadState& state, const Reader& r) {
  if (r.arg_count() != 1) r.fail("expected one NAME, got " + std::to_string(r.arg_count()));
  const std::string name(r.arg(0));
  if (bank_index(state.board, name) >= 0) r.fail("bank '" + name + "' is declared twice");
  if (!r.flag("bonus")) r.fail("needs bonus=POINTS");
  state.board.banks.push_back(Bank{name, points_attribute(r, "bonus"), {}});
  state.bank_lines.push_back(r.line());
}

// ---- obstacles ----

/// The statement's name (`name=`, or keyword@line), one per statement in the
/// whole board: an overlay and a trace name obstacles, flippers and sensors by it.
std::string statement_name(LoadState& state, const Reader& r) {
  std::string name =
      r.flag("name") ? std::string(r.text("name")) : std::string(r.keyword()) + "@" + std::to_string(r.line());
  // A trace writes names into CSV cells and joins a step's events with '|' ("hit:NAME|lost").
  if (name.find_first_of(",|\"") != std::string::npos) {
    r.fail("attribute name '" + name +
           "' may not contain ',', '|' or '\"': a trace's columns and events are split on them");
  }
  const auto [it, fresh] = state.names.emplace(name, r.line());
  if (!fresh) {
    r.fail("attribute name '" + name + "' is already line " + std::to_string(it->second) +
           "'s: an overlay names obstacles, flippers and sensors by it, so each must be the board's only one");
  }
  return name;
}

/// The attributes every shape of one obstacle statement shares.
Obstacle obstacle_attributes(LoadState& state, const Reader& r) {
  Obstacle o;
  o.rho = rho_attribute(r, state.default_rho);
  o.friction = r.attribute("friction", 0.0);
  r.require(o.friction >= 0, "attribute friction", ">= 0", o.friction);
  r.require(o.friction <= kMaxWallFriction, "attribute friction", "at most " + fmt(kMaxWallFriction), o.friction);
  o.action.score = points_attribute(r, "score");
  const double kick = r.attribute("kick", 0.0);
  r.require(kick >= 0, "attribute kick", ">= 0", kick);
  require_at_most(state, r, kick, "attribute kick", kMaxSpeed_mps, "/s");
  o.action.kick_mps = kick * state.length_scale;
  o.action.contact_score_per_s = points_attribute(r, "contact");
  o.action.eats_ball = r.flag("eat");
  o.visible = !r.flag("hidden");
  if (r.flag("bank")) {
    const std::string_view bank = r.text("bank");
    o.bank = bank_index(state.board, bank);
    if (o.bank < 0) r.fail("attribute bank names an undeclared bank '" + std::string(bank) + "'");
  }
  o.name = statement_name(state, r);
  o.source_line = r.line();
  return o;
}

void add(Board& board, const Shape& shape, const Obstacle& o) {
  if (o.bank >= 0) {
    board.banks[static_cast<std::size_t>(o.bank)].members.push_back(static_cast<int>(board.obstacles.size()));
  }
  board.shapes.push_back(shape);
  board.obstacles.push_back(o);
}

/// Two points, in file units, checked to differ; returned in metres.
std::pair<Vec2, Vec2> segment(const LoadState& state, const Reader& r, std::size_t first) {
  const auto v = r.numbers(first, {"X1", "Y1", "X2", "Y2"});
  if (v[0] == v[2] && v[1] == v[3]) r.fail("zero-length segment");
  return {position(state, r, v[0], v[1], "fields X1 Y1"), position(state, r, v[2], v[3], "fields X2 Y2")};
}

void line(LoadState& state, const Reader& r) {
  const auto [p0, p1] = segment(state, r, 0);
  add(state.board, make_line_shape(p0, p1), obstacle_attributes(state, r));
}

void wall(LoadState& state, const Reader& r) {
  const auto [p0, p1] = segment(state, r, 0);
  const Obstacle o = obstacle_attributes(state, r);
  add(state.board, make_line_shape(p0, p1), o);
  add(state.board, make_line_shape(p1, p0), o);
  add(state.board, make_circle_shape(p0, 0.0), o);
  add(state.board, make_circle_shape(p1, 0.0), o);
}

void point(LoadState& state, const Reader& r) {
  const auto v = r.numbers(0, {"X", "Y"});
  add(state.board, make_circle_shape(position(state, r, v[0], v[1], "fields X Y"), 0.0), obstacle_attributes(state, r));
}

void circle(LoadState& state, const Reader& r) {
  const auto v = r.numbers(0, {"X", "Y", "R"});
  r.require(v[2] >= 0, "field R (radius)", ">= 0", v[2]);
  require_at_most(state, r, v[2], "field R (radius)", kMaxLength_m);
  add(state.board, make_circle_shape(position(state, r, v[0], v[1], "fields X Y"), v[2] * state.length_scale),
      obstacle_attributes(state, r));
}

/// Vertices in file units, checked for zero-length edges (closed: also last -> first) and range.
std::vector<Vec2> path(const LoadState& state, const Reader& r, std::size_t min_count, bool closed) {
  const std::vector<Vec2> v = r.vertices(0, min_count);
  for (std::size_t i = 0; i < v.size(); ++i) (void)position(state, r, v[i].x(), v[i].y(), "vertex " + std::to_string(i + 1));
  const std::size_t edges = closed ? v.size() : v.size() - 1;
  for (std::size_t i = 0; i < edges; ++i) {
    const std::size_t j = (i + 1) % v.size();
    if (v[i] == v[j]) {
      r.fail("zero-length segment (vertices " + std::to_string(i + 1) + " and " + std::to_string(j + 1) + ")");
    }
  }
  return v;
}

void polyline(LoadState& state, const Reader& r) {
  const std::vector<Vec2> v = path(state, r, 2, false);
  const Obstacle o = obstacle_attributes(state, r);
  const bool two_sided = r.flag("two-sided");
  for (std::size_t i = 0; i + 1 < v.size(); ++i) {
    add(state.board, make_line_shape(v[i] * state.length_scale, v[i + 1] * state.length_scale), o);
    if (two_sided) add(state.board, make_line_shape(v[i + 1] * state.length_scale, v[i] * state.length_scale), o);
  }
  for (const Vec2& p : v) add(state.board, make_circle_shape(p * state.length_scale, 0.0), o);
}

void polygon(LoadState& state, const Reader& r) {
  // The crossing check is n² at worst (a comb of long edges side by side): a longer outline is a polyline.
  constexpr std::size_t kMaxPolygonVertices = 10000;
  std::vector<Vec2> v = path(state, r, 3, true);
  if (v.size() > kMaxPolygonVertices) {
    r.fail("a polygon has at most " + std::to_string(kMaxPolygonVertices) + " vertices, got " +
           std::to_string(v.size()));
  }
  double twice_area = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) twice_area += cross(v[i], v[(i + 1) % v.size()]);
  if (twice_area == 0.0) r.fail("the vertices enclose no area");
  // A crossing outline (a bow tie) has no outside: one lobe's edges would face in, and a ball
  // would be trapped in the solid.
  if (const auto [a, b] = polygon_self_crossing(v); a >= 0) {
    r.fail("edges " + std::to_string(a + 1) + " and " + std::to_string(b + 1) +
           " cross: a polygon's outline must not cross itself (draw each lobe as its own polygon)");
  }
  // Clockwise traversal puts each edge's left normal outside.
  if (twice_area > 0.0) std::reverse(v.begin(), v.end());
  const Obstacle o = obstacle_attributes(state, r);
  for (std::size_t i = 0; i < v.size(); ++i) {
    add(state.board, make_line_shape(v[i] * state.length_scale, v[(i + 1) % v.size()] * state.length_scale), o);
  }
  for (const Vec2& p : v) add(state.board, make_circle_shape(p * state.length_scale, 0.0), o);
  LoadState::Polygon solid{{}, o.name};
  for (const Vec2& p : v) solid.vertices_m.push_back(p * state.length_scale);
  state.polygons.push_back(std::move(solid));
}

// ---- flippers and sensors ----

void flipper(LoadState& state, const Reader& r) {
  Flipper f;
  const std::string_view side = r.arg_count() > 0 ? r.arg(0) : std::string_view{};
  const std::optional<Side> parsed = parse_side(side);
  if (!parsed) r.fail("field SIDE must be 'left' or 'right', got '" + std::string(side) + "'");
  f.side = *parsed;
  const auto v = r.numbers(1, {"PX", "PY", "LENGTH", "THETA_MIN", "THETA_MAX", "OMEGA"});
  r.require(v[2] > 0, "field LENGTH", "> 0", v[2]);
  require_at_most(state, r, v[2], "field LENGTH", kMaxLength_m);
  if (!(v[3] < v[4])) r.fail("field THETA_MIN (" + fmt(v[3]) + ") must be less than THETA_MAX (" + fmt(v[4]) + ")");
  // An elevation above the horizontal: past a quarter turn either way the blade points back over its pivot
  // (-1e9 .. 1e9, or a 360-degree stroke, had been accepted).
  const double quarter_turn = std::numbers::pi / 2.0 / state.angle_scale;  // in the file's unit
  const std::string quarter_text = fmt(quarter_turn) + (state.angle_scale == 1.0 ? " rad" : " deg");
  r.require(std::abs(v[3]) <= quarter_turn, "field THETA_MIN", "within +-" + quarter_text, v[3]);
  r.require(std::abs(v[4]) <= quarter_turn, "field THETA_MAX", "within +-" + quarter_text, v[4]);
  r.require(v[5] > 0, "field OMEGA", "> 0", v[5]);
  r.require(v[5] * state.angle_scale <= kMaxFlipperOmega_rad_s, "field OMEGA",
            "at most " + fmt(kMaxFlipperOmega_rad_s / state.angle_scale) +
                (state.angle_scale == 1.0 ? " rad/s" : " deg/s"),
            v[5]);
  f.pivot = position(state, r, v[0], v[1], "fields PX PY");
  f.length_m = v[2] * state.length_scale;
  f.theta_min_rad = v[3] * state.angle_scale;
  f.theta_max_rad = v[4] * state.angle_scale;
  f.omega_rad_s = v[5] * state.angle_scale;
  f.rho = rho_attribute(r, state.default_rho);
  f.mu = r.attribute("mu", 1.0);
  r.require(f.mu >= 0, "attribute mu", ">= 0", f.mu);
  r.require(f.mu <= kMaxFlipperMu, "attribute mu", "at most " + fmt(kMaxFlipperMu), f.mu);
  f.name = statement_name(state, r);
  f.source_line = r.line();
  state.board.flippers.push_back(f);
}

void finish_sensor(LoadState& state, const Reader& r, Sensor& s) {
  s.action.score = points_attribute(r, "score");
  s.action.eats_ball = r.flag("eat");
  s.name = statement_name(state, r);
  s.source_line = r.line();
  state.board.sensors.push_back(s);
}

void sensor(LoadState& state, const Reader& r) {
  Sensor s;
  const std::string_view shape = r.arg_count() > 0 ? r.arg(0) : std::string_view{};
  if (shape == "line") {
    const auto [p0, p1] = segment(state, r, 1);
    s.shape = make_line_shape(p0, p1);
  } else if (shape == "circle") {
    const auto v = r.numbers(1, {"X", "Y", "R"});
    r.require(v[2] >= 0, "field R (radius)", ">= 0", v[2]);
    require_at_most(state, r, v[2], "field R (radius)", kMaxLength_m);
    s.shape = make_circle_shape(position(state, r, v[0], v[1], "fields X Y"), v[2] * state.length_scale);
  } else {
    r.fail("field SHAPE must be 'line' or 'circle', got '" + std::string(shape) + "'");
  }
  s.kind = SensorKind::kProximity;
  finish_sensor(state, r, s);
}

void hole(LoadState& state, const Reader& r) {
  Sensor s;
  const auto v = r.numbers(0, {"X", "Y", "R"});
  r.require(v[2] > 0, "field R (radius)", "> 0", v[2]);
  require_at_most(state, r, v[2], "field R (radius)", kMaxLength_m);
  s.kind = SensorKind::kHole;
  s.shape = make_circle_shape(position(state, r, v[0], v[1], "fields X Y"), v[2] * state.length_scale);
  const bool eat = r.flag("eat");
  if (eat == r.flag("kickout")) r.fail("needs exactly one of 'eat' or 'kickout=VX,VY'");
  if (!eat) {
    const std::string_view k = r.text("kickout");
    const std::size_t comma = k.find(',');
    if (comma == std::string_view::npos) r.fail("attribute kickout must be VX,VY, got '" + std::string(k) + "'");
    s.has_kickout = true;
    const double vx = r.number(k.substr(0, comma), "attribute kickout VX");
    const double vy = r.number(k.substr(comma + 1), "attribute kickout VY");
    require_at_most(state, r, std::hypot(vx, vy), "attribute kickout speed", kMaxSpeed_mps, "/s");
    s.kickout_mps = Vec2{vx, vy} * state.length_scale;
    const double spread = r.attribute("spread", kDefaultKickoutSpread_rad / state.angle_scale);
    r.require(spread >= 0 && spread * state.angle_scale <= std::numbers::pi / 2, "attribute spread",
              "in [0, " + fmt(std::numbers::pi / 2 / state.angle_scale) + "]", spread);
    s.kickout_spread_rad = spread * state.angle_scale;
    s.kickout_noise = r.attribute("noise", kDefaultKickoutNoise);
    r.require(s.kickout_noise >= 0 && s.kickout_noise <= 0.5, "attribute noise", "in [0, 0.5]", s.kickout_noise);
  } else if (r.flag("spread") || r.flag("noise")) {
    r.fail("attributes spread and noise need kickout=VX,VY (an eating hole has no kickout to spread)");
  }
  finish_sensor(state, r, s);
}

}  // namespace

std::string unit_name(const LoadState& state) { return state.length_scale == 1.0 ? "m" : "mm"; }

std::string in_file_unit(const LoadState& state, double si, const std::string& per) {
  return fmt(si / state.length_scale) + " " + unit_name(state) + per;
}

const StatementKind* find_kind(std::string_view keyword) {
  static constexpr std::string_view kObstacleTwoSided = "rho friction score kick contact eat hidden bank name two-sided";
  static const StatementKind kKinds[] = {
      {"pinball-board", &header, true, false, ""},
      {"units", &units, true, false, ""},
      {"angles", &angles, true, false, ""},
      {"size", &size, true, true, ""},
      {"ball", &ball, true, true, ""},
      {"gravity", &gravity, true, true, ""},
      {"dt", &dt, true, false, ""},
      {"balls", &balls, true, false, ""},
      {"launcher", &launcher, true, true, "pull noise"},
      {"start", &start, true, true, ""},
      {"defaults", &defaults, false, false, "rho"},
      {"bank", &bank, false, false, "bonus"},
      {"line", &line, false, true, kObstacleAttributes},
      {"wall", &wall, false, true, kObstacleAttributes},
      {"point", &point, false, true, kObstacleAttributes},
      {"circle", &circle, false, true, kObstacleAttributes},
      {"polyline", &polyline, false, true, kObstacleTwoSided},
      {"polygon", &polygon, false, true, kObstacleAttributes},
      {"flipper", &flipper, false, true, "rho mu name"},
      {"sensor", &sensor, false, true, "score eat name"},
      {"hole", &hole, false, true, "score eat kickout spread noise name"},
  };
  for (const StatementKind& k : kKinds) {
    if (k.keyword == keyword) return &k;
  }
  return nullptr;
}

}  // namespace pinball::table::loader
