// pinballd end to end in the embedded simulation: pixels, detector, tracker,
// controller, CAN frames, the virtual board and the solenoid delay.

#include "pinball/daemon/daemon.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <thread>
#include <variant>

#include <nlohmann/json.hpp>

#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/message_convert.h"
#include "pinball/firmware/codec.h"
#include "pinball/control/controller_file.h"
#include "pinball/core/clock.h"
#include "pinball/core/running_stats.h"
#include "pinball/daemon/thread_table.h"
#include "pinball/firmware/frame_log.h"
#include "pinball/learn/evaluator.h"
#include "pinball/table/board_loader.h"

namespace pinball::daemon {
namespace {

const std::string kSource = PINBALL_SOURCE_DIR;

DaemonConfig sim_config(int balls, std::uint64_t seed) {
  DaemonConfig c;
  c.sim.board = kSource + "/boards/mit1993.board";
  c.controller = kSource + "/controllers/best.json";
  c.sim.balls = balls;
  c.sim.seed = seed;
  return c;
}

// sim_config with each ball cut at 10 s: time for every stage, the tracker's
// noise estimate and the recordings to see a game; the rest of a 60 s ball
// adds only run time (up to a minute a test under ThreadSanitizer).
DaemonConfig short_sim_config(int balls, std::uint64_t seed) {
  DaemonConfig c = sim_config(balls, seed);
  c.sim.max_ball_time_s = 10.0;
  return c;
}

// Values inside the documented ranges that the simulation used to refuse at start: a board id
// other than 0 (its virtual board answered only to 0: "did not answer within 2 s") and a camera
// faster than 500 frames/s (its 2 ms exposure was longer than the frame).
TEST(Daemon, TheSimulationTakesAnyBoardIdAndAFastCamera) {
  DaemonConfig c = short_sim_config(1, 3);
  c.can.board_id = 15;
  c.camera.fps = 600;
  Daemon d(c);
  const DaemonReport r = d.run();
  EXPECT_EQ(r.balls, 1);
  EXPECT_GT(r.commands, 0);
  EXPECT_TRUE(r.coils_off_at_exit);
}

TEST(Daemon, LockstepRunsAreDeterminedByTheSeed) {
  DaemonReport a, b;
  {
    Daemon d(sim_config(2, 5));
    a = d.run();
  }
  {
    Daemon d(sim_config(2, 5));
    b = d.run();
  }
  ASSERT_EQ(a.balls, 2);
  ASSERT_EQ(b.balls, 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(a.results[static_cast<std::size_t>(i)].score, b.results[static_cast<std::size_t>(i)].score);
    EXPECT_EQ(a.results[static_cast<std::size_t>(i)].duration_s, b.results[static_cast<std::size_t>(i)].duration_s);
  }
  EXPECT_EQ(a.commands, b.commands);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_TRUE(a.coils_off_at_exit);
  EXPECT_EQ(a.frames_dropped, 0u);
  EXPECT_EQ(a.ring_overflows, 0u);
  EXPECT_EQ(a.board.watchdog_trips, 0u);
}

// The tracker measures the camera's noise as it plays; the report gives it
// beside the calibration's, and says when the camera wants calibrating again.
TEST(Daemon, TheReportGivesTheCameraNoiseTheTrackerMeasured) {
  Daemon d(short_sim_config(1, 3));
  const DaemonReport r = d.run();
  ASSERT_GT(r.camera_noise_calibrated_m, 0.0);
  ASSERT_TRUE(r.camera_noise_measured_m.has_value());
  EXPECT_GT(*r.camera_noise_measured_m, 0.0);
  EXPECT_FALSE(camera_noisier_than_calibrated(r));  // the embedded camera's rendered frames are cleaner than calibrated
  const nlohmann::json j = report_to_json(r);
  EXPECT_DOUBLE_EQ(j.at("camera_noise").at("measured_m").get<double>(), *r.camera_noise_measured_m);
  EXPECT_DOUBLE_EQ(j.at("camera_noise").at("calibrated_m").get<double>(), r.camera_noise_calibrated_m);
  EXPECT_NE(report_to_text(r).find("mm calibrated\n"), std::string::npos);

  DaemonReport noisy = r;
  noisy.camera_noise_measured_m = 3.0 * r.camera_noise_calibrated_m;
  EXPECT_TRUE(camera_noisier_than_calibrated(noisy));
  EXPECT_TRUE(report_to_json(noisy).at("camera_noise").at("over_calibration").get<bool>());
  EXPECT_NE(report_to_text(noisy).find("calibrate the camera again"), std::string::npos);
  DaemonReport unmeasured = r;
  unmeasured.camera_noise_measured_m.reset();
  EXPECT_TRUE(report_to_json(unmeasured).at("camera_noise").at("measured_m").is_null());
  EXPECT_EQ(report_to_text(unmeasured).find("camera noise"), std::string::npos);
}

// The simulated table may be another board (or stepper) than the one the
// tracker and the controller believe: the world is configured apart.
TEST(Daemon, TheWorldIsConfiguredApartFromTheBelief) {
  std::ifstream in(kSource + "/boards/mit1993.board");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("gravity 1110"), 12, "gravity 1000");
  const std::string world_board =
      (std::filesystem::temp_directory_path() / ("pinballd_world_" + std::to_string(getpid()) + ".board")).string();
  std::ofstream(world_board) << text;
  DaemonReport model, other, event;
  {
    Daemon d(sim_config(2, 5));
    model = d.run();
  }
  {
    DaemonConfig c = sim_config(2, 5);
    c.sim.world_board = world_board;
    Daemon d(c);
    other = d.run();
  }
  {
    DaemonConfig c = sim_config(2, 5);
    c.sim.stepper = sim::StepperKind::kEvent;
    Daemon d(c);
    event = d.run();
  }
  std::filesystem::remove(world_board);
  EXPECT_EQ(model.world, "thesis");
  EXPECT_EQ(model.world_board, kSource + "/boards/mit1993.board");
  EXPECT_EQ(other.world_board, world_board);
  EXPECT_EQ(event.world, "event");
  ASSERT_EQ(other.balls, 2);
  EXPECT_NE(model.results[0].duration_s, other.results[0].duration_s);
  EXPECT_NE(model.results[0].duration_s, event.results[0].duration_s);
  EXPECT_EQ(report_to_json(other).at("world").at("board"), world_board);
}

TEST(Daemon, PlaysTheTwinThroughPixelsAndCanFrames) {
  if (!simlab::twin_available()) GTEST_SKIP() << "this build has no MuJoCo twin";
  DaemonConfig c = short_sim_config(2, 5);
  c.sim.world = simlab::WorldKind::kTwin;
  DaemonReport r;
  {
    Daemon d(c);
    r = d.run();
  }
  EXPECT_EQ(r.world, "twin");
  ASSERT_EQ(r.balls, 2);
  EXPECT_GT(r.detections, 0u) << "the camera saw the twin's ball";
  EXPECT_EQ(r.world_warnings.instability, 0u);
  EXPECT_EQ(report_to_json(r).at("world").at("stepper"), "twin");
  EXPECT_TRUE(r.coils_off_at_exit);
}

// Where the threads run and who writes the CAN frame change the timing, never the game.
TEST(Daemon, PinningDoesNotChangeTheGame) {
  DaemonConfig pinned = sim_config(2, 5);
  DaemonConfig free = pinned;
  free.threads.chain_cpu = "off";
  DaemonReport a, b;
  {
    Daemon d(pinned);
    a = d.run();
  }
  {
    Daemon d(free);
    b = d.run();
  }
  EXPECT_EQ(b.cpus, "not pinned");
  EXPECT_FALSE(a.cpus.empty());
  ASSERT_EQ(a.balls, b.balls);
  for (std::size_t i = 0; i < a.results.size(); ++i) EXPECT_EQ(a.results[i].score, b.results[i].score);
  EXPECT_EQ(a.commands, b.commands);
  EXPECT_EQ(a.driver.fires, b.driver.fires);
  // Every command has its command->CAN latency, but for the shutdown's
  // release, given after the threads have stopped.
  EXPECT_GT(a.latency[kFrameToCan].count, 0u);
  EXPECT_LE(a.latency[kCommandToCan].count, a.commands);
  EXPECT_GE(a.latency[kCommandToCan].count + 2, a.commands);
}

TEST(Daemon, FullPathScoresLikeTheFastLearningLoop) {
  // The same controller on the same 20 ball seeds: the daemon (pixels,
  // detector, rings, CAN, virtual board) and the fast loop (camera model,
  // no threads) must agree within their statistical error.
  constexpr int kBalls = 20;
  constexpr std::uint64_t kSeed = 11;
  Daemon d(sim_config(kBalls, kSeed));
  const DaemonReport r = d.run();
  ASSERT_EQ(r.balls, kBalls);
  RunningStats daemon_scores;
  for (const simlab::SimBallResult& b : r.results) daemon_scores.add(b.score);

  const table::Board board = table::load_board(kSource + "/boards/mit1993.board");
  const control::ControllerSpec spec = control::load_controller(kSource + "/controllers/best.json");
  learn::EvaluatorConfig ec;
  ec.actuation_delay_s = 0.004;
  ec.max_ball_time_s = 60.0;
  ec.camera.latency_s = 0.0;  // the daemon's simulated camera hands each frame over at once
  const learn::PinballEvaluator evaluator(board, ec);
  RunningStats fast_scores;
  for (int i = 0; i < kBalls; ++i) {
    fast_scores.add(evaluator.play(spec, ball_seed(kSeed, static_cast<std::uint64_t>(i))).score);
  }
  const double se = std::sqrt(daemon_scores.variance() / kBalls + fast_scores.variance() / kBalls);
  std::printf("daemon %.0f +- %.0f, fast loop %.0f +- %.0f (1 se)\n", daemon_scores.mean(),
              std::sqrt(daemon_scores.variance() / kBalls), fast_scores.mean(),
              std::sqrt(fast_scores.variance() / kBalls));
  EXPECT_LT(std::abs(daemon_scores.mean() - fast_scores.mean()), 3.0 * se);
  EXPECT_GT(daemon_scores.mean(), 0.0);
  // The controller really played: it fired, and the board obeyed every fire
  // (the controller never fires within a coil's recycle time).
  EXPECT_GT(r.driver.fires, static_cast<std::uint64_t>(kBalls));
  EXPECT_EQ(r.board.fires_accepted, r.driver.fires);
  EXPECT_GT(r.latency[kFrameToCan].count, 0u);
  EXPECT_TRUE(r.coils_off_at_exit);
}

struct StatsCounter {
  std::atomic<int> n{0};
  std::atomic<std::int64_t> frames{0};
  std::atomic<int> stages{0};
  std::atomic<int> games{0};
  std::atomic<std::int64_t> can_log_written{-1}, can_log_dropped{-1}, lcm_published{-1}, lcm_publish_failed{-1};
  bus::RawHandler on_stats = bus::typed_handler<pinball_lcm::lcmt_pinball_daemon_stats>(
      [this](const pinball_lcm::lcmt_pinball_daemon_stats& m) {
        frames = m.frames;
        stages = m.num_stages;
        can_log_written = m.can_log_written;
        can_log_dropped = m.can_log_dropped;
        lcm_published = m.lcm_published;
        lcm_publish_failed = m.lcm_publish_failed;
        ++n;
      });
  bus::RawHandler on_game =
      bus::typed_handler<pinball_lcm::lcmt_pinball_game_event>([this](const pinball_lcm::lcmt_pinball_game_event&) {
        ++games;
      });
};

TEST(Daemon, PublishesStatsAndGameEventsOnLcm) {
  StatsCounter c;
  Daemon d(short_sim_config(1, 3));
  bus::subscribe_raw(d.lcm_bus().lcm(), bus::kStatsChannel, c.on_stats);
  bus::subscribe_raw(d.lcm_bus().lcm(), bus::kGameChannel, c.on_game);
  const DaemonReport r = d.run();
  EXPECT_GE(c.n.load(), 1);  // at least the one on exit
  EXPECT_EQ(c.stages.load(), static_cast<int>(kStageCount));
  EXPECT_EQ(c.frames.load(), static_cast<std::int64_t>(r.frames));
  EXPECT_GE(c.games.load(), 2);  // launch and loss
  EXPECT_EQ(r.lcm.overflows, 0u);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The CAN log is written off the real-time threads now: a normal run must
// still hold every frame, in candump's format to the byte, and say so.
TEST(Daemon, ACanLogHoldsEveryFrameAndTheReportAndStatsSaySo) {
  const std::string path = ::testing::TempDir() + "/pinballd_can_" + std::to_string(getpid()) + ".log";
  DaemonConfig config = short_sim_config(2, 6);
  config.can.log = path;
  StatsCounter c;
  Daemon d(config);
  bus::subscribe_raw(d.lcm_bus().lcm(), bus::kStatsChannel, c.on_stats);
  const DaemonReport r = d.run();
  ASSERT_TRUE(r.can_log.has_value());
  EXPECT_EQ(r.can_log->dropped(), 0u);
  EXPECT_EQ(r.can_log->first_error, "");
  // Every frame sent is recorded (so are those received).
  EXPECT_GE(r.can_log->written, r.driver.frames_sent);
  EXPECT_EQ(recording_problems(r), "");
  EXPECT_TRUE(report_to_json(r)["recording_complete"].get<bool>());
  EXPECT_EQ(report_to_json(r)["can_log"]["written"].get<std::uint64_t>(), r.can_log->written);
  EXPECT_NE(report_to_text(r).find("recordings: CAN log " + std::to_string(r.can_log->written) + " frames written, 0 dropped"),
            std::string::npos);
  // The last PINBALL_STATS comes after the log is closed: its counts are the final ones.
  EXPECT_EQ(c.can_log_written.load(), static_cast<std::int64_t>(r.can_log->written));
  EXPECT_EQ(c.can_log_dropped.load(), 0);
  EXPECT_GT(c.lcm_published.load(), 0);
  EXPECT_EQ(c.lcm_publish_failed.load(), 0);
  const std::string text = read_text(path);
  std::uint64_t lines = 0;
  std::size_t start = 0;
  std::optional<firmware::MessageKind> last_host_kind;  // the host's last word to the board
  for (std::size_t end = text.find('\n'); end != std::string::npos; start = end + 1, end = text.find('\n', start)) {
    const std::string line = text.substr(start, end - start);
    const auto e = firmware::parse_log_line(line);
    ASSERT_TRUE(e.has_value()) << line;
    EXPECT_EQ(e->interface, "simcan");
    EXPECT_EQ(firmware::format_log_line(e->frame, e->time_s, "simcan"), line);  // candump's format, to the byte
    const firmware::DecodeResult m = firmware::decode(e->frame);
    const bool from_board = m.ok() && (std::holds_alternative<firmware::Status>(m.message.payload) ||
                                       std::holds_alternative<firmware::Fault>(m.message.payload) ||
                                       std::holds_alternative<firmware::HelloAck>(m.message.payload));
    if (m.ok() && !from_board) last_host_kind = firmware::kind_of(m.message.payload);
    ++lines;
  }
  EXPECT_EQ(start, text.size());  // nothing after the last newline
  EXPECT_EQ(lines, r.can_log->written);
  // The shutdown's ReleaseAll is the last frame the host sends: no heartbeat after it.
  ASSERT_TRUE(last_host_kind.has_value());
  EXPECT_EQ(*last_host_kind, firmware::MessageKind::kReleaseAll);
  std::remove(path.c_str());
}

// Every command the controller gave is on PINBALL_FLIPPER_CMD, the shutdown's
// release-all included (it used to reach the CAN log but not LCM).
TEST(Daemon, EveryCommandIsPublishedTheShutdownReleaseLast) {
  std::atomic<std::uint64_t> published{0};
  std::atomic<int> last_cause{-1};
  bus::RawHandler on_command = bus::typed_handler<pinball_lcm::lcmt_pinball_flipper_command>(
      [&](const pinball_lcm::lcmt_pinball_flipper_command& m) {
        ++published;
        last_cause = m.cause;
      });
  Daemon d(short_sim_config(2, 4));
  bus::subscribe_raw(d.lcm_bus().lcm(), bus::kFlipperCommandChannel, on_command);
  const DaemonReport r = d.run();
  EXPECT_GT(r.commands, 1u);
  EXPECT_EQ(published.load(), r.commands);
  EXPECT_EQ(last_cause.load(), pinball_lcm::lcmt_pinball_flipper_command::CAUSE_SHUTDOWN);
}

TEST(Daemon, StopMidBallReleasesEveryCoil) {
  DaemonConfig c = sim_config(1000, 2);
  c.sim.realtime = true;  // the wall clock: stop arrives mid-game
  Daemon d(c);
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    d.request_stop();
  });
  const DaemonReport r = d.run();
  stopper.join();
  EXPECT_LT(r.balls, 1000);
  EXPECT_TRUE(r.coils_off_at_exit);
  EXPECT_GE(r.driver.release_alls, 1u);
  EXPECT_GT(r.frames, 100u);
}

