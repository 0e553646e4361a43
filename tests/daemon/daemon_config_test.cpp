#include "pinball/daemon/daemon_config.h"

#include <yaml-cpp/yaml.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pinball/core/text_file.h"

namespace pinball::daemon {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    daemon_config_from_yaml(yaml, "t.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(DaemonConfig, TheDefaultsAreTheEmbeddedSimulation) {
  const DaemonConfig c;
  EXPECT_NO_THROW(validate_daemon_config(c, "defaults"));
  EXPECT_EQ(c.mode, "sim");
  EXPECT_EQ(c.sim.board, "boards/mit1993.board");
  EXPECT_EQ(c.sim.balls, 10);
  EXPECT_EQ(c.lcm_url, "memq://");
  EXPECT_EQ(c.controller, "controllers/imitation.json");
  EXPECT_FALSE(c.sim.realtime);
  EXPECT_EQ(c.threads.chain_cpu, "auto");
  EXPECT_EQ(c.threads.cpu_dma_latency_us, -1);
  EXPECT_EQ(daemon_config_from_yaml("version: 1", "t.yaml").mode, "sim");  // a file may say no more
}

TEST(DaemonConfig, AnEmptyFileIsRefusedNotTheSimulation) {
  // A wrong path, /dev/null or a truncated copy must not start the simulation.
  EXPECT_EQ(error_of(""), "t.yaml: (file): is empty (pinballd without --config runs the embedded simulation)");
  EXPECT_EQ(error_of("# nothing but a comment\n"),
            "t.yaml: (file): is empty (pinballd without --config runs the embedded simulation)");
  try {
    load_daemon_config("/dev/null");
    FAIL() << "/dev/null was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/null: is a device, not a file");  // /dev/zero was read without end
  }
}

TEST(DaemonConfig, OneDocumentAndEachKeyOnce) {
  EXPECT_EQ(error_of("sim: {balls: 3}\n---\nmode: lab\n"),
            "t.yaml:3: not valid YAML: a second YAML document (after ---): a file holds one");
  EXPECT_EQ(error_of("coils:\n  hold_duty_pct: 20\n  hold_duty_pct: 45\n"), "t.yaml: coils.hold_duty_pct: duplicate key");
  EXPECT_EQ(error_of("mode: sim\nmode: lab\n"), "t.yaml: mode: duplicate key");
}

TEST(DaemonConfig, CoilLimitsAreTheProtocolsAbsoluteOnes) {
  // Refused when the file is read, by key: not later as "DriverBusOptions: drivers[0]: ...".
  EXPECT_EQ(error_of("coils: {hold_duty_pct: 60}"),
            "t.yaml: coils.hold_duty_pct: must be in [0, 50] % (the protocol's absolute hold duty)");
  EXPECT_NO_THROW(daemon_config_from_yaml("coils: {hold_duty_pct: 50}", "t.yaml"));
  EXPECT_EQ(error_of("coils: {max_pulse_ms: 101}"),
            "t.yaml: coils.max_pulse_ms: must be in [1, 100] ms (the protocol's absolute pulse cap)");
  EXPECT_EQ(error_of("coils: {max_pulse_ms: 0}"),
            "t.yaml: coils.max_pulse_ms: must be in [1, 100] ms (the protocol's absolute pulse cap)");
  EXPECT_EQ(error_of("coils: {pulse_ms: 41}"), "t.yaml: coils.pulse_ms: must be in [1, max_pulse_ms] (40 ms)");
  EXPECT_EQ(error_of("coils: {pulse_ms: 0}"), "t.yaml: coils.pulse_ms: must be in [1, max_pulse_ms] (40 ms)");
  EXPECT_EQ(error_of("coils: {max_hold_ms: 10001}"),
            "t.yaml: coils.max_hold_ms: must be in [1, 10000] ms (the protocol's absolute hold cap)");
  EXPECT_EQ(error_of("coils: {max_hold_ms: 0}"),
            "t.yaml: coils.max_hold_ms: must be in [1, 10000] ms (the protocol's absolute hold cap)");
  EXPECT_EQ(error_of("coils: {recycle_ms: 256}"),
            "t.yaml: coils.recycle_ms: expected an integer in [0, 255], got '256' (line 1)");
  EXPECT_NO_THROW(daemon_config_from_yaml("coils: {pulse_ms: 100, max_pulse_ms: 100, max_hold_ms: 10000, recycle_ms: 0}",
                                          "t.yaml"));
}

