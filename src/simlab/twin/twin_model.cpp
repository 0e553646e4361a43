#include "pinball/simlab/twin_model.h"

#include <cmath>
#include <iomanip>
#include <numbers>
#include <string>
#include <utility>
#include <vector>
#include <sstream>
#include <stdexcept>

#include "pinball/core/check.h"
#include "pinball/core/format.h"

namespace pinball::simlab {
namespace {

// Numbers in the MJCF at full precision (a round trip through text must not move a wall).
struct Xml {
  std::ostringstream out;
  Xml() { out << std::setprecision(17); }
};

std::string solref(const TwinSolref& c) {
  std::ostringstream s;
  s << std::setprecision(17) << c.timeconst_s << ' ' << c.dampratio;
  return s.str();
}

// Every surface the ball meets decides its contact (priority 1 over the ball's 0):
// its friction, its softness, its restitution (via the damping ratio).
void surface_attributes(std::ostream& out, double friction, const std::string& sol) {
  out << " contype=\"0\" conaffinity=\"1\" priority=\"1\" condim=\"3\" friction=\"" << friction
      << " 0 0\" solref=\"" << sol << "\" solimp=\"0.99 0.99 0.001\"";
}

bool same_point(const Vec2& a, const Vec2& b) { return (a - b).norm() <= 1e-9; }

}  // namespace

std::vector<std::vector<int>> twin_obstacle_groups(const table::Board& board) {
  const std::size_t n = board.shapes.size();
  std::vector<int> group_of(n, -1);
  std::vector<std::vector<int>> groups;
  // Lines first: a line and its reverse make one bar.
  for (std::size_t i = 0; i < n; ++i) {
    const table::Shape& a = board.shapes[i];
    if (a.kind != table::ShapeKind::kLine || group_of[i] >= 0) continue;
    group_of[i] = static_cast<int>(groups.size());
    groups.push_back({static_cast<int>(i)});
    for (std::size_t j = i + 1; j < n; ++j) {
      const table::Shape& b = board.shapes[j];
      if (b.kind == table::ShapeKind::kLine && group_of[j] < 0 && same_point(a.p0, b.p1) && same_point(a.p1, b.p0)) {
        group_of[j] = group_of[i];
        groups.back().push_back(static_cast<int>(j));
        break;
      }
    }
  }
  // A point at a line's end joins it (bars first: their round ends are points).
  for (std::size_t i = 0; i < n; ++i) {
    const table::Shape& p = board.shapes[i];
    if (p.kind != table::ShapeKind::kCircle) continue;
    int joined = -1;
    if (p.radius_m == 0.0) {
      for (int pass = 0; pass < 2 && joined < 0; ++pass) {
        for (std::size_t g = 0; g < groups.size() && joined < 0; ++g) {
          const bool bar = groups[g].size() > 1;
          if (bar != (pass == 0)) continue;
          const table::Shape& line = board.shapes[static_cast<std::size_t>(groups[g].front())];
          if (same_point(p.p0, line.p0) || same_point(p.p0, line.p1)) joined = static_cast<int>(g);
        }
      }
    }
    if (joined >= 0) {
      groups[static_cast<std::size_t>(joined)].push_back(static_cast<int>(i));
    } else {
      groups.push_back({static_cast<int>(i)});
    }
  }
  return groups;
}

TwinMaterial twin_material(const table::Board& board, int index, const TwinParams& params) {
  const table::Obstacle& o = board.obstacles[static_cast<std::size_t>(index)];
  if (o.action.kick_mps > 0.0 || o.rho >= params.lively_rho.value) return TwinMaterial::kRubber;
  if (o.rho < params.dead_rho.value) return TwinMaterial::kDead;
  const table::Shape& s = board.shapes[static_cast<std::size_t>(index)];
  // Posts and rings are rubber whatever the board's ρ; a pin at a guide's corner is the guide.
  if (s.kind == table::ShapeKind::kCircle && s.radius_m > 0.0) return TwinMaterial::kRubber;
  return TwinMaterial::kRail;
}

double twin_slope_rad(const table::Board& board, const TwinParams& params) {
  const double s = board.gravity_mps2 / params.gravity_mps2.value;
  check_input(s > 0.0 && s < std::sin(std::numbers::pi / 4.0), "twin: " + board.source,
              "g along the table (" + std::to_string(board.gravity_mps2) +
                  " m/s^2) must give a slope between 0 and 45 degrees under gravity_mps2 (" +
                  std::to_string(params.gravity_mps2.value) + ")");
  return std::asin(s);
}

void check_board_fits_the_twin(const table::Board& board, const TwinParams& params, double timestep_s) {
  const std::string context = "twin: " + board.source;
  const double r = board.ball.radius_m;
  auto mm = [](double m) { return format_number(m * 1e3) + " mm"; };
  check_input(2.0 * r < params.glass_height_m.value, context,
              "a ball " + mm(2.0 * r) + " across does not fit under the twin's glass, " +
                  mm(params.glass_height_m.value) + " above the playfield (glass_height_m)");

  // Its solids are thicker than the board's lines: a 2 mm bar, a 6 mm flipper rubber. A ball passes
  // through one when its centre crosses the solid's middle in a step, or sinks that deep into the soft
  // contact (about v·T/π in a bounce of T); half that depth is kept as margin.
  double fastest_mps = board.ball.speed_max_mps;
  for (const table::Sensor& sensor : board.sensors) {
    if (sensor.has_kickout) fastest_mps = std::max(fastest_mps, sensor.kickout_mps.norm());
  }
  const double hold_m = r + std::min(params.pin_radius_m.value, params.flipper_radius_m.value);
  const double step_m = fastest_mps * timestep_s;
  const double sink_m = fastest_mps * params.contact_duration_s.value / std::numbers::pi;
  check_input(step_m < hold_m && sink_m < 0.5 * hold_m, context,
              "a ball of radius " + mm(r) + " at " + format_number(fastest_mps) +
                  " m/s (SPEED_MAX, or a kickout) would pass through the twin's thinnest solid: it moves " +
                  mm(step_m) + " a step and sinks about " + mm(sink_m) + " into a contact; the twin holds a ball " +
                  "that moves less than " + mm(hold_m) + " a step (its radius and half the solid) and sinks less "
                  "than " + mm(0.5 * hold_m));

  // Where a ball is put (the chute, a start, a kickout) must be clear of those solids too: the loader
  // measured it against the board's lines, and a ball served 1 µm from a wall had overlapped its bar
  // and been shot off at 2 m/s.
  std::vector<std::pair<std::string, Vec2>> places;
  if (board.start) {
    places.emplace_back("the start", board.start->position);
  } else {
    places.emplace_back("the launcher", board.launcher.position);
  }
  for (const table::Sensor& sensor : board.sensors) {
    if (sensor.has_kickout) places.emplace_back("kickout '" + sensor.name + "'", sensor.shape.p0);
  }
  const double pin = params.pin_radius_m.value;
  const double rf = params.flipper_radius_m.value;
  for (const auto& served : places) {
    const std::string& place = served.first;  // named, not bound: clang's lambdas take no structured binding
    const Vec2& p = served.second;
    auto refuse = [&](const std::string& solid, double gap_m) {
      check_input(gap_m >= 0.0, context,
                  "the ball at " + place + " would overlap " + solid + " by " + mm(-gap_m) +
                      " (the twin's solids are thicker than the board's lines: bars " + mm(pin) +
                      " about the line, pins and posts at least " + mm(pin) + " in radius, flipper rubbers " +
                      mm(rf) + "); move it clear");
    };
    for (const std::vector<int>& members : twin_obstacle_groups(board)) {
      const table::Shape& s = board.shapes[static_cast<std::size_t>(members.front())];
      const std::string& name = board.obstacles[static_cast<std::size_t>(members.front())].name;
      const bool bar = members.size() > 1 &&
                       board.shapes[static_cast<std::size_t>(members[1])].kind == table::ShapeKind::kLine;
      if (s.kind == table::ShapeKind::kLine && !bar) continue;  // its solid lies behind the line
      if (s.kind == table::ShapeKind::kLine) {
        refuse("the bar of wall '" + name + "'", distance_point_segment(p, s.p0, s.p1) - r - pin);
      } else {
        refuse("post '" + name + "'", (p - s.p0).norm() - r - std::max(s.radius_m, pin));
      }
    }
    for (const table::Flipper& f : board.flippers) {
      refuse("flipper '" + f.name + "' at rest",
             distance_point_segment(p, f.pivot, table::flipper_tip(f, f.theta_min_rad)) - r - rf);
    }
  }
}

TwinModelText twin_model_text(const table::Board& board, const TwinParams& params, double timestep_s,
                              const TwinContacts& contacts) {
  check_twin_params(params);
  check_board_fits_the_twin(board, params, timestep_s);
  TwinModelText model;
  model.slope_rad = twin_slope_rad(board, params);
  const double g = params.gravity_mps2.value;
  const double r = board.ball.radius_m;
  const std::string context = "twin: " + board.source;

  Xml xml;
  std::ostream& out = xml.out;
  out << "<mujoco model=\"pinball twin\">\n"
      << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
      << "  <option timestep=\"" << timestep_s << "\" gravity=\"0 " << -g * std::sin(model.slope_rad) << ' '
      << -g * std::cos(model.slope_rad) << "\" integrator=\"Euler\" cone=\"elliptic\"/>\n"
      << "  <size nconmax=\"64\" njmax=\"512\"/>\n"
      << "  <worldbody>\n";

  // The playfield (rolling and torsional friction live here: the ball rolls on it) and the glass.
  out << "    <geom name=\"playfield\" type=\"plane\" size=\"0 0 1\" contype=\"0\" conaffinity=\"1\" priority=\"1\""
      << " condim=\"6\" friction=\"" << params.playfield_friction.value << ' '
      << params.playfield_torsional_friction_m.value << ' ' << params.playfield_rolling_friction_m.value
      << "\" solref=\"" << solref(contacts.playfield) << "\" solimp=\"0.99 0.99 0.001\"/>\n";
  model.geoms.push_back({TwinGeom::kPlayfield, -1, {}, false});
  out << "    <geom name=\"glass\" type=\"plane\" size=\"0 0 1\" pos=\"0 0 " << params.glass_height_m.value
      << "\" quat=\"0 1 0 0\"";
  surface_attributes(out, params.rail_friction.value, solref(contacts.playfield));
  out << "/>\n";
  model.geoms.push_back({TwinGeom::kGlass, -1, {}, false});

  const double h = params.rail_height_m.value;
  const double t = params.rail_thickness_m.value;
  const double pin = params.pin_radius_m.value;
  for (const std::vector<int>& members : twin_obstacle_groups(board)) {
    const int first = members.front();
    const table::Shape& s = board.shapes[static_cast<std::size_t>(first)];
    const TwinMaterial material = twin_material(board, first, params);
    const TwinSolref& contact = material == TwinMaterial::kRubber ? contacts.rubber
                                : material == TwinMaterial::kDead ? contacts.dead
                                                                  : contacts.rail;
    const double friction = material == TwinMaterial::kRubber ? params.rubber_friction.value
                                                              : params.rail_friction.value;
    TwinGeom geom{TwinGeom::kObstacle, -1, members, false};
    out << "    <geom name=\"o" << model.geoms.size() << "\"";
    const bool bar = members.size() > 1 && board.shapes[static_cast<std::size_t>(members[1])].kind ==
                                               table::ShapeKind::kLine;
    if (s.kind == table::ShapeKind::kLine && !bar) {
      // A one-sided line: the box's front face is the line; its solid lies behind the normal.
      const Vec2 d = s.p1 - s.p0;
      const Vec2 centre = 0.5 * (s.p0 + s.p1) - 0.5 * t * s.normal;
      out << " type=\"box\" size=\"" << 0.5 * d.norm() << ' ' << 0.5 * t << ' ' << 0.5 * h << "\" pos=\""
          << centre.x() << ' ' << centre.y() << ' ' << 0.5 * h << "\" euler=\"0 0 " << std::atan2(d.y(), d.x()) << "\"";
      geom.one_sided = true;
    } else if (s.kind == table::ShapeKind::kLine) {
      // Both sides of a line: a bar as tall as a rail, centred on the line.
      const Vec2 d = s.p1 - s.p0;
      const Vec2 centre = 0.5 * (s.p0 + s.p1);
      out << " type=\"box\" size=\"" << 0.5 * d.norm() << ' ' << pin << ' ' << 0.5 * h << "\" pos=\"" << centre.x()
          << ' ' << centre.y() << ' ' << 0.5 * h << "\" euler=\"0 0 " << std::atan2(d.y(), d.x()) << "\"";
    } else {
      // A post or a pin: a vertical capsule. Its side is a cylinder's, and
      // MuJoCo 2.2 collides a sphere with a capsule in closed form (with a
      // cylinder only through its general convex search).
      const double radius = std::max(s.radius_m, pin);
      out << " type=\"capsule\" size=\"" << radius << "\" fromto=\"" << s.p0.x() << ' ' << s.p0.y() << " 0 "
          << s.p0.x() << ' ' << s.p0.y() << ' ' << h << "\"";
    }
    surface_attributes(out, friction, solref(contact));
    out << "/>\n";
    model.geoms.push_back(std::move(geom));
  }

  // Flippers: a hinge about the playfield's normal (−z for a right flipper, so
  // that the joint angle is the board's θ on both sides), the bat a capsule
  // at the ball's equator, the stops the joint's range.
  const double rf = params.flipper_radius_m.value;
  const double mf = params.flipper_mass_kg.value;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const table::Flipper& f = board.flippers[i];
    const std::string name = f.name.empty() ? "flipper " + std::to_string(i) : f.name;
    check_input(f.length_m > 2.0 * rf, context, "flipper '" + name + "' is shorter than its rubber is thick");
    check_input(f.theta_max_rad - f.theta_min_rad < std::numbers::pi, context,
                "flipper '" + name + "' sweeps half a turn or more");
    const double dir = f.side == table::Side::kLeft ? 1.0 : -1.0;
    const double arm = 0.5 * f.length_m;
    const double izz = params.flipper_inertia_kgm2.value - mf * arm * arm;  // about the centre of mass
    check_input(izz > 0.0, context,
                "flipper_inertia_kgm2 must exceed the bat's mass at half its length (flipper '" + name + "')");
    out << "    <body name=\"flipper" << i << "\" pos=\"" << f.pivot.x() << ' ' << f.pivot.y() << ' ' << r << "\">\n"
        << "      <joint name=\"flipper" << i << "\" type=\"hinge\" axis=\"0 0 " << dir << "\" limited=\"true\" range=\""
        << f.theta_min_rad << ' ' << f.theta_max_rad << "\" damping=\"" << params.flipper_damping_nms.value
        << "\" solreflimit=\"" << solref(contacts.end_stop) << "\" solimplimit=\"0.99 0.99 0.001\"/>\n"
        << "      <inertial pos=\"" << dir * arm << " 0 0\" mass=\"" << mf << "\" diaginertia=\"" << izz << ' ' << izz
        << ' ' << izz << "\"/>\n"
        << "      <geom name=\"f" << i << "\" type=\"capsule\" fromto=\"0 0 0 " << dir * f.length_m << " 0 0\" size=\""
        << rf << "\"";
    surface_attributes(out, params.flipper_friction.value, solref(contacts.flipper));
    out << "/>\n    </body>\n";
    model.geoms.push_back({TwinGeom::kFlipper, static_cast<int>(i), {}, false});
  }