TEST(Daemon, BadFilesAreNamed) {
  DaemonConfig c = sim_config(1, 1);
  c.controller = "/nonexistent/controller.json";
  EXPECT_THROW(Daemon{c}, std::exception);
  c = sim_config(1, 1);
  c.sim.board = "/nonexistent/x.board";
  try {
    Daemon d(c);
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.board"), std::string::npos);
  }
}

// Mode sim with camera.source lcm: observations arriving on LCM (here
// published in-process over memq://, in the lab by lcm-logplayer) drive the
// tracker and the controller, and the commands reach the virtual driver
// board over the sim CAN link; no world is played.
TEST(Daemon, SimModeTakesObservationsFromLcm) {
  DaemonConfig c = sim_config(0, 1);
  c.camera.source = "lcm";
  Daemon d(c);
  DaemonReport r;
  std::thread runner([&] { r = d.run(); });
  const table::Board board = table::load_board(c.sim.board);
  const double x_m = 0.5 * (board.flippers[0].pivot.x() + board.flippers[1].pivot.x());
  constexpr int kSent = 300;
  for (int i = 0; i < kSent; ++i) {
    // A ball rolling down the middle of the table at 200 frames a second.
    const double t_s = i / 200.0;
    track::Observation o;
    o.t_s = t_s;
    o.p_board = Vec2(x_m, 1.0 - 0.5 * t_s);
    const auto utime = static_cast<std::int64_t>(t_s * 1e6);
    const pinball_lcm::lcmt_pinball_observation m = bus::to_lcm_observation(utime, utime, i, true, o, 0.0, 0.0, {});
    d.lcm_bus().lcm().publish(bus::kObservationChannel, &m);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  d.request_stop();
  runner.join();
  EXPECT_TRUE(r.thread_failures.empty());
  EXPECT_EQ(r.balls, 0);  // no world
  EXPECT_GE(r.detections, static_cast<std::uint64_t>(kSent * 9 / 10));  // the tracker was fed them
  EXPECT_GT(r.projections, 0u);
  EXPECT_GE(r.driver.sessions, 1u);     // the virtual board answered Hello
  EXPECT_GT(r.driver.heartbeats, 0u);  // and the chain armed it (how often depends on the machine's load)
  EXPECT_TRUE(r.coils_off_at_exit);
  // The report says that no world played, rather than a blank world line.
  EXPECT_TRUE(report_to_json(r).at("world").is_null());
  EXPECT_NE(report_to_text(r).find("world none: observations from LCM drive the tracker\n"), std::string::npos)
      << report_to_text(r);
}

TEST(Daemon, ReadsACalibrationFile) {
  DaemonConfig c = sim_config(1, 6);
  c.calibration = kSource + "/calibration/lab.example.yaml";
  Daemon d(c);
  const DaemonReport r = d.run();
  EXPECT_EQ(r.balls, 1);
  EXPECT_GT(r.detections * 10, r.frames * 7);  // the calibrated homography still finds the ball
}

TEST(Daemon, BadCalibrationIsNamed) {
  const std::string path = ::testing::TempDir() + "/bad_calibration.yaml";
  FILE* f = std::fopen(path.c_str(), "w");
  std::fputs("version: 1\nflippers:\n  - {name: left}\n", f);
  std::fclose(f);
  DaemonConfig c = sim_config(1, 6);
  c.calibration = path;
  try {
    Daemon d(c);
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(Daemon, TheLabCameraNeedsACalibratedHomography) {
  DaemonConfig c = load_daemon_config(kSource + "/config/lab.example.yaml");
  c.board = kSource + "/boards/mit1993.board";
  c.controller = kSource + "/controllers/best.json";
  c.calibration = "";
  c.can.interface = "can0";
  // SocketCAN is tried first; without CAN in the kernel that is the error.
  try {
    Daemon d(c);
    FAIL();
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_TRUE(what.find("can0") != std::string::npos || what.find("calibration") != std::string::npos) << what;
  }
}

// Whether process `pid` has a handler of its own for `signal` (the SigCgt mask of /proc/PID/status).
bool catches_signal(pid_t pid, int signal) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (signal - 1)) & 1ULL;
  }
  return false;
}

