#include "pinball/simlab/twin_world.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "pinball/core/check.h"
#include "pinball/sim/game_rules.h"

namespace pinball::simlab {

// Types the shared state and the game state hold (not in an anonymous
// namespace: TwinWorld's members have external linkage).
struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// A box for one line: solid only to a ball in front of it.
struct SidedLine {
  int geom = 0;
  Vec2 p0, p1, normal;
};

namespace {

// MuJoCo reports through two global hooks whose defaults write MUJOCO_LOG.TXT
// into the working folder and, for an error, exit the process. Warnings are
// counted per mjData (and reported through World::warnings); errors are
// fatal in MuJoCo's own design, so say what happened and abort.
void ignore_warning(const char*) {}
void fatal_error(const char* message) {
  std::fprintf(stderr, "pinball: MuJoCo error: %s\n", message);
  std::abort();
}
void install_mujoco_hooks() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_warning = ignore_warning;
    mju_user_error = fatal_error;
  });
}

// Compiles MJCF text through MuJoCo's virtual file system (no file on disk).
ModelPtr compile(const std::string& mjcf, const std::string& context) {
  install_mujoco_hooks();
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "pinball_twin.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(mjcf.size())) != 0) {
    throw std::runtime_error(context + ": MuJoCo's file system refused the model");
  }
  std::memcpy(vfs->filedata[vfs->nfile - 1], mjcf.data(), mjcf.size());
  std::array<char, 1000> error{};
  mjModel* m = mj_loadXML(name, vfs.get(), error.data(), static_cast<int>(error.size()));
  mj_deleteVFS(vfs.get());
  if (m == nullptr) throw std::runtime_error(context + ": MuJoCo refused the twin's model: " + error.data());
  return ModelPtr(m);
}

// A sphere of radius 13.5 mm striking a wall at 1 m/s in zero gravity: a
// model compiled once per time step, whose wall's softness each trial sets.
class RestitutionRig {
 public:
  explicit RestitutionRig(double timestep_s) {
    char xml[1024];
    std::snprintf(xml, sizeof xml,
                  "<mujoco><option timestep=\"%.17g\" gravity=\"0 0 0\" integrator=\"Euler\"/>"
                  "<worldbody><geom type=\"plane\" size=\"0 0 1\" solimp=\"0.99 0.99 0.001\""
                  " priority=\"1\" friction=\"0 0 0\"/>"
                  "<body pos=\"0 0 0.0236\"><freejoint/><geom type=\"sphere\" size=\"0.0135\" mass=\"0.08\"/>"
                  "</body></worldbody></mujoco>",
                  timestep_s);
    model_ = compile(xml, "twin restitution");
    data_.reset(mj_makeData(model_.get()));
  }

  // Normal speed after / before, averaged over the phases a first contact
  // can fall at within a step and over slow to fast impacts: with a few
  // steps per bounce one impact's restitution depends on its phase.
  double restitution(const TwinSolref& c) {
    model_->geom_solref[0] = c.timeconst_s;
    model_->geom_solref[1] = c.dampratio;
    constexpr int kPhases = 8;
    double sum = 0.0;
    int n = 0;
    for (const double speed : {0.5, 2.0, 5.0}) {
      for (int k = 0; k < kPhases; ++k) {
        mj_resetData(model_.get(), data_.get());
        data_->qpos[2] = 0.0135 + speed * model_->opt.timestep * (1.0 + static_cast<double>(k) / kPhases);
        data_->qvel[2] = -speed;
        sum += bounce(speed);
        ++n;
      }
    }
    return sum / n;
  }

 private:
  double bounce(double speed) {
    bool touched = false;
    for (int i = 0; i < 20000; ++i) {
      mj_step(model_.get(), data_.get());
      if (data_->ncon > 0) touched = true;
      if (touched && data_->ncon == 0) return std::max(0.0, data_->qvel[2]) / speed;
    }
    return 0.0;  // never let go: a dead contact
  }

  ModelPtr model_;
  DataPtr data_;
};

