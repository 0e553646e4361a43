#pragma once
// What `pinball view` knows of a running pinballd: the daemon's LCM messages,
// decoded and checked, folded into the little the picture needs (the ball's
// recent sightings, the newest projection, the flipper commands, the coils,
// the daemon's counters). Plain data: the window, the log player and the
// live subscriber only feed it messages; a message that fails to decode or
// check is counted, never shown.

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>

#include "pinball_lcm/lcmt_pinball_daemon_stats.hpp"
#include "pinball_lcm/lcmt_pinball_driver_status.hpp"
#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"
#include "pinball_lcm/lcmt_pinball_game_event.hpp"
#include "pinball_lcm/lcmt_pinball_projection.hpp"
#include "pinball/core/geometry.h"

namespace pinball::view {

/// How much history the view keeps.
struct ViewStateOptions {
  double trail_s = 0.5;             ///< observations of the ball kept for its trail (s)
  double command_flash_s = 0.3;     ///< a command stays marked on its flipper this long (s)
  std::size_t command_history = 8;  ///< commands listed in the side panel
  double rate_window_s = 1.0;       ///< frame rate over this window (s)
};

/// One sighting of the ball.
struct Sighting {
  double t_s = 0.0;              ///< exposure time on the view's clock (s)
  Vec2 p_board = Vec2::Zero();   ///< ball centre (m)
  std::int64_t seq = 0;          ///< the camera's frame number
};

/// One flipper command as it was sent.
struct SentCommand {
  double t_s = 0.0;       ///< when it was given, on the view's clock (s)
  int flipper = 0;        ///< 0 left, 1 right, -1 all
  bool energize = false;  ///< fire (true) or release
  int cause = 0;          ///< lcmt_pinball_flipper_command::CAUSE_*
};

/// The daemon's figures for the strip along the bottom.
struct DaemonFigures {
  double frame_rate_hz = 0.0;         ///< camera frames per second over the rate window (from observation seq)
  std::int64_t frames_dropped = 0;    ///< seq gaps seen plus what PINBALL_STATS reports, whichever is larger
  std::int64_t camera_stalls = 0;     ///< PINBALL_STATS camera_stalls
  double frame_to_can_p99_us = -1.0;  ///< PINBALL_STATS "frame->can_written" p99; negative: not reported yet
  bool has_stats = false;             ///< a PINBALL_STATS message has arrived
};

/// The view of the daemon at one moment.
class ViewState {
 public:
  explicit ViewState(ViewStateOptions options = {});

  /// Feeds one encoded message of `channel` (the daemon's channel names,
  /// bus/channels.h; others are ignored), stamped `t_s` on the view's clock
  /// (seconds from the start of the log or of listening). Returns false when
  /// the message did not decode or check (counted in malformed()).
  bool apply(std::string_view channel, const void* data, std::size_t size, double t_s);

  /// The ball's sightings within the trail window before now(), oldest first.
  const std::deque<Sighting>& trail() const { return trail_; }
  /// The newest sighting when it is the newest observation (the ball was seen in
  /// the last frame); empty when the last frame found no ball or none came yet.
  std::optional<Sighting> ball() const;
  /// The newest projection and where its observation was: a valid one only.
  const std::optional<pinball_lcm::lcmt_pinball_projection>& projection() const { return projection_; }
  /// Why the newest projection message was not valid (track::NoProjection's code; 0: it was valid or none came).
  int no_projection_reason() const { return no_projection_reason_; }
  /// The ball position the newest projection started from (its observation).
  const Vec2& projection_origin() const { return projection_origin_; }
  /// Time of the newest projection, on the view's clock (s).
  double projection_t_s() const { return projection_t_s_; }
  /// The last commands, oldest first.
  const std::deque<SentCommand>& commands() const { return commands_; }
  /// The newest command of each flipper within the flash window, if any.
  std::optional<SentCommand> flashing_command(int flipper) const;
  /// Each coil's state from the newest PINBALL_DRIVER_STATUS; empty before the first.
  const std::optional<pinball_lcm::lcmt_pinball_driver_status>& driver_status() const { return driver_status_; }
  /// True when bit `driver` of the newest driver status's coils_on is set.
  bool coil_on(int driver) const;
  /// The strip's figures.
  DaemonFigures figures() const;
  /// Ball number and points of the ball in play (PINBALL_GAME), -1 before the first launch.
  int ball_number() const { return ball_; }
  double ball_points() const { return ball_points_; }
  /// Time of the newest message (s), the view's now.
  double now_s() const { return now_s_; }
  /// Messages applied and messages refused.
  std::uint64_t messages() const { return messages_; }
  std::uint64_t malformed() const { return malformed_; }
  /// Observations applied (found or not).
  std::uint64_t observations() const { return observations_; }

 private:
  void on_observation(const void* data, std::size_t size, double t_s, bool& ok);
  void forget_before(double t_s);

  ViewStateOptions options_;
  std::deque<Sighting> trail_;
  std::deque<double> frame_times_s_;  // observation times within the rate window
  bool last_found_ = false;
  std::int64_t last_seq_ = -1;
  double last_seq_t_s_ = 0.0;  // the time of the frame last_seq_ numbers
  std::int64_t seq_gaps_ = 0;
  std::optional<pinball_lcm::lcmt_pinball_projection> projection_;
  int no_projection_reason_ = 0;
  Vec2 projection_origin_ = Vec2::Zero();
  double projection_t_s_ = 0.0;
  std::deque<SentCommand> commands_;
  std::optional<pinball_lcm::lcmt_pinball_driver_status> driver_status_;
  std::optional<pinball_lcm::lcmt_pinball_daemon_stats> stats_;
  int ball_ = -1;
  double ball_points_ = 0.0;
  double now_s_ = 0.0;
  std::uint64_t messages_ = 0, malformed_ = 0, observations_ = 0;
};

}  // namespace pinball::view