// pinballd as a child process: SIGINT releases every coil and exits 0.
TEST(Pinballd, SigintReleasesCoilsAndExitsZero) {
  const std::string out = ::testing::TempDir() + "/pinballd_sigint.json";
  const std::string errors = ::testing::TempDir() + "/pinballd_sigint.err";
  const std::string cmd = std::string(PINBALLD_EXE) + " --balls 1000 --json --controller " + kSource +
                          "/controllers/best.json --sim " + kSource + "/boards/mit1993.board > " + out + " 2> " +
                          errors;
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // SIGUSR1's default is to end the process: wait (up to 60 s) until pinballd
  // catches it, which a slow start under ThreadSanitizer can take long to do.
  for (int i = 0; i < 600 && !catches_signal(pid, SIGUSR1); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(catches_signal(pid, SIGUSR1)) << "pinballd did not install its SIGUSR1 handler within 60 s";
  std::this_thread::sleep_for(std::chrono::milliseconds(2000));  // a game under way
  ASSERT_EQ(kill(pid, SIGUSR1), 0);  // prints the latency table and goes on
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  FILE* f = std::fopen(out.c_str(), "r");
  ASSERT_NE(f, nullptr);
  std::string text;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  std::fclose(f);
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_TRUE(j["coils_off_at_exit"].get<bool>());
  EXPECT_LT(j["balls"].get<int>(), 1000);
  EXPECT_GE(j["can"]["release_alls"].get<int>(), 1);
  FILE* e = std::fopen(errors.c_str(), "r");
  ASSERT_NE(e, nullptr);
  std::string err_text;
  while ((n = std::fread(buf, 1, sizeof buf, e)) > 0) err_text.append(buf, n);
  std::fclose(e);
  EXPECT_NE(err_text.find("frame->can_written"), std::string::npos) << err_text;
}

// Every signal whose default would kill it (SIGHUP: the terminal that started it closing)
// ends pinballd as SIGINT does: coils released, a report, exit 0.
TEST(Pinballd, EverySignalThatWouldKillItReleasesTheCoilsFirst) {
  for (const int sig : {SIGHUP, SIGQUIT, SIGUSR2, SIGALRM}) {
    const std::string out = ::testing::TempDir() + "/pinballd_signal_" + std::to_string(sig) + ".json";
    const std::string cmd = std::string(PINBALLD_EXE) + " --balls 1000 --json > " + out + " 2>/dev/null";
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    for (int i = 0; i < 600 && !catches_signal(pid, SIGUSR1); ++i) {  // installed last: all are
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ASSERT_TRUE(catches_signal(pid, sig)) << strsignal(sig) << " is not caught";
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ASSERT_EQ(kill(pid, sig), 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status)) << strsignal(sig) << " killed it";
    EXPECT_EQ(WEXITSTATUS(status), 0) << strsignal(sig);
    const nlohmann::json j = nlohmann::json::parse(read_text(out));
    EXPECT_TRUE(j["coils_off_at_exit"].get<bool>()) << strsignal(sig);
    EXPECT_TRUE(j["stopped_by_signal"].get<bool>()) << strsignal(sig);
    EXPECT_GE(j["can"]["release_alls"].get<int>(), 1) << strsignal(sig);
    std::remove(out.c_str());
  }
}

// A stderr nobody drains (a pipe whose reader sleeps) holds neither the release nor the exit:
// what stderr cannot take at once is dropped, and the report keeps it. Found with a simulated
// camera at 2 frames/s, whose frame gaps the simulated board's watchdog reports as faults all
// along (sim_watchdog_warning; 3 frames/s here, the slowest a stall timeout allows): stdio,
// blocked on the full pipe, went on retrying each partial write after SIGINT, and the daemon
// never reached its shutdown.
TEST(Pinballd, AStderrNobodyReadsHoldsNeitherTheReleaseNorTheExit) {
  const std::string base = ::testing::TempDir() + "/pinballd_stuck_stderr_" + std::to_string(getpid());
  // The LCM log shows the game going on (every frame publishes), whatever a slow build's start costs.
  const std::string lcm_log = base + ".lcmlog";
  write_file(base + ".yaml", "version: 1\nmode: sim\ncamera:\n  fps: 3\n  stall_timeout_s: 0.9\nlcm_url: \"file://" +
                                 lcm_log + "?mode=w\"\n");
  int err_pipe[2];
  ASSERT_EQ(pipe(err_pipe), 0);
  ASSERT_GT(fcntl(err_pipe[1], F_SETPIPE_SZ, 4096), 0);  // full after a few dozen faults
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    dup2(err_pipe[1], STDERR_FILENO);
    close(err_pipe[0]);
    const std::string cmd =
        std::string(PINBALLD_EXE) + " --config " + base + ".yaml --balls 1000 --realtime --json > " + base + ".json";
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(err_pipe[1]);
  // Until the game has gone on for a second and a half (its log growing all along: a frame gap is
  // a watchdog fault every third of a second) and stderr takes no more: bytes queued, none added
  // for a second.
  int queued_bytes = 0;
  int unchanged_polls = 0;
  int polls_in_play = -1;  // since the log first grew
  std::uintmax_t log_bytes = 0;
  for (int i = 0; i < 600 && (unchanged_polls < 10 || polls_in_play < 15); ++i) {  // 60 s
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const int before = queued_bytes;
    ASSERT_EQ(ioctl(err_pipe[0], FIONREAD, &queued_bytes), 0);
    unchanged_polls = queued_bytes > 0 && queued_bytes == before ? unchanged_polls + 1 : 0;
    std::error_code ec;
    const std::uintmax_t now_bytes = std::filesystem::file_size(lcm_log, ec);
    if (polls_in_play >= 0) {
      ++polls_in_play;
    } else if (!ec && log_bytes > 0 && now_bytes > log_bytes) {
      polls_in_play = 0;
    }
    if (!ec) log_bytes = now_bytes;
  }
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  pid_t done = 0;
  for (int i = 0; i < 100 && done == 0; ++i) {  // 10 s
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    done = waitpid(pid, &status, WNOHANG);
  }
  if (done == 0) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  close(err_pipe[0]);
  ASSERT_NE(done, 0) << "pinballd did not end within 10 s of SIGINT with its stderr full";
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const nlohmann::json j = nlohmann::json::parse(read_text(base + ".json"));
  EXPECT_TRUE(j["coils_off_at_exit"].get<bool>());
  EXPECT_TRUE(j["stopped_by_signal"].get<bool>());
  EXPECT_GT(j["faults"]["count"].get<int>(), 0) << "the faults that filled stderr are in the report";
  for (const char* ext : {".yaml", ".json", ".lcmlog"}) std::remove((base + ext).c_str());
}

// Runs `cmd` through the shell; returns its exit status and what it printed.
int run_shell(const std::string& cmd, std::string& output) {
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return -1;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) output += buf;
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void write_file(const std::string& path, const std::string& text) {
  FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  std::fputs(text.c_str(), f);
  std::fclose(f);
}

// A recording that lost anything is not a success: exit 3, and the report and stderr say what was lost.
TEST(Pinballd, ACanLogOnAFullDiskExitsThreeAndTheReportSaysSo) {
  const std::string out = ::testing::TempDir() + "/pinballd_full_" + std::to_string(getpid()) + ".json";
  std::string text;
  // stderr to `text`, the JSON report to `out`.
  const int status =
      run_shell(std::string(PINBALLD_EXE) + " --balls 1 --seed 2 --json --can-log /dev/full 2>&1 > " + out, text);
  EXPECT_EQ(status, kExitRecordingIncomplete) << text;
  EXPECT_NE(text.find("CAN log /dev/full: write failed: No space left on device"), std::string::npos) << text;
  EXPECT_NE(text.find("pinballd: the recording is incomplete (exit 3): "), std::string::npos) << text;
  EXPECT_NE(text.find("CAN frames dropped (0 queue full, "), std::string::npos) << text;
  const nlohmann::json j = nlohmann::json::parse(read_text(out));
  EXPECT_FALSE(j["recording_complete"].get<bool>());
  EXPECT_EQ(j["can_log"]["written"].get<int>(), 0);
  EXPECT_GT(j["can_log"]["dropped_write_error"].get<int>(), 0);
  EXPECT_EQ(j["can_log"]["first_errno"].get<int>(), ENOSPC);
  EXPECT_TRUE(j["coils_off_at_exit"].get<bool>());  // the run itself went on as ever
  EXPECT_EQ(j["balls"].get<int>(), 1);
  std::remove(out.c_str());
}

// The CAN log is opened only once the start has passed: a start that fails
// (here the world's board is no board) leaves the last run's log as it was.
TEST(Daemon, AStartThatFailsLeavesTheLastRunsCanLogAsItWas) {
  const std::string stem = ::testing::TempDir() + "/pinballd_keep_" + std::to_string(getpid());
  const std::string kept = "(1.000000) simcan 123#\n";
  write_file(stem + ".can", kept);
  write_file(stem + ".board", "this is not a board\n");
  DaemonConfig config = short_sim_config(1, 1);
  config.can.log = stem + ".can";
  config.sim.world_board = stem + ".board";
  EXPECT_THROW(Daemon d(config), std::exception);
  EXPECT_EQ(read_text(stem + ".can"), kept);
  std::remove((stem + ".can").c_str());
  std::remove((stem + ".board").c_str());
}

// --check loads what a run would and stops: 0 and the summary, or 1 naming
// the problem; it opens no camera, no CAN and no LCM, and plays nothing.
// Under systemd or in a script's pipe stderr is no terminal: --progress still shows the balls, and the
// end (the status line had stopped at "0/2 balls").
TEST(Pinballd, ProgressIntoAPipeShowsTheBallsToTheEnd) {
  std::string text;
  ASSERT_EQ(run_shell(std::string(PINBALLD_EXE) + " --balls 2 --seed 4 --progress 2>&1 >/dev/null", text), 0) << text;
  EXPECT_NE(text.find("pinballd: 0/2 balls (0 %)"), std::string::npos) << text;
  EXPECT_NE(text.find("pinballd: 2/2 balls (100 %)"), std::string::npos) << text;
  std::string quiet;
  ASSERT_EQ(run_shell(std::string(PINBALLD_EXE) + " --balls 1 --seed 4 2>&1 >/dev/null", quiet), 0) << quiet;
  EXPECT_EQ(quiet.find("balls ("), std::string::npos) << "no terminal, not asked: " << quiet;
}

TEST(Pinballd, CheckSaysWhatWouldRunOrWhatIsMissing) {
  std::string text;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --controller controllers/spastic.json --json 2>&1", text),
            0)
      << text;
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_TRUE(j.at("ok").get<bool>());
  EXPECT_EQ(j.at("controller_kind"), "spastic");
  EXPECT_EQ(j.at("mode"), "sim");

  const std::string config = ::testing::TempDir() + "/pinballd_check_" + std::to_string(getpid()) + ".yaml";
  write_file(config, "version: 1\nmode: lab\nboard: " + std::string(kSource) + "/boards/mit1993.board\n" +
                         "calibration: " + kSource + "/calibration/lab.example.yaml\n" +
                         "camera: {source: v4l2, device: /dev/pinball-check-no-such-video}\n" +
                         "can: {interface: pbnosuch0}\n");
  std::string lab;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --config " + config + " 2>&1", lab), 1) << lab;
  EXPECT_EQ(lab.rfind("pinballd: " + config + ": camera.device: ", 0), 0u) << "names the file it checked: " << lab;
  EXPECT_NE(lab.find("no such camera device"), std::string::npos) << lab;
  EXPECT_NE(lab.find("no interface pbnosuch0"), std::string::npos) << lab;
  std::string started;  // the start names all that is missing too, not only the CAN interface it opens first
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --config " + config + " 2>&1", started), 1) << started;
  EXPECT_EQ(started.rfind("pinballd: " + config + ": camera.device: ", 0), 0u) << started;
  EXPECT_NE(started.find("no interface pbnosuch0"), std::string::npos) << started;
  std::string overridden;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --config " + config + " --can-log /nonexistent-dir/x 2>&1",
                      overridden),
            1);
  EXPECT_EQ(overridden.rfind("pinballd: " + config + " and the command line: can.log: ", 0), 0u) << overridden;
  std::string unread;  // a world option for the other world: refused, not ignored
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --world twin --stepper event 2>&1", unread), 1);
  EXPECT_NE(unread.find("--stepper: the twin steps with MuJoCo's own integrator"), std::string::npos) << unread;
  const std::string twin_params = std::string(kSource) + "/config/twin.yaml";
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --twin-params " + twin_params + " 2>&1", unread), 1);
  EXPECT_NE(unread.find("--twin-params: only the twin reads it"), std::string::npos) << unread;
  // A pipe for the CAN log: the start refuses one nobody reads, so the check says the reader must be up.
  const std::string fifo = ::testing::TempDir() + "/pinballd_check_" + std::to_string(getpid()) + ".fifo";
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string piped;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --can-log " + fifo + " --json 2>/dev/null", piped), 0)
      << piped;
  EXPECT_NE(piped.find("is a named pipe: its reader must be running when pinballd starts"), std::string::npos)
      << piped;
  std::remove(fifo.c_str());
  std::string empty;  // an unset variable in a lab script: no log written, and nobody told
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --config " + config + " --can-log '' 2>&1", empty), 2);
  EXPECT_NE(empty.find("--can-log: an empty path names no file to write"), std::string::npos) << empty;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --lcm-url '' 2>&1", empty), 2);  // had meant memq://
  EXPECT_NE(empty.find("--lcm-url: an empty URL names no LCM provider"), std::string::npos) << empty;
  // With --json a script reads one object on stdout either way.
  std::string failed;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --json --config " + config + " 2>/dev/null", failed), 1);
  const nlohmann::json f = nlohmann::json::parse(failed);
  EXPECT_FALSE(f.at("ok").get<bool>());
  EXPECT_NE(f.at("error").get<std::string>().find("no interface pbnosuch0"), std::string::npos) << failed;
  std::remove(config.c_str());
}

