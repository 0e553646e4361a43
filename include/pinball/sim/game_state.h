#pragma once
// The dynamic state of a game (thesis 3.2.5): everything that changes while
// the static Board stays fixed. Sized once from the board; stepping it never
// allocates.

#include <cstdint>
#include <vector>

#include "pinball/core/geometry.h"
#include "pinball/core/rng.h"
#include "pinball/table/board.h"

namespace pinball::sim {

/// Ball position and velocity in the board frame.
struct BallState {
  Vec2 position_m = Vec2::Zero();     ///< centre (m)
  Vec2 velocity_mps = Vec2::Zero();   ///< velocity (m/s)
  double height_m = 0.0;              ///< lowest point above the playfield (m): 0 on it; the twin's ball hops
};

/// One flipper's moving parts and its solenoid command.
struct FlipperState {
  double theta_rad = 0.0;    ///< current elevation (rad)
  double omega_rad_s = 0.0;  ///< angular velocity over the last step (rad/s); 0 at a stop
  bool energized = false;    ///< solenoid command: true raises the flipper
  bool ball_contact = false; ///< contact sensor: the ball touches the flipper (thesis 4.1.2)
  bool was_energized = false; ///< command during the previous step (to count button presses)
};

/// Values of GameState::visible.
enum Visibility : std::uint8_t {
  kHidden = 0,   ///< cannot be hit (a fallen flag, a hidden obstacle)
  kVisible = 1,  ///< can be hit
  kRising = 2,   ///< a flag whose bank reset while the ball lay on it: rises once the ball has left
};

/// Everything that changes during a game.
struct GameState {
  double time_s = 0.0;                 ///< simulated time since the game started (s)
  std::uint64_t steps = 0;             ///< integration steps taken (step() calls)
  std::uint64_t events = 0;            ///< events handled by the event stepper (impacts, stops, entries, ...)
  std::uint64_t flips = 0;             ///< flipper activations (rising edges of a command)
  BallState ball;                      ///< the ball
  bool ball_in_play = false;           ///< false while the ball waits in the launcher or is lost
  int balls_left = 0;                  ///< balls left in this game, including the one in play
  double score = 0.0;                  ///< points this game
  std::vector<FlipperState> flippers;  ///< same index as Board::flippers
  std::vector<std::uint8_t> visible;   ///< per obstacle: a Visibility (banks, thesis 3.4)
  int rising_flags = 0;                ///< obstacles in state kRising
  std::vector<std::uint8_t> sensor_inside;  ///< per sensor: 1 while the ball is on it
  Rng rng;                             ///< launch and kickout noise; part of the state so runs replay bit for bit
};

/// A fresh game: flippers down, all obstacles at their initial visibility, the
/// ball waiting in the launcher, balls_left = board.balls_per_game.
GameState make_game_state(const table::Board& board, std::uint64_t seed);

/// Resets score, balls, visibility and flippers for a new game on the same
/// state object (keeps the random stream going; allocates nothing).
void reset_game(const table::Board& board, GameState& state);

/// Places the ball in the launcher and launches it with pull fraction `pull`
/// (thesis 3.3.1): v = (0, pull·(1 − R)·speed_max), R ~ U[0, noise_max].
/// On a board with a `start` the ball is served there instead, with the
/// start's velocity (no noise, no random draw; `pull` is ignored).
void launch_ball(const table::Board& board, GameState& state, double pull);

}  // namespace pinball::sim
