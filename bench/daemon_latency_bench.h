#pragma once
// `pinball bench latency`, daemon part: end-to-end frame -> CAN frame written
// through pinballd's threads at 200 fps in the embedded simulation, per stage,
// once on the lockstep clock (many balls, the pipeline alone on the CPU) and
// once paced to the wall clock (the simulator rendering beside it), each with
// the default thread placement (the chain on one CPU, threads.chain_cpu) and
// once more with a variant: on the lockstep clock the threads free to move
// (chain_cpu off, the baseline), paced to the wall clock idle cores kept
// polling (cpu_dma_latency_us 0). Baseline measured in the same run: one
// thread waking another through the same eventfd doorbell, the floor of
// every hand-off in the chain.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/daemon/daemon.h"

namespace pinball::bench {

/// What to measure.
struct DaemonLatencyOptions {
  std::string board = "boards/mit1993.board";                 ///< simulated table
  std::string controller = daemon::kDefaultController;         ///< controller file: pinballd's default
  int lockstep_balls = 100;                                   ///< balls on the lockstep clock
  double realtime_s = 60.0;                                   ///< seconds paced to the wall clock, per run
  int baseline_samples = 5000;                                ///< doorbell wake-ups for the baseline
  std::uint64_t seed = 1;                                     ///< launch seed
};

/// One run's latency table.
struct DaemonLatencyRun {
  std::array<daemon::LatencySummary, daemon::kStageCount> stages{};  ///< per stage
  std::uint64_t frames = 0;     ///< frames processed
  std::uint64_t dropped = 0;    ///< frames dropped before the camera thread
  double wall_s = 0.0;          ///< run time (s)
  double sim_s = 0.0;           ///< simulated time (s)
  std::string cpus;             ///< thread placement (DaemonReport::cpus)
  std::vector<std::string> warnings;  ///< e.g. cpu_dma_latency refused
};

/// The measurement.
struct DaemonLatencyReport {
  DaemonLatencyRun lockstep;           ///< lockstep clock, default threads
  DaemonLatencyRun lockstep_unpinned;  ///< lockstep clock, threads.chain_cpu off (baseline)
  DaemonLatencyRun realtime;           ///< wall clock, default threads
  DaemonLatencyRun realtime_idle_poll; ///< wall clock, threads.cpu_dma_latency_us 0
  double wake_p50_us = 0.0;         ///< baseline: eventfd wake-up of another thread, median (us)
  double wake_p99_us = 0.0;         ///< baseline 99th percentile (us)
  double fps = 200.0;               ///< camera rate
  std::string controller;           ///< the controller file every run played
};

/// Runs both; `progress` (may be empty) gets one line per part.
DaemonLatencyReport run_daemon_latency_bench(const DaemonLatencyOptions& options,
                                             const std::function<void(const std::string&)>& progress);

/// As one JSON object.
nlohmann::json to_json(const DaemonLatencyReport& report);

}  // namespace pinball::bench
