#include "pinball/daemon/daemon_config.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>
#include <utility>

#include "pinball/bus/lcm_bus.h"
#include "pinball/core/data_path.h"
#include "pinball/core/format.h"
#include "pinball/core/text_file.h"
#include "pinball/core/yaml_read_archive.h"
#include "pinball/daemon/thread_table.h"
#include "pinball/firmware/codec.h"
#include "pinball/firmware/protocol.h"

namespace pinball::daemon {
namespace {

// Largest camera frame side accepted (px).
constexpr int kMaxFrameSide_px = 8192;

void require(bool ok, const std::string& source, const std::string& key, const std::string& message) {
  if (!ok) throw ConfigError(source + ": " + key + ": " + message);
}

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

std::string range_text(double lo, double hi, const char* unit) {
  std::ostringstream out;
  out << "must be in [" << lo << ", " << hi << "]" << unit;
  return out.str();
}

void check_camera(const CameraSettings& c, const std::string& s) {
  static const std::set<std::string> sources{"sim", "v4l2", "file", "lcm"};
  require(sources.count(c.source) == 1, s, "camera.source", "must be sim, v4l2, file or lcm");
  // The simulated camera renders and the detector buffers whole frames of
  // this size; no camera we drive delivers more than 8192 px a side.
  require(c.width_px >= 1 && c.width_px <= kMaxFrameSide_px, s, "camera.width_px", range_text(1, kMaxFrameSide_px, " px"));
  require(c.height_px >= 1 && c.height_px <= kMaxFrameSide_px, s, "camera.height_px", range_text(1, kMaxFrameSide_px, " px"));
  require(positive(c.fps) && c.fps <= 10000.0, s, "camera.fps", "must be in (0, 10000]");
  // While no frame comes the coils stay as they were: past a second that is
  // no stall guard at all (the default, 20 ms, is four frames at 200 fps).
  require(positive(c.stall_timeout_s) && c.stall_timeout_s < 1.0, s, "camera.stall_timeout_s",
          "must be in (0, 1) s");
  // Shorter than two frame periods, every frame a little late reads as a
  // stall and lets the flippers go: the controller would play blind.
  const double two_periods_s = 2.0 / c.fps;
  require(c.stall_timeout_s >= two_periods_s, s, "camera.stall_timeout_s",
          "must be at least two frame periods (2 / camera.fps = " + format_number(two_periods_s) +
              " s), or every late frame releases the flippers" +
              (two_periods_s >= 1.0 ? "; at " + format_number(c.fps) + " frames/s no stall timeout under 1 s does: "
                                      "camera.fps must be above 2"
                                    : ""));
  // 10000 frames is 50 s at 200 fps of keeping the ball off the table: more is a typo.
  require(c.background_frames >= 1 && c.background_frames <= 10000, s, "camera.background_frames",
          "must be in [1, 10000]");
  const bool printable = std::all_of(c.fourcc.begin(), c.fourcc.end(), [](char ch) { return ch > ' ' && ch < 127; });
  require(c.fourcc.empty() || (c.fourcc.size() == 4 && printable), s, "camera.fourcc",
          "must be four characters, e.g. GREY, Y800, YUYV or MJPG (empty: the driver's format)");
  require(std::isfinite(c.exposure_s) && (c.exposure_s < 0.0 || (c.exposure_s > 0.0 && c.exposure_s <= 1.0)), s,
          "camera.exposure_s", "must be in (0, 1] s, or negative for the driver's automatic exposure");
  const bool lab_camera = c.source == "v4l2" || c.source == "file";
  require(c.occluder_mask.empty() || lab_camera, s, "camera.occluder_mask",
          "is for camera.source v4l2 or file (the simulated camera knows its plastics)");
}

void check_can(const CanSettings& c, const std::string& s) {
  // The driver board's firmware runs its bxCAN at this rate only (stm32f446/can.c): at any other the
  // interface would pass the bring-up check and every frame on the wire would be destroyed.
  require(c.bitrate_bps == firmware::kBitrate_bps, s, "can.bitrate_bps",
          "must be " + std::to_string(firmware::kBitrate_bps) +
              " bit/s: the driver board's firmware runs at no other rate (PROTOCOL.md)");
  require(c.board_id >= 0 && c.board_id < firmware::kMaxBoards, s, "can.board_id", "must be in [0, 15]");
  // The board accepts a watchdog of 10..1000 ms in Hello (firmware/protocol.h).
  require(std::isfinite(c.watchdog_timeout_s) && c.watchdog_timeout_s * 1e3 >= firmware::kMinWatchdogMs &&
              c.watchdog_timeout_s * 1e3 <= firmware::kMaxWatchdogMs,
          s, "can.watchdog_timeout_s", "must be in [0.01, 1] s (the protocol's watchdog range)");
  // Faster than 1 ms the heartbeats alone take about a fifth of the 500 kbit/s bus.
  require(positive(c.heartbeat_period_s) && c.heartbeat_period_s >= 1e-3, s, "can.heartbeat_period_s",
          "must be at least 0.001 s");
  // One lost heartbeat must not trip the watchdog.
  require(c.watchdog_timeout_s >= 3.0 * c.heartbeat_period_s, s, "can.watchdog_timeout_s",
          "must be at least 3 heartbeat periods");
}

// The coil limits are the protocol's absolute ones (firmware/protocol.h): the
// board refuses more, so a file asking for more fails here, naming its key,
// and not later inside DriverBus.
void check_coils(const firmware::DriverConfig& c, const std::string& s) {
  using namespace firmware;
  require(c.max_pulse_ms >= 1 && c.max_pulse_ms <= kAbsMaxPulseMs, s, "coils.max_pulse_ms",
          range_text(1, kAbsMaxPulseMs, " ms (the protocol's absolute pulse cap)"));
  require(c.pulse_ms >= 1 && c.pulse_ms <= c.max_pulse_ms, s, "coils.pulse_ms",
          "must be in [1, max_pulse_ms] (" + std::to_string(c.max_pulse_ms) + " ms)");
  require(c.hold_duty_pct <= kAbsMaxHoldDutyPct, s, "coils.hold_duty_pct",
          range_text(0, kAbsMaxHoldDutyPct, " % (the protocol's absolute hold duty)"));
  require(c.max_hold_ms >= 1 && c.max_hold_ms <= kAbsMaxHoldMs, s, "coils.max_hold_ms",
          range_text(1, kAbsMaxHoldMs, " ms (the protocol's absolute hold cap)"));
  // recycle_ms is a byte on the wire: the reader already refused anything past 255.
  const char* why = validate(c);  // the codec's own rule, should it ever grow
  require(why == nullptr, s, "coils", why ? why : "");
}

void check_sim(const SimSettings& c, const std::string& s) {
  require(c.balls >= 0, s, "sim.balls", "must be >= 0");
  require(c.actuation_delay_s >= 0.0 && c.actuation_delay_s < 0.1, s, "sim.actuation_delay_s",
          "must be in [0, 0.1) s");
  require(positive(c.max_ball_time_s), s, "sim.max_ball_time_s", "must be > 0");
  require(c.camera == "ideal" || c.camera == "typical", s, "sim.camera", "must be ideal or typical");
}

void check_threads(const ThreadSettings& c, const std::string& s) {
  for (std::size_t i = 0; i < kPriorityKeys.size(); ++i) {
    require(c.priorities[i] >= 0 && c.priorities[i] <= 99, s, std::string("threads.priorities.") + kPriorityKeys[i],
            "must be in [0, 99]");
  }
  require(c.chain_cpu == "auto" || c.chain_cpu == "off" ||
              (!c.chain_cpu.empty() && c.chain_cpu.size() <= 4 &&
               c.chain_cpu.find_first_not_of("0123456789") == std::string::npos),
          s, "threads.chain_cpu", "must be auto, off or a CPU number");
  try {
    (void)plan_cpus(c.chain_cpu);  // a CPU this process may not use
  } catch (const ConfigError& e) {
    throw ConfigError(s + ": " + e.what());
  }
  require(c.cpu_dma_latency_us >= -1 && c.cpu_dma_latency_us <= 1'000'000, s, "threads.cpu_dma_latency_us",
          "must be -1 (leave alone) or in [0, 1000000] us");
}

void check_mode(const DaemonConfig& c, const std::string& s) {
  if (c.mode == "sim") {
    // lcm: observations recorded or replayed (lcm-logplayer) drive the
    // tracker, and the coils drive the virtual driver board; no world runs.
    require(c.camera.source == "sim" || c.camera.source == "lcm", s, "camera.source", "must be sim or lcm in mode sim");
    require(c.can.interface == "sim", s, "can.interface", "must be sim in mode sim");
    require(!c.sim.board.empty(), s, "sim.board", "is required in mode sim");
    require(c.camera.source != "sim" || (c.camera.width_px >= 32 && c.camera.height_px >= 32), s, "camera.width_px",
            "and camera.height_px must be at least 32 px for the simulated camera");
  } else {
    require(c.camera.source != "sim", s, "camera.source", "cannot be sim in mode lab");
    require(c.camera.source == "lcm" || !c.camera.device.empty(), s, "camera.device", "is required in mode lab");
    require(!c.board.empty(), s, "board", "is required in mode lab");
    require(c.can.interface != "sim" && !c.can.interface.empty(), s, "can.interface",
            "must name a SocketCAN interface (can0) in mode lab");
    // A kernel interface name: at most 15 bytes, none of them a blank or a '/'. Anything else had gone
    // unquoted into the `ip link` command the bring-up check suggests ("can0; rm").
    const bool name_ok = c.can.interface.size() <= 15 && c.can.interface != "." && c.can.interface != ".." &&
                         c.can.interface.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                           "0123456789_.-@") == std::string::npos;
    require(name_ok, s, "can.interface",
            "'" + c.can.interface + "' is no interface name (at most 15 letters, digits, '_', '.', '-' or '@')");
  }
}

// ---- paths ----

// What a path key names, and so what is checked at load.
enum class PathUse {
  kRead,    // a file the daemon reads: it must exist
  kWrite,   // a file the daemon writes: its folder must exist
  kUnused,  // not used in this mode (or this source): resolved, not checked
};

// One key that names a file: its dotted key, the field, and its use in `c`'s mode.
struct PathField {
  const char* key;
  std::string* value;
  PathUse use;
};

// The LCM URL's log file: file://PATH?... (liblcm reads a log, or we write one).
struct LcmFilePart {
  std::string path;  // empty: not a file:// URL
  bool writes = false;
};

LcmFilePart lcm_file_part(const std::string& url) {
  const std::string scheme = "file://";
  if (url.rfind(scheme, 0) != 0) return {};
  const std::size_t query = url.find('?');
  LcmFilePart p;
  p.path = url.substr(scheme.size(), query == std::string::npos ? std::string::npos : query - scheme.size());
  p.writes = bus::lcm_log_target(url).has_value();  // mode=w or mode=a, as LcmBus reads it
  return p;
}

std::vector<PathField> path_fields(DaemonConfig& c) {
  const bool sim = c.mode == "sim";
  const bool world = sim && c.camera.source == "sim";
  const auto use = [](bool used, PathUse u) { return used ? u : PathUse::kUnused; };
  return {
      {"sim.board", &c.sim.board, use(sim, PathUse::kRead)},
      {"sim.world_board", &c.sim.world_board, use(world, PathUse::kRead)},
      {"sim.twin_params", &c.sim.twin_params, use(world && c.sim.world == simlab::WorldKind::kTwin, PathUse::kRead)},
      {"board", &c.board, use(!sim, PathUse::kRead)},
      {"calibration", &c.calibration, PathUse::kRead},
      {"identified", &c.identified, PathUse::kRead},
      {"controller", &c.controller, PathUse::kRead},
      {"camera.device", &c.camera.device, use(c.camera.source == "file", PathUse::kRead)},
      {"camera.occluder_mask", &c.camera.occluder_mask, PathUse::kRead},
      {"can.log", &c.can.log, PathUse::kWrite},
  };
}

// True when the file gives the dotted key. Const lookups only: yaml-cpp's
// non-const operator[] and Node assignment change the tree.
bool file_gives(const YAML::Node& map, const std::string& dotted) {
  if (!map.IsMap()) return false;
  const std::size_t dot = dotted.find('.');
  const YAML::Node child = map[dotted.substr(0, dot)];
  if (!child) return false;
  return dot == std::string::npos || file_gives(child, dotted.substr(dot + 1));
}

// Why the daemon could not create the file `path` ("": it can try): ": its
// folder F does not exist", ", which is a folder, not a file", or the system's
// reason it may not write there (a read-only folder, ProtectSystem=strict).
std::string unwritable_path_problem(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) return ", which is a folder, not a file";
  const fs::path folder = fs::absolute(path, ec).parent_path();
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec)) {
    return ": " + folder.string() + " is a file, not a folder";
  }
  if (!fs::is_directory(folder, ec)) return ": its folder " + folder.string() + " does not exist";
  const fs::path written = fs::exists(path, ec) ? path : folder;
  if (::access(written.c_str(), W_OK) != 0) return ": " + written.string() + ": " + std::strerror(errno);
  return "";
}

