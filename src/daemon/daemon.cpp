#include "pinball/core/json_write_archive.h"
#include "pinball/daemon/daemon.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "pinball/bus/channels.h"
#include "pinball/bus/message_convert.h"
#include "pinball/daemon/can_link_check.h"
#include "pinball/daemon/config_check.h"
#include "pinball/control/actuator_controller.h"
#include "pinball/control/controller_file.h"
#include "pinball/core/format.h"
#include "pinball/core/running_stats.h"
#include "pinball/core/clock.h"
#include "pinball/core/file_sink.h"
#include "pinball/core/writer_lock.h"
#include "pinball/daemon/doorbell.h"
#include "pinball/daemon/pipeline.h"
#include "pinball/daemon/thread_table.h"
#include "pinball/firmware/can_link.h"
#include "pinball/firmware/frame_log.h"
#include "pinball/firmware/socketcan_transport.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/simlab/world_factory.h"
#include "pinball/table/board_overlay.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/track/tracker.h"
#include "pinball/vision/capture_source.h"
#include "pinball/simlab/sim_camera_source.h"
#include "pinball/learn/planning_controller.h"

#include "camera_worker.h"
#include "controller_worker.h"
#include "driver_worker.h"
#include "frame_handoff.h"
#include "handoffs.h"
#include "live_status.h"
#include "sim_worker.h"
#include "virtual_board_runner.h"

namespace pinball::daemon {

const char* stage_name(int stage) {
  static constexpr std::array<const char*, kStageCount> kNames{
      "capture->detection", "detection->projection", "projection->decision",
      "command->can_written", "can_written->coil_on", "frame->can_written"};
  return stage >= 0 && stage < kStageCount ? kNames[static_cast<std::size_t>(stage)] : "?";
}

namespace {

// The messages carry the codes of the enums as constants: one spelling, checked here.
using FlipperCommandMessage = pinball_lcm::lcmt_pinball_flipper_command;
static_assert(static_cast<int>(CommandCause::kProjection) == FlipperCommandMessage::CAUSE_PROJECTION);
static_assert(static_cast<int>(CommandCause::kLaunch) == FlipperCommandMessage::CAUSE_LAUNCH);
static_assert(static_cast<int>(CommandCause::kBallLost) == FlipperCommandMessage::CAUSE_BALL_LOST);
static_assert(static_cast<int>(CommandCause::kCameraStall) == FlipperCommandMessage::CAUSE_CAMERA_STALL);
static_assert(static_cast<int>(CommandCause::kShutdown) == FlipperCommandMessage::CAUSE_SHUTDOWN);
static_assert(static_cast<int>(CommandCause::kBusFault) == FlipperCommandMessage::CAUSE_BUS_FAULT);
using GameEventMessage = pinball_lcm::lcmt_pinball_game_event;
static_assert(simlab::GameEvent::kLaunch == GameEventMessage::KIND_LAUNCH);
static_assert(simlab::GameEvent::kBallLost == GameEventMessage::KIND_BALL_LOST);
static_assert(simlab::GameEvent::kScore == GameEventMessage::KIND_SCORE);
static_assert(simlab::GameEvent::kBallCut == GameEventMessage::KIND_BALL_CUT);

}  // namespace

struct Daemon::Impl {
  DaemonConfig config;
  std::vector<WriterLock> recording_locks;  // the LCM and CAN logs: no second pinballd writes into them
  WriterLock board_lock{""};                // the lab's driver board: no second host drives it
  CpuPlan cpus;  // threads.chain_cpu
  bool fifo_allowed = true;  // false once the probe was refused: warned once, not once per thread
  bool sim_mode = true;
  bool lockstep = true;
  table::Board board;
  control::ControllerSpec spec;
  std::unique_ptr<control::FlipperController> controller;
  // CAN.
  std::unique_ptr<firmware::CanTransport> host_link;
  std::unique_ptr<firmware::StreamTransport> board_link;  // sim: the virtual board's end
  std::unique_ptr<VirtualBoardRunner> board_runner;  // sim without a world (camera.source lcm): that board's thread
  std::unique_ptr<firmware::FrameLog> frame_log;  // optional candump log, opened in run() before the threads
  std::unique_ptr<firmware::Liveness> liveness;  // camera and controller progress, behind the heartbeat
  std::unique_ptr<firmware::DriverBus> bus;
  // Frames.
  simlab::OwnedWorld world_model;                      // sim: the table that is played (sim.world_board)
  std::unique_ptr<simlab::SimWorld> world;                     // sim: that table, its camera and its driver board
  std::unique_ptr<vision::CaptureSource> capture;      // lab: v4l2 / file
  std::unique_ptr<vision::CameraHomography> homography;
  std::unique_ptr<vision::BallDetector> detector;
  std::unique_ptr<track::Tracker> tracker;
  std::unique_ptr<CameraStage> camera_stage;
  std::unique_ptr<ControllerStage> controller_stage;
  std::array<int, 2> driver_of_flipper{0, 1};
  // LCM.
  std::unique_ptr<bus::LcmBus> lcm;
  bus::ObservationRing lcm_observations;
  // What the threads share (handoffs.h), the pipeline's clock, and one worker per thread.
  Handoffs h;
  std::unique_ptr<PipelineClock> clock;
  std::unique_ptr<SimWorker> sim_worker;
  std::unique_ptr<FrameHandoffSource> frame_handoff;  // sim: the camera thread's FrameSource
  std::unique_ptr<CameraWorker> camera_worker;
  std::unique_ptr<ControllerWorker> controller_worker;
  std::unique_ptr<DriverWorker> driver_worker;
  std::atomic<bool> stats_requested{false};
  std::atomic<bool> stop_requested{false};  // by a signal: the run ended early
  mutable std::mutex warnings_mutex;
  std::vector<std::string> warnings;
  double start_wall_s = 0.0;
  double recording_anchor_s = 0.0;  // epoch time of the pipeline clock's zero (start_recording_clock)
  bool recording_clock_started = false;  // written before the threads start
  double can_log_last_s = 0.0;           // the frame log's caller's (one at a time, under DriverBus's lock)
  std::atomic<bool> coils_off_at_exit{true};  // written by shutdown() while the LCM thread may report
  std::atomic<bool> threads_joined{false};    // every thread is done: the simulator's own state may be read
  // Faults, read by the main thread alone (DriverBus::pop_fault has one reader).
  std::vector<std::string> faults;  // guarded by warnings_mutex (the LCM thread's stats read them)
  std::uint64_t fault_count = 0;
  std::uint64_t camera_failures_reported = 0;
  std::vector<std::string> thread_failures;  // guarded by warnings_mutex
  std::int64_t stats_seq = 0;  // PINBALL_STATS sequence (the LCM thread only)