// MuJoCo keeps a time constant of at least two steps.
TwinSolref solref_of(double dampratio, double contact_duration_s, double timestep_s) {
  return {std::max(contact_duration_s / (std::numbers::pi * dampratio), 2.0 * timestep_s), dampratio};
}

}  // namespace

double twin_restitution_of(const TwinSolref& solref, double timestep_s) {
  return RestitutionRig(timestep_s).restitution(solref);
}

TwinSolref twin_solref_for_restitution(double e, double contact_duration_s, double timestep_s) {
  check_input(e >= 0.0 && e <= 0.95, "twin", "a restitution must be in [0, 0.95]");
  static std::mutex mutex;
  static std::map<std::array<double, 3>, TwinSolref> memo;
  const std::array<double, 3> key{e, contact_duration_s, timestep_s};
  {
    const std::lock_guard lock(mutex);
    if (const auto it = memo.find(key); it != memo.end()) return it->second;
  }
  RestitutionRig rig(timestep_s);
  // Restitution falls as the damping ratio rises: bisection on log(zeta).
  double lo = 1e-3, hi = 1.5;
  TwinSolref best = solref_of(hi, contact_duration_s, timestep_s);
  const double least = rig.restitution(best);
  check_input(least <= e + 0.01, "twin",
              "a restitution of " + std::to_string(e) + " is below the least a contact lasting " +
                  std::to_string(contact_duration_s) + " s gives at this step (" + std::to_string(least) + ")");
  if (least < e) {
    for (int i = 0; i < 20; ++i) {
      const double mid = std::sqrt(lo * hi);
      (rig.restitution(solref_of(mid, contact_duration_s, timestep_s)) > e ? lo : hi) = mid;
    }
    best = solref_of(std::sqrt(lo * hi), contact_duration_s, timestep_s);
  }
  const std::lock_guard lock(mutex);
  memo.emplace(key, best);
  return best;
}

std::string mujoco_version() { return mj_versionString(); }

// What every fork shares: the board, the parameters, the compiled prototype,
// the geom tables and the warning counters.
struct TwinWorld::Shared {
  const table::Board& board;
  TwinParams params;
  TwinModelText text;
  ModelPtr prototype;
  double dt_s = 0.0;
  int substeps = 1;
  int ball_geom = -1;
  int ball_qpos = 0, ball_qvel = 0;
  std::vector<int> flipper_qpos, flipper_qvel;
  std::vector<int> obstacle_geoms;       // geom ids of board obstacles
  std::vector<double> surface_offset_m;  // per geom: its surface lies this far beyond its members' shapes
  std::vector<SidedLine> lines;
  std::vector<int> eaters;               // board lines that eat the ball (drains)
  double sin_slope = 0.0, cos_slope = 1.0;
  mutable std::atomic<std::uint64_t> penetration{0}, instability{0}, overflow{0};

  Shared(const table::Board& b, const TwinParams& p) : board(b), params(p) {}
};

// One game's MuJoCo state beside its GameState.
struct TwinWorld::Impl {
  ModelPtr model;  // a copy: geoms are switched on and off per game
  DataPtr data;
  // Per geom.
  std::vector<std::uint8_t> armed;       // a one-sided box faces the ball (always 1 for the others)
  std::vector<std::uint8_t> in_contact;  // in a contact episode with the ball
  std::vector<int> credited;             // the board obstacle the episode's hit went to
  std::vector<double> kick_due_s;        // when its kicker's coil strikes (< 0: none)
  std::vector<double> kicker_ready_s;    // when its kicker may fire again
  std::vector<std::uint8_t> touch_now;   // scratch: MuJoCo reports a contact this step
  // Per flipper.
  std::vector<std::uint8_t> flipper_contact;
  std::vector<std::uint8_t> flipper_touch_now;
  std::vector<double> coil_torque_nm;    // the coil's torque now (rises and falls with L/R)
  std::vector<double> coil_on_since_s;   // when its coil was last switched on
};