TEST(Pinballd, AnLcmFileLogOnAFullDiskExitsThree) {
  std::string text;
  const int status = run_shell(std::string(PINBALLD_EXE) +
                                   " --balls 1 --seed 2 --json --lcm-url 'file:///dev/full?mode=w' 2>&1 >/dev/null",
                               text);
  EXPECT_EQ(status, kExitRecordingIncomplete) << text;
  EXPECT_NE(text.find("lcm: publishing"), std::string::npos) << text;
  EXPECT_NE(text.find("No space left on device"), std::string::npos) << text;
  EXPECT_NE(text.find("pinballd: the recording is incomplete (exit 3): "), std::string::npos) << text;
  EXPECT_NE(text.find(" LCM messages refused, first: lcm: publishing"), std::string::npos) << text;
}

// On the lockstep clock a recording loses nothing to the clock's speed: the world waits for
// the LCM thread (found with a log read at 800 KB/s, which lost 5492 of 15018 messages while
// the run said complete). Messages that still do not fit (a reader that never reads) are
// counted as lost: exit 3.
TEST(Pinballd, ALockstepRunWaitsForASlowLcmLogAndCountsWhatAStuckOneDrops) {
  const std::string base = ::testing::TempDir() + "/pinballd_slow_lcm_" + std::to_string(getpid());
  const std::string fifo = base + ".fifo";
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::size_t read_bytes = 0;
  std::thread slow_reader([&] {
    const int fd = open(fifo.c_str(), O_RDONLY);  // blocks until pinballd opens the log
    if (fd < 0) return;
    char buf[16384];
    for (ssize_t n; (n = read(fd, buf, sizeof buf)) > 0;) {
      read_bytes += static_cast<std::size_t>(n);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // about 800 KB/s
    }
    close(fd);
  });
  std::string out;
  const int status = run_shell(std::string(PINBALLD_EXE) + " --balls 2 --seed 3 --json --lcm-url 'file://" + fifo +
                                   "?mode=w' 2>/dev/null",
                               out);
  slow_reader.join();
  EXPECT_EQ(status, 0) << out;
  const nlohmann::json slow = nlohmann::json::parse(out);
  EXPECT_EQ(slow["lcm"]["dropped_queue_full"].get<int>(), 0) << slow["lcm"];
  EXPECT_TRUE(slow["recording_complete"].get<bool>());
  EXPECT_GT(read_bytes, 0u);

  const int stuck = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // there, and never reads
  ASSERT_GE(stuck, 0);
  std::string err;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --balls 2 --seed 3 --lcm-url 'file://" + fifo +
                          "?mode=w' 2>&1 >/dev/null",
                      err),
            kExitRecordingIncomplete);
  close(stuck);
  EXPECT_NE(err.find("LCM messages dropped: the LCM thread fell behind"), std::string::npos) << err;
  std::remove(fifo.c_str());
}