TEST(DaemonConfig, TimesAndCountsHavePhysicalBounds) {
  EXPECT_EQ(error_of("can: {watchdog_timeout_s: 0.005}"),
            "t.yaml: can.watchdog_timeout_s: must be in [0.01, 1] s (the protocol's watchdog range)");
  EXPECT_EQ(error_of("can: {watchdog_timeout_s: 2}"),
            "t.yaml: can.watchdog_timeout_s: must be in [0.01, 1] s (the protocol's watchdog range)");
  EXPECT_EQ(error_of("can: {heartbeat_period_s: 0.0005}"), "t.yaml: can.heartbeat_period_s: must be at least 0.001 s");
  EXPECT_EQ(error_of("can: {heartbeat_period_s: 0.04}"),
            "t.yaml: can.watchdog_timeout_s: must be at least 3 heartbeat periods");
  EXPECT_NO_THROW(daemon_config_from_yaml("can: {heartbeat_period_s: 0.001, watchdog_timeout_s: 0.01}", "t.yaml"));
  EXPECT_EQ(error_of("camera: {stall_timeout_s: 0}"), "t.yaml: camera.stall_timeout_s: must be in (0, 1) s");
  EXPECT_EQ(error_of("camera: {stall_timeout_s: 1}"), "t.yaml: camera.stall_timeout_s: must be in (0, 1) s");
  EXPECT_EQ(error_of("camera: {stall_timeout_s: 1e300}"), "t.yaml: camera.stall_timeout_s: must be in (0, 1) s");
  EXPECT_EQ(error_of("camera: {background_frames: 0}"), "t.yaml: camera.background_frames: must be in [1, 10000]");
  EXPECT_EQ(error_of("camera: {background_frames: 10001}"), "t.yaml: camera.background_frames: must be in [1, 10000]");
  EXPECT_EQ(error_of("camera: {width_px: 100000}"), "t.yaml: camera.width_px: must be in [1, 8192] px");
  EXPECT_EQ(error_of("camera: {height_px: 0}"), "t.yaml: camera.height_px: must be in [1, 8192] px");
}

TEST(DaemonConfig, ReadsEverySection) {
  const DaemonConfig c = daemon_config_from_yaml(R"(
version: 1
sim: {balls: 3, seed: 9, realtime: true, actuation_delay_s: 0.002}
camera: {fps: 300, stall_timeout_s: 0.03}
can: {board_id: 2, heartbeat_period_s: 0.01, watchdog_timeout_s: 0.05}
coils: {pulse_ms: 25, hold_duty_pct: 30, max_hold_ms: 4000}
threads: {realtime: true, enforce: false, priorities: {driver: 95, lcm: 10}, chain_cpu: 1, cpu_dma_latency_us: 0}
lcm_url: "udpm://239.255.76.67:7667?ttl=0"
)", "t.yaml");
  EXPECT_EQ(c.sim.balls, 3);
  EXPECT_EQ(c.sim.seed, 9u);
  EXPECT_TRUE(c.sim.realtime);
  EXPECT_DOUBLE_EQ(c.camera.fps, 300.0);
  EXPECT_EQ(c.can.board_id, 2);
  EXPECT_EQ(c.coils.pulse_ms, 25);
  EXPECT_EQ(c.coils.hold_duty_pct, 30);
  EXPECT_EQ(c.coils.max_hold_ms, 4000);
  EXPECT_TRUE(c.threads.realtime);
  EXPECT_EQ(c.threads.priorities[0], 95);
  EXPECT_EQ(c.threads.priorities[1], 85);  // the table's
  EXPECT_EQ(c.threads.priorities[4], 10);
  EXPECT_EQ(c.threads.chain_cpu, "1");
  EXPECT_EQ(c.threads.cpu_dma_latency_us, 0);
  EXPECT_EQ(c.lcm_url, "udpm://239.255.76.67:7667?ttl=0");
}