// Makes `value` (given at `key` of the file) absolute against `base_dir` and
// checks it for its use. Messages: "file: key: 'cal.yaml' is /dir/cal.yaml
// (relative paths are relative to the configuration's folder), which does not exist".
void resolve_one(const std::string& source, const std::string& key, std::string* value, PathUse use,
                 const std::filesystem::path& base_dir) {
  namespace fs = std::filesystem;
  if (value->empty()) return;
  const fs::path given(*value);
  const fs::path resolved = given.is_absolute() ? given : (base_dir / given).lexically_normal();
  const std::string said = given.is_absolute()
                               ? "'" + resolved.string() + "'"
                               : "'" + *value + "' is " + resolved.string() +
                                     " (a relative path is relative to the configuration's folder)";
  *value = resolved.string();
  std::error_code ec;
  if (use == PathUse::kRead) {
    require(fs::exists(resolved, ec), source, key, said + ", which does not exist");
    const std::string problem = input_file_problem(resolved.string());  // a folder, a device (/dev/zero)
    require(problem.empty(), source, key, said + ", which " + problem);
  } else if (use == PathUse::kWrite) {
    const std::string problem = unwritable_path_problem(resolved);
    require(problem.empty(), source, key, said + problem);
  }
}

void resolve_paths(DaemonConfig& c, const YAML::Node& root, const std::string& source,
                   const std::filesystem::path& base_dir) {
  for (const PathField& f : path_fields(c)) {
    if (!file_gives(root, f.key)) continue;  // a default: looked up as pinballd always did (find_data_file)
    resolve_one(source, f.key, f.value, f.use, base_dir);
  }
  // lcm_url: file://PATH?mode=w writes a log there; file://PATH (mode=r, refused by the checks) would read one.
  const LcmFilePart lcm = lcm_file_part(c.lcm_url);
  if (file_gives(root, "lcm_url") && !lcm.path.empty()) {
    std::string path = lcm.path;
    resolve_one(source, "lcm_url", &path, lcm.writes ? PathUse::kWrite : PathUse::kRead, base_dir);
    c.lcm_url = "file://" + path + c.lcm_url.substr(std::string("file://").size() + lcm.path.size());
  }
}

