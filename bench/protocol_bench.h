#pragma once
// `pinball bench protocol`: random and mutated frame streams into the
// reference board with ProtocolRuleChecker and CoilSafetyMonitor on its
// outputs; every firmware rule of PROTOCOL.md that can be seen from outside
// must hold for every frame. Baseline in the same run: decoding the same
// stream alone (what the checker and the board cost on top of the codec).

#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

namespace pinball::bench {

/// What to run.
struct ProtocolBenchOptions {
  std::uint64_t frames = 1'000'000;  ///< frames per seed
  std::uint64_t seed = 1;            ///< first seed
  int seeds = 1;                     ///< seeds run one after the other (seed, seed + 1, ...)
  int driver_count = 2;              ///< drivers fitted on the board under test
};

/// What happened.
struct ProtocolBenchReport {
  std::uint64_t frames = 0;             ///< frames offered
  std::uint64_t mutated = 0;            ///< of which with bits flipped
  std::uint64_t noise = 0;              ///< of which random bytes
  std::uint64_t valid_frames = 0;       ///< frames that decoded for the board
  std::uint64_t bad_frames = 0;         ///< frames the board counted as bad
  std::uint64_t switch_ons = 0;         ///< coil switch-ons checked
  std::uint64_t fires_accepted = 0;     ///< the board's count
  std::uint64_t stale = 0;              ///< Fires and heartbeats refused as not newer
  std::uint64_t watchdog_trips = 0;     ///< all-off by the watchdog
  std::uint64_t hold_cap_trips = 0;     ///< holds ended by their cap
  std::uint64_t refused_locked = 0;     ///< Fires refused by a hold-cap lock
  std::uint64_t rule_violations = 0;    ///< ProtocolRuleChecker (must be 0)
  std::uint64_t cap_violations = 0;     ///< CoilSafetyMonitor against the absolute caps (must be 0)
  std::string first_violation;          ///< the first one, "" when none
  double simulated_s = 0.0;             ///< board time covered (s)
  double frames_per_s = 0.0;            ///< board + checker throughput
  double decode_only_frames_per_s = 0.0;  ///< baseline: decoding the same frames alone
};

/// Runs it; `progress` (may be empty) gets a line every 10 % with an ETA.
ProtocolBenchReport run_protocol_bench(const ProtocolBenchOptions& options,
                                       const std::function<void(const std::string&)>& progress);

/// The report as one JSON object.
nlohmann::json to_json(const ProtocolBenchReport& report);

}  // namespace pinball::bench