// The CAN log's reader leaves mid-run (`--can-log /dev/stdout | head -c 100`): the daemon
// neither dies of SIGPIPE (exit 141, no ReleaseAll) nor hangs; the log's frames are counted.
TEST(Pinballd, ACanLogReaderThatLeavesCostsTheLogNotTheRun) {
  const std::string base = ::testing::TempDir() + "/pinballd_head_" + std::to_string(getpid());
  std::string text;
  run_shell("( " + std::string(PINBALLD_EXE) + " --balls 1 --seed 2 --can-log /dev/stdout 2> " + base +
                ".err; echo $? > " + base + ".status ) | head -c 100 > /dev/null",
            text);
  EXPECT_EQ(read_text(base + ".status"), "3\n");
  const std::string err = read_text(base + ".err");
  EXPECT_NE(err.find("CAN log /dev/stdout: write failed: Broken pipe"), std::string::npos) << err;
  EXPECT_NE(err.find("pinballd: the recording is incomplete (exit 3)"), std::string::npos) << err;
  std::remove((base + ".err").c_str());
  std::remove((base + ".status").c_str());
}

// The finding behind the CAN log's writer thread: a log into a pipe whose reader stopped
// reading held the driver thread inside the bus lock, so the heartbeats stopped (the
// board's watchdog tripped) and SIGINT could not end the daemon.
TEST(Pinballd, ACanLogPipeNobodyReadsHoldsNeitherHeartbeatsNorSigint) {
  const std::string base = ::testing::TempDir() + "/pinballd_stalled_" + std::to_string(getpid());
  const std::string fifo = base + ".fifo";
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const int reader = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // there, and never reads
  ASSERT_GE(reader, 0);
  const int pipe_bytes = fcntl(reader, F_SETPIPE_SZ, 4096);  // full within a second of frames
  ASSERT_GT(pipe_bytes, 0);
  const std::string cmd = std::string(PINBALLD_EXE) + " --balls 1000 --realtime --json --can-log " + fifo + " > " +
                          base + ".json 2> " + base + ".err";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait for the log's writer to stall, not for a fixed time: a slow start (ThreadSanitizer on a
  // loaded machine) once let 3 s pass before the pipe was full, and nothing stalled. Stalled: bytes
  // queued and none added for half a second while the heartbeats go on. Not "within so many bytes
  // of the pipe's size": the writer hands the pipe several lines at once, and a write that does not
  // fit in the room left blocks with the pipe up to a kilobyte short of full (seen 3128 of 4096).
  int queued_bytes = 0;
  int unchanged_polls = 0;
  for (int i = 0; i < 600 && unchanged_polls < 5; ++i) {  // 60 s
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const int before = queued_bytes;
    ASSERT_EQ(ioctl(reader, FIONREAD, &queued_bytes), 0);
    unchanged_polls = queued_bytes > 0 && queued_bytes == before ? unchanged_polls + 1 : 0;
  }
  if (unchanged_polls < 5) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
  ASSERT_GE(unchanged_polls, 5) << "the CAN log's writer did not stall on its pipe within 60 s";
  std::this_thread::sleep_for(std::chrono::milliseconds(2000));  // stalled behind the full pipe
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  pid_t done = 0;
  for (int i = 0; i < 100 && done == 0; ++i) {  // 10 s: the log's grace is 1 s
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    done = waitpid(pid, &status, WNOHANG);
  }
  if (done == 0) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    FAIL() << "pinballd did not end within 10 s of SIGINT";
  }
  close(reader);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), kExitRecordingIncomplete) << read_text(base + ".err");
  const nlohmann::json j = nlohmann::json::parse(read_text(base + ".json"));
  // The heartbeats went on through the stall: over the run, less than 2 s of them missing, of
  // which the log's 1 s grace at the end is one (the heartbeats stop with the coils, before the
  // log closes); the stall alone lasted 2.5 s. Not "no watchdog trip": on a loaded 2-core machine
  // the driver thread is at times starved past the board's 100 ms, with or without a log (seen
  // once in 8 plain runs), and the board then rightly trips.
  const double period_s = DaemonConfig{}.can.heartbeat_period_s;
  EXPECT_GT(j["can"]["heartbeats"].get<double>(), (j["wall_s"].get<double>() - 2.0) / period_s) << j["can"];
  EXPECT_TRUE(j["coils_off_at_exit"].get<bool>());
  EXPECT_GT(j["can_log"]["written"].get<int>(), 0);
  EXPECT_GT(j["can_log"]["dropped"].get<int>(), 0);
  for (const char* ext : {".json", ".err", ".fifo"}) std::remove((base + ext).c_str());
}