TEST(DaemonConfig, ErrorsNameTheKey) {
  EXPECT_EQ(error_of("camera: {fsp: 200}"), "t.yaml: camera.fsp: unknown key");
  EXPECT_EQ(error_of("sim: {balls: many}"), "t.yaml: sim.balls: expected an integer (int32), got 'many' (line 1)");
  EXPECT_EQ(error_of("version: 2"), "t.yaml: version: is 2, this build reads 1");
  EXPECT_EQ(error_of("coils: {hold_duty_pct: 150}"),
            "t.yaml: coils.hold_duty_pct: must be in [0, 50] % (the protocol's absolute hold duty)");
  EXPECT_EQ(error_of("camera: {fps: 0}"), "t.yaml: camera.fps: must be in (0, 10000]");
  // A camera slower than the stall guard: every frame gap would let the flippers go.
  EXPECT_EQ(error_of("camera: {fps: 60}"),
            "t.yaml: camera.stall_timeout_s: must be at least two frame periods (2 / camera.fps = 0.0333 s), or "
            "every late frame releases the flippers");
  EXPECT_EQ(error_of("camera: {fps: 2, stall_timeout_s: 0.9}"),
            "t.yaml: camera.stall_timeout_s: must be at least two frame periods (2 / camera.fps = 1 s), or every "
            "late frame releases the flippers; at 2 frames/s no stall timeout under 1 s does: camera.fps must be "
            "above 2");
  EXPECT_EQ(error_of("can: {watchdog_timeout_s: 0.03}"),
            "t.yaml: can.watchdog_timeout_s: must be at least 3 heartbeat periods");
  EXPECT_EQ(error_of("mode: arcade"), "t.yaml: mode: must be sim or lab");
  EXPECT_EQ(error_of("camera: 5"), "t.yaml: camera: expected a mapping, got '5' (line 1)");
  EXPECT_EQ(error_of("threads: {priorities: {camera: 120}}"), "t.yaml: threads.priorities.camera: must be in [0, 99]");
  EXPECT_EQ(error_of("threads: {priorities: {gpu: 1}}"), "t.yaml: threads.priorities.gpu: unknown key");
  EXPECT_EQ(error_of("coils: {pulse_ms: 300}"), "t.yaml: coils.pulse_ms: expected an integer in [0, 255], got '300' (line 1)");
  EXPECT_EQ(error_of("sim: {stepper: rk4}"), "t.yaml: sim.stepper: unknown stepper 'rk4' (expected thesis or event)");
  EXPECT_EQ(error_of("threads: {chain_cpu: fast}"), "t.yaml: threads.chain_cpu: must be auto, off or a CPU number");
  EXPECT_EQ(error_of("threads: {chain_cpu: -3}"), "t.yaml: threads.chain_cpu: must be auto, off or a CPU number");
  EXPECT_EQ(error_of("threads: {chain_cpu: 1023}")
                .rfind("t.yaml: threads.chain_cpu: CPU 1023 is not one this process may use", 0),
            0u);
  EXPECT_EQ(error_of("threads: {cpu_dma_latency_us: -5}"),
            "t.yaml: threads.cpu_dma_latency_us: must be -1 (leave alone) or in [0, 1000000] us");
  EXPECT_NE(error_of("camera: {fps: [").find("t.yaml:1: not valid YAML"), std::string::npos);
}

TEST(DaemonConfig, TheWorldIsReadApartFromTheBelief) {
  const DaemonConfig c =
      daemon_config_from_yaml("sim: {board: a.board, world_board: b.board, stepper: event}", "t.yaml");
  EXPECT_EQ(c.sim.board, "a.board");
  EXPECT_EQ(c.sim.world_board, "b.board");
  EXPECT_EQ(c.sim.stepper, sim::StepperKind::kEvent);
  EXPECT_EQ(daemon_config_from_yaml("version: 1", "t.yaml").sim.stepper, sim::StepperKind::kThesis);
  EXPECT_EQ(error_of("sim: {stepper: euler}"),
            "t.yaml: sim.stepper: unknown stepper 'euler' (expected thesis or event)");
}