namespace {

// The time-step constraints of the twin: dt a whole number of MuJoCo steps.
int substeps_for(double dt_s, double timestep_s) {
  if (dt_s == 0.0) return 1;
  check_input(dt_s > 0.0 && std::isfinite(dt_s), "twin", "the world's time step must be positive");
  const double n = std::round(dt_s / timestep_s);
  check_input(n >= 1.0 && std::abs(n * timestep_s - dt_s) <= 1e-9 * dt_s + 1e-12, "twin",
              "the world's time step (" + std::to_string(dt_s) + " s) must be a whole number of the twin's " +
                  std::to_string(timestep_s) + " s steps (config/twin.yaml: timestep_s)");
  return static_cast<int>(n);
}

}  // namespace

TwinWorld::TwinWorld(const table::Board& board, const TwinParams& params, double dt_s)
    : TwinWorld(build(board, params, dt_s)) {}

std::shared_ptr<const TwinWorld::Shared> TwinWorld::build(const table::Board& board, const TwinParams& params,
                                                          double dt_s) {
  auto shared = std::make_shared<Shared>(board, params);
  const double timestep = params.timestep_s.value;
  shared->substeps = substeps_for(dt_s, timestep);
  shared->dt_s = shared->substeps * timestep;
  check_twin_params(params);
  const double duration = params.contact_duration_s.value;
  TwinContacts contacts;
  contacts.rail = twin_solref_for_restitution(params.rail_restitution.value, duration, timestep);
  contacts.rubber = twin_solref_for_restitution(params.rubber_restitution.value, duration, timestep);
  contacts.dead = twin_solref_for_restitution(params.dead_restitution.value, duration, timestep);
  contacts.flipper = twin_solref_for_restitution(params.flipper_restitution.value, duration, timestep);
  contacts.playfield = twin_solref_for_restitution(params.playfield_restitution.value, duration, timestep);
  contacts.end_stop = twin_solref_for_restitution(params.end_stop_restitution.value, duration, timestep);
  shared->text = twin_model_text(board, params, timestep, contacts);
  shared->prototype = compile(shared->text.mjcf, "twin: " + board.source);
  const mjModel* m = shared->prototype.get();
  if (m->ngeom != static_cast<int>(shared->text.geoms.size())) {
    throw std::runtime_error("twin: MuJoCo compiled " + std::to_string(m->ngeom) + " geoms, the model text has " +
                             std::to_string(shared->text.geoms.size()));
  }
  shared->surface_offset_m.assign(static_cast<std::size_t>(m->ngeom), 0.0);
  for (int g = 0; g < m->ngeom; ++g) {
    const TwinGeom& role = shared->text.geoms[static_cast<std::size_t>(g)];
    if (role.kind == TwinGeom::kBall) shared->ball_geom = g;
    if (role.kind != TwinGeom::kObstacle) continue;
    shared->obstacle_geoms.push_back(g);
    const table::Shape& first = board.shapes[static_cast<std::size_t>(role.members.front())];
    if (role.one_sided) {
      shared->lines.push_back({g, first.p0, first.p1, first.normal});
    } else if (first.kind == table::ShapeKind::kLine) {
      shared->surface_offset_m[static_cast<std::size_t>(g)] = params.pin_radius_m.value;  // a bar
    } else {
      shared->surface_offset_m[static_cast<std::size_t>(g)] = std::max(0.0, params.pin_radius_m.value - first.radius_m);
    }
  }
  const int ball_joint = mj_name2id(m, mjOBJ_JOINT, "ball");
  shared->ball_qpos = m->jnt_qposadr[ball_joint];
  shared->ball_qvel = m->jnt_dofadr[ball_joint];
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, ("flipper" + std::to_string(i)).c_str());
    shared->flipper_qpos.push_back(m->jnt_qposadr[j]);
    shared->flipper_qvel.push_back(m->jnt_dofadr[j]);
  }
  for (std::size_t i = 0; i < board.obstacles.size(); ++i) {
    if (board.obstacles[i].action.eats_ball && board.shapes[i].kind == table::ShapeKind::kLine) {
      shared->eaters.push_back(static_cast<int>(i));
    }
  }
  shared->sin_slope = std::sin(shared->text.slope_rad);
  shared->cos_slope = std::cos(shared->text.slope_rad);
  return shared;
}

