// pinballd: the real-time controller daemon. With no arguments it plays the
// embedded simulation of boards/mit1993.board over memq:// with the shipped
// controller and prints the mean score per ball and the latency table.

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "pinball/core/data_file_option.h"
#include "pinball/core/file_sink.h"
#include "pinball/core/json_text.h"
#include "pinball/core/number_option.h"
#include "pinball/daemon/config_check.h"
#include "pinball/daemon/daemon.h"
#include "pinball/daemon/thread_table.h"

namespace {

// Signals may arrive before the daemon exists (while it loads and trains its
// background): they are remembered and delivered once it does.
std::atomic<pinball::daemon::Daemon*> g_daemon{nullptr};
volatile std::sig_atomic_t g_stop_pending = 0;

extern "C" void on_stop_signal(int) {
  g_stop_pending = 1;
  if (pinball::daemon::Daemon* d = g_daemon.load()) d->request_stop();
}
// Last resort: anything that still reaches std::terminate switches the coils off before aborting.
[[noreturn]] void on_terminate() {
  if (pinball::daemon::Daemon* d = g_daemon.load()) d->emergency_release();
  std::fputs("pinballd: terminated by an unhandled error; every coil released\n", stderr);
  std::abort();
}

extern "C" void on_stats_signal(int) {
  if (pinball::daemon::Daemon* d = g_daemon.load()) d->request_stats();
}

void install(int sig, void (*handler)(int)) {
  struct sigaction sa {};
  sa.sa_handler = handler;
  sigemptyset(&sa.sa_mask);
  sigaction(sig, &sa, nullptr);
}

// True when `flag` is one of the arguments: read where the parse failed before setting it.
bool given(int argc, char** argv, const char* flag) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], flag) == 0) return true;
  return false;
}

// The thread table for a script: {"threads": [{name, fifo_priority, ...}, ...]}.
nlohmann::json thread_table_json() {
  nlohmann::json rows = nlohmann::json::array();
  for (const pinball::daemon::ThreadSpec& t : pinball::daemon::kThreadTable) {
    rows.push_back({{"name", t.name}, {"fifo_priority", t.fifo_priority}, {"nice", t.nice}, {"chain", t.chain},
                    {"cpu", t.cpu}, {"period", t.period}, {"job", t.job}});
  }
  return {{"threads", rows}};
}

}  // namespace

