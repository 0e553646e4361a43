#include "pinball/sim/model_world.h"


namespace pinball::sim {
namespace {

// One world over a stepper that is shared by its forks (step() is const).
template <class Stepper>
class ModelWorld final : public World {
 public:
  ModelWorld(std::shared_ptr<const Stepper> stepper, std::string_view name)
      : stepper_(std::move(stepper)), name_(name) {}

  const table::Board& board() const override { return stepper_->board(); }
  double dt_s() const override { return stepper_->dt_s(); }
  StepEvents step(GameState& state) override { return stepper_->step(state); }
  void launch(GameState& state, double pull) override { launch_ball(stepper_->board(), state, pull); }
  std::unique_ptr<World> fork() const override { return std::make_unique<ModelWorld>(stepper_, name_); }
  std::string_view name() const override { return name_; }

 private:
  std::shared_ptr<const Stepper> stepper_;
  std::string_view name_;
};

}  // namespace

std::unique_ptr<World> make_model_world(const table::Board& board, const ModelWorldOptions& options) {
  if (options.stepper == StepperKind::kEvent) {
    EventStepperOptions o = options.event;
    if (options.dt_s != 0.0) o.dt_s = options.dt_s;
    return std::make_unique<ModelWorld<EventStepper>>(std::make_shared<const EventStepper>(board, o), "event");
  }
  ThesisStepperOptions o = options.thesis;
  if (options.dt_s != 0.0) o.dt_s = options.dt_s;
  return std::make_unique<ModelWorld<ThesisStepper>>(std::make_shared<const ThesisStepper>(board, o), "thesis");
}

}  // namespace pinball::sim
