#include "pinball/learn/evaluator.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include "pinball/control/actuator_controller.h"
#include "pinball/sim/model_world.h"
#include "pinball/learn/planning_controller.h"

namespace pinball::learn {

namespace {

sim::ModelWorldOptions world_options(const EvaluatorConfig& c) {
  sim::ModelWorldOptions o;
  o.dt_s = c.dt_s;
  return o;
}

// Wraps the controller and books flip opportunities (thesis 6.3.1): an
// opportunity opens with the first hittable projection after a launch, is
// charged to the latest responsible partition, and earns the score until the
// next one opens, or −penalty if the ball is lost first.
class OpportunityBook final : public control::FlipperController {
 public:
  OpportunityBook(control::FlipperController& inner, const control::ActuatorController* actuator,
                  const double& score, std::vector<Opportunity>& out)
      : inner_(inner), actuator_(actuator), score_(score), out_(out) {}

  void update(const track::TrackerOutput& o, double now_s, std::array<bool, 2>& energized) override {
    inner_.update(o, now_s, energized);
    if (actuator_ == nullptr) return;
    if (o.launch.launched || o.launch.lost) {
      approach_open_ = false;
      return;
    }
    const int p = actuator_->responsible_partition();
    if (o.projection.valid && o.projection.hittable && p >= 0) {
      if (!approach_open_) {
        if (active_) out_.push_back({partition_, score_ - start_});
        active_ = true;
        approach_open_ = true;
        start_ = score_;
      }
      partition_ = p;
    }
  }
  void reset(std::array<bool, 2>& energized) override {
    inner_.reset(energized);
    approach_open_ = false;
  }
  void finish(bool lost, double penalty) {
    if (active_) out_.push_back({partition_, lost ? -penalty : score_ - start_});
    active_ = false;
  }

 private:
  control::FlipperController& inner_;
  const control::ActuatorController* actuator_;
  const double& score_;
  std::vector<Opportunity>& out_;
  bool active_ = false;
  bool approach_open_ = false;
  int partition_ = -1;
  double start_ = 0.0;
};

}  // namespace

PinballEvaluator::PinballEvaluator(const table::Board& board, const EvaluatorConfig& config)
    : PinballEvaluator(board, config, sim::make_model_world(board, world_options(config))) {}

PinballEvaluator::PinballEvaluator(const table::Board& belief, const EvaluatorConfig& config,
                                   std::unique_ptr<sim::World> world)
    : board_(belief), config_(config), world_(std::move(world)) {
  if (world_ == nullptr) throw std::invalid_argument("evaluator: no world");
  sim::check_same_flippers(world_->board(), belief);
  if (!(config.actuation_delay_s >= 0.0 && config.actuation_delay_s < 1.0)) {
    throw std::invalid_argument("evaluator: actuation delay must be in [0, 1) s");
  }
  if (!(config.max_ball_time_s > 0.0)) throw std::invalid_argument("evaluator: max ball time must be > 0");
  if (!(config.gravity_scale > 0.0)) throw std::invalid_argument("evaluator: gravity scale must be > 0");
  if (!std::isfinite(config.loss_penalty)) throw std::invalid_argument("evaluator: loss penalty must be finite");
  track::CameraModel check(config.camera, 0);  // throws for a bad camera
  track::CameraModel check_world(config.world_camera.value_or(config.camera), 0);
  (void)check;
  (void)check_world;
}

control::ControllerSpec PinballEvaluator::prototype() const {
  control::ActionFunctionConfig c = control::uniform_partition(config_.angle_partitions);
  if (config_.partition_by_h) c.h_borders = {1.0};  // pivot to tip | beyond the tip towards the V's centre
  c.rolling_minicontrollers = config_.rolling_minicontrollers;
  control::ControllerSpec spec;
  spec.action_function = control::ActionFunction(c);
  return spec;
}

BallOutcome PinballEvaluator::play(const control::ControllerSpec& spec, std::uint64_t seed) const {
  const std::unique_ptr<control::FlipperController> controller = make_controller(spec, board_);
  double pull = spec.launcher_pull;
  if (spec.randomise_launch) {
    Rng rng(seed ^ 0xA5A5A5A5DEADBEEFull);
    pull = rng.uniform(spec.launch_pull_min, spec.launch_pull_max);
  }
  // Flip opportunities are booked per minicontroller: only the action function has them.
  return run(*controller, dynamic_cast<const control::ActuatorController*>(controller.get()), pull, seed);
}

BallOutcome PinballEvaluator::play_with(control::FlipperController& controller, double pull,
                                        std::uint64_t seed) const {
  return run(controller, nullptr, pull, seed);
}

BallOutcome PinballEvaluator::run(control::FlipperController& controller,
                                  const control::ActuatorController* actuator, double pull,
                                  std::uint64_t seed) const {
  BallOutcome outcome;
  const std::unique_ptr<sim::World> world = world_->fork();
  sim::GameState state = sim::make_game_state(world->board(), seed);
  OpportunityBook book(controller, actuator, state.score, outcome.opportunities);
  track::TrackerConfig tracker = track::default_tracker_config(board_, config_.camera);
  tracker.g_mps2 *= config_.gravity_scale;
  sim::BallLimits limits;
  limits.max_ball_time_s = config_.max_ball_time_s;
  limits.pull = pull;
  const sim::BallResult r =
      play_through_tracker(*world, board_, state, config_.world_camera.value_or(config_.camera), tracker, book,
                           config_.actuation_delay_s, limits, seed,
                           [](const sim::GameState&, const sim::StepEvents&) {});
  book.finish(!r.cut, config_.loss_penalty);
  outcome.score = r.score;
  outcome.duration_s = r.duration_s;
  outcome.flips = r.flips;
  outcome.cut = r.cut;
  return outcome;
}

}  // namespace pinball::learn
