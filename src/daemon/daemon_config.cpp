#include "pinball/daemon/daemon_config.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "pinball/daemon/thread_table.h"

namespace pinball::daemon {
namespace {

// Reads one mapping, remembering which keys were used so that the rest can be
// reported as unknown (a misspelt key must not silently keep its default).
class Section {
 public:
  Section(const YAML::Node& node, std::string path, const std::string& source)
      : node_(node), path_(std::move(path)), source_(source) {
    if (node_ && !node_.IsNull() && !node_.IsMap()) fail(path_.empty() ? "(top)" : path_, "must be a mapping");
  }

  template <class T>
  void read(const char* key, T& out) {
    used_.insert(key);
    if (!node_ || node_.IsNull()) return;
    const YAML::Node v = node_[key];
    if (!v) return;
    try {
      out = v.as<T>();
    } catch (const YAML::Exception&) {
      fail(name(key), "has the wrong type");
    }
  }

  Section child(const char* key) {
    used_.insert(key);
    return Section(node_ && node_.IsMap() ? node_[key] : YAML::Node(), name(key), source_);
  }

  void finish() const {
    if (!node_ || !node_.IsMap()) return;
    for (const auto& kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (!used_.count(k)) fail(name(k.c_str()), "unknown key");
    }
  }

  std::string name(const char* key) const { return path_.empty() ? key : path_ + "." + key; }

  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw ConfigError(source_ + ": " + key + ": " + message);
  }

 private:
  YAML::Node node_;
  std::string path_;
  const std::string& source_;
  std::set<std::string> used_;
};

void require(bool ok, const std::string& source, const std::string& key, const std::string& message) {
  if (!ok) throw ConfigError(source + ": " + key + ": " + message);
}

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

}  // namespace

DaemonConfig daemon_config_from_yaml(const std::string& text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(source_name + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  DaemonConfig c;
  Section top(root, "", source_name);
  top.read("version", c.version);
  require(c.version == kConfigVersion, source_name, "version",
          "is " + std::to_string(c.version) + ", this build reads " + std::to_string(kConfigVersion));
  top.read("mode", c.mode);
  top.read("board", c.board);
  top.read("calibration", c.calibration);
  top.read("controller", c.controller);
  top.read("lcm_url", c.lcm_url);

  Section sim = top.child("sim");
  sim.read("board", c.sim.board);
  sim.read("world_board", c.sim.world_board);
  std::string stepper(pinball::sim::stepper_kind_name(c.sim.stepper));
  sim.read("stepper", stepper);
  try {
    c.sim.stepper = pinball::sim::parse_stepper_kind(stepper);
  } catch (const std::invalid_argument& e) {
    sim.fail(sim.name("stepper"), e.what());
  }
  sim.read("balls", c.sim.balls);
  sim.read("seed", c.sim.seed);
  sim.read("realtime", c.sim.realtime);
  sim.read("actuation_delay_s", c.sim.actuation_delay_s);
  sim.read("max_ball_time_s", c.sim.max_ball_time_s);
  sim.finish();

  Section cam = top.child("camera");
  cam.read("source", c.camera.source);
  cam.read("device", c.camera.device);
  cam.read("width_px", c.camera.width_px);
  cam.read("height_px", c.camera.height_px);
  cam.read("fps", c.camera.fps);
  cam.read("stall_timeout_s", c.camera.stall_timeout_s);
  cam.read("background_frames", c.camera.background_frames);
  cam.finish();

  Section can = top.child("can");
  can.read("interface", c.can.interface);
  can.read("board_id", c.can.board_id);
  can.read("heartbeat_period_s", c.can.heartbeat_period_s);
  can.read("watchdog_timeout_s", c.can.watchdog_timeout_s);
  can.read("log", c.can.log);
  can.finish();

  Section coils = top.child("coils");
  int pulse_ms = c.coils.pulse_ms, hold = c.coils.hold_duty_pct, max_pulse = c.coils.max_pulse_ms,
      max_hold = c.coils.max_hold_ms, recycle = c.coils.recycle_ms;
  coils.read("pulse_ms", pulse_ms);
  coils.read("hold_duty_pct", hold);
  coils.read("max_pulse_ms", max_pulse);
  coils.read("max_hold_ms", max_hold);
  coils.read("recycle_ms", recycle);
  coils.finish();
  auto in_range = [&](int v, int lo, int hi, const char* key) {
    require(v >= lo && v <= hi, source_name, std::string("coils.") + key,
            "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  };
  in_range(pulse_ms, 1, 255, "pulse_ms");
  in_range(hold, 0, 100, "hold_duty_pct");
  in_range(max_pulse, 1, 255, "max_pulse_ms");
  in_range(max_hold, 0, 65535, "max_hold_ms");
  in_range(recycle, 0, 255, "recycle_ms");
  c.coils.pulse_ms = static_cast<std::uint8_t>(pulse_ms);
  c.coils.hold_duty_pct = static_cast<std::uint8_t>(hold);
  c.coils.max_pulse_ms = static_cast<std::uint8_t>(max_pulse);
  c.coils.max_hold_ms = static_cast<std::uint16_t>(max_hold);
  c.coils.recycle_ms = static_cast<std::uint8_t>(recycle);

  Section threads = top.child("threads");
  threads.read("realtime", c.threads.realtime);
  threads.read("enforce", c.threads.enforce);
  threads.read("chain_cpu", c.threads.chain_cpu);
  threads.read("cpu_dma_latency_us", c.threads.cpu_dma_latency_us);
  Section prio = threads.child("priorities");
  static constexpr std::array<const char*, 5> kNames{"driver", "controller", "camera", "sim", "lcm"};
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    prio.read(kNames[i], c.threads.priorities[i]);
    require(c.threads.priorities[i] >= 0 && c.threads.priorities[i] <= 99, source_name,
            std::string("threads.priorities.") + kNames[i], "must be in [0, 99]");
  }
  prio.finish();
  threads.finish();
  top.finish();
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