// The lab camera's format, exposure and occluder mask (docs/vision.md).
TEST(DaemonConfig, TheLabCamerasFormatExposureAndMask) {
  const DaemonConfig c =
      daemon_config_from_yaml("mode: lab\nboard: b\ncan: {interface: can0}\n"
                              "camera: {source: v4l2, device: /dev/video0, fourcc: GREY, exposure_s: 0.002, "
                              "occluder_mask: m.png}",
                              "t.yaml");
  EXPECT_EQ(c.camera.fourcc, "GREY");
  EXPECT_DOUBLE_EQ(c.camera.exposure_s, 0.002);
  EXPECT_EQ(c.camera.occluder_mask, "m.png");  // no base folder: kept as written
  EXPECT_EQ(DaemonConfig().camera.exposure_s, -1.0);  // the default leaves the driver's automatic exposure
  const std::string fourcc =
      "t.yaml: camera.fourcc: must be four characters, e.g. GREY, Y800, YUYV or MJPG (empty: the driver's format)";
  EXPECT_EQ(error_of("camera: {fourcc: GRE}"), fourcc);
  EXPECT_EQ(error_of("camera: {fourcc: \"GR Y\"}"), fourcc);
  const std::string exposure =
      "t.yaml: camera.exposure_s: must be in (0, 1] s, or negative for the driver's automatic exposure";
  EXPECT_EQ(error_of("camera: {exposure_s: 0}"), exposure);
  EXPECT_EQ(error_of("camera: {exposure_s: 2}"), exposure);
  EXPECT_EQ(error_of("camera: {exposure_s: .nan}"),
            "t.yaml: camera.exposure_s: expected a finite number (double), got '.nan' (line 1)");
  EXPECT_EQ(error_of("camera: {occluder_mask: m.png}"),
            "t.yaml: camera.occluder_mask: is for camera.source v4l2 or file "
            "(the simulated camera knows its plastics)");
}

TEST(DaemonConfig, LabModeNeedsItsHardware) {
  EXPECT_EQ(error_of("mode: lab"), "t.yaml: camera.source: cannot be sim in mode lab");
  EXPECT_EQ(error_of("mode: lab\ncamera: {source: v4l2}"), "t.yaml: camera.device: is required in mode lab");
  EXPECT_EQ(error_of("mode: lab\ncamera: {source: v4l2, device: /dev/video0}"),
            "t.yaml: board: is required in mode lab");
  EXPECT_EQ(error_of("mode: lab\nboard: b\ncamera: {source: v4l2, device: /dev/video0}"),
            "t.yaml: can.interface: must name a SocketCAN interface (can0) in mode lab");
  EXPECT_EQ(error_of("can: {interface: can0}"), "t.yaml: can.interface: must be sim in mode sim");
  // Pasted unquoted into the bring-up check's `sudo ip link add dev ...` hint, "can0; rm" read as two commands.
  EXPECT_EQ(error_of("mode: lab\nboard: b\ncamera: {source: v4l2, device: /dev/video0}\n"
                     "can: {interface: 'can0; rm'}"),
            "t.yaml: can.interface: 'can0; rm' is no interface name (at most 15 letters, digits, '_', '.', '-' "
            "or '@')");
}

TEST(DaemonConfig, TheLabExampleLoads) {
  const DaemonConfig c = load_daemon_config(std::string(PINBALL_SOURCE_DIR) + "/config/lab.example.yaml");
  EXPECT_EQ(c.mode, "lab");
  EXPECT_EQ(c.can.interface, "can0");
  EXPECT_EQ(c.camera.source, "v4l2");
}

// The issue's case: `fps: fast` names the file, the line, the key and the type.
TEST(DaemonConfig, AWrongTypeSaysWhichTypeWasExpected) {
  EXPECT_EQ(error_of("version: 1\ncamera:\n  fps: fast\n"),
            "t.yaml: camera.fps: expected a number (double), got 'fast' (line 3)");
  EXPECT_EQ(error_of("threads:\n  realtime: sometimes\n"),
            "t.yaml: threads.realtime: expected true or false, got 'sometimes' (line 2)");
  EXPECT_EQ(error_of("can: {interface: [can0]}"), "t.yaml: can.interface: expected text, got a list of 1 (line 1)");
}

TEST(DaemonConfig, SimModeMayTakeObservationsFromLcm) {
  DaemonConfig c = daemon_config_from_yaml("mode: sim\ncamera: {source: lcm}\n", "t.yaml");
  EXPECT_EQ(c.camera.source, "lcm");
  // pinballd's own bus, or a log it writes, brings it none from another process: it waited until SIGINT.
  for (const char* url : {"memq://", "file:///tmp/x.lcm?mode=w"}) {
    c.lcm_url = url;
    try {
      check_observation_source(c, "t.yaml");
      ADD_FAILURE() << url;
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(std::string("t.yaml: lcm_url: '") + url + "' carries no observation", 0),
                0u)
          << e.what();
    }
  }
  c.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  EXPECT_NO_THROW(check_observation_source(c, "t.yaml"));
  EXPECT_EQ(error_of("camera: {source: v4l2, device: /dev/video0}"),
            "t.yaml: camera.source: must be sim or lcm in mode sim");
}

