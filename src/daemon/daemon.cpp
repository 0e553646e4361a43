#include "pinball/daemon/daemon.h"

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
#include "pinball/control/actuator_controller.h"
#include "pinball/control/controller_file.h"
#include "pinball/core/running_stats.h"
#include "pinball/core/clock.h"
#include "pinball/daemon/doorbell.h"
#include "pinball/daemon/hot_path.h"
#include "pinball/daemon/pipeline.h"
#include "pinball/daemon/thread_table.h"
#include "pinball/firmware/frame_log.h"
#include "pinball/firmware/socketcan_transport.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/simlab/world_factory.h"
#include "pinball/table/board_loader.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/vision/capture_source.h"
#include "pinball/simlab/sim_camera_source.h"

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

// A frame and what was read with it, handed from the frame producer to the camera thread.
struct FrameSlot {
  vision::Frame frame;
  track::ContactSensors contacts;
  double capture_wall_s = 0.0;
};

constexpr std::size_t kFrameQueue = 4;              // frames waiting for the camera thread
constexpr std::size_t kFramePool = kFrameQueue + 2; // + one being processed + one being written

firmware::DriverBusOptions bus_options(const DaemonConfig& c, int drivers) {
  firmware::DriverBusOptions o;
  o.board_id = static_cast<std::uint8_t>(c.can.board_id);
  o.driver_count = drivers;
  for (auto& d : o.drivers) d = c.coils;
  o.heartbeat_period_s = c.can.heartbeat_period_s;
  o.watchdog_timeout_s = c.can.watchdog_timeout_s;
  return o;
}

}  // namespace

struct Daemon::Impl {
  DaemonConfig config;
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
  std::unique_ptr<firmware::FrameLog> frame_log;  // optional candump log
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
  // Hand-offs.
  std::array<FrameSlot, kFramePool> pool;
  SpscRing<int, kFrameQueue> frames;
  SpscRing<ProjectionRecord, 64> records;
  SpscRing<CommandRecord, 64> commands;
  Doorbell camera_bell, controller_bell, driver_bell, sim_bell, main_bell;
  std::atomic<bool> stop{false};
  std::atomic<bool> stats_requested{false};
  std::atomic<bool> producer_done{false};
  std::atomic<bool> camera_done{false};
  std::atomic<bool> controller_done{false};
  std::atomic<std::uint64_t> frames_pushed{0};
  std::atomic<std::uint64_t> records_done{0};   // records the controller finished
  std::atomic<std::uint64_t> driver_done{0};    // records whose commands the driver sent
  std::atomic<double> virtual_now_s{0.0};       // lockstep: exposure time of the latest record
  std::atomic<std::uint64_t> frames_dropped{0};
  std::atomic<std::uint64_t> ring_overflows{0};
  std::atomic<double> sim_time_s{0.0};
  std::array<std::atomic<double>, firmware::kMaxDrivers> can_written_wall_s{};
  double wall_offset_s = 0.0;                   // sim realtime: wall = sim + offset
  std::array<LatencyHistogram, kStageCount> latency;
  mutable std::mutex warnings_mutex;
  std::vector<std::string> warnings;
  double start_wall_s = 0.0;
  bool coils_off_at_exit = true;
  std::uint64_t last_coil_on_count = 0;
  std::int64_t stats_seq = 0;  // PINBALL_STATS sequence (the LCM thread only)

