#pragma once
// pinballd: the real-time controller daemon. Threads (thread_table.h):
//   camera:     frames -> BallDetector -> Tracker          (CameraStage)
//   controller: projections -> action function -> DriverBus (ControllerStage)
//   driver:     DriverBus: CAN frames, heartbeat, status
//   sim:        the embedded simulation (SimWorld), in sim mode
//   lcm:        publishes everything, receives observations (LcmBus)
// The hot threads hand each other plain records through lock-free rings and
// never touch LCM. In sim mode the default clock is lockstep: each frame goes
// camera -> controller -> driver before the world moves on, so a run is fully
// determined by its seed and runs as fast as the machine allows;
// sim.realtime paces the world to the wall clock instead.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/bus/lcm_bus.h"
#include "pinball/daemon/daemon_config.h"
#include "pinball/daemon/latency_histogram.h"
#include "pinball/simlab/sim_world.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/frame_log.h"
#include "pinball/firmware/virtual_driver_board.h"

namespace pinball::daemon {

/// The latency table's stages (steady clock).
enum LatencyStage : int {
  kCaptureToDetection = 0,  ///< frame handed over -> detector done
  kDetectionToProjection,   ///< detector done -> tracker done
  kProjectionToDecision,    ///< tracker done -> controller done with the record
  kCommandToCan,            ///< command accepted by DriverBus -> its CAN frame written
  kCanToCoil,               ///< CAN frame written -> coil on at the virtual board (sim only)
  kFrameToCan,              ///< end to end: frame handed over -> CAN frame written
  kStageCount
};

/// Name of a stage ("capture->detection", ...).
const char* stage_name(int stage);

/// What a run did.
struct DaemonReport {
  std::string mode;                          ///< sim or lab
  bool lockstep = false;                     ///< sim with the virtual clock
  std::string identified;                    ///< the overlay laid over the belief board (`identified`); empty: none
  std::string world_board;                   ///< sim: the board the world plays
  std::string world;                         ///< sim: the world that played it (thesis, event, twin)
  sim::WorldWarnings world_warnings;         ///< sim: the world's warnings (the twin's MuJoCo warnings)
  int balls = 0;                             ///< balls played (sim)
  int balls_asked = 0;                       ///< balls the run was to play (sim with a world)
  bool stopped_by_signal = false;            ///< SIGINT or SIGTERM (request_stop) ended the run
  double mean_score = 0.0;                   ///< mean score per ball (sim)
  double score_ci95 = 0.0;                   ///< half-width of its 95 % interval (sim)
  double mean_ball_time_s = 0.0;             ///< mean simulated ball time (s)
  int cut_balls = 0;                         ///< balls cut at the time limit (cycles)
  std::vector<simlab::SimBallResult> results;        ///< per ball (sim)
  std::array<LatencySummary, kStageCount> latency{};  ///< per stage
  std::uint64_t frames = 0;                  ///< frames processed by the camera thread
  std::uint64_t frames_dropped = 0;          ///< frames lost before the camera thread
  std::uint64_t camera_reopens = 0;          ///< a lab camera opened again after failing reads in a row (replugged)
  std::uint64_t detections = 0;              ///< frames with a ball
  std::uint64_t projections = 0;             ///< valid projections
  /// The camera's noise per coordinate (m): the calibration's, which the
  /// tracker is given, and what the tracker measured from the ball's tracks
  /// (docs/tracking.md; once the threads are done and it has enough frames).
  /// Measured over track::kNoiseOverCalibration times the calibration, the
  /// tracker weighs its fits by the measured one: the camera wants calibrating again.
  double camera_noise_calibrated_m = 0.0;
  std::optional<double> camera_noise_measured_m;
  std::uint64_t commands = 0;                ///< flipper commands given
  std::uint64_t camera_stalls = 0;           ///< releases because frames stopped
  std::uint64_t ball_lost_releases = 0;      ///< releases because the ball went out of sight
  std::uint64_t bus_fault_releases = 0;      ///< releases because the CAN session dropped
  std::uint64_t fires_deferred = 0;          ///< fires held back for the coil's recycle time
  std::uint64_t ring_overflows = 0;          ///< records dropped between threads
  bus::LcmBusCounters lcm;                   ///< LCM traffic (publish_failed: lost to every recording)
  std::optional<firmware::FrameLogCounters> can_log;  ///< the CAN log (can.log), when one is written
  /// Epoch time (s) of the pipeline clock's zero: every recording of the run
  /// (LCM log events, CAN log lines) is stamped anchor + pipeline time, and
  /// an LCM message's utime is its pipeline time.
  double recording_anchor_s = 0.0;
  firmware::DriverBusCounters driver;        ///< CAN host side
  firmware::BoardCounters board;             ///< virtual board (sim)
  double wall_s = 0.0;                       ///< run time (s)
  double sim_s = 0.0;                        ///< simulated time (s)
  std::string cpus;                          ///< where the threads ran (threads.chain_cpu)
  bool coils_off_at_exit = true;             ///< sim: every coil of the virtual board was off after shutdown
  std::vector<std::string> warnings;         ///< e.g. real-time scheduling refused
  std::vector<std::string> faults;           ///< CAN faults seen and what was done (the first kMaxReportedFaults)
  std::uint64_t fault_count = 0;             ///< all of them, reported or not
  std::uint64_t camera_read_failures = 0;    ///< failed grabs of a lab camera
  std::vector<std::string> thread_failures;  ///< a thread that ended by an exception: "pb-camera: what"
};

/// Faults listed one by one in a report (the rest are counted).
inline constexpr std::size_t kMaxReportedFaults = 100;

/// pinballd's exit status when it ran but a recording is incomplete: the CAN
/// log dropped frames or LCM refused or dropped messages (0: ran, 1: bad
/// configuration or file, or a thread failed, 2: bad argument).
constexpr int kExitRecordingIncomplete = 3;

/// What the run's recordings lost (the CAN log, LCM), for people; "" when
/// they are complete.
std::string recording_problems(const DaemonReport& report);

/// Why the LCM traffic of `config` cannot be recorded whole by a logger on
/// the network ("" when it can): the lockstep clock publishes as fast as the
/// simulation runs, tens of times real time, and an lcm-logger on udpm://
/// loses messages it cannot keep up with, without a word.
std::string lcm_pace_warning(const DaemonConfig& config);

/// Why the simulated driver board's watchdog will trip in `config` ("" when
/// it will not): the simulated world hands the board what the host sent only
/// between camera frames, so a frame period of can.watchdog_timeout_s or more
/// starves it of heartbeats every frame. A real board hears the host at once.
std::string sim_watchdog_warning(const DaemonConfig& config);

/// Every warning the configuration alone gives: lcm_pace_warning, sim_watchdog_warning.
std::vector<std::string> config_warnings(const DaemonConfig& config);

/// The tracker measured the camera noisier than track::kNoiseOverCalibration
/// times its calibration (and so weighed its fits by the measured noise).
bool camera_noisier_than_calibrated(const DaemonReport& report);

/// The report as one JSON object (the --json output).
nlohmann::json report_to_json(const DaemonReport& report);

/// One latency stage as JSON: count, p50_us, p99_us, max_us; a stage that
/// measured nothing has no quantiles: null, not 0 us.
nlohmann::json latency_to_json(const LatencySummary& summary);
/// The report for people: score line and latency table.
std::string report_to_text(const DaemonReport& report);

/// The daemon.
class Daemon {
 public:
  /// Loads the board, controller and calibration and builds every part.
  /// Throws ConfigError / std::runtime_error naming what is wrong.
  explicit Daemon(const DaemonConfig& config);
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  /// Runs until every ball is played (sim) or request_stop(); then releases
  /// every coil, stops the heartbeats and returns the report.
  DaemonReport run();
  /// Asks run() to finish (async-signal-safe).
  void request_stop();
  /// Asks run() to print the latency table to stderr (async-signal-safe).
  void request_stats();
  /// A report of the run so far (any thread).
  DaemonReport snapshot() const;
  /// The LCM endpoint (tests subscribe on it).
  bus::LcmBus& lcm_bus();
  /// The host side of the CAN link.
  firmware::DriverBus& driver_bus();

  /// Queues a ReleaseAll and writes it from the calling thread if the bus is
  /// free (never waits): for a process about to die (std::terminate).
  void emergency_release();

  /// Fault injection (tests/faults): thread `thread` (a ThreadId) sleeps for
  /// `freeze_s` seconds at the top of its next loop, or throws there when
  /// `fail`. Any thread may call it while run() runs.
  void inject_fault(int thread, double freeze_s, bool fail = false);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pinball::daemon