TEST(DaemonConfig, TheBitrateIsTheProtocols) {
  EXPECT_EQ(daemon_config_from_yaml("version: 1", "t.yaml").can.bitrate_bps, 500000u);
  EXPECT_EQ(error_of("can: {bitrate_bps: 5000000}"),
            "t.yaml: can.bitrate_bps: must be 500000 bit/s: the driver board's firmware runs at no other rate "
            "(PROTOCOL.md)");
  EXPECT_NE(error_of("can: {bitrate_bps: 250000}").find("can.bitrate_bps: must be 500000"), std::string::npos);
}

// ---- paths ----

// A folder of its own under the test's temporary folder, made empty.
std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Runs `body` with the working directory set to `dir`, then restores it.
template <class Body>
void in_dir(const std::filesystem::path& dir, Body body) {
  const std::filesystem::path before = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  try {
    body();
  } catch (...) {
    std::filesystem::current_path(before);
    throw;
  }
  std::filesystem::current_path(before);
}

std::string load_error(const std::string& path) {
  try {
    load_daemon_config(path);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// The issue's case: `calibration: cal.yaml` beside the configuration loads
// from another working directory, and every path key is the file's folder's.
TEST(DaemonConfig, RelativePathsAreRelativeToTheConfigurationsFolder) {
  namespace fs = std::filesystem;
  const fs::path dir = fresh_dir("config_paths");
  const std::string source = PINBALL_SOURCE_DIR;
  fs::copy_file(source + "/calibration/lab.example.yaml", dir / "cal.yaml");
  fs::copy_file(source + "/boards/mit1993.board", dir / "table.board");
  fs::create_directories(dir / "logs");
  fs::create_directories(dir / "controllers");
  fs::copy_file(source + "/controllers/best.json", dir / "controllers" / "mine.json");
  write_file(dir / "pinballd.yaml",
             "version: 1\nmode: sim\ncalibration: cal.yaml\ncontroller: controllers/mine.json\n"
             "sim: {board: table.board, world_board: ./table.board}\ncan: {log: logs/can.log}\n"
             "lcm_url: \"file://logs/game.lcmlog?mode=w\"\n");
  DaemonConfig c;
  in_dir("/", [&] { c = load_daemon_config((dir / "pinballd.yaml").string()); });
  EXPECT_EQ(c.calibration, (dir / "cal.yaml").string());
  EXPECT_EQ(c.controller, (dir / "controllers" / "mine.json").string());
  EXPECT_EQ(c.sim.board, (dir / "table.board").string());
  EXPECT_EQ(c.sim.world_board, (dir / "table.board").string());
  EXPECT_EQ(c.can.log, (dir / "logs" / "can.log").string());
  EXPECT_EQ(c.lcm_url, "file://" + (dir / "logs" / "game.lcmlog").string() + "?mode=w");
  // A relative --config works the same from the file's folder's parent.
  in_dir(dir.parent_path(), [&] { c = load_daemon_config("config_paths/pinballd.yaml"); });
  EXPECT_EQ(c.calibration, (dir / "cal.yaml").string());
  // Keys left out keep their defaults, found as before (the working directory, then the source tree).
  write_file(dir / "pinballd.yaml", "version: 1\n");
  in_dir("/", [&] { c = load_daemon_config((dir / "pinballd.yaml").string()); });
  EXPECT_EQ(c.controller, "controllers/imitation.json");
}

// The defaults and a command line's relative paths name the shipped data
// from any folder; what a configuration file gave (absolute) is kept.
TEST(DaemonConfig, FindDataFilesFindsTheShippedDataFromAnyFolder) {
  const std::string source = PINBALL_SOURCE_DIR;
  DaemonConfig c;
  c.board = "boards/mit1993.board";  // the lab board, as --board would give it
  c.identified = "config/twin.identified.yaml";
  c.sim.twin_params = "config/twin.yaml";
  const std::string given = (fresh_dir("config_given") / "mine.json").string();
  c.sim.world_board = given;  // absolute: kept though it does not exist, for the loader's error to name
  in_dir("/", [&] { find_data_files(c); });
  EXPECT_TRUE(std::filesystem::exists(c.controller)) << c.controller;
  EXPECT_TRUE(std::filesystem::exists(c.board)) << c.board;
  EXPECT_TRUE(std::filesystem::exists(c.sim.board)) << c.sim.board;
  EXPECT_TRUE(std::filesystem::exists(c.identified)) << c.identified;
  EXPECT_TRUE(std::filesystem::exists(c.sim.twin_params)) << c.sim.twin_params;
  EXPECT_EQ(std::filesystem::path(c.sim.board).filename(), "mit1993.board");
  EXPECT_EQ(c.sim.world_board, given);
}

TEST(DaemonConfig, AMissingFileNamesTheConfigurationTheKeyAndThePath) {
  namespace fs = std::filesystem;
  const fs::path dir = fresh_dir("config_missing");
  const std::string file = (dir / "pinballd.yaml").string();
  write_file(file, "version: 1\ncalibration: cal.yaml\n");
  std::string what;
  in_dir("/", [&] { what = load_error(file); });
  EXPECT_EQ(what, file + ": calibration: 'cal.yaml' is " + (dir / "cal.yaml").string() +
                      " (a relative path is relative to the configuration's folder), which does not exist");
  write_file(file, "version: 1\ncan: {log: nowhere/can.log}\n");
  EXPECT_EQ(load_error(file), file + ": can.log: 'nowhere/can.log' is " + (dir / "nowhere" / "can.log").string() +
                                  " (a relative path is relative to the configuration's folder): its folder " +
                                  (dir / "nowhere").string() + " does not exist");
  write_file(file, "version: 1\nmode: lab\nboard: " + std::string(PINBALL_SOURCE_DIR) +
                       "/boards/mit1993.board\ncan: {interface: can0}\n"
                       "camera: {source: v4l2, device: /dev/video0, occluder_mask: mask.png}\n");
  EXPECT_EQ(load_error(file), file + ": camera.occluder_mask: 'mask.png' is " + (dir / "mask.png").string() +
                                  " (a relative path is relative to the configuration's folder), which does not exist");
  write_file(file, "version: 1\ncontroller: /nonexistent/c.json\n");
  EXPECT_EQ(load_error(file), file + ": controller: '/nonexistent/c.json', which does not exist");
  write_file(file, "version: 1\nsim: {board: ../config_missing}\n");
  EXPECT_EQ(load_error(file), file + ": sim.board: '../config_missing' is " + dir.string() +
                                  " (a relative path is relative to the configuration's folder), which is a "
                                  "folder, not a file");
  // The lab's board in mode sim would be read nowhere: refused, not ignored.
  write_file(file, "version: 1\nboard: lab.board\n");
  EXPECT_EQ(load_error(file), file + ": board: is the lab's table, unused in mode sim: the simulation's is sim.board "
                                     "(the world's sim.world_board)");
}

// A recording must not replace an input, nor the other recording (found: --can-log naming the
// controller file replaced it with the log, exit 0).
TEST(DaemonConfig, ARecordingReplacesNoInputAndNotTheOtherRecording) {
  DaemonConfig c;
  c.controller = ::testing::TempDir() + "/config_victim.json";
  c.can.log = c.controller;
  try {
    check_written_paths(c, "x.yaml");
    ADD_FAILURE() << "a CAN log over the controller file was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "x.yaml: can.log: '" + c.controller +
                                         "' is the file controller names: it would be replaced by the recording");
  }
  c.can.log = ::testing::TempDir() + "/config_both.log";
  c.lcm_url = "file://" + c.can.log + "?mode=w";
  EXPECT_THROW(check_written_paths(c, "x.yaml"), ConfigError) << "two recordings into one file";
  c.lcm_url = "file://" + c.controller + "?mode=w";
  EXPECT_THROW(check_written_paths(c, "x.yaml"), ConfigError) << "an LCM log over the controller";
}

// Compared by name, a hard link of the board became a CAN log (exit 0), and a log through a link whose
// target was not made yet was taken for another pinballd's and left an empty file behind.
TEST(DaemonConfig, ARecordingIsComparedAsTheFileItWritesNotByName) {
  namespace fs = std::filesystem;
  const fs::path dir = fresh_dir("config_links");
  const std::string controller = (dir / "c.json").string();
  write_file(controller, "{}");
  fs::create_hard_link(controller, dir / "c.can");
  DaemonConfig c;
  c.controller = controller;
  c.can.log = (dir / "c.can").string();
  try {
    check_written_paths(c, "x.yaml");
    ADD_FAILURE() << "a CAN log onto a hard link of the controller was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "x.yaml: can.log: '" + c.can.log +
                                         "' is the file controller names: it would be replaced by the recording");
  }
  c.controller.clear();
  fs::create_symlink("target.log", dir / "link.log");  // dangling: the write would create target.log
  c.can.log = (dir / "target.log").string();
  c.lcm_url = "file://" + (dir / "link.log").string() + "?mode=w";
  try {
    check_written_paths(c, "x.yaml");
    ADD_FAILURE() << "two recordings into one file through a link";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("is the lcm_url's log too"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "target.log"));
}

