#pragma once
// `pinball replay LOG`: feeds the observations recorded in an LCM log (by
// lcm-logger, or pinballd --lcm-url file://...?mode=w) through the same
// tracker and controller stages pinballd ran, offline, and compares the
// decisions with the flipper commands recorded in the same log.

#include <cstdint>
#include <functional>
#include <string>

#include "pinball/daemon/daemon_config.h"

namespace pinball::daemon {

/// What a replay found.
struct ReplayReport {
  std::uint64_t events = 0;             ///< log events read
  std::uint64_t observations = 0;       ///< PINBALL_OBSERVATION messages replayed
  /// Of them, recorded before the delivery stamp (lcmt_pinball_observation_v1):
  /// their latency is unknown and replayed as 0, so a leading controller's
  /// decisions may differ from the recorded ones.
  std::uint64_t observations_without_latency = 0;
  std::uint64_t malformed = 0;          ///< messages that failed to decode or check, skipped
  std::uint64_t recorded_commands = 0;  ///< PINBALL_FLIPPER_CMD messages from projections, launches and losses
  std::uint64_t replayed_commands = 0;  ///< commands the replay gave for the same causes
  std::uint64_t matched = 0;            ///< leading commands equal in flipper, direction, cause and frame
  std::int64_t first_mismatch = -1;     ///< index of the first difference, -1 when none
  std::string mismatch;                 ///< the two decisions at first_mismatch, for people
  std::uint64_t skipped_timing = 0;     ///< recorded commands caused by timing alone (stall, shutdown, bus)
  bool reproduced = false;              ///< every recorded decision was reproduced, in order
};

/// How far a replay has come.
struct ReplayProgress {
  std::uint64_t bytes_read = 0;   ///< of the log
  std::uint64_t bytes_total = 0;  ///< the log's size
  std::uint64_t observations = 0;  ///< replayed so far
};

/// Replays `log_path` with the board and controller of `config` (looked up
/// as pinballd does, find_data_files). Decisions are compared by the camera
/// frame behind them (the log's PINBALL_PROJECTION messages map a recorded
/// decision's projection to its frame), so an observation the log lost (a
/// udpm drop) shifts nothing after it; a log without projections is compared
/// by projection number, one per observation. Throws std::runtime_error
/// naming the file when it cannot be read, or holds nothing to compare: no
/// PINBALL_OBSERVATION decoded, or no PINBALL_FLIPPER_CMD at all. `progress`
/// (may be empty) is called every `progress_every` observations (about half
/// a second of replay at 20000) and at the end.
ReplayReport replay_log(const std::string& log_path, DaemonConfig config,
                        const std::function<void(const ReplayProgress&)>& progress = {},
                        std::uint64_t progress_every = 20000);

}  // namespace pinball::daemon
