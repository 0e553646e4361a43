#pragma once
// A controller playing the simulator the way it will play the real table:
// it sees only what the camera model and the flipper contact sensors report,
// never the simulator's ball state (thesis 4.1), and answers with solenoid
// commands. The fast loop of the design: no threads, no pixels.

#include <array>
#include <cstdint>

#include "pinball/control/flipper_controller.h"
#include "pinball/control/spastic_controller.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/track/camera_model.h"
#include "pinball/track/tracker.h"

namespace pinball::simlab {

/// Any FlipperController behind a simulated camera and the tracker.
class SimulatedPlayer {
 public:
  /// Borrows `controller` (it must outlive the player). Throws
  /// std::invalid_argument for a board without a left and a right flipper or
  /// a bad camera setting. `tracker` overrides the tracker settings derived
  /// from the board and camera (e.g. a miscalibrated g).
  SimulatedPlayer(const table::Board& board, const track::CameraModelConfig& camera, control::FlipperController& controller,
                  std::uint64_t seed);
  SimulatedPlayer(const table::Board& board, const track::CameraModelConfig& camera, const track::TrackerConfig& tracker,
                  control::FlipperController& controller, std::uint64_t seed);

  /// One simulation step: expose the camera, feed delivered observations to
  /// the tracker and the controller, and set the flipper commands in `state`.
  void act(sim::GameState& state);

  /// The latest tracker output (for traces and tests).
  const track::TrackerOutput& last_output() const { return last_; }
  /// Observations processed.
  std::uint64_t observations() const { return observations_; }
  /// The tracker (its counters and the noise it has measured, for reports and tests).
  const track::Tracker& tracker() const { return tracker_; }
  /// Board flipper index of tracker flipper f (track::kLeftFlipper / kRightFlipper).
  int board_index(int f) const { return board_index_[static_cast<std::size_t>(f)]; }

 private:
  const table::Board& board_;
  track::CameraModel camera_;
  track::Tracker tracker_;
  control::FlipperController& controller_;
  std::array<int, 2> board_index_{};  // tracker flipper -> board flipper
  std::array<bool, 2> energized_{};
  bool ball_was_in_play_ = false;
  track::TrackerOutput last_;
  std::uint64_t observations_ = 0;
};

/// The spastic flipper behind a simulated camera and the tracker.
class SimulatedSpasticPlayer {
 public:
  /// Throws std::invalid_argument for a board without a left and a right
  /// flipper or a bad camera setting.
  SimulatedSpasticPlayer(const table::Board& board, const track::CameraModelConfig& camera,
                         const control::SpasticConfig& spastic, std::uint64_t seed)
      : spastic_(spastic), player_(board, camera, spastic_, seed) {}

  SimulatedSpasticPlayer(const SimulatedSpasticPlayer&) = delete;
  SimulatedSpasticPlayer& operator=(const SimulatedSpasticPlayer&) = delete;

  /// One simulation step (see SimulatedPlayer::act).
  void act(sim::GameState& state) { player_.act(state); }
  /// The latest tracker output (for traces and tests).
  const track::TrackerOutput& last_output() const { return player_.last_output(); }
  /// Observations processed.
  std::uint64_t observations() const { return player_.observations(); }

 private:
  control::SpasticController spastic_;
  SimulatedPlayer player_;
};

}  // namespace pinball::simlab
