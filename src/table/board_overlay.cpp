#include "pinball/table/board_overlay.h"

#include <map>
#include <sstream>
#include <stdexcept>

#include "pinball/core/format.h"
#include "pinball/core/text_file.h"
#include "pinball/core/utc_date.h"
#include "pinball/core/yaml_read_archive.h"
#include "pinball/core/yaml_write_archive.h"
#include "pinball/table/board_loader.h"

namespace pinball::table {
namespace {


// An inclusive or open bound of a range check.
struct Bound {
  double value;
  bool open;
};

// Throws KeyError "file:key: must be in [lo, hi] unit" unless `x` is in the range.
void check_range(double x, Bound lo, Bound hi, const char* unit, const std::string& key, const YamlReadArchive& r) {
  const bool above = lo.open ? x > lo.value : x >= lo.value;
  const bool below = hi.open ? x < hi.value : x <= hi.value;
  if (above && below) return;
  std::ostringstream m;
  m << x << " is out of range: must be in " << (lo.open ? "(" : "[") << lo.value << ", " << hi.value
    << (hi.open ? ")" : "]") << unit;
  r.fail(key, m.str());
}

void check_at_least_zero(double x, const char* unit, const std::string& key, const YamlReadArchive& r) {
  if (x >= 0.0) return;
  std::ostringstream m;
  m << x << " is out of range: must be >= 0" << unit;
  r.fail(key, m.str());
}

// The value's range, and stderr and events >= 0, for one identified number at `key`.
void check_value(const IdentifiedValue& v, Bound lo, Bound hi, const char* unit, const std::string& key,
                 const YamlReadArchive& r) {
  check_range(v.value, lo, hi, unit, key + ".value", r);
  check_at_least_zero(v.stderr_, unit, key + ".stderr", r);
  if (v.events < 0) r.fail(key + ".events", std::to_string(v.events) + " is out of range: must be >= 0");
}

constexpr Bound kZero{0.0, false};
constexpr Bound kAboveZero{0.0, true};

// The checks a type cannot express, after reading (header: the ranges).
void check_overlay(const BoardOverlay& o, const YamlReadArchive& r) {
  // g and ρ in the board format's ranges: an overlay gives no world a board file could not.
  if (o.gravity_mps2) check_value(*o.gravity_mps2, kAboveZero, {kMaxGravity_mps2, false}, " m/s^2", "gravity_mps2", r);
  if (o.wall_thickness_m) check_value(*o.wall_thickness_m, kZero, {0.05, false}, " m", "wall_thickness_m", r);
  std::map<std::string, std::string> obstacle_at;  // each obstacle's one place: a second would be dropped
  for (std::size_t i = 0; i < o.obstacle_groups.size(); ++i) {
    const ObstacleGroupOverlay& g = o.obstacle_groups[i];
    const std::string key = "obstacle_groups[" + std::to_string(i) + "]";
    check_at_least_zero(g.board_rho, "", key + ".board_rho", r);
    check_at_least_zero(g.board_kick_mps, " m/s", key + ".board_kick_mps", r);
    if (g.obstacles.empty()) r.fail(key + ".obstacles", "names no obstacle");
    check_value(g.rho, kZero, {kMaxRho, false}, "", key + ".rho", r);
    if (g.kick_mps) check_value(*g.kick_mps, kZero, {kMaxOverlayKick_mps, false}, " m/s", key + ".kick_mps", r);
    // A kick identified for a group the board gives none would turn its walls into kickers.
    if (g.kick_mps && g.board_kick_mps == 0.0) {
      r.fail(key + ".kick_mps", "is only for a group the board gives a kick (its board_kick_mps is 0)");
    }
    for (std::size_t j = 0; j < g.obstacles.size(); ++j) {
      const std::string at = key + ".obstacles[" + std::to_string(j) + "]";
      if (const auto [first, fresh] = obstacle_at.emplace(g.obstacles[j], at); !fresh) {
        r.fail(at, "'" + g.obstacles[j] + "' is given twice (also " + first->second + "): which value counts?");
      }
    }
    if (g.friction) check_value(*g.friction, kZero, {kMaxWallFriction, false}, "", key + ".friction", r);
  }
  for (std::size_t i = 0; i < o.flippers.size(); ++i) {
    const std::string key = "flippers[" + std::to_string(i) + "]";
    if (o.flippers[i].name.empty()) r.fail(key + ".name", "is empty");
    for (std::size_t k = 0; k < i; ++k) {
      if (o.flippers[k].name == o.flippers[i].name) {
        r.fail(key + ".name", "'" + o.flippers[i].name + "' is given twice (also flippers[" + std::to_string(k) +
                                  "]): which value counts?");
      }
    }
    if (o.flippers[i].mu) check_value(*o.flippers[i].mu, kZero, {kMaxFlipperMu, false}, "", key + ".mu", r);
    if (o.flippers[i].omega_rad_s)
      check_value(*o.flippers[i].omega_rad_s, kAboveZero, {kMaxFlipperOmega_rad_s, false}, " rad/s",
                  key + ".omega_rad_s", r);
    if (o.flippers[i].rise_delay_s)
      check_value(*o.flippers[i].rise_delay_s, kZero, {0.1, false}, " s", key + ".rise_delay_s", r);
  }
  if (o.launcher) {
    check_value(o.launcher->pull, kAboveZero, {1.0, false}, "", "launcher.pull", r);
    check_value(o.launcher->noise_max, kZero, {kMaxLaunchNoise, false}, "", "launcher.noise_max", r);
  }
}

// "'a', 'b'" of the flippers' names, or "none".
std::string names_of(const std::vector<Flipper>& flippers) {
  std::string out;
  for (const Flipper& f : flippers) out += (out.empty() ? "'" : ", '") + f.name + "'";
  return out.empty() ? "none" : out;
}

}  // namespace

std::string board_overlay_to_yaml(const BoardOverlay& overlay) {
  BoardOverlay o = overlay;
  if (o.date.empty()) o.date = utc_now_iso8601();
  YAML::Emitter e;
  e << YAML::Comment(
      "pinball board overlay (docs/identification.md): identified parameters laid over the board file below,\n"
      "written by `pinball identify`; read with --identified FILE. SI units; stderr: one standard uncertainty;\n"
      "events: the recorded events each value rests on. A section left out keeps the board's values.");
  YamlWriteArchive::emit(e, o);
  return std::string(e.c_str()) + "\n";
}

void write_board_overlay(const BoardOverlay& overlay, const std::string& path) {
  write_text_file(path, board_overlay_to_yaml(overlay));
}

BoardOverlay parse_board_overlay(const std::string& text, const std::string& name) {
  const YAML::Node root = load_yaml(text, name);
  require_yaml_version(root, name, kBoardOverlayVersion, "a board overlay file");
  // Every key is required and no other is allowed (a misspelt key must not
  // pass unseen); the sections and a group's kick are optional. A repeated
  // key is refused by the reader.
  YamlReadArchive r(name, {.refuse_unknown_keys = true, .require_every_key = true});
  BoardOverlay o;
  r.read(root, "", &o);
  check_overlay(o, r);
  return o;
}

BoardOverlay read_board_overlay(const std::string& path) { return parse_board_overlay(read_text_file(path), path); }

void apply_board_overlay(const BoardOverlay& overlay, const std::string& name, Board& board) {
  Board b = board;  // all or nothing: the board changes only when every name is found
  if (overlay.gravity_mps2) b.gravity_mps2 = overlay.gravity_mps2->value;
  if (overlay.wall_thickness_m) set_wall_thickness(b, overlay.wall_thickness_m->value);
  for (std::size_t i = 0; i < overlay.obstacle_groups.size(); ++i) {
    const ObstacleGroupOverlay& g = overlay.obstacle_groups[i];
    for (std::size_t j = 0; j < g.obstacles.size(); ++j) {
      int shapes = 0;
      for (Obstacle& o : b.obstacles) {
        if (o.name != g.obstacles[j]) continue;
        o.rho = g.rho.value;
        if (g.kick_mps) o.action.kick_mps = g.kick_mps->value;
        if (g.friction) o.friction = g.friction->value;
        ++shapes;
      }
      if (shapes == 0) {
        // keyword@LINE is the name of an obstacle without name=: it moves with the board's lines.
        const bool by_line = g.obstacles[j].find('@') != std::string::npos;
        throw KeyError(name, "obstacle_groups[" + std::to_string(i) + "].obstacles[" + std::to_string(j) + "]",
                       "'" + g.obstacles[j] + "' is not an obstacle of the board " + board.source +
                           (by_line ? " (an obstacle without name= is named by its keyword and line: the board's "
                                      "lines moved since the overlay was written? give its obstacles a name=)"
                                    : " (an obstacle's name is its name= in the board file)"));
      }
    }
  }
  for (std::size_t i = 0; i < overlay.flippers.size(); ++i) {
    const FlipperOverlay& f = overlay.flippers[i];
    Flipper* target = nullptr;
    for (Flipper& candidate : b.flippers) {
      if (candidate.name == f.name) target = &candidate;
    }
    if (!target) {
      throw KeyError(name, "flippers[" + std::to_string(i) + "].name",
                     "'" + f.name + "' is not a flipper of the board " + board.source +
                         " (its flippers: " + names_of(board.flippers) + ")");
    }
    if (f.mu) target->mu = f.mu->value;
    if (f.omega_rad_s) {
      target->omega_rad_s = f.omega_rad_s->value;
      // A faster stroke sweeps further in one of the board's steps: the loader's rule must still hold.
      try {
        Board one = b;
        one.flippers = {*target};
        check_flipper_time_step(one, b.dt_s);
        if (const std::string problem = flipper_tip_speed_problem(b, *target); !problem.empty()) {
          throw std::invalid_argument(problem);
        }
      } catch (const std::invalid_argument& e) {
        throw KeyError(name, "flippers[" + std::to_string(i) + "].omega_rad_s",
                       std::string(e.what()) + " on the board " + board.source);
      }
    }
  }
  if (overlay.launcher) {
    b.launcher.pull = overlay.launcher->pull.value;
    b.launcher.noise_max = overlay.launcher->noise_max.value;
  }
  // The board loader's rule, for the new pull, noise and g: a launch must leave the launcher.
  try {
    check_launch_pull(b, b.launcher.pull);
  } catch (const std::invalid_argument& e) {
    throw KeyError(name, overlay.launcher ? "launcher.pull" : "gravity_mps2",
                   std::string(e.what()) + " (on the board " + board.source + ")");
  }
  // Thicker walls move their faces: the board loader's placements must stay clear of them, or
  // the ball begins inside a wall (found: out through the chute's wall at 0.05 m).
  if (overlay.wall_thickness_m) {
    const auto require_clear = [&](const Vec2& p, const std::string& where) {
      if (const std::optional<BallOverlap> o = ball_overlap(b, p)) {
        throw KeyError(name, "wall_thickness_m",
                       "with walls " + format_number(overlay.wall_thickness_m->value) + " m thick the ball " + where +
                           " overlaps " + o->what + " (distance " + format_number(o->distance_m) + " m, ball radius " +
                           format_number(b.ball.radius_m) + " m) on the board " + board.source);
      }
    };
    if (b.start) {
      require_clear(b.start->position, "at the start");
    } else {
      require_clear(b.launcher.position, "at the launch position");
    }
    for (const Sensor& hole : b.sensors) {
      if (hole.kind == SensorKind::kHole && hole.has_kickout) {
        require_clear(hole.shape.p0, "kicked out of " + hole.name);
      }
    }
  }
  board = std::move(b);
}

std::optional<double> identified_actuation_delay_s(const BoardOverlay& overlay) {
  double sum = 0.0;
  int n = 0;
  for (const FlipperOverlay& f : overlay.flippers)
    if (f.rise_delay_s) sum += f.rise_delay_s->value, ++n;
  if (n == 0) return std::nullopt;
  return sum / n;
}

Board load_belief_board(const std::string& board_path, const std::string& overlay_path) {
  Board board = load_board(board_path);
  if (!overlay_path.empty()) apply_board_overlay(read_board_overlay(overlay_path), overlay_path, board);
  return board;
}

}  // namespace pinball::table
