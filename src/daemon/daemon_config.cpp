#include "pinball/daemon/daemon_config.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

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
  // 10000 frames is 50 s at 200 fps of keeping the ball off the table: more is a typo.
  require(c.background_frames >= 1 && c.background_frames <= 10000, s, "camera.background_frames",
          "must be in [1, 10000]");
}

void check_can(const CanSettings& c, const std::string& s) {
  require(c.board_id >= 0 && c.board_id < firmware::kMaxBoards, s, "can.board_id", "must be in [0, 15]");
  // The board accepts a watchdog of 10..1000 ms in Hello (firmware/protocol.h).
  require(std::isfinite(c.watchdog_timeout_s) && c.watchdog_timeout_s * 1e3 >= firmware::kMinWatchdogMs &&
              c.watchdog_timeout_s * 1e3 <= firmware::kMaxWatchdogMs,
          s, "can.watchdog_timeout_s", "must be in [0.01, 1] s (the protocol's watchdog range)");
  // Faster than 1 ms the heartbeats alone take about a tenth of a 1 Mbit/s bus.
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
    require(c.camera.source == "sim", s, "camera.source", "must be sim in mode sim");
    require(c.can.interface == "sim", s, "can.interface", "must be sim in mode sim");
    require(!c.sim.board.empty(), s, "sim.board", "is required in mode sim");
  } else {
    require(c.camera.source != "sim", s, "camera.source", "cannot be sim in mode lab");
    require(c.camera.source == "lcm" || !c.camera.device.empty(), s, "camera.device", "is required in mode lab");
    require(!c.board.empty(), s, "board", "is required in mode lab");
    require(c.can.interface != "sim" && !c.can.interface.empty(), s, "can.interface",
            "must name a SocketCAN interface (can0) in mode lab");
  }
}

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

DaemonConfig daemon_config_from_yaml(const std::string& text, const std::string& source_name) {
  DaemonConfig c;
  try {
    const YAML::Node root = load_yaml(text, source_name);
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
    throw ConfigError(source_name + ":" + e.key() + ": not valid YAML: " + e.message());
  } catch (const KeyError& e) {
    // The archive says "file:key: message"; this file's errors say "file: key: message".
    throw ConfigError(source_name + ": " + e.key() + ": " + e.message());
  }
  validate_daemon_config(c, source_name);
  return c;
}

DaemonConfig load_daemon_config(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return daemon_config_from_yaml(ss.str(), path);
}

void validate_daemon_config(const DaemonConfig& c, const std::string& s) {
  require(c.mode == "sim" || c.mode == "lab", s, "mode", "must be sim or lab");
  check_camera(c.camera, s);
  check_can(c.can, s);
  check_coils(c.coils, s);
  require(!c.controller.empty(), s, "controller", "is required");
  require(!c.lcm_url.empty(), s, "lcm_url", "is required");
  check_sim(c.sim, s);
  check_threads(c.threads, s);
  check_mode(c, s);
}

}  // namespace pinball::daemon