// Collects the dotted key of every field a Serialize() visits.
class KeyListArchive {
 public:
  template <class T>
  void Visit(const NameValue<T>& field) {
    const std::string key = join_key(path_, field.name);
    if constexpr (requires(T& t, KeyListArchive* a) { t.Serialize(a); }) {
      const std::string outer = std::exchange(path_, key);
      field.value->Serialize(this);
      path_ = outer;
    } else {
      keys.push_back(key);
    }
  }
  std::vector<std::string> keys;

 private:
  std::string path_;
};

// The version alone, read first: a file from another version is refused as
// such, not for the keys it has.
struct VersionKey {
  int version = kConfigVersion;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(version));
  }
};

}  // namespace

DaemonConfig daemon_config_from_yaml(const std::string& text, const std::string& source_name,
                                     const std::string& base_dir) {
  DaemonConfig c;
  YAML::Node root;
  try {
    root = load_yaml(text, source_name);
    // An empty file is a mistake (a wrong path, /dev/null, a truncated copy),
    // not a request for the embedded simulation: pinballd without --config is.
    require(!YamlDoc::is_null(root), source_name, "(file)",
            "is empty (pinballd without --config runs the embedded simulation)");
    VersionKey v;
    YamlReadArchive(source_name, {.refuse_unknown_keys = false}).read(root, "", &v);
    require(v.version == kConfigVersion, source_name, "version",
            "is " + std::to_string(v.version) + ", this build reads " + std::to_string(kConfigVersion));
    YamlReadArchive(source_name).read(root, "", &c);
  } catch (const YamlSyntaxError& e) {
    throw ConfigError(source_name + ":" + e.key() + ": " + e.message());
  } catch (const KeyError& e) {
    // The archive says "file:key: message"; this file's errors say "file: key: message".
    throw ConfigError(source_name + ": " + e.key() + ": " + e.message());
  }
  validate_daemon_config(c, source_name);
  // The lab's table, given in mode sim, would be read nowhere: said, not ignored.
  require(c.mode != "sim" || !file_gives(root, "board"), source_name, "board",
          "is the lab's table, unused in mode sim: the simulation's is sim.board (the world's sim.world_board)");
  if (!base_dir.empty()) resolve_paths(c, root, source_name, base_dir);
  return c;
}

