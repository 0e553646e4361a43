#pragma once
// `pinball bench latency`: time from DriverBus::fire() to the reference
// board's coil output over the stream transport (a socketpair, the bus's own
// thread in between, exactly as the daemon runs it), and the codec's cost per
// frame; each with a baseline measured in the same run.

#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

namespace pinball::bench {

/// What to measure.
struct LatencyBenchOptions {
  int samples = 2000;              ///< fire -> coil samples
  int codec_frames = 1'000'000;    ///< frames encoded and decoded for the codec figure
  int baseline_samples = 2000;     ///< raw 16-byte write/read round trips for the baseline
};

/// The measurement. Times in microseconds or nanoseconds as named.
struct LatencyReport {
  int samples = 0;                    ///< fire -> coil samples taken
  double fire_to_coil_p50_us = 0.0;   ///< median fire() -> coil on (us)
  double fire_to_coil_p99_us = 0.0;   ///< 99th percentile (us)
  double fire_to_coil_max_us = 0.0;   ///< worst (us)
  double fire_call_max_us = 0.0;      ///< longest fire() call itself (us): it must never block
  double raw_p50_us = 0.0;            ///< baseline: raw write+read of one 16-byte frame on the same socketpair, median (us)
  double raw_p99_us = 0.0;            ///< baseline 99th percentile (us)
  double stack_overhead_ratio = 0.0;  ///< fire_to_coil_p50_us / raw_p50_us
  double encode_decode_ns = 0.0;      ///< encode + decode of one Fire frame (ns)
  double copy_baseline_ns = 0.0;      ///< baseline: copying one CanFrame and summing its bytes (ns)
  std::uint64_t coil_violations = 0;  ///< safety-monitor violations during the run (must be 0)
};

/// Runs the measurement; `progress` (may be empty) receives one line per part.
LatencyReport run_latency_bench(const LatencyBenchOptions& options,
                                const std::function<void(const std::string&)>& progress);

/// The report as one JSON object.
nlohmann::json to_json(const LatencyReport& report);

}  // namespace pinball::bench
