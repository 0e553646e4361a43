#pragma once
// pinballd's configuration: one YAML file (config/lab.example.yaml documents
// every key). Without a file the defaults run the embedded simulation of
// boards/mit1993.board over memq:// with the shipped controller; an empty
// file is refused, not read as that. Loading is all or nothing: a bad file
// throws ConfigError naming the file and the key, range checks included (the
// coil limits are the CAN protocol's absolute ones), so nothing out of range
// reaches DriverBus. One YAML document per file; a repeated key is refused.
// Each struct lists its keys once, in Serialize(); core/yaml_read_archive.h
// reads them (unknown keys refused, missing keys keep the defaults below).
// A relative path in a file is relative to that file's folder, never to the
// working directory (Mission Pinball Framework's rule for its machine
// folder); load_daemon_config makes every such path absolute and checks, at
// load, that the files the mode reads exist and that the folders it writes
// into do, naming the file, the key and the resolved path.

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "pinball/core/name_value.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/firmware/messages.h"
#include "pinball/firmware/protocol.h"
#include "pinball/sim/world.h"
#include "pinball/simlab/world_factory.h"

namespace pinball::daemon {

/// Version of the configuration format this build reads.
inline constexpr int kConfigVersion = 1;

/// Where frames come from.
struct CameraSettings {
  std::string source = "sim";     ///< sim (rendered board), v4l2 (a camera device), file (a video), lcm (observations on PINBALL_OBSERVATION)
  std::string device;             ///< v4l2: /dev/videoN; file: the video's path
  int width_px = 640;             ///< requested frame width (px), 1..8192
  int height_px = 480;            ///< requested frame height (px), 1..8192
  double fps = 200.0;             ///< requested frame rate (frames per second)
  double stall_timeout_s = 0.02;  ///< no frame (or no ball while a flipper is up) this long: release all (s), in (0, 1)
  int background_frames = 30;     ///< ball-free frames averaged into the detector's background at start, 1..10000
  std::string fourcc;             ///< v4l2: pixel format, four characters (GREY, Y800, YUYV, MJPG); empty: the driver's
  /// v4l2: a fixed exposure (s), (0, 1]; set in V4L2's units of 100 µs with
  /// auto-exposure off. Negative: the driver's automatic exposure.
  double exposure_s = -1.0;
  std::string occluder_mask;      ///< v4l2, file: image of the frame's size, white where plastics hide the playfield

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(source));
    a->Visit(PINBALL_NVP(device));
    a->Visit(PINBALL_NVP(width_px));
    a->Visit(PINBALL_NVP(height_px));
    a->Visit(PINBALL_NVP(fps));
    a->Visit(PINBALL_NVP(fourcc));
    a->Visit(PINBALL_NVP(exposure_s));
    a->Visit(PINBALL_NVP(occluder_mask));
    a->Visit(PINBALL_NVP(stall_timeout_s));
    a->Visit(PINBALL_NVP(background_frames));
  }
};

/// The CAN link to the solenoid driver board.
struct CanSettings {
  std::string interface = "sim";     ///< sim (the virtual board over a socket pair) or a SocketCAN interface (can0)
  /// The bus's bit rate (bit/s), PROTOCOL.md's 500 kbit/s: pinballd refuses
  /// a SocketCAN interface set to another (a virtual one, vcan, has none).
  std::uint32_t bitrate_bps = firmware::kBitrate_bps;
  int board_id = 0;                  ///< driver board number 0..15
  double heartbeat_period_s = 0.02;  ///< heartbeat period (s), 0.001 .. watchdog_timeout_s / 3
  double watchdog_timeout_s = 0.1;   ///< the board switches everything off after this silence (s), 0.01..1
  std::string log;                   ///< candump-format log of every frame (empty: none); in the lab `candump -l` does the same

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(interface));
    a->Visit(PINBALL_NVP(bitrate_bps));
    a->Visit(PINBALL_NVP(board_id));
    a->Visit(PINBALL_NVP(heartbeat_period_s));
    a->Visit(PINBALL_NVP(watchdog_timeout_s));
    a->Visit(PINBALL_NVP(log));
  }
};

/// The keys of threads.priorities, in ThreadId order.
inline constexpr std::array<const char*, 5> kPriorityKeys{"driver", "controller", "camera", "sim", "lcm"};