TwinWorld::TwinWorld(std::shared_ptr<const Shared> shared) : shared_(std::move(shared)), impl_(std::make_unique<Impl>()) {
  const table::Board& board = shared_->board;
  impl_->model.reset(mj_copyModel(nullptr, shared_->prototype.get()));
  impl_->data.reset(mj_makeData(impl_->model.get()));
  if (!impl_->model || !impl_->data) throw std::runtime_error("twin: MuJoCo could not allocate a game");
  const std::size_t geoms = static_cast<std::size_t>(impl_->model->ngeom);
  impl_->armed.assign(geoms, 1);
  impl_->in_contact.assign(geoms, 0);
  impl_->credited.assign(geoms, -1);
  impl_->kick_due_s.assign(geoms, -1.0);
  impl_->kicker_ready_s.assign(geoms, 0.0);
  impl_->touch_now.assign(geoms, 0);
  impl_->flipper_contact.assign(board.flippers.size(), 0);
  impl_->flipper_touch_now.assign(board.flippers.size(), 0);
  impl_->coil_torque_nm.assign(board.flippers.size(), 0.0);
  impl_->coil_on_since_s.assign(board.flippers.size(), 0.0);
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    impl_->data->qpos[shared_->flipper_qpos[i]] = board.flippers[i].theta_min_rad;
  }
  mj_forward(impl_->model.get(), impl_->data.get());
}

TwinWorld::~TwinWorld() = default;

std::unique_ptr<sim::World> make_twin_world(const table::Board& board, const TwinParams& params, double dt_s) {
  return std::make_unique<TwinWorld>(board, params, dt_s);
}

const table::Board& TwinWorld::board() const { return shared_->board; }
double TwinWorld::dt_s() const { return shared_->dt_s; }
int TwinWorld::substeps() const { return shared_->substeps; }
const TwinParams& TwinWorld::params() const { return shared_->params; }
const TwinModelText& TwinWorld::model_text() const { return shared_->text; }

std::unique_ptr<sim::World> TwinWorld::fork() const {
  return std::unique_ptr<sim::World>(new TwinWorld(shared_));
}

sim::WorldWarnings TwinWorld::warnings() const {
  sim::WorldWarnings w;
  w.penetration = shared_->penetration.load(std::memory_order_relaxed);
  w.instability = shared_->instability.load(std::memory_order_relaxed);
  w.overflow = shared_->overflow.load(std::memory_order_relaxed);
  return w;
}

TwinBall TwinWorld::ball() const {
  const mjData* d = impl_->data.get();
  const mjtNum* q = d->qpos + shared_->ball_qpos;
  const mjtNum* v = d->qvel + shared_->ball_qvel;
  TwinBall b;
  b.position_m = {q[0], q[1], q[2]};
  b.velocity_mps = {v[0], v[1], v[2]};
  // A free joint's angular velocity is in the body's frame: turn it into the board's.
  mjtNum world_w[3];
  mju_rotVecQuat(world_w, v + 3, q + 3);
  b.angular_velocity_rad_s = {world_w[0], world_w[1], world_w[2]};
  return b;
}

double TwinWorld::ball_energy_j() const {
  const TwinBall b = ball();
  const double m = shared_->params.ball_mass_kg.value;
  const double r = shared_->board.ball.radius_m;
  const double g = shared_->params.gravity_mps2.value;
  const double height = shared_->sin_slope * b.position_m.y() + shared_->cos_slope * b.position_m.z();
  return 0.5 * m * b.velocity_mps.squaredNorm() + 0.5 * (0.4 * m * r * r) * b.angular_velocity_rad_s.squaredNorm() +
         m * g * height;
}