  double pipeline_now_s() const {
    if (!sim_mode) return steady_now_s();
    if (lockstep) return virtual_now_s.load(std::memory_order_acquire);
    return steady_now_s() - wall_offset_s;
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
  void warm_up_bus();
  void sim_thread();
  void camera_thread();
  void controller_thread();
  void driver_thread();
  void send_now(ControllerStage::Commands& cmds, int n, double now_s);
  void publish_commands(const ControllerStage::Commands& cmds, int n);
  void publish_stats(lcm::LCM& lcm);
  void shutdown();
  DaemonReport report() const;
};

// A relative path that does not exist from the working directory is looked up
// in the source tree the daemon was built from, so that the defaults
// (boards/mit1993.board, controllers/best.json) work from any directory.
std::string find_data_file(const std::string& path) {
  if (path.empty() || path.front() == '/' || std::filesystem::exists(path)) return path;
  const std::string in_tree = std::string(PINBALL_DATA_DIR) + "/" + path;
  return std::filesystem::exists(in_tree) ? in_tree : path;
}

void Daemon::Impl::build() {
  sim_mode = config.mode == "sim";
  cpus = plan_cpus(config.threads.chain_cpu);
  config.sim.board = find_data_file(config.sim.board);
  if (!config.sim.world_board.empty()) config.sim.world_board = find_data_file(config.sim.world_board);
  config.board = find_data_file(config.board);
  config.controller = find_data_file(config.controller);
  lockstep = sim_mode && !config.sim.realtime;
  board = table::load_board(sim_mode ? config.sim.board : config.board);
  spec = control::load_controller(config.controller);
  controller = control::make_flipper_controller(spec);
  driver_of_flipper = controller_stage_options_for(config, board).driver_of_flipper;
  const int drivers = static_cast<int>(board.flippers.size());

  if (config.can.interface == "sim") {
    auto [host, far] = firmware::StreamTransport::make_pair();
    host_link = std::move(host);
    board_link = std::move(far);
  } else {
    firmware::SocketCanOptions o;
    o.interface = config.can.interface;
    host_link = std::make_unique<firmware::SocketCanTransport>(o);
  }
  firmware::DriverBusOptions bo = bus_options(config, drivers);
  if (!config.can.log.empty()) {
    frame_log = std::make_unique<firmware::FrameLog>(config.can.log,
                                                     config.can.interface == "sim" ? "simcan" : config.can.interface);
    bo.log = frame_log.get();
  }
  bus = std::make_unique<firmware::DriverBus>(*host_link, bo);

  TrackingSetup setup = tracking_setup_for(config, board);
  tracker = std::make_unique<track::Tracker>(setup.geometry, setup.tracker);

  cv::Size frame_size(config.camera.width_px, config.camera.height_px);
  if (sim_mode) {
    simlab::SimCameraConfig cc;
    cc.width_px = config.camera.width_px;
    cc.height_px = config.camera.height_px;
    cc.fps = config.camera.fps;
    cc.seed = config.sim.seed;
    simlab::SimWorldOptions wo;
    wo.balls = config.sim.balls;
    wo.seed = config.sim.seed;
    wo.actuation_delay_s = config.sim.actuation_delay_s;
    wo.max_ball_time_s = config.sim.max_ball_time_s;
    wo.launcher_pull = spec.launcher_pull;
    simlab::WorldSpec ws;
    ws.board_path = config.sim.world_board;
    ws.stepper = config.sim.stepper;
    world_model = simlab::make_world(ws, board);
    world = std::make_unique<simlab::SimWorld>(*world_model, *board_link, cc, wo);
    // A calibration file (e.g. from `pinball calibrate camera --sim`) stands in
    // for the simulated camera's true homography, as it would in the lab.
    homography = std::make_unique<vision::CameraHomography>(setup.homography ? *setup.homography
                                                                             : world->camera().homography());
  } else if (config.camera.source != "lcm") {
    if (!setup.homography) {
      throw ConfigError("config: calibration: the lab camera needs a calibration file with a camera section "
                        "(docs/calibration.md)");
    }
    homography = std::make_unique<vision::CameraHomography>(*setup.homography);
  }
  if (homography) {
    // OpenCV's thread pool would hand the camera thread's work to threads
    // outside the thread table, allocate task objects per call and add jitter:
    // the detector runs on the camera thread alone.
    cv::setNumThreads(1);
    vision::BallDetectorConfig dc;
    dc.ball_radius_m = board.ball.radius_m;
    detector = std::make_unique<vision::BallDetector>(*homography, frame_size, dc);
    if (world) detector->set_occluder_mask(world->camera().occluder_mask());
  }
  camera_stage = std::make_unique<CameraStage>(detector.get(), *tracker, lost_after_s_for(config));
  controller_stage =
      std::make_unique<ControllerStage>(*controller, *bus, controller_stage_options_for(config, board));

  lcm = std::make_unique<bus::LcmBus>(config.lcm_url);
  if (config.camera.source == "lcm") lcm->subscribe_observations(lcm_observations);
  for (auto& slot : pool) slot.frame.gray.create(frame_size, CV_8UC1);
}

void Daemon::Impl::learn_background() {
  if (!detector) return;
  vision::Frame f;
  f.gray.create(cv::Size(config.camera.width_px, config.camera.height_px), CV_8UC1);
  for (int i = 0; i < config.camera.background_frames; ++i) {
    if (world) {
      world->render_background(f, -1.0 - i / config.camera.fps);
    } else if (!capture->read(f)) {
      throw std::runtime_error("camera: no frame for the background (" + capture->describe() + ")");
    }
    detector->background().add_training_frame(f.gray);
  }
  detector->background().finish_training();
}

void Daemon::Impl::warm_up_bus() {
  // Before the first ball: let the bus and the board finish their handshake,
  // on the world's clock in sim mode (the table idles), else on the steady clock.
  const double deadline_s = 2.0;
  for (double t = 0.0; t < deadline_s; t += 0.001) {
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

void Daemon::Impl::sim_thread() {
  enter_thread(kSimThread);
  std::uint64_t pushed = 0;
  std::uint64_t seq = 0;
  auto on_event = [&](const simlab::GameEvent& e) {
    lcm->try_publish(bus::to_lcm_game_event(to_utime(e.t_s), static_cast<std::int64_t>(seq++), e.kind, e.ball,
                                            e.points, e.ball_time_s));
  };
  wall_offset_s = steady_now_s() - world->time_s();
  while (!stop.load(std::memory_order_acquire)) {
    FrameSlot& slot = pool[pushed % kFramePool];
    if (!world->next_frame(slot.frame, slot.contacts, on_event)) break;
    sim_time_s.store(world->time_s(), std::memory_order_relaxed);
    // Coil-on stamps of the virtual board close the latency chain.
    if (world->coil_on_count() != last_coil_on_count) {
      last_coil_on_count = world->coil_on_count();
      for (int d = 0; d < static_cast<int>(board.flippers.size()); ++d) {
        const double written = can_written_wall_s[static_cast<std::size_t>(d)].exchange(0.0);
        if (written > 0.0) latency[kCanToCoil].record((world->coil_on_wall_s(d) - written) * 1e6);
      }
    }
    if (!lockstep) {
      // Pace to the wall clock.
      const double wait_s = slot.frame.t_s + wall_offset_s - steady_now_s();
      if (wait_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
    }
    slot.capture_wall_s = steady_now_s();
    if (!frames.try_push(static_cast<int>(pushed % kFramePool))) {
      frames_dropped.fetch_add(1, std::memory_order_relaxed);  // the camera thread is behind: this frame is lost
      continue;
    }
    ++pushed;
    frames_pushed.store(pushed, std::memory_order_release);
    camera_bell.ring();
    if (lockstep) {
      while (driver_done.load(std::memory_order_acquire) < pushed && !stop.load(std::memory_order_acquire)) {
        sim_bell.wait(0.1);
      }
    }
  }
  producer_done.store(true, std::memory_order_release);
  camera_bell.ring();
}

void Daemon::Impl::camera_thread() {
  enter_thread(kCameraThread);
  ProjectionRecord record;
  FrameSlot lab_slot;
  const bool from_lcm = config.camera.source == "lcm";
  while (!stop.load(std::memory_order_acquire)) {
    const FrameSlot* slot = nullptr;
    pinball_lcm::lcmt_pinball_observation incoming;
    int index = -1;
    if (world) {
      if (!frames.try_pop(index)) {
        if (producer_done.load(std::memory_order_acquire) && frames.empty()) break;
        camera_bell.wait(0.05);
        continue;
      }
      slot = &pool[static_cast<std::size_t>(index)];
    } else if (from_lcm) {
      if (!lcm_observations.try_pop(incoming)) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
    } else {
      if (!capture->read(lab_slot.frame)) {  // the camera's own blocking grab
        if (!vision::is_device_source(config.camera.device)) break;  // end of the video file
        continue;
      }
      lab_slot.capture_wall_s = steady_now_s();
      slot = &lab_slot;
    }
    {
      HotPathScope hot;
      if (slot != nullptr) {
        camera_stage->process(slot->frame, slot->contacts, slot->capture_wall_s, record);
      } else {
        bool found = false;
        track::Observation o;
        track::ContactSensors c;
        bus::from_lcm_observation(incoming, found, o, c);
        const double now = steady_now_s();
        camera_stage->track(found, o, o.t_s, c, now, record);
        record.detected_wall_s = now;
      }
      record.projected_wall_s = steady_now_s();
      if (slot != nullptr) {
        latency[kCaptureToDetection].record((record.detected_wall_s - record.capture_wall_s) * 1e6);
      }
      latency[kDetectionToProjection].record((record.projected_wall_s - record.detected_wall_s) * 1e6);
      if (!records.try_push(record)) ring_overflows.fetch_add(1, std::memory_order_relaxed);
      controller_bell.ring();
      const std::int64_t utime = to_utime(record.t_s);
      if (!from_lcm) {
        lcm->try_publish(bus::to_lcm_observation(utime, static_cast<std::int64_t>(record.frame_seq), record.found,
                                                 record.observation, record.u_px, record.v_px, record.contacts));
      }
      lcm->try_publish(bus::to_lcm_projection(utime, static_cast<std::int64_t>(record.seq),
                                              static_cast<std::int64_t>(record.frame_seq), record.output));
    }
  }
  camera_done.store(true, std::memory_order_release);
  controller_bell.ring();
}

// Writes the commands' CAN frames on the controller thread, saving the wake-up
// of the driver thread; when the driver thread is busy sending, it takes them.
void Daemon::Impl::send_now(ControllerStage::Commands& cmds, int n, double now_s) {
  if (n == 0 || !bus->send_queued(now_s)) return;
  const double written = steady_now_s();
  for (int i = 0; i < n; ++i) cmds[static_cast<std::size_t>(i)].written_wall_s = written;
}

void Daemon::Impl::publish_commands(const ControllerStage::Commands& cmds, int n) {
  for (int i = 0; i < n; ++i) {
    const CommandRecord& c = cmds[static_cast<std::size_t>(i)];
    if (!commands.try_push(c)) ring_overflows.fetch_add(1, std::memory_order_relaxed);
    lcm->try_publish(bus::to_lcm_flipper_command(to_utime(c.t_s), static_cast<std::int64_t>(c.seq), c.projection_seq,
                                                 c.flipper, c.energize, static_cast<std::int8_t>(c.cause)));
  }
}

void Daemon::Impl::controller_thread() {
  enter_thread(kControllerThread);
  ProjectionRecord record;
  ControllerStage::Commands cmds;
  const double frame_period_s = 1.0 / config.camera.fps;
  while (!stop.load(std::memory_order_acquire)) {
    if (records.try_pop(record)) {
      HotPathScope hot;
      if (lockstep) virtual_now_s.store(record.t_s, std::memory_order_release);
      const double now = lockstep ? record.t_s : pipeline_now_s();
      const int n = controller_stage->on_record(record, now, steady_now_s(), cmds);
      send_now(cmds, n, now);
      latency[kProjectionToDecision].record((steady_now_s() - record.projected_wall_s) * 1e6);
      publish_commands(cmds, n);
      records_done.fetch_add(1, std::memory_order_acq_rel);
      driver_bell.ring();
      continue;
    }
    if (camera_done.load(std::memory_order_acquire) && records.empty()) break;
    controller_bell.wait(frame_period_s);
    if (!lockstep) {
      HotPathScope hot;
      const double now = pipeline_now_s();
      const int n = controller_stage->on_idle(now, steady_now_s(), cmds);
      send_now(cmds, n, now);
      if (n > 0) {
        publish_commands(cmds, n);
        driver_bell.ring();
      }
    }
  }
  controller_done.store(true, std::memory_order_release);
  driver_bell.ring();
}

void Daemon::Impl::driver_thread() {
  enter_thread(kDriverThread);
  CommandRecord c;
  double next_status_s = 0.0;
  std::uint64_t status_seq = 0;
  while (!stop.load(std::memory_order_acquire)) {
    std::uint64_t done = 0;
    if (lockstep) {
      done = records_done.load(std::memory_order_acquire);
      if (done == driver_done.load(std::memory_order_relaxed)) {
        if (controller_done.load(std::memory_order_acquire)) break;
        driver_bell.wait(0.05);
        continue;
      }
    } else {
      driver_bell.wait(0.001);
      if (controller_done.load(std::memory_order_acquire) && commands.empty()) break;
    }
    const double now = pipeline_now_s();
    bus->poll_once(now);
    const double polled = steady_now_s();
    while (commands.try_pop(c)) {
      const double written = c.written_wall_s > 0.0 ? c.written_wall_s : polled;  // > 0: sent by the controller thread
      latency[kCommandToCan].record((written - c.command_wall_s) * 1e6);
      if (c.capture_wall_s > 0.0) latency[kFrameToCan].record((written - c.capture_wall_s) * 1e6);
      if (c.energize && c.flipper >= 0) {
        can_written_wall_s[static_cast<std::size_t>(driver_of_flipper[static_cast<std::size_t>(c.flipper)])].store(
            written);
      }
    }
    if (now >= next_status_s) {
      next_status_s = now + 0.1;
      lcm->try_publish(bus::to_lcm_driver_status(to_utime(now), static_cast<std::int64_t>(status_seq++),
                                                 bus->state(), bus->board(), bus->counters()));
    }
    if (lockstep) {
      driver_done.store(done, std::memory_order_release);
      sim_bell.ring();
    }
  }
  if (lockstep) {
    driver_done.store(~std::uint64_t{0}, std::memory_order_release);
    sim_bell.ring();
  }
}

void Daemon::Impl::shutdown() {
  // Every coil off first, then no more heartbeats: the board's watchdog
  // stays as the second line of defence.
  ControllerStage::Commands cmds;
  controller_stage->release_all(CommandCause::kShutdown, pipeline_now_s(), steady_now_s(), cmds);
  if (world) {
    const double t = world->time_s();
    bus->poll_once(t);
    world->idle(0.001);  // the board reads the ReleaseAll
    coils_off_at_exit = world->all_coils_off();
  } else {
    bus->poll_once(steady_now_s());
  }
}

DaemonReport Daemon::Impl::report() const {
  DaemonReport r;
  r.mode = config.mode;
  r.lockstep = lockstep;
  for (int s = 0; s < kStageCount; ++s) r.latency[static_cast<std::size_t>(s)] = latency[static_cast<std::size_t>(s)].summary();
  const CameraStageCounters& cc = camera_stage->counters();
  const ControllerStageCounters& kc = controller_stage->counters();
  r.frames = cc.frames;
  r.detections = cc.detections;
  r.projections = cc.projections;
  r.commands = kc.commands;
  r.camera_stalls = kc.camera_stalls;
  r.ball_lost_releases = kc.ball_lost;
  r.bus_fault_releases = kc.bus_faults;
  r.fires_deferred = kc.deferred;
  r.frames_dropped = frames_dropped.load() + (capture ? capture->counters().dropped : 0);
  r.ring_overflows = ring_overflows.load();
  r.lcm = lcm->counters();
  r.driver = bus->counters();
  r.wall_s = steady_now_s() - start_wall_s;
  r.sim_s = sim_time_s.load();
  {
    const std::lock_guard<std::mutex> lock(warnings_mutex);
    r.warnings = warnings;
  }
  r.coils_off_at_exit = coils_off_at_exit;
  r.cpus = cpus.describe;
  if (world) {
    r.world_board = world_model->board().source;
    r.world = std::string(world_model->name());
    r.results = world->results();
    r.board = world->driver_board().counters();
    RunningStats score, time;
    for (const simlab::SimBallResult& b : r.results) {
      score.add(b.score);
      time.add(b.duration_s);
      r.cut_balls += b.cut ? 1 : 0;
    }
    r.balls = static_cast<int>(r.results.size());
    r.mean_score = score.mean();
    r.score_ci95 = score.ci95_half_width();
    r.mean_ball_time_s = time.mean();
  }
  return r;
}

void Daemon::Impl::publish_stats(lcm::LCM& l) {
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
  const pinball_lcm::lcmt_pinball_daemon_stats m =
      bus::to_lcm_daemon_stats(to_utime(steady_now_s()), stats_seq++, stages, counts);
  l.publish(bus::kStatsChannel, &m);
}

Daemon::Daemon(const DaemonConfig& config) : impl_(std::make_unique<Impl>()) {
  impl_->config = config;
  validate_daemon_config(config, "config");
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
    std::string probe_why;
    std::thread([&] {
      configure_current_thread(kDriverThread, true, probe_why, d.config.threads.priorities[kDriverThread]);
    }).join();
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
  if (d.config.camera.source == "file" || d.config.camera.source == "v4l2") {
    vision::CaptureConfig cc;
    cc.source = d.config.camera.device;
    cc.width_px = d.config.camera.width_px;
    cc.height_px = d.config.camera.height_px;
    cc.fps = d.config.camera.fps;
    d.capture = std::make_unique<vision::CaptureSource>(cc);
  }
  d.learn_background();
  d.warm_up_bus();
  d.lcm->start([&d](lcm::LCM& l) { d.publish_stats(l); }, 1.0, [&d] { d.enter_thread(kLcmThread); });
  std::thread driver([&d] { d.driver_thread(); });
  std::thread controller([&d] { d.controller_thread(); });
  std::thread camera([&d] { d.camera_thread(); });
  std::thread world;
  if (d.world) world = std::thread([&d] { d.sim_thread(); });
  while (!d.stop.load(std::memory_order_acquire) && !d.controller_done.load(std::memory_order_acquire)) {
    d.main_bell.wait(0.1);
    if (d.stats_requested.exchange(false)) std::fputs(report_to_text(d.report()).c_str(), stderr);
  }
  d.stop.store(true, std::memory_order_release);
  for (Doorbell* b : {&d.camera_bell, &d.controller_bell, &d.driver_bell, &d.sim_bell}) b->ring();
  if (world.joinable()) world.join();
  camera.join();
  controller.join();
  driver.join();
  d.shutdown();
  d.lcm->stop();
  if (d.frame_log) d.frame_log->flush();
  return d.report();
}

void Daemon::request_stop() {
  impl_->stop.store(true, std::memory_order_release);
  impl_->main_bell.ring();
}

void Daemon::request_stats() {
  impl_->stats_requested.store(true, std::memory_order_release);
  impl_->main_bell.ring();
}

DaemonReport Daemon::snapshot() const { return impl_->report(); }
bus::LcmBus& Daemon::lcm_bus() { return *impl_->lcm; }
firmware::DriverBus& Daemon::driver_bus() { return *impl_->bus; }

nlohmann::json report_to_json(const DaemonReport& r) {
  nlohmann::json j;
  j["mode"] = r.mode;
  j["clock"] = r.mode == "sim" ? (r.lockstep ? "lockstep" : "realtime") : "steady";
  if (r.mode == "sim") j["world"] = {{"board", r.world_board}, {"stepper", r.world}};
  j["balls"] = r.balls;
  j["mean_score"] = r.mean_score;
  j["score_ci95"] = r.score_ci95;
  j["mean_ball_time_s"] = r.mean_ball_time_s;
  j["cut_balls"] = r.cut_balls;
  nlohmann::json scores = nlohmann::json::array();
  for (const simlab::SimBallResult& b : r.results) scores.push_back(b.score);
  j["ball_scores"] = scores;
  nlohmann::json lat = nlohmann::json::object();
  for (int s = 0; s < kStageCount; ++s) {
    const LatencySummary& x = r.latency[static_cast<std::size_t>(s)];
    lat[stage_name(s)] = {{"count", x.count}, {"p50_us", x.p50_us}, {"p99_us", x.p99_us}, {"max_us", x.max_us}};
  }
  j["latency"] = lat;
  j["frames"] = r.frames;
  j["frames_dropped"] = r.frames_dropped;
  j["detections"] = r.detections;
  j["projections"] = r.projections;
  j["commands"] = r.commands;
  j["camera_stalls"] = r.camera_stalls;
  j["ball_lost_releases"] = r.ball_lost_releases;
  j["bus_fault_releases"] = r.bus_fault_releases;
  j["fires_deferred"] = r.fires_deferred;
  j["ring_overflows"] = r.ring_overflows;
  j["lcm"] = {{"published", r.lcm.published}, {"overflows", r.lcm.overflows}, {"received", r.lcm.received},
              {"malformed", r.lcm.malformed}};
  j["can"] = {{"frames_sent", r.driver.frames_sent}, {"heartbeats", r.driver.heartbeats},
              {"fires", r.driver.fires}, {"releases", r.driver.releases}, {"release_alls", r.driver.release_alls},
              {"bus_off", r.driver.bus_off}, {"reconnects", r.driver.reconnects},
              {"tx_failures", r.driver.tx_failures}, {"rx_bad", r.driver.rx_bad},
              {"dropped_not_running", r.driver.dropped_not_running}};
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
    o << "balls " << r.balls << "  mean score per ball " << r.mean_score << " ± " << r.score_ci95
      << " (95 %)  mean ball time " << std::setprecision(2) << r.mean_ball_time_s << " s";
    if (r.cut_balls > 0) o << "  cut " << r.cut_balls;
    o << "\n";
  }
  o << std::setprecision(1);
  o << "frames " << r.frames << " (dropped " << r.frames_dropped << ")  ball seen " << r.detections
    << "  projections " << r.projections << "  commands " << r.commands << "  stalls " << r.camera_stalls
    << "  malformed LCM " << r.lcm.malformed << "\n";
  o << std::left << std::setw(24) << "latency (us)" << std::right << std::setw(10) << "count" << std::setw(10)
    << "p50" << std::setw(10) << "p99" << std::setw(10) << "max" << "\n";
  for (int s = 0; s < kStageCount; ++s) {
    const LatencySummary& x = r.latency[static_cast<std::size_t>(s)];
    o << std::left << std::setw(24) << stage_name(s) << std::right << std::setw(10) << x.count << std::setw(10)
      << x.p50_us << std::setw(10) << x.p99_us << std::setw(10) << x.max_us << "\n";
  }
  o << "threads: " << r.cpus << "\n";
  for (const std::string& w : r.warnings) o << "warning: " << w << "\n";
  return o.str();
}

}  // namespace pinball::daemon
