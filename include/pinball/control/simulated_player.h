#pragma once
// A controller playing the simulator the way it will play the real table:
// it sees only what the camera model and the flipper contact sensors report,
// never the simulator's ball state (thesis 4.1), and answers with solenoid
// commands. The fast loop of the design: no threads, no pixels.

#include <array>
#include <cstdint>

#include "pinball/control/spastic_controller.h"
#include "pinball/sim/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/track/camera_model.h"
#include "pinball/track/tracker.h"

namespace pinball::control {

/// The spastic flipper behind a simulated camera and the tracker.
class SimulatedSpasticPlayer {
 public:
  /// Throws std::invalid_argument for a board without a left and a right
  /// flipper or a bad camera setting.
  SimulatedSpasticPlayer(const sim::Board& board, const track::CameraModelConfig& camera,
                         const SpasticConfig& spastic, std::uint64_t seed);

  /// One simulation step: expose the camera, feed delivered observations to
  /// the tracker, and set the flipper commands in `state`.
  void act(sim::GameState& state);

  /// The latest tracker output (for traces and tests).
  const track::TrackerOutput& last_output() const { return last_; }
  /// Observations processed.
  std::uint64_t observations() const { return observations_; }

 private:
  const sim::Board& board_;
  track::CameraModel camera_;
  track::Tracker tracker_;
  SpasticController spastic_;
  std::array<int, 2> board_index_{};  // tracker flipper -> board flipper
  std::array<bool, 2> energized_{};
  bool ball_was_in_play_ = false;
  track::TrackerOutput last_;
  std::uint64_t observations_ = 0;
};

}  // namespace pinball::control