namespace {

// Writes the ball's 3-D state (board frame) into MuJoCo, orientation reset.
void write_ball(mjData* d, int qpos, int qvel, const TwinBall& b) {
  mjtNum* q = d->qpos + qpos;
  mjtNum* v = d->qvel + qvel;
  q[0] = b.position_m.x();
  q[1] = b.position_m.y();
  q[2] = b.position_m.z();
  q[3] = 1.0;
  q[4] = q[5] = q[6] = 0.0;
  for (int i = 0; i < 3; ++i) {
    v[i] = b.velocity_mps[i];
    v[3 + i] = b.angular_velocity_rad_s[i];  // the identity orientation: body frame = board frame
  }
}

// A ball on the playfield at `p` moving at `v`, rolling without slipping (a
// launch or a kickout: the board's speeds are those the ball leaves with).
TwinBall rolling_ball(const Vec2& p, const Vec2& v, double r) {
  TwinBall b;
  b.position_m = {p.x(), p.y(), r};
  b.velocity_mps = {v.x(), v.y(), 0.0};
  b.angular_velocity_rad_s = {-v.y() / r, v.x() / r, 0.0};
  return b;
}

}  // namespace

void TwinWorld::place_ball(sim::GameState& state, const TwinBall& ball) {
  state.ball_in_play = true;
  state.ball.position_m = ball.position_m.head<2>();
  state.ball.velocity_mps = ball.velocity_mps.head<2>();
  state.ball.height_m = std::max(0.0, ball.position_m.z() - shared_->board.ball.radius_m);
  write_ball(impl_->data.get(), shared_->ball_qpos, shared_->ball_qvel, ball);
  std::fill(impl_->in_contact.begin(), impl_->in_contact.end(), 0);
  std::fill(impl_->flipper_contact.begin(), impl_->flipper_contact.end(), 0);
  std::fill(impl_->kick_due_s.begin(), impl_->kick_due_s.end(), -1.0);
  // A line faces the ball when its centre is in front of it.
  for (const SidedLine& l : shared_->lines) {
    impl_->armed[static_cast<std::size_t>(l.geom)] = l.normal.dot(state.ball.position_m - l.p0) >= 0.0 ? 1 : 0;
  }
  for (std::size_t i = 0; i < shared_->board.flippers.size(); ++i) {
    impl_->data->qpos[shared_->flipper_qpos[i]] = state.flippers[i].theta_rad;
  }
  mj_forward(impl_->model.get(), impl_->data.get());
}

void TwinWorld::launch(sim::GameState& state, double pull) {
  // The model's launch (the same random draws, so the same ball seeds give
  // the same launches), then the twin's ball takes its place, rolling.
  sim::launch_ball(shared_->board, state, pull);
  place_ball(state, rolling_ball(state.ball.position_m, state.ball.velocity_mps, shared_->board.ball.radius_m));
}

namespace {

// A contact episode ends when the ball's surface is this far from the obstacle.
constexpr double kReleaseGap_m = 0.001;
// A flag rises only when the ball is this far clear of it (as the steppers).
constexpr double kFlagClearance_m = 0.0005;

// The member of a geom a hit at p goes to: the nearest of its visible shapes
// that faces the ball (a line's front, or a point), as the model would have
// reflected it; with its distance from p.
std::pair<int, double> nearest_member(const table::Board& board, const sim::GameState& state, const TwinGeom& geom,
                                      const Vec2& p) {
  std::pair<int, double> best{geom.members.front(), std::numeric_limits<double>::infinity()};
  for (const int m : geom.members) {
    const table::Shape& shape = board.shapes[static_cast<std::size_t>(m)];
    if (state.visible[static_cast<std::size_t>(m)] != sim::kVisible) continue;
    if (shape.kind == table::ShapeKind::kLine && shape.normal.dot(p - shape.p0) < 0.0) continue;
    const double d = table::distance_to_shape(shape, p);
    if (d < best.second) best = {m, d};
  }
  return best;
}

// Distance from p to a geom's surface (m).
double geom_surface_distance(const table::Board& board, const TwinGeom& geom, double offset_m, const Vec2& p) {
  double d = std::numeric_limits<double>::infinity();
  for (const int m : geom.members) d = std::min(d, table::distance_to_shape(board.shapes[static_cast<std::size_t>(m)], p));
  return d - offset_m;
}

// The direction a kicker throws a ball at p: its line's front, or away from its centre.
Vec2 kick_direction(const table::Shape& shape, const Vec2& p) {
  if (shape.kind == table::ShapeKind::kLine) return shape.normal;
  const Vec2 d = p - shape.p0;
  const double n = d.norm();
  return n > 0.0 ? Vec2(d / n) : Vec2(0.0, 1.0);
}

}  // namespace