DaemonConfig load_daemon_config(const std::string& path) {
  std::string text;
  try {
    text = read_text_file(path);
  } catch (const std::runtime_error& e) {
    throw ConfigError(e.what());
  }
  // The folder of the file as an absolute path: its relative paths mean the
  // same whatever the working directory.
  const std::filesystem::path folder = std::filesystem::absolute(path).parent_path();
  DaemonConfig c = daemon_config_from_yaml(text, path, folder.string());
  c.origin = path;
  c.file = path;
  return c;
}

std::vector<std::string> daemon_config_keys() {
  DaemonConfig c;
  KeyListArchive a;
  c.Serialize(&a);
  return a.keys;
}

std::vector<std::string> daemon_config_path_keys() {
  DaemonConfig c;
  std::vector<std::string> out;
  for (const PathField& f : path_fields(c)) out.push_back(f.key);
  out.push_back("lcm_url");  // a file:// URL's path
  return out;
}

void validate_daemon_config(const DaemonConfig& c, const std::string& s) {
  require(c.mode == "sim" || c.mode == "lab", s, "mode", "must be sim or lab");
  check_camera(c.camera, s);
  check_can(c.can, s);
  check_coils(c.coils, s);
  require(!c.controller.empty(), s, "controller", "is required");
  require(!c.lcm_url.empty(), s, "lcm_url", "is required");
  require(bus::lcm_url_problem(c.lcm_url).empty(), s, "lcm_url", bus::lcm_url_problem(c.lcm_url));
  // A file:// URL without mode=w or mode=a reads a log, where liblcm refuses every publish; and
  // pinballd publishes every frame's projection and command: it would run blind to LCM and exit 3.
  require(c.lcm_url.rfind("file://", 0) != 0 || bus::lcm_log_target(c.lcm_url).has_value(), s, "lcm_url",
          "'" + c.lcm_url + "' reads a log (no ?mode=w), and liblcm refuses every message pinballd publishes there: "
          "record with '" + c.lcm_url + "?mode=w'; replay a recorded game with `pinball replay LOG`, or play it "
          "onto the bus with `lcm-logplayer LOG` and a udpm:// lcm_url");
  check_sim(c.sim, s);
  check_threads(c.threads, s);
  check_mode(c, s);
}

