#pragma once
// A world plays a table (design.md, "Worlds and beliefs"): it advances time,
// moves the ball and the flippers, takes the flipper coils as input and shows
// itself only through what a camera, the contact switches and the game's
// events would show. The thesis model on the thesis stepper and on the event
// stepper are two worlds (model_world.h); the MuJoCo twin is another. What
// plays a world (the ball runner, the fast learning loop, the daemon's
// simulator thread, the simulated camera and lab) sees only this interface,
// so any world can stand in for the table while the tracker and the controller
// keep their own belief of it.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "pinball/core/name_value.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/step_events.h"
#include "pinball/table/board.h"

namespace pinball::sim {

/// Which integrator plays the thesis model.
enum class StepperKind : std::uint8_t {
  kThesis,  ///< fixed-step semi-implicit Euler (thesis Ch. 3)
  kEvent,   ///< exact event-driven stepper
};

/// Trouble a world met while playing, counted and reported, never silent
/// (the twin's MuJoCo warnings; the model worlds have none). A world and all
/// its forks share one set of counters, so the world a command built reports
/// every ball its forks played.
struct WorldWarnings {
  std::uint64_t penetration = 0;  ///< contacts deeper than the world's limit (a ball pushed into an obstacle)
  std::uint64_t instability = 0;  ///< bad positions, velocities or accelerations the engine reset
  std::uint64_t overflow = 0;     ///< contact or constraint buffers full
  std::uint64_t total() const { return penetration + instability + overflow; }

  /// The counts as every report spells them (core/json_write_archive.h, json_read_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(penetration));
    a->Visit(PINBALL_NVP(instability));
    a->Visit(PINBALL_NVP(overflow));
  }
};

/// For text reports: "3 warnings (3 deep contacts, 0 instabilities, 0 overflows)".
std::string describe(const WorldWarnings& warnings);

/// The thing that plays a table. One object per game in progress (a world may
/// keep state of its own beside the GameState, as the twin does); fork() makes
/// another for another ball or thread, sharing what never changes.
class World {
 public:
  virtual ~World() = default;

  /// The table as this world plays it: its truth, which a belief may not share.
  virtual const table::Board& board() const = 0;
  /// Simulated time one step() advances (s).
  virtual double dt_s() const = 0;
  /// Advances `state` by exactly dt_s(). Input: each flipper's coil,
  /// state.flippers[i].energized. Output: the ball, the flippers' angles and
  /// contact switches, sensors, score, and the step's game events.
  virtual StepEvents step(GameState& state) = 0;
  /// Puts the ball in the launcher and launches it with pull fraction `pull`.
  virtual void launch(GameState& state, double pull) = 0;
  /// A world of the same kind and settings for another game (another ball or
  /// thread): no history, shares everything that is immutable.
  virtual std::unique_ptr<World> fork() const = 0;
  /// Short name for reports and errors: "thesis", "event", "twin".
  virtual std::string_view name() const = 0;
  /// Warnings of this world and all its forks so far (thread-safe).
  virtual WorldWarnings warnings() const { return {}; }
};

/// Parses "thesis" or "event"; throws std::invalid_argument naming the value otherwise.
StepperKind parse_stepper_kind(std::string_view name);
/// "thesis" or "event".
std::string_view stepper_kind_name(StepperKind kind);

/// A world and a belief must agree on which flippers exist, in which order and
/// on which side (the coils are wired by index); everything else may differ.
/// Throws std::invalid_argument naming both boards otherwise.
void check_same_flippers(const table::Board& world, const table::Board& belief);

}  // namespace pinball::sim