  // One clock for every recording of the run (docs/daemon.md): the pipeline's
  // clock moved onto the epoch as of now. LCM log events are stamped with
  // their message's utime plus this anchor and CAN frames with the anchored
  // clock, so a lockstep run's logs play back at the game's pace, together.
  // Before it starts (the bus's warm-up) frames are stamped with the epoch
  // clock itself, which the anchored clock continues.
  void start_recording_clock() {
    recording_anchor_s = epoch_now_s() - clock->now_s();
    recording_clock_started = true;
    lcm->set_log_anchor_us(to_utime(recording_anchor_s));
  }
  // A CAN log line's stamp: never back, neither when the simulator's start
  // refreshes its offset nor when a frame's receipt is logged after a send.
  double can_log_stamp_s() {
    can_log_last_s = std::max(can_log_last_s, recording_clock_started ? recording_anchor_s + clock->now_s() : epoch_now_s());
    return can_log_last_s;
  }

  // Names the calling thread and applies its scheduling and CPUs; a refusal becomes a warning.
  void enter_thread(ThreadId id) {
    std::string why;
    const bool scheduled = configure_current_thread(id, config.threads.realtime && fifo_allowed, why,
                                                    config.threads.priorities[static_cast<std::size_t>(id)]);
    // On the lockstep clock the world waits for the chain and the chain for
    // the world: the simulator is one more link of it and runs on its CPU.
    const bool on_chain = kThreadTable[static_cast<std::size_t>(id)].chain || (id == kSimThread && lockstep);
    std::string pin_why;
    const bool pinned = pin_current_thread(on_chain ? cpus.chain : cpus.others, pin_why);
    if (scheduled && pinned) return;
    const std::lock_guard<std::mutex> lock(warnings_mutex);
    if (!scheduled) warnings.push_back(why);
    if (!pinned) warnings.push_back(pin_why);
  }
  void build();
  void learn_background();
  void open_can_log();
  void warm_up_bus();
  void make_workers();
  void publish_stats(lcm::LCM& lcm);
  void shutdown();
  DaemonReport report() const;
  void report_faults();
  void fail_thread(ThreadId id, const std::string& what);
  // Runs one thread's body: an exception makes the coils safe first, reports second, stops the run.
  template <class Body>
  void guarded(ThreadId id, Body body) {
    try {
      body();
    } catch (const std::exception& e) {
      fail_thread(id, e.what());
    } catch (...) {
      fail_thread(id, "unknown exception");
    }
  }
};

void Daemon::Impl::build() {
  sim_mode = config.mode == "sim";
  // Mode sim with camera.source lcm plays no world: observations come from LCM (virtual_board_runner.h).
  const bool plays_world = sim_mode && config.camera.source != "lcm";
  cpus = plan_cpus(config.threads.chain_cpu);
  find_data_files(config);
  lockstep = plays_world && !config.sim.realtime;
  for (const std::string& w : config_warnings(config)) {
    std::fprintf(stderr, "pinballd: warning: %s\n", w.c_str());
    warnings.push_back(w);
  }
  DaemonInputs inputs = load_daemon_inputs(config);
  board = std::move(inputs.board);
  spec = std::move(inputs.spec);
  controller = learn::make_controller(spec, board);
  driver_of_flipper = controller_stage_options_for(config, board).driver_of_flipper;
  const int drivers = static_cast<int>(board.flippers.size());

  if (config.can.interface == "sim") {
    auto [host, far] = firmware::StreamTransport::make_pair();
    host_link = std::move(host);
    board_link = std::move(far);
  } else {
    // In the lab the camera is looked for too, so that a start names all that is missing at once.
    for (std::string& note : check_lab_hardware(config)) warnings.push_back(std::move(note));
    board_lock = firmware::lock_driver_board(config.can.interface, config.can.board_id);
    firmware::SocketCanOptions o;
    o.interface = config.can.interface;
    host_link = std::make_unique<firmware::SocketCanTransport>(o);
  }
  firmware::DriverBusOptions bo = driver_bus_options_for(config, drivers);
  // The heartbeat vouches for the chain: it flows only while the camera and
  // the controller threads progress. A beat every frame is expected; three
  // frame periods (at least one heartbeat period) without one is a stall.
  liveness = std::make_unique<firmware::Liveness>(std::max(config.can.heartbeat_period_s, 3.0 / config.camera.fps));
  if (liveness->watch("camera") != kCameraBeat || liveness->watch("controller") != kControllerBeat) {
    throw std::logic_error("daemon: liveness indices");
  }
  h.liveness = liveness.get();
  bo.liveness = liveness.get();
  bus = std::make_unique<firmware::DriverBus>(*host_link, bo);  // its CAN log comes in run(): open_can_log()

  const TrackingSetup& setup = inputs.setup;
  tracker = std::make_unique<track::Tracker>(setup.geometry, setup.tracker);

  cv::Size frame_size(config.camera.width_px, config.camera.height_px);
  if (sim_mode && !plays_world) {
    board_runner = std::make_unique<VirtualBoardRunner>(
        *board_link, firmware::VirtualDriverBoardOptions{.board_id = static_cast<std::uint8_t>(config.can.board_id),
                                                         .driver_count = drivers});
  } else if (sim_mode) {
    simlab::SimCameraConfig cc;
    cc.width_px = config.camera.width_px;
    cc.height_px = config.camera.height_px;
    cc.fps = config.camera.fps;
    cc.exposure_s = std::min(cc.exposure_s, 1.0 / cc.fps);  // a faster camera exposes for at most its frame period
    cc.seed = config.sim.seed;
    if (config.sim.camera == "typical") cc.realism = simlab::SimCameraRealism::typical(cc.width_px, cc.height_px);
    simlab::SimWorldOptions wo;
    wo.balls = config.sim.balls;
    wo.seed = config.sim.seed;
    wo.actuation_delay_s = config.sim.actuation_delay_s;
    wo.max_ball_time_s = config.sim.max_ball_time_s;
    wo.launcher_pull = spec.launcher_pull;
    wo.board_id = config.can.board_id;
    simlab::WorldSpec ws;
    ws.kind = config.sim.world;
    ws.twin_params_path = config.sim.twin_params;
    ws.board_path = config.sim.world_board;
    ws.stepper = config.sim.stepper;
    world_model = simlab::make_world(simlab::world_for_belief(ws, config.sim.board, config.identified), board);
    world = std::make_unique<simlab::SimWorld>(*world_model, *board_link, cc, wo);
    // A calibration file (e.g. from `pinball calibrate camera --sim`) stands in
    // for the simulated camera's true homography, as it would in the lab.
    homography = std::make_unique<vision::CameraHomography>(setup.homography ? *setup.homography
                                                                             : world->camera().homography());
  } else if (config.camera.source != "lcm") {
    homography = std::make_unique<vision::CameraHomography>(*setup.homography);  // load_daemon_inputs checked it
  }
  if (homography) {
    // OpenCV's thread pool would hand the camera thread's work to threads
    // outside the thread table, allocate task objects per call and add jitter:
    // the detector runs on the camera thread alone.
    cv::setNumThreads(1);
    vision::BallDetectorConfig dc;
    dc.ball_radius_m = board.ball.radius_m;
    // The calibration's lens and timing; in the simulation without them, the simulated
    // camera's true ones stand in (as its homography does).
    std::optional<vision::CameraIntrinsics> lens = setup.lens;
    std::optional<calibration::CameraTiming> timing = setup.timing;
    if (world) {
      const simlab::SimCameraRealism& r = world->camera().config().realism;
      if (!lens) lens = r.lens;
      if (!timing && (r.row_time_s > 0.0 || r.latency_min_s > 0.0)) {
        timing = calibration::CameraTiming{r.latency_min_s, 0.0, r.row_time_s, 0};
      }
    }
    apply_camera_corrections(lens, timing, config.camera.fps, dc);
    detector = std::make_unique<vision::BallDetector>(*homography, frame_size, dc);
    if (world) detector->set_occluder_mask(world->camera().occluder_mask());
    if (!inputs.occluder_mask.empty()) detector->set_occluder_mask(inputs.occluder_mask);
  }
  camera_stage = std::make_unique<CameraStage>(detector.get(), *tracker, lost_after_s_for(config));
  controller_stage =
      std::make_unique<ControllerStage>(*controller, *bus, controller_stage_options_for(config, board));

  // The camera before the LCM bus, whose file:// log replaces an old one of
  // its name: a camera that is missing or busy fails the start before that.
  if (config.camera.source == "file" || config.camera.source == "v4l2") {
    capture = open_lab_camera(config.camera);
  }
  // One writer per recording, for the whole run: taken here, after every input loaded (a start that
  // fails before leaves no empty log behind), and before liblcm opens its log.
  const std::optional<bus::LcmLogTarget> lcm_log = bus::lcm_log_target(config.lcm_url);
  try {
    if (lcm_log) recording_locks.emplace_back(lcm_log->path);
    recording_locks.emplace_back(config.can.log);
  } catch (const std::runtime_error& e) {
    throw ConfigError(config.origin + ": " + e.what());
  }
  lcm = std::make_unique<bus::LcmBus>(config.lcm_url);
  if (config.camera.source == "lcm") lcm->subscribe_observations(lcm_observations);
  clock = std::make_unique<PipelineClock>(h, plays_world, lockstep);
  for (auto& slot : h.pool) slot.frame.gray.create(frame_size, CV_8UC1);
}

void Daemon::Impl::learn_background() {
  if (!detector) return;
  vision::Frame f;
  f.gray.create(cv::Size(config.camera.width_px, config.camera.height_px), CV_8UC1);
  for (int i = 0; i < config.camera.background_frames; ++i) {
    if (h.stop.load(std::memory_order_acquire)) return;  // SIGINT during start-up
    if (world) {
      world->render_background(f, -1.0 - i / config.camera.fps);
    } else if (!capture->read(f)) {
      throw std::runtime_error("camera: no frame for the background (" + capture->describe() + ")");
    }
    detector->background().add_training_frame(f.gray);
  }
  detector->background().finish_training();
}

// The CAN log is opened (and an old one of that name replaced) only once
// every start-up step that can fail without a frame on the bus has passed:
// a start that fails leaves the last run's log as it was.
void Daemon::Impl::open_can_log() {
  if (config.can.log.empty()) return;
  try {
    frame_log = std::make_unique<firmware::FrameLog>(config.can.log,
                                                     config.can.interface == "sim" ? "simcan" : config.can.interface);
  } catch (const std::runtime_error& e) {
    throw ConfigError(config.origin + ": can.log: " + e.what());
  }
  frame_log->stamp_with([this] { return can_log_stamp_s(); });
  bus->attach_log(frame_log.get());
}

void Daemon::Impl::warm_up_bus() {
  // Before the first ball: let the bus and the board finish their handshake,
  // on the world's clock in sim mode (the table idles), else on the steady clock.
  const double deadline_s = 2.0;
  for (double t = 0.0; t < deadline_s; t += 0.001) {
    if (h.stop.load(std::memory_order_acquire)) return;  // SIGINT during start-up
    if (world) {
      world->idle(0.001);
      bus->poll_once(world->time_s());
    } else {
      bus->poll_once(steady_now_s());
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (bus->state() == firmware::BusState::kRunning) return;
  }
  throw std::runtime_error("can: the driver board did not answer within 2 s (" + config.can.interface + ")");
}

// One worker per thread, each borrowing only what its thread uses.
void Daemon::Impl::make_workers() {
  const CameraInput input = config.camera.source == "lcm" ? CameraInput::kLcm : CameraInput::kFrames;
  if (world) {
    sim_worker = std::make_unique<SimWorker>(h, *world, *lcm, lockstep, static_cast<int>(board.flippers.size()));
    frame_handoff = std::make_unique<FrameHandoffSource>(
        h, config.camera.fps, cv::Size(config.camera.width_px, config.camera.height_px));
  }
  vision::FrameSource* frames = world ? static_cast<vision::FrameSource*>(frame_handoff.get()) : capture.get();
  camera_worker = std::make_unique<CameraWorker>(
      h, *camera_stage, *lcm, *clock, input, frames, frame_handoff.get(),
      !world && vision::is_device_source(config.camera.device), lcm_observations,
      cv::Size(config.camera.width_px, config.camera.height_px));
  controller_worker =
      std::make_unique<ControllerWorker>(h, *controller_stage, *bus, *lcm, *clock, 1.0 / config.camera.fps);
  driver_worker = std::make_unique<DriverWorker>(h, *bus, *lcm, *clock, driver_of_flipper);
}

void Daemon::Impl::fail_thread(ThreadId id, const std::string& what) {
  // Safe first: ReleaseAll, written now from this thread when the bus is free
  // (the driver thread sends it otherwise); this thread's beats stop, so the
  // heartbeat stops too if it was the camera or the controller.
  bus->release_all();
  bus->send_queued(clock ? clock->now_s() : steady_now_s());
  const std::string line = std::string(kThreadTable[static_cast<std::size_t>(id)].name) + ": " + what;
  {
    const std::lock_guard<std::mutex> lock(warnings_mutex);
    thread_failures.push_back(line);
  }
  h.stop.store(true, std::memory_order_release);
  h.main_bell.ring();
}

// The main thread's watch: every CAN fault on stderr at once, and in the
// report; a failing camera raises the alarm at 1, 10, 100, ... failed reads.
// What stderr does not take at once is dropped (the report keeps every
// fault): a stderr nobody drains must not hold up the release and the exit.
void Daemon::Impl::report_faults() {
  firmware::BusFault f;
  while (bus->pop_fault(f)) {
    const std::string line = firmware::describe(f, liveness.get());
    char stamp[48];
    std::snprintf(stamp, sizeof stamp, "pinballd: t=%.3f s: ", f.t_s);
    write_if_ready(STDERR_FILENO, stamp + line + "\n");
    const std::lock_guard<std::mutex> lock(warnings_mutex);
    ++fault_count;
    if (faults.size() < kMaxReportedFaults) faults.push_back(line);
  }
  const std::uint64_t failed = h.camera_read_failures.load(std::memory_order_relaxed);
  if (failed > 0 && failed >= camera_failures_reported * 10) {
    write_if_ready(STDERR_FILENO, "pinballd: camera: " + std::to_string(failed) + " failed reads (" +
                                      (capture ? capture->describe() : std::string("?")) +
                                      "); retrying with back-off up to 0.1 s\n");
    camera_failures_reported = std::max<std::uint64_t>(failed, 1);
  }
}

void Daemon::Impl::shutdown() {
  // Every coil off first, then no more heartbeats: the board's watchdog
  // stays as the second line of defence.
  ControllerStage::Commands cmds;
  const int n = controller_stage->release_all(CommandCause::kShutdown, clock->now_s(), steady_now_s(), cmds);
  // The queue alone (ReleaseAll first): a poll would add a heartbeat after it when one is due.
  if (world) {
    bus->send_queued(world->time_s());
    world->idle(0.001);  // the board reads the ReleaseAll
    coils_off_at_exit.store(world->all_coils_off(), std::memory_order_release);
  } else {
    bus->send_queued(steady_now_s());
  }
  // Then report it: PINBALL_FLIPPER_CMD promises the shutdown's release (cause "shutdown")
  // like every other command; the LCM thread still runs and publishes it before it stops.
  if (controller_worker) controller_worker->publish(cmds, n);
}

DaemonReport Daemon::Impl::report() const {
  DaemonReport r;
  r.mode = config.mode;
  r.lockstep = lockstep;
  r.identified = config.identified;
  for (int s = 0; s < kStageCount; ++s) r.latency[static_cast<std::size_t>(s)] = h.latency[static_cast<std::size_t>(s)].summary();
  const CameraStageCounters& cc = camera_stage->counters();
  const ControllerStageCounters& kc = controller_stage->counters();
  r.frames = cc.frames;
  r.detections = cc.detections;
  r.projections = cc.projections;
  r.camera_noise_calibrated_m = tracker->config().sigma_m;
  // The tracker belongs to the camera thread: its measurement is read once that thread is done.
  if (threads_joined.load(std::memory_order_acquire)) r.camera_noise_measured_m = tracker->measured_sigma_m();
  r.commands = kc.commands;
  r.camera_stalls = kc.camera_stalls;
  r.ball_lost_releases = kc.ball_lost;
  r.bus_fault_releases = kc.bus_faults;
  r.fires_deferred = kc.deferred;
  r.frames_dropped = h.frames_dropped.load() + (capture ? capture->counters().dropped : 0);
  r.camera_reopens = capture ? capture->counters().reopens : 0;
  r.ring_overflows = h.ring_overflows.load();
  r.lcm = lcm->counters();
  if (frame_log) r.can_log = frame_log->counters();
  r.recording_anchor_s = recording_anchor_s;
  r.driver = bus->counters();
  r.wall_s = steady_now_s() - start_wall_s;
  r.sim_s = h.sim_time_s.load();
  {
    const std::lock_guard<std::mutex> lock(warnings_mutex);
    r.warnings = warnings;
  }
  r.coils_off_at_exit = coils_off_at_exit.load(std::memory_order_acquire);
  r.stopped_by_signal = stop_requested.load(std::memory_order_acquire);
  {
    const std::lock_guard<std::mutex> lock(warnings_mutex);
    r.faults = faults;
    r.fault_count = fault_count;
    r.thread_failures = thread_failures;
  }
  r.camera_read_failures = h.camera_read_failures.load(std::memory_order_relaxed);
  r.cpus = cpus.describe;
  if (world) {
    r.world_board = world_model->board().source;
    r.world = std::string(world_model->name());
    r.world_warnings = world_model->warnings();
    r.results = world->results();
    // The virtual board belongs to the simulator thread: its counters are read once that thread is done.
    if (threads_joined.load(std::memory_order_acquire)) r.board = world->driver_board().counters();
    RunningStats score, time;
    for (const simlab::SimBallResult& b : r.results) {
      score.add(b.score);
      time.add(b.duration_s);
      r.cut_balls += b.cut ? 1 : 0;
    }
    r.balls = static_cast<int>(r.results.size());
    r.balls_asked = config.sim.balls;
    r.mean_score = score.mean();
    r.score_ci95 = score.ci95_half_width();
    r.mean_ball_time_s = time.mean();
  }
  return r;
}

void Daemon::Impl::publish_stats(lcm::LCM&) {
  h.take_injected_fault(kLcmThread);  // the LCM thread's loop is LcmBus's: its hook is here, once a second
  const DaemonReport r = report();
  std::array<bus::StageLatency, kStageCount> stages;
  for (int s = 0; s < kStageCount; ++s) {
    const LatencySummary& x = r.latency[static_cast<std::size_t>(s)];
    stages[static_cast<std::size_t>(s)] = {stage_name(s), x.count, x.p50_us, x.p99_us, x.max_us};
  }
  bus::DaemonStatsCounts counts;
  counts.frames = r.frames;
  counts.frames_dropped = r.frames_dropped;
  counts.detections = r.detections;
  counts.projections = r.projections;
  counts.commands = r.commands;
  counts.camera_stalls = r.camera_stalls;
  counts.malformed_messages = r.lcm.malformed;
  counts.ring_overflows = r.ring_overflows + r.lcm.overflows;
  counts.lcm_published = r.lcm.published;
  counts.lcm_publish_failed = r.lcm.publish_failed;
  if (r.can_log) {
    counts.can_log_written = r.can_log->written;
    counts.can_log_dropped = r.can_log->dropped();
  }
  const pinball_lcm::lcmt_pinball_daemon_stats m =
      bus::to_lcm_daemon_stats(to_utime(clock->now_s()), stats_seq++, stages, counts);
  lcm->publish_now(bus::kStatsChannel, m);  // counted like every other message
}

Daemon::Daemon(const DaemonConfig& config) : impl_(std::make_unique<Impl>()) {
  impl_->config = config;
  validate_daemon_config(config, config.origin);
  check_written_paths(config, config.origin);
  impl_->build();
}

Daemon::~Daemon() {
  if (impl_ && impl_->lcm) impl_->lcm->stop();
}

DaemonReport Daemon::run() {
  Impl& d = *impl_;
  d.start_wall_s = steady_now_s();
  if (d.config.threads.realtime) {
    std::string why;
    if (!lock_memory(why)) d.warnings.push_back(why);  // before any thread starts
    // Probe SCHED_FIFO on a throw-away thread, so that `enforce` refuses before anything runs.
    const std::string probe_why = probe_sched_fifo(kDriverThread, d.config.threads.priorities[kDriverThread]);
    if (!probe_why.empty()) {
      d.warnings.push_back(probe_why);
      d.fifo_allowed = false;
    }
    if (d.config.threads.enforce && !d.warnings.empty()) {
      throw std::runtime_error("real-time scheduling refused (threads.enforce: true): " + d.warnings.front());
    }
    for (const std::string& w : d.warnings) std::fprintf(stderr, "pinballd: warning: %s; running without it\n", w.c_str());
  }
  std::unique_ptr<CpuLatencyRequest> cpu_latency;
  if (d.config.threads.cpu_dma_latency_us >= 0) {
    cpu_latency = std::make_unique<CpuLatencyRequest>(d.config.threads.cpu_dma_latency_us);
    if (!cpu_latency->ok()) {
      if (d.config.threads.enforce) throw std::runtime_error("threads.cpu_dma_latency_us refused: " + cpu_latency->why());
      std::fprintf(stderr, "pinballd: warning: %s; running without it\n", cpu_latency->why().c_str());
      const std::lock_guard<std::mutex> lock(d.warnings_mutex);
      d.warnings.push_back(cpu_latency->why());
    }
  }
  d.learn_background();
  d.open_can_log();
  d.warm_up_bus();
  // The simulated clock's offset before any thread reads it: the driver
  // thread's first poll must not see the steady clock's epoch (a false
  // Status timeout); the simulator thread refreshes it when it starts.
  if (d.world) d.h.wall_offset_s.store(steady_now_s() - d.world->time_s(), std::memory_order_release);
  d.start_recording_clock();
  d.lcm->start([&d](lcm::LCM& l) { d.guarded(kLcmThread, [&] { d.publish_stats(l); }); }, 1.0,
               [&d] { d.enter_thread(kLcmThread); },
               [&d](const std::string& what) { d.fail_thread(kLcmThread, what); });
  d.make_workers();
  std::thread driver([&d] {
    d.guarded(kDriverThread, [&d] {
      d.enter_thread(kDriverThread);
      d.driver_worker->run();
    });
  });
  std::thread controller([&d] {
    d.guarded(kControllerThread, [&d] {
      d.enter_thread(kControllerThread);
      d.controller_worker->run();
    });
  });
  std::thread camera([&d] {
    d.guarded(kCameraThread, [&d] {
      d.enter_thread(kCameraThread);
      d.camera_worker->run();
    });
  });
  std::thread world;
  if (d.sim_worker) {
    world = std::thread([&d] {
      d.guarded(kSimThread, [&d] {
        d.enter_thread(kSimThread);
        d.sim_worker->run();
      });
    });
  }
  LiveStatus live = LiveStatus::for_stderr(d.sim_mode ? d.config.sim.balls : 0, d.lockstep, d.config.progress);
  while (!d.h.stop.load(std::memory_order_acquire) && !d.h.controller_done.load(std::memory_order_acquire)) {
    d.h.main_bell.wait(0.1);
    d.report_faults();
    if (d.stats_requested.exchange(false)) write_if_ready(STDERR_FILENO, report_to_text(d.report()));
    live.tick([&d] { return d.report(); });
  }
  d.h.stop.store(true, std::memory_order_release);
  for (Doorbell* b : {&d.h.camera_bell, &d.h.controller_bell, &d.h.driver_bell, &d.h.sim_bell}) b->ring();
  if (world.joinable()) world.join();
  camera.join();
  controller.join();
  driver.join();
  d.shutdown();
  live.finish([&d] { return d.report(); });  // after the coils are off: it writes to stderr
  d.report_faults();
  // The CAN log's last frame is the shutdown's ReleaseAll: closed (what the sink takes within its
  // grace, the rest counted) before the LCM thread's last PINBALL_STATS, which carries its counters.
  if (d.frame_log) d.frame_log->close();
  d.lcm->stop();
  d.threads_joined.store(true, std::memory_order_release);  // nothing else runs: the board may be read
  return d.report();
}

void Daemon::request_stop() {
  impl_->stop_requested.store(true, std::memory_order_release);
  impl_->h.stop.store(true, std::memory_order_release);
  impl_->h.main_bell.ring();
}

void Daemon::request_stats() {
  impl_->stats_requested.store(true, std::memory_order_release);
  impl_->h.main_bell.ring();
}

DaemonReport Daemon::snapshot() const { return impl_->report(); }
bus::LcmBus& Daemon::lcm_bus() { return *impl_->lcm; }
firmware::DriverBus& Daemon::driver_bus() { return *impl_->bus; }

void Daemon::emergency_release() {
  if (!impl_->bus) return;
  impl_->bus->release_all();
  impl_->bus->send_queued(steady_now_s());
}

void Daemon::inject_fault(int thread, double freeze_s, bool fail) {
  if (thread < 0 || thread >= kThreadCount) throw std::invalid_argument("inject_fault: no thread " + std::to_string(thread));
  InjectedFault& f = impl_->h.injected[static_cast<std::size_t>(thread)];
  f.freeze_s.store(freeze_s, std::memory_order_relaxed);
  f.fail.store(fail, std::memory_order_relaxed);
}

bool camera_noisier_than_calibrated(const DaemonReport& r) {
  return r.camera_noise_measured_m && track::measured_noise_overrides(*r.camera_noise_measured_m, r.camera_noise_calibrated_m);
}

std::string recording_problems(const DaemonReport& r) {
  std::string lost;
  if (r.can_log && !r.can_log->complete()) {
    const firmware::FrameLogCounters& c = *r.can_log;
    lost = std::to_string(c.dropped()) + " CAN frames dropped (" + std::to_string(c.dropped_queue_full) +
           " queue full, " + std::to_string(c.dropped_write_error) + " write errors, " +
           std::to_string(c.dropped_at_close) + " at close), first: " + c.first_error;
  }
  if (r.lcm.publish_failed > 0) {
    if (!lost.empty()) lost += "; ";
    lost += std::to_string(r.lcm.publish_failed) + " LCM messages refused, first: " + r.lcm.first_failure;
  }
  if (r.lcm.dropped_queue_full > 0) {
    if (!lost.empty()) lost += "; ";
    lost += std::to_string(r.lcm.dropped_queue_full) + " LCM messages dropped: the LCM thread fell behind";
  }
  return lost;
}

std::string lcm_pace_warning(const DaemonConfig& config) {
  const bool lockstep = config.mode == "sim" && config.camera.source != "lcm" && !config.sim.realtime;
  if (!lockstep || config.lcm_url.rfind("udpm://", 0) != 0) return "";
  return "lcm_url '" + config.lcm_url +
         "' with the lockstep clock: the run publishes many times faster than real time and a logger on the "
         "network loses messages it cannot keep up with; record with --lcm-url 'file:///PATH?mode=w' (every "
         "message, stamped on the game's clock) or run --realtime";
}

std::string sim_watchdog_warning(const DaemonConfig& config) {
  const bool plays_world = config.mode == "sim" && config.camera.source == "sim";
  const double frame_period_s = 1.0 / config.camera.fps;
  if (!plays_world || frame_period_s < config.can.watchdog_timeout_s) return "";
  return "camera.fps " + format_number(config.camera.fps) + ": the simulated board hears the host only between " +
         "frames, so its " + format_number(config.can.watchdog_timeout_s) + " s watchdog trips every " +
         format_number(frame_period_s) + " s frame and drops the coils (a real board would not); for play, raise " +
         "camera.fps above " + format_number(1.0 / config.can.watchdog_timeout_s);
}

std::vector<std::string> config_warnings(const DaemonConfig& config) {
  std::vector<std::string> warnings;
  for (std::string w : {lcm_pace_warning(config), sim_watchdog_warning(config)}) {
    if (!w.empty()) warnings.push_back(std::move(w));
  }
  return warnings;
}

nlohmann::json latency_to_json(const LatencySummary& x) {
  const auto us = [&x](double v) { return x.count > 0 ? nlohmann::json(v) : nlohmann::json(); };
  return {{"count", x.count}, {"p50_us", us(x.p50_us)}, {"p99_us", us(x.p99_us)}, {"max_us", us(x.max_us)}};
}

nlohmann::json report_to_json(const DaemonReport& r) {
  nlohmann::json j;
  j["mode"] = r.mode;
  j["clock"] = r.mode == "sim" ? (r.lockstep ? "lockstep" : "realtime") : "steady";
  j["identified"] = r.identified.empty() ? nlohmann::json() : nlohmann::json(r.identified);
  if (r.mode == "sim") {
    // "stepper" names the world (thesis, event or twin), as before the twin;
    // null when observations come from LCM and no world plays.
    j["world"] = r.world.empty() ? nlohmann::json()
                                 : nlohmann::json{{"board", r.world_board},
                                                  {"stepper", r.world},
                                                  {"warnings", to_json_value(r.world_warnings)}};
  }
  j["balls"] = r.balls;
  j["balls_asked"] = r.balls_asked;
  j["stopped_by_signal"] = r.stopped_by_signal;
  // No ball, no mean: null, not 0.
  j["mean_score_per_ball"] = r.balls > 0 ? nlohmann::json(r.mean_score) : nlohmann::json();
  j["score_ci95_half_width"] = r.score_ci95;
  j["mean_ball_time_s"] = r.balls > 0 ? nlohmann::json(r.mean_ball_time_s) : nlohmann::json();
  j["balls_cut_at_time_limit"] = r.cut_balls;
  nlohmann::json scores = nlohmann::json::array();
  for (const simlab::SimBallResult& b : r.results) scores.push_back(b.score);
  j["ball_scores"] = scores;
  nlohmann::json lat = nlohmann::json::object();
  for (int s = 0; s < kStageCount; ++s) {
    lat[stage_name(s)] = latency_to_json(r.latency[static_cast<std::size_t>(s)]);
  }
  j["latency"] = lat;
  j["frames"] = r.frames;
  j["frames_dropped"] = r.frames_dropped;
  j["camera_reopens"] = r.camera_reopens;
  j["detections"] = r.detections;
  j["projections"] = r.projections;
  j["camera_noise"] = {{"calibrated_m", r.camera_noise_calibrated_m},
                       {"measured_m", r.camera_noise_measured_m ? nlohmann::json(*r.camera_noise_measured_m) : nlohmann::json()},
                       {"over_calibration", camera_noisier_than_calibrated(r)}};
  j["commands"] = r.commands;
  j["camera_stalls"] = r.camera_stalls;
  j["ball_lost_releases"] = r.ball_lost_releases;
  j["bus_fault_releases"] = r.bus_fault_releases;
  j["fires_deferred"] = r.fires_deferred;
  j["ring_overflows"] = r.ring_overflows;
  j["lcm"] = {{"published", r.lcm.published}, {"publish_failed", r.lcm.publish_failed},
              {"first_failure", r.lcm.first_failure}, {"overflows", r.lcm.overflows},
              {"dropped_queue_full", r.lcm.dropped_queue_full}, {"received", r.lcm.received},
              {"malformed", r.lcm.malformed}};
  j["can_log"] = nullptr;
  if (const auto& c = r.can_log) {
    j["can_log"] = {{"written", c->written}, {"dropped", c->dropped()}, {"dropped_queue_full", c->dropped_queue_full},
                    {"dropped_write_error", c->dropped_write_error}, {"dropped_at_close", c->dropped_at_close},
                    {"first_errno", c->first_errno}, {"first_error", c->first_error}};
  }
  j["recording_complete"] = recording_problems(r).empty();
  j["recording_anchor_s"] = r.recording_anchor_s;
  j["can"] = {{"frames_sent", r.driver.frames_sent}, {"heartbeats", r.driver.heartbeats},
              {"fires", r.driver.fires}, {"releases", r.driver.releases}, {"release_alls", r.driver.release_alls},
              {"bus_off", r.driver.bus_off}, {"reconnects", r.driver.reconnects},
              {"tx_failures", r.driver.tx_failures}, {"rx_bad", r.driver.rx_bad},
              {"dropped_not_running", r.driver.dropped_not_running},
              {"release_retries", r.driver.release_retries}, {"release_escalations", r.driver.release_escalations},
              {"liveness_stalls", r.driver.liveness_stalls}, {"heartbeats_withheld", r.driver.heartbeats_withheld},
              {"watchdog_faults", r.driver.watchdog_faults}, {"hold_cap_faults", r.driver.hold_cap_faults},
              {"stale_faults", r.driver.stale_faults}, {"locked_faults", r.driver.locked_faults},
              {"refused_faults", r.driver.refused_faults}, {"coils_dropped", r.driver.coils_dropped},
              {"faults", r.driver.faults}};
  j["faults"] = {{"count", r.fault_count}, {"listed", r.faults}};
  j["camera_read_failures"] = r.camera_read_failures;
  j["thread_failures"] = r.thread_failures;
  j["board"] = {{"fires_accepted", r.board.fires_accepted}, {"watchdog_trips", r.board.watchdog_trips},
                {"bad_frames", r.board.bad_frames}, {"refused_recycle", r.board.refused_recycle}};
  j["coils_off_at_exit"] = r.coils_off_at_exit;
  j["wall_s"] = r.wall_s;
  j["sim_s"] = r.sim_s;
  j["cpus"] = r.cpus;
  j["warnings"] = r.warnings;
  return j;
}

std::string report_to_text(const DaemonReport& r) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(1);
  if (r.mode == "sim") {
    o << "balls " << r.balls;
    if (r.stopped_by_signal && r.balls < r.balls_asked) o << " of " << r.balls_asked << " (stopped by a signal)";
    if (r.balls > 0) {
      o << "  mean score per ball " << format_mean_ci(r.mean_score, r.score_ci95) << " (95 %)  mean ball time "
        << format_number(r.mean_ball_time_s) << " s";
    }
    if (r.cut_balls > 0) o << "  cut " << r.cut_balls;
    o << "\n";
    if (r.world.empty()) {
      o << "world none: observations from LCM drive the tracker\n";
    } else if (r.world != "thesis") {
      o << "world " << r.world << " on " << r.world_board << "  " << describe(r.world_warnings) << "\n";
    }
  }
  if (!r.identified.empty()) o << "identified " << r.identified << " laid over the belief\n";
  o << std::setprecision(1);
  o << "frames " << r.frames << " (dropped " << r.frames_dropped << ")  ball seen " << r.detections
    << "  projections " << r.projections << "  commands " << r.commands << "  stalls " << r.camera_stalls
    << "  malformed LCM " << r.lcm.malformed << "\n";
  if (r.camera_noise_measured_m) {
    o << std::setprecision(2) << "camera noise " << *r.camera_noise_measured_m * 1e3 << " mm measured, "
      << r.camera_noise_calibrated_m * 1e3 << " mm calibrated"
      << (camera_noisier_than_calibrated(r)
              ? ": the tracker weighs by the measured noise; calibrate the camera again (docs/calibration.md)"
              : "")
      << "\n" << std::setprecision(1);
  }
  o << std::left << std::setw(24) << "latency (us)" << std::right << std::setw(10) << "count" << std::setw(10)
    << "p50" << std::setw(10) << "p99" << std::setw(10) << "max" << "\n";
  for (int s = 0; s < kStageCount; ++s) {
    const LatencySummary& x = r.latency[static_cast<std::size_t>(s)];
    o << std::left << std::setw(24) << stage_name(s) << std::right << std::setw(10) << x.count;
    if (x.count > 0) {
      o << std::setw(10) << x.p50_us << std::setw(10) << x.p99_us << std::setw(10) << x.max_us;
    } else {
      o << std::setw(10) << "-" << std::setw(10) << "-" << std::setw(10) << "-";
    }
    o << "\n";
  }
  o << "recordings: ";
  if (r.can_log) o << "CAN log " << r.can_log->written << " frames written, " << r.can_log->dropped() << " dropped; ";
  o << "LCM " << r.lcm.published << " published, " << r.lcm.publish_failed << " refused, " << r.lcm.dropped_queue_full
    << " dropped\n";
  if (const std::string lost = recording_problems(r); !lost.empty()) o << "recording INCOMPLETE: " << lost << "\n";
  o << "threads: " << r.cpus << "\n";
  const firmware::DriverBusCounters& k = r.driver;
  if (r.fault_count + k.release_retries + k.liveness_stalls > 0) {
    o << "CAN faults " << r.fault_count << "  release retries " << k.release_retries << "  escalations "
      << k.release_escalations << "  chain stalls " << k.liveness_stalls << "  watchdog " << k.watchdog_faults
      << "  hold cap " << k.hold_cap_faults << "\n";
    for (const std::string& f : r.faults) o << "fault: " << f << "\n";
    if (r.fault_count > r.faults.size()) o << "fault: ... and " << r.fault_count - r.faults.size() << " more\n";
  }
  if (r.camera_read_failures > 0) o << "camera: " << r.camera_read_failures << " failed reads\n";
  for (const std::string& f : r.thread_failures) o << "thread failed: " << f << "\n";
  for (const std::string& w : r.warnings) o << "warning: " << w << "\n";
  return o.str();
}

}  // namespace pinball::daemon