TEST(Pinballd, VersionNamesTheProgramAndItsVersion) {
  std::string text;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --version", text), 0);
  EXPECT_EQ(text.rfind("pinballd 0.", 0), 0u) << text;
}

// A bad argument is one line naming the program, as `pinball` says it; --check
// --json answers with one object even when the command line itself is wrong.
TEST(Pinballd, BadArgumentsAreOneLineAndCheckJsonStillAnswers) {
  std::string text;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --frobnicate 2>&1", text), 2);
  EXPECT_EQ(text, "pinballd: The following argument was not expected: --frobnicate (try --help)\n");
  std::string out;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --json --controller /nonexistent/c.json 2>/dev/null", out),
            2);
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_FALSE(j.at("ok").get<bool>());
  EXPECT_NE(j.at("error").get<std::string>().find("/nonexistent/c.json"), std::string::npos) << out;
}

TEST(Pinballd, AReportThatDidNotReachStdoutExitsOne) {
  std::string text;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --threads 2>&1 >/dev/full", text), 1);
  EXPECT_EQ(text, "pinballd: the output did not all reach standard output (a full disk, or its reader left)\n");
}

TEST(Pinballd, TheThreadTableAsJson) {
  std::string out;
  ASSERT_EQ(run_shell(std::string(PINBALLD_EXE) + " --threads --json", out), 0);
  const nlohmann::json j = nlohmann::json::parse(out);
  ASSERT_EQ(j.at("threads").size(), kThreadTable.size());
  EXPECT_EQ(j.at("threads")[0].at("name"), kThreadTable[0].name);
  EXPECT_EQ(j.at("threads")[0].at("fifo_priority"), kThreadTable[0].fifo_priority);
}

