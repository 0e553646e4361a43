#pragma once
// The MuJoCo lab twin as a world (issue 19, design.md "Worlds and beliefs"):
// a 3-D steel ball that slides, rolls, spins and hops, rubber and rails,
// kickers that fire after a delay, flippers swung by a solenoid model
// (pulse, hold, rise time, return spring, bouncing stops) whose coil input is
// each flipper's `energized` (in pinballd: the VirtualDriverBoard's output).
// It was not written as our model; it plays the same board file with the
// same scoring rules (sim/game_rules.h), the same launch and the same ball
// seeds as the model worlds. How each board element maps to MuJoCo is in
// twin_model.h and docs/worlds.md.

#include <memory>
#include <string>

#include "pinball/core/geometry.h"
#include "pinball/sim/world.h"
#include "pinball/simlab/twin_model.h"
#include "pinball/simlab/twin_params.h"

namespace pinball::simlab {

/// The twin's ball in 3-D (board frame, z out of the playfield): what the
/// tests check and what GameState's 2-D record leaves out.
struct TwinBall {
  Vec3 position_m = Vec3::Zero();             ///< centre
  Vec3 velocity_mps = Vec3::Zero();           ///< centre's velocity
  Vec3 angular_velocity_rad_s = Vec3::Zero(); ///< spin (board frame)
};

/// The twin. Each object owns its MuJoCo model copy and data (a fork costs a
/// model copy, ~0.1 ms); the compiled prototype and the warning counters are
/// shared by all forks.
class TwinWorld final : public sim::World {
 public:
  /// Compiles the twin of `board` (borrowed: it must outlive every fork).
  /// dt_s: the world's step (0: the parameters' timestep), a whole number of
  /// MuJoCo steps. Throws std::invalid_argument for a board the twin cannot
  /// represent or a bad dt, std::runtime_error if MuJoCo refuses the model.
  TwinWorld(const table::Board& board, const TwinParams& params, double dt_s = 0.0);
  ~TwinWorld() override;
  TwinWorld(const TwinWorld&) = delete;
  TwinWorld& operator=(const TwinWorld&) = delete;

  const table::Board& board() const override;
  double dt_s() const override;
  sim::StepEvents step(sim::GameState& state) override;
  void launch(sim::GameState& state, double pull) override;
  std::unique_ptr<sim::World> fork() const override;
  std::string_view name() const override { return "twin"; }
  sim::WorldWarnings warnings() const override;

  /// The ball in 3-D now.
  TwinBall ball() const;
  /// Puts the ball at `ball` (in play) and makes `state` say so: for tests
  /// that start from a chosen state rather than a launch.
  void place_ball(sim::GameState& state, const TwinBall& ball);
  /// The ball's mechanical energy now: kinetic (translation and spin) plus
  /// potential in the tilted gravity, zero at the board's origin (J).
  double ball_energy_j() const;
  /// The parameters and the generated model text.
  const TwinParams& params() const;
  const TwinModelText& model_text() const;
  /// MuJoCo steps per step().
  int substeps() const;

 private:
  struct Shared;
  struct Impl;
  explicit TwinWorld(std::shared_ptr<const Shared> shared);
  static std::shared_ptr<const Shared> build(const table::Board& board, const TwinParams& params, double dt_s);
  std::shared_ptr<const Shared> shared_;
  std::unique_ptr<Impl> impl_;
};

/// make_world's entry: a TwinWorld.
std::unique_ptr<sim::World> make_twin_world(const table::Board& board, const TwinParams& params, double dt_s = 0.0);

/// The contact softness that gives restitution `e` (normal speed out / in)
/// in bounces lasting about `contact_duration_s`, at MuJoCo step
/// `timestep_s`: a damping ratio ζ with e = exp(−πζ/√(1 − ζ²)) and a time
/// constant duration/(πζ) (MuJoCo's spring has natural frequency
/// 1/(timeconst·ζ)), with ζ refined by simulating a ball striking a wall
/// (bisection), because the step's discretisation and the unilateral contact
/// letting go early move the closed form's answer. e in [0, 0.95]; memoised.
TwinSolref twin_solref_for_restitution(double e, double contact_duration_s, double timestep_s);

/// Restitution of a ball striking a wall with contact `solref`, measured the same way.
double twin_restitution_of(const TwinSolref& solref, double timestep_s);

/// The MuJoCo library's version ("2.2.2").
std::string mujoco_version();

}  // namespace pinball::simlab
