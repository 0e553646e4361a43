#include "pinball/daemon/daemon_config.h"

#include <gtest/gtest.h>

#include <string>

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

TEST(DaemonConfig, EmptyFileGivesTheEmbeddedSimulation) {
  const DaemonConfig c = daemon_config_from_yaml("", "t.yaml");
  EXPECT_EQ(c.mode, "sim");
  EXPECT_EQ(c.sim.board, "boards/mit1993.board");
  EXPECT_EQ(c.sim.balls, 10);
  EXPECT_EQ(c.lcm_url, "memq://");
  EXPECT_EQ(c.controller, "controllers/best.json");
  EXPECT_FALSE(c.sim.realtime);
  EXPECT_EQ(c.threads.chain_cpu, "auto");
  EXPECT_EQ(c.threads.cpu_dma_latency_us, -1);
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
  EXPECT_EQ(error_of("sim: {balls: many}"), "t.yaml: sim.balls: expected an integer");
  EXPECT_EQ(error_of("version: 2"), "t.yaml: version: is 2, this build reads 1");
  EXPECT_EQ(error_of("coils: {hold_duty_pct: 150}"), "t.yaml: coils.hold_duty_pct: must be in [0, 100]");
  EXPECT_EQ(error_of("camera: {fps: 0}"), "t.yaml: camera.fps: must be in (0, 10000]");
  EXPECT_EQ(error_of("can: {watchdog_timeout_s: 0.03}"),
            "t.yaml: can.watchdog_timeout_s: must be at least 3 heartbeat periods");
  EXPECT_EQ(error_of("mode: arcade"), "t.yaml: mode: must be sim or lab");
  EXPECT_EQ(error_of("camera: 5"), "t.yaml: camera: expected a mapping");
  EXPECT_EQ(error_of("threads: {priorities: {camera: 120}}"), "t.yaml: threads.priorities.camera: must be in [0, 99]");
  EXPECT_EQ(error_of("threads: {priorities: {gpu: 1}}"), "t.yaml: threads.priorities.gpu: unknown key");
  EXPECT_EQ(error_of("coils: {pulse_ms: 300}"), "t.yaml: coils.pulse_ms: expected an integer in [0, 255]");
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
  EXPECT_EQ(daemon_config_from_yaml("", "t.yaml").sim.stepper, sim::StepperKind::kThesis);
  EXPECT_EQ(error_of("sim: {stepper: euler}"),
            "t.yaml: sim.stepper: unknown stepper 'euler' (expected thesis or event)");
}

TEST(DaemonConfig, LabModeNeedsItsHardware) {
  EXPECT_EQ(error_of("mode: lab"), "t.yaml: camera.source: cannot be sim in mode lab");
  EXPECT_EQ(error_of("mode: lab\ncamera: {source: v4l2}"), "t.yaml: camera.device: is required in mode lab");
  EXPECT_EQ(error_of("mode: lab\ncamera: {source: v4l2, device: /dev/video0}"),
            "t.yaml: board: is required in mode lab");
  EXPECT_EQ(error_of("mode: lab\nboard: b\ncamera: {source: v4l2, device: /dev/video0}"),
            "t.yaml: can.interface: must name a SocketCAN interface (can0) in mode lab");
  EXPECT_EQ(error_of("can: {interface: can0}"), "t.yaml: can.interface: must be sim in mode sim");
}

TEST(DaemonConfig, TheLabExampleLoads) {
  const DaemonConfig c = load_daemon_config(std::string(PINBALL_SOURCE_DIR) + "/config/lab.example.yaml");
  EXPECT_EQ(c.mode, "lab");
  EXPECT_EQ(c.can.interface, "can0");
  EXPECT_EQ(c.camera.source, "v4l2");
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