/// Thread priorities as the file spells them: one key per thread.
struct PriorityKeys {
  std::array<int, 5>* priorities;  ///< ThreadSettings::priorities

  template <class Archive>
  void Serialize(Archive* a) {
    for (std::size_t i = 0; i < kPriorityKeys.size(); ++i) {
      a->Visit(make_name_value(kPriorityKeys[i], &(*priorities)[i]));
    }
  }
};

/// Real-time scheduling of the daemon's threads (the table is in thread_table.h).
struct ThreadSettings {
  bool realtime = false;  ///< ask for SCHED_FIFO priorities and locked memory
  bool enforce = false;   ///< true: refuse to run when that is not allowed; false: warn once and run
  /// SCHED_FIFO priority (1..99) per thread, in ThreadId order (driver, controller, camera, sim, lcm);
  /// 0 leaves a thread SCHED_OTHER. Defaults: the thread table.
  std::array<int, 5> priorities{90, 85, 80, 70, 0};
  /// The CPU of the frame -> CAN chain (camera, controller and driver threads):
  /// "auto" the highest CPU the process may use (the other threads get the
  /// rest), "off" no pinning, or a CPU number (e.g. one kept free with isolcpus).
  std::string chain_cpu = "auto";
  /// Holds /dev/cpu_dma_latency at this many microseconds while running (-1:
  /// leave it alone). 0 keeps idle cores polling instead of sleeping, so that
  /// waking a thread costs microseconds, not a deep-idle exit (needs root).
  int cpu_dma_latency_us = -1;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(realtime));
    a->Visit(PINBALL_NVP(enforce));
    PriorityKeys keys{&priorities};  // the file names each thread
    a->Visit(make_name_value("priorities", &keys));
    a->Visit(PINBALL_NVP(chain_cpu));
    a->Visit(PINBALL_NVP(cpu_dma_latency_us));
  }
};

/// The embedded simulation.
struct SimSettings {
  std::string board = "boards/mit1993.board";  ///< board file: the belief, and the world unless world_board is set
  std::string world_board;                     ///< the world's own board file (empty: `board`); same flippers
  simlab::WorldKind world = simlab::WorldKind::kModel;  ///< which world plays it (YAML: model | twin)
  sim::StepperKind stepper = sim::StepperKind::kThesis;  ///< the model world's integrator (YAML: thesis | event)
  std::string twin_params;                     ///< the twin's parameter file (empty: the shipped config/twin.yaml)
  int balls = 10;                              ///< balls to play
  std::uint64_t seed = 1;                      ///< launch noise seed (ball i uses ball_seed(seed, i))
  bool realtime = false;                       ///< pace to the wall clock (default: lockstep, as fast as possible)
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;            ///< coil on -> flipper moves (s)
  double max_ball_time_s = 60.0;               ///< a ball alive this long is cut (s)
  /// The simulated camera: ideal (a pinhole, global shutter, stamped at exposure) or typical (lens
  /// distortion, rolling shutter, 8 ms latency, flicker, drift: simlab::SimCameraRealism::typical();
  /// the detector corrects it with the camera's true lens and timing unless a calibration file gives them).
  std::string camera = "ideal";

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(board));
    a->Visit(PINBALL_NVP(world_board));
    a->Visit(PINBALL_NVP(world));
    a->Visit(PINBALL_NVP(stepper));
    a->Visit(PINBALL_NVP(twin_params));
    a->Visit(PINBALL_NVP(balls));
    a->Visit(PINBALL_NVP(seed));
    a->Visit(PINBALL_NVP(realtime));
    a->Visit(PINBALL_NVP(actuation_delay_s));
    a->Visit(PINBALL_NVP(max_ball_time_s));
    a->Visit(PINBALL_NVP(camera));
  }
};

/// Everything pinballd reads.
/// pinballd's controller file unless told otherwise. imitation.json: it keeps
/// its lead over the spastic flipper with a camera noisier than the
/// simulation's, where best.json falls below it (controllers/README.md).
inline constexpr const char* kDefaultController = "controllers/imitation.json";

