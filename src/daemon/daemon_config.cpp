#include "pinball/daemon/daemon_config.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "pinball/core/yaml_read_archive.h"
#include "pinball/daemon/thread_table.h"

namespace pinball::daemon {
namespace {

void require(bool ok, const std::string& source, const std::string& key, const std::string& message) {
  if (!ok) throw ConfigError(source + ": " + key + ": " + message);
}

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

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
  auto in_range = [&](int v, int lo, int hi, const char* key) {
    require(v >= lo && v <= hi, source_name, std::string("coils.") + key,
            "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  };
  in_range(c.coils.pulse_ms, 1, 255, "pulse_ms");
  in_range(c.coils.hold_duty_pct, 0, 100, "hold_duty_pct");
  in_range(c.coils.max_pulse_ms, 1, 255, "max_pulse_ms");
  for (std::size_t i = 0; i < kPriorityKeys.size(); ++i) {
    require(c.threads.priorities[i] >= 0 && c.threads.priorities[i] <= 99, source_name,
            std::string("threads.priorities.") + kPriorityKeys[i], "must be in [0, 99]");
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
  static const std::set<std::string> sources{"sim", "v4l2", "file", "lcm"};
  require(sources.count(c.camera.source) == 1, s, "camera.source", "must be sim, v4l2, file or lcm");
  require(c.camera.width_px > 0 && c.camera.height_px > 0, s, "camera.width_px", "size must be positive");
  require(positive(c.camera.fps) && c.camera.fps <= 10000.0, s, "camera.fps", "must be in (0, 10000]");
  require(positive(c.camera.stall_timeout_s), s, "camera.stall_timeout_s", "must be > 0");
  require(c.camera.background_frames >= 1, s, "camera.background_frames", "must be >= 1");
  require(c.can.board_id >= 0 && c.can.board_id <= 15, s, "can.board_id", "must be in [0, 15]");
  require(positive(c.can.heartbeat_period_s), s, "can.heartbeat_period_s", "must be > 0");
  require(c.can.watchdog_timeout_s >= 3.0 * c.can.heartbeat_period_s, s, "can.watchdog_timeout_s",
          "must be at least 3 heartbeat periods");
  require(!c.controller.empty(), s, "controller", "is required");
  require(!c.lcm_url.empty(), s, "lcm_url", "is required");
  require(c.sim.balls >= 0, s, "sim.balls", "must be >= 0");
  require(c.sim.actuation_delay_s >= 0.0 && c.sim.actuation_delay_s < 0.1, s, "sim.actuation_delay_s",
          "must be in [0, 0.1) s");
  require(positive(c.sim.max_ball_time_s), s, "sim.max_ball_time_s", "must be > 0");
  require(c.threads.chain_cpu == "auto" || c.threads.chain_cpu == "off" ||
              (!c.threads.chain_cpu.empty() && c.threads.chain_cpu.size() <= 4 &&
               c.threads.chain_cpu.find_first_not_of("0123456789") == std::string::npos),
          s, "threads.chain_cpu", "must be auto, off or a CPU number");
  try {
    (void)plan_cpus(c.threads.chain_cpu);  // a CPU this process may not use
  } catch (const ConfigError& e) {
    throw ConfigError(s + ": " + e.what());
  }
  require(c.threads.cpu_dma_latency_us >= -1 && c.threads.cpu_dma_latency_us <= 1'000'000, s,
          "threads.cpu_dma_latency_us", "must be -1 (leave alone) or in [0, 1000000] us");
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

}  // namespace pinball::daemon
