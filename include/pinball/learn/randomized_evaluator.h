#pragma once
// Learning that does not overfit one world (issue 20): every ball is played
// in a world drawn from ranges a user states (or takes from `pinball
// identify`'s uncertainties): g, wall ρ, flipper μ, pivots, rest angle, the
// solenoid's delay, the camera's latency and noise, and which stepper plays
// the model. The tracker and the controller keep believing the nominal table
// and camera, as they will on the real one. The worlds are drawn once, when
// the evaluator is made (building a model world builds its stepper's grids),
// and each ball plays the one its seed picks, so a ball's outcome still
// depends only on the controller and the seed, on any thread.
// File format: docs/learning.md, "Learning across worlds".

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pinball/core/name_value.h"
#include "pinball/learn/evaluator.h"
#include "pinball/learn/world_perturbation.h"
#include "pinball/sim/world.h"

namespace pinball::learn {

/// [low, high] of one perturbation, in its unit (world_perturbation.h).
using PerturbationRange = std::optional<std::array<double, 2>>;

/// A randomization file: how many worlds, and the range of each perturbation
/// (keys are perturbation_name(); a missing key leaves that thing nominal).
struct Randomization {
  std::string source;              ///< the file (not a key)
  int variants = 32;               ///< worlds drawn; each ball plays one
  std::uint64_t seed = 1;          ///< draws of the worlds
  double event_stepper_share = 0.0;///< fraction of the worlds played by the event stepper instead of the thesis one
  struct Ranges {
    PerturbationRange pivot_y_mm, theta_min_deg, flipper_mu_pct, wall_rho, gravity_pct, actuation_delay_ms,
        camera_latency_ms, camera_noise_px;
    template <class Archive>
    void Serialize(Archive* a) {
      a->Visit(PINBALL_NVP(pivot_y_mm));
      a->Visit(PINBALL_NVP(theta_min_deg));
      a->Visit(PINBALL_NVP(flipper_mu_pct));
      a->Visit(PINBALL_NVP(wall_rho));
      a->Visit(PINBALL_NVP(gravity_pct));
      a->Visit(PINBALL_NVP(actuation_delay_ms));
      a->Visit(PINBALL_NVP(camera_latency_ms));
      a->Visit(PINBALL_NVP(camera_noise_px));
    }
  } ranges;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(variants));
    a->Visit(PINBALL_NVP(seed));
    a->Visit(PINBALL_NVP(event_stepper_share));
    a->Visit(PINBALL_NVP(ranges));
  }

  /// The range of `p`, as the file gives it.
  const PerturbationRange& range(Perturbation p) const;
};

/// Reads a randomization file. Throws KeyError "path:key: ..." for a missing
/// variants, seed, event_stepper_share or ranges key, an unknown or repeated
/// key, a range that is not [low, high] with low ≤ high, variants outside
/// [1, 1024], a share outside [0, 1]; std::runtime_error when the file
/// cannot be read or parsed.
Randomization load_randomization(const std::string& path);
/// Parses YAML text; `name` stands for the file in messages.
Randomization parse_randomization(const std::string& text, const std::string& name);

/// One drawn world: its table and world-side settings, and its stepper.
struct DrawnWorld {
  WorldSettings settings;                       ///< the perturbed table, delay and camera
  sim::StepperKind stepper = sim::StepperKind::kThesis;
  std::vector<std::pair<Perturbation, double>> values;  ///< what was drawn
};

/// Draws `randomization.variants` worlds around the nominal belief, delay and
/// camera. Throws std::invalid_argument naming the file when a draw is no table
/// (a rest stop turned past the up stop).
std::vector<DrawnWorld> draw_worlds(const table::Board& belief, const EvaluatorConfig& config,
                                    const Randomization& randomization);

/// Which of `variants` drawn worlds ball `ball_seed` plays (every learner of
/// a randomization picks by this rule, so a ball's world depends only on its seed).
std::size_t drawn_world_index(std::uint64_t ball_seed, std::size_t variants);

/// Plays each ball in the drawn world its seed picks, believing the nominal table.
class RandomizedEvaluator final : public BallObjective {
 public:
  /// Draws the worlds (draw_worlds) and builds them; borrows `belief`.
  RandomizedEvaluator(const table::Board& belief, const EvaluatorConfig& config, const Randomization& randomization);

  BallOutcome play(const control::ControllerSpec& spec, std::uint64_t ball_seed) const override;
  control::ControllerSpec prototype() const override;

  /// Which world ball `ball_seed` plays.
  std::size_t world_of(std::uint64_t ball_seed) const;
  /// The drawn worlds, in order.
  const std::vector<DrawnWorld>& worlds() const { return drawn_; }

 private:
  std::vector<DrawnWorld> drawn_;                       // their boards outlive the evaluators
  std::vector<std::unique_ptr<PinballEvaluator>> evaluators_;
};

}  // namespace pinball::learn
