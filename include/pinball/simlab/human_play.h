#pragma once
// A person at the flippers (`pinball play`, issue "Seeing the game"): the
// session owns the game state, takes key presses and releases, and steps the
// world at its own dt until simulated time catches up with the wall clock.
// It knows no window and no clock: the command feeds it keys (from the
// keyboard or a script) and the time, so tests drive it directly.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pinball/core/name_value.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/world.h"

namespace pinball::simlab {

/// The player's three buttons.
enum class Key : std::uint8_t {
  kLeftFlipper,   ///< every left flipper's coil while held
  kRightFlipper,  ///< every right flipper's coil while held
  kLaunch,        ///< pull and release the plunger (a press launches; release does nothing)
};

/// One key event at a session time (s).
struct KeyEvent {
  double t_s = 0.0;  ///< session time (simulated seconds since the session began)
  Key key = Key::kLaunch;
  bool down = true;  ///< true: pressed; false: released
};

/// The latest time a key script may name (s): a day of play.
inline constexpr double kMaxKeyScriptTime_s = 86400.0;

/// Parses a key script: comma- or newline-separated "T:ACTION" with T in
/// session seconds (non-decreasing, at most kMaxKeyScriptTime_s) and ACTION one of launch, left-down,
/// left-up, right-down, right-up, left (a 0.1 s tap), right (a 0.1 s tap).
/// Throws std::invalid_argument naming the entry and what is wrong.
std::vector<KeyEvent> parse_key_script(const std::string& text);

/// Settings of a session.
struct PlayConfig {
  std::uint64_t seed = 1;            ///< launch noise
  double max_ball_time_s = 300.0;    ///< a ball still in play after this is cut (s)
  double pull = -1.0;                ///< launcher pull fraction; negative: the board's
  int max_steps_per_advance = 0;     ///< most steps one advance_to takes; 0: 0.1 s worth of steps
};

/// A ball the player finished.
struct PlayedBall {
  double score = 0.0;       ///< points scored during the ball
  double duration_s = 0.0;  ///< simulated time from its first launch to its loss or cut (s)
  int launches = 0;         ///< launches (a ball back in the chute is launched again by the key)
  bool cut = false;         ///< stopped at max_ball_time_s rather than lost

  /// The fields as reports spell them (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(score));
    a->Visit(PINBALL_NVP(duration_s));
    a->Visit(PINBALL_NVP(launches));
    a->Visit(PINBALL_NVP(cut));
  }
};

/// What a session did so far.
struct PlayCounters {
  std::uint64_t steps = 0;          ///< world steps
  std::uint64_t advances = 0;       ///< advance_to calls
  std::uint64_t fell_behind = 0;    ///< advance_to calls that hit the step cap and dropped the rest
  double dropped_s = 0.0;           ///< wall time dropped that way (s): the game ran that much slow
  std::uint64_t key_events = 0;     ///< presses and releases taken

  /// The counters as reports spell them (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(steps));
    a->Visit(PINBALL_NVP(advances));
    a->Visit(PINBALL_NVP(fell_behind));
    a->Visit(PINBALL_NVP(dropped_s));
    a->Visit(PINBALL_NVP(key_events));
  }
};

/// One person's game on one world.
class PlaySession {
 public:
  /// Borrows `world` for the session's life; a fresh game, the ball in the launcher.
  PlaySession(sim::World& world, const PlayConfig& config);

  /// A key went down or up (repeats of a held key are ignored).
  void key(Key k, bool down);
  void press(Key k) { key(k, true); }
  void release(Key k) { key(k, false); }
  /// True while `k` is held.
  bool held(Key k) const { return held_[static_cast<int>(k)]; }

  /// Steps the world while a whole step fits before session time `t_s`
  /// (never past it), at most max_steps_per_advance steps; the backlog beyond
  /// that is dropped and counted (fell_behind, dropped_s) so a stall cannot
  /// spiral. Returns the steps taken.
  int advance_to(double t_s);
  /// The session time that wall time `wall_s` (s since the session began)
  /// stands for: the wall time less what was dropped.
  double session_time_for_wall(double wall_s) const { return wall_s - counters_.dropped_s; }
  /// Session time (simulated s since the session began).
  double time_s() const { return time_s_; }

  /// True while a ball is on the table (launched, neither lost nor cut).
  bool ball_in_play() const { return in_ball_; }
  /// The game as the window draws it.
  const sim::GameState& state() const { return state_; }
  /// Balls finished so far, in order.
  const std::vector<PlayedBall>& balls() const { return balls_; }
  /// What the session did.
  const PlayCounters& counters() const { return counters_; }
  /// The world's simulated time per step (s).
  double dt_s() const { return world_.dt_s(); }

 private:
  void launch();
  void set_coils(Key flipper_key, bool energized);
  void step();
  void end_ball(bool cut);

  sim::World& world_;
  PlayConfig config_;
  sim::GameState state_;
  bool held_[3] = {false, false, false};
  bool in_ball_ = false;
  double ball_t0_s_ = 0.0;
  double score_before_ = 0.0;
  int launches_ = 0;
  double time_s_ = 0.0;
  int max_steps_ = 1;
  std::vector<PlayedBall> balls_;
  PlayCounters counters_;
};

/// Feeds `session` the script's events from index `next` whose time is at or
/// before `t_s`, advancing the session to each event's time first, then
/// advances it to `t_s`. Returns the index of the first event not yet fed.
std::size_t play_script_until(PlaySession& session, const std::vector<KeyEvent>& script, std::size_t next, double t_s);

}  // namespace pinball::simlab
