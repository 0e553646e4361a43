#include "pinball/simlab/simulated_player.h"

namespace pinball::simlab {

SimulatedPlayer::SimulatedPlayer(const table::Board& board, const track::CameraModelConfig& camera,
                                 control::FlipperController& controller, std::uint64_t seed)
    : SimulatedPlayer(board, camera, track::default_tracker_config(board, camera), controller, seed) {}

SimulatedPlayer::SimulatedPlayer(const table::Board& board, const track::CameraModelConfig& camera,
                                 const track::TrackerConfig& tracker, control::FlipperController& controller,
                                 std::uint64_t seed)
    : board_(board),
      camera_(camera, seed),
      tracker_(track::flipper_geometry_from_board(board), tracker),
      controller_(controller),
      board_index_(table::flippers_by_side(board)) {}

void SimulatedPlayer::act(sim::GameState& state) {
  if (!state.ball_in_play) {
    if (ball_was_in_play_) {  // the ball is gone: forget it
      tracker_.reset();
      camera_.reset(state.time_s);
      controller_.reset(energized_);
    }
    ball_was_in_play_ = false;
  } else {
    ball_was_in_play_ = true;
    camera_.expose(state.time_s, state.ball.position_m);
    track::Observation obs;
    while (camera_.deliver(state.time_s, obs)) {
      const track::ContactSensors contacts{state.flippers[board_index_[track::kLeftFlipper]].ball_contact,
                                           state.flippers[board_index_[track::kRightFlipper]].ball_contact};
      last_ = tracker_.update(obs, contacts);
      controller_.update(last_, state.time_s, energized_);
      ++observations_;
    }
  }
  for (int f = 0; f < 2; ++f) state.flippers[board_index_[f]].energized = energized_[f];
}

}  // namespace pinball::simlab