static int run_pinballd(int argc, char** argv) {
  using namespace pinball::daemon;
  // First of all, so that no signal finds the default action (death with the coils as they are).
  std::set_terminate(on_terminate);
  // Every signal whose default would end the daemon ends it the way SIGINT does: coils off,
  // report, exit 0. SIGHUP is the terminal or ssh session that started it closing.
  for (const int stop : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR2, SIGALRM}) install(stop, on_stop_signal);
  install(SIGUSR1, on_stats_signal);
  // A reader of a recording (or of stdout) that leaves makes a write fail with EPIPE, which the
  // recorders count; the signal would kill the daemon before it released the coils and reported.
  install(SIGPIPE, SIG_IGN);
  CLI::App app("pinballd: the real-time pinball controller (camera -> tracker -> controller -> CAN)");
  app.set_version_flag("--version", std::string("pinballd ") + PINBALL_VERSION);
  app.footer(
      "Exit status: 0 ran (every ball played, or stopped by SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR2 or "
      "SIGALRM); 1 bad configuration or file, or a thread failed; 2 bad argument; "
      "3 ran, but a recording is incomplete (the --can-log file dropped frames, or LCM refused or dropped "
      "messages, e.g. a file:// log on a full disk): the report says what was lost.");
  std::string config_path, sim_board, world_board, world_kind, twin_params, stepper, controller, lcm_url, can_log,
      sim_camera, identified;
  int balls = -1;
  long long seed = -1;
  bool realtime = false, json = false, threads = false, check = false, progress = false;
  const DaemonConfig defaults;  // what --help shows as each option's default (no --config)
  app.add_option("--config", config_path, "YAML configuration (config/lab.example.yaml); none: embedded simulation")
      ->transform(pinball::data_file());
  app.add_option("--sim", sim_board, "simulate this board")
      ->transform(pinball::data_file())
      ->default_str(defaults.sim.board);
  app.add_option("--world-board", world_board,
                 "simulation: the board the table really is (default: the --sim board, which stays the belief of "
                 "the tracker and the controller); same flippers required")
      ->transform(pinball::data_file());
  app.add_option("--world", world_kind,
                 "simulation: which world plays the table, model (the thesis model on --stepper) or twin (the MuJoCo "
                 "lab twin, docs/worlds.md)")
      ->check(CLI::IsMember({"model", "twin"}))
      ->default_str(std::string(pinball::simlab::world_kind_name(defaults.sim.world)));
  app.add_option("--twin-params", twin_params, "simulation: the twin's parameter file (default: config/twin.yaml)")
      ->transform(pinball::data_file());
  app.add_option("--sim-camera", sim_camera,
                 "simulation: the camera, ideal or typical (lens distortion, rolling shutter, 8 ms latency, flicker; "
                 "docs/vision.md)")
      ->check(CLI::IsMember({"ideal", "typical"}))
      ->default_str(defaults.sim.camera);
  app.add_option("--stepper", stepper, "simulation: the model world's integrator, thesis or event")
      ->check(CLI::IsMember({"thesis", "event"}))
      ->default_str(std::string(pinball::sim::stepper_kind_name(defaults.sim.stepper)));
  app.add_option("--identified", identified,
                 "identified parameters laid over the belief board (`pinball identify`, docs/identification.md)")
      ->transform(pinball::data_file());
  app.add_option("--controller", controller, "controller file")
      ->transform(pinball::data_file())
      ->default_str(defaults.controller);
  app.add_option("--balls", balls, "balls to play in simulation")->check(pinball::finite_range(0, 1000000))
      ->default_str(std::to_string(defaults.sim.balls));
  app.add_option("--seed", seed, "launch noise seed in simulation")->check(pinball::unsigned_64())
      ->default_str(std::to_string(defaults.sim.seed));
  app.add_option("--lcm-url", lcm_url, "LCM provider, e.g. memq:// or udpm://239.255.76.67:7667?ttl=0")
      ->check(pinball::lcm_url_given())
      ->default_str(defaults.lcm_url);
  app.add_option("--can-log", can_log,
                 "write every CAN frame to this file in candump's log format (frames it cannot write are "
                 "dropped, counted, and make the exit status 3)")
      ->check(pinball::output_file());
  app.add_flag("--realtime", realtime, "simulation paced to the wall clock (default: lockstep virtual clock)");
  app.add_flag("--json", json, "print the report as one JSON object on stdout");
  app.add_flag("--progress", progress,
               "the live status line (balls with percent and ETA in simulation) on stderr even when it is not a "
               "terminal (a terminal always gets it)");
  app.add_flag("--threads", threads, "print the thread table and exit");
  app.add_flag("--check", check,
               "load and check the configuration and every file it names, as at start, then exit: 0 when all is "
               "well, 1 naming the first problem (in the lab also the camera device and the CAN interface's state; "
               "nothing is opened or fired)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::CallForVersion& e) {
    std::cout << e.what() << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    // One line, as `pinball` says it; and --check --json still answers with one object.
    std::fprintf(stderr, "pinballd: %s (try --help)\n", e.what());
    if (given(argc, argv, "--check") && given(argc, argv, "--json")) {
      std::cout << pinball::json_text(config_check_failure_to_json(e.what()), 2) << std::endl;
    }
    return 2;
  }
  if (threads) {
    if (json) {
      std::cout << pinball::json_text(thread_table_json(), 2) << std::endl;
    } else {
      std::fputs(thread_table_markdown().c_str(), stdout);
    }
    return 0;
  }
  try {
    DaemonConfig config;
    if (!config_path.empty()) config = load_daemon_config(config_path);
    if (!sim_board.empty()) {
      config.mode = "sim";
      config.sim.board = sim_board;
      config.camera.source = "sim";
      config.can.interface = "sim";
    }
    if (!world_board.empty()) config.sim.world_board = world_board;
    if (!stepper.empty()) config.sim.stepper = pinball::sim::parse_stepper_kind(stepper);
    if (!world_kind.empty()) config.sim.world = pinball::simlab::parse_world_kind(world_kind);
    if (!sim_camera.empty()) config.sim.camera = sim_camera;
    if (!twin_params.empty()) config.sim.twin_params = twin_params;
    if (!controller.empty()) config.controller = controller;
    if (!identified.empty()) config.identified = identified;
    if (balls >= 0) config.sim.balls = balls;
    if (seed >= 0) config.sim.seed = static_cast<std::uint64_t>(seed);
    if (!lcm_url.empty()) config.lcm_url = lcm_url;
    if (realtime) config.sim.realtime = true;
    config.progress = progress;
    if (!can_log.empty()) config.can.log = can_log;
    // Given on the command line and then read by no world: said, not ignored (a file lists every key).
    const bool twin = config.sim.world == pinball::simlab::WorldKind::kTwin;
    if (!stepper.empty() && twin) {
      throw std::invalid_argument("--stepper: the twin steps with MuJoCo's own integrator, not a stepper");
    }
    if (!twin_params.empty() && !twin) {
      throw std::invalid_argument("--twin-params: only the twin reads it: give --world twin (or sim.world: twin)");
    }
    // A setting checked after this point is named by where it came from.
    std::size_t settings_given = 0;
    for (const CLI::Option* o : app.get_options()) settings_given += o->count();
    settings_given -= app.count("--config") + app.count("--json") + app.count("--check");
    if (!config_path.empty() && settings_given > 0) config.origin = config_path + " and the command line";
    check_observation_source(config, config.origin);
    if (check) {
      const ConfigCheck result = check_daemon_config(config);
      if (json) {
        std::cout << pinball::json_text(config_check_to_json(result), 2) << std::endl;
      } else {
        std::cout << config_check_to_text(result);
      }
      return 0;
    }
    Daemon daemon(config);
    g_daemon = &daemon;
    if (g_stop_pending) daemon.request_stop();
    std::fprintf(stderr, "pinballd: %s, %s, LCM %s, controller %s\n",
                 config.mode != "sim"            ? "lab"
                 : config.camera.source == "lcm" ? "observations from LCM, virtual driver board (until SIGINT)"
                                                 : ("simulating " + config.sim.board + ", " +
                                                    std::to_string(config.sim.balls) + " balls")
                                                       .c_str(),
                 config.mode == "sim" && config.camera.source == "sim"
                     ? (config.sim.realtime ? "real-time clock" : "lockstep clock")
                     : "steady clock",
                 config.lcm_url.c_str(), config.controller.c_str());
    const DaemonReport report = daemon.run();
    g_daemon = nullptr;
    if (json) {
      std::cout << pinball::json_text(report_to_json(report), 2) << std::endl;
    } else {
      std::cout << report_to_text(report);
    }
    for (const std::string& f : report.thread_failures) std::fprintf(stderr, "pinballd: thread failed: %s\n", f.c_str());
    if (!report.thread_failures.empty()) return 1;  // a failed thread outranks a hole in a recording
    if (const std::string lost = recording_problems(report); !lost.empty()) {
      std::fprintf(stderr, "pinballd: the recording is incomplete (exit %d): %s\n", kExitRecordingIncomplete,
                   lost.c_str());
      return kExitRecordingIncomplete;
    }
    return 0;
  } catch (const std::exception& e) {
    // --check --json: a script reads one object whatever the verdict (the configuration file
    // itself included); a person reads stderr.
    if (check && json) std::cout << pinball::json_text(config_check_failure_to_json(e.what()), 2) << std::endl;
    std::fprintf(stderr, "pinballd: %s\n", e.what());
    return 1;
  }
}

int main(int argc, char** argv) {
  return pinball::exit_status_after_stdout("pinballd", run_pinballd(argc, argv));
}
