#include "pinball/simlab/sim_world.h"

#include <stdexcept>

#include "pinball/core/clock.h"
#include "pinball/core/rng.h"
#include "pinball/sim/ball_runner.h"

namespace pinball::simlab {
namespace {

firmware::VirtualDriverBoardOptions board_options(const table::Board& board, int board_id) {
  if (board.flippers.empty() || board.flippers.size() > static_cast<std::size_t>(firmware::kMaxDrivers)) {
    throw std::invalid_argument("sim: the board needs 1 to 8 flippers (one driver each)");
  }
  firmware::VirtualDriverBoardOptions o;
  o.driver_count = static_cast<int>(board.flippers.size());
  o.board_id = static_cast<std::uint8_t>(board_id);  // the id the host addresses (can.board_id)
  return o;
}

}  // namespace

void SimWorld::CoilWatch::on_coil_change(int driver, const firmware::CoilOutput& output) {
  if (driver < 0 || static_cast<std::size_t>(driver) >= world_.actuation_.size()) return;
  world_.actuation_[static_cast<std::size_t>(driver)]->on_coil_change(driver, output);
  if (output.state != firmware::CoilState::kOff) {
    world_.coil_on_wall_s_[static_cast<std::size_t>(driver)] = steady_now_s();
    ++world_.coil_on_count_;
  }
}

SimWorld::SimWorld(const sim::World& world, firmware::CanTransport& board_link, const simlab::SimCameraConfig& camera,
                   const SimWorldOptions& options)
    : world_(world.fork()),
      board_(world_->board()),
      link_(board_link),
      options_(options),
      state_(sim::make_game_state(board_, options.seed)),
      camera_(board_, camera),
      driver_board_(board_options(board_, options.board_id)) {
  const table::Board& board = board_;
  if (options.balls < 0) throw std::invalid_argument("sim: balls must be >= 0");
  if (!(options.max_ball_time_s > 0.0)) throw std::invalid_argument("sim: max ball time must be > 0 s");
  bool left = false, right = false;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const bool is_left = board.flippers[i].side == table::Side::kLeft;
    (is_left ? left : right) = true;
    board_flipper_[is_left ? 0 : 1] = static_cast<int>(i);
    actuation_.push_back(std::make_unique<firmware::FlipperActuation>(static_cast<int>(i), options.actuation_delay_s));
  }
  if (!left || !right) throw std::invalid_argument("sim: the board needs a left and a right flipper");
  driver_board_.add_listener(&coil_watch_);
  results_.resize(static_cast<std::size_t>(options.balls));
  pull_ = options.launcher_pull >= 0.0 ? options.launcher_pull : board.launcher.pull;
  table::check_launch_pull(board, pull_);  // a launch that cannot leave would be relaunched for ever
}

void SimWorld::render_background(vision::Frame& frame, double t_s) {
  camera_.set_lamps_blinking(false);
  camera_.set_glare(false);
  camera_.render({}, t_s, frame);
  camera_.set_lamps_blinking(true);
  camera_.set_glare(true);
}

void SimWorld::start_ball() {
  // The same launch noise per ball index as the fast learning loop's evaluator.
  state_.rng = Rng(ball_seed(options_.seed, static_cast<std::uint64_t>(ball_)));
  sim::begin_ball(*world_, state_, pull_);
  ball_active_ = true;
  ball_t0_s_ = state_.time_s;
  ball_score0_ = state_.score;
  ball_flips0_ = state_.flips;
}

void SimWorld::drive_flippers() {
  const double t = state_.time_s;
  driver_board_.service(link_, t);
  for (std::size_t i = 0; i < actuation_.size(); ++i) {
    state_.flippers[i].energized = actuation_[i]->energized(t);
    driver_board_.set_end_of_stroke(static_cast<int>(i),
                                    state_.flippers[i].theta_rad >= board_.flippers[i].theta_max_rad);
  }
}

void SimWorld::idle(double duration_s) {
  const double end_s = state_.time_s + duration_s;
  while (state_.time_s < end_s) {
    drive_flippers();
    world_->step(state_);
    camera_.observe(state_);
  }
}

bool SimWorld::all_coils_off() const {
  for (std::size_t i = 0; i < actuation_.size(); ++i) {
    if (driver_board_.coil(static_cast<int>(i)).state != firmware::CoilState::kOff) return false;
  }
  return true;
}

bool SimWorld::step(GameEvent* events, int& n) {
  n = 0;
  if (!ball_active_) {
    if (ball_ >= options_.balls) return false;
    start_ball();
    events[n++] = GameEvent{GameEvent::kLaunch, ball_, state_.time_s, 0.0, 0.0};
  }
  drive_flippers();
  const double score_before = state_.score;
  const sim::StepEvents ev = world_->step(state_);
  camera_.observe(state_);
  const double ball_time = state_.time_s - ball_t0_s_;
  if (state_.score > score_before) {
    events[n++] = GameEvent{GameEvent::kScore, ball_, state_.time_s, state_.score - score_before, ball_time};
  }
  const bool lost = ev.has(sim::StepEvents::kBallLost);
  const bool cut = !lost && ball_time >= options_.max_ball_time_s - 0.5 * world_->dt_s();
  if (lost || cut) {
    if (cut) sim::cut_ball(board_, state_);
    SimBallResult r;
    r.score = state_.score - ball_score0_;
    r.duration_s = ball_time;
    r.flips = static_cast<int>(state_.flips - ball_flips0_);
    r.cut = cut;
    results_[finished_.load(std::memory_order_relaxed)] = r;
    finished_.fetch_add(1, std::memory_order_release);
    events[n++] = GameEvent{cut ? GameEvent::kBallCut : GameEvent::kBallLost, ball_, state_.time_s, r.score, ball_time};
    ++ball_;
    ball_active_ = false;
  } else if (sim::resting_in_launcher(board_, state_)) {
    world_->launch(state_, pull_);
  }
  return true;
}

}  // namespace pinball::simlab