void check_observation_source(const DaemonConfig& c, const std::string& s) {
  if (c.camera.source != "lcm") return;
  require(c.lcm_url.rfind("memq://", 0) != 0 && !bus::lcm_log_target(c.lcm_url).has_value(), s, "lcm_url",
          "'" + c.lcm_url + "' carries no observation from another process, and camera.source lcm reads them "
          "there: use a bus other processes publish on (udpm://239.255.76.67:7667?ttl=0)");
}

void check_written_paths(const DaemonConfig& c, const std::string& source_name) {
  const auto check = [&](const char* key, const std::string& path) {
    if (path.empty()) return;
    const std::string problem = unwritable_path_problem(path);
    require(problem.empty(), source_name, key, "'" + path + "'" + problem);
  };
  check("can.log", c.can.log);
  const std::optional<bus::LcmLogTarget> lcm_log = bus::lcm_log_target(c.lcm_url);
  if (lcm_log) check("lcm_url", lcm_log->path);
  // A recording must not replace what the run reads, nor the other recording (found: --can-log
  // naming the controller file replaced it with the log, exit 0).
  // The file, not the name: a hard link of the board had become a CAN log, and a link to a log not made
  // yet had been taken for another process's (same_written_file).
  const auto same_path = same_written_file;
  DaemonConfig inputs = c;
  const std::vector<std::pair<const char*, std::string>> written = {
      {"can.log", c.can.log}, {"lcm_url", lcm_log ? lcm_log->path : std::string()}};
  for (const auto& [key, path] : written) {
    // The configuration file itself (found: --lcm-url file://CONFIG?mode=w made it an LCM log, exit 0).
    require(!same_path(path, c.file), source_name, key,
            "'" + path + "' is this configuration file: it would be replaced by the recording");
    for (const PathField& f : path_fields(inputs)) {
      if (f.use == PathUse::kRead) {
        require(!same_path(path, *f.value), source_name, key,
                "'" + path + "' is the file " + f.key + " names: it would be replaced by the recording");
      }
    }
  }
  require(!same_path(c.can.log, written[1].second), source_name, "can.log",
          "'" + c.can.log + "' is the lcm_url's log too: the two recordings would write into one file");
}

void find_data_files(DaemonConfig& c) {
  for (std::string* path : {&c.board, &c.identified, &c.controller, &c.sim.board, &c.sim.world_board,
                            &c.sim.twin_params})
    *path = find_data_file(*path);
}

}  // namespace pinball::daemon
