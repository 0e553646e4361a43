#pragma once
// A recorded LCM log played into a ViewState: forward at any speed, paused,
// seeked to any time, stepped frame by frame. The whole log is read into
// memory once (bus::read_lcm_log checks it first); going back replays from
// the start, which is fast next to a person's reaction (about 10 ms per
// 100 000 events).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pinball/bus/lcm_log_format.h"
#include "pinball/view/view_state.h"

namespace pinball::view {

/// Plays a log into a view. Times are seconds from the log's first event, on
/// the daemon's own clock: each of its messages' utime (as the live view
/// reads them), not the log's event headers, which lcm-logger stamps on
/// receipt (an NTP step under it had put the end of a game before its
/// start). Another program's event takes the time of the event before it.
class LogPlayer {
 public:
  /// Takes the events of a log (file order; an event out of order is played
  /// at its place in the file). Throws std::invalid_argument for no events.
  explicit LogPlayer(std::vector<bus::LcmLogEvent> events, ViewStateOptions options = {});

  /// Time of the last event (s).
  double duration_s() const { return duration_s_; }
  /// Where the view stands (s): every event up to here is applied.
  double position_s() const { return position_s_; }
  /// Applies every event up to `t_s` (clamped to [0, duration]); going back
  /// starts again from the first event.
  void seek(double t_s);
  /// Moves to the next camera frame (PINBALL_OBSERVATION) after the position;
  /// false at the end.
  bool step_frame_forward();
  /// Moves to the camera frame before the current one; false at the start.
  bool step_frame_back();
  /// The view at the position.
  const ViewState& state() const { return state_; }
  /// Events in the log.
  std::size_t events() const { return events_.size(); }

 private:
  double time_of(std::size_t i) const;

  std::vector<bus::LcmLogEvent> events_;
  std::vector<double> times_s_;  // each event's time, from the first
  ViewStateOptions options_;
  ViewState state_;
  std::size_t next_ = 0;  // first event not applied
  double position_s_ = 0.0;
  double duration_s_ = 0.0;
};

}  // namespace pinball::view
