#include "pinball/daemon/config_check.h"

#include <filesystem>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "pinball/bus/lcm_bus.h"
#include "pinball/calibration/calibration_file.h"
#include "pinball/daemon/can_link_check.h"
#include "pinball/daemon/daemon.h"
#include "pinball/daemon/pipeline.h"
#include "pinball/daemon/thread_table.h"
#include "pinball/learn/planning_controller.h"
#include "pinball/sim/world.h"
#include "pinball/simlab/twin_params.h"
#include "pinball/simlab/world_factory.h"
#include "pinball/table/board_loader.h"
#include "pinball/vision/capture_source.h"

namespace pinball::daemon {
namespace {

std::string controller_kind(const control::ControllerSpec& spec) {
  if (spec.spastic) return "spastic";
  if (spec.cradle) return "cradle";
  if (spec.planner) return "planner";
  if (spec.shot_table) return "imitation";
  return "action function";
}

std::vector<std::string> calibration_sections(const calibration::Calibration& c) {
  std::vector<std::string> out;
  if (c.camera) out.emplace_back("camera");
  if (c.intrinsics) out.emplace_back("intrinsics");
  if (c.camera_timing) out.emplace_back("camera_timing");
  if (!c.flippers.empty()) out.emplace_back("flippers");
  if (c.gravity) out.emplace_back("gravity");
  return out;
}

// What the start's real-time requests (threads.realtime, threads.cpu_dma_latency_us)
// would be refused, asked of the system as the start asks, and given back.
std::vector<std::string> realtime_refusals(const ThreadSettings& t) {
  std::vector<std::string> out;
  if (t.realtime) {
    for (std::string why : {probe_lock_memory(), probe_sched_fifo(kDriverThread, t.priorities[kDriverThread])}) {
      if (!why.empty()) out.push_back(std::move(why));
    }
  }
  if (t.cpu_dma_latency_us >= 0) {
    const CpuLatencyRequest request(t.cpu_dma_latency_us);
    if (!request.ok()) out.push_back(request.why());
  }
  return out;
}

std::string camera_text(const CameraSettings& c) {
  std::ostringstream s;
  s << c.source;
  if (c.source == "v4l2" || c.source == "file") s << " " << c.device;
  if (c.source != "lcm") s << " " << c.width_px << "x" << c.height_px << " at " << c.fps << " fps";
  if (c.source == "v4l2") {
    s << ", format " << (c.fourcc.empty() ? "the driver's" : c.fourcc) << ", exposure ";
    if (c.exposure_s < 0.0) {
      s << "automatic";
    } else {
      s << c.exposure_s * 1e3 << " ms";
    }
  }
  return s.str();
}

}  // namespace

std::vector<std::string> check_lab_hardware(const DaemonConfig& config) {
  std::vector<std::string> warnings;
  std::string missing;
  if (config.camera.source == "v4l2") {
    if (const std::string m = vision::missing_camera_device(config.camera.device); !m.empty()) {
      missing = "camera.device: " + m;
    }
  } else if (config.camera.source == "file") {
    // A recording is read, not a device opened: decoding it is the only way to know it is a video
    // of the configured frame size.
    try {
      open_lab_camera(config.camera);
    } catch (const std::runtime_error& e) {
      missing = "camera.device: " + std::string(e.what());
    }
  }
  try {
    if (std::string note = check_can_link(config.can); !note.empty()) warnings.push_back(note);
  } catch (const ConfigError& e) {
    missing += (missing.empty() ? "" : "; ") + std::string(e.what());
  }
  if (!missing.empty()) throw ConfigError(config.origin + ": " + missing);
  return warnings;
}

ConfigCheck check_daemon_config(DaemonConfig config) {
  validate_daemon_config(config, config.origin);
  check_written_paths(config, config.origin);
  find_data_files(config);
  const bool sim = config.mode == "sim";
  ConfigCheck out;
  out.mode = config.mode;
  out.warnings = config_warnings(config);  // as the start prints them
  // The start opens a pipe for writing and refuses one nobody reads; the check opens nothing (a reader
  // would see the end of its input when it closed), so it says what the start will need.
  std::error_code ec;
  if (!config.can.log.empty() && std::filesystem::is_fifo(config.can.log, ec)) {
    out.warnings.push_back("can.log " + config.can.log +
                           " is a named pipe: its reader must be running when pinballd starts (the start refuses a "
                           "pipe nobody reads)");
  }
  for (const std::string& why : realtime_refusals(config.threads)) {
    if (config.threads.enforce) {
      throw ConfigError(config.origin + ": threads.enforce: true, and the system refuses: " + why);
    }
    out.warnings.push_back(why + "; the start runs without it");
  }
  const DaemonInputs inputs = load_daemon_inputs(config);
  learn::make_controller(inputs.spec, inputs.board);  // fits the board's flippers, or says why not
  out.board = sim ? config.sim.board : config.board;
  out.identified = config.identified;
  out.controller = config.controller;
  out.controller_kind = controller_kind(inputs.spec);
  out.calibration = config.calibration;
  if (!config.calibration.empty()) {
    out.calibration_sections = calibration_sections(calibration::read_calibration(config.calibration));
  }
  if (sim && config.camera.source == "sim") {
    if (config.sim.world == simlab::WorldKind::kTwin) {
      simlab::load_twin_params(config.sim.twin_params.empty() ? simlab::default_twin_params_path()
                                                              : config.sim.twin_params);
      out.world = "twin";
    } else {
      out.world = "model on the " + std::string(sim::stepper_kind_name(config.sim.stepper)) + " stepper";
    }
    if (!config.sim.world_board.empty()) {
      sim::check_same_flippers(table::load_board(config.sim.world_board), inputs.board);  // as the start does
      out.world += ", board " + config.sim.world_board;
    }
  }
  out.camera = camera_text(config.camera);
  out.occluder_mask = config.camera.occluder_mask;
  out.can = config.can.interface == "sim" ? "sim (the virtual driver board)"
                                          : config.can.interface + " at " + std::to_string(config.can.bitrate_bps) +
                                                " bit/s";
  out.lcm_url = config.lcm_url;
  try {
    bus::check_lcm_url_connects(config.lcm_url);  // found only at the start before
  } catch (const std::runtime_error& e) {
    throw ConfigError(config.origin + ": lcm_url: " + e.what());
  }
  if (!sim) {
    for (std::string& note : check_lab_hardware(config)) out.warnings.push_back(std::move(note));
  }
  return out;
}

std::string config_check_to_text(const ConfigCheck& c) {
  std::ostringstream s;
  const auto line = [&](const char* what, const std::string& value) {
    if (!value.empty()) s << what << value << "\n";
  };
  line("mode             ", c.mode);
  line("board            ", c.board);
  line("identified       ", c.identified);
  line("world            ", c.world);
  line("controller       ", c.controller + " (" + c.controller_kind + ")");
  if (!c.calibration.empty()) {
    std::string sections;
    for (const std::string& name : c.calibration_sections) sections += (sections.empty() ? "" : ", ") + name;
    line("calibration      ", c.calibration + " (" + (sections.empty() ? "no sections" : sections) + ")");
  }
  line("camera           ", c.camera);
  line("occluder mask    ", c.occluder_mask);
  line("can              ", c.can);
  line("lcm              ", c.lcm_url);
  for (const std::string& w : c.warnings) s << "warning          " << w << "\n";
  s << "ok: the configuration and every file it names load\n";
  return s.str();
}

nlohmann::json config_check_failure_to_json(const std::string& error) { return {{"ok", false}, {"error", error}}; }

nlohmann::json config_check_to_json(const ConfigCheck& c) {
  const auto or_null = [](const std::string& v) { return v.empty() ? nlohmann::json() : nlohmann::json(v); };
  return {{"ok", true},
          {"mode", c.mode},
          {"board", c.board},
          {"identified", or_null(c.identified)},
          {"world", or_null(c.world)},
          {"controller", c.controller},
          {"controller_kind", c.controller_kind},
          {"calibration", or_null(c.calibration)},
          {"calibration_sections", c.calibration_sections},
          {"camera", c.camera},
          {"occluder_mask", or_null(c.occluder_mask)},
          {"can", c.can},
          {"lcm_url", c.lcm_url},
          {"warnings", c.warnings}};
}

}  // namespace pinball::daemon