// --lcm-url file://CONFIG?mode=w made the configuration file an LCM log, exit 0 (--check said ok).
TEST(DaemonConfig, ARecordingReplacesNotItsOwnConfigurationFile) {
  const std::string file = ::testing::TempDir() + "/config_self.yaml";
  write_file(file, "version: 1\nmode: sim\n");
  DaemonConfig c = load_daemon_config(file);
  c.origin = file + " and the command line";  // as pinballd says it once an option overrides the file
  c.lcm_url = "file://" + file + "?mode=w";
  try {
    check_written_paths(c, c.origin);
    ADD_FAILURE() << "an LCM log over the configuration file was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), file + " and the command line: lcm_url: '" + file +
                                         "' is this configuration file: it would be replaced by the recording");
  }
  c.lcm_url = "memq://";
  c.can.log = file;
  EXPECT_THROW(check_written_paths(c, c.origin), ConfigError);
  EXPECT_EQ(read_text_file(file), "version: 1\nmode: sim\n");
}

TEST(DaemonConfig, TheSimulatedCameraRendersAtLeast32Pixels) {
  DaemonConfig c;
  c.camera.width_px = 31;
  try {
    validate_daemon_config(c, "x.yaml");
    ADD_FAILURE() << "a 31 px wide simulated camera was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "x.yaml: camera.width_px: and camera.height_px must be at least 32 px for the simulated camera");
  }
}