struct DaemonConfig {
  int version = kConfigVersion;  ///< format version
  std::string mode = "sim";      ///< sim: embedded simulation; lab: camera + SocketCAN
  SimSettings sim;               ///< sim mode
  CameraSettings camera;         ///< frames
  std::string board;             ///< lab: the table's board file (flipper and ball geometry)
  std::string calibration;       ///< lab: calibration file (docs/calibration.md); empty: the board's geometry
  /// Identified parameters laid over the belief board, in either mode
  /// (`pinball identify`, docs/identification.md); empty: the board file alone.
  /// A simulated twin still plays the board file (simlab::world_for_belief).
  std::string identified;
  CanSettings can;               ///< CAN link
  firmware::DriverConfig coils;  ///< pulse, hold, caps and recycle time of every flipper coil (protocol limits)
  std::string controller = kDefaultController;       ///< controller file (docs/learning.md)
  std::string lcm_url = "memq://";                   ///< LCM provider URL
  ThreadSettings threads;                            ///< scheduling
  /// Where these settings came from, for the messages of checks made after
  /// loading: the file, "the command line", or both. Not a key.
  std::string origin = "the command line";
  /// The configuration file it was loaded from ("" for none): no recording may replace it. Not a key.
  std::string file;
  /// The live status line on stderr even when it is not a terminal (--progress: a log file, a lab
  /// script's pipe). Not a key.
  bool progress = false;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(version));
    a->Visit(PINBALL_NVP(mode));
    a->Visit(PINBALL_NVP(sim));
    a->Visit(PINBALL_NVP(camera));
    a->Visit(PINBALL_NVP(board));
    a->Visit(PINBALL_NVP(calibration));
    a->Visit(PINBALL_NVP(identified));
    a->Visit(PINBALL_NVP(can));
    a->Visit(PINBALL_NVP(coils));
    a->Visit(PINBALL_NVP(controller));
    a->Visit(PINBALL_NVP(lcm_url));
    a->Visit(PINBALL_NVP(threads));
  }
};

/// Bad configuration; what() is "file: key: message".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses YAML text; `source_name` is used in messages. Unknown keys are
/// errors. With a `base_dir`, the relative paths the text gives are resolved
/// against it and checked as load_daemon_config does; without one they are
/// kept as written.
DaemonConfig daemon_config_from_yaml(const std::string& text, const std::string& source_name,
                                     const std::string& base_dir = "");
/// Reads a configuration file; its relative paths are relative to its folder.
DaemonConfig load_daemon_config(const std::string& path);

/// For the pinballd program: with camera.source lcm the observations come
/// from another process, which this process's own bus (memq://) or a log it
/// writes (file://...?mode=w) cannot carry (the run had waited for them until
/// SIGINT, exit 0). Throws ConfigError "source: lcm_url: ...". A program that
/// publishes into the daemon's memq:// bus itself (a test) does not call it.
void check_observation_source(const DaemonConfig& config, const std::string& source_name);

/// Every key the loader accepts, dotted ("can.log", "threads.priorities.lcm"),
/// in file order: config/lab.example.yaml must show each (a test checks).
std::vector<std::string> daemon_config_keys();
/// The keys that name a file or folder (resolved against the file's folder).
std::vector<std::string> daemon_config_path_keys();
/// Checks every key's range and the cross-key rules (sim mode needs
/// camera.source sim and can.interface sim, ...). Throws ConfigError.
void validate_daemon_config(const DaemonConfig& config, const std::string& source_name);
/// The files the daemon writes (can.log, a file:// lcm_url with mode=w or
/// mode=a) can be created: their folders exist and they are not folders. For
/// paths from the command line, which the loader never saw. Throws ConfigError.
void check_written_paths(const DaemonConfig& config, const std::string& source_name);
/// The data files a configuration names (boards, overlay, twin parameters,
/// controller) through find_data_file, so that the defaults and a command
/// line's relative paths name the shipped data from any folder; what a
/// configuration file gave is already absolute and stays as it is.
void find_data_files(DaemonConfig& config);

}  // namespace pinball::daemon

/// The world as the file spells it: model | twin.
template <>
struct pinball::EnumText<pinball::simlab::WorldKind> {
  static std::string name(simlab::WorldKind kind) { return std::string(simlab::world_kind_name(kind)); }
  static simlab::WorldKind parse(const std::string& text) { return simlab::parse_world_kind(text); }
};

/// The stepper as the file spells it: thesis | event.
template <>
struct pinball::EnumText<pinball::sim::StepperKind> {
  static std::string name(sim::StepperKind kind) { return std::string(sim::stepper_kind_name(kind)); }
  static sim::StepperKind parse(const std::string& text) { return sim::parse_stepper_kind(text); }
};