  // The ball: parked off the table until the first launch.
  out << "    <body name=\"ball\" pos=\"-1 -1 " << r << "\">\n"
      << "      <freejoint name=\"ball\"/>\n"
      << "      <geom name=\"ball\" type=\"sphere\" size=\"" << r << "\" mass=\"" << params.ball_mass_kg.value
      << "\" contype=\"1\" conaffinity=\"0\" priority=\"0\" condim=\"6\" friction=\"0.001 0 0\"/>\n"
      << "      <inertial pos=\"0 0 0\" mass=\"" << params.ball_mass_kg.value << "\" diaginertia=\""
      << 0.4 * params.ball_mass_kg.value * r * r << ' ' << 0.4 * params.ball_mass_kg.value * r * r << ' '
      << 0.4 * params.ball_mass_kg.value * r * r << "\"/>\n"
      << "    </body>\n";
  model.geoms.push_back({TwinGeom::kBall, -1, {}, false});
  out << "  </worldbody>\n  <actuator>\n";
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    out << "    <motor name=\"coil" << i << "\" joint=\"flipper" << i << "\" gear=\"1\" ctrllimited=\"false\"/>\n";
  }
  out << "  </actuator>\n</mujoco>\n";
  model.mjcf = xml.out.str();
  return model;
}

}  // namespace pinball::simlab
