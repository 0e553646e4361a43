#pragma once
// What a hit or a sensor entry does to the game (thesis 3.3.2, 3.4): shared by
// every world (the thesis and event steppers, the MuJoCo twin) so that worlds
// differ only in their physics, never in their scoring.

#include <cstdint>
#include <span>
#include <vector>

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/step_events.h"

namespace pinball::sim::rules {

/// The ball is lost: back to the launcher, out of play, one ball fewer.
void lose_ball(const table::Board& board, GameState& state, StepEvents& events);

/// Raises the flags waiting in state kRising whose shape is at least clear_m
/// from the ball (a flag never rises into the ball).
void raise_flags(const table::Board& board, GameState& state, double clear_m);

/// What striking obstacle `index` does to the game, its physics aside: the
/// score, the bank flag falling (and the bank's bonus), the ball eaten.
/// clear_m as for raise_flags. The twin calls this; its contacts are its own.
void score_obstacle_hit(const table::Board& board, GameState& state, std::int32_t index, StepEvents& events,
                        double clear_m);

/// Slower than this along the contact normal, the ball rests or rolls on an
/// obstacle rather than striking it (m/s): a real switch does not close, and
/// the twin, which scores a contact only when it begins, never scores it.
/// The steppers meet a resting ball every step or two (gravity feeds it
/// about g·dt, 0.6 mm/s, between contacts), so without this a ball balanced
/// on the caret's apex scored 200 points a contact, 185 000 a second. The
/// speed a ball gains falling 0.2 mm.
inline constexpr double kMinStrikeSpeed_mps = 0.02;

/// The ball strikes obstacle `index` with contact normal `normal`: reflection
/// with ρ, the kick, then score_obstacle_hit if it struck at
/// kMinStrikeSpeed_mps or more (an eating obstacle eats at any speed).
/// clear_m as for raise_flags.
void hit_obstacle(const table::Board& board, GameState& state, std::int32_t index, const Vec2& normal,
                  StepEvents& events, double clear_m);

/// A hole's kickout velocity: the nominal one turned by U[−spread, spread]
/// and scaled by 1 − U[0, noise], drawn from `rng` (the game's stream).
Vec2 kickout_velocity(const table::Sensor& sensor, Rng& rng);

/// The ball entered sensor `index`: score, eat, or the hole's kickout.
void fire_sensor(const table::Board& board, GameState& state, std::int32_t index, StepEvents& events);

/// Reads a flipper's command at the start of a step: counts a press (rising
/// edge) in `flips`, remembers the command, and returns the commanded θ̇
/// (+θ̇₀ energised, −θ̇₀ released).
double take_command(const table::Flipper& f, FlipperState& fs, std::uint64_t& flips);

/// True while a ball of radius r at p is on the sensor (touching it; for a
/// hole, its centre inside).
bool on_sensor(const table::Sensor& sensor, const Vec2& p, double r);

/// True when a ball of radius r moving straight from `from` to `to` touched
/// the sensor on the way: swept, so that a fast ball cannot skip one.
bool swept_onto_sensor(const table::Sensor& sensor, const Vec2& from, const Vec2& to, double r);

/// The flippers' contact sensors (ball within touch_m of the segment) and the
/// contact scores (rate·dt for each listed obstacle within touch_m) at the
/// ball's current position.
void update_contacts(const table::Board& board, GameState& state, std::span<const std::int32_t> candidates, double touch_m,
                     double dt_s, bool has_contact_score, StepEvents& events);

/// Whether any obstacle pays for contact time.
bool has_contact_score(const table::Board& board);

/// The sensors' shapes, same index as Board::sensors (for a sensor grid).
std::vector<table::Shape> sensor_shapes(const table::Board& board);

/// 0, 1, ..., n − 1 (the candidate list of a linear scan).
std::vector<std::int32_t> all_indices(std::size_t n);

}  // namespace pinball::sim::rules
