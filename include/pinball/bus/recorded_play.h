#pragma once
// Recorded play: what `lcm-logger` (or pinballd's own file:// log) keeps of a
// game that a lab can learn the table from (issue 20): every camera frame's
// ball sighting with the flipper contact switches (PINBALL_OBSERVATION) and
// every coil command (PINBALL_FLIPPER_CMD). Other channels are skipped.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pinball/bus/lcm_log_format.h"
#include "pinball/core/geometry.h"

namespace pinball::bus {

/// One camera frame as recorded.
struct RecordedFrame {
  double t_s = 0.0;              ///< exposure time on the daemon's clock (s)
  std::int64_t seq = 0;          ///< camera frame number (a gap: dropped frames)
  bool found = false;            ///< the detector saw the ball
  Vec2 p_board = Vec2::Zero();   ///< ball centre (m, board frame) when found
  bool contact_left = false;     ///< left flipper contact switch closed
  bool contact_right = false;    ///< right flipper contact switch closed
};

/// One coil command as recorded.
struct RecordedCommand {
  double t_s = 0.0;       ///< when the controller gave it, daemon's clock (s)
  int flipper = 0;        ///< 0 left, 1 right, -1 every flipper
  bool energize = false;  ///< true: fire (pulse then hold); false: release
  int cause = 0;          ///< lcmt_pinball_flipper_command's CAUSE_ code
};

/// A log's recorded play, frames and commands each in time order.
struct RecordedPlay {
  std::string source;                     ///< the log file
  std::vector<RecordedFrame> frames;      ///< PINBALL_OBSERVATION, sorted by t_s
  std::vector<RecordedCommand> commands;  ///< PINBALL_FLIPPER_CMD, sorted by t_s
  std::uint64_t malformed = 0;            ///< messages on those channels that failed to decode or check
  std::string first_malformed;            ///< the first of them and why ("PINBALL_FLIPPER_CMD message 3 ...")
  double duration_s() const { return frames.empty() ? 0.0 : frames.back().t_s - frames.front().t_s; }
};

/// Reads the recorded play of the LCM log at `path`. Throws
/// std::runtime_error naming the file and what is missing: a file that is
/// unreadable, empty, not an LCM log or truncated (bus::require_lcm_log);
/// a log with no PINBALL_OBSERVATION or no PINBALL_FLIPPER_CMD messages (the
/// message lists the channels it has); a log whose messages on those channels
/// are not pinball messages (none decodes) or all have a bad field (the first
/// is named); one where no frame saw the ball;
/// and one whose clock goes back more than a second (runs appended with
/// lcm_url mode=a, which sorting by time would shuffle together).
RecordedPlay read_recorded_play(const std::string& path);

/// The observations' clock as check_one_run has seen it so far.
struct RunClock {
  double latest_s = -1e300;         ///< the latest time seen
  double before_latest_s = -1e300;  ///< the latest before the frame that set it
  std::int64_t latest_seq = -1;     ///< that frame
};

/// The readers' check that a log holds one run: an observation at `t_s` more
/// than a second before the latest so far (`clock`, updated here) is a clock
/// that started again, a second run appended (lcm_url mode=a), unless it is
/// back in step with the frames before the latest: then that one frame's
/// time jumped ahead alone (a damaged timestamp). Throws std::runtime_error
/// "path: its clock goes back ..." or "path: ... frame N jumps ... ahead",
/// naming the frame.
void check_one_run(const std::string& path, RunClock& clock, double t_s, std::int64_t seq);

/// check_one_run over every PINBALL_OBSERVATION of `events` (the log at
/// `path`) that decodes; for a reader that plays the whole log on one
/// timeline (`pinball view`), where two runs would play interleaved.
void check_log_holds_one_run(const std::string& path, const std::vector<LcmLogEvent>& events);

/// The sightings of a moving ball that two recordings share.
struct SharedSightings {
  std::size_t shared = 0;    ///< in both: same frame number, time and position to the last bit
  std::size_t moving_a = 0;  ///< of `a`'s sightings where the ball had moved since the frame before
  std::size_t moving_b = 0;  ///< the same of `b`
  std::int64_t first_seq = -1;  ///< the first shared one (by time in `a`), or -1
  double first_t_s = 0.0;
  /// Copies of one recording share every sighting, even when their bytes
  /// differ (a channel dropped, a log cut or logged again). Two runs share
  /// none, but for a deterministic simulation's launch, which two games of one
  /// seed both start with: hence half of the shorter one, not one sighting.
  bool same_recording() const { return shared > 0 && 2 * shared >= std::min(moving_a, moving_b); }
};

/// Compares the moving sightings of `a` and `b` (a ball at rest, or no ball,
/// looks the same in any run).
SharedSightings shared_sightings(const RecordedPlay& a, const RecordedPlay& b);

/// `play` as the bytes of an LCM log (frames and commands interleaved in time
/// order, stamped with their own times), which read_recorded_play reads back:
/// for tests and benches that make recordings from a simulation.
std::string recorded_play_log(const RecordedPlay& play);

}  // namespace pinball::bus