TEST(Pinballd, BadConfigExitsOneNamingTheKey) {
  const std::string path = ::testing::TempDir() + "/bad_pinballd.yaml";
  write_file(path, "camera:\n  fsp: 200\n");
  std::string text;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --config " + path + " 2>&1", text), 1);
  EXPECT_NE(text.find("camera.fsp: unknown key"), std::string::npos) << text;
  // --check --json answers a bad configuration file with one object too.
  std::string out;
  EXPECT_EQ(run_shell(std::string(PINBALLD_EXE) + " --check --json --config " + path + " 2>/dev/null", out), 1);
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_FALSE(j.at("ok").get<bool>());
  EXPECT_NE(j.at("error").get<std::string>().find("camera.fsp: unknown key"), std::string::npos) << out;
}

// An ordinary user (no CAP_SYS_NICE, RLIMIT_RTPRIO 0) asking for real-time
// scheduling: refused, pinballd warns once and plays; with enforce it exits 1.
// --check says the same before anything runs.
TEST(Pinballd, RealTimeRefusedWarnsAndPlaysOrWithEnforceExitsOne) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to drop to an unprivileged user";
  if (access("/usr/bin/setpriv", X_OK) != 0) GTEST_SKIP() << "no /usr/bin/setpriv (util-linux)";
  const std::string unprivileged =
      "ulimit -r 0; ulimit -l 64; exec /usr/bin/setpriv --reuid=65534 --regid=65534 --clear-groups --inh-caps=-all ";
  for (const bool enforce : {false, true}) {
    const std::string path = ::testing::TempDir() + "/pinballd_rt_" + (enforce ? "enforce" : "warn") + ".yaml";
    write_file(path, "version: 1\nmode: sim\ncontroller: " + kSource + "/controllers/best.json\nsim: {board: " +
                         kSource + "/boards/mit1993.board, balls: 1}\nthreads: {realtime: true, enforce: " +
                         (enforce ? "true" : "false") + "}\n");
    const std::string errors = path + ".err";
    std::string out;
    const int status =
        run_shell("sh -c '" + unprivileged + PINBALLD_EXE + " --config " + path + " --json' 2> " + errors, out);
    std::string err;
    run_shell("cat " + errors, err);
    if (!enforce) {
      ASSERT_EQ(status, 0) << err;
      const nlohmann::json j = nlohmann::json::parse(out);
      EXPECT_EQ(j["balls"].get<int>(), 1);
      EXPECT_TRUE(j["coils_off_at_exit"].get<bool>());
      int fifo_warnings = 0;  // one, not one per thread
      for (const auto& w : j["warnings"]) fifo_warnings += w.get<std::string>().find("SCHED_FIFO") == 0 ? 1 : 0;
      EXPECT_EQ(fifo_warnings, 1) << j["warnings"].dump();
      EXPECT_NE(err.find("warning: SCHED_FIFO"), std::string::npos) << err;
    } else {
      EXPECT_EQ(status, 1) << err;
      EXPECT_NE(err.find("real-time scheduling refused (threads.enforce: true)"), std::string::npos) << err;
    }
    // --check asks the system the same, and says it before the start does.
    std::string check;
    const int check_status = run_shell(
        "sh -c '" + unprivileged + PINBALLD_EXE + " --check --json --config " + path + "' 2>/dev/null", check);
    const nlohmann::json c = nlohmann::json::parse(check);
    if (!enforce) {
      EXPECT_EQ(check_status, 0) << check;
      int fifo_warnings = 0;
      for (const auto& w : c["warnings"]) {
        fifo_warnings += w.get<std::string>().find("; the start runs without it") != std::string::npos &&
                                 w.get<std::string>().find("SCHED_FIFO") == 0
                             ? 1
                             : 0;
      }
      EXPECT_EQ(fifo_warnings, 1) << check;
    } else {
      EXPECT_EQ(check_status, 1) << check;
      EXPECT_NE(c["error"].get<std::string>().find(": threads.enforce: true, and the system refuses: "),
                std::string::npos)
          << check;
    }
  }
}

