#pragma once
// The thesis's fixed-step integrator (Ch. 3): semi-implicit Euler with a speed
// clamp, earliest time of impact on the new velocity, reflection with ρ,
// flipper impulses and the flipper sweep. Choices the thesis leaves open are
// written down in docs/physics.md.

#include <cstdint>
#include <span>
#include <vector>

#include "pinball/table/board.h"
#include "pinball/sim/broadphase.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/step_events.h"

namespace pinball::sim {

/// Settings of the thesis stepper.
struct ThesisStepperOptions {
  double dt_s = 0.0;                  ///< time step (s); 0 takes the board's
  bool use_grid = true;               ///< false: test every obstacle each step (the baseline)
  double separation_m = 1e-6;         ///< gap left between ball and surface after a contact (thesis 3.3.2, fn. 3)
  double contact_tolerance_m = 5e-4;  ///< ball within this of a surface counts as touching (contact score, sensors)
};

/// Advances a GameState by fixed steps over a Board it borrows. Owns the
/// broadphase built for its time step. step() allocates nothing.
class ThesisStepper {
 public:
  /// Builds the grids. Throws std::invalid_argument if dt is not positive or
  /// violates the flipper condition l·sin(θ̇₀·dt/2) < r (thesis 3.3.3).
  explicit ThesisStepper(const table::Board& board, ThesisStepperOptions options = {});

  /// One step of dt: flippers, then the ball, then sensors and contact scores.
  StepEvents step(GameState& state) const;

  /// The time step (s).
  double dt_s() const { return options_.dt_s; }
  /// The board it steps.
  const table::Board& board() const { return board_; }
  /// The settings in force.
  const ThesisStepperOptions& options() const { return options_; }
  /// Obstacles the ball at p may touch within one step (the linear list when the grid is off).
  std::span<const std::int32_t> obstacle_candidates(const Vec2& p) const;
  /// The obstacle grid (for benchmarks and tests).
  const UniformGrid& obstacle_grid() const { return obstacle_grid_; }

 private:
  void update_flippers(GameState& state, StepEvents& events) const;
  void move_ball(GameState& state, StepEvents& events) const;
  void apply_obstacle_hit(GameState& state, std::int32_t index, const Vec2& normal, StepEvents& events) const;
  void update_sensors(GameState& state, const Vec2& from, StepEvents& events) const;
  void update_contacts(GameState& state, std::span<const std::int32_t> candidates, StepEvents& events) const;
  void lose_ball(GameState& state, StepEvents& events) const;
  /// Whether a flipper's sweep may not push the ball from `from` to `to`: an
  /// obstacle overlaps it there or lies across the way, or another flipper's
  /// blade overlaps it there. Then the flipper stalls.
  bool push_is_blocked(const GameState& state, std::size_t pusher, const Vec2& from, const Vec2& to) const;
  void raise_flags(GameState& state) const;

  const table::Board& board_;
  ThesisStepperOptions options_;
  double reach_m_ = 0.0;  // farthest a shape can be and still matter this step
  bool has_contact_score_ = false;
  UniformGrid obstacle_grid_;
  UniformGrid sensor_grid_;
  std::vector<std::int32_t> all_obstacles_;  // 0..n-1, for the linear scan
  std::vector<std::int32_t> all_sensors_;
  std::vector<table::Shape> sensor_shapes_;
};

}  // namespace pinball::sim
