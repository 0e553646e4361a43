#pragma once
// `pinball bench protocol`: random and mutated frame streams into the
// reference board with ProtocolRuleChecker and CoilSafetyMonitor on its
// outputs; every firmware rule of PROTOCOL.md that can be seen from outside
// must hold for every frame. Baseline in the same run: decoding the same
// stream alone (what the checker and the board cost on top of the codec).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pinball::bench {

/// What to run.
struct ProtocolBenchOptions {
  std::uint64_t frames = 1'000'000;  ///< frames per seed
  std::uint64_t seed = 1;            ///< first seed
  int seeds = 1;                     ///< seeds run one after the other (seed, seed + 1, ...)
  int driver_count = 2;              ///< drivers fitted on the board under test
  int release_cycles = 400;          ///< fire/release cycles per ReleaseUnderLoss row
};

/// Coils released over a lossy link (both ways): how long each stays on
/// after the host releases it, with the host's closed loop on Status, and
/// without it (the baseline: the protocol v1 host, which never looked).
struct ReleaseUnderLoss {
  double drop_p = 0.0;               ///< probability each frame is lost, each way
  bool closed_loop = true;           ///< the host re-sends Releases (false: never)
  int cycles = 0;                    ///< fire, hold 60 ms, release
  double p50_s = 0.0;                ///< median on-time after the release (s)
  double p99_s = 0.0;                ///< 99th percentile (s)
  double worst_s = 0.0;              ///< longest (s)
  std::uint64_t frames_dropped = 0;  ///< frames the link lost
  std::uint64_t release_retries = 0; ///< Releases the host sent again
  std::uint64_t release_escalations = 0;  ///< ReleaseAlls past the deadline
  std::uint64_t cap_violations = 0;  ///< CoilSafetyMonitor (must be 0)
};

/// Measures ReleaseUnderLoss on a virtual clock (1 ms ticks) with the reference board.
ReleaseUnderLoss measure_release_under_loss(double drop_p, bool closed_loop, int cycles, std::uint64_t seed);

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
  std::vector<ReleaseUnderLoss> release_under_loss;  ///< 1 % and 5 % loss, closed loop on and off
};


/// Runs it; `progress` (may be empty) gets a line every 10 % with an ETA.
ProtocolBenchReport run_protocol_bench(const ProtocolBenchOptions& options,
                                       const std::function<void(const std::string&)>& progress);

/// The report as one JSON object.
nlohmann::json to_json(const ProtocolBenchReport& report);

}  // namespace pinball::bench