// One clock for a run's recordings. A lockstep run is many times faster than
// real time; its LCM log events used to carry the wall clock when written
// and its CAN log the wall clock when sent (the game squeezed about 30x),
// while the messages' utime carried the game's time: three clocks. Now every
// stamp is the game's time on the epoch, so lcm-logplayer and canplayer
// replay at the game's pace and line up.
TEST(Daemon, EveryRecordingOfALockstepRunIsStampedOnTheGamesClock) {
  const std::string base = ::testing::TempDir() + "/pinballd_clock_" + std::to_string(getpid());
  DaemonConfig config = short_sim_config(1, 6);
  config.can.log = base + ".can";
  config.lcm_url = "file://" + base + ".lcmlog?mode=w";
  DaemonReport r;
  {
    Daemon d(config);
    r = d.run();
  }
  ASSERT_GT(r.sim_s, 1.0);
  // In a release build lockstep outruns the wall clock about 20 times, so the
  // CAN log's length below tells the game's clock from the wall's; under
  // ThreadSanitizer it may not, and the LCM events still tell them apart.
  const std::int64_t anchor_us = to_utime(r.recording_anchor_s);
  EXPECT_NEAR(r.recording_anchor_s, epoch_now_s() - r.wall_s, 5.0);
  EXPECT_DOUBLE_EQ(report_to_json(r)["recording_anchor_s"].get<double>(), r.recording_anchor_s);

  // LCM: each event is its message's utime (the first field of every type) plus the anchor;
  // the old bus stamped the moment it wrote, which no event would match.
  const std::string log = read_text(base + ".lcmlog");
  std::size_t at = 0, events = 0, on_anchor = 0;
  std::int64_t previous_event_us = 0, first_command_event_us = -1;
  while (at + bus::kLcmEventHeaderBytes <= log.size()) {
    const auto* p = reinterpret_cast<const unsigned char*>(log.data() + at);
    const bus::LcmEventHeader h = bus::read_lcm_event_header(p);
    const std::string channel = log.substr(at + bus::kLcmEventHeaderBytes, static_cast<std::size_t>(h.channel_bytes));
    const unsigned char* data = p + bus::kLcmEventHeaderBytes + h.channel_bytes;
    std::int64_t utime = 0;
    for (int i = 8; i < 16; ++i) utime = (utime << 8) | data[i];  // after the 8-byte fingerprint, big-endian
    EXPECT_GE(h.utime, previous_event_us) << "event " << events << " goes back in time";
    previous_event_us = h.utime;
    on_anchor += h.utime == utime + anchor_us ? 1 : 0;
    if (channel == bus::kFlipperCommandChannel && first_command_event_us < 0) first_command_event_us = h.utime;
    ++events;
    at += bus::kLcmEventHeaderBytes + static_cast<std::size_t>(h.channel_bytes + h.data_bytes);
  }
  ASSERT_EQ(at, log.size());
  ASSERT_GT(events, 100u);
  // A message queued after a later one on another channel is stamped no
  // earlier than that one (about 1 % of them here, more on a slow machine).
  EXPECT_GE(on_anchor, events * 9 / 10) << on_anchor << " of " << events << " events at utime + anchor";
  ASSERT_GE(first_command_event_us, 0);

  // CAN: the game's stretch of the log lasts as long as the game, not as
  // long as the wall clock took, and its first Fire is where LCM has the
  // first command (the driver sends it on the next record).
  const std::string can = read_text(base + ".can");
  double first_game_s = -1.0, last_s = 0.0, first_fire_s = -1.0;
  std::size_t start = 0;
  for (std::size_t end = can.find('\n'); end != std::string::npos; start = end + 1, end = can.find('\n', start)) {
    const auto e = firmware::parse_log_line(can.substr(start, end - start));
    ASSERT_TRUE(e.has_value());
    EXPECT_GE(e->time_s, last_s) << can.substr(start, end - start);
    last_s = e->time_s;
    if (e->time_s >= r.recording_anchor_s && first_game_s < 0.0) first_game_s = e->time_s;
    const firmware::DecodeResult d = firmware::decode(e->frame);
    if (first_fire_s < 0.0 && d.ok() && std::holds_alternative<firmware::Fire>(d.message.payload)) first_fire_s = e->time_s;
  }
  ASSERT_GE(first_game_s, 0.0);
  EXPECT_NEAR(last_s - r.recording_anchor_s, r.sim_s, 0.05 * r.sim_s);
  ASSERT_GE(first_fire_s, 0.0);
  EXPECT_NEAR(first_fire_s, from_utime(first_command_event_us), 2.0 / config.camera.fps);
  std::remove((base + ".can").c_str());
  std::remove((base + ".lcmlog").c_str());
}

// The text report rounds the score as every command does (it printed
// "12100.5 ± 48106.3"); --json keeps full precision.
TEST(Daemon, TheTextReportRoundsTheScore) {
  DaemonReport r;
  r.mode = "sim";
  r.balls = 3;
  r.mean_score = 12100.53;
  r.score_ci95 = 48106.31;
  r.mean_ball_time_s = 12.5533;
  const std::string text = report_to_text(r);
  EXPECT_NE(text.find("mean score per ball 12101 ± 48106 (95 %)  mean ball time 12.6 s"), std::string::npos) << text;
  EXPECT_DOUBLE_EQ(report_to_json(r)["mean_score_per_ball"].get<double>(), 12100.53);
}

// A run a signal ended says so, and how many balls it was to play; a run of
// no ball has no mean (null), not a mean of 0.
TEST(Daemon, TheReportSaysARunEndedBySignalAndHasNoMeanOfNoBall) {
  DaemonReport r;
  r.mode = "sim";
  r.balls = 2;
  r.balls_asked = 100;
  r.stopped_by_signal = true;
  r.mean_score = 5000.0;
  r.score_ci95 = 300.0;
  EXPECT_NE(report_to_text(r).find("balls 2 of 100 (stopped by a signal)  mean score per ball 5000 ± 300"),
            std::string::npos)
      << report_to_text(r);
  EXPECT_TRUE(report_to_json(r)["stopped_by_signal"].get<bool>());
  EXPECT_EQ(report_to_json(r)["balls_asked"], 100);
  DaemonReport none;
  none.mode = "sim";
  const nlohmann::json j = nlohmann::json::parse(report_to_json(none).dump());
  EXPECT_TRUE(j["mean_score_per_ball"].is_null());
  EXPECT_TRUE(j["mean_ball_time_s"].is_null());
  EXPECT_EQ(report_to_text(none).find("mean score"), std::string::npos) << report_to_text(none);
  // Nor latencies of no frame: a stage with count 0 has no quantiles.
  EXPECT_EQ(j["latency"][stage_name(kFrameToCan)]["count"], 0);
  EXPECT_TRUE(j["latency"][stage_name(kFrameToCan)]["p99_us"].is_null());
}

// One JSON for a latency stage, the report's and the latency bench's: a stage with no
// sample has no quantiles (the bench printed 0 us for a controller that never fired).
TEST(Daemon, ALatencyStageWithNoSampleHasNullQuantiles) {
  const nlohmann::json none = latency_to_json(LatencySummary{});
  EXPECT_EQ(none["count"], 0);
  EXPECT_TRUE(none["p50_us"].is_null());
  EXPECT_TRUE(none["p99_us"].is_null());
  EXPECT_TRUE(none["max_us"].is_null());
  const nlohmann::json some = latency_to_json(LatencySummary{3, 120.0, 300.0, 310.0});
  EXPECT_EQ(some["p99_us"].get<double>(), 300.0);
}

TEST(Daemon, UdpmInLockstepWarnsThatALoggerWouldLoseMessages) {
  DaemonConfig c = sim_config(1, 1);
  EXPECT_EQ(lcm_pace_warning(c), "");  // memq://
  c.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  EXPECT_NE(lcm_pace_warning(c).find("--lcm-url 'file:///PATH?mode=w'"), std::string::npos);
  c.sim.realtime = true;
  EXPECT_EQ(lcm_pace_warning(c), "");  // paced by the wall clock
  c.sim.realtime = false;
  c.mode = "lab";
  EXPECT_EQ(lcm_pace_warning(c), "");
}

// The simulated world hands its board the host's frames between camera frames:
// at 10 frames/s or fewer a 0.1 s watchdog trips every frame. Said at the start
// and by --check, with the rate that plays.
TEST(Daemon, ASimulatedCameraSlowerThanTheWatchdogIsWarnedOf) {
  DaemonConfig c = sim_config(1, 1);
  EXPECT_TRUE(config_warnings(c).empty());  // 200 frames/s
  c.camera.fps = 10.0;
  c.camera.stall_timeout_s = 0.5;
  EXPECT_EQ(sim_watchdog_warning(c),
            "camera.fps 10: the simulated board hears the host only between frames, so its 0.1 s watchdog trips "
            "every 0.1 s frame and drops the coils (a real board would not); for play, raise camera.fps above 10");
  ASSERT_EQ(config_warnings(c).size(), 1u);
  c.camera.fps = 12.0;  // 83 ms frames: the board hears every heartbeat in time
  EXPECT_EQ(sim_watchdog_warning(c), "");
  c.camera.fps = 10.0;
  c.mode = "lab";  // the lab's board has its own clock
  c.camera.source = "v4l2";
  EXPECT_EQ(sim_watchdog_warning(c), "");
}

}  // namespace
}  // namespace pinball::daemon