// What the command line gives never passed the loader: the files the daemon
// writes are checked on the configuration it runs with, and an LCM URL must
// name a provider liblcm has.
TEST(DaemonConfig, WrittenFilesAndTheLcmProviderAreCheckedWhereverTheyCameFrom) {
  namespace fs = std::filesystem;
  const fs::path dir = fresh_dir("config_written");
  DaemonConfig c;
  EXPECT_NO_THROW(check_written_paths(c, "config"));
  c.can.log = (dir / "can.log").string();
  EXPECT_NO_THROW(check_written_paths(c, "config"));
  c.can.log = (dir / "nowhere" / "can.log").string();
  try {
    check_written_paths(c, "config");
    ADD_FAILURE() << "a CAN log in a missing folder was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "config: can.log: '" + c.can.log + "': its folder " + (dir / "nowhere").string() +
                                         " does not exist");
  }
  c.can.log = dir.string();
  EXPECT_THROW(check_written_paths(c, "config"), ConfigError) << "a folder is not a log";
  std::ofstream(dir / "plain.txt") << "x";
  c.can.log = (dir / "plain.txt" / "can.log").string();
  try {
    check_written_paths(c, "config");
    ADD_FAILURE() << "a CAN log under a regular file was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "config: can.log: '" + c.can.log + "': " + (dir / "plain.txt").string() + " is a file, not a folder");
  }
  c.can.log.clear();
  c.lcm_url = "file://" + (dir / "nowhere" / "run.lcmlog").string() + "?mode=w";
  EXPECT_THROW(check_written_paths(c, "config"), ConfigError);
  c.lcm_url = "file://" + (dir / "nowhere" / "run.lcmlog").string();  // read: lcm-logplayer's, not written
  EXPECT_NO_THROW(check_written_paths(c, "config"));

  DaemonConfig bad_url;
  bad_url.lcm_url = "bogus://x";
  try {
    validate_daemon_config(bad_url, "config");
    ADD_FAILURE() << "an LCM URL with no provider was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "config: lcm_url: 'bogus://x' names no LCM provider: it starts with udpm://, "
                                     "mpudpm://, file://, memq:// or tcpq://");
  }
  for (const char* url : {"udpm://239.255.76.67:7667?ttl=0", "memq://", "file:///tmp/x.lcmlog?mode=w"}) {
    bad_url.lcm_url = url;
    EXPECT_NO_THROW(validate_daemon_config(bad_url, "config")) << url;
  }
  // A log read, not written: every publish refused, and exit 3 after the run.
  bad_url.lcm_url = "file:///tmp/x.lcmlog";
  try {
    validate_daemon_config(bad_url, "config");
    ADD_FAILURE() << "a file:// URL that reads was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("config: lcm_url: 'file:///tmp/x.lcmlog' reads a log (no ?mode=w), and "
                                          "liblcm refuses every message pinballd publishes there: record with "
                                          "'file:///tmp/x.lcmlog?mode=w'; replay",
                                          0),
              0u)
        << e.what();
  }
}

