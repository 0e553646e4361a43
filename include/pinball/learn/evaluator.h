#pragma once
// The fast learning loop of the design: simulator -> camera model -> tracker
// -> action function -> flipper commands (with an actuation delay), no
// threads, no pixels. One ball per call, fully determined by the controller
// and the ball's seed, so balls can be played on any thread in any order.

#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "pinball/control/controller_file.h"
#include "pinball/core/rng.h"
#include "pinball/control/flipper_controller.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/simlab/simulated_player.h"
#include "pinball/simlab/delay_line.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/table/board.h"
#include "pinball/sim/world.h"
#include "pinball/track/camera_model.h"

namespace pinball::learn {

/// One flip opportunity's reward (thesis 6.3.1).
struct Opportunity {
  int partition = -1;  ///< the responsible minicontroller
  double value = 0.0;  ///< score until the next opportunity, or −loss_penalty when the ball was lost
};

/// Outcome of one ball.
struct BallOutcome {
  double score = 0.0;       ///< points scored by this ball
  double duration_s = 0.0;  ///< simulated time of the ball (s)
  int flips = 0;            ///< flipper activations
  bool cut = false;         ///< still alive at the time limit: a cycle
  std::vector<Opportunity> opportunities;  ///< per flip opportunity, in order
};

/// A source of balls played by a controller: the pinball evaluator, or a toy
/// objective in the tests. play() must be safe to call from several threads at once.
class BallObjective {
 public:
  virtual ~BallObjective() = default;
  /// Plays one ball with controller `spec`; the same (spec, seed) gives the same outcome.
  virtual BallOutcome play(const control::ControllerSpec& spec, std::uint64_t ball_seed) const = 0;
  /// A controller of the right shape (partition) to start a search from; its gains are to be replaced.
  virtual control::ControllerSpec prototype() const = 0;
};

/// Settings of the pinball evaluator.
struct EvaluatorConfig {
  track::CameraModelConfig camera;     ///< the camera the tracker believes it sees through
  /// The camera the world really has (latency, noise) when it is not the
  /// believed one (`learn --randomize`); empty: `camera`.
  std::optional<track::CameraModelConfig> world_camera;
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;    ///< command to flipper motion (s): the solenoid's rise
  double max_ball_time_s = 60.0;       ///< a ball alive after this is cut and reported as a cycle
  double loss_penalty = 500.0;         ///< reward of an opportunity that ended with the ball lost (6.3.1)
  double gravity_scale = 1.0;          ///< tracker's g / board's g (1: calibrated)
  double dt_s = 0.0;                   ///< stepper time step; 0: the board's
  int angle_partitions = 4;            ///< k of prototype()
  bool partition_by_h = false;         ///< prototype(): also split each angle bin at the middle of the V (7.1)
  bool rolling_minicontrollers = false;///< prototype(): separate rolling minicontrollers (7.1)
};

/// The camera model's noise seed for a ball: every player that watches ball
/// `ball_seed` through the camera sees the same noise.
inline std::uint64_t camera_seed(std::uint64_t ball_seed) { return ball_seed ^ 0x5DEECE66Dull; }

/// One ball of the fast loop: `state` (made for ball `ball_seed`) played in
/// `world` by `controller` behind the camera model and the tracker, which
/// believe the table is `belief`; its commands reach the flippers
/// `actuation_delay_s` later. `observer(state, events)` sees every step.
template <class Observer>
sim::BallResult play_through_tracker(sim::World& world, const table::Board& belief, sim::GameState& state,
                                     const track::CameraModelConfig& camera, const track::TrackerConfig& tracker,
                                     control::FlipperController& controller, double actuation_delay_s,
                                     const sim::BallLimits& limits, std::uint64_t ball_seed, Observer&& observer) {
  simlab::SimulatedPlayer player(belief, camera, tracker, controller, camera_seed(ball_seed));
  simlab::DelayLine delay(world.board().flippers.size(), actuation_delay_s);
  return sim::play_ball(
      world, state, limits,
      [&](sim::GameState& s) {
        player.act(s);
        delay.apply(s);
      },
      std::forward<Observer>(observer));
}

/// Plays balls in a world through the camera model and the tracker, which
/// believe the table is a board (by default the world is that board's model).
class PinballEvaluator final : public BallObjective {
 public:
  /// The world is the model of `board` on the thesis stepper at config.dt_s.
  /// Borrows the board. Throws std::invalid_argument for bad settings.
  PinballEvaluator(const table::Board& board, const EvaluatorConfig& config);
  /// Plays in `world` (each ball in a fork of it) while the tracker and the
  /// controller believe `belief`. Throws std::invalid_argument for bad
  /// settings or a world whose flippers are not the belief's.
  PinballEvaluator(const table::Board& belief, const EvaluatorConfig& config, std::unique_ptr<sim::World> world);

  BallOutcome play(const control::ControllerSpec& spec, std::uint64_t ball_seed) const override;
  control::ControllerSpec prototype() const override;

  /// Plays one ball with any flipper controller (the baselines); `pull` < 0 takes the board's.
  BallOutcome play_with(control::FlipperController& controller, double pull, std::uint64_t ball_seed) const;

  /// The settings, the belief and the world.
  const EvaluatorConfig& config() const { return config_; }
  const table::Board& board() const { return board_; }
  const sim::World& world() const { return *world_; }

 private:
  BallOutcome run(control::FlipperController& controller, const control::ActuatorController* actuator, double pull,
                  std::uint64_t seed) const;

  const table::Board& board_;
  EvaluatorConfig config_;
  std::unique_ptr<sim::World> world_;  // forked per ball
};

}  // namespace pinball::learn