sim::StepEvents TwinWorld::step(sim::GameState& state) {
  const Shared& s = *shared_;
  Impl& w = *impl_;
  mjModel* m = w.model.get();
  mjData* d = w.data.get();
  const table::Board& board = s.board;
  const TwinParams& p = s.params;
  const double r = board.ball.radius_m;
  const double h = p.timestep_s.value;
  const double rise = 1.0 - std::exp(-h / p.coil_rise_s.value);
  sim::StepEvents events;

  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    sim::FlipperState& fs = state.flippers[i];
    if (fs.energized && !fs.was_energized) w.coil_on_since_s[i] = state.time_s;
    sim::rules::take_command(board.flippers[i], fs, state.flips);
  }

  for (int sub = 0; sub < s.substeps; ++sub) {
    const double t_s = state.time_s + sub * h;
    // The solenoid: the driver board pulses then holds; the coil's current
    // (so its torque) follows with its L/R time constant; the spring pulls back.
    for (std::size_t i = 0; i < board.flippers.size(); ++i) {
      const bool on = state.flippers[i].energized;
      const double target = !on ? 0.0
                            : t_s - w.coil_on_since_s[i] < p.coil_pulse_s.value ? p.coil_pulse_torque_nm.value
                                                                                 : p.coil_hold_torque_nm.value;
      w.coil_torque_nm[i] += (target - w.coil_torque_nm[i]) * rise;
      d->ctrl[i] = w.coil_torque_nm[i] - p.return_spring_torque_nm.value;
    }
    if (!state.ball_in_play) {
      // No ball in play: it waits off the table, still.
      write_ball(d, s.ball_qpos, s.ball_qvel, rolling_ball(Vec2(-1.0, -1.0), Vec2::Zero(), r));
    } else {
      // One-sided lines and hidden flags (design: docs/worlds.md). A line is
      // solid only to a ball in front of it; a ball that came from behind
      // passes until it is clear of it.
      const Vec2& ball = state.ball.position_m;
      for (const SidedLine& l : s.lines) {
        std::uint8_t& armed = w.armed[static_cast<std::size_t>(l.geom)];
        if (l.normal.dot(ball - l.p0) < 0.0) {
          armed = 0;
        } else if (!armed) {
          // Clear of the line, or off its ends (rounding a corner, where the
          // neighbour's solid already holds it): never armed into a ball it overlaps.
          const double u = closest_param_on_segment(ball, l.p0, l.p1);
          if (u <= 0.0 || u >= 1.0 || distance_point_segment(ball, l.p0, l.p1) >= r) armed = 1;
        }
      }
      for (const int g : s.obstacle_geoms) {
        // A flag that falls when hit still stops the ball that hit it: it drops once the ball has left.
        const std::size_t k = static_cast<std::size_t>(g);
        bool standing = w.in_contact[k] != 0;
        for (const int member : s.text.geoms[k].members) standing |= state.visible[static_cast<std::size_t>(member)] == sim::kVisible;
        m->geom_conaffinity[g] = w.armed[k] && standing ? 1 : 0;
      }
    }

    mj_step(m, d);

    // MuJoCo's warnings: counted, and a reset (bad numbers) loses the ball.
    bool unstable = false;
    for (int kind = 0; kind < mjNWARNING; ++kind) {
      const int n = d->warning[kind].number;
      if (n == 0) continue;
      d->warning[kind].number = 0;
      if (kind == mjWARN_BADQPOS || kind == mjWARN_BADQVEL || kind == mjWARN_BADQACC || kind == mjWARN_BADCTRL) {
        s.instability.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
        unstable = true;
      } else if (kind == mjWARN_CONTACTFULL || kind == mjWARN_CNSTRFULL) {
        s.overflow.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
      }
    }
    const TwinBall b = ball();
    if (unstable || !b.position_m.allFinite() || !b.velocity_mps.allFinite()) {
      if (!unstable) s.instability.fetch_add(1, std::memory_order_relaxed);
      for (std::size_t i = 0; i < board.flippers.size(); ++i) {
        d->qpos[s.flipper_qpos[i]] = state.flippers[i].theta_rad;
        d->qvel[s.flipper_qvel[i]] = 0.0;
      }
      if (state.ball_in_play) sim::rules::lose_ball(board, state, events);
      continue;
    }
    if (!state.ball_in_play) continue;

    const Vec2 from = state.ball.position_m;
    const Vec2 at = b.position_m.head<2>();
    state.ball.position_m = at;
    state.ball.velocity_mps = b.velocity_mps.head<2>();
    state.ball.height_m = std::max(0.0, b.position_m.z() - r);

    // Which obstacles and flippers MuJoCo has the ball touching.
    std::fill(w.touch_now.begin(), w.touch_now.end(), 0);
    std::fill(w.flipper_touch_now.begin(), w.flipper_touch_now.end(), 0);
    double deepest_m = 0.0;
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact& con = d->contact[c];
      const int other = con.geom1 == s.ball_geom ? con.geom2 : con.geom2 == s.ball_geom ? con.geom1 : -1;
      if (other < 0) continue;
      const TwinGeom& role = s.text.geoms[static_cast<std::size_t>(other)];
      if (role.kind == TwinGeom::kObstacle || role.kind == TwinGeom::kFlipper) deepest_m = std::max(deepest_m, -con.dist);
      if (role.kind == TwinGeom::kObstacle) w.touch_now[static_cast<std::size_t>(other)] = 1;
      if (role.kind == TwinGeom::kFlipper) w.flipper_touch_now[static_cast<std::size_t>(role.flipper)] = 1;
    }
    // 30 % of the radius at most: a limit of 4 mm had let a 1 mm ball sink through a bar unreported.
    if (deepest_m > std::min(p.penetration_warning_m.value, 0.3 * board.ball.radius_m)) {
      s.penetration.fetch_add(1, std::memory_order_relaxed);
    }

    const double t_end_s = t_s + h;
    for (const int g : s.obstacle_geoms) {
      if (!state.ball_in_play) break;
      const std::size_t k = static_cast<std::size_t>(g);
      const TwinGeom& geom = s.text.geoms[k];
      if (w.touch_now[k] && !w.in_contact[k]) {
        // A new contact: the game's rules score it, drop a flag, eat the ball.
        w.in_contact[k] = 1;
        const int hit = nearest_member(board, state, geom, at).first;
        w.credited[k] = hit;
        if (board.obstacles[static_cast<std::size_t>(hit)].action.kick_mps > 0.0 && t_end_s >= w.kicker_ready_s[k]) {
          w.kick_due_s[k] = t_end_s + p.kicker_delay_s.value;
          w.kicker_ready_s[k] = t_end_s + p.kicker_recycle_s.value;
        }
        sim::rules::score_obstacle_hit(board, state, hit, events, r + kFlagClearance_m);
      } else if (w.in_contact[k] && !w.touch_now[k] &&
                 geom_surface_distance(board, geom, s.surface_offset_m[k], at) > r + kReleaseGap_m) {
        w.in_contact[k] = 0;
      }
      if (w.in_contact[k] && w.credited[k] >= 0) {
        const std::size_t hit = static_cast<std::size_t>(w.credited[k]);
        const double rate = board.obstacles[hit].action.contact_score_per_s;
        if (rate > 0.0 && state.visible[hit] == sim::kVisible) {
          state.score += rate * h;
          events.score_gained += rate * h;
        }
      }
      if (w.kick_due_s[k] >= 0.0 && t_end_s >= w.kick_due_s[k]) {
        // The kicker's coil strikes: only a ball still at its rubber is thrown.
        w.kick_due_s[k] = -1.0;
        if (geom_surface_distance(board, geom, s.surface_offset_m[k], at) <= r + p.kicker_reach_m.value) {
          const table::Shape& shape = board.shapes[static_cast<std::size_t>(w.credited[k])];
          const double speed = shape.kind == table::ShapeKind::kLine ? p.slingshot_kick_mps.value
                                                                      : p.bumper_kick_mps.value;
          const Vec2 n = kick_direction(shape, at);
          d->qvel[s.ball_qvel + 0] += speed * n.x();
          d->qvel[s.ball_qvel + 1] += speed * n.y();
        }
      }
    }
    // A drain is a hole in the playfield's end: a ball that reaches it is
    // eaten even if it hops over the rail the twin builds there.
    for (const int e : s.eaters) {
      if (!state.ball_in_play) break;
      const table::Shape& shape = board.shapes[static_cast<std::size_t>(e)];
      if (state.visible[static_cast<std::size_t>(e)] != sim::kVisible) continue;
      if (distance_segment_segment(from, at, shape.p0, shape.p1) <= r) {
        sim::rules::score_obstacle_hit(board, state, e, events, r + kFlagClearance_m);
      }
    }
    if (!state.ball_in_play) continue;

    for (std::size_t i = 0; i < board.flippers.size(); ++i) {
      const bool touching = w.flipper_touch_now[i] != 0;
      if (touching && !w.flipper_contact[i]) {
        events.flags |= sim::StepEvents::kHitFlipper;
        if (events.flipper < 0) events.flipper = static_cast<std::int32_t>(i);
        w.flipper_contact[i] = 1;
      } else if (!touching && w.flipper_contact[i]) {
        const table::Flipper& f = board.flippers[i];
        const double theta = d->qpos[s.flipper_qpos[i]];
        const double gap = distance_point_segment(at, f.pivot, table::flipper_tip(f, theta)) - p.flipper_radius_m.value;
        if (gap > r + kReleaseGap_m) w.flipper_contact[i] = 0;
      }
      state.flippers[i].ball_contact = w.flipper_contact[i] != 0;
    }

    for (std::size_t i = 0; i < board.sensors.size(); ++i) {
      const table::Sensor& sensor = board.sensors[i];
      const bool entered = sim::rules::swept_onto_sensor(sensor, from, at, r) && !state.sensor_inside[i];
      state.sensor_inside[i] = sim::rules::on_sensor(sensor, at, r) ? 1 : 0;
      if (!entered) continue;
      sim::rules::fire_sensor(board, state, static_cast<std::int32_t>(i), events);
      if (!state.ball_in_play) break;
      if (sensor.has_kickout) {
        place_ball(state, rolling_ball(state.ball.position_m, state.ball.velocity_mps, r));
        break;
      }
    }
    if (!state.ball_in_play) continue;

    const bool off_table = at.x() < -r || at.x() > board.width_m + r || at.y() < -r || at.y() > board.height_m + r ||
                           b.position_m.z() < -r;
    if (off_table) {
      events.flags |= sim::StepEvents::kLeftTable;
      sim::rules::lose_ball(board, state, events);
    }
  }

  state.time_s += s.dt_s;
  ++state.steps;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    state.flippers[i].theta_rad = d->qpos[s.flipper_qpos[i]];
    state.flippers[i].omega_rad_s = d->qvel[s.flipper_qvel[i]];
  }
  if (!state.ball_in_play) {
    state.ball.height_m = 0.0;
    std::fill(w.in_contact.begin(), w.in_contact.end(), 0);
    std::fill(w.flipper_contact.begin(), w.flipper_contact.end(), 0);
    for (auto& f : state.flippers) f.ball_contact = false;
  }
  if (state.rising_flags > 0) sim::rules::raise_flags(board, state, r + kFlagClearance_m);
  return events;
}

}  // namespace pinball::simlab