// `identified:` names the overlay laid over the belief (docs/identification.md):
// a file the daemon reads in either mode, found beside the configuration.
TEST(DaemonConfig, TheIdentifiedOverlayIsAFileTheDaemonReads) {
  namespace fs = std::filesystem;
  EXPECT_EQ(DaemonConfig{}.identified, "") << "by default the belief is the board file alone";
  const std::vector<std::string> path_keys = daemon_config_path_keys();
  EXPECT_EQ(std::set<std::string>(path_keys.begin(), path_keys.end()).count("identified"), 1u);
  const fs::path dir = fresh_dir("config_identified");
  write_file(dir / "over.yaml", "version: 1\n");  // the daemon reads it when it starts, not the configuration
  const std::string file = (dir / "pinballd.yaml").string();
  write_file(file, "version: 1\nidentified: over.yaml\n");
  DaemonConfig c;
  in_dir("/", [&] { c = load_daemon_config(file); });
  EXPECT_EQ(c.identified, (dir / "over.yaml").string());
  write_file(file,
             "version: 1\nmode: lab\nboard: over.yaml\ncamera: {source: lcm}\ncan: {interface: can0}\n"
             "identified: gone.yaml\n");
  EXPECT_EQ(load_error(file), file + ": identified: 'gone.yaml' is " + (dir / "gone.yaml").string() +
                                  " (a relative path is relative to the configuration's folder), which does not exist")
      << "read in mode lab too";
  EXPECT_EQ(error_of("identified: [a, b]"), "t.yaml: identified: expected text, got a list of 2 (line 1)");
}

// True when the mapping has the dotted key (const lookups: they never change the tree).
bool gives(const YAML::Node& map, const std::string& dotted) {
  if (!map.IsMap()) return false;
  const std::size_t dot = dotted.find('.');
  const YAML::Node child = map[dotted.substr(0, dot)];
  return child.IsDefined() && (dot == std::string::npos || gives(child, dotted.substr(dot + 1)));
}

// Every key the loader accepts is shown in config/lab.example.yaml, so the
// example cannot fall behind the loader (and loading it proves the reverse:
// a key the loader does not know is refused).
TEST(DaemonConfig, TheLabExampleShowsEveryKey) {
  const std::string path = std::string(PINBALL_SOURCE_DIR) + "/config/lab.example.yaml";
  (void)load_daemon_config(path);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const YAML::Node root = YAML::Load(text.str());
  const std::vector<std::string> keys = daemon_config_keys();
  EXPECT_GT(keys.size(), 40u);
  for (const std::string& key : keys) EXPECT_TRUE(gives(root, key)) << key << " is missing from " << path;
  EXPECT_EQ(std::set<std::string>(keys.begin(), keys.end()).count("can.log"), 1u);
  // The choices are listed beside the keys that take one.
  EXPECT_NE(text.str().find("# sim | lab"), std::string::npos);
  EXPECT_NE(text.str().find("# sim | v4l2 | file | lcm"), std::string::npos);
}

TEST(DaemonConfig, MissingFileIsNamed) {
  try {
    load_daemon_config("/nonexistent/pinballd.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/pinballd.yaml: cannot open");
  }
}

}  // namespace
}  // namespace pinball::daemon
